//! The scene stage: surfaces, the points sampled on them and the cameras that look at them;
//! the kinds of scene ([`orbit`], [`duplicate`]) build on these helpers.

pub mod duplicate;
pub mod orbit;

use crate::eval::synth::spec::SceneSpec;
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// A surface that points are sampled on.
#[derive(Clone, Debug)]
pub(crate) enum Surface {
    /// Box standing on the ground (bottom face not sampled), rotated by `yaw` about z.
    Box {
        centre: Vector3<f64>,
        half: Vector3<f64>,
        yaw: f64,
    },
    /// Disc of the ground plane z = 0; its "normals" are random facets tilted towards the
    /// horizon, so ground texture is also seen only from a range of azimuths.
    Ground { radius: f64 },
}

#[derive(Clone, Debug)]
pub(crate) struct ScenePoint {
    pub position: Vector3<f64>,
    /// Axis of the visibility cone (unit).
    pub normal: Vector3<f64>,
    /// Correspondences join observations of equal appearance.
    pub appearance: u32,
    /// Which copy of a duplicated object the point is on (0 elsewhere).
    pub copy: u32,
}

/// The default scene: three boxes of different sizes near the centre on a ground disc, with
/// `weight` the share of points.
pub(crate) fn default_surfaces(spec: &SceneSpec) -> Vec<(Surface, f64)> {
    let r = spec.orbit_radius;
    vec![
        (
            Surface::Box {
                centre: Vector3::new(0.0, 0.0, 0.75),
                half: Vector3::new(1.0, 0.6, 0.75),
                yaw: 0.3,
            },
            0.35,
        ),
        (
            Surface::Box {
                centre: Vector3::new(1.7, 1.1, 0.45),
                half: Vector3::new(0.45, 0.45, 0.45),
                yaw: -0.4,
            },
            0.12,
        ),
        (
            Surface::Box {
                centre: Vector3::new(-1.4, -1.1, 0.55),
                half: Vector3::new(0.55, 0.3, 0.55),
                yaw: 0.9,
            },
            0.13,
        ),
        (Surface::Ground { radius: 0.7 * r }, 0.40),
    ]
}

pub(crate) fn sample_surface(
    surface: &Surface,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let jitter = Normal::new(0.0, 0.2).unwrap();
    let mut out = Vec::with_capacity(n);
    match surface {
        Surface::Box { centre, half, yaw } => {
            let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), *yaw);
            // Faces: +x, -x, +y, -y, +z with their areas.
            let faces: [(usize, f64); 5] = [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0)];
            let area = |axis: usize| {
                let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
                half[a] * half[b]
            };
            let total: f64 = faces.iter().map(|&(ax, _)| area(ax)).sum();
            for _ in 0..n {
                let mut pick = rng.gen::<f64>() * total;
                let mut face = faces[4];
                for &f in &faces {
                    if pick < area(f.0) {
                        face = f;
                        break;
                    }
                    pick -= area(f.0);
                }
                let (axis, sign) = face;
                let mut local = Vector3::new(
                    rng.gen_range(-1.0..1.0) * half[0],
                    rng.gen_range(-1.0..1.0) * half[1],
                    rng.gen_range(-1.0..1.0) * half[2],
                );
                local[axis] = sign * half[axis];
                let mut normal = Vector3::zeros();
                normal[axis] = sign;
                let perturbed = normal
                    + Vector3::new(jitter.sample(rng), jitter.sample(rng), jitter.sample(rng));
                out.push((centre + rot * local, (rot * perturbed).normalize()));
            }
        }
        Surface::Ground { radius } => {
            for _ in 0..n {
                let r = radius * rng.gen::<f64>().sqrt();
                let a = rng.gen_range(0.0..std::f64::consts::TAU);
                let az = rng.gen_range(0.0..std::f64::consts::TAU);
                let el = rng.gen_range(15f64..40.0).to_radians();
                out.push((
                    Vector3::new(r * a.cos(), r * a.sin(), 0.0),
                    Vector3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin()),
                ));
            }
        }
    }
    out
}

/// World-to-camera rotation of a camera at `centre` looking at `target`, z up in the world,
/// COLMAP's camera axes (x right, y down, z forward).
pub(crate) fn look_at(centre: &Vector3<f64>, target: &Vector3<f64>) -> Rotation3<f64> {
    let forward = (target - centre).normalize();
    let right = forward.cross(&Vector3::z()).normalize();
    let down = forward.cross(&right);
    Rotation3::from_matrix_unchecked(Matrix3::from_rows(&[
        right.transpose(),
        down.transpose(),
        forward.transpose(),
    ]))
}
