//! The selection problem and its flow network (paper, section 4).
//!
//! Per image i two nodes in_i and out_i; arcs source -> in_i (capacity F, cost 0),
//! in_i -> out_i (capacity deg(i), cost c_i), out_i -> in_j for every pair i < j (capacity 1,
//! cost c_ij) and out_i -> sink (capacity F, cost 0). Image i is selected when its image arc
//! carries flow, pair (i, j) when its arc carries its unit.

/// Image and pair costs, each in [-1, 0]. Images are indexed `0..n` in the order that orients the
/// pair arcs (lower index to higher): the caller chooses it (COLMAP image_id order in `prune`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SelectionProblem {
    /// Cost c_i of each image arc (selecting image i).
    pub image_costs: Vec<f64>,
    /// The pair arcs, one per view-graph edge.
    pub pairs: Vec<PairArc>,
}

/// One view-graph edge between image indices `i < j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairArc {
    /// Lower image index.
    pub i: u32,
    /// Higher image index.
    pub j: u32,
    /// Cost c_ij of the pair arc, in [-1, 0].
    pub cost: f64,
}

/// A min-cost flow for one value of F, read back as a selection.
#[derive(Clone, Debug, PartialEq)]
pub struct Selection {
    /// The flow value F this selection was solved for.
    pub flow: u64,
    /// Indexed like `SelectionProblem::image_costs`.
    pub images: Vec<bool>,
    /// Indexed like `SelectionProblem::pairs`.
    pub pairs: Vec<bool>,
    /// Total cost of the flow, sum over arcs of flow x cost (original, unscaled costs).
    pub cost: f64,
}

/// What a restriction ([`SelectionProblem::restrict`]) does with one pair arc.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArcRule {
    /// The arc stays in the network; the flow decides.
    Free,
    /// The arc leaves the network and its pair is always selected, with both its images.
    Fixed,
    /// The arc leaves the network and its pair is never selected.
    Removed,
}

/// A problem restricted to some images and pair arcs, and the way back from its selections to
/// selections of the whole problem. Restricting changes the network, never the costs, so the
/// result stays an exact min-cost flow of what remains.
#[derive(Clone, Debug)]
pub struct Restriction {
    /// The network left: the images not removed and the free arcs, in the original order (so
    /// pair arcs keep their orientation).
    pub problem: SelectionProblem,
    /// Whole-problem image of each restricted image.
    image_of: Vec<u32>,
    /// Whole-problem pair of each restricted pair arc.
    pair_of: Vec<usize>,
    rules: Vec<ArcRule>,
    /// Endpoints of every whole-problem pair.
    ends: Vec<(u32, u32)>,
    num_images: usize,
}

impl SelectionProblem {
    /// The network without the images marked in `removed_images` (and so all their arcs) and
    /// without every arc whose rule is not [`ArcRule::Free`]. `rules` is indexed like `pairs`;
    /// an arc of a removed image must not be [`ArcRule::Fixed`].
    pub fn restrict(&self, removed_images: &[bool], rules: &[ArcRule]) -> Restriction {
        let mut index = vec![u32::MAX; self.image_costs.len()];
        let mut image_of = Vec::new();
        let mut image_costs = Vec::new();
        for (v, (&removed, &cost)) in removed_images.iter().zip(&self.image_costs).enumerate() {
            if !removed {
                index[v] = image_of.len() as u32;
                image_of.push(v as u32);
                image_costs.push(cost);
            }
        }
        let mut pairs = Vec::new();
        let mut pair_of = Vec::new();
        for (k, (p, rule)) in self.pairs.iter().zip(rules).enumerate() {
            let removed = removed_images[p.i as usize] || removed_images[p.j as usize];
            if *rule == ArcRule::Free && !removed {
                pairs.push(PairArc {
                    i: index[p.i as usize],
                    j: index[p.j as usize],
                    cost: p.cost,
                });
                pair_of.push(k);
            }
        }
        Restriction {
            problem: SelectionProblem { image_costs, pairs },
            image_of,
            pair_of,
            rules: rules.to_vec(),
            ends: self.pairs.iter().map(|p| (p.i, p.j)).collect(),
            num_images: self.image_costs.len(),
        }
    }
}

impl Restriction {
    /// The pairs of the whole problem that a selection of the restricted network's `pairs`
    /// keeps: those selected and the fixed ones.
    pub fn expand_pairs(&self, pairs: &[bool]) -> Vec<bool> {
        let mut whole: Vec<bool> = self.rules.iter().map(|&r| r == ArcRule::Fixed).collect();
        for (k, &e) in self.pair_of.iter().enumerate() {
            whole[e] = pairs[k];
        }
        whole
    }

    /// A selection of the restricted network as a selection of the whole problem: plus the
    /// fixed pairs and their images; removed images and arcs never selected. Flow and cost stay
    /// the restricted network's.
    pub fn expand(&self, selection: &Selection) -> Selection {
        let mut images = vec![false; self.num_images];
        for (k, &v) in self.image_of.iter().enumerate() {
            images[v as usize] = selection.images[k];
        }
        let pairs = self.expand_pairs(&selection.pairs);
        for (&(i, j), rule) in self.ends.iter().zip(&self.rules) {
            if *rule == ArcRule::Fixed {
                images[i as usize] = true;
                images[j as usize] = true;
            }
        }
        Selection {
            flow: selection.flow,
            images,
            pairs,
            cost: selection.cost,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restriction_drops_removed_images_and_arcs_and_expands_back_with_fixed_pairs() {
        // Images 0..4; pairs 0-1, 1-2, 2-3, 0-3, 1-3.
        let arc = |i, j, cost| PairArc { i, j, cost };
        let whole = SelectionProblem {
            image_costs: vec![-0.1, -0.2, -0.3, -0.4],
            pairs: vec![
                arc(0, 1, -0.5),
                arc(1, 2, -0.6),
                arc(2, 3, -0.7),
                arc(0, 3, -0.8),
                arc(1, 3, -0.9),
            ],
        };
        use ArcRule::{Fixed, Free, Removed};
        let r = whole.restrict(
            &[false, false, true, false],
            &[Fixed, Free, Free, Removed, Free],
        );
        // Image 2 and its arcs go; the fixed and the removed arc leave too; 3 becomes index 2.
        assert_eq!(r.problem.image_costs, vec![-0.1, -0.2, -0.4]);
        assert_eq!(r.problem.pairs, vec![arc(1, 2, -0.9)]);
        let expanded = r.expand(&Selection {
            flow: 1,
            images: vec![false, true, true],
            pairs: vec![true],
            cost: -1.5,
        });
        assert_eq!(expanded.images, vec![true, true, false, true]);
        assert_eq!(expanded.pairs, vec![true, false, false, false, true]);
        assert_eq!((expanded.flow, expanded.cost), (1, -1.5));
    }
}
