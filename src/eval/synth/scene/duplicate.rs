//! A duplicate-structure scene for [`crate::eval::synth`]: two identical copies of the default box
//! group (same appearance ids, the second turned by a yaw) in distinct surroundings (each on
//! its own ground disc), two groups of cameras orbiting one copy each, and a few overview
//! cameras that see both. Cameras of different groups facing their copies from similar angles
//! match on the object alone: these are the false pairs that make `colmap mapper` fold the two
//! copies into one ghosted model. The overview cameras truly link the groups.

use crate::eval::synth::scene::{default_surfaces, look_at, sample_surface, ScenePoint, Surface};
use crate::eval::synth::spec::SceneSpec;
use crate::eval::synth::truth::GtImage;
use nalgebra::{Rotation3, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Distance of each copy from the scene centre, in orbit radii: the two grounds (radius 0.7)
/// and orbits do not overlap.
const HALF_SEPARATION: f64 = 1.2;
/// Share of the points on the object (sampled once, placed twice).
const OBJECT_SHARE: f64 = 0.4;

/// Points and cameras of the scene, `overview` of the cameras looking at both copies.
pub(crate) fn build(
    spec: &SceneSpec,
    yaw_degrees: f64,
    overview: usize,
    rng: &mut ChaCha8Rng,
) -> (Vec<ScenePoint>, Vec<GtImage>) {
    let r = spec.orbit_radius;
    let centres = [
        Vector3::new(-HALF_SEPARATION * r, 0.0, 0.0),
        Vector3::new(HALF_SEPARATION * r, 0.0, 0.0),
    ];
    let turns = [
        Rotation3::identity(),
        Rotation3::from_axis_angle(&Vector3::z_axis(), yaw_degrees.to_radians()),
    ];
    let points = points(spec, &centres, &turns, rng);
    let images = cameras(spec, &centres, overview, rng);
    (points, images)
}

/// The object sampled once and placed at each of `centres` turned by its `turns` (same
/// appearance ids, copy 0 and 1), then a ground disc of its own under each copy.
fn points(
    spec: &SceneSpec,
    centres: &[Vector3<f64>; 2],
    turns: &[Rotation3<f64>; 2],
    rng: &mut ChaCha8Rng,
) -> Vec<ScenePoint> {
    let r = spec.orbit_radius;
    let boxes: Vec<(Surface, f64)> = default_surfaces(spec)
        .into_iter()
        .filter(|(s, _)| matches!(s, Surface::Box { .. }))
        .collect();
    let box_weight: f64 = boxes.iter().map(|b| b.1).sum();
    let num_object = (spec.num_points as f64 * OBJECT_SHARE) as usize;
    let mut object = Vec::new();
    for (surface, w) in &boxes {
        let n = (num_object as f64 * w / box_weight).round() as usize;
        object.extend(sample_surface(surface, n, rng));
    }
    let mut points = Vec::new();
    for (copy, (centre, turn)) in centres.iter().zip(turns).enumerate() {
        for (k, (p, n)) in object.iter().enumerate() {
            points.push(ScenePoint {
                position: centre + turn * p,
                normal: turn * n,
                appearance: k as u32,
                copy: copy as u32,
            });
        }
    }
    let num_ground = (spec.num_points - object.len()) / 2;
    let ground = Surface::Ground { radius: 0.7 * r };
    for centre in centres {
        for (p, n) in sample_surface(&ground, num_ground, rng) {
            let appearance = (object.len() + points.len()) as u32;
            points.push(ScenePoint {
                position: centre + p,
                normal: n,
                appearance,
                copy: 0,
            });
        }
    }
    points
}

/// The cameras: one group orbiting each of `centres`, then `overview` looking at both; every
/// eye and target jittered by the spec's pose jitter.
fn cameras(
    spec: &SceneSpec,
    centres: &[Vector3<f64>; 2],
    overview: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<GtImage> {
    let r = spec.orbit_radius;
    let jitter = Normal::new(0.0, spec.pose_jitter.max(1e-12)).unwrap();
    let noisy = |v: Vector3<f64>, rng: &mut ChaCha8Rng| {
        v + Vector3::new(jitter.sample(rng), jitter.sample(rng), jitter.sample(rng))
    };
    let mut placements = Vec::new();
    let per_group = spec.num_images.saturating_sub(overview) / 2;
    for (g, centre) in centres.iter().enumerate() {
        let n = if g == 0 {
            per_group
        } else {
            spec.num_images - overview - per_group
        };
        let phase = rng.gen_range(0.0..std::f64::consts::TAU);
        for k in 0..n {
            let az = phase + std::f64::consts::TAU * k as f64 / n as f64;
            let eye = centre + Vector3::new(r * az.cos(), r * az.sin(), spec.camera_height);
            placements.push((eye, centre + Vector3::new(0.0, 0.0, 0.6)));
        }
    }
    for k in 0..overview {
        // Alternately in front of and behind the pair of copies, spread along the x axis.
        let side = if k % 2 == 0 { -1.0 } else { 1.0 };
        let x = (k / 2) as f64 * 0.4 * r - 0.2 * r;
        let eye = Vector3::new(x, side * 2.4 * r, 1.5 * r);
        placements.push((eye, Vector3::new(0.0, 0.0, 0.5)));
    }
    placements
        .into_iter()
        .enumerate()
        .map(|(i, (eye, target))| {
            let centre = noisy(eye, rng);
            let rotation = look_at(&centre, &noisy(target, rng));
            GtImage {
                image_id: i as u32 + 1,
                name: format!("image_{:04}.jpg", i + 1),
                translation: -(rotation * centre),
                rotation,
                centre,
            }
        })
        .collect()
}
