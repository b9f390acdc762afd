//! How well priors and a selection separate true from false pairs, against ground-truth labels
//! (from [`crate::eval::synth`]): each prior's AUC, and what the selection removed and kept.

use crate::eval::synth::GroundTruth;
use crate::selection::pipeline::Plan;
use serde::Serialize;
use std::collections::{HashMap, HashSet};

/// Probability that a random true pair scores above a random false pair (ties count half);
/// NaN scores are left out. None without both classes.
pub fn auc(scores: &[f64], truth: &[bool]) -> Option<f64> {
    let mut rows: Vec<(f64, bool)> = scores
        .iter()
        .zip(truth)
        .filter(|(s, _)| !s.is_nan())
        .map(|(&s, &t)| (s, t))
        .collect();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let positives = rows.iter().filter(|r| r.1).count() as f64;
    let negatives = rows.len() as f64 - positives;
    if positives == 0.0 || negatives == 0.0 {
        return None;
    }
    // Mann-Whitney U with average ranks over ties.
    let mut rank_sum = 0.0;
    let mut k = 0;
    while k < rows.len() {
        let end = (k..rows.len())
            .find(|&m| rows[m].0 != rows[k].0)
            .unwrap_or(rows.len());
        let rank = (k + end + 1) as f64 / 2.0;
        rank_sum += rank * rows[k..end].iter().filter(|r| r.1).count() as f64;
        k = end;
    }
    Some((rank_sum - positives * (positives + 1.0) / 2.0) / (positives * negatives))
}

#[derive(Clone, Debug, Serialize)]
pub struct PriorSeparation {
    pub name: String,
    /// AUC of the prior's fitness (after g: higher is better), over the pairs it applies to.
    pub auc: Option<f64>,
    /// Share of true / false pairs the prior applies to (not NaN).
    pub coverage_true: f64,
    pub coverage_false: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Separation {
    pub true_pairs: usize,
    pub false_pairs: usize,
    pub priors: Vec<PriorSeparation>,
    /// AUC of minus the pair cost.
    pub cost_auc: Option<f64>,
    pub false_removed: f64,
    pub true_kept: f64,
    /// Images (of the view graph) without any selected pair.
    pub images_without_pair: usize,
    /// Connected components of the selected true pairs over the view graph's images.
    pub true_components: usize,
}

/// The view graph's edge labels: true when the pair's inliers come from the same 3D points.
pub fn labels(plan: &Plan, gt: &GroundTruth) -> Vec<bool> {
    let truth: HashMap<(u32, u32), bool> = gt
        .pairs
        .iter()
        .map(|p| ((p.image_id1, p.image_id2), p.true_pair))
        .collect();
    plan.graph
        .edges
        .iter()
        .map(|e| {
            let p = &plan.pairs[e.pair];
            truth
                .get(&(p.image_id1, p.image_id2))
                .copied()
                .unwrap_or(false)
        })
        .collect()
}

pub fn measure(plan: &Plan, gt: &GroundTruth) -> Separation {
    let truth = labels(plan, gt);
    let count = |f: &dyn Fn(usize) -> bool| (0..truth.len()).filter(|&k| f(k)).count();
    let true_pairs = count(&|k| truth[k]);
    let false_pairs = truth.len() - true_pairs;
    let share = |n: usize, of: usize| if of == 0 { 1.0 } else { n as f64 / of as f64 };
    let priors = plan
        .costs
        .pair_fitness
        .iter()
        .map(|p| PriorSeparation {
            name: p.name.to_string(),
            auc: auc(&p.values, &truth),
            coverage_true: share(count(&|k| truth[k] && !p.values[k].is_nan()), true_pairs),
            coverage_false: share(count(&|k| !truth[k] && !p.values[k].is_nan()), false_pairs),
        })
        .collect();
    let minus_cost: Vec<f64> = plan.costs.pair_costs.iter().map(|c| -c).collect();
    let kept = &plan.search.selection.pairs;
    let n = plan.graph.num_vertices();
    let mut has_pair = vec![false; n];
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(parent: &mut [usize], v: usize) -> usize {
        let mut v = v;
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    for (k, e) in plan.graph.edges.iter().enumerate() {
        if kept[k] {
            has_pair[e.i as usize] = true;
            has_pair[e.j as usize] = true;
            if truth[k] {
                let (a, b) = (
                    find(&mut parent, e.i as usize),
                    find(&mut parent, e.j as usize),
                );
                parent[a] = b;
            }
        }
    }
    let roots: HashSet<usize> = (0..n).map(|v| find(&mut parent, v)).collect();
    Separation {
        true_pairs,
        false_pairs,
        priors,
        cost_auc: auc(&minus_cost, &truth),
        false_removed: share(count(&|k| !truth[k] && !kept[k]), false_pairs),
        true_kept: share(count(&|k| truth[k] && kept[k]), true_pairs),
        images_without_pair: has_pair.iter().filter(|&&h| !h).count(),
        true_components: roots.len(),
    }
}

impl Separation {
    /// A Markdown table of the priors' AUCs and the selection's figures.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{} true / {} false pairs\n\n| prior | AUC | applies to true / false |\n| --- | --- | --- |\n",
            self.true_pairs, self.false_pairs
        );
        let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.3}"));
        for p in &self.priors {
            s += &format!(
                "| {} | {} | {:.0}% / {:.0}% |\n",
                p.name,
                f(p.auc),
                100.0 * p.coverage_true,
                100.0 * p.coverage_false
            );
        }
        s += &format!(
            "| (pair cost) | {} | |\n\nfalse pairs removed {:.1}%, true pairs kept {:.1}%, \
             images without a selected pair {}, components of the selected true pairs {}\n",
            f(self.cost_auc),
            100.0 * self.false_removed,
            100.0 * self.true_kept,
            self.images_without_pair,
            self.true_components
        );
        s
    }
}

#[cfg(test)]
mod tests {
    use super::auc;

    #[test]
    fn auc_of_perfect_reversed_tied_and_absent() {
        let t = [true, true, false, false];
        assert_eq!(auc(&[0.9, 0.8, 0.1, 0.2], &t), Some(1.0));
        assert_eq!(auc(&[0.1, 0.2, 0.9, 0.8], &t), Some(0.0));
        assert_eq!(auc(&[0.5; 4], &t), Some(0.5));
        assert_eq!(auc(&[0.9, f64::NAN, 0.1, f64::NAN], &t), Some(1.0));
        assert_eq!(auc(&[0.9, 0.8], &[true, true]), None);
    }
}
