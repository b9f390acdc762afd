//! The observation stage: each image's keypoints, the noisy projections of the points it sees
//! plus random extra keypoints, in random order.

use crate::eval::synth::scene::ScenePoint;
use crate::eval::synth::spec::SceneSpec;
use crate::eval::synth::truth::GtImage;
use rand::seq::SliceRandom;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Keypoints of one image: positions and, for each visible point, its keypoint index.
pub(super) struct ImageObservations {
    pub keypoints: Vec<[f32; 2]>,
    /// (point index, keypoint index).
    pub seen: Vec<(u32, u32)>,
}

/// The keypoints of `image`: the points it sees from within their view cones, projected with
/// Gaussian noise, plus random extra keypoints, shuffled.
pub(super) fn observe(
    spec: &SceneSpec,
    image: &GtImage,
    points: &[ScenePoint],
    rng: &mut ChaCha8Rng,
) -> ImageObservations {
    let (w, h) = (spec.width as f64, spec.height as f64);
    let (cx, cy) = (w / 2.0, h / 2.0);
    let cos_cone = spec.view_cone_degrees.to_radians().cos();
    let noise = Normal::new(0.0, spec.noise_px.max(1e-12)).unwrap();
    let margin = 2.0;
    // (x, y, point index or u32::MAX for an extra keypoint)
    let mut entries: Vec<(f32, f32, u32)> = Vec::new();
    for (pi, p) in points.iter().enumerate() {
        let ray = image.centre - p.position;
        if ray.dot(&p.normal) < cos_cone * ray.norm() {
            continue;
        }
        let xc = image.rotation * p.position + image.translation;
        if xc.z < 0.1 {
            continue;
        }
        let u = spec.focal * xc.x / xc.z + cx;
        let v = spec.focal * xc.y / xc.z + cy;
        if u < margin || u > w - margin || v < margin || v > h - margin {
            continue;
        }
        let x = (u + noise.sample(rng)).clamp(0.0, w);
        let y = (v + noise.sample(rng)).clamp(0.0, h);
        entries.push((x as f32, y as f32, pi as u32));
    }
    let extra = (entries.len() as f64 * spec.extra_keypoint_fraction).round() as usize;
    for _ in 0..extra {
        entries.push((
            rng.gen_range(0.0..w) as f32,
            rng.gen_range(0.0..h) as f32,
            u32::MAX,
        ));
    }
    entries.shuffle(rng);
    let mut seen = Vec::new();
    let keypoints = entries
        .iter()
        .enumerate()
        .map(|(k, &(x, y, pi))| {
            if pi != u32::MAX {
                seen.push((pi, k as u32));
            }
            [x, y]
        })
        .collect();
    ImageObservations { keypoints, seen }
}
