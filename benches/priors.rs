//! The hottest priors (overlap: a convex hull per pair and image; track fraction: a pass over
//! every inlier) on a synthetic view graph generated in-process: 300 images in a loop, each
//! paired with its 20 nearest neighbours by 200 inliers drawn from 2,000 keypoints per image.

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vgsel_colmap::colmap::database::{Image, VerifiedPair};
use vgsel_colmap::priors::{overlap, track_fraction};
use vgsel_colmap::scene::view_graph::ViewGraph;
use vgsel_colmap::scene::Scene;

const IMAGES: u32 = 300;
const NEIGHBOURS: u32 = 20;
const KEYPOINTS: u32 = 2_000;
const INLIERS: usize = 200;
const SIZE: (u32, u32) = (1024, 768);

fn two_copies() -> (Vec<Image>, Vec<VerifiedPair>, Vec<Vec<[f32; 2]>>) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let images: Vec<Image> = (1..=IMAGES)
        .map(|id| Image {
            image_id: id,
            name: format!("{id}.jpg"),
            camera_id: 1,
        })
        .collect();
    let keypoints = (0..IMAGES)
        .map(|_| {
            (0..KEYPOINTS)
                .map(|_| {
                    [
                        rng.gen_range(0.0..SIZE.0 as f32),
                        rng.gen_range(0.0..SIZE.1 as f32),
                    ]
                })
                .collect()
        })
        .collect();
    let mut pairs = Vec::new();
    for a in 1..=IMAGES {
        for d in 1..=NEIGHBOURS / 2 {
            let b = (a - 1 + d) % IMAGES + 1;
            let inliers = (0..INLIERS)
                .map(|_| [rng.gen_range(0..KEYPOINTS), rng.gen_range(0..KEYPOINTS)])
                .collect();
            pairs.push(VerifiedPair {
                image_id1: a.min(b),
                image_id2: a.max(b),
                config: 2,
                inliers,
            });
        }
    }
    (images, pairs, keypoints)
}

fn bench_priors(c: &mut Criterion) {
    let (images, pairs, keypoints) = two_copies();
    let graph = ViewGraph::build(&images, &pairs, 15);
    // Vertices are image ids ascending, so vertex k is image k + 1: keypoints line up.
    assert_eq!(graph.image_ids.len(), IMAGES as usize);
    let scene = Scene::new(&graph, &pairs, keypoints, vec![SIZE; IMAGES as usize]);
    let mut group = c.benchmark_group("priors");
    group.sample_size(20);
    group.bench_function("overlap 300 images / 3000 pairs", |b| {
        b.iter(|| overlap::compute(&scene))
    });
    group.bench_function("track fraction 300 images / 3000 pairs", |b| {
        b.iter(|| track_fraction::compute(&scene))
    });
    group.finish();
}

criterion_group!(benches, bench_priors);
criterion_main!(benches);
