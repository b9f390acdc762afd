// Peer for the solver benchmark: the paper's flow search with LEMON's NetworkSimplex.
// Reads the `vgsel-colmap solve` graph format; builds the paper's network (section 4); doubles F
// from 1 until the criteria hold (images >= ceil(A n), pairs >= min(ceil(B n), E)), then bisects
// for the smallest such F; finally times one solve at that F. Prints one JSON object.
// Build: g++ -O2 -o lemon_search lemon_search.cpp  (Debian liblemon-dev)
#include <lemon/network_simplex.h>
#include <lemon/smart_graph.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

using namespace lemon;
using Clock = std::chrono::steady_clock;

struct Problem {
  int n = 0;
  std::vector<double> image_cost;
  std::vector<int> pi, pj;
  std::vector<double> pair_cost;
};

static Problem read(const char* path) {
  FILE* f = std::fopen(path, "r");
  if (!f) { std::perror(path); std::exit(1); }
  Problem p;
  long e;
  if (std::fscanf(f, "%d %ld", &p.n, &e) != 2) std::exit(1);
  p.image_cost.resize(p.n);
  for (auto& c : p.image_cost) if (std::fscanf(f, "%lf", &c) != 1) std::exit(1);
  p.pi.resize(e); p.pj.resize(e); p.pair_cost.resize(e);
  for (long k = 0; k < e; ++k)
    if (std::fscanf(f, "%d %d %lf", &p.pi[k], &p.pj[k], &p.pair_cost[k]) != 3) std::exit(1);
  std::fclose(f);
  return p;
}

struct Result { long images = 0, pairs = 0; double cost = 0; };

struct Solver {
  const Problem& p;
  SmartDigraph g;
  std::vector<SmartDigraph::Arc> source_arc, sink_arc, image_arc, pair_arc;
  SmartDigraph::Node s, t;
  SmartDigraph::ArcMap<long long> cap, cost;
  explicit Solver(const Problem& p) : p(p), cap(g), cost(g) {
    s = g.addNode(); t = g.addNode();
    std::vector<SmartDigraph::Node> in(p.n), out(p.n);
    std::vector<long long> deg(p.n, 0);
    for (size_t k = 0; k < p.pi.size(); ++k) { deg[p.pi[k]]++; deg[p.pj[k]]++; }
    for (int i = 0; i < p.n; ++i) { in[i] = g.addNode(); out[i] = g.addNode(); }
    for (int i = 0; i < p.n; ++i) {
      source_arc.push_back(g.addArc(s, in[i]));
      sink_arc.push_back(g.addArc(out[i], t));
      image_arc.push_back(g.addArc(in[i], out[i]));
      cap[image_arc.back()] = deg[i];
      cost[image_arc.back()] = std::llround(p.image_cost[i] * 1073741824.0);
      cost[source_arc.back()] = cost[sink_arc.back()] = 0;
    }
    for (size_t k = 0; k < p.pi.size(); ++k) {
      pair_arc.push_back(g.addArc(out[p.pi[k]], in[p.pj[k]]));
      cap[pair_arc.back()] = 1;
      cost[pair_arc.back()] = std::llround(p.pair_cost[k] * 1073741824.0);
    }
  }
  Result solve(long long F) {
    for (auto a : source_arc) cap[a] = F;
    for (auto a : sink_arc) cap[a] = F;
    NetworkSimplex<SmartDigraph, long long, long long> ns(g);
    ns.upperMap(cap).costMap(cost).stSupply(s, t, F);
    if (ns.run() != NetworkSimplex<SmartDigraph, long long, long long>::OPTIMAL) {
      std::fprintf(stderr, "no flow of value %lld\n", F); std::exit(1);
    }
    Result r;
    for (int i = 0; i < p.n; ++i) {
      long long x = ns.flow(image_arc[i]);
      if (x > 0) r.images++;
      r.cost += x * p.image_cost[i];
    }
    for (size_t k = 0; k < pair_arc.size(); ++k)
      if (ns.flow(pair_arc[k]) > 0) { r.pairs++; r.cost += p.pair_cost[k]; }
    return r;
  }
};

int main(int argc, char** argv) {
  if (argc != 4) { std::fprintf(stderr, "usage: %s GRAPH MIN_IMAGE_FRACTION MIN_PAIRS_PER_IMAGE\n", argv[0]); return 2; }
  Problem p = read(argv[1]);
  const double a = std::atof(argv[2]), b = std::atof(argv[3]);
  const long e = (long)p.pi.size();
  const long want_images = (long)std::ceil(a * p.n);
  const long want_pairs = std::min((long)std::ceil(b * p.n), e);
  const long long max_flow = 2LL * e;
  auto ok = [&](const Result& r) { return r.images >= want_images && r.pairs >= want_pairs; };

  auto t0 = Clock::now();
  Solver solver(p);
  int solves = 0;
  long long lo = 0, hi = 1;  // criteria fail at lo (or lo = 0), hold at hi
  Result r = solver.solve(hi); solves++;
  while (!ok(r) && hi < max_flow) {
    lo = hi; hi = std::min(2 * hi, max_flow);
    r = solver.solve(hi); solves++;
  }
  bool capped = !ok(r);
  while (!capped && hi - lo > 1) {
    long long mid = lo + (hi - lo) / 2;
    Result m = solver.solve(mid); solves++;
    if (ok(m)) hi = mid; else lo = mid;
  }
  double search_s = std::chrono::duration<double>(Clock::now() - t0).count();
  auto t1 = Clock::now();
  Result final_r = solver.solve(hi);
  double one_s = std::chrono::duration<double>(Clock::now() - t1).count();
  std::printf("{\"peer\":\"lemon\",\"flow\":%lld,\"capped\":%s,\"images_selected\":%ld,\"pairs_selected\":%ld,"
              "\"cost\":%.9f,\"solves\":%d,\"search_seconds\":%.6f,\"one_solve_seconds\":%.6f}\n",
              hi, capped ? "true" : "false", final_r.images, final_r.pairs, final_r.cost, solves, search_s, one_s);
  return 0;
}
