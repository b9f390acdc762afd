//! The solver on the paper's synthetic view graphs (generated in-process): the criteria search
//! (A = 0.9, B = 5, the benchmark criteria of docs/performance.md) and a fixed-F solve.

use criterion::{criterion_group, criterion_main, Criterion};
use vgsel_colmap::flow::search::{search, Criteria, FlowRule};
use vgsel_colmap::flow::solver::solve;
use vgsel_colmap::flow::synthetic_graph::{generate, Arrangement};

fn bench_solver(c: &mut Criterion) {
    let mut group = c.benchmark_group("solver");
    group.sample_size(10);
    for (images, pairs) in [(300, 10_000), (1_000, 100_000)] {
        let problem = generate(images, pairs, Arrangement::Loop, 1);
        let rule = FlowRule::Criteria(Criteria {
            min_image_fraction: 0.9,
            min_pairs_per_image: 5.0,
            min_pair_fraction: 0.0,
            min_pairs_each: 0.0,
        });
        group.bench_function(format!("search {images}/{pairs}"), |b| {
            b.iter(|| search(&problem, &rule))
        });
        group.bench_function(format!("solve F=128 {images}/{pairs}"), |b| {
            b.iter(|| solve(&problem, 128))
        });
    }
    group.finish();
}

criterion_group!(benches, bench_solver);
criterion_main!(benches);
