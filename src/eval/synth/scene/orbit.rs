//! The default scene: boxes on a ground disc, cameras on an orbit around them.

use crate::eval::synth::scene::{default_surfaces, look_at, sample_surface, ScenePoint};
use crate::eval::synth::spec::SceneSpec;
use crate::eval::synth::truth::GtImage;
use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Points and cameras of the orbit scene (points first: the order of the random draws).
pub(crate) fn build(spec: &SceneSpec, rng: &mut ChaCha8Rng) -> (Vec<ScenePoint>, Vec<GtImage>) {
    let points = build_points(spec, rng);
    (points, build_cameras(spec, rng))
}

fn build_points(spec: &SceneSpec, rng: &mut ChaCha8Rng) -> Vec<ScenePoint> {
    let surfaces = default_surfaces(spec);
    let total: f64 = surfaces.iter().map(|s| s.1).sum();
    let mut points = Vec::with_capacity(spec.num_points);
    let mut left = spec.num_points;
    for (i, (surface, weight)) in surfaces.iter().enumerate() {
        let n = if i + 1 == surfaces.len() {
            left
        } else {
            ((spec.num_points as f64) * weight / total).round() as usize
        }
        .min(left);
        left -= n;
        for (position, normal) in sample_surface(surface, n, rng) {
            let appearance = points.len() as u32;
            points.push(ScenePoint {
                position,
                normal,
                appearance,
                copy: 0,
            });
        }
    }
    points
}

fn build_cameras(spec: &SceneSpec, rng: &mut ChaCha8Rng) -> Vec<GtImage> {
    let jitter = Normal::new(0.0, spec.pose_jitter.max(1e-12)).unwrap();
    let full = (spec.arc_degrees - 360.0).abs() < 1e-9;
    let step = if full || spec.num_images < 2 {
        spec.arc_degrees / spec.num_images.max(1) as f64
    } else {
        spec.arc_degrees / (spec.num_images - 1) as f64
    };
    (0..spec.num_images)
        .map(|i| {
            let az = (i as f64 * step).to_radians();
            let centre = Vector3::new(
                spec.orbit_radius * az.cos() + jitter.sample(rng),
                spec.orbit_radius * az.sin() + jitter.sample(rng),
                spec.camera_height + jitter.sample(rng),
            );
            let target = Vector3::new(
                jitter.sample(rng),
                jitter.sample(rng),
                0.6 + jitter.sample(rng),
            );
            let rotation = look_at(&centre, &target);
            let translation = -(rotation * centre);
            GtImage {
                image_id: i as u32 + 1,
                name: format!("image_{:04}.jpg", i + 1),
                rotation,
                translation,
                centre,
            }
        })
        .collect()
}
