//! Exactness of the parametric min-cost-flow solver: brute force on small networks, an
//! independent optimality certificate (Bellman-Ford on the residual network) on larger ones,
//! monotone path costs, and a timing run on a paper-style graph (`--ignored`).

use proptest::prelude::*;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::collections::HashSet;
use std::time::Instant;
use vgsel_colmap::flow::network::{PairArc, Selection, SelectionProblem};
use vgsel_colmap::flow::search::{search, Criteria, FlowRule};
use vgsel_colmap::flow::solver::{scale_cost, solve, ParametricSolver};

fn degrees(p: &SelectionProblem) -> Vec<u64> {
    let mut deg = vec![0u64; p.image_costs.len()];
    for e in &p.pairs {
        deg[e.i as usize] += 1;
        deg[e.j as usize] += 1;
    }
    deg
}

/// Exhaustive optimum (scaled integer cost) of a flow of value `f`, or None if infeasible.
/// For each subset x of pair arcs the image flows must satisfy
/// max(in_i, out_i) <= f_i <= deg(i) and sum_i f_i = F + |x|; the best f_i fill the lower
/// bounds and put the remaining units on the cheapest image arcs first.
fn brute_force(p: &SelectionProblem, f: u64) -> Option<i64> {
    let n = p.image_costs.len();
    let m = p.pairs.len();
    let deg = degrees(p);
    let ci: Vec<i64> = p.image_costs.iter().map(|&c| scale_cost(c)).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| ci[i]);
    let mut best: Option<i64> = None;
    for mask in 0u32..(1 << m) {
        let mut ins = vec![0u64; n];
        let mut outs = vec![0u64; n];
        let mut cost = 0i64;
        for (k, e) in p.pairs.iter().enumerate() {
            if mask >> k & 1 == 1 {
                outs[e.i as usize] += 1;
                ins[e.j as usize] += 1;
                cost += scale_cost(e.cost);
            }
        }
        let total = f + mask.count_ones() as u64; // sum of image flows
        let lower: Vec<u64> = (0..n).map(|i| ins[i].max(outs[i])).collect();
        let lsum: u64 = lower.iter().sum();
        if lsum > total || total > deg.iter().sum::<u64>() {
            continue;
        }
        let mut rest = total - lsum;
        for i in 0..n {
            cost += lower[i] as i64 * ci[i];
        }
        for &i in &order {
            let add = rest.min(deg[i] - lower[i]);
            cost += add as i64 * ci[i];
            rest -= add;
        }
        assert_eq!(rest, 0);
        best = Some(best.map_or(cost, |b: i64| b.min(cost)));
    }
    best
}

/// Scaled cost of the solver's current flow, computed from its image flows and pairs.
fn scaled_cost(p: &SelectionProblem, s: &ParametricSolver) -> i64 {
    let mut c = 0i64;
    for (i, &ci) in p.image_costs.iter().enumerate() {
        c += s.image_flow(i) as i64 * scale_cost(ci);
    }
    for (k, e) in p.pairs.iter().enumerate() {
        if s.pair_selected(k) {
            c += scale_cost(e.cost);
        }
    }
    c
}

/// Selection read-back is consistent with the solver's counters and itself.
fn check_selection(p: &SelectionProblem, s: &ParametricSolver, sel: &Selection) {
    assert_eq!(sel.flow, s.flow());
    assert_eq!(sel.images.len(), p.image_costs.len());
    assert_eq!(sel.pairs.len(), p.pairs.len());
    assert_eq!(
        sel.images.iter().filter(|&&b| b).count(),
        s.images_selected()
    );
    assert_eq!(sel.pairs.iter().filter(|&&b| b).count(), s.pairs_selected());
    for (k, e) in p.pairs.iter().enumerate() {
        if sel.pairs[k] {
            assert!(
                sel.images[e.i as usize] && sel.images[e.j as usize],
                "pair {k} endpoints"
            );
        }
    }
    let mut cost = 0.0;
    for (i, &c) in p.image_costs.iter().enumerate() {
        assert_eq!(sel.images[i], s.image_flow(i) > 0);
        cost += s.image_flow(i) as f64 * c;
    }
    for (k, e) in p.pairs.iter().enumerate() {
        if sel.pairs[k] {
            cost += e.cost;
        }
    }
    assert!((cost - sel.cost).abs() <= 1e-9 * (1.0 + cost.abs()));
}

/// Independent certificate: rebuild the flow from the solver's image flows and selected pairs,
/// check capacities and conservation, then run Bellman-Ford on the full residual network
/// (including reverse source/sink arcs) and fail on a negative cycle.
fn certify(p: &SelectionProblem, s: &ParametricSolver) {
    let n = p.image_costs.len();
    let deg = degrees(p);
    let (src, sink) = (2 * n, 2 * n + 1);
    let (inn, out) = (|i: usize| 2 * i, |i: usize| 2 * i + 1);
    let mut pin = vec![0u64; n];
    let mut pout = vec![0u64; n];
    let mut arcs: Vec<(usize, usize, i64)> = Vec::new();
    for (k, e) in p.pairs.iter().enumerate() {
        let (i, j, c) = (e.i as usize, e.j as usize, scale_cost(e.cost));
        if s.pair_selected(k) {
            pout[i] += 1;
            pin[j] += 1;
            arcs.push((inn(j), out(i), -c));
        } else {
            arcs.push((out(i), inn(j), c));
        }
    }
    let mut total = 0u64;
    for i in 0..n {
        let f = s.image_flow(i);
        assert!(f <= deg[i], "image {i}: flow {f} > deg {}", deg[i]);
        assert!(f >= pin[i] && f >= pout[i], "image {i}: conservation");
        total += f - pin[i];
        let c = scale_cost(p.image_costs[i]);
        if f < deg[i] {
            arcs.push((inn(i), out(i), c));
        }
        if f > 0 {
            arcs.push((out(i), inn(i), -c));
        }
        if deg[i] > 0 {
            arcs.push((src, inn(i), 0));
            arcs.push((out(i), sink, 0));
        }
        if f > pin[i] {
            arcs.push((inn(i), src, 0));
        }
        if f > pout[i] {
            arcs.push((sink, out(i), 0));
        }
    }
    assert_eq!(total, s.flow(), "source out-flow");
    let nn = 2 * n + 2;
    let mut d = vec![0i64; nn];
    for round in 0..=nn {
        let mut changed = false;
        for &(u, v, c) in &arcs {
            if d[u] + c < d[v] {
                d[v] = d[u] + c;
                changed = true;
            }
        }
        if !changed {
            return;
        }
        assert!(round < nn, "negative residual cycle at flow {}", s.flow());
    }
}

fn problem_strategy() -> impl Strategy<Value = SelectionProblem> {
    let cost = prop_oneof![
        (-4i32..=0).prop_map(|k| k as f64 / 4.0),
        -1.0f64..=0.0,
        Just(0.0),
        Just(-1.0),
    ];
    (1usize..=6).prop_flat_map(move |n| {
        (
            prop::collection::vec(cost.clone(), n),
            prop::collection::vec((0..n as u32, 0..n as u32, cost.clone()), 0..=14),
        )
            .prop_map(|(image_costs, raw)| {
                let mut seen = HashSet::new();
                let pairs: Vec<PairArc> = raw
                    .into_iter()
                    .filter(|&(a, b, _)| a != b && seen.insert((a.min(b), a.max(b))))
                    .map(|(a, b, cost)| PairArc {
                        i: a.min(b),
                        j: a.max(b),
                        cost,
                    })
                    .take(10)
                    .collect();
                SelectionProblem { image_costs, pairs }
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn matches_brute_force_for_every_flow(p in problem_strategy()) {
        let mut s = ParametricSolver::new(&p);
        let max = degrees(&p).iter().sum::<u64>();
        prop_assert_eq!(s.max_flow(), max);
        prop_assert_eq!(brute_force(&p, 0), Some(0));
        let mut last = f64::NEG_INFINITY;
        for f in 1..=max {
            let c = s.augment();
            prop_assert!(c.is_some(), "augment failed below max flow at F={}", f);
            let c = c.unwrap();
            prop_assert!(c >= last, "path cost decreased: {} after {}", c, last);
            last = c;
            prop_assert_eq!(s.flow(), f);
            prop_assert_eq!(Some(scaled_cost(&p, &s)), brute_force(&p, f), "F = {}", f);
            prop_assert_eq!(s.check_optimality(), Ok(()));
            check_selection(&p, &s, &s.selection());
        }
        prop_assert!(s.augment().is_none());
        prop_assert_eq!(brute_force(&p, max + 1), None);
        // at max flow every unit is on its own image arc: no pair selected
        prop_assert_eq!(s.pairs_selected(), 0);
        // solve() agrees and clamps at max flow
        let mid = solve(&p, max / 2);
        prop_assert_eq!(mid.flow, max / 2);
        let over = solve(&p, max + 3);
        prop_assert_eq!(over.flow, max);
    }
}

#[test]
fn brute_force_rejects_a_wrong_answer() {
    // Path 0 - 1 - 2: the F=1 optimum uses both pairs (cost -0.5*3 + -0.2*2 = -1.9) rather
    // than the direct arc of image 1 (-0.5): the oracle must see the difference.
    let p = SelectionProblem {
        image_costs: vec![-0.5, -0.5, -0.5],
        pairs: vec![
            PairArc {
                i: 0,
                j: 1,
                cost: -0.2,
            },
            PairArc {
                i: 1,
                j: 2,
                cost: -0.2,
            },
        ],
    };
    assert_eq!(brute_force(&p, 1), Some(scale_cost(-1.9)));
    assert_ne!(brute_force(&p, 1), Some(scale_cost(-0.5)));
    let sel = solve(&p, 1);
    assert_eq!(sel.pairs, vec![true, true]);
    assert!((sel.cost + 1.9).abs() < 1e-12);
    // F = 4 = max flow: no pair, every image arc full.
    assert_eq!(solve(&p, 4).pairs, vec![false, false]);
}

fn random_problem(n: usize, m: usize, seed: u64) -> SelectionProblem {
    crate::support::random_problem(n, m, seed, true)
}

#[test]
fn certificate_on_large_random_instance() {
    let p = random_problem(300, 10_000, 7);
    let mut s = ParametricSolver::new(&p);
    let mut last = f64::NEG_INFINITY;
    for f in [1u64, 2, 5, 17, 64, 150, 400] {
        while s.flow() < f {
            let c = s.augment().unwrap();
            assert!(c >= last);
            last = c;
        }
        s.check_optimality().unwrap();
        certify(&p, &s);
        check_selection(&p, &s, &s.selection());
    }
}

#[test]
fn whole_run_to_max_flow_is_monotone_and_certified() {
    let p = random_problem(60, 400, 11);
    let mut s = ParametricSolver::new(&p);
    let mut last = f64::NEG_INFINITY;
    let mut steps = 0u64;
    let mut peak_pairs = 0;
    while let Some(c) = s.augment() {
        assert!(
            c >= last,
            "path cost decreased at F={}: {c} < {last}",
            s.flow()
        );
        last = c;
        steps += 1;
        peak_pairs = peak_pairs.max(s.pairs_selected());
        s.check_optimality().unwrap();
        if steps.is_multiple_of(97) {
            certify(&p, &s);
        }
    }
    assert_eq!(steps, 800);
    assert_eq!(s.flow(), s.max_flow());
    assert_eq!(s.pairs_selected(), 0);
    assert!(peak_pairs > 0);
    certify(&p, &s);
    assert!(s.augment().is_none());
}

#[test]
fn isolated_images_and_empty_problems() {
    let empty = SelectionProblem::default();
    let mut s = ParametricSolver::new(&empty);
    assert!(s.augment().is_none());
    assert_eq!(s.selection().images.len(), 0);
    s.check_optimality().unwrap();
    let lonely = SelectionProblem {
        image_costs: vec![-1.0, 0.0],
        pairs: vec![],
    };
    let sel = solve(&lonely, 5);
    assert_eq!(sel.flow, 0);
    assert_eq!(sel.images, vec![false, false]);
    let p = SelectionProblem {
        image_costs: vec![-1.0, -0.3, -1.0, -0.2],
        pairs: vec![PairArc {
            i: 1,
            j: 3,
            cost: -0.5,
        }],
    };
    let mut s = ParametricSolver::new(&p);
    assert_eq!(s.max_flow(), 2);
    assert!((s.augment().unwrap() - (-1.0)).abs() < 1e-9);
    assert_eq!(s.pairs_selected(), 1);
    certify(&p, &s);
    assert!((s.augment().unwrap() - 0.5).abs() < 1e-9);
    assert_eq!((s.images_selected(), s.pairs_selected()), (2, 0));
    s.check_optimality().unwrap();
    assert!(s.augment().is_none());
}

/// Synthetic view graph after the paper's supplement (section III): vertices on a loop, each
/// vertex draws Gaussian-distributed neighbours around itself, uniform costs in [-1, 0], labels
/// shuffled.
pub fn paper_graph(n: usize, edges: usize, seed: u64) -> SelectionProblem {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let per_vertex = edges as f64 / n as f64;
    let draws = Normal::new(per_vertex, per_vertex / 4.0).unwrap();
    let spread = Normal::new(0.0, 2.0 * per_vertex).unwrap();
    let mut perm: Vec<u32> = (0..n as u32).collect();
    perm.shuffle(&mut rng);
    let mut seen = HashSet::with_capacity(edges);
    let mut pairs = Vec::with_capacity(edges);
    'outer: loop {
        for i in 0..n as i64 {
            let d = draws.sample(&mut rng).round().max(1.0) as usize;
            for _ in 0..d {
                let mut off = spread.sample(&mut rng).round() as i64;
                if off == 0 {
                    off = if rng.gen_bool(0.5) { 1 } else { -1 };
                }
                let j = (i + off).rem_euclid(n as i64);
                let (a, b) = (perm[i as usize], perm[j as usize]);
                if a != b && seen.insert((a.min(b), a.max(b))) {
                    pairs.push(PairArc {
                        i: a.min(b),
                        j: a.max(b),
                        cost: -rng.gen::<f64>(),
                    });
                    if pairs.len() == edges {
                        break 'outer;
                    }
                }
            }
        }
    }
    let image_costs = (0..n).map(|_| -rng.gen::<f64>()).collect();
    SelectionProblem { image_costs, pairs }
}

/// `cargo test --release --test solver timing -- --ignored --nocapture`
#[test]
#[ignore]
fn timing_paper_graph_1k_100k() {
    let p = paper_graph(1000, 100_000, 1);
    let t0 = Instant::now();
    let mut s = ParametricSolver::new(&p);
    let build = t0.elapsed();
    let mut marks = Vec::new();
    for f in [16u64, 128, 1024] {
        while s.flow() < f {
            s.augment().unwrap();
        }
        marks.push((f, t0.elapsed(), s.images_selected(), s.pairs_selected()));
    }
    println!("1K/100K build {:.3} s", build.as_secs_f64());
    for (f, t, i, e) in marks {
        println!("  F={f}: {:.3} s (images {i}, pairs {e})", t.as_secs_f64());
    }
    s.check_optimality().unwrap();
    let t1 = Instant::now();
    let crit = Criteria {
        min_image_fraction: 0.9,
        min_pairs_per_image: 5.0,
        min_pair_fraction: 0.0,
        min_pairs_each: 0.0,
    };
    let r = search(&p, &FlowRule::Criteria(crit));
    println!(
        "  criteria search (A=0.9, B=5): {:.3} s, F={} images {} pairs {} capped {}",
        t1.elapsed().as_secs_f64(),
        r.selection.flow,
        r.selection.images.iter().filter(|&&b| b).count(),
        r.selection.pairs.iter().filter(|&&b| b).count(),
        r.capped
    );
}

/// `cargo test --release --test solver timing -- --ignored --nocapture`
#[test]
#[ignore]
fn timing_parse_5m_pairs() {
    let n = 10_000u32;
    let mut pairs = Vec::with_capacity(5_000_000);
    'outer: for k in 1..n {
        for i in 0..n - k {
            pairs.push(PairArc {
                i,
                j: i + k,
                cost: -(((i ^ k) % 1000) as f64) / 999.0,
            });
            if pairs.len() == 5_000_000 {
                break 'outer;
            }
        }
    }
    let p = SelectionProblem {
        image_costs: vec![-0.5; n as usize],
        pairs,
    };
    let text = vgsel_colmap::flow::graph_file::write(&p);
    let t0 = Instant::now();
    let q = vgsel_colmap::flow::graph_file::parse(&text).unwrap();
    println!(
        "parse 10K images / 5M pairs ({} MB): {:.3} s",
        text.len() >> 20,
        t0.elapsed().as_secs_f64()
    );
    assert_eq!(q, p);
}
