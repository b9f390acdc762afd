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

use super::tracks::Tracks;
use super::PriorValues;
use crate::scene::view_graph::ViewGraph;
use crate::scene::Scene;
use petgraph::unionfind::UnionFind;
use rayon::prelude::*;

/// A pair among this many strongest pairs of both its images is in the backbone.
pub const NEIGHBOURS: usize = 3;

/// Share in [0, 1] of each edge's inliers whose two features are on one backbone track (1 for
/// backbone edges, 0 without inliers).
pub fn compute(scene: &Scene) -> PriorValues {
    let backbone = backbone(scene.graph, &strengths(scene));
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
        name: "backbone_tracks",
        values,
    }
}

/// Each edge's strength: its inliers, each weighted by 1 / the images its track (over all
/// edges) is seen in.
fn strengths(scene: &Scene) -> Vec<f64> {
    let all = Tracks::build(scene, |_| true);
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

/// Which edges are in the backbone: the maximum spanning forest of `strength`, and every edge
/// among the [`NEIGHBOURS`] strongest of both its vertices. Ties go to the lower edge index, so
/// the backbone is the same on every run.
pub fn backbone(graph: &ViewGraph, strength: &[f64]) -> Vec<bool> {
    let mut order: Vec<usize> = (0..graph.edges.len()).collect();
    order.sort_by(|&a, &b| strength[b].total_cmp(&strength[a]).then(a.cmp(&b)));
    let mut rank = vec![0usize; order.len()];
    for (r, &edge) in order.iter().enumerate() {
        rank[edge] = r;
    }
    let mut keep = vec![false; graph.edges.len()];
    let mut forest = UnionFind::<u32>::new(graph.num_vertices());
    for &edge in &order {
        let e = &graph.edges[edge];
        if forest.union(e.i, e.j) {
            keep[edge] = true;
        }
    }
    // Each vertex's NEIGHBOURS strongest edges, as the rank of its weakest one.
    let mut incident: Vec<Vec<usize>> = vec![Vec::new(); graph.num_vertices()];
    for (edge, e) in graph.edges.iter().enumerate() {
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
    for (edge, e) in graph.edges.iter().enumerate() {
        if rank[edge] <= cut[e.i as usize] && rank[edge] <= cut[e.j as usize] {
            keep[edge] = true;
        }
    }
    keep
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::testing::{images, pair};

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
        let values = compute(&scene).values;
        let backbone = backbone(&graph, &strengths(&scene));
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
        let keep = backbone(&graph, &strength);
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
