//! Flow search: exact smallest F meeting the criteria, capped fallback, fixed F, degenerate input.

use vgsel_colmap::flow::connectivity::{is_biconnected, Biconnected};
use vgsel_colmap::flow::network::{Selection, SelectionProblem};
use vgsel_colmap::flow::search::{
    search, search_with_curve, targets, Criteria, FlowRule, SearchResult, SelectionCheck,
};
use vgsel_colmap::flow::solver::{solve, ParametricSolver};

fn random_problem(n: usize, m: usize, seed: u64) -> SelectionProblem {
    crate::support::random_problem(n, m, seed, false)
}

fn counts(s: &Selection) -> (usize, usize) {
    (
        s.images.iter().filter(|&&b| b).count(),
        s.pairs.iter().filter(|&&b| b).count(),
    )
}

fn criteria(a: f64, b: f64) -> FlowRule {
    FlowRule::Criteria(Criteria {
        min_image_fraction: a,
        min_pairs_per_image: b,
        min_pair_fraction: 0.0,
        min_pairs_each: 0.0,
    })
}

fn status<'a>(r: &'a SearchResult, name: &str) -> &'a vgsel_colmap::flow::search::CriterionStatus {
    r.criteria.iter().find(|c| c.name == name).unwrap()
}

#[test]
fn criteria_search_finds_the_smallest_flow() {
    for (seed, a, b) in [
        (1u64, 0.8, 2.0),
        (2, 0.95, 1.0),
        (3, 0.5, 4.0),
        (4, 0.9, 3.0),
    ] {
        let p = random_problem(80, 700, seed);
        let rule = criteria(a, b);
        let FlowRule::Criteria(c) = rule else {
            unreachable!()
        };
        let (ti, tp) = targets(&p, &c);
        assert_eq!(ti, (a * 80.0f64).ceil() as usize);
        assert_eq!(tp, ((b * 80.0f64).ceil() as usize).min(700));
        let r = search(&p, &rule);
        assert!(!r.capped, "seed {seed}");
        let f = r.selection.flow;
        assert!(f >= 1);
        // meets at F (independent solve), fails at F - 1 and at every smaller F
        let at = solve(&p, f);
        assert_eq!(at, r.selection);
        let (i, e) = counts(&at);
        assert!(i >= ti && e >= tp);
        let before = solve(&p, f - 1);
        let (i0, e0) = counts(&before);
        assert!(i0 < ti || e0 < tp, "F-1 = {} already meets", f - 1);
        let mut s = ParametricSolver::new(&p);
        for g in 1..f {
            s.augment().unwrap();
            assert!(
                s.images_selected() < ti || s.pairs_selected() < tp,
                "F={g} meets"
            );
        }
        // statuses: met, achieved and binding = not met at F - 1
        let (si, sp) = (status(&r, "images"), status(&r, "pairs"));
        assert!(si.met && sp.met);
        assert_eq!((si.achieved, sp.achieved), (i as f64, e as f64));
        assert_eq!((si.target, sp.target), (ti as f64, tp as f64));
        assert_eq!(si.binding, i0 < ti);
        assert_eq!(sp.binding, e0 < tp);
        assert!(si.binding || sp.binding);
        // curve covers F = 0 ..= chosen F and agrees with independent solves
        assert_eq!(r.curve.len() as u64, f + 1);
        for (k, pt) in r.curve.iter().enumerate() {
            assert_eq!(pt.flow, k as u64);
        }
        for g in [0, f / 2, f] {
            let pt = r.curve[g as usize];
            assert_eq!(
                (pt.images_selected, pt.pairs_selected),
                counts(&solve(&p, g))
            );
        }
    }
}

#[test]
fn full_graph_at_flow_e_and_capped_search() {
    // Strictly negative costs: the min-cost flow of value |E| selects every pair, so a pair
    // target of |E| (B large) is met at some F <= |E| and never caps the search.
    let p = random_problem(20, 150, 9);
    let full = solve(&p, 150);
    assert_eq!(counts(&full), (20, 150));
    let r = search(&p, &criteria(1.0, 100.0));
    assert!(!r.capped);
    assert!(r.selection.flow <= 150);
    assert_eq!(counts(&r.selection), (20, 150));
    assert!(status(&r, "pairs").binding);

    // A capped search returns the full graph with the cost of the flow saturating every arc.
    let mut q = random_problem(20, 60, 4);
    q.image_costs.push(-0.25); // isolated image 20
    let r = search(&q, &criteria(1.0, 0.0));
    assert!(r.capped);
    assert_eq!(r.selection.images, vec![true; 21]);
    assert_eq!(r.selection.pairs, vec![true; 60]);
    assert_eq!(r.selection.flow, 60);
    let mut deg = [0.0; 21];
    let mut cost = 0.0;
    for e in &q.pairs {
        deg[e.i as usize] += 1.0;
        deg[e.j as usize] += 1.0;
        cost += e.cost;
    }
    for (d, c) in deg.iter().zip(&q.image_costs) {
        cost += d * c;
    }
    assert!((r.selection.cost - cost).abs() < 1e-9);
    let si = status(&r, "images");
    assert!(si.binding && !status(&r, "pairs").binding);
    assert_eq!((si.target, si.achieved), (21.0, 21.0));
    // independently: no F up to max flow selects 21 images
    let mut s = ParametricSolver::new(&q);
    while s.augment().is_some() {
        assert!(s.images_selected() <= 20);
    }
}

#[test]
fn fixed_flow() {
    let p = random_problem(40, 200, 5);
    let r = search(&p, &FlowRule::Fixed(10));
    assert!(!r.capped && r.criteria.is_empty());
    assert_eq!(r.selection.flow, 10);
    assert_eq!(r.selection, solve(&p, 10));
    assert_eq!(r.curve.len(), 11);
    assert_eq!(
        (r.curve[10].images_selected, r.curve[10].pairs_selected),
        counts(&r.selection)
    );
    let r = search(&p, &FlowRule::Fixed(10_000));
    assert_eq!(r.selection.flow, 400);
    assert_eq!(counts(&r.selection).1, 0);
    let r = search(&p, &FlowRule::Fixed(0));
    assert_eq!(r.selection.flow, 0);
    assert_eq!(counts(&r.selection), (0, 0));
}

#[test]
fn degenerate_inputs() {
    let empty = SelectionProblem::default();
    for rule in [FlowRule::Fixed(5), criteria(0.9, 5.0)] {
        let r = search(&empty, &rule);
        assert!(!r.capped);
        assert_eq!(r.selection.flow, 0);
        assert!(r.selection.images.is_empty() && r.selection.pairs.is_empty());
        assert_eq!(r.selection.cost, 0.0);
    }
    // images but no pairs
    let lonely = SelectionProblem {
        image_costs: vec![-0.5; 4],
        pairs: vec![],
    };
    let r = search(&lonely, &criteria(0.5, 5.0));
    assert!(r.capped);
    assert_eq!(r.selection.images, vec![true; 4]);
    let r = search(&lonely, &criteria(0.0, 5.0));
    assert!(!r.capped);
    assert_eq!(r.selection.flow, 0);
    assert_eq!(r.selection.images, vec![false; 4]);
    assert!(!status(&r, "images").binding && !status(&r, "pairs").binding);
    let r = search(&lonely, &FlowRule::Fixed(3));
    assert_eq!(r.selection.flow, 0);
}

#[test]
fn the_pair_fraction_raises_the_pair_target_and_the_flow() {
    let p = random_problem(80, 700, 5);
    let with = |per_image: f64, fraction: f64| Criteria {
        min_image_fraction: 0.0,
        min_pairs_per_image: per_image,
        min_pair_fraction: fraction,
        min_pairs_each: 0.0,
    };
    // 25% of 700 pairs = 175 > 1 x 80 images; the larger target wins either way round.
    assert_eq!(targets(&p, &with(1.0, 0.25)), (0, 175));
    assert_eq!(targets(&p, &with(3.0, 0.25)), (0, 240));
    assert_eq!(targets(&p, &with(0.0, 1.0)), (0, 700));
    let r = search(&p, &FlowRule::Criteria(with(0.0, 0.25)));
    let (_, pairs) = counts(&r.selection);
    assert!(pairs >= 175 && status(&r, "pairs").binding);
    let (_, before) = counts(&solve(&p, r.selection.flow - 1));
    assert!(before < 175);
}

/// Selected pairs of each image, counted independently of the search.
fn selected_degrees(p: &SelectionProblem, s: &Selection) -> Vec<usize> {
    let mut d = vec![0; p.image_costs.len()];
    for (arc, &on) in p.pairs.iter().zip(&s.pairs) {
        if on {
            d[arc.i as usize] += 1;
            d[arc.j as usize] += 1;
        }
    }
    d
}

#[test]
fn every_image_keeps_its_own_pairs_at_the_smallest_such_flow() {
    for (seed, k) in [(6u64, 1.0f64), (7, 2.0), (8, 3.0), (9, 2.5)] {
        let p = random_problem(60, 400, seed);
        let full = selected_degrees(
            &p,
            &Selection {
                pairs: vec![true; p.pairs.len()],
                ..solve(&p, 0)
            },
        );
        let need: Vec<usize> = full.iter().map(|&d| d.min(k.ceil() as usize)).collect();
        let holds = |s: &Selection| {
            selected_degrees(&p, s)
                .iter()
                .zip(&need)
                .all(|(&got, &n)| got >= n)
        };
        let rule = FlowRule::Criteria(Criteria {
            min_image_fraction: 0.0,
            min_pairs_per_image: 0.0,
            min_pair_fraction: 0.0,
            min_pairs_each: k,
        });
        let r = search(&p, &rule);
        assert!(!r.capped, "seed {seed}");
        let f = r.selection.flow;
        assert_eq!(r.selection, solve(&p, f));
        assert!(holds(&r.selection), "seed {seed}: not met at F = {f}");
        for smaller in 0..f {
            assert!(
                !holds(&solve(&p, smaller)),
                "seed {seed}: met at F = {smaller} < {f}"
            );
        }
        let each = status(&r, "pairs_each");
        assert!(each.met && each.binding);
        assert_eq!(each.target, need.iter().filter(|&&n| n > 0).count() as f64);
    }
}

/// A caller's check: the listed pairs must all be selected (one unit each).
struct PairsSelected(Vec<usize>);

impl SelectionCheck for PairsSelected {
    fn name(&self) -> &str {
        "listed_pairs"
    }
    fn target(&self) -> usize {
        self.0.len()
    }
    fn achieved(&self, pairs: &[bool]) -> usize {
        self.0.iter().filter(|&&k| pairs[k]).count()
    }
}

#[test]
fn a_callers_check_is_met_within_its_step_of_the_smallest_flow() {
    for seed in 10..16u64 {
        let p = random_problem(40, 240, seed);
        // Three pairs the cheapest flows tend not to take: the most expensive ones.
        let mut by_cost: Vec<usize> = (0..p.pairs.len()).collect();
        by_cost.sort_by(|&a, &b| p.pairs[b].cost.total_cmp(&p.pairs[a].cost));
        let check = PairsSelected(by_cost[..3].to_vec());
        let holds = |s: &Selection| check.achieved(&s.pairs) == 3;
        let rule = criteria(0.5, 0.0);
        let r = search_with_curve(&p, &rule, 0, &[&check]);
        let smallest = (0..=2 * p.pairs.len() as u64).find(|&f| {
            let s = solve(&p, f);
            counts(&s).0 >= 20 && holds(&s)
        });
        let listed = status(&r, "listed_pairs");
        match smallest {
            Some(f0) => {
                assert!(!r.capped, "seed {seed}");
                let f = r.selection.flow;
                assert_eq!(r.selection, solve(&p, f));
                assert!(holds(&r.selection), "seed {seed}: check not met at F = {f}");
                // Checked at F0 or later, then every F/32 (at least 1) flows.
                assert!(
                    f >= f0 && f <= f0 + (f0 / 32).max(1),
                    "seed {seed}: F {f}, smallest {f0}"
                );
                assert!(listed.met && listed.achieved == 3.0);
                // Binding exactly when the image criterion held already at F - 1.
                let images_before = f > 0 && counts(&solve(&p, f - 1)).0 >= 20;
                assert_eq!(listed.binding, images_before, "seed {seed}");
            }
            None => assert!(r.capped && listed.met, "seed {seed}"),
        }
        // Without the check the same rule stops no later.
        assert!(search(&p, &rule).selection.flow <= r.selection.flow);
    }
}

/// Whether the graph of `edges` is connected and stays connected without any one of its
/// vertices (three or more), by removing each in turn: independent of the library's low points.
fn biconnected_by_brute_force(edges: &[(u32, u32)]) -> bool {
    let vertices: std::collections::BTreeSet<u32> =
        edges.iter().flat_map(|&(i, j)| [i, j]).collect();
    let connected_without = |skip: Option<u32>| {
        let left: Vec<u32> = vertices
            .iter()
            .copied()
            .filter(|&v| Some(v) != skip)
            .collect();
        let mut seen = std::collections::BTreeSet::from([left[0]]);
        let mut todo = vec![left[0]];
        while let Some(v) = todo.pop() {
            for &(i, j) in edges {
                for (a, b) in [(i, j), (j, i)] {
                    if a == v && Some(b) != skip && seen.insert(b) {
                        todo.push(b);
                    }
                }
            }
        }
        seen.len() == left.len()
    };
    !vertices.is_empty()
        && connected_without(None)
        && (vertices.len() < 3 || vertices.iter().all(|&v| connected_without(Some(v))))
}

/// The selected pairs as edges.
fn selected_edges(p: &SelectionProblem, s: &Selection) -> Vec<(u32, u32)> {
    p.pairs
        .iter()
        .zip(&s.pairs)
        .filter(|(_, &on)| on)
        .map(|(a, _)| (a.i, a.j))
        .collect()
}

#[test]
fn biconnectivity_agrees_with_brute_force_on_random_graphs() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move |m: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % m
    };
    let (mut yes, mut no) = (0, 0);
    for _ in 0..3000 {
        let n = 2 + next(8) as usize;
        let m = next(2 * n as u64 + 1) as usize;
        let mut edges = Vec::new();
        for _ in 0..m {
            let (a, b) = (next(n as u64) as u32, next(n as u64) as u32);
            if a != b && !edges.contains(&(a.min(b), a.max(b))) {
                edges.push((a.min(b), a.max(b)));
            }
        }
        let expected = biconnected_by_brute_force(&edges);
        assert_eq!(
            is_biconnected(n, &edges),
            expected,
            "{n} vertices, {edges:?}"
        );
        if expected {
            yes += 1
        } else {
            no += 1
        }
    }
    assert!(yes > 300 && no > 300, "{yes} biconnected, {no} not");
}

#[test]
fn a_biconnected_search_has_no_cut_image() {
    let mut checked = 0;
    for seed in 20..30u64 {
        let p = random_problem(30, 120, seed);
        let check = Biconnected::new(&p);
        let rule = criteria(0.6, 0.0);
        let r = search_with_curve(&p, &rule, 0, &[&check]);
        let smallest = (0..=2 * p.pairs.len() as u64).find(|&f| {
            let s = solve(&p, f);
            counts(&s).0 >= 18 && biconnected_by_brute_force(&selected_edges(&p, &s))
        });
        match smallest {
            Some(f0) => {
                let f = r.selection.flow;
                assert!(
                    biconnected_by_brute_force(&selected_edges(&p, &r.selection)),
                    "seed {seed}"
                );
                assert!(
                    f >= f0 && f <= f0 + (f0 / 32).max(1),
                    "seed {seed}: F {f}, smallest {f0}"
                );
                checked += 1;
            }
            None => assert!(r.capped, "seed {seed}"),
        }
    }
    assert!(
        checked >= 5,
        "only {checked} problems had a biconnected selection"
    );
}

#[test]
fn curve_beyond_the_choice_continues_the_same_flows_and_keeps_the_selection() {
    for seed in 0..20 {
        let problem = random_problem(12, 30, seed);
        for rule in [criteria(0.6, 1.0), FlowRule::Fixed(3), criteria(1.0, 30.0)] {
            let plain = search(&problem, &rule);
            let extended = search_with_curve(&problem, &rule, 4, &[]);
            assert_eq!(extended.selection, plain.selection, "seed {seed}");
            assert_eq!(extended.curve.len(), plain.curve.len());
            // Every point, chosen or beyond, is what a fresh solver selects at that F.
            let mut fresh = ParametricSolver::new(&problem);
            for p in extended.curve.iter().chain(&extended.beyond) {
                while fresh.flow() < p.flow {
                    fresh.augment().expect("the search reached this flow");
                }
                assert_eq!(
                    (p.images_selected, p.pairs_selected),
                    (fresh.images_selected(), fresh.pairs_selected()),
                    "seed {seed}, F = {}",
                    p.flow
                );
            }
            let chosen = plain.selection.flow.max(1);
            let last = extended.beyond.last().or(extended.curve.last()).unwrap();
            let limit = (4 * chosen).min(2 * problem.pairs.len() as u64);
            assert!(
                last.flow >= limit.min(fresh.max_flow())
                    || last.pairs_selected == problem.pairs.len(),
                "seed {seed}: the curve stops early at F = {}",
                last.flow
            );
        }
    }
}
