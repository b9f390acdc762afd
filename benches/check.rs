//! `check` on correct models of growing size: cameras in a row along a wall (a street's walk),
//! 300 points per image, each seen by 60% of the images it is in view of. Its cost was the
//! points times the images for each of some 4n candidate splits (cubic: 79 s at 200 images on
//! 2 cores); each split now visits only the views within its points' gates (docs/performance.md).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vgsel_colmap::check::{check_model, DEFAULT_SETTINGS};
use vgsel_colmap::colmap::model::{ModelCamera, ModelImage};
use vgsel_colmap::colmap::sparse::{Point2D, SparseImage, SparseModel};

/// `n` cameras 0.5 apart along x, looking along +z at points 5-6 away.
fn wall(n: usize) -> SparseModel {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let length = 0.5 * n as f64 + 8.0;
    let points: Vec<(u64, [f64; 3])> = (0..300 * n as u64)
        .map(|k| {
            let p = [
                rng.gen_range(-4.0..length - 4.0),
                rng.gen_range(-2.0..2.0),
                rng.gen_range(5.0..6.0),
            ];
            (k, p)
        })
        .collect();
    let images = (0..n)
        .map(|i| {
            let x = 0.5 * i as f64;
            let mut points2d = Vec::new();
            for (id, p) in &points {
                let xy = [
                    400.0 * (p[0] - x) / p[2] + 240.0,
                    400.0 * p[1] / p[2] + 180.0,
                ];
                let inside = (0.0..480.0).contains(&xy[0]) && (0.0..360.0).contains(&xy[1]);
                if inside && rng.gen_bool(0.6) {
                    points2d.push(Point2D {
                        xy,
                        point3d_id: Some(*id),
                    });
                }
            }
            let image = ModelImage {
                image_id: i as u32 + 1,
                camera_id: 1,
                name: format!("{i:05}.png"),
                rotation: UnitQuaternion::identity(),
                translation: Vector3::new(-x, 0.0, 0.0),
                observations: points2d.len(),
            };
            SparseImage { image, points2d }
        })
        .collect();
    let camera = ModelCamera {
        camera_id: 1,
        model: "PINHOLE".into(),
        width: 480,
        height: 360,
        params: vec![400.0, 400.0, 240.0, 180.0],
    };
    SparseModel {
        cameras: vec![camera],
        images,
        points: points.into_iter().collect(),
    }
}

/// The model sizes: 50, 100 and 200 images, or those `CHECK_BENCH_IMAGES` lists (`800,1600`).
fn sizes() -> Vec<usize> {
    match std::env::var("CHECK_BENCH_IMAGES") {
        Ok(list) => list.split(',').map(|n| n.trim().parse().unwrap()).collect(),
        Err(_) => vec![50, 100, 200],
    }
}

fn bench_check(c: &mut Criterion) {
    let mut group = c.benchmark_group("check, a correct model of n images");
    group.sample_size(10);
    for n in sizes() {
        let model = wall(n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &model, |b, model| {
            b.iter(|| check_model(model, None, &DEFAULT_SETTINGS).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_check);
criterion_main!(benches);
