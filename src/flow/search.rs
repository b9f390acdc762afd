//! Choice of the flow F: fixed, or the smallest F whose selection meets the criteria.
//!
//! One [`ParametricSolver`] run gives the min-cost selection for F = 1, 2, ... in turn, so the
//! criteria search simply augments until the selection meets both targets: the F found is the
//! exact smallest such F (the paper doubles F and bisects, with one full solve per probe).
//!
//! Targets, with n = number of images in the problem: images selected >= ceil(A n) and pairs
//! selected >= min(max(ceil(B n), ceil(P |E|)), |E|).
//!
//! A caller may add [`SelectionCheck`]s computed from the selected pairs
//! ([`crate::connectivity::Biconnected`]); they are evaluated
//! once the other targets hold, in steps (see the trait).
//!
//! When no F meets both targets the full graph is kept (`capped`): every image and every pair
//! selected, including images without pairs. Its `flow` is |E| and its `cost` is that of the
//! feasible flow of value |E| saturating every pair arc and every image arc
//! (sum_ij c_ij + sum_i deg(i) c_i). The search stops early when the targets are provably out of
//! reach: an image without pairs can never carry flow, and since every selected pair feeds one
//! more image arc, images' flows sum to F + pairs <= 2|E|, so pairs <= 2|E| - F and no F beyond
//! 2|E| - target_pairs can meet the pair target.
//!
//! In practice a search is capped by the image criterion only: with strictly negative costs the
//! min-cost flow of value |E| is the full graph (every image arc saturated, every pair selected:
//! dropping a pair loses its cost and one image-arc unit), so the pair target min(ceil(B n), |E|)
//! is met at the latest at F = |E|; only zero costs (ties) can prevent it. Images without pairs
//! never carry flow, so A n above the number of images with pairs caps the search at once.

use crate::network::{Selection, SelectionProblem};
use crate::solver::ParametricSolver;
use serde::Serialize;

/// How F is chosen: given, or the smallest F whose selection meets the criteria.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FlowRule {
    /// This F exactly.
    Fixed(u64),
    /// The smallest F that meets these coverage criteria.
    Criteria(Criteria),
}

/// Criteria as a user may give them: any of them unset.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct GivenCriteria {
    /// See [`Criteria::min_image_fraction`].
    pub min_image_fraction: Option<f64>,
    /// See [`Criteria::min_pairs_per_image`].
    pub min_pairs_per_image: Option<f64>,
    /// See [`Criteria::min_pair_fraction`].
    pub min_pair_fraction: Option<f64>,
    /// See [`Criteria::min_pairs_each`].
    pub min_pairs_each: Option<f64>,
}

impl GivenCriteria {
    /// The criteria given, each taken from `defaults` where unset.
    pub fn or(self, defaults: Criteria) -> Criteria {
        Criteria {
            min_image_fraction: self
                .min_image_fraction
                .unwrap_or(defaults.min_image_fraction),
            min_pairs_per_image: self
                .min_pairs_per_image
                .unwrap_or(defaults.min_pairs_per_image),
            min_pair_fraction: self.min_pair_fraction.unwrap_or(defaults.min_pair_fraction),
            min_pairs_each: self.min_pairs_each.unwrap_or(defaults.min_pairs_each),
        }
    }
}

/// Coverage a selection must reach: the smallest F that reaches it is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Criteria {
    /// Selected images / images in the view graph.
    pub min_image_fraction: f64,
    /// Selected pairs >= this x images in the view graph (capped at all pairs).
    pub min_pairs_per_image: f64,
    /// ... and >= this share of all pairs: the paper's criterion for its dense lab scenes
    /// (about 25% of the edges); 0 for the others.
    pub min_pair_fraction: f64,
    /// ... and every image with a pair keeps at least min(ceil(this), its degree) selected
    /// pairs: a count per image rather than on average, so that no image is left with too few
    /// pairs to be registered while dense parts of the graph keep many (0: off).
    pub min_pairs_each: f64,
}

/// One criterion after the search: its target, what the chosen F reached, whether it was met.
#[derive(Clone, Debug, Serialize)]
pub struct CriterionStatus {
    /// Which criterion (images or pairs).
    pub name: String,
    /// Count the criterion asks for.
    pub target: f64,
    /// Count the chosen selection reaches.
    pub achieved: f64,
    /// Whether `achieved` reaches `target`.
    pub met: bool,
    /// The criterion that was met last as F grew (the one that set F).
    pub binding: bool,
}

/// The selection's size at one F, a point of the selection curve (for plots and reports).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct CurvePoint {
    /// The flow value F.
    pub flow: u64,
    /// Images selected at this F.
    pub images_selected: usize,
    /// Pairs selected at this F.
    pub pairs_selected: usize,
}

/// What the search over F found: the selection, how it met the criteria, and the curve.
#[derive(Clone, Debug)]
pub struct SearchResult {
    /// The selection at the chosen F.
    pub selection: Selection,
    /// Each criterion's status (empty for a fixed F).
    pub criteria: Vec<CriterionStatus>,
    /// True when no F met the criteria and the full graph was kept instead.
    pub capped: bool,
    /// Images and pairs selected for F = 1, 2, ... up to the chosen F.
    pub curve: Vec<CurvePoint>,
    /// The curve past the last F in `curve`, when asked for ([`search_with_curve`]).
    pub beyond: Vec<CurvePoint>,
}

/// Target counts (images, pairs) of `criteria` for `problem`.
pub fn targets(problem: &SelectionProblem, criteria: &Criteria) -> (usize, usize) {
    let n = problem.image_costs.len() as f64;
    let images = (criteria.min_image_fraction * n).ceil().max(0.0) as usize;
    let m = problem.pairs.len();
    let per_image = (criteria.min_pairs_per_image * n).ceil().max(0.0) as usize;
    let fraction = (criteria.min_pair_fraction * m as f64).ceil().max(0.0) as usize;
    let pairs = per_image.max(fraction).min(m);
    (images, pairs)
}

/// The full graph as a selection (see the module doc).
pub fn full_selection(problem: &SelectionProblem) -> Selection {
    let n = problem.image_costs.len();
    let mut deg = vec![0u64; n];
    let mut cost = 0.0;
    for p in &problem.pairs {
        deg[p.i as usize] += 1;
        deg[p.j as usize] += 1;
        cost += p.cost;
    }
    for (d, c) in deg.iter().zip(&problem.image_costs) {
        cost += *d as f64 * c;
    }
    Selection {
        flow: problem.pairs.len() as u64,
        images: vec![true; n],
        pairs: vec![true; problem.pairs.len()],
        cost,
    }
}

/// A criterion the caller computes from the selected pairs, which the network alone cannot: the
/// main crate counts each image's observations on feature tracks with it. A criteria search
/// evaluates it only once the other criteria hold, and as it may be costly (a union-find over
/// every selected pair's matches) not at every F: after a failure at F the next evaluation is at
/// F + max(1, F / 32), so the F found is at most about 3% above the smallest that meets it.
pub trait SelectionCheck {
    /// The criterion's name in reports.
    fn name(&self) -> &str;
    /// How many units (images, say) must meet it; the full graph meets all of them.
    fn target(&self) -> usize;
    /// How many meet it under this selection of the problem's pairs.
    fn achieved(&self, pairs: &[bool]) -> usize;
}

/// After a failed [`SelectionCheck`] at F, the next one is at F + F / CHECK_STEP (at least F + 1).
const CHECK_STEP: u64 = 32;

/// The per-image criterion: each image with a pair needs min(ceil(k), its degree) of its pairs
/// selected.
struct EachImage {
    /// The images of each pair, as in the problem.
    ends: Vec<(u32, u32)>,
    /// Pairs each image needs (0 for images without pairs, or when the criterion is off).
    need: Vec<u32>,
    /// Images that need any.
    target: usize,
}

impl EachImage {
    fn new(problem: &SelectionProblem, k: f64) -> EachImage {
        let mut degree = vec![0u32; problem.image_costs.len()];
        for p in &problem.pairs {
            degree[p.i as usize] += 1;
            degree[p.j as usize] += 1;
        }
        let k = k.ceil().max(0.0) as u32;
        let need: Vec<u32> = degree.iter().map(|&d| d.min(k)).collect();
        let target = need.iter().filter(|&&n| n > 0).count();
        let ends = problem.pairs.iter().map(|p| (p.i, p.j)).collect();
        EachImage { ends, need, target }
    }

    fn active(&self) -> bool {
        self.target > 0
    }

    /// Images whose need the solver's current selection meets (images without need excluded).
    fn met(&self, solver: &ParametricSolver) -> usize {
        if !self.active() {
            return 0;
        }
        let mut selected = vec![0u32; self.need.len()];
        for (k, &(i, j)) in self.ends.iter().enumerate() {
            if solver.pair_selected(k) {
                selected[i as usize] += 1;
                selected[j as usize] += 1;
            }
        }
        self.need
            .iter()
            .zip(&selected)
            .filter(|(&n, &s)| n > 0 && s >= n)
            .count()
    }
}

fn point(solver: &ParametricSolver) -> CurvePoint {
    CurvePoint {
        flow: solver.flow(),
        images_selected: solver.images_selected(),
        pairs_selected: solver.pairs_selected(),
    }
}

/// Runs `rule` on `problem`. The curve starts at F = 0 and ends at the chosen F (for a capped
/// criteria search: at the last F examined).
pub fn search(problem: &SelectionProblem, rule: &FlowRule) -> SearchResult {
    search_with_curve(problem, rule, 0, &[])
}

/// [`search`], then the same solver goes on past the chosen F to record `beyond`: up to `factor`
/// times that F (at most 2|E|), stopping once every pair is selected (`--plots` draws what more
/// flow would buy). The selection stays the chosen one. `factor` 0 records nothing more.
/// A criteria search also has to meet every one of `checks`.
pub fn search_with_curve(
    problem: &SelectionProblem,
    rule: &FlowRule,
    factor: u64,
    checks: &[&dyn SelectionCheck],
) -> SearchResult {
    let mut solver = ParametricSolver::new(problem);
    let mut result = run(&mut solver, problem, rule, checks);
    if factor > 0 {
        let end = CurveEnd::new(problem, &result, factor);
        while !end.complete(&point(&solver))
            && solver.flow() < end.limit
            && solver.augment().is_some()
        {
            result.beyond.push(point(&solver));
        }
    }
    result
}

/// Where a selection curve continued past the chosen F ends: at `factor` times that F (at most
/// 2|E|), or at the first point from the chosen F on that selects every pair.
struct CurveEnd {
    chosen: u64,
    limit: u64,
    pairs: usize,
}

impl CurveEnd {
    fn new(problem: &SelectionProblem, result: &SearchResult, factor: u64) -> CurveEnd {
        let chosen = result.selection.flow.max(1);
        CurveEnd {
            chosen,
            limit: (factor * chosen).min(2 * problem.pairs.len() as u64),
            pairs: problem.pairs.len(),
        }
    }

    fn complete(&self, p: &CurvePoint) -> bool {
        p.pairs_selected == self.pairs && p.flow >= self.chosen
    }
}

impl SearchResult {
    /// The curve from F = 1 to where [`search_with_curve`] with `factor` stops it (the recorded
    /// curve and `beyond`, cut there: a capped search may have examined more).
    pub fn curve_to(&self, problem: &SelectionProblem, factor: u64) -> Vec<CurvePoint> {
        let end = CurveEnd::new(problem, self, factor);
        let mut points = Vec::new();
        for p in self.curve.iter().chain(&self.beyond) {
            if p.flow == 0 {
                continue;
            }
            if p.flow > end.limit {
                break;
            }
            points.push(*p);
            if end.complete(p) {
                break;
            }
        }
        points
    }
}

/// Runs `rule` on a fresh `solver` of `problem`: augments to the fixed F, or until every
/// criterion and every one of `checks` holds.
fn run(
    solver: &mut ParametricSolver,
    problem: &SelectionProblem,
    rule: &FlowRule,
    checks: &[&dyn SelectionCheck],
) -> SearchResult {
    match *rule {
        FlowRule::Fixed(f) => run_fixed(solver, f),
        FlowRule::Criteria(criteria) => {
            let goal = Goal::new(problem, &criteria);
            let walk = walk_to_goal(solver, problem, &goal, checks);
            match walk.found {
                Some(p) => met(solver, &goal, checks, walk, p),
                None => capped(problem, &goal, checks, walk),
            }
        }
    }
}

/// Augments to `f` (or as far as the network allows) and selects there.
fn run_fixed(solver: &mut ParametricSolver, f: u64) -> SearchResult {
    let mut curve = vec![point(solver)];
    while solver.flow() < f && solver.augment().is_some() {
        curve.push(point(solver));
    }
    SearchResult {
        selection: solver.selection(),
        criteria: Vec::new(),
        capped: false,
        curve,
        beyond: Vec::new(),
    }
}

/// What a criteria search must reach: the image and pair targets ([`targets`]) and each image's
/// pairs.
struct Goal {
    /// Images to select.
    images: usize,
    /// Pairs to select.
    pairs: usize,
    /// The per-image criterion.
    each: EachImage,
}

impl Goal {
    fn new(problem: &SelectionProblem, criteria: &Criteria) -> Goal {
        let (images, pairs) = targets(problem, criteria);
        let each = EachImage::new(problem, criteria.min_pairs_each);
        Goal {
            images,
            pairs,
            each,
        }
    }
}

/// What the walk over F saw: the curve, the point where everything held, and what each criterion
/// did on the way (which decides the ones that were binding).
struct Walk {
    /// Images and pairs selected at each F examined, from F = 0.
    curve: Vec<CurvePoint>,
    /// The first point where every criterion and check held; none if the search is capped.
    found: Option<CurvePoint>,
    /// What held at the F before the one examined: images, pairs, each image's pairs.
    prev: (bool, bool, bool),
    /// Whether the image and the pair target were met at any F examined.
    ever: (bool, bool),
    /// For each of the caller's checks, whether it ever failed.
    check_failed: Vec<bool>,
    /// For each of the caller's checks, what it achieved at its last evaluation.
    check_achieved: Vec<usize>,
}

impl Walk {
    /// Evaluates `checks` on the solver's current selection and records what each achieved;
    /// true when all of them hold.
    fn evaluate(&mut self, solver: &ParametricSolver, checks: &[&dyn SelectionCheck]) -> bool {
        let selected = if checks.is_empty() {
            Vec::new()
        } else {
            solver.selection().pairs
        };
        let mut all = true;
        for (k, c) in checks.iter().enumerate() {
            self.check_achieved[k] = c.achieved(&selected);
            if self.check_achieved[k] < c.target() {
                self.check_failed[k] = true;
                all = false;
            }
        }
        all
    }
}

/// Images that have a pair: the only ones that can ever carry flow.
fn reachable_images(problem: &SelectionProblem) -> usize {
    let mut has_pair = vec![false; problem.image_costs.len()];
    for p in &problem.pairs {
        has_pair[p.i as usize] = true;
        has_pair[p.j as usize] = true;
    }
    has_pair.iter().filter(|&&b| b).count()
}

/// Augments F = 0, 1, ... until `goal` and `checks` hold at F, or up to where the pair target is
/// out of reach (see the module doc); the checks only once the rest holds, and not at every F
/// ([`SelectionCheck`]).
fn walk_to_goal(
    solver: &mut ParametricSolver,
    problem: &SelectionProblem,
    goal: &Goal,
    checks: &[&dyn SelectionCheck],
) -> Walk {
    let mut walk = Walk {
        curve: vec![point(solver)],
        found: None,
        prev: (false, false, false),
        ever: (false, false),
        check_failed: vec![false; checks.len()],
        check_achieved: vec![0usize; checks.len()],
    };
    if goal.images > reachable_images(problem) {
        // Out of reach from the start: only the image criterion is to blame.
        walk.ever = (false, true);
        return walk;
    }
    // Beyond this F the pair target is out of reach (pairs <= 2|E| - F).
    let last_useful = 2 * problem.pairs.len() as u64 - goal.pairs as u64;
    // The F from which the caller's checks are next evaluated.
    let mut next_check = 0u64;
    loop {
        let p = *walk.curve.last().unwrap();
        let images = p.images_selected >= goal.images;
        let pairs = p.pairs_selected >= goal.pairs;
        walk.ever = (walk.ever.0 || images, walk.ever.1 || pairs);
        // The per-selection criteria are counted only once the cheap ones hold.
        let each_ok = images && pairs && goal.each.met(solver) == goal.each.target;
        if each_ok && p.flow >= next_check {
            if walk.evaluate(solver, checks) {
                walk.found = Some(p);
                break;
            }
            next_check = p.flow + (p.flow / CHECK_STEP).max(1);
        }
        walk.prev = (images, pairs, each_ok);
        if solver.flow() >= last_useful || solver.augment().is_none() {
            break;
        }
        walk.curve.push(point(solver));
    }
    walk
}

/// One criterion's status.
fn status(name: &str, target: usize, achieved: usize, binding: bool) -> CriterionStatus {
    CriterionStatus {
        name: name.to_string(),
        target: target as f64,
        achieved: achieved as f64,
        met: achieved >= target,
        binding,
    }
}

/// The result where every criterion held, at `p`: the solver's selection there.
fn met(
    solver: &ParametricSolver,
    goal: &Goal,
    checks: &[&dyn SelectionCheck],
    walk: Walk,
    p: CurvePoint,
) -> SearchResult {
    let (prev, each) = (walk.prev, &goal.each);
    // Binding: not met at F - 1 (none at F = 0, where nothing was needed).
    let first = p.flow == 0;
    let mut criteria = vec![
        status("images", goal.images, p.images_selected, !first && !prev.0),
        status("pairs", goal.pairs, p.pairs_selected, !first && !prev.1),
    ];
    if each.active() {
        // Binding when the others held at F - 1 and it did not.
        let binding = !first && prev.0 && prev.1 && !prev.2;
        criteria.push(status("pairs_each", each.target, each.met(solver), binding));
    }
    for (k, c) in checks.iter().enumerate() {
        // Binding when the others held at F - 1 and it had failed before.
        let binding = !first && prev.2 && walk.check_failed[k];
        criteria.push(status(
            c.name(),
            c.target(),
            walk.check_achieved[k],
            binding,
        ));
    }
    SearchResult {
        selection: solver.selection(),
        criteria,
        capped: false,
        curve: walk.curve,
        beyond: Vec::new(),
    }
}

/// The result where no F met the criteria: the full graph.
fn capped(
    problem: &SelectionProblem,
    goal: &Goal,
    checks: &[&dyn SelectionCheck],
    walk: Walk,
) -> SearchResult {
    let ever = walk.ever;
    // Binding: the criteria never met at any F examined; both if each was met at some F but
    // never together.
    let both = ever.0 && ever.1;
    let mut criteria = vec![
        status(
            "images",
            goal.images,
            problem.image_costs.len(),
            both || !ever.0,
        ),
        status("pairs", goal.pairs, problem.pairs.len(), both || !ever.1),
    ];
    if goal.each.active() {
        criteria.push(status(
            "pairs_each",
            goal.each.target,
            goal.each.target,
            false,
        ));
    }
    for (k, c) in checks.iter().enumerate() {
        // The full graph meets it (a check's contract); binding when it failed.
        criteria.push(status(
            c.name(),
            c.target(),
            c.target(),
            walk.check_failed[k],
        ));
    }
    SearchResult {
        selection: full_selection(problem),
        criteria,
        capped: true,
        curve: walk.curve,
        beyond: Vec::new(),
    }
}
