//! The per-pair geometry of the pose-based priors, against OpenCV doing the same job: pose from a
//! stored E (ours: `decomposeEssentialMat` and a closed-form cheirality test; OpenCV's
//! `recoverPose`, which triangulates every point with an SVD), and the homography prior's
//! inlier count of a stored H against a RANSAC fit (`findHomography`). One pair of 200 noisy
//! correspondences, 10% of them outliers, in normalised coordinates.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Matrix3, Rotation3, Vector3};
use opencv::core::{Mat, Point2d, Vector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use vgsel_colmap::geometry::pose::{
    estimate_homography, homography_inliers, recover_pose, PoseSource,
};

type Points = Vec<[f64; 2]>;

fn pair() -> (Matrix3<f64>, Points, Points) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let r = Rotation3::from_euler_angles(0.05, -0.3, 0.1);
    let t = Vector3::new(1.0, 0.1, 0.2);
    let (mut x1, mut x2) = (Vec::new(), Vec::new());
    for k in 0..200 {
        let p = Vector3::new(
            rng.gen_range(-2.0..2.0),
            rng.gen_range(-1.5..1.5),
            rng.gen_range(4.0..8.0),
        );
        let q = r * p + t;
        let noise = 0.002;
        x1.push([p.x / p.z, p.y / p.z]);
        x2.push(if k % 10 == 3 {
            [rng.gen_range(-0.5..0.5), rng.gen_range(-0.5..0.5)]
        } else {
            [
                q.x / q.z + rng.gen_range(-noise..noise),
                q.y / q.z + rng.gen_range(-noise..noise),
            ]
        });
    }
    let skew = Matrix3::new(0.0, -t.z, t.y, t.z, 0.0, -t.x, -t.y, t.x, 0.0);
    (skew * r.matrix(), x1, x2)
}

fn mat(m: &Matrix3<f64>) -> Mat {
    let rows: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]));
    Mat::from_slice_2d(&rows).unwrap()
}

fn cv_points(x: &[[f64; 2]]) -> Vector<Point2d> {
    x.iter().map(|p| Point2d::new(p[0], p[1])).collect()
}

fn bench_geometry(c: &mut Criterion) {
    opencv::core::set_num_threads(1).unwrap();
    let (e, x1, x2) = pair();
    let h = estimate_homography(&x1, &x2, 0.01).unwrap().unwrap().0;
    let mut group = c.benchmark_group("geometry, 200 correspondences");
    group.bench_function("pose from E: ours", |b| {
        b.iter(|| recover_pose(&e, &x1, &x2, PoseSource::Essential).unwrap())
    });
    let (p1, p2, e_cv, k) = (
        cv_points(&x1),
        cv_points(&x2),
        mat(&e),
        mat(&Matrix3::identity()),
    );
    group.bench_function("pose from E: OpenCV recoverPose", |b| {
        b.iter(|| {
            let (mut r, mut t, mut mask) = (Mat::default(), Mat::default(), Mat::default());
            opencv::calib3d::recover_pose_estimated(&e_cv, &p1, &p2, &k, &mut r, &mut t, &mut mask)
                .unwrap()
        })
    });
    group.bench_function("homography: stored H inliers", |b| {
        b.iter(|| homography_inliers(&h, &x1, &x2, 0.01))
    });
    group.bench_function("homography: OpenCV findHomography RANSAC", |b| {
        b.iter(|| estimate_homography(&x1, &x2, 0.01).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench_geometry);
criterion_main!(benches);
