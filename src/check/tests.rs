//! The check on small synthetic models: a correct one (one textured wall, cameras along it,
//! each seeing a random 60% of what is in view) and a ghosted one (two differently textured
//! walls whose cameras were registered onto one place, joined by a shared object).

use super::*;
use crate::colmap::model::{ModelCamera, ModelImage};
use crate::colmap::sparse::{Point2D, SparseImage};
use nalgebra::{UnitQuaternion, Vector3};

/// A deterministic generator in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn camera() -> ModelCamera {
    ModelCamera {
        camera_id: 1,
        model: "SIMPLE_RADIAL".into(),
        width: 480,
        height: 360,
        params: vec![400.0, 240.0, 180.0, 0.0],
    }
}

/// Points on the wall z = 5 (x in [-4, 4], y in [-2, 2]) with ids from `first`.
fn wall(rng: &mut Lcg, count: usize, first: u64) -> Vec<(u64, [f64; 3])> {
    (0..count)
        .map(|k| {
            (
                first + k as u64,
                [8.0 * rng.next() - 4.0, 4.0 * rng.next() - 2.0, 5.0],
            )
        })
        .collect()
}

/// An image at x = `x` looking along +z, observing each of `points` in view with probability
/// `keep`.
fn image(id: u32, x: f64, points: &[(u64, [f64; 3])], keep: f64, rng: &mut Lcg) -> SparseImage {
    let view = ModelImage {
        image_id: id,
        camera_id: 1,
        name: format!("{id:04}.png"),
        rotation: UnitQuaternion::identity(),
        translation: Vector3::new(-x, 0.0, 0.0),
        observations: 0,
    };
    let intrinsics = views::Intrinsics::from_camera(&camera());
    let mut points2d = Vec::new();
    for (pid, p) in points {
        let at = Vector3::new(p[0] - x, p[1], p[2]);
        if let Some(xy) = intrinsics.project(&at) {
            if rng.next() < keep {
                points2d.push(Point2D {
                    xy,
                    point3d_id: Some(*pid),
                });
            }
        }
    }
    let mut image = SparseImage {
        image: view,
        points2d,
    };
    image.image.observations = image.points2d.len();
    image
}

fn model(images: Vec<SparseImage>, points: &[(u64, [f64; 3])]) -> SparseModel {
    SparseModel {
        cameras: vec![camera()],
        images,
        points: points.iter().copied().collect(),
    }
}

fn correct_model() -> SparseModel {
    let mut rng = Lcg(7);
    let points = wall(&mut rng, 3000, 0);
    let images = (0..12)
        .map(|k| image(k + 1, -3.0 + 0.5 * k as f64, &points, 0.6, &mut rng))
        .collect();
    model(images, &points)
}

/// Two walls at the same place, each seen by its own six cameras only, and a small object
/// (points at z = 4.5 in the middle) that all twelve see.
fn ghosted_model() -> SparseModel {
    let mut rng = Lcg(11);
    let first = wall(&mut rng, 2000, 0);
    let second = wall(&mut rng, 2000, 10_000);
    let object: Vec<(u64, [f64; 3])> = (0..300)
        .map(|k| (20_000 + k, [rng.next() - 0.5, rng.next() - 0.5, 4.5]))
        .collect();
    let mut images = Vec::new();
    for k in 0..12u32 {
        let mut seen = object.clone();
        seen.extend(if k % 2 == 0 { &first } else { &second });
        images.push(image(k + 1, -1.5 + 0.25 * k as f64, &seen, 0.6, &mut rng));
    }
    let all: Vec<_> = first
        .iter()
        .chain(&second)
        .chain(&object)
        .copied()
        .collect();
    model(images, &all)
}

#[test]
fn a_correct_model_is_clean() {
    let check = check_model(&correct_model(), None, &DEFAULT_SETTINGS).unwrap();
    assert!(check.splits_scored > 0);
    assert!(!check.ghosted, "score {}", check.score);
    assert!(check.score < 0.2, "score {}", check.score);
}

#[test]
fn a_ghosted_model_is_found_with_its_two_groups() {
    let check = check_model(&ghosted_model(), None, &DEFAULT_SETTINGS).unwrap();
    assert!(check.ghosted, "score {}", check.score);
    assert!(check.score > 0.8, "score {}", check.score);
    let worst = check.worst.unwrap();
    // The groups are the two walls' cameras: odd ids on one side, even on the other.
    let parity = |g: &Vec<String>| {
        g.iter()
            .map(|n| n[..4].parse::<u32>().unwrap() % 2)
            .collect::<Vec<_>>()
    };
    for group in &worst.groups {
        let p = parity(group);
        assert!(p.iter().all(|x| *x == p[0]), "{:?}", worst.groups);
    }
    assert!(!worst.joining_pairs.is_empty());
}

#[test]
fn the_check_is_deterministic() {
    let a = check_model(&ghosted_model(), None, &DEFAULT_SETTINGS).unwrap();
    let b = check_model(&ghosted_model(), None, &DEFAULT_SETTINGS).unwrap();
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
}

#[test]
fn projection_applies_radial_distortion() {
    let mut c = camera();
    c.params[3] = 0.1;
    let at = views::Intrinsics::from_camera(&c)
        .project(&Vector3::new(0.5, 0.0, 1.0))
        .unwrap();
    assert!((at[0] - (240.0 + 400.0 * 0.5 * (1.0 + 0.1 * 0.25))).abs() < 1e-9);
    assert!(views::Intrinsics::from_camera(&c)
        .project(&Vector3::new(0.0, 0.0, -1.0))
        .is_none());
}
