//! The prune pipeline up to the selection, in six stages: (1) load what the database holds and
//! the priors need, (2) compute the priors, (3) turn them into costs, (4) apply the arc rules
//! (overrides, close neighbours, the fitness floor), (5) search the flow, (6) complete the
//! feature tracks. [`plan`] runs them in that order; it writes nothing:
//! [`crate::colmap::rewrite`] applies the plan.

use crate::colmap::database::{Camera, Database, Image, TwoViewGeometry, VerifiedPair};
use crate::colmap::ids::pair_id;
use crate::colmap::rewrite::{self, Edits, Trim};
use crate::costs::{self, Costs};
use crate::flow::connectivity::Biconnected;
use crate::flow::network::{PairArc, Restriction, SelectionProblem};
use crate::flow::search::{self, SearchResult, SelectionCheck};
use crate::geometry::camera::CameraModel;
use crate::priors::pairs::FocalEstimate;
use crate::priors::{self, Prior, PriorValues};
use crate::scene::view_graph::ViewGraph;
use crate::scene::{Scene, Sequence};
use crate::selection::arc_rules::{self, ArcRules, Listed, Overrides, Resolved, ZeroFitness};
use crate::selection::capture_order::{self, CaptureOrder};
use crate::selection::parameters::{Flow, Parameters};
use crate::selection::preset::Preset;
use crate::selection::track_completion::{self, Completion};
use anyhow::{bail, Context, Result};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::time::Instant;

/// What the outputs want of a plan beyond the selection.
#[derive(Clone, Copy, Debug, Default)]
pub struct Extras {
    /// Also compute the cost model's priors of weight 0 (they do not change the costs): for
    /// `--scores` and `export`. Otherwise they are skipped, which matters at scale (multiple
    /// motions run a RANSAC per pair).
    pub unweighted_priors: bool,
    /// Continue the selection curve to this many times the chosen F (0: stop there), for plots.
    pub curve_factor: u64,
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
    /// The fitness floor applied (see [`arc_rules::fitness_floor`]).
    pub fitness_floor: f64,
    /// Free edges (neither kept nor forbidden) below `fitness_floor`, taken out of the network.
    pub below_fitness_floor: usize,
    /// Edges the network offers whose `backbone_tracks` share is below the cost model's
    /// `min_backbone_tracks`: the track completion's forests and image need pass over them.
    pub below_backbone_tracks: usize,
    /// What the write does: the view-graph edges the selection leaves out are invalidated.
    pub edits: Edits,
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

/// Reads the database and decides the selection with `parameters`, honouring the user's
/// `overrides` (read from the files `parameters.arc_rules` names). `stage` is told the name of
/// each long step.
pub fn plan(
    db: &Database,
    parameters: &Parameters,
    overrides: &Overrides,
    extras: Extras,
    stage: &dyn Fn(&str),
) -> Result<Plan> {
    let started = Instant::now();
    let mut timings = Timings::default();

    // 1. Load: the view graph, the overrides' names checked against it, the capture order, and
    //    what the priors read.
    stage("reading images and verified pairs");
    let data_version = db.data_version()?;
    let Read {
        images,
        cameras,
        pairs,
        graph,
    } = read(db, parameters.min_num_matches)?;
    let rules = overrides.resolve(&images, &graph, parameters.min_num_matches)?;
    let to_compute = (parameters.cost_model).pair_priors_to_compute(extras.unweighted_priors);
    let mut scene = load_scene(db, &graph, &pairs, &images, cameras, &to_compute, stage)?;
    let order = capture_order::compute(&parameters.capture, &graph, &images, &pairs)?;
    let window = parameters.capture.sequence_window;
    scene.sequence = (window > 0).then(|| Sequence {
        rank: order.rank.clone(),
        window,
    });
    timings.read = started.elapsed().as_secs_f64();

    // 2. Priors, and 3. costs.
    stage("computing priors");
    let t = Instant::now();
    let image_priors = priors::general_image_priors(&scene);
    let pair_priors = priors::pairs::compute(&scene, &to_compute, stage)?;
    let costs = costs::compute(&parameters.cost_model, &image_priors, &pair_priors.values);
    timings.priors = t.elapsed().as_secs_f64();

    // 4. Arc rules: close neighbours kept, pairs below the floor removed, below the gate marked.
    stage("solving the min-cost flow selection");
    let t = Instant::now();
    let ruled = apply_arc_rules(parameters, &rules, &graph, &costs, &order);

    // 5. The flow search, and 6. the track completion.
    let mut search = search_flow(
        &ruled.network,
        &parameters.flow,
        extras.curve_factor,
        &order,
    );
    let completion = complete_tracks(&scene, &ruled, &mut search, &parameters.flow, stage);
    timings.solve = t.elapsed().as_secs_f64();

    // 7. The edits: pairs left out invalidated, kept ones trimmed of what `--model` drops.
    let kept = &search.selection.pairs;
    let edits = edits(&graph, &pairs, kept, &rules.dropped);
    timings.total = started.elapsed().as_secs_f64();
    Ok(Plan {
        images,
        pairs,
        graph,
        image_priors,
        pair_priors: pair_priors.values,
        focal_estimates: pair_priors.focal_estimates,
        costs,
        network: ruled.network,
        overrides: rules.listed,
        neighbours_kept: ruled.neighbours_kept,
        order,
        search,
        completion,
        fitness_floor: ruled.fitness_floor,
        below_fitness_floor: ruled.below_fitness_floor,
        below_backbone_tracks: ruled.uncorroborated.iter().filter(|&&u| u).count(),
        edits,
        timings,
        data_version,
    })
}

/// The plan of the database's last prune, recomputed from its recorded parameters (the general
/// preset's when it was never pruned), without running a flow: its priors and costs are the ones
/// that drove that selection. Which pairs were kept is the database's to say
/// ([`crate::colmap::database::Database::invalidated_pair_ids`]).
pub fn last_plan(db: &Database, stage: &dyn Fn(&str)) -> Result<Plan> {
    let recorded = match rewrite::last_run::<Parameters>(db)? {
        Some(row) => row.run.parameters,
        None => Parameters::of_preset(Preset::General),
    };
    // No flow runs, so the order, which only orients the arcs, is image_id's: it needs no image
    // files (an EXIF order would). Unless a sequence window made the order shape the backbone
    // and so the costs: then it is the recorded one, with its close neighbours.
    let sequence = recorded.capture.sequence_window > 0;
    let parameters = Parameters {
        flow: Flow::Fixed(0),
        capture: if sequence {
            recorded.capture.clone()
        } else {
            Default::default()
        },
        arc_rules: ArcRules {
            keep_neighbours: if sequence {
                recorded.arc_rules.keep_neighbours
            } else {
                0
            },
            ..ArcRules::default()
        },
        ..recorded
    };
    let extras = Extras {
        unweighted_priors: true,
        curve_factor: 0,
    };
    plan(db, &parameters, &Overrides::default(), extras, stage)
}

/// What [`read`] returns: the database's images, cameras and verified pairs, and their view
/// graph.
struct Read {
    images: Vec<Image>,
    cameras: Vec<Camera>,
    pairs: Vec<VerifiedPair>,
    graph: ViewGraph,
}

/// Stage 1's first step: the rows every prune needs, and the view graph of pairs with at least
/// `min_num_matches` inliers; refuses a database without one.
fn read(db: &Database, min_num_matches: usize) -> Result<Read> {
    let images = db.images()?;
    let cameras = db.cameras()?;
    let pairs = db.verified_pairs()?;
    if pairs.is_empty() {
        bail!("no verified image pairs in two_view_geometries: run a COLMAP matcher first");
    }
    let graph = ViewGraph::build(&images, &pairs, min_num_matches);
    if graph.edges.is_empty() {
        bail!("no image pair has at least {min_num_matches} verified inliers (min_num_matches)");
    }
    Ok(Read {
        images,
        cameras,
        pairs,
        graph,
    })
}

/// What stage 4 made of the view graph: the network the flow runs on, and what the rules did.
struct Ruled {
    network: Restriction,
    neighbours_kept: usize,
    fitness_floor: f64,
    below_fitness_floor: usize,
    /// Per view-graph edge: one the network offers whose `backbone_tracks` share is below the
    /// cost model's `min_backbone_tracks`; the completion's forests and image need pass over it.
    uncorroborated: Vec<bool>,
}

/// Stage 4: to the overrides' rules, adds the close neighbours kept and the pairs below the
/// fitness floor, restricts the paper's network by them, and marks the pairs it offers that
/// the backbone-tracks gate leaves to the flow and the track-length need.
fn apply_arc_rules(
    parameters: &Parameters,
    overrides: &Resolved,
    graph: &ViewGraph,
    costs: &Costs,
    order: &CaptureOrder,
) -> Ruled {
    let mut edges = overrides.edges.clone();
    let window = parameters.arc_rules.keep_neighbours;
    let neighbours_kept = arc_rules::keep_neighbours(&mut edges, graph, order, window);
    let model = &parameters.cost_model;
    let rule = parameters.flow.rule();
    let zero = match parameters.arc_rules.model.is_empty() {
        true => ZeroFitness::Out,
        false => ZeroFitness::In,
    };
    let floor = arc_rules::fitness_floor(
        model.min_pair_fitness,
        &rule,
        graph,
        &edges,
        &costs.pair_costs,
        zero,
    );
    let fitness = costs.pair_costs.iter().map(|c| -c);
    let below_fitness_floor = arc_rules::remove_below(&mut edges, fitness, floor);
    let network = problem(graph, costs, order)
        .restrict(&order.by_rank(&overrides.forbidden_vertices), &edges);
    let uncorroborated = uncorroborated(&network, costs, model.min_backbone_tracks);
    Ruled {
        network,
        neighbours_kept,
        fitness_floor: floor,
        below_fitness_floor,
        uncorroborated,
    }
}

/// Per view-graph edge: one `network` offers whose `backbone_tracks` share is below `gate`
/// (none with the gate at 0).
fn uncorroborated(network: &Restriction, costs: &Costs, gate: f64) -> Vec<bool> {
    let selectable = network.expand_pairs(&vec![true; network.problem.pairs.len()]);
    let share = (costs.pair_fitness.iter()).find(|p| p.prior == Prior::BackboneTracks);
    match share {
        Some(share) if gate > 0.0 => (selectable.iter().zip(&share.values))
            .map(|(&s, &v)| s && v < gate)
            .collect(),
        _ => vec![false; selectable.len()],
    }
}

/// Stage 7: what the write does. The view-graph edges the selection leaves out are
/// invalidated; a kept pair with matches `--model` drops is trimmed to the rest of its inliers
/// (below `--min_num_matches` the mapper passes it over, as any pair that weak).
fn edits(
    graph: &ViewGraph,
    pairs: &[VerifiedPair],
    kept: &[bool],
    dropped: &BTreeMap<usize, BTreeSet<[u32; 2]>>,
) -> Edits {
    let mut edits = Edits::default();
    for (k, (e, &kept)) in graph.edges.iter().zip(kept).enumerate() {
        let pair = &pairs[e.pair];
        let id = pair_id(pair.image_id1, pair.image_id2);
        if !kept {
            edits.invalidate.push(id);
        } else if let Some(d) = dropped.get(&k) {
            let inliers: Vec<[u32; 2]> = (pair.inliers.iter())
                .filter(|m| !d.contains(*m))
                .copied()
                .collect();
            if inliers.len() < pair.inliers.len() {
                edits.trim.push(Trim {
                    pair_id: id,
                    inliers,
                });
            }
        }
    }
    edits
}

/// Stage 5: the flow search on the network, its selection mapped back to the whole view graph
/// (kept pairs added, images by vertex).
fn search_flow(
    network: &Restriction,
    flow: &Flow,
    curve_factor: u64,
    order: &CaptureOrder,
) -> SearchResult {
    let biconnected = match flow {
        Flow::Searched(s) if s.biconnected => Some(Biconnected::new(&network.problem)),
        _ => None,
    };
    let mut checks: Vec<&dyn SelectionCheck> = Vec::new();
    if let Some(b) = &biconnected {
        checks.push(b);
    }
    let mut search =
        search::search_with_curve(&network.problem, &flow.rule(), curve_factor, &checks);
    search.selection = network.expand(&search.selection);
    search.selection.images = order.by_vertex(&search.selection.images);
    search
}

/// Stage 6: after a search, the track completion adds the pairs the feature tracks need (none
/// after a fixed flow, or a capped search, which kept everything already); its forests and
/// image need pass over the pairs below the backbone-tracks gate.
fn complete_tracks(
    scene: &Scene,
    ruled: &Ruled,
    search: &mut SearchResult,
    flow: &Flow,
    stage: &dyn Fn(&str),
) -> Option<Completion> {
    let Flow::Searched(settings) = flow else {
        return None;
    };
    if search.capped || !settings.completion.any() {
        return None;
    }
    stage("completing feature tracks");
    let selection = &mut search.selection;
    let done = track_completion::complete(
        scene,
        &ruled.network,
        &ruled.uncorroborated,
        &mut selection.pairs,
        &settings.completion,
    );
    let edges = scene.graph.edges.iter();
    for (e, _) in edges.zip(&selection.pairs).filter(|(_, &k)| k) {
        selection.images[e.i as usize] = true;
        selection.images[e.j as usize] = true;
    }
    Some(done)
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
    priors_to_compute: &[Prior],
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
    let needs = priors::pairs::needs(priors_to_compute);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flow::search::FlowRule;
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

    /// A pair left out is invalidated whatever `--model` drops; a kept one is trimmed to the
    /// inliers not dropped (their order kept), however few are left; a kept pair with none of
    /// its inliers dropped is not touched.
    #[test]
    fn kept_pairs_are_trimmed_of_the_dropped_matches() {
        let images = images(4);
        let inliers: Vec<[u32; 2]> = (0..20).map(|k| [k, 100 + k]).collect();
        let pairs: Vec<VerifiedPair> = [(1, 2), (2, 3), (3, 4), (1, 4)]
            .map(|(a, b)| pair(a, b, inliers.clone()))
            .to_vec();
        let graph = ViewGraph::build(&images, &pairs, 15);
        let edge = |a: u32, b: u32| {
            let e = graph.edges.iter().position(|e| {
                let ids = |x: u32| graph.image_ids[x as usize];
                (ids(e.i), ids(e.j)) == (a, b)
            });
            e.unwrap()
        };
        let dropped: BTreeMap<usize, BTreeSet<[u32; 2]>> = [
            (edge(1, 2), [[3, 103], [5, 105], [5, 999]].into()),
            (edge(2, 3), inliers[..6].iter().copied().collect()),
            (edge(1, 4), [[0, 100]].into()),
        ]
        .into();
        let mut kept = vec![true; 4];
        kept[edge(1, 4)] = false;
        let e = edits(&graph, &pairs, &kept, &dropped);
        let id = |a, b| pair_id(a, b);
        assert_eq!(e.invalidate, [id(1, 4)]);
        let left = |gone: &dyn Fn(u32) -> bool| -> Vec<[u32; 2]> {
            inliers.iter().filter(|m| !gone(m[0])).copied().collect()
        };
        let trim = |a, b, inliers| Trim {
            pair_id: id(a, b),
            inliers,
        };
        assert_eq!(
            e.trim,
            [
                trim(1, 2, left(&|k| k == 3 || k == 5)),
                trim(2, 3, left(&|k| k < 6))
            ]
        );
    }
}
