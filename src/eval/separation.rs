//! How well priors and a selection separate true from false pairs, against ground-truth labels
//! (from [`crate::eval::synth`]): each prior's AUC, and what the selection removed and kept.

use crate::eval::synth::GroundTruth;
use crate::named::Named;
use crate::selection::pipeline::Plan;
use anyhow::{bail, Context, Result};
use petgraph::unionfind::UnionFind;
use serde::Serialize;
use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;

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

/// How well one prior tells true pairs from false ones.
#[derive(Clone, Debug, Serialize)]
pub struct PriorSeparation {
    /// The prior's name, as in the report.
    pub name: String,
    /// AUC of the prior's fitness (after g: higher is better), over the pairs it applies to.
    pub auc: Option<f64>,
    /// Share of true / false pairs the prior applies to (not NaN).
    pub coverage_true: f64,
    /// Share of false pairs the prior applies to (not NaN).
    pub coverage_false: f64,
}

/// How well priors and a selection separate true from false pairs of a view graph.
#[derive(Clone, Debug, Serialize)]
pub struct Separation {
    /// True pairs of the view graph.
    pub true_pairs: usize,
    /// False pairs of the view graph.
    pub false_pairs: usize,
    /// Separation by each prior alone.
    pub priors: Vec<PriorSeparation>,
    /// AUC of minus the pair cost.
    pub cost_auc: Option<f64>,
    /// Share of the false pairs the selection removed (1 without false pairs).
    pub false_removed: f64,
    /// Share of the true pairs the selection kept (1 without true pairs).
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

/// Measures `plan`'s priors and selection against the synthetic ground truth `gt`.
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
            name: p.prior.name().to_string(),
            auc: auc(&p.values, &truth),
            coverage_true: share(count(&|k| truth[k] && !p.values[k].is_nan()), true_pairs),
            coverage_false: share(count(&|k| !truth[k] && !p.values[k].is_nan()), false_pairs),
        })
        .collect();
    let minus_cost: Vec<f64> = plan.costs.pair_costs.iter().map(|c| -c).collect();
    let kept = &plan.search.selection.pairs;
    let n = plan.graph.num_vertices();
    let mut has_pair = vec![false; n];
    let mut components = UnionFind::<usize>::new(n);
    for (k, e) in plan.graph.edges.iter().enumerate() {
        if kept[k] {
            has_pair[e.i as usize] = true;
            has_pair[e.j as usize] = true;
            if truth[k] {
                components.union(e.i as usize, e.j as usize);
            }
        }
    }
    let roots: HashSet<usize> = (0..n).map(|v| components.find(v)).collect();
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

/// A CSV's header and rows (blank lines skipped), checking every row has the header's fields;
/// `what` names the CSV in errors.
fn csv_rows(text: &str, what: &str) -> Result<(Vec<String>, Vec<Vec<String>>)> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<String> = lines
        .next()
        .with_context(|| format!("{what} is empty"))?
        .split(',')
        .map(str::to_string)
        .collect();
    let body = lines
        .map(|l| l.split(',').map(str::to_string).collect::<Vec<_>>())
        .collect::<Vec<_>>();
    if let Some(bad) = body.iter().position(|r| r.len() != header.len()) {
        bail!(
            "{what} line {}: {} fields, the header has {}",
            bad + 2,
            body[bad].len(),
            header.len()
        );
    }
    Ok((header, body))
}

/// The index of column `name` in `header`; `what` names the CSV in errors.
fn csv_column(header: &[String], name: &str, what: &str) -> Result<usize> {
    header
        .iter()
        .position(|h| h == name)
        .with_context(|| format!("{what} has no column `{name}`"))
}

/// The columns of a pair's two image ids.
fn pair_key(header: &[String], what: &str) -> Result<[usize; 2]> {
    Ok([
        csv_column(header, "image_id1", what)?,
        csv_column(header, "image_id2", what)?,
    ])
}

/// The AUC of column `c` (called `name`; negated for `cost`) over the `labelled` rows that have
/// a value there, and how many do.
fn column_auc(labelled: &[(&Vec<String>, bool)], c: usize, name: &str) -> Result<(f64, usize)> {
    let sign = if name == "cost" { -1.0 } else { 1.0 };
    let (values, classes): (Vec<f64>, Vec<bool>) = labelled
        .iter()
        .filter(|(r, _)| !r[c].is_empty())
        .map(|(r, t)| {
            Ok((
                sign * r[c]
                    .parse::<f64>()
                    .with_context(|| format!("column {name}: `{}` is no number", r[c]))?,
                *t,
            ))
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    Ok((auc(&values, &classes).unwrap_or(f64::NAN), values.len()))
}

/// The AUC table of a `prune --scores` CSV against an `eval --labels` CSV (pairs joined by their
/// image ids): per column, the AUC of true pairs over false ones (of -cost for `cost`, where lower
/// is better) and how many pairs have a value; then how many true and false pairs were kept.
pub fn csv_table(scores: &str, labels: &str) -> Result<String> {
    let (score_header, score_rows) = csv_rows(scores, "the scores CSV")?;
    let (label_header, label_rows) = csv_rows(labels, "the labels CSV")?;
    let [a, b] = pair_key(&label_header, "the labels CSV")?;
    let truth_column = csv_column(&label_header, "true_pair", "the labels CSV")?;
    let truth: HashMap<(String, String), bool> = label_rows
        .iter()
        .map(|r| ((r[a].clone(), r[b].clone()), r[truth_column] == "1"))
        .collect();
    let [sa, sb] = pair_key(&score_header, "the scores CSV")?;
    let kept_column = csv_column(&score_header, "kept", "the scores CSV")?;
    let labelled: Vec<(&Vec<String>, bool)> = score_rows
        .iter()
        .filter_map(|r| truth.get(&(r[sa].clone(), r[sb].clone())).map(|&t| (r, t)))
        .collect();
    let n_true = labelled.iter().filter(|(_, t)| *t).count();
    let mut out = format!(
        "{} labelled pairs: {n_true} true, {} false\n{:<28} {:>6} {:>18}\n",
        labelled.len(),
        labelled.len() - n_true,
        "column",
        "AUC",
        "pairs with a value"
    );
    for (c, name) in score_header.iter().enumerate() {
        if c == sa || c == sb || c == kept_column {
            continue;
        }
        let (auc, values) = column_auc(&labelled, c, name)?;
        writeln!(out, "{name:<28} {auc:>6.3} {values:>18}")?;
    }
    let kept = |want: bool| {
        labelled
            .iter()
            .filter(|(r, t)| *t == want && r[kept_column] == "1")
            .count()
    };
    writeln!(
        out,
        "kept: {}/{n_true} true, {}/{} false",
        kept(true),
        kept(false),
        labelled.len() - n_true
    )?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::{auc, csv_table};

    #[test]
    fn auc_of_perfect_reversed_tied_and_absent() {
        let t = [true, true, false, false];
        assert_eq!(auc(&[0.9, 0.8, 0.1, 0.2], &t), Some(1.0));
        assert_eq!(auc(&[0.1, 0.2, 0.9, 0.8], &t), Some(0.0));
        assert_eq!(auc(&[0.5; 4], &t), Some(0.5));
        assert_eq!(auc(&[0.9, f64::NAN, 0.1, f64::NAN], &t), Some(1.0));
        assert_eq!(auc(&[0.9, 0.8], &[true, true]), None);
    }

    #[test]
    fn csv_table_joins_by_image_ids_and_ranks_cost_lower_is_better() {
        let scores = "image_id1,image_id2,inliers,cost,kept\n\
                      1,2,30,-0.9,1\n1,3,10,-0.2,0\n2,3,20,-0.5,1\n3,4,5,-0.1,0\n";
        // (3, 4) has no label and is left out; (1, 3) is the one false pair.
        let labels = "image_id1,image_id2,median_sampson_px,true_pair\n\
                      1,2,0.5,1\n1,3,9.0,0\n2,3,1.0,1\n";
        let table = csv_table(scores, labels).unwrap();
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines[0], "3 labelled pairs: 2 true, 1 false");
        assert!(
            lines[2].starts_with("inliers") && lines[2].contains(" 1.000 "),
            "{table}"
        );
        assert!(
            lines[3].starts_with("cost") && lines[3].contains(" 1.000 "),
            "{table}"
        );
        assert_eq!(lines[4], "kept: 2/2 true, 0/1 false");
        assert!(csv_table("a,b\n1\n", labels).is_err());
    }
}
