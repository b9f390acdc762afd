//! What a prune did: the JSON report (`--report FILE`) and the short summary on stderr.

use crate::colmap::ids::pair_id;
use crate::flow::search::CriterionStatus;
use crate::named::Named;
use crate::priors::PriorValues;
use crate::scene::view_graph::{GraphStats, ViewGraph};
use crate::selection::arc_rules::Listed;
use crate::selection::parameters::Parameters;
use crate::selection::pipeline::{Plan, Timings};
use crate::selection::track_completion::Completion;
use serde::Serialize;
use std::collections::HashMap;

/// Version of the report's layout; bumped when a field changes meaning or disappears.
pub const SCHEMA_VERSION: u32 = 1;

/// The JSON report of one prune (layout in docs/report.md), built from its [`Plan`].
#[derive(Debug, Serialize)]
pub struct Report {
    /// [`SCHEMA_VERSION`], so readers can tell layouts apart.
    pub schema_version: u32,
    /// vgsel-colmap's version (Cargo package version).
    pub tool_version: &'static str,
    /// The input database, as given.
    pub database_path: String,
    /// Where the pruned database was written (the input itself unless `--output`); null on a dry run.
    pub output_path: Option<String>,
    /// True when nothing was written (no output path).
    pub dry_run: bool,
    /// The run's [`Parameters`], as recorded in the database's run record.
    pub parameters: serde_json::Value,
    /// The total flow F of the selection.
    pub flow: u64,
    /// True when no flow met the criteria and the full view graph was kept.
    pub capped: bool,
    /// Rows of the images table.
    pub images_total: usize,
    /// Images with at least one view-graph edge.
    pub images_in_view_graph: usize,
    /// View-graph images the selection uses (kept pairs' images included).
    pub images_selected: usize,
    /// Names of images without any verified pair of at least `min_num_matches` inliers.
    pub images_isolated: Vec<String>,
    /// two_view_geometries rows with inliers (below `min_num_matches` too).
    pub pairs_verified: usize,
    /// View-graph edges (pairs with at least `min_num_matches` inliers).
    pub pairs_total: usize,
    /// Edges left valid (kept pairs included).
    pub pairs_selected: usize,
    /// Edges invalidated (or that would be, on a dry run): `pairs_total - pairs_selected`.
    pub pairs_invalidated: usize,
    /// Selected edges kept with fewer inliers: `--model` dropped the matches that held a
    /// misplaced image where a mapper put it, and a link's matches its placement does not
    /// explain.
    pub pairs_trimmed: usize,
    /// The inliers those pairs lost.
    pub matches_dropped: usize,
    /// The fitness floor applied: the cost model's `min_pair_fitness`, lowered (with a
    /// searched flow) as far as the criteria need ([`crate::selection::arc_rules::fitness_floor`]).
    pub fitness_floor: f64,
    /// Edges never offered to the flow: fitness below `fitness_floor`.
    pub pairs_below_fitness_floor: usize,
    /// The cost model's `min_backbone_tracks` (0: no gate).
    pub min_backbone_tracks: f64,
    /// Edges offered to the flow whose `backbone_tracks` share is below `min_backbone_tracks`
    /// (the view graph does not corroborate them): the track completion's spanning forests
    /// and per-image need pass over them.
    pub pairs_below_backbone_tracks: usize,
    /// The view graph before the prune.
    pub graph_before: GraphStats,
    /// The graph of the selected pairs; its `isolated_images` counts every image left without one.
    pub graph_after: GraphStats,
    /// Of the flow's selection, before kept pairs are added (see docs/report.md).
    pub criteria: Vec<CriterionStatus>,
    /// The pairs the track completion added after the flow (null when it did not run).
    pub completion: Option<Completion>,
    /// Mean fitness of each prior, image priors first, to show what the selection favoured.
    pub priors: Vec<PriorSummary>,
    /// The overrides applied, by name.
    pub overrides: Listed,
    /// The order the network's pair arcs followed, and how sequential the selection is in it.
    pub order: OrderReport,
    /// Files written besides the database: filled in by the command as it writes them.
    pub outputs: Outputs,
    /// Seconds per stage.
    pub timings: Timings,
}

/// Paths of the extra files a prune wrote (null or empty when not asked for).
#[derive(Debug, Default, Serialize)]
pub struct Outputs {
    /// The `--pairs_out` pair list, if written.
    pub pairs_out: Option<String>,
    /// The SVG plots written (`--plots`).
    pub plots: Vec<String>,
}

/// The order the pair arcs followed and how sequential the pairs are in it.
#[derive(Debug, Serialize)]
pub struct OrderReport {
    /// Which order (`--order`).
    pub name: crate::selection::capture_order::Order,
    /// Share of the selected pairs whose images are at most `window` positions apart (null when
    /// none is selected), and the same over the whole view graph for comparison.
    pub selected_within_window: Option<f64>,
    /// See `selected_within_window`.
    pub view_graph_within_window: Option<f64>,
    /// Positions apart that count as sequential.
    pub window: u32,
    /// With the `exif` order: images without a capture time (placed last, by name).
    pub images_without_time: usize,
    /// `--sequence_window`: images this many positions apart are neighbours in a capture
    /// sequence, which backbone_tracks' backbone keeps to (0: not used).
    pub sequence_window: u32,
    /// `--keep_neighbours`: pairs of images at most this many positions apart were kept
    /// whatever the flow selected (0: not used).
    pub keep_neighbours: u32,
    /// How many view-graph pairs that kept (besides `--keep_pairs`).
    pub neighbours_kept: usize,
}

/// Spread of one prior's fitness over all images or pairs, and over the selected ones.
#[derive(Debug, Serialize)]
pub struct PriorSummary {
    /// The prior's name, as in the cost model.
    pub name: &'static str,
    /// `images` or `pairs`.
    pub applies_to: &'static str,
    /// Mean fitness (after g, in [0, 1]) over all images or pairs of the view graph; NaN (JSON
    /// null) when the prior does not apply to some of them.
    pub mean_fitness: f64,
    /// Over the images or pairs the selection kept (0 when none).
    pub mean_fitness_selected: f64,
    /// Over the images or pairs the selection left out (0 when none).
    pub mean_fitness_removed: f64,
}

impl Report {
    /// The report of `plan`; `output_path` None means a dry run. `outputs` starts empty.
    pub fn new(
        plan: &Plan,
        database_path: String,
        output_path: Option<String>,
        parameters: &Parameters,
    ) -> Report {
        let selection = &plan.search.selection;
        let after = ViewGraph::build(&plan.images, &plan.selected_pairs(), 1);
        let mut priors = prior_summaries(&plan.costs.image_fitness, &selection.images, "images");
        priors.extend(prior_summaries(
            &plan.costs.pair_fitness,
            &selection.pairs,
            "pairs",
        ));
        Report {
            schema_version: SCHEMA_VERSION,
            tool_version: env!("CARGO_PKG_VERSION"),
            dry_run: output_path.is_none(),
            database_path,
            output_path,
            parameters: serde_json::to_value(parameters).expect("parameters serialise"),
            flow: selection.flow,
            capped: plan.search.capped,
            images_total: plan.images.len(),
            images_in_view_graph: plan.graph.num_vertices(),
            images_selected: selection.images.iter().filter(|&&s| s).count(),
            images_isolated: isolated_names(plan),
            pairs_verified: plan.pairs.len(),
            pairs_total: plan.graph.edges.len(),
            pairs_selected: selection.pairs.iter().filter(|&&s| s).count(),
            pairs_invalidated: plan.edits.invalidate.len(),
            pairs_trimmed: plan.edits.trim.len(),
            matches_dropped: matches_dropped(plan),
            fitness_floor: plan.fitness_floor,
            pairs_below_fitness_floor: plan.below_fitness_floor,
            min_backbone_tracks: parameters.cost_model.min_backbone_tracks,
            pairs_below_backbone_tracks: plan.below_backbone_tracks,
            graph_before: plan.graph.stats(),
            graph_after: after.stats(),
            criteria: plan.search.criteria.clone(),
            completion: plan.completion.clone(),
            priors,
            overrides: plan.overrides.clone(),
            order: OrderReport::new(plan, parameters),
            outputs: Outputs::default(),
            timings: plan.timings.clone(),
        }
    }

    /// Two or three lines for a person.
    pub fn summary(&self) -> String {
        let mut s = self.headline();
        if let Some(c) = &self.completion {
            let gated = match self.pairs_below_backbone_tracks {
                0 => String::new(),
                n => format!(" (passing over {n} pairs below the backbone-tracks gate)"),
            };
            s += &format!(
                "track completion: the flow kept {} pairs; {} added from the strongest spanning \
                 forests{gated}, {} for {} images short of keypoints on tracks, {} for the track \
                 length ({:.1} -> {:.1}; full graph {:.1})\n",
                c.pairs_from_flow,
                c.pairs_added_for_spanning_forests,
                c.pairs_added_for_images,
                c.images_short,
                c.pairs_added_for_track_length,
                c.track_length_flow,
                c.track_length,
                c.track_length_full,
            );
        }
        s += &format!(
            "components: {} before, {} after; {} pairs invalidated{}",
            self.graph_before.components,
            self.graph_after.components,
            self.pairs_invalidated,
            if self.dry_run {
                " (dry run: nothing written)"
            } else {
                ""
            }
        );
        s + &self.notes()
    }

    /// The summary's first line: what was selected, at which F, and what set it.
    fn headline(&self) -> String {
        let pct = |a: usize, b: usize| {
            if b == 0 {
                0.0
            } else {
                100.0 * a as f64 / b as f64
            }
        };
        let binding = self
            .criteria
            .iter()
            .find(|c| c.binding)
            .map(|c| c.name.as_str());
        let why = match (self.capped, binding) {
            (true, _) => "no flow met the criteria: every pair the network offers kept".to_string(),
            (false, Some(name)) => format!("set by the {name} criterion"),
            (false, None) => "fixed by --flow".to_string(),
        };
        format!(
            "selected {} of {} pairs ({:.1}%) and {} of {} images at flow F = {} ({why})\n",
            self.pairs_selected,
            self.pairs_total,
            pct(self.pairs_selected, self.pairs_total),
            self.images_selected,
            self.images_in_view_graph,
            self.flow,
        )
    }

    /// The summary's last lines, each where it applies: the order, the overrides, the close
    /// neighbours, the isolated images.
    fn notes(&self) -> String {
        let mut s = String::new();
        if let Some(share) = self.order.selected_within_window {
            s += &format!(
                "\npair arcs in {} order: {:.0}% of the selected pairs are within {} positions",
                self.order.name.name(),
                100.0 * share,
                self.order.window
            );
        }
        let o = &self.overrides;
        if !(o.keep_pairs.is_empty() && o.forbid_pairs.is_empty() && o.forbid_images.is_empty()) {
            s += &format!(
                "\noverrides: {} pairs kept, {} pairs and {} images forbidden",
                o.keep_pairs.len(),
                o.forbid_pairs.len(),
                o.forbid_images.len()
            );
        }
        if let Some(blamed) = &o.model_conflicts {
            s += &format!(
                "\nmodel check: {} pairs that glued a ghosted model never selected",
                blamed.len()
            );
        }
        if let Some(links) = o.model_links.as_ref().filter(|l| !l.is_empty()) {
            s += &format!(
                "\nmodel check: {} pairs that link clean models into one kept",
                links.len()
            );
        }
        if self.pairs_trimmed > 0 {
            s += &format!(
                "\nmodel check: {} matches dropped from {} kept pairs (holding misplaced images, \
                 or not explained by a link's placement)",
                self.matches_dropped, self.pairs_trimmed
            );
        }
        if self.order.keep_neighbours > 0 {
            s += &format!(
                "\nclose neighbours: {} pairs within {} positions kept",
                self.order.neighbours_kept, self.order.keep_neighbours
            );
        }
        if !self.images_isolated.is_empty() {
            s += &format!(
                "\n{} images have no verified pair and were left alone",
                self.images_isolated.len()
            );
        }
        s
    }
}

/// The inliers the trimmed pairs lost.
fn matches_dropped(plan: &Plan) -> usize {
    let before = |id: u64| {
        let p = plan
            .pairs
            .iter()
            .find(|p| pair_id(p.image_id1, p.image_id2) == id);
        p.map_or(0, |p| p.inliers.len())
    };
    (plan.edits.trim.iter())
        .map(|t| before(t.pair_id) - t.inliers.len())
        .sum()
}

/// Names of the images without a view-graph edge, sorted.
fn isolated_names(plan: &Plan) -> Vec<String> {
    let names: HashMap<u32, &str> = plan
        .images
        .iter()
        .map(|im| (im.image_id, im.name.as_str()))
        .collect();
    let mut isolated: Vec<String> = plan
        .graph
        .isolated
        .iter()
        .map(|id| names[id].to_string())
        .collect();
    isolated.sort();
    isolated
}

/// Each prior's mean fitness over all images (or pairs), the kept and the removed ones.
fn prior_summaries(
    fitness: &[PriorValues],
    kept: &[bool],
    applies_to: &'static str,
) -> Vec<PriorSummary> {
    let mean_where = |values: &[f64], want: bool| {
        let values = values.iter().zip(kept);
        mean(values.filter(|(_, &k)| k == want).map(|(&v, _)| v))
    };
    fitness
        .iter()
        .map(|f| PriorSummary {
            name: f.prior.name(),
            applies_to,
            mean_fitness: mean(f.values.iter().copied()),
            mean_fitness_selected: mean_where(&f.values, true),
            mean_fitness_removed: mean_where(&f.values, false),
        })
        .collect()
}

impl OrderReport {
    /// The order `plan` followed and how sequential its selection is in it.
    fn new(plan: &Plan, parameters: &Parameters) -> OrderReport {
        let order = &plan.order;
        let window = crate::selection::capture_order::SEQUENTIAL_WINDOW;
        let share = |kept: Option<&[bool]>| {
            let edges = plan.graph.edges.iter().enumerate();
            order.share_within(
                edges
                    .filter(|(k, _)| kept.is_none_or(|kept| kept[*k]))
                    .map(|(_, e)| (e.i, e.j)),
                window,
            )
        };
        OrderReport {
            name: order.order,
            selected_within_window: share(Some(&plan.search.selection.pairs)),
            view_graph_within_window: share(None),
            window,
            images_without_time: order.images_without_time,
            sequence_window: parameters.capture.sequence_window,
            keep_neighbours: parameters.arc_rules.keep_neighbours,
            neighbours_kept: plan.neighbours_kept,
        }
    }
}

/// Mean of the values that are numbers: a NaN fitness means the prior does not apply to that item
/// (no triangle, no second motion), and the cost leaves it out too. No items: 0; items but none
/// the prior applies to: NaN (null in the JSON).
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut n, mut items) = (0.0, 0usize, 0usize);
    for v in values {
        items += 1;
        if !v.is_nan() {
            sum += v;
            n += 1;
        }
    }
    match (items, n) {
        (0, _) => 0.0,
        (_, 0) => f64::NAN,
        _ => sum / n as f64,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn means_leave_out_priors_that_do_not_apply() {
        assert_eq!(super::mean([0.5, f64::NAN, 1.0].into_iter()), 0.75);
        assert!(super::mean([f64::NAN].into_iter()).is_nan());
        assert_eq!(super::mean(std::iter::empty()), 0.0);
    }
}
