//! Pair prior: context similarity (paper, section 5.1). For pair (i, j), U_i = features of i
//! matched in some pair but not in (i, j); `w_ij[k]` = number of features of U_i that match image
//! k (k ≠ j). Two images of the same instance of a duplicated structure see the same context, so
//! their context features match the same images; images of two copies do not.
//!
//! Three variants: `context` (cosine of w_ij and w_ji, the paper's), `context_hamming` (number of
//! images on which the binarised vectors differ, the paper's alternative; lower is better) and
//! `context_outside` (cosine, with U_i restricted to features outside the convex hull of the
//! pair's inliers, and each image k weighted by ln(1 + N / (1 + degree of k)): the features on the
//! duplicated object that this pair did not match still match both copies' images, which blurs
//! the literal context, and images that match nearly everything (overviews) dominate a raw
//! cosine while saying nothing about which instance a view sees; outside the matched region, with
//! such images down-weighted as in TF-IDF, the distinct surroundings remain). The weight is the
//! smoothed IDF: with the plain ln(N / (1 + degree)) every weight is 0 when every image matches
//! every other, as in small exhaustively matched sets, and the variant was constant there.
//! `context_hamming` is constant on such complete view graphs by its definition (every context
//! vector names every other image).

use super::overlap::convex_hull;
use super::values::{Prior, PriorValues};
use crate::scene::Scene;
use rayon::prelude::*;
use std::collections::{BTreeMap, HashSet};

/// Each vertex's matched keypoints with the vertices they match, sorted by keypoint.
fn matched_features(scene: &Scene) -> Vec<Vec<(u32, u32)>> {
    let n = scene.graph.num_vertices();
    let mut out: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
    for (edge, e) in scene.graph.edges.iter().enumerate() {
        for [a, b] in scene.edge_inliers(edge) {
            out[e.i as usize].push((a, e.j));
            out[e.j as usize].push((b, e.i));
        }
    }
    out.par_iter_mut().for_each(|v| v.sort_unstable());
    out
}

/// Ordered, so that sums over it run in one order and the prior is the same bit for bit on every run.
type Context = BTreeMap<u32, f64>;

/// w of vertex `v` in its pair with `other`: features of `v` not in `matched`, kept by `keep`.
fn context_vector(
    features: &[(u32, u32)],
    other: u32,
    matched: &HashSet<u32>,
    keep: &dyn Fn(u32) -> bool,
    weight: &dyn Fn(u32) -> f64,
) -> Context {
    let mut w = Context::new();
    for &(kp, k) in features {
        if k != other && !matched.contains(&kp) && keep(kp) {
            *w.entry(k).or_default() += weight(k);
        }
    }
    w
}

/// Cosine similarity of two context vectors; 0 when either is all zero.
pub fn cosine(a: &Context, b: &Context) -> f64 {
    let dot: f64 = a.iter().map(|(k, x)| x * b.get(k).unwrap_or(&0.0)).sum();
    let norm = |v: &Context| v.values().map(|x| x * x).sum::<f64>().sqrt();
    match norm(a) * norm(b) {
        d if d > 0.0 => dot / d,
        _ => 0.0,
    }
}

/// Number of images in one context vector but not the other (the binarised vectors' distance).
pub fn hamming(a: &Context, b: &Context) -> f64 {
    let only = |x: &Context, y: &Context| x.keys().filter(|k| !y.contains_key(k)).count();
    (only(a, b) + only(b, a)) as f64
}

/// Whether `p` lies inside the convex polygon `hull` (counter-clockwise), border included.
fn inside(hull: &[[f32; 2]], p: [f32; 2]) -> bool {
    if hull.len() < 3 {
        return false;
    }
    (0..hull.len()).all(|k| {
        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
        (b[0] - a[0]) as f64 * (p[1] - a[1]) as f64 - (b[1] - a[1]) as f64 * (p[0] - a[0]) as f64
            >= 0.0
    })
}

/// The three context variants of every edge, in the order `context`, `context_hamming`,
/// `context_outside`.
pub fn compute(scene: &Scene) -> Vec<PriorValues> {
    let features = matched_features(scene);
    let n = scene.graph.num_vertices() as f64;
    let idf = |k: u32| (1.0 + n / (1.0 + scene.graph.degree(k as usize) as f64)).ln();
    let rows: Vec<[f64; 3]> = (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let e = &scene.graph.edges[edge];
            let (i, j) = (e.i as usize, e.j as usize);
            let (mi, mj): (HashSet<u32>, HashSet<u32>) =
                scene.edge_inliers(edge).map(|[a, b]| (a, b)).unzip();
            let all = |_: u32| true;
            let one = |_: u32| 1.0;
            let wi = context_vector(&features[i], e.j, &mi, &all, &one);
            let wj = context_vector(&features[j], e.i, &mj, &all, &one);
            let hull = |v: usize, m: &HashSet<u32>| {
                convex_hull(m.iter().map(|&k| scene.keypoints[v][k as usize]).collect())
            };
            let (hi, hj) = (hull(i, &mi), hull(j, &mj));
            let out_i = |kp: u32| !inside(&hi, scene.keypoints[i][kp as usize]);
            let out_j = |kp: u32| !inside(&hj, scene.keypoints[j][kp as usize]);
            let oi = context_vector(&features[i], e.j, &mi, &out_i, &idf);
            let oj = context_vector(&features[j], e.i, &mj, &out_j, &idf);
            [cosine(&wi, &wj), hamming(&wi, &wj), cosine(&oi, &oj)]
        })
        .collect();
    [Prior::Context, Prior::ContextHamming, Prior::ContextOutside]
        .into_iter()
        .enumerate()
        .map(|(c, prior)| PriorValues {
            prior,
            values: rows.iter().map(|r| r[c]).collect(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colmap::database::{Image, VerifiedPair};
    use crate::scene::testing::{images, pair};
    use crate::scene::view_graph::ViewGraph;

    /// Images 1, 2 see copy A with surroundings seen by image 3; image 4 sees copy B with
    /// surroundings seen by image 5. Pair (1, 2) is true, pair (1, 4) false: the copies match
    /// on keypoints 0..20 (pair (1, 4) only on 0..10, whose hull holds 10..20), the
    /// surroundings are keypoints 20..40.
    /// Pairs (a, b) matching keypoint k of a to keypoint k of b for k in the range.
    fn ranges(spec: &[(u32, u32, std::ops::Range<u32>)]) -> Vec<VerifiedPair> {
        spec.iter()
            .map(|(a, b, r)| pair(*a, *b, r.clone().map(|k| [k, k]).collect()))
            .collect()
    }

    fn two_copies() -> (Vec<Image>, Vec<VerifiedPair>, Vec<Vec<[f32; 2]>>) {
        let images = images(5);
        let pairs = ranges(&[
            (1, 2, 0..20),
            (1, 3, 20..40),
            (2, 3, 20..40),
            (1, 4, 0..10),
            (2, 4, 0..20),
            (4, 5, 20..40),
        ]);
        // Object in the image centre (keypoints 0..20), surroundings on the border.
        let kp = (0..40)
            .map(|k| {
                let a = k as f32 * 0.7;
                let r = match k {
                    0..=9 => 50.0,
                    10..=19 => 20.0,
                    _ => 200.0,
                };
                [320.0 + r * a.cos(), 240.0 + r * a.sin()]
            })
            .collect::<Vec<_>>();
        (images, pairs, vec![kp; 5])
    }

    #[test]
    fn true_pair_shares_context_false_pair_does_not() {
        let (images, pairs, keypoints) = two_copies();
        let graph = ViewGraph::build(&images, &pairs, 1);
        let scene = Scene::new(&graph, &pairs, keypoints, vec![(640, 480); 5]);
        let values = compute(&scene);
        let at = |prior: Prior, a: u32, b: u32| {
            let edge = graph
                .edges
                .iter()
                .position(|e| e.i == a - 1 && e.j == b - 1)
                .unwrap();
            values.iter().find(|p| p.prior == prior).unwrap().values[edge]
        };
        // (1, 2): both images' context is image 3 and the other's copy-mates: identical.
        assert!(at(Prior::ContextOutside, 1, 2) > 0.99);
        // (1, 4): image 1's surroundings match image 3, image 4's match image 5.
        assert_eq!(at(Prior::ContextOutside, 1, 4), 0.0);
        // The literal variant sees the shared object features (matched to 2 and 4 by both).
        assert!(at(Prior::Context, 1, 4) > 0.0);
        assert!(at(Prior::ContextHamming, 1, 4) > at(Prior::ContextHamming, 1, 2));
    }

    #[test]
    fn outside_context_is_seen_when_every_image_matches_every_other() {
        // Images 1..=4, every pair matched: (1, 2) on the object's outer ring (keypoints
        // 0..10, whose hull holds the inner ring 10..20), images 1 and 2 share their
        // surroundings (20..40) with image 3, and image 4 matches the others on the inner ring.
        let (_, _, keypoints) = two_copies();
        let pairs = ranges(&[
            (1, 2, 0..10),
            (1, 3, 20..40),
            (2, 3, 20..40),
            (1, 4, 10..20),
            (2, 4, 10..20),
            (3, 4, 10..20),
        ]);
        let graph = ViewGraph::build(&images(4), &pairs, 1);
        let scene = Scene::new(&graph, &pairs, keypoints[..4].to_vec(), vec![(640, 480); 4]);
        let values = compute(&scene);
        let outside = &values
            .iter()
            .find(|p| p.prior == Prior::ContextOutside)
            .unwrap();
        let edge = graph
            .edges
            .iter()
            .position(|e| (e.i, e.j) == (0, 1))
            .unwrap();
        assert!(outside.values[edge] > 0.99, "{}", outside.values[edge]);
    }

    #[test]
    fn cosine_and_hamming_of_known_vectors() {
        let a: Context = [(1, 1.0), (2, 1.0)].into_iter().collect();
        let b: Context = [(2, 2.0), (3, 5.0)].into_iter().collect();
        assert!((cosine(&a, &b) - 2.0 / (2f64.sqrt() * 29f64.sqrt())).abs() < 1e-12);
        assert_eq!(hamming(&a, &b), 2.0);
        assert_eq!(cosine(&a, &Context::new()), 0.0);
    }
}
