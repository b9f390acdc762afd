//! A model made ready for the check: each registered image with its centre, its projection
//! (pinhole plus COLMAP's radial/tangential distortion) and a grid of its triangulated
//! keypoints; each 3D point with the images that observe it; with a database, the verified
//! matches between the registered images ([`super::evidence`]).

use super::evidence::{in_name_order, Evidence};
use crate::colmap::model::ModelCamera;
use crate::colmap::sparse::SparseModel;
use anyhow::{Context, Result};
use nalgebra::{Matrix3, Vector3};
use std::collections::{BTreeMap, HashMap};
use std::sync::OnceLock;

/// Intrinsics as a pinhole with up to two radial and two tangential coefficients (OpenCV's
/// meaning, which is COLMAP's for the models it names alike).
#[derive(Clone, Debug)]
pub struct Intrinsics {
    f: [f64; 2],
    c: [f64; 2],
    k: [f64; 2],
    p: [f64; 2],
    /// Image width in pixels.
    pub width: f64,
    /// Image height in pixels.
    pub height: f64,
}

impl Intrinsics {
    /// From a model camera; the fisheye and FOV models are taken as their pinhole part (their
    /// distortion shifts a projection by a few pixels at most where the check looks).
    pub fn from_camera(c: &ModelCamera) -> Intrinsics {
        let p = &c.params;
        let at = |k: usize| p.get(k).copied().unwrap_or(0.0);
        let (f, cc, k, t) = match c.model.as_str() {
            "SIMPLE_PINHOLE" => ([at(0); 2], [at(1), at(2)], [0.0; 2], [0.0; 2]),
            "PINHOLE" => ([at(0), at(1)], [at(2), at(3)], [0.0; 2], [0.0; 2]),
            "SIMPLE_RADIAL" => ([at(0); 2], [at(1), at(2)], [at(3), 0.0], [0.0; 2]),
            "RADIAL" => ([at(0); 2], [at(1), at(2)], [at(3), at(4)], [0.0; 2]),
            "OPENCV" | "FULL_OPENCV" => (
                [at(0), at(1)],
                [at(2), at(3)],
                [at(4), at(5)],
                [at(6), at(7)],
            ),
            _ if p.len() >= 4 && c.model.contains("OPENCV") => {
                ([at(0), at(1)], [at(2), at(3)], [0.0; 2], [0.0; 2])
            }
            _ => ([at(0); 2], [at(1), at(2)], [0.0; 2], [0.0; 2]),
        };
        Intrinsics {
            f,
            c: cc,
            k,
            p: t,
            width: c.width as f64,
            height: c.height as f64,
        }
    }

    /// The pinhole part as OpenCV's camera matrix.
    pub fn camera_matrix(&self) -> [[f64; 3]; 3] {
        [
            [self.f[0], 0.0, self.c[0]],
            [0.0, self.f[1], self.c[1]],
            [0.0, 0.0, 1.0],
        ]
    }

    /// The distortion as OpenCV's coefficients (k1, k2, p1, p2).
    pub fn distortion(&self) -> [f64; 4] {
        [self.k[0], self.k[1], self.p[0], self.p[1]]
    }

    /// Pixel position of a point in camera coordinates, if in front and inside the image.
    pub fn project(&self, x: &Vector3<f64>) -> Option<[f64; 2]> {
        if x.z <= 1e-9 {
            return None;
        }
        let (u, v) = (x.x / x.z, x.y / x.z);
        let r2 = u * u + v * v;
        let radial = 1.0 + self.k[0] * r2 + self.k[1] * r2 * r2;
        let du = 2.0 * self.p[0] * u * v + self.p[1] * (r2 + 2.0 * u * u);
        let dv = self.p[0] * (r2 + 2.0 * v * v) + 2.0 * self.p[1] * u * v;
        let px = self.f[0] * (u * radial + du) + self.c[0];
        let py = self.f[1] * (v * radial + dv) + self.c[1];
        let inside = px >= 0.0 && py >= 0.0 && px < self.width && py < self.height;
        // Strong distortion folds far-off points back into the image: refuse them.
        (inside && r2 < 4.0).then_some([px, py])
    }
}

/// Triangulated keypoints by grid cell: (pixel x, y; point index). Only looked up, never
/// iterated, so the hash order cannot reach a result.
pub type Grid = HashMap<(i64, i64), Vec<([f64; 2], usize)>>;

/// Matches between two views a < b, borrowed from the [`Evidence`], by (a, b): each pair's
/// matches, and whether their columns are (keypoint of b, keypoint of a) rather than (a, b).
pub type ViewMatches<'e> = HashMap<(usize, usize), (&'e [[u32; 2]], bool)>;

/// One registered image, ready to project into.
#[derive(Clone, Debug)]
pub struct View {
    /// Image name.
    pub name: String,
    /// World-to-camera rotation.
    pub rotation: Matrix3<f64>,
    /// World-to-camera translation.
    pub translation: Vector3<f64>,
    /// Camera centre in the world.
    pub centre: Vector3<f64>,
    /// The camera's intrinsics.
    pub intrinsics: Intrinsics,
    /// Triangulated keypoints in grid cells of [`Views::cell`] pixels: (x, y, point index).
    pub grid: Grid,
    /// Every keypoint's position, by keypoint index (the model's points2D order, which is the
    /// database's).
    pub keypoints: Vec<[f64; 2]>,
    /// The point each keypoint observes, by keypoint index (None: not triangulated).
    pub point_of: Vec<Option<usize>>,
    /// Every keypoint's index in grid cells of [`Views::cell`] pixels, built the first time
    /// [`Views::keypoint_near`] asks: only bare samples need it.
    pub keypoint_cells: OnceLock<HashMap<(i64, i64), Vec<u32>>>,
}

/// The model as the check reads it, borrowing the database's matches from the [`Evidence`].
/// Points and views are indexed densely, in id order.
#[derive(Clone, Debug)]
pub struct Views<'e> {
    /// Registered images, in image-id order.
    pub views: Vec<View>,
    /// 3D point positions.
    pub points: Vec<Vector3<f64>>,
    /// For each point, the views observing it (sorted, no repeats).
    pub observers: Vec<Vec<usize>>,
    /// For each point, the keypoint index of each observation, in `observers`' order.
    pub observed_at: Vec<Vec<u32>>,
    /// For each view, the points it observes (sorted, no repeats).
    pub seen_by: Vec<Vec<usize>>,
    /// Grid cell size in pixels (the neighbourhood radius).
    pub cell: f64,
    /// Verified matches between registered views. Empty without a database.
    pub matches: ViewMatches<'e>,
}

impl<'e> Views<'e> {
    /// Prepares `model`; `radius` is the neighbourhood radius as a fraction of each image's
    /// diagonal (the grid is built for the largest image's radius); `evidence` gives the
    /// matches.
    pub fn new(
        model: &SparseModel,
        radius: f64,
        evidence: Option<&'e Evidence>,
    ) -> Result<Views<'e>> {
        let cameras: BTreeMap<u32, &ModelCamera> =
            model.cameras.iter().map(|c| (c.camera_id, c)).collect();
        let index: BTreeMap<u64, usize> = model
            .points
            .keys()
            .enumerate()
            .map(|(k, id)| (*id, k))
            .collect();
        let points = model
            .points
            .values()
            .map(|p| Vector3::new(p[0], p[1], p[2]))
            .collect();
        let diagonal = cameras
            .values()
            .map(|c| (c.width as f64).hypot(c.height as f64))
            .fold(1.0, f64::max);
        let cell = (radius * diagonal).max(1.0);
        let mut images: Vec<_> = model.images.iter().collect();
        images.sort_by_key(|im| im.image.image_id);
        let mut tracks: Vec<Vec<(usize, u32)>> = vec![Vec::new(); index.len()];
        let mut views = Vec::new();
        for (v, im) in images.iter().enumerate() {
            let camera = cameras.get(&im.image.camera_id).with_context(|| {
                format!(
                    "image {} names camera {}, which the model lacks",
                    im.image.name, im.image.camera_id
                )
            })?;
            let mut grid = Grid::new();
            let mut point_of = vec![None; im.points2d.len()];
            for (keypoint, p) in im.points2d.iter().enumerate() {
                let Some(k) = p.point3d_id.and_then(|id| index.get(&id)) else {
                    continue;
                };
                point_of[keypoint] = Some(*k);
                tracks[*k].push((v, keypoint as u32));
                grid.entry(cell_of(p.xy, cell))
                    .or_default()
                    .push((p.xy, *k));
            }
            let rotation = im.image.rotation.to_rotation_matrix().into_inner();
            views.push(View {
                name: im.image.name.clone(),
                rotation,
                translation: im.image.translation,
                centre: im.image.centre(),
                intrinsics: Intrinsics::from_camera(camera),
                grid,
                keypoints: im.points2d.iter().map(|p| p.xy).collect(),
                point_of,
                keypoint_cells: OnceLock::new(),
            });
        }
        let mut seen_by = vec![Vec::new(); views.len()];
        let (mut observers, mut observed_at) = (Vec::new(), Vec::new());
        for (k, mut track) in tracks.into_iter().enumerate() {
            track.sort_unstable();
            track.dedup_by_key(|o| o.0);
            track.iter().for_each(|&(v, _)| seen_by[v].push(k));
            observers.push(track.iter().map(|o| o.0).collect());
            observed_at.push(track.iter().map(|o| o.1).collect());
        }
        let matches = evidence.map_or_else(HashMap::new, |e| view_matches(&views, e));
        Ok(Views {
            views,
            points,
            observers,
            observed_at,
            seen_by,
            cell,
            matches,
        })
    }

    /// The names of views `a` and `b`, in name order.
    pub fn name_pair(&self, a: usize, b: usize) -> [String; 2] {
        let name = |v: usize| self.views[v].name.clone();
        in_name_order(name(a), name(b))
    }

    /// Whether view `b`'s keypoints within `radius_b` pixels of `at` are matched to keypoints
    /// of view `a` within `radius_a` of `from`: the two saw the same structure there.
    pub fn matched_near(
        &self,
        (a, from, radius_a): (usize, [f64; 2], f64),
        (b, at, radius_b): (usize, [f64; 2], f64),
    ) -> bool {
        let near = |xy: Option<&[f64; 2]>, to: [f64; 2], r: f64| {
            xy.is_some_and(|xy| (xy[0] - to[0]).hypot(xy[1] - to[1]) <= r)
        };
        let (ka, kb) = (&self.views[a].keypoints, &self.views[b].keypoints);
        self.pair_matches(a, b).any(|[x, y]| {
            near(kb.get(y as usize), at, radius_b) && near(ka.get(x as usize), from, radius_a)
        })
    }

    /// The verified matches of views `a` and `b`, each as (keypoint of a, keypoint of b); none
    /// without a database.
    pub(super) fn pair_matches(&self, a: usize, b: usize) -> impl Iterator<Item = [u32; 2]> + '_ {
        let found = self.matches.get(&(a.min(b), a.max(b)));
        let (m, flipped) = found.map_or((&[][..], false), |&(m, f)| (m, f));
        let swap = flipped != (a > b);
        m.iter().map(move |&m| if swap { [m[1], m[0]] } else { m })
    }

    /// The verified matches of views `a` and `b` whose keypoints both observe points: how many
    /// observe the same point, and how many two different ones (the model holds them apart).
    /// With `within` pixels, two different points that each project that close to the other
    /// view's keypoint count as one: a selection that dropped the pair made the same surface
    /// twice at the same place, which contradicts nothing.
    pub fn matches_held(&self, a: usize, b: usize, within: Option<f64>) -> (usize, usize) {
        let (pa, pb) = (&self.views[a].point_of, &self.views[b].point_of);
        let near = |v: usize, point: usize, k: u32| {
            let at = self.views[v].keypoints[k as usize];
            (within.zip(self.project(v, point)))
                .is_some_and(|(px, xy)| (xy[0] - at[0]).hypot(xy[1] - at[1]) <= px)
        };
        let (mut joined, mut apart) = (0, 0);
        for [x, y] in self.pair_matches(a, b) {
            let at = |p: &[Option<usize>], k: u32| p.get(k as usize).copied().flatten();
            if let (Some(p), Some(q)) = (at(pa, x), at(pb, y)) {
                if p == q || (near(a, q, x) && near(b, p, y)) {
                    joined += 1;
                } else {
                    apart += 1;
                }
            }
        }
        (joined, apart)
    }

    /// For each view, its keypoints with a verified match to another view of the model.
    pub fn matched_keypoints(&self) -> Vec<usize> {
        let mut matched: Vec<Vec<bool>> = (self.views.iter())
            .map(|v| vec![false; v.keypoints.len()])
            .collect();
        for (&(a, b), &(m, flipped)) in &self.matches {
            for &[x, y] in m {
                let (ka, kb) = if flipped { (y, x) } else { (x, y) };
                for (v, k) in [(a, ka), (b, kb)] {
                    if let Some(slot) = matched[v].get_mut(k as usize) {
                        *slot = true;
                    }
                }
            }
        }
        matched
            .iter()
            .map(|m| m.iter().filter(|&&x| x).count())
            .collect()
    }

    /// Neighbourhood radius in view `v`'s pixels for a radius given as a fraction of the
    /// diagonal.
    pub fn radius(&self, v: usize, fraction: f64) -> f64 {
        let i = &self.views[v].intrinsics;
        fraction * i.width.hypot(i.height)
    }

    /// The points observed by view `v` within `radius` pixels of `at` (indices, may repeat).
    pub fn neighbours(
        &self,
        v: usize,
        at: [f64; 2],
        radius: f64,
    ) -> impl Iterator<Item = usize> + '_ {
        let grid = &self.views[v].grid;
        around(cell_of(at, self.cell))
            .filter_map(move |key| grid.get(&key))
            .flatten()
            .filter(move |(xy, _)| (xy[0] - at[0]).hypot(xy[1] - at[1]) <= radius)
            .map(|(_, k)| *k)
    }

    /// Whether view `v` has any keypoint, on a point or not, within `radius` pixels of `at`
    /// (at most [`Views::cell`]), from its [`View::keypoint_cells`].
    pub fn keypoint_near(&self, v: usize, at: [f64; 2], radius: f64) -> bool {
        let view = &self.views[v];
        let cells = view.keypoint_cells.get_or_init(|| {
            let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
            for (k, &xy) in view.keypoints.iter().enumerate() {
                cells
                    .entry(cell_of(xy, self.cell))
                    .or_default()
                    .push(k as u32);
            }
            cells
        });
        around(cell_of(at, self.cell))
            .filter_map(|key| cells.get(&key))
            .flatten()
            .map(|&k| view.keypoints[k as usize])
            .any(|q| (q[0] - at[0]).hypot(q[1] - at[1]) <= radius)
    }

    /// Point `k`'s observations as (view, keypoint), in `observers`' order.
    pub fn observations(&self, k: usize) -> impl Iterator<Item = (usize, u32)> + '_ {
        (self.observers[k].iter().copied()).zip(self.observed_at[k].iter().copied())
    }

    /// Pixel position of point `k` in view `v`, if in front and inside the image.
    pub fn project(&self, v: usize, k: usize) -> Option<[f64; 2]> {
        let view = &self.views[v];
        view.intrinsics
            .project(&(view.rotation * self.points[k] + view.translation))
    }
}

/// The grid cell of `cell` pixels holding pixel `xy`.
fn cell_of(xy: [f64; 2], cell: f64) -> (i64, i64) {
    ((xy[0] / cell).floor() as i64, (xy[1] / cell).floor() as i64)
}

/// Cell `c` and its eight neighbours: every pixel within one cell's width of `c`'s.
fn around(c: (i64, i64)) -> impl Iterator<Item = (i64, i64)> {
    (c.0 - 1..=c.0 + 1).flat_map(move |x| (c.1 - 1..=c.1 + 1).map(move |y| (x, y)))
}

/// The evidence's matches between registered views.
fn view_matches<'e>(views: &[View], evidence: &'e Evidence) -> ViewMatches<'e> {
    let index: HashMap<&str, usize> = views
        .iter()
        .enumerate()
        .map(|(v, view)| (view.name.as_str(), v))
        .collect();
    let mut out = HashMap::new();
    for ((n1, n2), m) in &evidence.matches {
        if let (Some(&a), Some(&b)) = (index.get(n1.as_str()), index.get(n2.as_str())) {
            out.insert((a.min(b), a.max(b)), (m.as_slice(), a > b));
        }
    }
    out
}
