//! Exact min-cost flow on the selection network: parametric successive shortest paths.
//!
//! # What
//!
//! [`ParametricSolver`] finds, for every flow value F = 0, 1, 2, ... up to the maximum flow, a
//! minimum-cost flow of value exactly F on the network of paper section 4 (see
//! [`crate::network`]): nodes s, in_i, out_i, t; arcs s -> in_i, in_i -> out_i (capacity deg(i),
//! cost c_i), out_i -> in_j for pairs i < j (capacity 1, cost c_ij), out_i -> t. The source and
//! sink arcs have capacity F, which never binds for a flow of value F, so they are treated as
//! unbounded. The maximum flow is sum_i deg(i) = 2|E| (every unit on its own image arc, no pair).
//!
//! It is the successive shortest path (SSP) algorithm of Ahuja, Magnanti and Orlin (Network
//! Flows, section 9.7) run one unit at a time: [`ParametricSolver::augment`] sends one unit along
//! a shortest s-t path of the residual network. After k augmentations the flow is a min-cost
//! flow of value k, so one run replaces the paper's search of repeated full solves; the image
//! and pair counts of the current selection are maintained incrementally (a path may cancel
//! flow on reverse arcs, deselecting pairs or images).
//!
//! # Why it is exact
//!
//! Costs are scaled to integers, `round(cost * 2^30)` ([`scale_cost`]); every computation after
//! that is integer arithmetic (i64), so ties are ties and no rounding can steer a decision.
//! Potentials pi with non-negative reduced costs `c(u,v) + pi(u) - pi(v)` on every residual arc
//! are an LP-duality certificate that the current flow is a min-cost flow of its value.
//! Initially (zero flow) the network is a DAG (pair arcs go from lower to higher index), so one
//! pass in the topological order s, in_0, out_0, in_1, out_1, ..., t gives exact shortest-path
//! potentials. Each augmentation runs Dijkstra on the reduced costs, stops once t is settled and
//! sets pi(v) += min(d(v), d(t)) (implemented as pi(v) += d(v) - d(t) on the settled nodes only,
//! a uniform shift that leaves reduced costs unchanged). This keeps every reduced cost >= 0 and
//! makes the augmenting path's arcs (and their new reverse arcs) zero-reduced-cost, so the
//! certificate survives the augmentation. Path costs are non-decreasing.
//! [`ParametricSolver::check_optimality`] re-verifies the certificate, capacities and flow
//! conservation from scratch.
//!
//! Reverse source arcs (in_i -> s) and reverse sink arcs (t -> out_i) are never on a simple s-t
//! path; they are not stored, and their reduced costs stay >= 0 because s always has distance 0
//! and t the largest distance among settled nodes (checked by `check_optimality` as well).
//!
//! # Complexity
//!
//! With N = 2n + 2 nodes and A = 2|E| + 2n stored residual arcs, one augmentation costs
//! O(A + N log N) (4-ary indexed heap with decrease-key); in practice far less, as Dijkstra stops
//! when t is settled. A run to flow F costs O(F (A + N log N)). The building blocks avoid
//! per-augmentation allocation: compressed (CSR) adjacency with each arc's reverse stored next to
//! its partner index, u32 node and arc indices, i32 arc costs, and scratch vectors reused across
//! augmentations. A path without pair arcs (s -> in_i -> out_i -> t) that still has residual
//! capacity after an augmentation is still a zero-reduced-cost, hence shortest, path: the next
//! augmentation reuses it without a Dijkstra run (this makes the tail of a run to maximum flow
//! cheap).
//!
//! Memory: 16 bytes per stored arc plus 24 bytes per node (about 170 MB for 5M pairs).
//! Capacity limits: fewer than 2^31 stored arcs and 2^31 nodes.

use crate::network::{Selection, SelectionProblem};

/// Multiplier from original costs (in [-1, 0]) to the integer costs the solver works with.
pub const COST_SCALE: f64 = (1u64 << 30) as f64;

/// The integer cost the solver uses for an original cost `c` in [-1, 0].
pub fn scale_cost(c: f64) -> i64 {
    (c * COST_SCALE).round() as i64
}

const NONE: u32 = u32::MAX;
const INF: i64 = i64::MAX;

/// One residual arc. `rev` is the index of its partner (reverse) arc; `cap` its residual
/// capacity. The flow on an original arc is the residual capacity of its reverse arc.
#[derive(Clone, Copy, Debug)]
struct Arc {
    head: u32,
    rev: u32,
    cap: u32,
    cost: i32,
}

#[derive(Clone, Copy, Debug)]
struct Node {
    pi: i64,
    /// Dijkstra label; `INF` outside a Dijkstra run.
    dist: i64,
    /// Arc by which `dist` was reached; `NONE` for in-nodes reached straight from the source.
    pred: u32,
    heap_pos: u32,
}

/// Successive shortest paths from the zero flow; after `k` augmentations the flow is a min-cost
/// flow of value `k`, so one run yields the optimal selection for every F.
pub struct ParametricSolver {
    n: usize,
    /// CSR offsets into `arcs`, one per node plus one.
    first: Vec<u32>,
    arcs: Vec<Arc>,
    nodes: Vec<Node>,
    /// Per image: index of its arc in_i -> out_i, or `NONE` if deg(i) = 0.
    image_arc: Vec<u32>,
    /// Per pair: index of its arc out_i -> in_j.
    pair_arc: Vec<u32>,
    deg: Vec<u32>,
    image_cost: Vec<f64>,
    pair_cost: Vec<f64>,
    flow: u64,
    max_flow: u64,
    images_selected: usize,
    pairs_selected: usize,
    // Scratch, reused across augmentations.
    heap: Vec<(i64, u32)>,
    settled: Vec<u32>,
    touched: Vec<u32>,
    /// Out-node preceding t on the last shortest path.
    t_pred: u32,
    /// Image whose direct path s -> in_i -> out_i -> t is known to be shortest, or `NONE`.
    reuse_image: u32,
    /// Scaled cost of the last augmenting path.
    last_path_cost: i64,
}

#[inline]
fn in_node(i: usize) -> usize {
    2 * i + 1
}
#[inline]
fn out_node(i: usize) -> usize {
    2 * i + 2
}

/// Each image's degree (pairs it is in), after checking the problem as [`ParametricSolver::new`]
/// says it panics.
fn image_degrees(problem: &SelectionProblem) -> Vec<u32> {
    let n = problem.image_costs.len();
    let m = problem.pairs.len();
    assert!(
        2 * (m as u64) + 2 * (n as u64) < (i32::MAX as u64) && 2 * (n as u64) + 2 < NONE as u64,
        "selection network too large for u32 indices ({n} images, {m} pairs)"
    );
    for (i, &c) in problem.image_costs.iter().enumerate() {
        assert!(
            (-1.0..=0.0).contains(&c),
            "image {i}: cost {c} outside [-1, 0]"
        );
    }
    let mut deg = vec![0u32; n];
    for (k, p) in problem.pairs.iter().enumerate() {
        assert!(
            p.i < p.j && (p.j as usize) < n,
            "pair {k}: indices ({}, {}) not i < j < {n}",
            p.i,
            p.j
        );
        assert!(
            (-1.0..=0.0).contains(&p.cost),
            "pair {k}: cost {} outside [-1, 0]",
            p.cost
        );
        deg[p.i as usize] += 1;
        deg[p.j as usize] += 1;
    }
    deg
}

/// Where each node's residual arcs start in the arc array (`first`, one more entry than nodes).
fn arc_offsets(problem: &SelectionProblem, deg: &[u32]) -> Vec<u32> {
    let num_nodes = 2 * deg.len() + 2;
    // Out-degree in the residual network: in_i has its image arc plus one reverse pair arc
    // per pair (k, i); out_i has the reverse image arc plus one pair arc per pair (i, j).
    let mut count = vec![0u32; num_nodes + 1];
    for (i, &d) in deg.iter().enumerate() {
        if d > 0 {
            count[in_node(i)] += 1;
            count[out_node(i)] += 1;
        }
    }
    for p in &problem.pairs {
        count[out_node(p.i as usize)] += 1;
        count[in_node(p.j as usize)] += 1;
    }
    let mut first = vec![0u32; num_nodes + 1];
    for v in 0..num_nodes {
        first[v + 1] = first[v] + count[v];
    }
    first
}

/// The residual arcs at zero flow, each with its reverse, at the offsets `first`; and the arc of
/// each image (`NONE` for an image without pairs) and of each pair.
fn place_arcs(
    problem: &SelectionProblem,
    deg: &[u32],
    first: &[u32],
) -> (Vec<Arc>, Vec<u32>, Vec<u32>) {
    let (n, num_nodes) = (deg.len(), first.len() - 1);
    let num_arcs = first[num_nodes] as usize;
    let mut arcs = vec![
        Arc {
            head: 0,
            rev: 0,
            cap: 0,
            cost: 0
        };
        num_arcs
    ];
    let mut next: Vec<u32> = first[..num_nodes].to_vec();
    let mut place = |arcs: &mut Vec<Arc>, u: usize, v: usize, cap: u32, cost: i32| -> u32 {
        let a = next[u];
        let b = next[v];
        next[u] += 1;
        next[v] += 1;
        arcs[a as usize] = Arc {
            head: v as u32,
            rev: b,
            cap,
            cost,
        };
        arcs[b as usize] = Arc {
            head: u as u32,
            rev: a,
            cap: 0,
            cost: -cost,
        };
        a
    };
    let mut image_arc = vec![NONE; n];
    for i in 0..n {
        if deg[i] > 0 {
            let c = scale_cost(problem.image_costs[i]) as i32;
            image_arc[i] = place(&mut arcs, in_node(i), out_node(i), deg[i], c);
        }
    }
    let pair_arc: Vec<u32> = problem
        .pairs
        .iter()
        .map(|p| {
            let c = scale_cost(p.cost) as i32;
            place(
                &mut arcs,
                out_node(p.i as usize),
                in_node(p.j as usize),
                1,
                c,
            )
        })
        .collect();
    (arcs, image_arc, pair_arc)
}

/// Node potentials at zero flow: the exact shortest distances from s, in topological order s,
/// in_0, out_0, ..., t (so every residual arc starts with a reduced cost >= 0).
fn initial_potentials(deg: &[u32], first: &[u32], arcs: &[Arc], image_arc: &[u32]) -> Vec<Node> {
    let (n, num_nodes) = (deg.len(), first.len() - 1);
    let mut nodes = vec![
        Node {
            pi: 0,
            dist: INF,
            pred: NONE,
            heap_pos: NONE,
        };
        num_nodes
    ];
    let t = num_nodes - 1;
    let mut pi_t = 0i64;
    for i in 0..n {
        if deg[i] == 0 {
            continue;
        }
        let u = in_node(i);
        let mut p = 0i64; // via the source arc
        for a in &arcs[first[u] as usize..first[u + 1] as usize] {
            if (a.head as usize) < u {
                // reverse pair arc in_i -> out_k: the pair arc out_k -> in_i costs -a.cost
                p = p.min(nodes[a.head as usize].pi - a.cost as i64);
            }
        }
        nodes[u].pi = p;
        let po = p + arcs[image_arc[i] as usize].cost as i64;
        nodes[out_node(i)].pi = po;
        pi_t = pi_t.min(po);
    }
    nodes[t].pi = pi_t;
    nodes
}

impl ParametricSolver {
    /// Builds the network at zero flow.
    ///
    /// Panics if a cost is outside [-1, 0] (or NaN), a pair has `i >= j` or an index out of
    /// range, or the network exceeds the u32 index limits.
    pub fn new(problem: &SelectionProblem) -> Self {
        let n = problem.image_costs.len();
        let deg = image_degrees(problem);
        let num_nodes = 2 * n + 2;
        let first = arc_offsets(problem, &deg);
        let (arcs, image_arc, pair_arc) = place_arcs(problem, &deg, &first);
        let nodes = initial_potentials(&deg, &first, &arcs, &image_arc);
        let max_flow = deg.iter().map(|&d| d as u64).sum();
        ParametricSolver {
            n,
            first,
            arcs,
            nodes,
            image_arc,
            pair_arc,
            deg,
            image_cost: problem.image_costs.clone(),
            pair_cost: problem.pairs.iter().map(|p| p.cost).collect(),
            flow: 0,
            max_flow,
            images_selected: 0,
            pairs_selected: 0,
            heap: Vec::with_capacity(num_nodes),
            settled: Vec::with_capacity(num_nodes),
            touched: Vec::with_capacity(num_nodes),
            t_pred: NONE,
            reuse_image: NONE,
            last_path_cost: 0,
        }
    }

    /// Sends one more unit along a shortest residual path; returns its cost (original units), or
    /// `None` when the flow is already maximal.
    ///
    /// The returned cost is the path's integer cost divided by [`COST_SCALE`], exact in f64, so
    /// successive values are exactly non-decreasing.
    pub fn augment(&mut self) -> Option<f64> {
        if self.flow >= self.max_flow {
            return None;
        }
        if self.reuse_image != NONE {
            // The last path was s -> in_i -> out_i -> t and its image arc has capacity left:
            // all its arcs still have reduced cost 0, so it is still a shortest path.
            let a = self.image_arc[self.reuse_image as usize];
            self.push_arc(a);
            if self.arcs[a as usize].cap == 0 {
                self.reuse_image = NONE;
            }
            self.flow += 1;
            return Some(self.last_path_cost as f64 / COST_SCALE);
        }
        let Some(dt) = self.dijkstra() else {
            // Unreachable for a consistent network (max flow is 2|E|); stay safe.
            self.max_flow = self.flow;
            return None;
        };
        let t = self.nodes.len() - 1;
        // Path cost in scaled units: d(t) + pi(t) - pi(s), with the potentials before update.
        let cost = dt + self.nodes[t].pi - self.nodes[0].pi;
        for &u in &self.settled {
            let nd = &mut self.nodes[u as usize];
            nd.pi += nd.dist - dt;
        }
        for &v in &self.touched {
            let nd = &mut self.nodes[v as usize];
            nd.dist = INF;
            nd.heap_pos = NONE;
        }
        self.heap.clear();
        self.settled.clear();
        self.touched.clear();

        // Walk back from t and push one unit.
        let mut v = self.t_pred as usize;
        let mut path_arcs = 0usize;
        let mut direct_image = NONE;
        loop {
            let a = self.nodes[v].pred;
            if a == NONE {
                break;
            }
            self.push_arc(a);
            path_arcs += 1;
            let arc = self.arcs[a as usize];
            v = self.arcs[arc.rev as usize].head as usize;
            if path_arcs == 1 && v + 1 == arc.head as usize && v & 1 == 1 && arc.cap > 0 {
                direct_image = ((v - 1) / 2) as u32;
            }
        }
        if path_arcs == 1 {
            self.reuse_image = direct_image;
        }
        self.flow += 1;
        self.last_path_cost = cost;
        Some(cost as f64 / COST_SCALE)
    }

    /// Pushes one unit through stored arc `a`, keeping the selection counts exact.
    #[inline]
    fn push_arc(&mut self, a: u32) {
        let arc = self.arcs[a as usize];
        let r = arc.rev as usize;
        self.arcs[a as usize].cap -= 1;
        self.arcs[r].cap += 1;
        let u = self.arcs[r].head as usize;
        let v = arc.head as usize;
        if u & 1 == 1 {
            if v > u {
                // image arc in_i -> out_i: flow is now the reverse arc's capacity
                if self.arcs[r].cap == 1 {
                    self.images_selected += 1;
                }
            } else {
                // reverse pair arc: cancels a selected pair
                self.pairs_selected -= 1;
            }
        } else if v < u {
            // reverse image arc: flow on the image arc is now this arc's capacity
            if self.arcs[a as usize].cap == 0 {
                self.images_selected -= 1;
            }
        } else {
            self.pairs_selected += 1;
        }
    }

    /// Dijkstra on reduced costs from s, stopping once t is settled. Leaves labels in `nodes`,
    /// the settled nodes (excluding t) in `settled`, the labelled ones in `touched`, and the
    /// out-node before t in `t_pred`. Returns d(t), or `None` if t is unreachable.
    ///
    /// One algorithm, read whole: the seeding from s, the heap loop with its early stop at t and
    /// the reset on failure share the scratch borrowed at the top; split, each step would take
    /// them all.
    fn dijkstra(&mut self) -> Option<i64> {
        let t = self.nodes.len() - 1;
        let Self {
            nodes,
            arcs,
            first,
            heap,
            settled,
            touched,
            deg,
            t_pred,
            ..
        } = self;
        nodes[0].dist = 0;
        touched.push(0);
        settled.push(0);
        let ps = nodes[0].pi;
        for (i, &d) in deg.iter().enumerate() {
            if d > 0 {
                let v = in_node(i);
                let nd = ps - nodes[v].pi;
                debug_assert!(nd >= 0);
                nodes[v].dist = nd;
                nodes[v].pred = NONE;
                touched.push(v as u32);
                heap_insert(heap, nodes, v as u32, nd);
            }
        }
        let mut result = None;
        while let Some((du, u)) = heap_pop(heap, nodes) {
            let u = u as usize;
            if u == t {
                result = Some(du);
                break;
            }
            settled.push(u as u32);
            let pu = nodes[u].pi + du;
            let (lo, hi) = (first[u] as usize, first[u + 1] as usize);
            for (k, arc) in arcs[lo..hi].iter().enumerate() {
                if arc.cap == 0 {
                    continue;
                }
                let v = arc.head as usize;
                let nv = &mut nodes[v];
                let nd = pu + arc.cost as i64 - nv.pi;
                if nd < nv.dist {
                    debug_assert!(nd >= du, "negative reduced cost");
                    if nv.dist == INF {
                        touched.push(v as u32);
                    }
                    nv.dist = nd;
                    nv.pred = (lo + k) as u32;
                    heap_update(heap, nodes, v as u32, nd);
                }
            }
            if u & 1 == 0 {
                // out_u -> t, unbounded, cost 0
                let nt = &mut nodes[t];
                let nd = pu - nt.pi;
                if nd < nt.dist {
                    debug_assert!(nd >= du, "negative reduced cost");
                    if nt.dist == INF {
                        touched.push(t as u32);
                    }
                    nt.dist = nd;
                    *t_pred = u as u32;
                    heap_update(heap, nodes, t as u32, nd);
                }
                // Every label still in the heap is >= du: t is final.
                if nodes[t].dist == du {
                    result = Some(du);
                    break;
                }
            }
        }
        if result.is_none() {
            for &v in touched.iter() {
                nodes[v as usize].dist = INF;
                nodes[v as usize].heap_pos = NONE;
            }
            heap.clear();
            settled.clear();
            touched.clear();
        }
        result
    }

    /// The flow value F the solver has reached so far.
    pub fn flow(&self) -> u64 {
        self.flow
    }
    /// The maximum flow value, sum of the image degrees (= 2|E|).
    pub fn max_flow(&self) -> u64 {
        self.max_flow
    }
    /// Images whose image arc carries flow at the current F.
    pub fn images_selected(&self) -> usize {
        self.images_selected
    }
    /// Pairs whose arc carries its unit at the current F.
    pub fn pairs_selected(&self) -> usize {
        self.pairs_selected
    }
    /// Flow on the image arc of image `i` (0 ..= deg(i)).
    pub fn image_flow(&self, i: usize) -> u64 {
        match self.image_arc[i] {
            NONE => 0,
            a => self.arcs[self.arcs[a as usize].rev as usize].cap as u64,
        }
    }
    /// Whether pair `k` (index into `SelectionProblem::pairs`) carries its unit.
    pub fn pair_selected(&self, k: usize) -> bool {
        self.arcs[self.pair_arc[k] as usize].cap == 0
    }

    /// The current flow read back as a selection (images, pairs, cost).
    pub fn selection(&self) -> Selection {
        let images: Vec<bool> = (0..self.n).map(|i| self.image_flow(i) > 0).collect();
        let pairs: Vec<bool> = (0..self.pair_arc.len())
            .map(|k| self.pair_selected(k))
            .collect();
        let mut cost = 0.0;
        for (i, &c) in self.image_cost.iter().enumerate() {
            cost += self.image_flow(i) as f64 * c;
        }
        for (k, &c) in self.pair_cost.iter().enumerate() {
            if pairs[k] {
                cost += c;
            }
        }
        Selection {
            flow: self.flow,
            images,
            pairs,
            cost,
        }
    }

    /// Verifies from scratch that the current flow is a min-cost flow of its value: capacities,
    /// flow conservation (source and sink arc flows implied and non-negative, totalling the flow
    /// value), the incremental counts, and non-negative reduced costs under the current
    /// potentials on every residual arc, including the implicit source and sink arcs and their
    /// reverses. By LP duality the last condition certifies optimality.
    pub fn check_optimality(&self) -> Result<(), String> {
        let n = self.n;
        let t = self.nodes.len() - 1;
        let mut pin = vec![0u64; n];
        let mut pout = vec![0u64; n];
        let mut pairs = 0usize;
        for k in 0..self.pair_arc.len() {
            let a = self.arcs[self.pair_arc[k] as usize];
            let r = self.arcs[a.rev as usize];
            let (i, j) = ((r.head as usize - 2) / 2, (a.head as usize - 1) / 2);
            if a.cap + r.cap != 1 || r.head as usize != out_node(i) || a.head as usize != in_node(j)
            {
                return Err(format!("pair arc {k}: bad residual pair"));
            }
            if r.cap == 1 {
                pairs += 1;
                pout[i] += 1;
                pin[j] += 1;
            }
        }
        let (mut total_s, mut total_t, mut images) = (0u64, 0u64, 0usize);
        let pi = |v: usize| self.nodes[v].pi;
        for i in 0..n {
            let f = if self.image_arc[i] == NONE {
                if self.deg[i] != 0 {
                    return Err(format!("image {i}: missing image arc"));
                }
                0
            } else {
                let a = self.arcs[self.image_arc[i] as usize];
                let r = self.arcs[a.rev as usize];
                if a.cap as u64 + r.cap as u64 != self.deg[i] as u64 {
                    return Err(format!("image {i}: capacity not deg(i)"));
                }
                r.cap as u64
            };
            if f < pin[i] || f < pout[i] {
                return Err(format!(
                    "image {i}: conservation violated (image flow {f}, pairs in {}, out {})",
                    pin[i], pout[i]
                ));
            }
            let (s_i, t_i) = (f - pin[i], f - pout[i]);
            total_s += s_i;
            total_t += t_i;
            images += (f > 0) as usize;
            if self.deg[i] > 0 {
                let (vi, vo) = (in_node(i), out_node(i));
                if pi(0) - pi(vi) < 0 || (s_i > 0 && pi(vi) - pi(0) < 0) {
                    return Err(format!("image {i}: negative reduced cost on a source arc"));
                }
                if pi(vo) - pi(t) < 0 || (t_i > 0 && pi(t) - pi(vo) < 0) {
                    return Err(format!("image {i}: negative reduced cost on a sink arc"));
                }
            }
        }
        if total_s != self.flow || total_t != self.flow {
            return Err(format!(
                "flow value {} but source sends {total_s}, sink receives {total_t}",
                self.flow
            ));
        }
        if images != self.images_selected || pairs != self.pairs_selected {
            return Err(format!(
                "counts drifted: images {} (actual {images}), pairs {} (actual {pairs})",
                self.images_selected, self.pairs_selected
            ));
        }
        for u in 0..self.nodes.len() {
            for a in &self.arcs[self.first[u] as usize..self.first[u + 1] as usize] {
                if a.cap > 0 && a.cost as i64 + pi(u) - pi(a.head as usize) < 0 {
                    return Err(format!(
                        "residual arc {u} -> {} has negative reduced cost",
                        a.head
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Min-cost flow of value exactly `flow` (or the maximum flow if smaller).
pub fn solve(problem: &SelectionProblem, flow: u64) -> Selection {
    let mut solver = ParametricSolver::new(problem);
    while solver.flow() < flow && solver.augment().is_some() {}
    solver.selection()
}

// Indexed 4-ary min-heap of (label, node); positions live in `Node::heap_pos`.

#[inline]
fn heap_insert(heap: &mut Vec<(i64, u32)>, nodes: &mut [Node], v: u32, key: i64) {
    heap.push((key, v));
    let last = heap.len() - 1;
    sift_up(heap, nodes, last);
}

#[inline]
fn heap_update(heap: &mut Vec<(i64, u32)>, nodes: &mut [Node], v: u32, key: i64) {
    let p = nodes[v as usize].heap_pos;
    if p == NONE {
        heap_insert(heap, nodes, v, key);
    } else {
        heap[p as usize].0 = key;
        sift_up(heap, nodes, p as usize);
    }
}

#[inline]
fn sift_up(heap: &mut [(i64, u32)], nodes: &mut [Node], mut i: usize) {
    let e = heap[i];
    while i > 0 {
        let p = (i - 1) / 4;
        if heap[p].0 <= e.0 {
            break;
        }
        heap[i] = heap[p];
        nodes[heap[i].1 as usize].heap_pos = i as u32;
        i = p;
    }
    heap[i] = e;
    nodes[e.1 as usize].heap_pos = i as u32;
}

#[inline]
fn heap_pop(heap: &mut Vec<(i64, u32)>, nodes: &mut [Node]) -> Option<(i64, u32)> {
    let top = *heap.first()?;
    nodes[top.1 as usize].heap_pos = NONE;
    let last = heap.pop().unwrap();
    let len = heap.len();
    if len > 0 {
        let mut i = 0;
        loop {
            let c = 4 * i + 1;
            if c >= len {
                break;
            }
            let end = (c + 4).min(len);
            let mut mc = c;
            for k in c + 1..end {
                if heap[k].0 < heap[mc].0 {
                    mc = k;
                }
            }
            if heap[mc].0 >= last.0 {
                break;
            }
            heap[i] = heap[mc];
            nodes[heap[i].1 as usize].heap_pos = i as u32;
            i = mc;
        }
        heap[i] = last;
        nodes[last.1 as usize].heap_pos = i as u32;
    }
    Some(top)
}
