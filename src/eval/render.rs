//! Rendered test scenes: PNG images with exactly known camera poses, for running the real
//! COLMAP pipeline (SIFT, matching, mapper) end to end and scoring the result with `eval`.
//!
//! A scene is a set of axis-aligned boxes (the room is a box seen from inside) with procedural
//! textures: multi-octave value noise under random high-contrast discs at three scales, which
//! gives SIFT many distinctive blobs on every surface. Textures live in each face's own metric
//! coordinates, so two boxes with the same texture seeds look identical wherever they stand —
//! which is how the duplicate-structure scene makes its twin objects.
//!
//! Images are ray cast with 2x2 supersampling through one SIMPLE_RADIAL camera with k = 0
//! (COLMAP's pixel convention: the centre of pixel (i, j) is at (i + 0.5, j + 0.5)); the ground
//! truth is written as a COLMAP text model. Everything is deterministic from the seed, and the
//! ground-truth folder also gets `scene.json` ([`SceneRecord`]: design, images, seed; and a
//! fingerprint of the surfaces), from which [`Scene::load`] rebuilds the scene's surfaces: the
//! exact pair labels cast rays into them (`eval::surface_truth`).

use crate::colmap::ids::SIMPLE_RADIAL;
use crate::eval::synth::scene::look_at;
use crate::eval::synth::{write_gt_model, GroundTruth, GtCamera, GtImage};
use crate::named::Named;
use anyhow::{ensure, Context, Result};
use nalgebra::{Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};
use std::path::Path;

/// Image width of the rendered scenes (pixels), the test size.
pub const WIDTH: u32 = 480;
/// Image height of the rendered scenes (pixels).
pub const HEIGHT: u32 = 360;
/// Focal length in pixels (a 62-degree horizontal field of view).
pub const FOCAL: f64 = 400.0;

/// Which scene to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SceneKind {
    /// One object (a stack of boxes) in a room, cameras on a closed orbit around it.
    Room,
    /// Two identical objects in the two halves of a long room whose walls differ; each object is
    /// half-orbited the same way, and a sideways walk along the room links the two orbits.
    Duplicate,
    /// Two identical objects far apart on a textured ground under a black sky, each orbited all
    /// round from close by (the views share little ground beyond their own object's), linked
    /// only by a few views on a walk from one to the other past three boxes; in capture order
    /// (first orbit, walk, second orbit).
    Twin,
    /// One object whose opposite faces carry the same textures and whose top sits centred, so
    /// that views half an orbit apart look alike, alone under a black sky and on black ground,
    /// orbited all round: the orbit's continuity is the only evidence against folding it.
    Symmetric,
    /// A row of identical buildings along a street (one facade texture, a period of
    /// [`STREET_PERIOD`] metres) in front of a far wall of its own, walked past by cameras that
    /// translate along the row looking at it (small turns): views one or two buildings apart
    /// match copy to copy, and as the translation runs along the repetition those matches fit
    /// the true epipolar geometry with rays that meet in front of both cameras.
    Street,
    /// The duplicate's room and objects, each object orbited all round (as the twin's, but
    /// indoors: every view has walls behind its object, and the halves' walls differ), the two
    /// orbits linked by a short walk along the room's side; in capture order (first orbit,
    /// walk, second orbit). Views of the two objects from the same side match copy to copy.
    Hall,
    /// Two identical objects side by side in one room ([`ADJACENT_GAP`] metres between their
    /// centres), each half-orbited from the front, first one then the other: most views show
    /// both, and the copies share the room behind them (the same walls, three boxes of their
    /// own), as the lab photographs' cans and cereal boxes do; views of the two objects from
    /// the same angle differ only in what stands beside and behind them.
    Adjacent,
    /// The adjacent design in a plain room (walls and floor of one flat grey): only the objects
    /// and the three boxes carry features, so the copies' surroundings hold little to tell them
    /// apart, as in the lab photographs (cans and boxes before bare walls).
    Plain,
}

/// The texture seed of a surface of one flat grey, on which SIFT finds nothing.
const FLAT: u64 = u64::MAX;

/// Distance in metres between the adjacent design's two objects (each 1.2 m wide).
pub const ADJACENT_GAP: f64 = 3.0;

/// Distance in metres from one building of the street to the next (3 m wide, 2 m gaps).
pub const STREET_PERIOD: f64 = 5.0;

/// Buildings in the street's row, the first with its corner at the origin.
pub const STREET_BUILDINGS: usize = 6;

impl Named for SceneKind {
    const ALL: &'static [SceneKind] = &[
        SceneKind::Room,
        SceneKind::Duplicate,
        SceneKind::Twin,
        SceneKind::Symmetric,
        SceneKind::Street,
        SceneKind::Hall,
        SceneKind::Adjacent,
        SceneKind::Plain,
    ];

    fn name(self) -> &'static str {
        match self {
            SceneKind::Room => "room",
            SceneKind::Duplicate => "duplicate",
            SceneKind::Twin => "twin",
            SceneKind::Symmetric => "symmetric",
            SceneKind::Street => "street",
            SceneKind::Hall => "hall",
            SceneKind::Adjacent => "adjacent",
            SceneKind::Plain => "plain",
        }
    }

    fn help(self) -> &'static str {
        match self {
            SceneKind::Room => "One object in a room, cameras orbiting it",
            SceneKind::Duplicate => "Two identical objects in differently textured halves of a room, each half-orbited, linked by a walk",
            SceneKind::Twin => "Two identical objects far apart, each orbited all round, linked by a walk past three boxes",
            SceneKind::Symmetric => "One object that looks the same from opposite sides, orbited all round",
            SceneKind::Street => "A row of identical buildings walked past by cameras translating along it",
            SceneKind::Hall => "Two identical objects in differently textured halves of a room, each orbited all round, linked by a walk",
            SceneKind::Adjacent => "Two identical objects side by side in one room, each half-orbited from the front: the copies share their surroundings",
            SceneKind::Plain => "The adjacent design in a room without texture: little but the objects to match, as in the lab photographs",
        }
    }
}

/// What a rendered scene is rebuilt from (`gt/scene.json`): [`Scene::build`]'s arguments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SceneRecord {
    /// The design.
    pub kind: SceneKind,
    /// Number of cameras.
    pub num_images: usize,
    /// The seed of textures and camera jitter.
    pub seed: u64,
}

/// The file name of the [`SceneRecord`] in a ground-truth folder.
pub const SCENE_RECORD: &str = "scene.json";

/// What `scene.json` holds: the record, and a fingerprint of the surfaces it built (so that a
/// renderer whose geometry changed since is noticed even where its cameras did not move).
#[derive(Serialize, Deserialize)]
struct RecordFile {
    #[serde(flatten)]
    record: SceneRecord,
    /// [`Scene::surfaces_fingerprint`] in hex.
    surfaces: String,
}

/// An axis-aligned box; `inside` boxes (the room) are seen from within.
#[derive(Clone, Debug)]
struct Cuboid {
    min: Vector3<f64>,
    max: Vector3<f64>,
    /// Texture seed of each face: -x, +x, -y, +y, -z, +z.
    faces: [u64; 6],
    /// Texture seeds where x >= 0 (a room whose two halves differ); `faces` elsewhere.
    east: [u64; 6],
    inside: bool,
    /// Textures of the +x and +y faces run the other way round and the top's are folded about
    /// its centre, so that a box whose opposite faces share their seeds looks the same after
    /// half a turn about the vertical (without it the opposite face would be the mirror image,
    /// which SIFT does not match).
    half_turn: bool,
}

/// A scene and the cameras that look at it.
#[derive(Clone, Debug)]
pub struct Scene {
    cuboids: Vec<Cuboid>,
    /// What the scene was built from.
    pub record: SceneRecord,
    /// The cameras' true poses and the shared camera, written as the `gt` model.
    pub truth: GroundTruth,
}

fn hash(mut x: u64) -> u64 {
    // splitmix64 finaliser: a cheap, well-mixed hash of lattice coordinates.
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

fn hash3(seed: u64, i: i64, j: i64) -> u64 {
    hash(seed ^ hash((i as u64) ^ hash(j as u64).rotate_left(17)))
}

/// Uniform in [0, 1) from a hash.
fn unit(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Smoothly interpolated lattice noise in [0, 1].
fn value_noise(seed: u64, u: f64, v: f64) -> f64 {
    let (i, j) = (u.floor(), v.floor());
    let (fu, fv) = (u - i, v - j);
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (i, j) = (i as i64, j as i64);
    let at = |a: i64, b: i64| unit(hash3(seed, i + a, j + b));
    let top = at(0, 0) + (at(1, 0) - at(0, 0)) * s(fu);
    let bottom = at(0, 1) + (at(1, 1) - at(0, 1)) * s(fu);
    top + (bottom - top) * s(fv)
}

/// Grey level in [0, 1] of texture `seed` at face coordinates (u, v) in metres.
fn texture(seed: u64, u: f64, v: f64) -> f64 {
    if seed == FLAT {
        return 0.5;
    }
    let mut grey = 0.0;
    let mut weight = 0.5;
    for octave in 0..5 {
        let scale = 2.0 * (1u64 << octave) as f64;
        grey += weight * value_noise(seed ^ octave, u * scale, v * scale);
        weight *= 0.5;
    }
    grey = 0.25 + 0.5 * grey;
    // Discs: one per cell, at random position, radius and polarity, on three cell sizes.
    for (level, cell) in [0.4f64, 0.17, 0.07].into_iter().enumerate() {
        let (cu, cv) = (u / cell, v / cell);
        let (ci, cj) = (cu.floor() as i64, cv.floor() as i64);
        for di in -1..=1 {
            for dj in -1..=1 {
                let h = hash3(seed ^ (0x5151 + level as u64), ci + di, cj + dj);
                if unit(h) < 0.45 {
                    continue;
                }
                let x = (ci + di) as f64 + unit(hash(h ^ 1));
                let y = (cj + dj) as f64 + unit(hash(h ^ 2));
                let r = 0.15 + 0.3 * unit(hash(h ^ 3));
                let d2 = (cu - x).powi(2) + (cv - y).powi(2);
                if d2 < r * r {
                    grey = if hash(h ^ 4) & 1 == 0 { 0.05 } else { 0.95 };
                }
            }
        }
    }
    grey
}

impl Cuboid {
    fn new(min: [f64; 3], max: [f64; 3], faces: [u64; 6]) -> Cuboid {
        Cuboid {
            min: Vector3::from(min),
            max: Vector3::from(max),
            faces,
            east: faces,
            inside: false,
            half_turn: false,
        }
    }

    /// Distance along the ray to the surface and the face hit (axis, 0 for the min side).
    fn hit(&self, origin: &Vector3<f64>, dir: &Vector3<f64>) -> Option<(f64, usize, usize)> {
        let (mut near, mut far) = ((f64::NEG_INFINITY, 0, 0), (f64::INFINITY, 0, 0));
        for a in 0..3 {
            let inv = 1.0 / dir[a];
            let t0 = (self.min[a] - origin[a]) * inv;
            let t1 = (self.max[a] - origin[a]) * inv;
            let (lo, hi) = if t0 < t1 {
                ((t0, a, 0), (t1, a, 1))
            } else {
                ((t1, a, 1), (t0, a, 0))
            };
            if lo.0 > near.0 {
                near = lo;
            }
            if hi.0 < far.0 {
                far = hi;
            }
        }
        if near.0 > far.0 {
            return None;
        }
        let hit = if self.inside { far } else { near };
        (hit.0 > 1e-9).then_some(hit)
    }
}

/// A camera's centre and the point it looks at.
type CameraAim = (Vector3<f64>, Vector3<f64>);

/// The random draws a scene is built from, each from its own generator so that the textures do
/// not depend on the cameras: the object's textures, then one per further box; the cameras'
/// jitter.
struct Draws {
    /// Texture seeds, seeded with the scene's seed.
    textures: ChaCha8Rng,
    /// Camera jitter, seeded with the scene's seed ^ 0xC0FFEE.
    cameras: ChaCha8Rng,
    /// Texture seeds of the object's block.
    object_tex: [u64; 6],
    /// Texture seeds of the box on top of the block.
    top_tex: [u64; 6],
}

impl Draws {
    fn new(seed: u64) -> Draws {
        let mut textures = ChaCha8Rng::seed_from_u64(seed);
        let mut tex = || -> [u64; 6] { std::array::from_fn(|_| textures.gen()) };
        let (object_tex, top_tex) = (tex(), tex());
        Draws {
            textures,
            cameras: ChaCha8Rng::seed_from_u64(seed ^ 0xC0FFEE),
            object_tex,
            top_tex,
        }
    }

    /// The next box's texture seeds.
    fn tex(&mut self) -> [u64; 6] {
        std::array::from_fn(|_| self.textures.gen())
    }

    /// A random horizontal offset of up to `s / 2` along x and y.
    fn jitter(&mut self, s: f64) -> Vector3<f64> {
        let rng = &mut self.cameras;
        Vector3::new(rng.gen::<f64>() - 0.5, rng.gen::<f64>() - 0.5, 0.0) * s
    }

    /// The object: a table-high block with a smaller box on it, offset so no view is symmetric.
    fn object(&self, x: f64, y: f64) -> Vec<Cuboid> {
        vec![
            Cuboid::new(
                [x - 0.6, y - 0.4, 0.0],
                [x + 0.6, y + 0.4, 0.8],
                self.object_tex,
            ),
            Cuboid::new(
                [x - 0.5, y - 0.3, 0.8],
                [x + 0.1, y + 0.2, 1.3],
                self.top_tex,
            ),
        ]
    }

    /// `n` cameras around the object at (x, 0), on angles [from, from + span) (radians).
    fn orbit(&mut self, poses: &mut Vec<CameraAim>, x: f64, n: usize, from: f64, span: f64) {
        for k in 0..n {
            let a = from + span * k as f64 / n as f64;
            let centre = Vector3::new(x + 2.8 * a.cos(), 2.8 * a.sin(), 1.6) + self.jitter(0.2);
            poses.push((centre, Vector3::new(x, 0.0, 0.7) + self.jitter(0.2)));
        }
    }
}

/// [`SceneKind::Room`]: its boxes and `num_images` cameras.
fn room(draws: &mut Draws, num_images: usize) -> (Vec<Cuboid>, Vec<CameraAim>) {
    let (mut cuboids, mut poses) = (Vec::new(), Vec::new());
    let mut room = Cuboid::new([-5.0, -5.0, 0.0], [5.0, 5.0, 3.5], draws.tex());
    room.inside = true;
    cuboids.push(room);
    cuboids.extend(draws.object(0.0, 0.0));
    cuboids.push(Cuboid::new([2.0, 3.0, 0.0], [3.5, 4.0, 1.0], draws.tex()));
    cuboids.push(Cuboid::new(
        [-4.0, -3.5, 0.0],
        [-3.0, -2.0, 1.5],
        draws.tex(),
    ));
    draws.orbit(&mut poses, 0.0, num_images, 0.0, TAU);
    (cuboids, poses)
}

/// [`SceneKind::Twin`]: its boxes and `num_images` cameras.
fn twin(draws: &mut Draws, num_images: usize) -> (Vec<Cuboid>, Vec<CameraAim>) {
    let (mut cuboids, mut poses) = (Vec::new(), Vec::new());
    let mut ground = Cuboid::new([-16.0, -10.0, -1.0], [16.0, 10.0, 0.0], draws.tex());
    ground.east = draws.tex();
    cuboids.push(ground);
    cuboids.extend(draws.object(-7.0, 0.0));
    cuboids.extend(draws.object(7.0, 0.0));
    // Three boxes of their own between the objects: what a walk from one object to
    // the other passes (the ground's texture alone barely matches: its discs look
    // alike to SIFT's ratio test).
    for x in [-3.2, 0.0, 3.2] {
        cuboids.push(Cuboid::new(
            [x - 0.5, 0.5, 0.0],
            [x + 0.5, 1.5, 1.6],
            draws.tex(),
        ));
    }
    let links = (num_images / 7).max(2);
    let per_orbit = (num_images - links) / 2;
    draws.orbit(&mut poses, -7.0, per_orbit, 0.0, TAU);
    draws.orbit(&mut poses, 7.0, num_images - links - per_orbit, PI, TAU);
    // The walk, beside the orbits, looking across at the boxes: the first view sees
    // the first object, the last the second, each the boxes its neighbours see.
    // (Overview views from far back, as this scene had first, matched each other
    // only: SIFT did not bridge the 6x scale.)
    let walk: Vec<_> = (0..links)
        .map(|k| {
            let x = -4.2 + 8.4 * k as f64 / (links - 1) as f64;
            let centre = Vector3::new(x, -5.0, 1.6) + draws.jitter(0.2);
            (centre, Vector3::new(1.3 * x, 1.0, 0.6) + draws.jitter(0.2))
        })
        .collect();
    // In capture order: round the first object, the walk to the second, round it
    // from the side the walk ends on.
    poses.splice(per_orbit..per_orbit, walk);
    (cuboids, poses)
}

/// [`SceneKind::Symmetric`]: its boxes and `num_images` cameras.
fn symmetric(draws: &mut Draws, num_images: usize) -> (Vec<Cuboid>, Vec<CameraAim>) {
    let (mut cuboids, mut poses) = (Vec::new(), Vec::new());
    // Faces -x/+x and -y/+y share their seeds; the top box is centred.
    let [a, _, c, _, e, f] = draws.object_tex;
    let [ta, _, tc, _, te, tf] = draws.top_tex;
    for (min, max, faces) in [
        ([-0.6, -0.4, 0.0], [0.6, 0.4, 0.8], [a, a, c, c, e, f]),
        (
            [-0.3, -0.25, 0.8],
            [0.3, 0.25, 1.3],
            [ta, ta, tc, tc, te, tf],
        ),
    ] {
        let mut part = Cuboid::new(min, max, faces);
        part.half_turn = true;
        cuboids.push(part);
    }
    draws.orbit(&mut poses, 0.0, num_images, 0.0, TAU);
    (cuboids, poses)
}

/// The duplicate's and the hall's boxes: a long room whose halves (x < 0, x > 0) have their own
/// wall textures, the same object in the middle of each half.
fn two_halves(draws: &mut Draws) -> Vec<Cuboid> {
    let mut room = Cuboid::new([-10.0, -4.0, 0.0], [10.0, 4.0, 3.5], draws.tex());
    room.east = draws.tex();
    room.inside = true;
    let mut cuboids = vec![room];
    cuboids.extend(draws.object(-5.0, 0.0));
    cuboids.extend(draws.object(5.0, 0.0));
    cuboids
}

/// [`SceneKind::Duplicate`]: its boxes and `num_images` cameras.
fn duplicate(draws: &mut Draws, num_images: usize) -> (Vec<Cuboid>, Vec<CameraAim>) {
    let (cuboids, mut poses) = (two_halves(draws), Vec::new());
    let walk = (num_images / 4).max(2);
    let per_orbit = (num_images - walk) / 2;
    // Half orbits on the walk's side, so the walk sees what the orbits see.
    draws.orbit(&mut poses, -5.0, per_orbit, 1.1 * PI, 0.8 * PI);
    draws.orbit(
        &mut poses,
        5.0,
        num_images - walk - per_orbit,
        1.1 * PI,
        0.8 * PI,
    );
    for k in 0..walk {
        let x = -6.0 + 12.0 * k as f64 / (walk - 1) as f64;
        let centre = Vector3::new(x, -3.5, 1.6) + draws.jitter(0.2);
        poses.push((centre, Vector3::new(x, 4.0, 1.2) + draws.jitter(0.4)));
    }
    (cuboids, poses)
}

/// [`SceneKind::Hall`]: its boxes and `num_images` cameras.
fn hall(draws: &mut Draws, num_images: usize) -> (Vec<Cuboid>, Vec<CameraAim>) {
    let (cuboids, mut poses) = (two_halves(draws), Vec::new());
    let walk = (num_images / 8).max(2);
    let per_orbit = (num_images - walk) / 2;
    draws.orbit(&mut poses, -5.0, per_orbit, 0.0, TAU);
    // The walk along the room's -y side, looking across it, from the first object's orbit to
    // the second's; the second orbit starts on the side the walk ends on.
    for k in 0..walk {
        let x = -3.0 + 6.0 * k as f64 / (walk - 1) as f64;
        let centre = Vector3::new(x, -3.2, 1.6) + draws.jitter(0.2);
        poses.push((centre, Vector3::new(1.5 * x, 0.0, 0.8) + draws.jitter(0.4)));
    }
    draws.orbit(
        &mut poses,
        5.0,
        num_images - walk - per_orbit,
        1.5 * PI,
        TAU,
    );
    (cuboids, poses)
}

/// [`SceneKind::Adjacent`], or with a `plain` room [`SceneKind::Plain`]: its boxes and
/// `num_images` cameras (the same textures and cameras either way).
fn adjacent(draws: &mut Draws, num_images: usize, plain: bool) -> (Vec<Cuboid>, Vec<CameraAim>) {
    // Drawn either way, so that both designs get the same objects' and boxes' textures.
    let walls = draws.tex();
    let walls = if plain { [FLAT; 6] } else { walls };
    let mut room = Cuboid::new([-7.0, -5.0, 0.0], [7.0, 5.0, 3.5], walls);
    room.inside = true;
    let (a, b) = (-ADJACENT_GAP / 2.0, ADJACENT_GAP / 2.0);
    let mut cuboids = vec![room];
    cuboids.extend(draws.object(a, 0.0));
    cuboids.extend(draws.object(b, 0.0));
    // What only the room holds once: a box between the objects and behind them, one behind
    // each side; each view of an object shows some of them, at places its copy's views do not.
    for (min, max) in [
        ([-0.3, 1.6, 0.0], [0.3, 2.2, 1.0]),
        ([-4.2, 1.0, 0.0], [-3.4, 2.0, 1.4]),
        ([3.0, 2.2, 0.0], [4.2, 2.8, 0.7]),
    ] {
        cuboids.push(Cuboid::new(min, max, draws.tex()));
    }
    // Half orbits on the front (-y) side, the same angles round each object, so that views of
    // the two from one angle match copy to copy.
    let per_orbit = num_images / 2;
    let mut poses = Vec::new();
    draws.orbit(&mut poses, a, per_orbit, 1.15 * PI, 0.7 * PI);
    draws.orbit(&mut poses, b, num_images - per_orbit, 1.15 * PI, 0.7 * PI);
    (cuboids, poses)
}

/// [`SceneKind::Street`]: its boxes and `num_images` cameras.
fn street(draws: &mut Draws, num_images: usize) -> (Vec<Cuboid>, Vec<CameraAim>) {
    let length = STREET_PERIOD * STREET_BUILDINGS as f64;
    // The ground and the wall behind the row each carry one texture of their own over the whole
    // street: they differ from place to place, the facades do not.
    let mut cuboids = vec![
        Cuboid::new(
            [-12.0, -16.0, -1.0],
            [length + 12.0, 20.0, 0.0],
            draws.tex(),
        ),
        Cuboid::new([-12.0, 9.0, 0.0], [length + 12.0, 10.0, 9.0], draws.tex()),
    ];
    let facade = draws.tex();
    for k in 0..STREET_BUILDINGS {
        let x = STREET_PERIOD * k as f64;
        cuboids.push(Cuboid::new([x, 0.0, 0.0], [x + 3.0, 3.0, 3.8], facade));
    }
    // The walk: along the row 8 m in front of it, from the first building to the last, the
    // cameras looking level across at the facades (the wall shows above and between them),
    // turned a little by the aim's jitter. Measured variants (seed 1, COLMAP 3.8): 6 m away with
    // 4.5 m buildings a period of 4 m apart, or 8 m with 4.5 m ones, most pairs of overlapping
    // views verify on the copy one building along and even the true pairs alone do not give
    // one correct model; with 3 m buildings COLMAP does not ghost the full database.
    let poses = (0..num_images)
        .map(|k| {
            let x = (length - 1.0) * k as f64 / (num_images - 1) as f64;
            let centre = Vector3::new(x, -8.0, 1.6) + draws.jitter(0.2);
            let aim = Vector3::new(x, 3.0, 1.6) + draws.jitter(0.5);
            (centre, aim)
        })
        .collect();
    (cuboids, poses)
}

/// The ground truth of cameras at `poses` (in order, named `0000.png`, ...), all the one
/// rendering camera.
fn ground_truth(poses: &[CameraAim]) -> GroundTruth {
    let images = poses
        .iter()
        .enumerate()
        .map(|(k, (centre, target))| {
            let rotation = look_at(centre, target);
            GtImage {
                image_id: k as u32 + 1,
                name: format!("{k:04}.png"),
                translation: -(rotation * centre),
                rotation,
                centre: *centre,
            }
        })
        .collect();
    let camera = GtCamera {
        camera_id: 1,
        model_id: SIMPLE_RADIAL,
        width: WIDTH,
        height: HEIGHT,
        params: vec![FOCAL, WIDTH as f64 / 2.0, HEIGHT as f64 / 2.0, 0.0],
    };
    GroundTruth {
        camera,
        images,
        pairs: Vec::new(),
    }
}

impl Scene {
    /// Builds `kind` with `num_images` cameras; `seed` jitters the cameras and picks textures.
    pub fn build(kind: SceneKind, num_images: usize, seed: u64) -> Result<Scene> {
        ensure!(num_images >= 4, "a rendered scene needs at least 4 images");
        let mut draws = Draws::new(seed);
        let (cuboids, poses) = match kind {
            SceneKind::Room => room(&mut draws, num_images),
            SceneKind::Twin => twin(&mut draws, num_images),
            SceneKind::Symmetric => symmetric(&mut draws, num_images),
            SceneKind::Duplicate => duplicate(&mut draws, num_images),
            SceneKind::Street => street(&mut draws, num_images),
            SceneKind::Hall => hall(&mut draws, num_images),
            SceneKind::Adjacent => adjacent(&mut draws, num_images, false),
            SceneKind::Plain => adjacent(&mut draws, num_images, true),
        };
        Ok(Scene {
            cuboids,
            record: SceneRecord {
                kind,
                num_images,
                seed,
            },
            truth: ground_truth(&poses),
        })
    }

    /// The scene a ground-truth folder was rendered from, rebuilt from its `scene.json`; None
    /// when there is none (a model not rendered here). The rebuilt cameras must be the folder's
    /// (by name, centres within a micrometre): a renderer that changed since would otherwise
    /// label pairs against surfaces the images never showed.
    pub fn load(gt: &Path) -> Result<Option<Scene>> {
        let path = gt.join(SCENE_RECORD);
        if !path.exists() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let file: RecordFile =
            serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
        let record = file.record;
        let scene = Scene::build(record.kind, record.num_images, record.seed)?;
        ensure!(
            file.surfaces == format!("{:016x}", scene.surfaces_fingerprint()),
            "{}: the surfaces rebuilt from it are not the ones rendered: the renderer changed \
             since, render again",
            path.display()
        );
        let written = crate::colmap::sparse::read_images(gt)?;
        for im in &written {
            let rebuilt = scene.truth.images.iter().find(|r| r.name == im.name);
            ensure!(
                rebuilt.is_some_and(|r| (r.centre - im.centre()).norm() < 1e-6),
                "{}: image {} is not where {} puts it: the renderer changed since, render again",
                gt.display(),
                im.name,
                path.display()
            );
        }
        Ok(Some(scene))
    }

    /// A hash of every box's corners, texture seeds and kind: what the labels' rays meet.
    fn surfaces_fingerprint(&self) -> u64 {
        let mut h = 0;
        for c in &self.cuboids {
            let corners = c.min.iter().chain(c.max.iter()).map(|v| v.to_bits());
            let flags = [c.inside as u64, c.half_turn as u64];
            for v in corners.chain(c.faces).chain(c.east).chain(flags) {
                h = hash(h ^ v);
            }
        }
        h
    }

    /// The first surface point along the ray from `origin` in direction `dir` (any length), if
    /// the ray hits one (the sky of the outdoor designs is none).
    pub fn surface_point(&self, origin: &Vector3<f64>, dir: &Vector3<f64>) -> Option<Vector3<f64>> {
        self.trace(origin, dir).map(|(t, ..)| origin + dir * t)
    }

    /// Whether surface point `point` is seen from `centre`: nothing nearer lies on the ray
    /// between (1 mm and a part in 10^6 of the distance to spare, for rounding).
    pub fn visible_from(&self, centre: &Vector3<f64>, point: &Vector3<f64>) -> bool {
        let to = point - centre;
        let distance = to.norm();
        self.trace(centre, &(to / distance))
            .is_none_or(|(t, ..)| t >= distance * (1.0 - 1e-6) - 1e-3)
    }

    /// The nearest surface along a ray: distance, box, face axis and side.
    fn trace(
        &self,
        origin: &Vector3<f64>,
        dir: &Vector3<f64>,
    ) -> Option<(f64, &Cuboid, usize, usize)> {
        let mut best: Option<(f64, &Cuboid, usize, usize)> = None;
        for c in &self.cuboids {
            if let Some((t, axis, side)) = c.hit(origin, dir) {
                if best.is_none_or(|b| t < b.0) {
                    best = Some((t, c, axis, side));
                }
            }
        }
        best
    }

    /// Grey level seen along a ray (Lambert shading by face, light fixed in the world).
    fn shade(&self, origin: &Vector3<f64>, dir: &Vector3<f64>) -> f64 {
        let Some((t, c, axis, side)) = self.trace(origin, dir) else {
            return 0.0;
        };
        let p = origin + dir * t;
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        let faces = if p.x >= 0.0 { &c.east } else { &c.faces };
        // Face coordinates; on a half-turn box the +x and +y faces count their horizontal one
        // from the far end, and the tops fold both about the centre (symmetric under the turn).
        let along = |k: usize| {
            let (from_min, from_max) = (p[k] - c.min[k], c.max[k] - p[k]);
            match (c.half_turn, axis) {
                (true, 2) => from_min.min(from_max),
                (true, _) if side == 1 && k < 2 => from_max,
                _ => from_min,
            }
        };
        let grey = texture(faces[2 * axis + side], along(a), along(b));
        let light = [0.75, 0.9, 0.6][axis] * if side == 0 { 0.85 } else { 1.0 };
        grey * light
    }

    /// Renders image `index` as 8-bit RGB rows (a slight warm tint; SIFT sees the grey).
    pub fn render(&self, index: usize) -> Vec<u8> {
        let im = &self.truth.images[index];
        let to_world: Rotation3<f64> = im.rotation.inverse();
        let (w, h) = (WIDTH as usize, HEIGHT as usize);
        let (cx, cy) = (WIDTH as f64 / 2.0, HEIGHT as f64 / 2.0);
        let mut rgb = vec![0u8; w * h * 3];
        rgb.par_chunks_mut(w * 3).enumerate().for_each(|(j, row)| {
            for i in 0..w {
                let mut sum = 0.0;
                for (du, dv) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
                    let x = (i as f64 + du - cx) / FOCAL;
                    let y = (j as f64 + dv - cy) / FOCAL;
                    sum += self.shade(&im.centre, &(to_world * Vector3::new(x, y, 1.0)));
                }
                let g = sum / 4.0 * 255.0;
                row[3 * i..3 * i + 3].copy_from_slice(&[
                    g.min(255.0) as u8,
                    (g * 0.95) as u8,
                    (g * 0.85) as u8,
                ]);
            }
        });
        rgb
    }

    /// Writes `dir/images/NNNN.png` and the ground truth as a COLMAP text model in `dir/gt`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let images = dir.join("images");
        std::fs::create_dir_all(&images)
            .with_context(|| format!("cannot create {}", images.display()))?;
        for (k, im) in self.truth.images.iter().enumerate() {
            let path = images.join(&im.name);
            let file = std::fs::File::create(&path)
                .with_context(|| format!("cannot create {}", path.display()))?;
            let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), WIDTH, HEIGHT);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder
                .write_header()
                .and_then(|mut w| w.write_image_data(&self.render(k)))
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        self.write_truth(&dir.join("gt"))
    }

    /// Writes the ground truth as a COLMAP text model in `gt` and the [`SceneRecord`] beside it.
    pub fn write_truth(&self, gt: &Path) -> Result<()> {
        write_gt_model(&self.truth, gt)?;
        let path = gt.join(SCENE_RECORD);
        let file = RecordFile {
            record: self.record,
            surfaces: format!("{:016x}", self.surfaces_fingerprint()),
        };
        std::fs::write(&path, serde_json::to_string_pretty(&file)? + "\n")
            .with_context(|| format!("writing {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The name `generate images --scene` takes is the one `gt/scene.json` records.
    #[test]
    fn each_design_is_named_as_its_record_names_it() {
        for &kind in SceneKind::ALL {
            let json = serde_json::to_string(&kind).unwrap();
            assert_eq!(json, format!("\"{}\"", kind.name()));
            assert_eq!(SceneKind::from_name(kind.name()), Some(kind));
        }
    }

    /// The world point seen at the centre of pixel (i, j) projects back onto that centre
    /// through the written ground truth: renderer and COLMAP model share one convention.
    #[test]
    fn ground_truth_projects_surface_points_to_their_pixels() {
        let scene = Scene::build(SceneKind::Duplicate, 8, 3).unwrap();
        let p = &scene.truth.camera.params;
        for im in &scene.truth.images {
            for (i, j) in [(0.5, 0.5), (100.5, 300.5), (479.5, 179.5)] {
                let ray =
                    im.rotation.inverse() * Vector3::new((i - p[1]) / p[0], (j - p[2]) / p[0], 1.0);
                let (t, ..) = scene.trace(&im.centre, &ray).expect("closed room");
                let x = im.rotation * (im.centre + ray * t) + im.translation;
                let (u, v) = (p[0] * x.x / x.z + p[1], p[0] * x.y / x.z + p[2]);
                assert!(
                    (u - i).abs() < 1e-6 && (v - j).abs() < 1e-6,
                    "{u} {v} vs {i} {j}"
                );
            }
        }
    }

    #[test]
    fn rendering_is_deterministic_and_seeded() {
        let a = Scene::build(SceneKind::Room, 4, 1).unwrap();
        let b = Scene::build(SceneKind::Room, 4, 1).unwrap();
        let c = Scene::build(SceneKind::Room, 4, 2).unwrap();
        assert_eq!(a.render(1), b.render(1));
        assert_ne!(a.render(1), c.render(1));
    }

    /// The two copies of the duplicate scene look the same: a texture depends on the face's own
    /// coordinates only, and both objects carry the same seeds.
    #[test]
    fn duplicate_objects_are_identical() {
        let scene = Scene::build(SceneKind::Duplicate, 8, 1).unwrap();
        let (a, b) = (&scene.cuboids[1], &scene.cuboids[3]);
        assert_eq!(a.faces, b.faces);
        assert_eq!(b.min - a.min, Vector3::new(10.0, 0.0, 0.0));
        let room = &scene.cuboids[0];
        assert_ne!(room.faces, room.east, "the halves of the room must differ");
    }

    /// The symmetric object looks the same after half a turn: each side face point and its
    /// turned twin have the same texture (the light differs by side, 0.85 against 1), and so do
    /// points of the top.
    #[test]
    fn symmetric_object_is_the_same_after_half_a_turn() {
        let scene = Scene::build(SceneKind::Symmetric, 8, 2).unwrap();
        let grey = |p: Vector3<f64>, outward: Vector3<f64>| scene.shade(&(p + outward), &-outward);
        let turn = |p: Vector3<f64>| Vector3::new(-p.x, -p.y, p.z);
        for (y, z) in [(-0.31, 0.1), (0.05, 0.42), (0.27, 0.77)] {
            let p = Vector3::new(-0.6, y, z);
            let (a, b) = (grey(p, -Vector3::x()), grey(turn(p), Vector3::x()));
            assert!((a / 0.85 - b).abs() < 1e-9, "x faces at {y} {z}: {a} {b}");
            let q = Vector3::new(y, -0.4, z);
            let (a, b) = (grey(q, -Vector3::y()), grey(turn(q), Vector3::y()));
            assert!((a / 0.85 - b).abs() < 1e-9, "y faces at {y} {z}: {a} {b}");
        }
        for (x, y) in [(-0.21, 0.13), (0.08, -0.2)] {
            let p = Vector3::new(x, y, 1.3);
            assert_eq!(grey(p, Vector3::z()), grey(turn(p), Vector3::z()));
        }
        // Not trivially: the faces are textured.
        let p = Vector3::new(-0.6, 0.0, 0.4);
        let samples: Vec<f64> = (0..20)
            .map(|k| grey(p + Vector3::y() * (k as f64 * 0.03), -Vector3::x()))
            .collect();
        assert!(samples.iter().any(|&g| (g - samples[0]).abs() > 0.1));
    }

    /// The twin scene's objects are identical and far apart, and its link views walk from one
    /// to the other: the first sees the first object, the last the second.
    #[test]
    fn twin_objects_are_identical_and_the_links_walk_between_them() {
        let scene = Scene::build(SceneKind::Twin, 36, 1).unwrap();
        let (a, b) = (&scene.cuboids[1], &scene.cuboids[3]);
        assert_eq!(a.faces, b.faces);
        assert_eq!(b.min - a.min, Vector3::new(14.0, 0.0, 0.0));
        let links = &scene.truth.images[15..20];
        let sees = |im: &GtImage, x: f64| {
            let c = im.rotation * Vector3::new(x, 0.0, 0.7) + im.translation;
            let (u, v) = (FOCAL * c.x / c.z + 240.0, FOCAL * c.y / c.z + 180.0);
            c.z > 0.0 && (0.0..480.0).contains(&u) && (0.0..360.0).contains(&v)
        };
        assert!(sees(&links[0], -7.0) && !sees(&links[0], 7.0));
        assert!(sees(&links[4], 7.0) && !sees(&links[4], -7.0));
        for w in links.windows(2) {
            assert!((w[1].centre - w[0].centre).norm() < 3.5);
        }
    }

    /// The hall's objects are identical, the room's halves are not, and its orbits go all round
    /// their own object, in capture order: first orbit, walk, second orbit.
    #[test]
    fn hall_orbits_go_round_identical_objects_in_different_halves() {
        let scene = Scene::build(SceneKind::Hall, 38, 1).unwrap();
        let (room, a, b) = (&scene.cuboids[0], &scene.cuboids[1], &scene.cuboids[3]);
        assert_eq!(a.faces, b.faces);
        assert_ne!(room.faces, room.east);
        assert_eq!(b.min - a.min, Vector3::new(10.0, 0.0, 0.0));
        let centres: Vec<_> = scene.truth.images.iter().map(|im| im.centre).collect();
        let round = |orbit: &[Vector3<f64>], x: f64| {
            let mut seen = [false; 4];
            for c in orbit {
                assert!(((c.x - x).hypot(c.y) - 2.8).abs() < 0.3);
                let quadrant = (c.y.atan2(c.x - x) + PI) / (PI / 2.0);
                seen[(quadrant as usize).min(3)] = true;
            }
            seen.iter().all(|&s| s)
        };
        assert!(round(&centres[..17], -5.0) && round(&centres[21..], 5.0));
        assert!(centres[17..21].iter().all(|c| (c.y + 3.2).abs() < 0.2));
    }

    /// The adjacent design's objects are identical and a gap apart in one room, and its two
    /// half orbits go round the front of their own object at the same angles, in capture order.
    #[test]
    fn adjacent_half_orbits_see_identical_objects_side_by_side() {
        let scene = Scene::build(SceneKind::Adjacent, 20, 1).unwrap();
        let (room, a, b) = (&scene.cuboids[0], &scene.cuboids[1], &scene.cuboids[3]);
        assert_eq!(a.faces, b.faces);
        assert_eq!(room.faces, room.east);
        assert_eq!(b.min - a.min, Vector3::new(ADJACENT_GAP, 0.0, 0.0));
        let centres: Vec<_> = scene.truth.images.iter().map(|im| im.centre).collect();
        for (k, c) in centres.iter().enumerate() {
            let x = if k < 10 { -ADJACENT_GAP } else { ADJACENT_GAP } / 2.0;
            assert!(
                ((c.x - x).hypot(c.y) - 2.8).abs() < 0.3 && c.y < -0.5,
                "{k}: {c}"
            );
        }
        for k in 0..10 {
            let step = centres[k + 10] - centres[k];
            assert!(
                (step - Vector3::x() * ADJACENT_GAP).norm() < 0.3,
                "{k}: {step}"
            );
        }
        // The plain design: the same cameras and boxes, the room one flat grey.
        let plain = Scene::build(SceneKind::Plain, 20, 1).unwrap();
        assert_eq!(plain.truth.images[7].centre, scene.truth.images[7].centre);
        assert_eq!(plain.cuboids[0].faces, [FLAT; 6]);
        assert_eq!(plain.cuboids.len(), scene.cuboids.len());
        assert!((0..50).all(|k| texture(FLAT, k as f64 * 0.1, 0.3) == 0.5));
    }

    /// The street's buildings are copies a period apart, and the cameras walk along the row.
    #[test]
    fn street_buildings_are_copies_along_the_walk() {
        let scene = Scene::build(SceneKind::Street, 20, 1).unwrap();
        let buildings = &scene.cuboids[2..];
        assert!(buildings.len() >= 5);
        for w in buildings.windows(2) {
            assert_eq!(w[0].faces, w[1].faces);
            let step = w[1].min - w[0].min;
            assert!((step - Vector3::x() * STREET_PERIOD).norm() < 1e-12);
        }
        let xs: Vec<f64> = scene.truth.images.iter().map(|im| im.centre.x).collect();
        assert!(xs.windows(2).all(|w| w[1] > w[0]));
        assert!(xs[19] - xs[0] > 3.0 * STREET_PERIOD);
    }

    /// The ground truth's scene.json rebuilds the scene, and a ground truth whose cameras or
    /// surfaces are not the rebuilt ones (a renderer changed since) is refused; without
    /// scene.json there is no scene.
    #[test]
    fn scene_record_rebuilds_the_scene_and_refuses_other_cameras() {
        let dir = tempfile::tempdir().unwrap();
        let gt = dir.path().join("gt");
        Scene::build(SceneKind::Twin, 8, 3)
            .unwrap()
            .write_truth(&gt)
            .unwrap();
        let scene = Scene::load(&gt).unwrap().expect("scene.json written");
        assert_eq!(scene.record.kind, SceneKind::Twin);
        assert_eq!((scene.record.num_images, scene.record.seed), (8, 3));
        let record = std::fs::read_to_string(gt.join(SCENE_RECORD)).unwrap();
        let moved = serde_json::from_str::<serde_json::Value>(&record).unwrap()["surfaces"]
            .as_str()
            .unwrap()
            .to_string();
        let changed = record.replace(&moved, "0123456789abcdef");
        std::fs::write(gt.join(SCENE_RECORD), changed).unwrap();
        let err = Scene::load(&gt).unwrap_err().to_string();
        assert!(
            err.contains("surfaces") && err.contains("render again"),
            "{err}"
        );
        std::fs::write(gt.join(SCENE_RECORD), record).unwrap();
        let other = Scene::build(SceneKind::Twin, 8, 4).unwrap();
        write_gt_model(&other.truth, &gt).unwrap();
        let err = Scene::load(&gt).unwrap_err().to_string();
        assert!(
            err.contains("is not where") && err.contains("render again"),
            "{err}"
        );
        std::fs::remove_file(gt.join(SCENE_RECORD)).unwrap();
        assert!(Scene::load(&gt).unwrap().is_none());
    }

    #[test]
    fn textures_have_contrast_at_feature_scales() {
        let samples: Vec<f64> = (0..400)
            .map(|k| texture(7, (k % 20) as f64 * 0.05, (k / 20) as f64 * 0.05))
            .collect();
        let dark = samples.iter().filter(|&&g| g < 0.2).count();
        let bright = samples.iter().filter(|&&g| g > 0.8).count();
        assert!(dark > 20 && bright > 20, "{dark} dark, {bright} bright");
    }
}
