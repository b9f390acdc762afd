//! Pair prior (beyond the paper; after the geodesic consistency of Yan et al. 2017): the share of
//! a pair's inliers that the view graph's backbone links by a chain of matches.
//!
//! A false pair between two copies of a duplicated structure is a shortcut: its images are far
//! apart in the scene, and the photographs between them lead from one to the other only the long
//! way round, through views where the copy's point leaves the picture. A true pair's inliers
//! are usually also linked through the images between its two: a point is matched from frame to
//! frame. The backbone stands for "the photographs between": each image's strongest pairs, where
//! strength counts inliers weighted by 1 / the number of images their track is seen in (a
//! feature on a duplicated object joins the copies' tracks, which grow long), so a false pair is
//! rarely among an image's strongest. It is the maximum spanning forest of that strength (every
//! image keeps its link) together with each pair that is among the [`NEIGHBOURS`] strongest of
//! both its images. Tracks made by the backbone's inliers alone then join a true pair's two
//! features and leave a false pair's apart. Backbone pairs score 1.
//!
//! Nothing here depends on the image order or on a cut-off of the matcher's statistics; measured
//! on real photographs and rendered scenes in docs/priors.md.
//!
//! Where a copy's view is an image's strongest pair (views of identical objects from the same
//! side, a symmetric object half an orbit away), that pair enters the backbone and the copies'
//! tracks join. When the user vouches that the images are a sequence ([`Scene::sequence`]), the
//! strongest pairs are chosen among each image's neighbours in the sequence only: views of two
//! copies are far apart in a capture, so no false pair is among them unless two sub-sequences
//! meet there. The forest then only joins the pieces the sequence leaves apart.

use super::tracks::Tracks;
use super::values::{Prior, PriorValues};
use crate::scene::view_graph::{Edge, ViewGraph};
use crate::scene::{Scene, Sequence};
use petgraph::unionfind::UnionFind;
use rayon::prelude::*;

/// A pair among this many strongest pairs of both its images is in the backbone.
pub const NEIGHBOURS: usize = 3;

/// Share in [0, 1] of each edge's inliers whose two features are on one backbone track (1 for
/// backbone edges, 0 without inliers); `all` are the tracks of every edge ([`Tracks::all`]).
pub fn compute(scene: &Scene, all: &Tracks) -> PriorValues {
    let backbone = backbone(scene.graph, &strengths(scene, all), scene.sequence.as_ref());
    let tracks = Tracks::build(scene, |edge| backbone[edge]);
    let values = (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let e = &scene.graph.edges[edge];
            if backbone[edge] {
                return 1.0;
            }
            tracks.inlier_share(scene, edge, |t, [a, b]| t.track(e.i, a) == t.track(e.j, b))
        })
        .collect();
    PriorValues {
        prior: Prior::BackboneTracks,
        values,
    }
}

/// Each edge's strength: its inliers, each weighted by 1 / the images its track (`all`, over
/// every edge) is seen in.
fn strengths(scene: &Scene, all: &Tracks) -> Vec<f64> {
    (0..scene.graph.edges.len())
        .into_par_iter()
        .map(|edge| {
            let i = scene.graph.edges[edge].i;
            scene
                .edge_inliers(edge)
                .map(|[a, _]| 1.0 / all.length(i, a).max(1) as f64)
                .sum()
        })
        .collect()
}

/// Which edges are in the backbone: every edge among the [`NEIGHBOURS`] strongest of both its
/// vertices, and a maximum spanning forest of `strength`. With a `sequence` only neighbours in
/// it count for the strongest, and the forest joins what they leave apart (sub-sequences whose
/// ends do not overlap) by neighbours in the sequence first, then by the strongest pairs between
/// the pieces. Ties go to the lower edge index, so the backbone is the same on every run.
pub fn backbone(graph: &ViewGraph, strength: &[f64], sequence: Option<&Sequence>) -> Vec<bool> {
    let near = |e: &Edge| sequence.is_none_or(|s| s.near(e.i, e.j));
    let mut order = by_strength(strength);
    let mut keep = mutual_strongest(graph, &order, near);
    let mut forest = UnionFind::<u32>::new(graph.num_vertices());
    if sequence.is_some() {
        for (e, _) in graph.edges.iter().zip(&keep).filter(|(_, &k)| k) {
            forest.union(e.i, e.j);
        }
        // Stable: by strength within each group.
        order.sort_by_key(|&edge| !near(&graph.edges[edge]));
    }
    for edge in order {
        let e = &graph.edges[edge];
        if forest.union(e.i, e.j) {
            keep[edge] = true;
        }
    }
    keep
}

/// Edge indices from the strongest to the weakest, ties to the lower index.
fn by_strength(strength: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..strength.len()).collect();
    order.sort_by(|&a, &b| strength[b].total_cmp(&strength[a]).then(a.cmp(&b)));
    order
}

/// The edges for which `candidate` holds that are among the [`NEIGHBOURS`] strongest candidates
/// of both their vertices; `order` lists the edges strongest first ([`by_strength`]).
fn mutual_strongest(
    graph: &ViewGraph,
    order: &[usize],
    candidate: impl Fn(&Edge) -> bool,
) -> Vec<bool> {
    let mut rank = vec![0usize; order.len()];
    for (r, &edge) in order.iter().enumerate() {
        rank[edge] = r;
    }
    let is_candidate: Vec<bool> = graph.edges.iter().map(&candidate).collect();
    // Each vertex's NEIGHBOURS strongest candidates, as the rank of its weakest one.
    let mut incident: Vec<Vec<usize>> = vec![Vec::new(); graph.num_vertices()];
    for (edge, e) in graph
        .edges
        .iter()
        .enumerate()
        .filter(|(k, _)| is_candidate[*k])
    {
        incident[e.i as usize].push(rank[edge]);
        incident[e.j as usize].push(rank[edge]);
    }
    let cut: Vec<usize> = incident
        .iter_mut()
        .map(|ranks| {
            ranks.sort_unstable();
            ranks.get(NEIGHBOURS - 1).copied().unwrap_or(usize::MAX)
        })
        .collect();
    graph
        .edges
        .iter()
        .enumerate()
        .map(|(edge, e)| {
            is_candidate[edge] && rank[edge] <= cut[e.i as usize] && rank[edge] <= cut[e.j as usize]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::testing::{images, pair};
    use crate::scene::Sequence;

    /// A walk of `N` images: background point m (m = 1..=N) is seen by images m..m+REACH-1,
    /// as keypoint (m - k + REACH - 1) * 5 + t (t < 5) of image k. Images 1, 2 see one copy of
    /// an object and images 7, 8 the other (keypoints 20, 21); the copies are matched by the
    /// false pairs (1, 7) and (2, 8), and within each copy by (1, 2) and (7, 8).
    const N: u32 = 8;
    const REACH: u32 = 4;
    const FALSE_PAIRS: [(u32, u32); 2] = [(1, 7), (2, 8)];

    fn walk() -> Vec<crate::colmap::database::VerifiedPair> {
        let feature = |m: u32, k: u32, t: u32| (m + REACH - 1 - k) * 5 + t;
        let mut pairs = Vec::new();
        for a in 1..=N {
            for b in a + 1..=N.min(a + REACH - 1) {
                let mut inliers: Vec<[u32; 2]> = (b.saturating_sub(REACH - 1).max(1)..=a)
                    .flat_map(|m| (0..5).map(move |t| [feature(m, a, t), feature(m, b, t)]))
                    .collect();
                if (a, b) == (1, 2) || (a, b) == (7, 8) {
                    inliers.extend([[20, 20], [21, 21]]);
                }
                pairs.push(pair(a, b, inliers));
            }
        }
        for (a, b) in FALSE_PAIRS {
            pairs.push(pair(a, b, vec![[20, 20], [21, 21]]));
        }
        pairs
    }

    #[test]
    fn false_shortcuts_score_zero_and_true_pairs_one() {
        let pairs = walk();
        let images = images(N);
        let graph = ViewGraph::build(&images, &pairs, 1);
        let scene = Scene::new(
            &graph,
            &pairs,
            vec![vec![[0.0, 0.0]; 22]; N as usize],
            vec![(100, 100); N as usize],
        );
        let all = Tracks::all(&scene);
        let values = compute(&scene, &all).values;
        let backbone = backbone(&graph, &strengths(&scene, &all), None);
        let mut true_outside_backbone = 0;
        for (edge, e) in graph.edges.iter().enumerate() {
            let ids = (graph.image_ids[e.i as usize], graph.image_ids[e.j as usize]);
            if FALSE_PAIRS.contains(&ids) {
                assert!(!backbone[edge], "{ids:?} in the backbone");
                assert_eq!(values[edge], 0.0, "{ids:?}");
            } else {
                true_outside_backbone += !backbone[edge] as usize;
                assert_eq!(values[edge], 1.0, "{ids:?}");
            }
        }
        // The test means something only if some true pair had to be joined the long way.
        assert!(true_outside_backbone > 0);
    }

    /// An orbit of 12 views of an object that looks the same after half a turn: each view's
    /// strongest pair is the one opposite (k, k + 6), false; its true pairs are its neighbours.
    fn symmetric_orbit() -> (ViewGraph, Vec<f64>) {
        let mut pairs = Vec::new();
        for a in 1..=12u32 {
            for b in a + 1..=12 {
                let d = (b - a).min(12 - (b - a));
                if d <= 2 || d == 6 {
                    pairs.push(pair(a, b, vec![[0, 0]]));
                }
            }
        }
        let graph = ViewGraph::build(&images(12), &pairs, 1);
        let strength = graph
            .edges
            .iter()
            .map(|e| match (e.j - e.i).min(12 - (e.j - e.i)) {
                6 => 150.0,
                1 => 100.0 + e.i as f64,
                _ => 80.0 + e.i as f64,
            })
            .collect();
        (graph, strength)
    }

    #[test]
    fn a_sequence_keeps_look_alike_views_far_apart_in_it_out_of_the_backbone() {
        let (graph, strength) = symmetric_orbit();
        let opposite = |e: &Edge| e.j - e.i == 6;
        let count = |keep: &[bool], f: &dyn Fn(&Edge) -> bool| {
            graph
                .edges
                .iter()
                .zip(keep)
                .filter(|(e, &k)| k && f(e))
                .count()
        };
        // Without the sequence every view's strongest pair is in: the test means something.
        let plain = backbone(&graph, &strength, None);
        assert_eq!(count(&plain, &opposite), 6);
        let sequence = Sequence {
            rank: (0..12).collect(),
            window: 2,
        };
        let keep = backbone(&graph, &strength, Some(&sequence));
        assert_eq!(count(&keep, &opposite), 0);
        // Consecutive views (the ring's 11 in the order, and the 12th across the seam is not
        // near in it) are all in.
        assert_eq!(count(&keep, &|e: &Edge| e.j - e.i == 1), 11);
    }

    #[test]
    fn a_sequence_joins_its_pieces_by_neighbours_in_it_before_stronger_pairs() {
        // Two sub-sequences, 1-4 and 5-8, each matched within; between them (4, 6) is near in
        // the sequence but weaker than every pair within, (1, 8) the strongest pair but far.
        let mut ids: Vec<(u32, u32)> = vec![(4, 6), (1, 8)];
        for piece in [1u32, 5] {
            for a in piece..piece + 4 {
                ids.extend((a + 1..piece + 4).map(|b| (a, b)));
            }
        }
        ids.sort_unstable();
        let pairs: Vec<_> = ids.iter().map(|&(a, b)| pair(a, b, vec![[0, 0]])).collect();
        let graph = ViewGraph::build(&images(8), &pairs, 1);
        let strength: Vec<f64> = graph
            .edges
            .iter()
            .map(|e| match (e.i + 1, e.j + 1) {
                (4, 6) => 5.0,
                (1, 8) => 500.0,
                _ => 50.0,
            })
            .collect();
        let kept = |keep: &[bool], ids: (u32, u32)| {
            graph
                .edges
                .iter()
                .zip(keep)
                .any(|(e, &k)| k && (e.i + 1, e.j + 1) == ids)
        };
        let sequence = Sequence {
            rank: (0..8).collect(),
            window: 3,
        };
        let keep = backbone(&graph, &strength, Some(&sequence));
        assert!(kept(&keep, (4, 6)) && !kept(&keep, (1, 8)));
        // Without the sequence the strongest pair joins them, and the weak one is left out.
        let plain = backbone(&graph, &strength, None);
        assert!(kept(&plain, (1, 8)) && !kept(&plain, (4, 6)));
    }

    #[test]
    fn backbone_keeps_a_weak_bridge_and_each_vertex_strongest_pairs() {
        // Two 5-cliques (vertices 1..=5 and 6..=10) joined by one weak edge (5, 6).
        let mut pairs = Vec::new();
        for group in [1u32, 6] {
            for a in group..group + 5 {
                for b in a + 1..group + 5 {
                    pairs.push(pair(a, b, vec![[0, 0]]));
                }
            }
        }
        pairs.push(pair(5, 6, vec![[0, 0]]));
        let graph = ViewGraph::build(&images(10), &pairs, 1);
        // Strength: the bridge weakest; within a clique, pairs of near ids strongest, and of
        // two equally near pairs the later one.
        let strength: Vec<f64> = graph
            .edges
            .iter()
            .map(|e| match (e.i, e.j) {
                (4, 5) => 0.1,
                (i, j) => 10.0 - (j - i) as f64 + 0.01 * i as f64,
            })
            .collect();
        let keep = backbone(&graph, &strength, None);
        let kept: Vec<(u32, u32)> = graph
            .edges
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(e, _)| (e.i + 1, e.j + 1))
            .collect();
        // Forest: the chain 1-2-3-4-5, the bridge, 6-7-8-9-10. Mutual top 3 beyond it: (2, 4)
        // and (3, 5); (1, 3) is in 1's top 3 but not in 3's (4, 2 and 5 are stronger there),
        // (1, 4) in 1's but not in 4's. The same in the other clique.
        let mut expected = vec![(5, 6)];
        for g in [0, 5] {
            expected.extend(
                [(1, 2), (2, 3), (3, 4), (4, 5), (2, 4), (3, 5)].map(|(a, b)| (a + g, b + g)),
            );
        }
        expected.sort_unstable();
        let mut kept = kept;
        kept.sort_unstable();
        assert_eq!(kept, expected);
    }
}
