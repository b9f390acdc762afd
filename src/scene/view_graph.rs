//! The view graph: images as vertices, verified pairs with enough inliers as edges.
//!
//! Vertex indices follow ascending COLMAP image_id, the order that orients the flow network's pair
//! arcs (the paper's network is a DAG from lower to higher index, so the order matters).

use crate::colmap::database::{Image, VerifiedPair};
use serde::Serialize;

/// One edge: vertex indices `i < j` and the verified pair it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Edge {
    pub i: u32,
    pub j: u32,
    /// Index into the `pairs` slice given to [`ViewGraph::build`].
    pub pair: usize,
}

#[derive(Clone, Debug)]
pub struct ViewGraph {
    /// image_id of each vertex, ascending. Only images with at least one edge are vertices.
    pub image_ids: Vec<u32>,
    pub edges: Vec<Edge>,
    /// Images without any edge: reported, left alone.
    pub isolated: Vec<u32>,
    /// Neighbour vertices of each vertex, ascending.
    neighbours: Vec<Vec<u32>>,
}

/// Figures `inspect` and the report show.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct GraphStats {
    pub images: usize,
    pub isolated_images: usize,
    pub pairs: usize,
    pub components: usize,
    pub degree_min: usize,
    pub degree_median: f64,
    pub degree_mean: f64,
    pub degree_max: usize,
}

impl ViewGraph {
    /// A pair is an edge when it has at least `min_num_matches` inliers, as `colmap mapper`
    /// decides (`--Mapper.min_num_matches`, default 15).
    pub fn build(images: &[Image], pairs: &[VerifiedPair], min_num_matches: usize) -> ViewGraph {
        let kept: Vec<usize> = (0..pairs.len())
            .filter(|&p| pairs[p].inliers.len() >= min_num_matches.max(1))
            .collect();
        let mut image_ids: Vec<u32> = kept
            .iter()
            .flat_map(|&p| [pairs[p].image_id1, pairs[p].image_id2])
            .collect();
        image_ids.sort_unstable();
        image_ids.dedup();
        let index = |id: u32| image_ids.binary_search(&id).expect("vertex") as u32;
        let mut edges: Vec<Edge> = kept
            .iter()
            .map(|&p| {
                let (a, b) = (index(pairs[p].image_id1), index(pairs[p].image_id2));
                Edge {
                    i: a.min(b),
                    j: a.max(b),
                    pair: p,
                }
            })
            .collect();
        edges.sort_by_key(|e| (e.i, e.j));
        let mut neighbours = vec![Vec::new(); image_ids.len()];
        for e in &edges {
            neighbours[e.i as usize].push(e.j);
            neighbours[e.j as usize].push(e.i);
        }
        for n in &mut neighbours {
            n.sort_unstable();
        }
        let mut isolated: Vec<u32> = images
            .iter()
            .map(|im| im.image_id)
            .filter(|id| image_ids.binary_search(id).is_err())
            .collect();
        isolated.sort_unstable();
        ViewGraph {
            image_ids,
            edges,
            isolated,
            neighbours,
        }
    }

    pub fn num_vertices(&self) -> usize {
        self.image_ids.len()
    }

    pub fn degree(&self, v: usize) -> usize {
        self.neighbours[v].len()
    }

    pub fn neighbours(&self, v: usize) -> &[u32] {
        &self.neighbours[v]
    }

    /// Local clustering coefficient: the fraction of a vertex's neighbour pairs that are
    /// themselves connected (0 for degree < 2).
    pub fn clustering_coefficient(&self, v: usize) -> f64 {
        let nb = &self.neighbours[v];
        let k = nb.len();
        if k < 2 {
            return 0.0;
        }
        let links: usize = nb
            .iter()
            .map(|&u| count_common(&self.neighbours[u as usize], nb))
            .sum::<usize>()
            / 2;
        links as f64 / (k * (k - 1) / 2) as f64
    }

    /// Connected components, by union-find over the edges.
    pub fn num_components(&self) -> usize {
        let mut parent: Vec<u32> = (0..self.num_vertices() as u32).collect();
        fn root(parent: &mut [u32], mut v: u32) -> u32 {
            while parent[v as usize] != v {
                parent[v as usize] = parent[parent[v as usize] as usize];
                v = parent[v as usize];
            }
            v
        }
        let mut components = self.num_vertices();
        for e in &self.edges {
            let (a, b) = (root(&mut parent, e.i), root(&mut parent, e.j));
            if a != b {
                parent[a as usize] = b;
                components -= 1;
            }
        }
        components
    }

    pub fn stats(&self) -> GraphStats {
        let mut degrees: Vec<usize> = (0..self.num_vertices()).map(|v| self.degree(v)).collect();
        degrees.sort_unstable();
        let n = degrees.len();
        let median = match n {
            0 => 0.0,
            _ if n % 2 == 1 => degrees[n / 2] as f64,
            _ => (degrees[n / 2 - 1] + degrees[n / 2]) as f64 / 2.0,
        };
        GraphStats {
            images: n,
            isolated_images: self.isolated.len(),
            pairs: self.edges.len(),
            components: self.num_components(),
            degree_min: degrees.first().copied().unwrap_or(0),
            degree_median: median,
            degree_mean: if n == 0 {
                0.0
            } else {
                2.0 * self.edges.len() as f64 / n as f64
            },
            degree_max: degrees.last().copied().unwrap_or(0),
        }
    }
}

/// Size of the intersection of two ascending lists.
fn count_common(a: &[u32], b: &[u32]) -> usize {
    let (mut i, mut j, mut n) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                n += 1;
                i += 1;
                j += 1;
            }
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::scene::testing::image;

    fn pair(a: u32, b: u32, n: usize) -> VerifiedPair {
        crate::scene::testing::pair(a, b, vec![[0, 0]; n])
    }

    /// Triangle 1-2-3, tail 3-7, weak pair 7-9 below the threshold, image 5 without pairs.
    fn graph() -> ViewGraph {
        let images: Vec<Image> = [1, 2, 3, 5, 7, 9].map(image).to_vec();
        let pairs = vec![
            pair(1, 2, 20),
            pair(2, 3, 15),
            pair(1, 3, 30),
            pair(3, 7, 40),
            pair(7, 9, 14),
        ];
        ViewGraph::build(&images, &pairs, 15)
    }

    #[test]
    fn edges_need_min_num_matches_and_vertices_follow_image_id() {
        let g = graph();
        assert_eq!(g.image_ids, vec![1, 2, 3, 7]);
        assert_eq!(g.isolated, vec![5, 9]);
        let ends: Vec<(u32, u32, usize)> = g.edges.iter().map(|e| (e.i, e.j, e.pair)).collect();
        assert_eq!(ends, vec![(0, 1, 0), (0, 2, 2), (1, 2, 1), (2, 3, 3)]);
    }

    #[test]
    fn clustering_and_components() {
        let g = graph();
        assert_eq!(g.clustering_coefficient(0), 1.0);
        // Vertex 2 (image 3) has neighbours {1, 2, 7}: one linked pair of three.
        assert!((g.clustering_coefficient(2) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(g.clustering_coefficient(3), 0.0);
        assert_eq!(g.num_components(), 1);
        let s = g.stats();
        assert_eq!(
            (s.images, s.pairs, s.degree_min, s.degree_max),
            (4, 4, 1, 3)
        );
        assert_eq!(s.degree_median, 2.0);
    }

    #[test]
    fn swapped_ids_and_two_components() {
        let images: Vec<Image> = [1, 2, 3, 4].map(image).to_vec();
        let pairs = vec![pair(2, 1, 20), pair(4, 3, 20)];
        let g = ViewGraph::build(&images, &pairs, 15);
        assert_eq!(g.edges[0].i, 0);
        assert_eq!(g.edges[0].j, 1);
        assert_eq!(g.num_components(), 2);
    }
}
