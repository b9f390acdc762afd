#!/usr/bin/env python3
"""Peers for the solver benchmark: the paper's flow search with OR-tools' SimpleMinCostFlow or
networkx's network_simplex, on a `vgsel-colmap solve` graph file. Same network, integer costs
(x 2^30) and search as scripts/bench/lemon_search.cpp: double F from 1 until images >= ceil(A n)
and pairs >= min(ceil(B n), E), bisect for the smallest such F, then time one solve at that F.
Prints one JSON object.

usage: peers.py ortools|networkx GRAPH MIN_IMAGE_FRACTION MIN_PAIRS_PER_IMAGE
"""
import json
import math
import sys
import time

SCALE = 1 << 30


def read(path):
    with open(path) as f:
        tokens = f.read().split()
    n, e = int(tokens[0]), int(tokens[1])
    image_cost = [float(x) for x in tokens[2:2 + n]]
    rest = tokens[2 + n:]
    pairs = [(int(rest[3 * k]), int(rest[3 * k + 1]), float(rest[3 * k + 2])) for k in range(e)]
    return n, image_cost, pairs


class OrTools:
    def __init__(self, n, image_cost, pairs):
        from ortools.graph.python import min_cost_flow
        self.mcf, self.n, self.image_cost, self.pairs = min_cost_flow, n, image_cost, pairs
        self.deg = [0] * n
        for i, j, _ in pairs:
            self.deg[i] += 1
            self.deg[j] += 1

    def solve(self, flow):
        n = self.n
        g = self.mcf.SimpleMinCostFlow()
        s, t = 2 * n, 2 * n + 1
        image_arcs = [g.add_arc_with_capacity_and_unit_cost(2 * i, 2 * i + 1, self.deg[i], round(c * SCALE))
                      for i, c in enumerate(self.image_cost)]
        pair_arcs = [g.add_arc_with_capacity_and_unit_cost(2 * i + 1, 2 * j, 1, round(c * SCALE))
                     for i, j, c in self.pairs]
        for i in range(n):
            g.add_arc_with_capacity_and_unit_cost(s, 2 * i, flow, 0)
            g.add_arc_with_capacity_and_unit_cost(2 * i + 1, t, flow, 0)
        g.set_node_supply(s, flow)
        g.set_node_supply(t, -flow)
        if g.solve() != g.OPTIMAL:
            sys.exit(f"ortools: no optimal flow of value {flow}")
        images = sum(1 for a in image_arcs if g.flow(a) > 0)
        chosen = sum(1 for a in pair_arcs if g.flow(a) > 0)
        cost = sum(g.flow(a) * c for a, c in zip(image_arcs, self.image_cost))
        cost += sum(c for a, (_, _, c) in zip(pair_arcs, self.pairs) if g.flow(a) > 0)
        return images, chosen, cost


class NetworkX:
    def __init__(self, n, image_cost, pairs):
        import networkx as nx
        self.nx, self.n, self.image_cost, self.pairs = nx, n, image_cost, pairs
        self.deg = [0] * n
        for i, j, _ in pairs:
            self.deg[i] += 1
            self.deg[j] += 1

    def solve(self, flow):
        nx, n = self.nx, self.n
        g = nx.DiGraph()
        g.add_node("s", demand=-flow)
        g.add_node("t", demand=flow)
        for i, c in enumerate(self.image_cost):
            g.add_edge(("in", i), ("out", i), capacity=self.deg[i], weight=round(c * SCALE))
            g.add_edge("s", ("in", i), capacity=flow, weight=0)
            g.add_edge(("out", i), "t", capacity=flow, weight=0)
        for i, j, c in self.pairs:
            g.add_edge(("out", i), ("in", j), capacity=1, weight=round(c * SCALE))
        _, f = nx.network_simplex(g)
        images = sum(1 for i in range(n) if f[("in", i)][("out", i)] > 0)
        chosen = sum(1 for i, j, _ in self.pairs if f[("out", i)][("in", j)] > 0)
        cost = sum(f[("in", i)][("out", i)] * c for i, c in enumerate(self.image_cost))
        cost += sum(c for i, j, c in self.pairs if f[("out", i)][("in", j)] > 0)
        return images, chosen, cost


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    peer, path, a, b = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
    n, image_cost, pairs = read(path)
    want_images, want_pairs = math.ceil(a * n), min(math.ceil(b * n), len(pairs))
    max_flow = 2 * len(pairs)
    t0 = time.perf_counter()
    solver = {"ortools": OrTools, "networkx": NetworkX}[peer](n, image_cost, pairs)

    def ok(r):
        return r[0] >= want_images and r[1] >= want_pairs

    lo, hi, solves = 0, 1, 1
    r = solver.solve(hi)
    while not ok(r) and hi < max_flow:
        lo, hi = hi, min(2 * hi, max_flow)
        r = solver.solve(hi)
        solves += 1
    capped = not ok(r)
    while not capped and hi - lo > 1:
        mid = (lo + hi) // 2
        solves += 1
        if ok(solver.solve(mid)):
            hi = mid
        else:
            lo = mid
    search_s = time.perf_counter() - t0
    t1 = time.perf_counter()
    images, chosen, cost = solver.solve(hi)
    one_s = time.perf_counter() - t1
    print(json.dumps({"peer": peer, "flow": hi, "capped": capped, "images_selected": images,
                      "pairs_selected": chosen, "cost": cost, "solves": solves,
                      "search_seconds": search_s, "one_solve_seconds": one_s}))


if __name__ == "__main__":
    main()
