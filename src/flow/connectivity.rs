//! The search criterion that the selection has no cut image: its selected images are connected
//! and stay connected when any one of them is removed (2-vertex-connected, for two images or
//! more). A chain or a tree of pairs meets coverage criteria as well as a ring does, but each of
//! its images is a single point of failure for the mapper; the authors' later code asked for
//! k-connectivity in the same place. Measured, it did not pay (docs/performance.md): on a
//! rendered 100-image orbit the chain of 99 pairs that a registrability criterion kept gave a model
//! 1.5x less accurate than the full one, and the biconnected selection (197 pairs) 4x, so no
//! preset turns it on.

use crate::network::SelectionProblem;
use crate::search::SelectionCheck;

/// [`SelectionCheck`] met (1 of 1) when the selected pairs form one 2-vertex-connected graph.
pub struct Biconnected {
    ends: Vec<(u32, u32)>,
    num_images: usize,
}

impl Biconnected {
    /// The check for `problem`'s pairs.
    pub fn new(problem: &SelectionProblem) -> Biconnected {
        Biconnected {
            ends: problem.pairs.iter().map(|p| (p.i, p.j)).collect(),
            num_images: problem.image_costs.len(),
        }
    }
}

impl SelectionCheck for Biconnected {
    fn name(&self) -> &str {
        "biconnected"
    }

    fn target(&self) -> usize {
        1
    }

    fn achieved(&self, pairs: &[bool]) -> usize {
        let edges: Vec<(u32, u32)> = self
            .ends
            .iter()
            .zip(pairs)
            .filter(|(_, &on)| on)
            .map(|(&e, _)| e)
            .collect();
        is_biconnected(self.num_images, &edges) as usize
    }
}

/// Whether the graph of `edges` on the vertices they touch is connected and has no
/// articulation vertex (Hopcroft-Tarjan low points, iterative). Fewer than three touched vertices
/// count as biconnected when connected; no edge at all does not.
pub fn is_biconnected(num_vertices: usize, edges: &[(u32, u32)]) -> bool {
    let mut adjacency = vec![Vec::new(); num_vertices];
    for &(i, j) in edges {
        adjacency[i as usize].push(j as usize);
        adjacency[j as usize].push(i as usize);
    }
    let touched = adjacency.iter().filter(|a| !a.is_empty()).count();
    let Some(root) = adjacency.iter().position(|a| !a.is_empty()) else {
        return false;
    };
    const UNSEEN: usize = usize::MAX;
    let mut order = vec![UNSEEN; num_vertices];
    let mut low = vec![0usize; num_vertices];
    let mut parent = vec![UNSEEN; num_vertices];
    // Depth-first stack of (vertex, next neighbour index).
    let mut stack = vec![(root, 0usize)];
    order[root] = 0;
    low[root] = 0;
    let (mut visited, mut root_children) = (1usize, 0usize);
    while let Some(&mut (v, ref mut next)) = stack.last_mut() {
        if let Some(&w) = adjacency[v].get(*next) {
            *next += 1;
            if order[w] == UNSEEN {
                order[w] = visited;
                low[w] = visited;
                visited += 1;
                parent[w] = v;
                if v == root {
                    root_children += 1;
                }
                stack.push((w, 0));
            } else if w != parent[v] {
                low[v] = low[v].min(order[w]);
            }
        } else {
            stack.pop();
            let p = parent[v];
            if p != UNSEEN {
                low[p] = low[p].min(low[v]);
                // p cuts v's subtree off unless that subtree reaches above p.
                if p != root && low[v] >= order[p] {
                    return false;
                }
            }
        }
    }
    visited == touched && root_children <= 1
}

/// Compared with a brute-force test on random graphs in tests/search.rs.
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_ring_and_bowtie() {
        assert!(!is_biconnected(4, &[(0, 1), (1, 2), (2, 3)]));
        assert!(is_biconnected(4, &[(0, 1), (1, 2), (2, 3), (0, 3)]));
        // Two triangles sharing vertex 2.
        assert!(!is_biconnected(
            5,
            &[(0, 1), (1, 2), (0, 2), (2, 3), (3, 4), (2, 4)]
        ));
        assert!(is_biconnected(2, &[(0, 1)]));
        assert!(!is_biconnected(3, &[]));
    }
}
