//! Synthetic COLMAP 3.8 databases with known ground truth, deterministic from a seed.
//!
//! Why: testing the pruning against the real `colmap mapper` needs databases whose true camera
//! poses are known, without rendering images and running SIFT. [`generate`] writes exactly what
//! `colmap feature_extractor` + `colmap exhaustive_matcher` would have written for a scene of
//! textured boxes on a ground disc seen by cameras on an orbit:
//!
//! - one shared SIMPLE_RADIAL camera (k = 0, principal point at the image centre,
//!   `prior_focal_length = 1` with the true focal length);
//! - keypoints = projections of the visible points + Gaussian noise, plus random extra keypoints,
//!   in random order per image (float32 x 6, COLMAP's pixel convention: x = f X/Z + w/2);
//! - descriptors: COLMAP's mapper never reads them, so each image gets a row with rows = 0,
//!   cols = 128, data NULL (set [`SceneSpec::random_descriptors`] for random uint8 rows);
//! - `matches`: the true correspondences plus `outlier_fraction` random wrong ones;
//! - `two_view_geometries`: the true correspondences (minus a few RANSAC would miss) as inliers,
//!   config 2 (CALIBRATED), F and E from the true relative pose, H the infinite homography;
//!   pairs with fewer than [`SceneSpec::min_num_inliers`] true correspondences get the failed row
//!   3.8 writes (rows 0, cols 2, data NULL, config 0, F..tvec NULL).
//!
//! Points are only seen inside a cone around their (perturbed) surface normal, which stands in for
//! the limited viewpoint invariance of SIFT: neighbouring cameras share many points, cameras more
//! than about twice the cone angle apart share none.
//!
//! A scene is a list of surfaces whose points carry an *appearance* id: correspondences are made
//! between observations of equal appearance, and are true only when they come from the same 3D
//! point. Today every point has its own appearance; a duplicate-structure scene only has to give
//! two copies of an object the same appearance ids, and [`GtPair::true_pair`] labels the result.
//! [`Layout::Duplicate`] is such a scene ([`crate::eval::synth::duplicate`]). There, a pair's
//! correspondences fall into motions (same point, or copy a's point matched to copy b's), and the
//! verified inliers are the largest motion, as RANSAC would keep; the others stay in `matches`.

pub mod duplicate;

use crate::colmap::ids::{self, TwoViewConfig, SIMPLE_RADIAL};
use crate::colmap::model::ModelImage;
use anyhow::{bail, ensure, Context, Result};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rusqlite::{params, Connection};
use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;

/// What to generate. Every field has a default (see [`Default`]) sized for CI.
#[derive(Clone, Debug)]
pub struct SceneSpec {
    pub num_images: usize,
    /// 3D points in the whole scene (about 60% on the boxes, the rest on the ground).
    pub num_points: usize,
    pub width: u32,
    pub height: u32,
    /// Focal length in pixels.
    pub focal: f64,
    /// Radius of the camera orbit around the scene centre (scene units).
    pub orbit_radius: f64,
    /// Height of the cameras above the ground.
    pub camera_height: f64,
    /// Angle covered by the cameras; 360 closes the loop.
    pub arc_degrees: f64,
    /// Random jitter of camera positions (scene units) and look-at targets.
    pub pose_jitter: f64,
    /// Half-angle of the cone around a point's normal from which it can be seen.
    pub view_cone_degrees: f64,
    /// Standard deviation of the keypoint noise in pixels.
    pub noise_px: f64,
    /// Fraction of each pair's `matches` rows that are wrong correspondences.
    pub outlier_fraction: f64,
    /// Random keypoints that see no point, as a fraction of the visible points per image.
    pub extra_keypoint_fraction: f64,
    /// Fraction of true correspondences left out of the inliers (what RANSAC would miss).
    pub inlier_drop_fraction: f64,
    /// Pairs with fewer true correspondences get a failed two_view_geometries row (COLMAP's
    /// `--SiftMatching.min_num_inliers`, 15).
    pub min_num_inliers: usize,
    /// Write rows for every image pair, as the exhaustive matcher does (empty matches, failed
    /// geometry) — not only for pairs that share points.
    pub all_pairs: bool,
    /// Store the true relative pose in qvec/tvec (unit tvec), as
    /// `--SiftMatching.compute_relative_pose 1` would; otherwise zeros, as 3.8 writes by default.
    pub relative_pose: bool,
    /// Random uint8 descriptors (rows = keypoints) instead of empty rows; the mapper ignores them.
    pub random_descriptors: bool,
    /// Which scene.
    pub layout: Layout,
    /// Write this focal length with `prior_focal_length = 0` and UNCALIBRATED geometries (F, no
    /// E), as COLMAP does for images without EXIF; the ground truth keeps `focal`.
    pub stored_focal: Option<f64>,
    pub seed: u64,
}

/// The scene layout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Layout {
    /// Boxes on a ground disc, cameras on an orbit.
    Orbit,
    /// Two identical objects in distinct surroundings; see [`crate::eval::synth::duplicate`].
    Duplicate {
        /// Yaw of the second copy relative to the first (0: a pure translation).
        yaw_degrees: f64,
        /// Images looking at both copies (the rest split between the two copies).
        overview_images: usize,
    },
}

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec {
            num_images: 24,
            num_points: 6000,
            width: 480,
            height: 360,
            focal: 420.0,
            orbit_radius: 8.0,
            camera_height: 2.5,
            arc_degrees: 360.0,
            pose_jitter: 0.2,
            view_cone_degrees: 55.0,
            noise_px: 0.5,
            outlier_fraction: 0.2,
            extra_keypoint_fraction: 0.3,
            inlier_drop_fraction: 0.05,
            min_num_inliers: 15,
            all_pairs: true,
            relative_pose: false,
            random_descriptors: false,
            layout: Layout::Orbit,
            stored_focal: None,
            seed: 0,
        }
    }
}

/// True pose of one image (COLMAP convention: x_cam = rotation * X + translation).
#[derive(Clone, Debug)]
pub struct GtImage {
    pub image_id: u32,
    pub name: String,
    /// World-to-camera rotation.
    pub rotation: Rotation3<f64>,
    /// World-to-camera translation.
    pub translation: Vector3<f64>,
    /// Camera centre in world coordinates, -R^T t.
    pub centre: Vector3<f64>,
}

/// The shared camera.
#[derive(Clone, Debug)]
pub struct GtCamera {
    pub camera_id: u32,
    pub model_id: i32,
    pub width: u32,
    pub height: u32,
    /// SIMPLE_RADIAL: f, cx, cy, k.
    pub params: Vec<f64>,
}

/// Ground truth of one pair that has at least one correspondence.
#[derive(Clone, Debug)]
pub struct GtPair {
    /// Smaller image id first, as in COLMAP's pair_id.
    pub image_id1: u32,
    pub image_id2: u32,
    /// Correspondences between observations of the same 3D point.
    pub num_true: usize,
    /// Rows written to `matches` (true + same-appearance-other-point + random outliers).
    pub num_matches: usize,
    /// Inliers written to `two_view_geometries` (0 when the pair failed).
    pub num_inliers: usize,
    /// The verified inliers come from the same 3D points (false only in duplicate-structure
    /// scenes, or for pairs that failed verification).
    pub true_pair: bool,
}

#[derive(Clone, Debug)]
pub struct GroundTruth {
    pub camera: GtCamera,
    /// In image_id order.
    pub images: Vec<GtImage>,
    /// In pair_id order.
    pub pairs: Vec<GtPair>,
}

impl GroundTruth {
    /// The poses as a model, for [`crate::eval::align::evaluate`].
    pub fn model_images(&self) -> Vec<ModelImage> {
        self.images
            .iter()
            .map(|im| ModelImage {
                image_id: im.image_id,
                camera_id: self.camera.camera_id,
                name: im.name.clone(),
                rotation: UnitQuaternion::from_rotation_matrix(&im.rotation),
                translation: im.translation,
            })
            .collect()
    }

    /// The intrinsic matrix of the shared camera.
    pub fn calibration(&self) -> Matrix3<f64> {
        let p = &self.camera.params;
        Matrix3::new(p[0], 0.0, p[1], 0.0, p[0], p[2], 0.0, 0.0, 1.0)
    }
}

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

/// Keypoint in image a, keypoint in image b (a < b), motion class: 0 for the same 3D point,
/// 1 + 8 × copy in a + copy in b for a duplicate's copy matched to another copy.
type Correspondence = (u32, u32, u32);

/// Keypoints of one image: positions and, for each visible point, its keypoint index.
struct ImageObservations {
    keypoints: Vec<[f32; 2]>,
    /// (point index, keypoint index).
    seen: Vec<(u32, u32)>,
}

fn observe(
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

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Relative pose cam2_from_cam1 of two images.
fn relative_pose(a: &GtImage, b: &GtImage) -> (Rotation3<f64>, Vector3<f64>) {
    let r = b.rotation * a.rotation.inverse();
    let t = b.translation - r * a.translation;
    (r, t)
}

/// E (unit-norm t), F (unit Frobenius norm) and the infinite homography (H[2][2] = 1) of a pair,
/// such that x2^T F x1 = 0 with x1 in image `a`.
pub fn pair_geometry(
    k: &Matrix3<f64>,
    a: &GtImage,
    b: &GtImage,
) -> (Matrix3<f64>, Matrix3<f64>, Matrix3<f64>) {
    let (r, t) = relative_pose(a, b);
    let e = skew(&t.normalize()) * r.matrix();
    let k_inv = k.try_inverse().expect("calibration is invertible");
    let f = k_inv.transpose() * e * k_inv;
    let f = f / f.norm();
    let h = k * r.matrix() * k_inv;
    let h = h / h[(2, 2)];
    (e, f, h)
}

fn matrix_blob(m: &Matrix3<f64>) -> Vec<u8> {
    let mut out = Vec::with_capacity(72);
    for r in 0..3 {
        for c in 0..3 {
            out.extend_from_slice(&m[(r, c)].to_le_bytes());
        }
    }
    out
}

fn f64_blob(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn pairs_blob(pairs: &[[u32; 2]]) -> Vec<u8> {
    pairs
        .iter()
        .flat_map(|p| p.iter().flat_map(|v| v.to_le_bytes()))
        .collect()
}

/// Writes a synthetic COLMAP 3.8 database for `spec` at `database_path` (which must not exist)
/// and returns its ground truth. Everything is written in one transaction.
pub fn generate(spec: &SceneSpec, database_path: &Path) -> Result<GroundTruth> {
    ensure!(spec.num_images >= 2, "a scene needs at least 2 images");
    ensure!(
        (0.0..1.0).contains(&spec.outlier_fraction),
        "outlier_fraction must be in [0, 1)"
    );
    if database_path.exists() {
        bail!(
            "refusing to overwrite existing file {}",
            database_path.display()
        );
    }
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let (points, images) = match spec.layout {
        Layout::Orbit => {
            let points = build_points(spec, &mut rng);
            (points, build_cameras(spec, &mut rng))
        }
        Layout::Duplicate {
            yaw_degrees,
            overview_images,
        } => crate::eval::synth::duplicate::build(spec, yaw_degrees, overview_images, &mut rng),
    };
    let camera = GtCamera {
        camera_id: 1,
        model_id: SIMPLE_RADIAL,
        width: spec.width,
        height: spec.height,
        params: vec![
            spec.focal,
            spec.width as f64 / 2.0,
            spec.height as f64 / 2.0,
            0.0,
        ],
    };
    let observations: Vec<ImageObservations> = images
        .iter()
        .map(|im| observe(spec, im, &points, &mut rng))
        .collect();

    // Observations grouped by appearance; correspondences are then gathered per first image
    // (below), so time is the size of the output, not pairs x points, and memory one image's.
    let num_appearances = points.iter().map(|p| p.appearance + 1).max().unwrap_or(0) as usize;
    let mut by_appearance: Vec<Vec<(u32, u32, u32)>> = vec![Vec::new(); num_appearances];
    for (ii, obs) in observations.iter().enumerate() {
        for &(pi, kp) in &obs.seen {
            by_appearance[points[pi as usize].appearance as usize].push((ii as u32, kp, pi));
        }
    }
    let mut conn = Connection::open(database_path)
        .with_context(|| format!("creating {}", database_path.display()))?;
    conn.execute_batch(include_str!("../../../sql/colmap-3.8.sql"))
        .context("creating the COLMAP 3.8 schema")?;
    let tx = conn.transaction()?;
    let k = Matrix3::new(
        spec.focal,
        0.0,
        spec.width as f64 / 2.0,
        0.0,
        spec.focal,
        spec.height as f64 / 2.0,
        0.0,
        0.0,
        1.0,
    );
    let mut pairs_gt = Vec::new();
    {
        let mut stored_params = camera.params.clone();
        stored_params[0] = spec.stored_focal.unwrap_or(spec.focal);
        tx.execute(
            "INSERT INTO cameras(camera_id, model, width, height, params, prior_focal_length) \
             VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
            params![
                camera.camera_id,
                camera.model_id,
                camera.width,
                camera.height,
                f64_blob(&stored_params),
                spec.stored_focal.is_none()
            ],
        )?;
        let mut ins_image =
            tx.prepare("INSERT INTO images(image_id, name, camera_id) VALUES (?1, ?2, ?3)")?;
        let mut ins_kp =
            tx.prepare("INSERT INTO keypoints(image_id, rows, cols, data) VALUES (?1, ?2, 6, ?3)")?;
        let mut ins_desc = tx.prepare(
            "INSERT INTO descriptors(image_id, rows, cols, data) VALUES (?1, ?2, 128, ?3)",
        )?;
        for (im, obs) in images.iter().zip(&observations) {
            ins_image.execute(params![im.image_id, im.name, camera.camera_id])?;
            let mut blob = Vec::with_capacity(obs.keypoints.len() * 24);
            for kp in &obs.keypoints {
                let scale: f32 = rng.gen_range(1.5..6.0);
                let angle: f32 = rng.gen_range(0.0..std::f32::consts::TAU);
                let (s, c) = angle.sin_cos();
                for v in [kp[0], kp[1], scale * c, -scale * s, scale * s, scale * c] {
                    blob.extend_from_slice(&v.to_le_bytes());
                }
            }
            ins_kp.execute(params![im.image_id, obs.keypoints.len(), blob])?;
            if spec.random_descriptors {
                let mut d = vec![0u8; obs.keypoints.len() * 128];
                rng.fill(&mut d[..]);
                ins_desc.execute(params![im.image_id, obs.keypoints.len(), d])?;
            } else {
                ins_desc.execute(params![im.image_id, 0, None::<Vec<u8>>])?;
            }
        }

        let mut ins_match =
            tx.prepare("INSERT INTO matches(pair_id, rows, cols, data) VALUES (?1, ?2, 2, ?3)")?;
        let mut ins_tvg = tx.prepare(
            "INSERT INTO two_view_geometries(pair_id, rows, cols, data, config, F, E, H, qvec, tvec) \
             VALUES (?1, ?2, 2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
        )?;
        let write_failed = |ins_match: &mut rusqlite::Statement,
                            ins_tvg: &mut rusqlite::Statement,
                            pair_id: u64,
                            matches: &[[u32; 2]]|
         -> Result<()> {
            let data = (!matches.is_empty()).then(|| pairs_blob(matches));
            ins_match.execute(params![pair_id, matches.len(), data])?;
            let null = None::<Vec<u8>>;
            ins_tvg.execute(params![pair_id, 0, null, 0, null, null, null, null, null])?;
            Ok(())
        };
        let n = images.len() as u32;
        let mut buckets: Vec<Vec<Correspondence>> = vec![Vec::new(); n as usize];
        for a in 0..n {
            for bucket in &mut buckets {
                bucket.clear();
            }
            for &(pa, ka) in &observations[a as usize].seen {
                let group = &by_appearance[points[pa as usize].appearance as usize];
                for &(ib, kb, pb) in group {
                    if ib > a {
                        let class = if pa == pb {
                            0
                        } else {
                            1 + 8 * points[pa as usize].copy + points[pb as usize].copy
                        };
                        buckets[ib as usize].push((ka, kb, class));
                    }
                }
            }
            for b in a + 1..n {
                let id1 = images[a as usize].image_id as u64;
                let id2 = images[b as usize].image_id as u64;
                let pair_id = ids::pair_id(id1 as u32, id2 as u32);
                let corr = &buckets[b as usize];
                if corr.is_empty() {
                    if spec.all_pairs {
                        write_failed(&mut ins_match, &mut ins_tvg, pair_id, &[])?;
                    }
                    continue;
                }
                // One-to-one, as COLMAP's cross-checked matching produces.
                let mut used1 = HashSet::new();
                let mut used2 = HashSet::new();
                let mut matches: Vec<[u32; 2]> = Vec::new();
                let mut classes: Vec<u32> = Vec::new();
                let mut true_ones: Vec<[u32; 2]> = Vec::new();
                for &(k1, k2, class) in corr {
                    if !used1.contains(&k1) && !used2.contains(&k2) {
                        used1.insert(k1);
                        used2.insert(k2);
                        matches.push([k1, k2]);
                        classes.push(class);
                        if class == 0 {
                            true_ones.push([k1, k2]);
                        }
                    }
                }
                // Inliers: the largest motion (RANSAC cannot tell duplicates apart, it keeps
                // the best-supported motion) minus a few it would miss.
                let mut sizes = std::collections::BTreeMap::new();
                for &c in &classes {
                    *sizes.entry(c).or_insert(0usize) += 1;
                }
                let largest = sizes
                    .iter()
                    .max_by_key(|(c, n)| (**n, std::cmp::Reverse(**c)));
                let largest = largest.map_or(0, |(c, _)| *c);
                let drop = spec.inlier_drop_fraction.clamp(0.0, 1.0);
                let mut inliers: Vec<[u32; 2]> = matches
                    .iter()
                    .zip(&classes)
                    .filter(|(_, &c)| !rng.gen_bool(drop) && c == largest)
                    .map(|(m, _)| *m)
                    .collect();
                inliers.sort_unstable();
                let num_kp1 = observations[a as usize].keypoints.len() as u32;
                let num_kp2 = observations[b as usize].keypoints.len() as u32;
                let want = (matches.len() as f64 * spec.outlier_fraction
                    / (1.0 - spec.outlier_fraction))
                    .round() as usize;
                // Rejection sampling of unused keypoints, bounded for nearly full images.
                let (mut added, mut attempts) = (0, 0);
                while added < want && attempts < 20 * want + 100 {
                    attempts += 1;
                    let k1 = rng.gen_range(0..num_kp1);
                    let k2 = rng.gen_range(0..num_kp2);
                    if !used1.contains(&k1) && !used2.contains(&k2) {
                        used1.insert(k1);
                        used2.insert(k2);
                        matches.push([k1, k2]);
                        added += 1;
                    }
                }
                matches.shuffle(&mut rng);
                let same_point: HashSet<[u32; 2]> = true_ones.iter().copied().collect();
                let num_true_inliers = inliers.iter().filter(|m| same_point.contains(*m)).count();
                let mut gt = GtPair {
                    image_id1: id1 as u32,
                    image_id2: id2 as u32,
                    num_true: true_ones.len(),
                    num_matches: matches.len(),
                    num_inliers: 0,
                    true_pair: false,
                };
                if inliers.len() < spec.min_num_inliers {
                    write_failed(&mut ins_match, &mut ins_tvg, pair_id, &matches)?;
                } else {
                    let (ia, ib) = (&images[a as usize], &images[b as usize]);
                    let (e, f, h) = pair_geometry(&k, ia, ib);
                    let (qvec, tvec) = if spec.relative_pose {
                        let (r, t) = relative_pose(ia, ib);
                        let q = UnitQuaternion::from_rotation_matrix(&r);
                        let t = t.normalize();
                        (vec![q.w, q.i, q.j, q.k], vec![t.x, t.y, t.z])
                    } else {
                        (vec![0.0; 4], vec![0.0; 3])
                    };
                    ins_match.execute(params![pair_id, matches.len(), pairs_blob(&matches)])?;
                    let (config, e) = match spec.stored_focal {
                        None => (TwoViewConfig::Calibrated.code(), Some(matrix_blob(&e))),
                        Some(_) => (TwoViewConfig::Uncalibrated.code(), None),
                    };
                    ins_tvg.execute(params![
                        pair_id,
                        inliers.len(),
                        pairs_blob(&inliers),
                        config,
                        matrix_blob(&f),
                        e,
                        matrix_blob(&h),
                        f64_blob(&qvec),
                        f64_blob(&tvec)
                    ])?;
                    gt.num_inliers = inliers.len();
                    gt.true_pair = 2 * num_true_inliers >= inliers.len();
                }
                pairs_gt.push(gt);
            }
        }
    }
    tx.commit()?;
    Ok(GroundTruth {
        camera,
        images,
        pairs: pairs_gt,
    })
}

/// Writes the ground truth as a COLMAP text model (cameras.txt, images.txt with empty 2D-point
/// lines, empty points3D.txt), e.g. for `colmap model_aligner` or `model_comparer`.
pub fn write_gt_model(gt: &GroundTruth, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let c = &gt.camera;
    let mut cameras = String::from(
        "# Camera list with one line of data per camera:\n\
         #   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n\
         # Number of cameras: 1\n",
    );
    write!(
        cameras,
        "{} SIMPLE_RADIAL {} {}",
        c.camera_id, c.width, c.height
    )?;
    for p in &c.params {
        write!(cameras, " {p}")?;
    }
    cameras.push('\n');
    let mut images = format!(
        "# Image list with two lines of data per image:\n\
         #   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n\
         #   POINTS2D[] as (X, Y, POINT3D_ID)\n\
         # Number of images: {}, mean observations per image: 0\n",
        gt.images.len()
    );
    for im in &gt.images {
        let q = UnitQuaternion::from_rotation_matrix(&im.rotation);
        let t = im.translation;
        writeln!(
            images,
            "{} {} {} {} {} {} {} {} {} {}\n",
            im.image_id, q.w, q.i, q.j, q.k, t.x, t.y, t.z, c.camera_id, im.name
        )?;
    }
    let points = "# 3D point list with one line of data per point:\n\
                  #   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n\
                  # Number of points: 0, mean track length: 0\n";
    for (name, text) in [
        ("cameras.txt", cameras.as_str()),
        ("images.txt", images.as_str()),
        ("points3D.txt", points),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}
