//! The prune pipeline up to the selection: read the database, build the view graph, compute the
//! priors and costs, run the flow search. It writes nothing; [`crate::colmap::rewrite`] applies the plan.

use crate::colmap::database::{Camera, Database, Image, TwoViewGeometry, VerifiedPair};
use crate::colmap::ids::pair_id;
use crate::colmap::rewrite;
use crate::costs::{self, CostModel, Costs};
use crate::flow::connectivity::Biconnected;
use crate::flow::network::{ArcRule, PairArc, Restriction, SelectionProblem};
use crate::flow::search::{self, FlowRule, SearchResult, SelectionCheck};
use crate::geometry::camera::CameraModel;
use crate::priors::pairs::FocalEstimate;
use crate::priors::{self, Prior, PriorValues};
use crate::scene::view_graph::ViewGraph;
use crate::scene::{Scene, Sequence};
use crate::selection::capture_order::{self, CaptureOrder};
use crate::selection::overrides::{Listed, Overrides};
use crate::selection::parameters::Parameters;
use crate::selection::preset::Preset;
use crate::selection::track_completion::{self, Completion, Needs};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::collections::HashMap;
use std::time::Instant;

/// COLMAP's default `--Mapper.min_num_matches`: fewer verified inliers make no view-graph edge.
pub const DEFAULT_MIN_NUM_MATCHES: usize = 15;

/// What the pipeline runs with (built from [`crate::selection::parameters::Parameters`]).
pub struct Options {
    /// A pair is a view-graph edge when it has at least this many verified inliers.
    pub min_num_matches: usize,
    /// How the flow F is chosen: fixed, or searched against the image and pair criteria.
    pub rule: FlowRule,
    /// After a criteria search, pairs are added until every image keeps this many keypoints on
    /// feature tracks of three or more observations ([`track_completion`]); 0: off.
    pub min_track_observations: usize,
    /// ... after adding this many maximum spanning forests by inliers ...
    pub spanning_forests: usize,
    /// ... and until the mean track length a keypoint sees is this share of the full graph's;
    /// 0: off.
    pub min_track_length_ratio: f64,
    /// A criteria search also keeps the selection free of cut images ([`Biconnected`]).
    pub biconnected: bool,
    /// The priors, their g and weights, and the fitness floor that make the arc costs.
    pub model: CostModel,
    /// Also compute the model's priors of weight 0 (they do not change the costs): for
    /// `--scores`. Otherwise they are skipped, which matters at scale (multiple motions run a
    /// RANSAC per pair).
    pub unweighted_priors: bool,
    /// Continue the selection curve to this many times the chosen F (0: stop there), for plots.
    pub curve_factor: u64,
    /// The order the network's pair arcs follow.
    pub capture: capture_order::Input,
}

/// Seconds spent in each stage.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timings {
    /// Reading the database and loading the scene.
    pub read: f64,
    /// Computing the priors and costs.
    pub priors: f64,
    /// The flow search.
    pub solve: f64,
    /// Rewriting the database; 0 in the plan, set by `prune` after it writes.
    pub write: f64,
    /// Wall time of the whole run so far (the plan's stages, plus `write` once written).
    pub total: f64,
}

/// Everything decided before writing.
pub struct Plan {
    /// Every image of the database, by image_id.
    pub images: Vec<Image>,
    /// Every verified pair as originally verified, including those below `min_num_matches`.
    pub pairs: Vec<VerifiedPair>,
    /// The view graph of `pairs`; its vertex and edge order index the priors, costs and search.
    pub graph: ViewGraph,
    /// Raw prior values, indexed like the graph's vertices (image priors) or edges (pair priors).
    pub image_priors: Vec<PriorValues>,
    /// Raw pair prior values, one per edge (only the priors computed; see `unweighted_priors`).
    pub pair_priors: Vec<PriorValues>,
    /// Arc costs and each prior's fitness, from `image_priors` and `pair_priors`.
    pub costs: Costs,
    /// Focal lengths estimated where the database had only a guess.
    pub focal_estimates: Vec<FocalEstimate>,
    /// The network the flow ran on (the view graph less the overrides' arcs).
    pub network: Restriction,
    /// The overrides applied, by name, for the report.
    pub overrides: Listed,
    /// View-graph pairs kept as close neighbours in the order (`--keep_neighbours`), besides
    /// the listed ones.
    pub neighbours_kept: usize,
    /// The order the pair arcs followed.
    pub order: CaptureOrder,
    /// On the whole view graph (kept pairs included); its criteria and curve are the network's.
    /// Its selection includes the pairs the track completion added.
    pub search: SearchResult,
    /// What the track completion added to the flow's selection (None when it did not run).
    pub completion: Option<Completion>,
    /// The fitness floor applied (see [`fitness_floor`]).
    pub fitness_floor: f64,
    /// Free edges (neither kept nor forbidden) below `fitness_floor`, taken out of the network.
    pub below_fitness_floor: usize,
    /// pair_ids of the view-graph edges the selection leaves out.
    pub invalidate: Vec<u64>,
    /// Seconds per stage, for the report.
    pub timings: Timings,
    /// The database's [`Database::data_version`] before anything was read: the write refuses a
    /// database another program changed since.
    pub data_version: i64,
}

impl Plan {
    /// The selected edges' verified pairs.
    pub fn selected_pairs(&self) -> Vec<VerifiedPair> {
        self.graph
            .edges
            .iter()
            .zip(&self.search.selection.pairs)
            .filter(|(_, &kept)| kept)
            .map(|(e, _)| self.pairs[e.pair].clone())
            .collect()
    }
}

/// Reads the database and decides the selection. `stage` is told the name of each long step.
pub fn plan(db: &Database, options: &Options, stage: &dyn Fn(&str)) -> Result<Plan> {
    plan_with(db, options, &Overrides::default(), stage)
}

/// The plan of the database's last prune, recomputed from its recorded parameters (the general
/// preset's when it was never pruned), without running a flow: its priors and costs are the ones
/// that drove that selection. Which pairs were kept is the database's to say
/// ([`crate::colmap::database::Database::invalidated_pair_ids`]).
pub fn last_plan(db: &Database, stage: &dyn Fn(&str)) -> Result<Plan> {
    let parameters = match rewrite::last_run::<Parameters>(db)? {
        Some(row) => row.run.parameters,
        None => Parameters::of_preset(Preset::General, DEFAULT_MIN_NUM_MATCHES),
    };
    // No flow runs, so the order, which only orients the arcs, is image_id's: it needs no image
    // files (an EXIF order would). Unless a sequence window made the order shape the backbone
    // and so the costs: then it is the recorded one.
    let recorded = parameters.options(true);
    let capture = match recorded.capture.sequence_window {
        0 => Default::default(),
        _ => recorded.capture.clone(),
    };
    let options = Options {
        rule: FlowRule::Fixed(0),
        capture,
        ..recorded
    };
    plan_with(db, &options, &Overrides::default(), stage)
}

/// [`plan`] honouring user overrides (see [`crate::selection::overrides`]).
pub fn plan_with(
    db: &Database,
    options: &Options,
    overrides: &Overrides,
    stage: &dyn Fn(&str),
) -> Result<Plan> {
    let started = Instant::now();
    let mut timings = Timings::default();

    stage("reading images and verified pairs");
    let data_version = db.data_version()?;
    let images = db.images()?;
    let cameras = db.cameras()?;
    let pairs = db.verified_pairs()?;
    if pairs.is_empty() {
        bail!("no verified image pairs in two_view_geometries: run a COLMAP matcher first");
    }
    let graph = ViewGraph::build(&images, &pairs, options.min_num_matches);
    if graph.edges.is_empty() {
        bail!(
            "no image pair has at least {} verified inliers (min_num_matches)",
            options.min_num_matches
        );
    }
    let mut resolved = overrides.resolve(&images, &graph, options.min_num_matches)?;
    let names = options
        .model
        .pair_priors_to_compute(options.unweighted_priors);
    let mut scene = load_scene(db, &graph, &pairs, &images, cameras, &names, stage)?;
    let order = capture_order::compute(&options.capture, &graph, &images, &pairs)?;
    let neighbours_kept = keep_neighbours(
        &mut resolved.edges,
        &graph,
        &order,
        options.capture.keep_neighbours,
    );
    let window = options.capture.sequence_window;
    scene.sequence = (window > 0).then(|| Sequence {
        rank: order.rank.clone(),
        window,
    });
    timings.read = started.elapsed().as_secs_f64();

    stage("computing priors");
    let t = Instant::now();
    let image_priors = priors::general_image_priors(&scene);
    let pair_priors = priors::pairs::compute(&scene, &names, stage)?;
    let costs = costs::compute(&options.model, &image_priors, &pair_priors.values);
    timings.priors = t.elapsed().as_secs_f64();

    stage("solving the min-cost flow selection");
    let t = Instant::now();
    let floor = fitness_floor(options, &graph, &costs.pair_costs);
    let mut below_fitness_floor = 0;
    for (rule, cost) in resolved.edges.iter_mut().zip(&costs.pair_costs) {
        if *rule == ArcRule::Free && -cost < floor {
            *rule = ArcRule::Removed;
            below_fitness_floor += 1;
        }
    }
    let network = problem(&graph, &costs, &order).restrict(
        &order.by_rank(&resolved.forbidden_vertices),
        &resolved.edges,
    );
    let searched = matches!(options.rule, FlowRule::Criteria(_));
    let biconnected = (searched && options.biconnected).then(|| Biconnected::new(&network.problem));
    let mut checks: Vec<&dyn SelectionCheck> = Vec::new();
    if let Some(b) = &biconnected {
        checks.push(b);
    }
    let mut search = search::search_with_curve(
        &network.problem,
        &options.rule,
        options.curve_factor,
        &checks,
    );
    search.selection = network.expand(&search.selection);
    search.selection.images = order.by_vertex(&search.selection.images);
    let needs = Needs {
        spanning_forests: options.spanning_forests,
        min_track_observations: options.min_track_observations,
        min_track_length_ratio: options.min_track_length_ratio,
    };
    // A capped search kept everything already.
    let completion = (searched && !search.capped && needs.any()).then(|| {
        stage("completing feature tracks");
        let done =
            track_completion::complete(&scene, &network, &mut search.selection.pairs, &needs);
        for (e, _) in graph
            .edges
            .iter()
            .zip(&search.selection.pairs)
            .filter(|(_, &k)| k)
        {
            search.selection.images[e.i as usize] = true;
            search.selection.images[e.j as usize] = true;
        }
        done
    });
    timings.solve = t.elapsed().as_secs_f64();

    let invalidate = graph
        .edges
        .iter()
        .zip(&search.selection.pairs)
        .filter(|(_, &kept)| !kept)
        .map(|(e, _)| pair_id(pairs[e.pair].image_id1, pairs[e.pair].image_id2))
        .collect();
    timings.total = started.elapsed().as_secs_f64();
    Ok(Plan {
        images,
        pairs,
        graph,
        image_priors,
        pair_priors: pair_priors.values,
        focal_estimates: pair_priors.focal_estimates,
        costs,
        network,
        overrides: resolved.listed,
        neighbours_kept,
        order,
        search,
        completion,
        fitness_floor: floor,
        below_fitness_floor,
        invalidate,
        timings,
        data_version,
    })
}

/// Fixes every free edge whose images are at most `window` positions apart in `order`, so the
/// pair is kept whatever the flow selects; forbidden pairs stay forbidden. Returns how many.
/// Why: in a capture known to be a sequence, close neighbours see the same things, so their
/// verified pairs are true, and keeping them all gives a walk between look-alike objects the
/// redundancy a mapper needs to cross it in one piece (docs/cli.md).
fn keep_neighbours(
    rules: &mut [ArcRule],
    graph: &ViewGraph,
    order: &CaptureOrder,
    window: u32,
) -> usize {
    if window == 0 {
        return 0;
    }
    let mut kept = 0;
    for (rule, e) in rules.iter_mut().zip(&graph.edges) {
        if *rule == ArcRule::Free && order.within(e.i, e.j, window) {
            *rule = ArcRule::Fixed;
            kept += 1;
        }
    }
    kept
}

/// The paper's network on the whole view graph: images indexed by their position in `order`
/// (which orients the pair arcs, lower to higher), pair arcs in view-graph edge order.
fn problem(graph: &ViewGraph, costs: &Costs, order: &CaptureOrder) -> SelectionProblem {
    SelectionProblem {
        image_costs: order.by_rank(&costs.image_costs),
        pairs: graph
            .edges
            .iter()
            .zip(&costs.pair_costs)
            .map(|(e, &cost)| {
                let (a, b) = (order.rank[e.i as usize], order.rank[e.j as usize]);
                PairArc {
                    i: a.min(b),
                    j: a.max(b),
                    cost,
                }
            })
            .collect(),
    }
}

/// Reads what the priors `names` need of the database into a [`Scene`] of `graph`: keypoints
/// and image sizes always; cameras and stored geometries for the pose priors; raw matches for
/// multiple motions. The only place the priors' inputs come from the database.
fn load_scene<'a>(
    db: &Database,
    graph: &'a ViewGraph,
    pairs: &'a [VerifiedPair],
    images: &[Image],
    cameras: Vec<Camera>,
    names: &[Prior],
    stage: &dyn Fn(&str),
) -> Result<Scene<'a>> {
    let camera_of: HashMap<u32, u32> = images
        .iter()
        .map(|im| (im.image_id, im.camera_id))
        .collect();
    let camera_ids: Vec<u32> = graph.image_ids.iter().map(|id| camera_of[id]).collect();
    let sizes: HashMap<u32, (u32, u32)> = cameras
        .iter()
        .map(|c| (c.camera_id, (c.width, c.height)))
        .collect();
    let image_sizes = graph
        .image_ids
        .iter()
        .zip(&camera_ids)
        .map(|(id, camera)| {
            let (w, h) = sizes.get(camera).copied().with_context(|| {
                format!("image {id} names camera {camera}, which does not exist")
            })?;
            if w == 0 || h == 0 {
                bail!("camera {camera}: size {w} x {h} (width and height must be positive)");
            }
            Ok((w, h))
        })
        .collect::<Result<Vec<_>>>()?;
    // A camera the mapper could not use is refused whether or not the priors read it.
    for c in cameras.iter().filter(|c| camera_ids.contains(&c.camera_id)) {
        CameraModel::from_colmap(c)?;
    }
    stage("reading keypoints");
    let keypoints = graph
        .image_ids
        .iter()
        .map(|&id| db.keypoints_xy(id))
        .collect::<Result<Vec<_>>>()?;
    let mut scene = Scene::new(graph, pairs, keypoints, image_sizes);
    let needs = priors::pairs::needs(names);
    if needs.geometry {
        scene.cameras = cameras
            .into_iter()
            .filter(|c| camera_ids.contains(&c.camera_id))
            .collect();
        let mut stored: HashMap<(u32, u32), TwoViewGeometry> = db
            .geometries()?
            .into_iter()
            .map(|g| ((g.image_id1, g.image_id2), g))
            .collect();
        scene.geometries = graph
            .edges
            .iter()
            .map(|e| stored.remove(&(pairs[e.pair].image_id1, pairs[e.pair].image_id2)))
            .collect();
    }
    scene.camera_ids = camera_ids;
    if needs.matches {
        stage("reading raw matches");
        scene.matches = graph
            .edges
            .iter()
            .map(|e| db.matches(graph.image_ids[e.i as usize], graph.image_ids[e.j as usize]))
            .collect::<Result<Vec<_>>>()?;
    }
    Ok(scene)
}

/// The cost model's `min_pair_fitness`, lowered where needed so that the image criterion's
/// share of images keep a pair above it, and at least half as many pairs as the pair criterion
/// asks for reach it. On scenes where the priors score every pair low (real photos where few
/// triangles close within the loop tolerance) a fixed floor left the flow too few pairs for
/// `colmap mapper` to start a model (docs/priors.md). With a fixed flow it is applied as given.
pub fn fitness_floor(options: &Options, graph: &ViewGraph, pair_costs: &[f64]) -> f64 {
    let floor = options.model.min_pair_fitness;
    let FlowRule::Criteria(criteria) = &options.rule else {
        return floor;
    };
    let n = graph.num_vertices();
    if floor <= 0.0 || n == 0 {
        return floor;
    }
    // The k-th largest of some values (k >= 1, at most their count).
    let kth = |mut values: Vec<f64>, k: usize| {
        let k = k.clamp(1, values.len());
        *values
            .select_nth_unstable_by(k - 1, |a, b| b.total_cmp(a))
            .1
    };
    // Each image's best pair fitness: the wanted-th best image sets the highest usable floor.
    let mut best = vec![0.0f64; n];
    for (e, cost) in graph.edges.iter().zip(pair_costs) {
        for v in [e.i as usize, e.j as usize] {
            best[v] = best[v].max(-cost);
        }
    }
    let images = (criteria.min_image_fraction * n as f64).ceil() as usize;
    let pairs = (criteria.min_pairs_per_image * n as f64 / 2.0).ceil() as usize;
    let fitness = pair_costs.iter().map(|c| -c).collect();
    floor.min(kth(best, images)).min(kth(fitness, pairs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flow::search::Criteria;
    use crate::scene::testing::{images, pair};

    /// The order decides what one unit of flow selects: on a triangle of equal costs the flow
    /// takes the two pairs along the order and leaves the pair that skips the middle image.
    #[test]
    fn the_network_orients_its_arcs_by_the_capture_order() {
        let images = images(3);
        let pairs: Vec<VerifiedPair> = [(1, 2), (2, 3), (1, 3)]
            .map(|(a, b)| pair(a, b, vec![[0, 0]; 50]))
            .to_vec();
        let graph = ViewGraph::build(&images, &pairs, 15);
        let costs = Costs {
            image_costs: vec![0.0; 3],
            pair_costs: vec![-1.0; 3],
            image_fitness: Vec::new(),
            pair_fitness: Vec::new(),
        };
        let skipped = |rank: Vec<u32>| {
            let order = CaptureOrder {
                order: capture_order::Order::Name,
                rank,
                images_without_time: 0,
            };
            let whole = problem(&graph, &costs, &order);
            assert!(whole.pairs.iter().all(|p| p.i < p.j));
            let selection = search::search(&whole, &FlowRule::Fixed(1)).selection;
            let left: Vec<(u32, u32)> = graph
                .edges
                .iter()
                .zip(&selection.pairs)
                .filter(|(_, &kept)| !kept)
                .map(|(e, _)| (graph.image_ids[e.i as usize], graph.image_ids[e.j as usize]))
                .collect();
            left
        };
        assert_eq!(skipped(vec![0, 1, 2]), [(1, 3)]);
        assert_eq!(skipped(vec![0, 2, 1]), [(1, 2)]);
        assert_eq!(skipped(vec![1, 0, 2]), [(2, 3)]);
    }

    #[test]
    fn the_floor_is_lowered_only_as_far_as_the_criteria_need() {
        // A path 1-2-3-4-5: pair fitnesses 0.9, 0.8, 0.2, 0.1.
        let images = images(5);
        let pairs: Vec<VerifiedPair> = (1..5).map(|a| pair(a, a + 1, vec![[0, 0]; 20])).collect();
        let graph = ViewGraph::build(&images, &pairs, 15);
        let costs = [-0.9, -0.8, -0.2, -0.1];
        let options = |fraction: f64, per_image: f64, rule: Option<u64>| Options {
            min_num_matches: 15,
            rule: match rule {
                Some(f) => FlowRule::Fixed(f),
                None => FlowRule::Criteria(Criteria {
                    min_image_fraction: fraction,
                    min_pairs_per_image: per_image,
                    min_pair_fraction: 0.0,
                    min_pairs_each: 0.0,
                }),
            },
            model: CostModel::disambiguation(),
            unweighted_priors: false,
            curve_factor: 0,
            capture: Default::default(),
            min_track_observations: 0,
            min_track_length_ratio: 0.0,
            spanning_forests: 0,
            biconnected: false,
        };
        // Best pair per image: 0.9, 0.9, 0.8, 0.2, 0.1. Three images reach the preset's floor
        // (0.6) already, and half of 0.4 pairs per image x 5 images is one pair.
        let preset = CostModel::disambiguation().min_pair_fitness;
        assert!(preset <= 0.8);
        assert_eq!(
            fitness_floor(&options(0.6, 0.4, None), &graph, &costs),
            preset
        );
        // Four images need the floor at 0.2, all five at 0.1.
        assert_eq!(fitness_floor(&options(0.8, 0.4, None), &graph, &costs), 0.2);
        assert_eq!(fitness_floor(&options(1.0, 0.4, None), &graph, &costs), 0.1);
        // Half of 1.2 pairs per image x 5 images is 3 pairs: the third best is 0.2.
        assert_eq!(fitness_floor(&options(0.6, 1.2, None), &graph, &costs), 0.2);
        // A fixed flow takes the floor as given.
        assert_eq!(
            fitness_floor(&options(1.0, 1.2, Some(3)), &graph, &costs),
            preset
        );
    }
}
