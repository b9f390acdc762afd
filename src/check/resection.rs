//! Is each image where the database's matches put it? An image's keypoints on 3D points of
//! the model, and its verified matches to other images' keypoints on them, are 2D-3D
//! correspondences; the pose
//! most of them agree with (RANSAC on P3P, OpenCV's `solvePnPRansac`) is where the matches
//! place the image. A camera that the model holds between its true neighbours and the false
//! matches of another copy (the demo's image 0000 with the global mapper: 13-22% of the
//! scene off, its two false pairs among three selected) sits where neither agrees; its true
//! matches, pruned or not, place it back. The pairs that agree with that pose are the links
//! `prune --model` keeps; those that agree with the model's pose instead are blamed.

use super::evidence::{in_name_order, LostImage};
use super::join::{spread_of, MISPLACED_DISTANCE};
use super::views::{Intrinsics, Views};
use crate::colmap::sparse::SparseModel;
use anyhow::Result;
use nalgebra::{Matrix3, Rotation3, Vector3};
use opencv::core::{Mat, Point2d, Point3d, Vector};
use opencv::prelude::*;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};

/// A correspondence agrees with a pose when the pose projects its 3D point within this many
/// pixels of its keypoint: COLMAP's mapper filters observations at 4 px
/// (`filter_max_reproj_error`).
pub const AGREE_PX: f64 = 4.0;
/// RANSAC iterations of the pose.
const ITERATIONS: i32 = 1000;

/// A misplaced image's pose is supported by at least this many times the correspondences
/// that support the model's pose. Measured on 253 models of the demo, hall and street designs
/// (docs/check.md): where the matches' pose moves an image of a correct model by more than 5%,
/// it is supported by at most 0.96 times the model's (a RANSAC that stopped short); the
/// misplaced images of models the conflicts call clean reach 1.22 to 3.9 (1.5 until a demo
/// camera 0.59 of the extent off was measured at 1.38, session 20). See [`MAX_MOVED`] for
/// scenes whose false matches outnumber the true ones.
pub const SUPPORT_RATIO: f64 = 1.2;
/// ... and at least this many.
pub const MIN_SUPPORT: usize = 30;
/// A pose the matches put farther than this many times the model's spread away is a jump to
/// another place the image's view repeats, not a correction: on correct models of Cup, Oats
/// and the symmetric orbit, whose false matches can outnumber an image's true ones, such jumps
/// of 2.6 to 9.3 spreads reach 1.8 to 4.9 times the model's support. The misplaced images
/// measured move 0.36 to 2.41 spreads, the farthest a hall camera put on the other copy's
/// orbit, 2.36-2.41 in four matchings (docs/check.md, "Held by its own pairs").
pub const MAX_MOVED: f64 = 2.5;
/// A match holds a misplaced image where the model put it when it agrees with the model's pose
/// and the matches' pose puts it farther than this fraction of the image diagonal from its
/// keypoint: the look of another copy (a street's next building, an object a quarter turn
/// away), not a true match the matches' pose misses by a little. Measured on three streets'
/// misplaced cameras against the renderer's surfaces (docs/check.md, "Held by its own pairs"):
/// of the matches that agree with the model's pose and not within [`AGREE_PX`] with the
/// matches', in the pairs that place the image back, 554 were true and 699 false; beyond 80 px
/// (0.13 of the diagonal) 2 true and 690 false.
pub const HOLDING_FAR: f64 = 0.15;
/// An image's matches place it (a misplaced image, for the repair; a lost image, at all) only
/// where no third place holds this share of its correspondences: the best pose among those
/// that neither the model's pose nor the matches' explains (for a lost image, those that
/// neither the matches' pose nor the best pose of the rest, its other copy, explains). A
/// misplaced image matches two places, where the model put it and where it belongs; on a
/// short street, whose every view matches every building, it matches more, and the best pose
/// is one copy among several (session 43, 25 misplaced images of
/// streets with COLMAP 3.8: a third place held 0.02-0.33 of their correspondences, and the
/// pairs that placed them were 42 true of 207; the demo design's three misplaced cameras with
/// the global mapper, 0.00, their 22 pairs all true; docs/check.md). Noise does not agree on
/// a pose: a third place is a copy.
pub const THIRD_PLACE_SHARE: f64 = 0.05;
/// A misplaced image's matches' pose holds at least this many times the correspondences of
/// the third place ([`ImagePlacement::elsewhere`]): where a third place holds about as many,
/// the image's view repeats and its matches do not say where it belongs. Cup's frames 0043 and
/// 0046 in four correct models (session 55): their matches' pose, 5-8% of the spread away,
/// held 1.00 to 1.20 times the third place, and 1.27 to 1.49 times the model's pose. In each
/// of the 28 wrong models at hand that only misplaced images flagged (sessions 52-54's loops,
/// runs and peers' tables), one image's matches' pose held at least 1.37 times its third place
/// (a street design's full model, 323 against 235). Midway (geometric): 1.28 (docs/check.md).
pub const THIRD_PLACE_RATIO: f64 = 1.28;
/// A misplaced image whose matches name a third place is still placed by them where their
/// pose holds this many times the correspondences of the model's pose and of the third: it is
/// where the image belongs, not one copy among several. A street's every view matches every
/// building, and its copies hold alike: the matches' pose held 1.21 to 2.63 times the larger
/// of the other two for the 79 misplaced street cameras with a third place in sessions
/// 43-44's loops (15 streets, COLMAP 3.8 and 4.2's incremental mapper; their links 211 true of
/// 801); a hall camera put on the other object's orbit held 3.55 and 3.19 times (0023 in two
/// matchings of the test's hall, session 44's CI and session 45: 1226 and 1244
/// correspondences, 345 and 390 with the model's pose, 328 and 297 with a third; its 15 links
/// all true). Midway: 2.9 (docs/check.md).
pub const DOMINANT_SUPPORT: f64 = 2.9;
/// A pair of a misplaced image is judged (a link or against it) with at least this many
/// correspondences.
pub const PAIR_MIN_CORRESPONDENCES: usize = 5;

/// Where the database's matches put one image, next to where the model put it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImagePlacement {
    /// Image name.
    pub image: String,
    /// Its correspondences: its keypoints on a 3D point of the model, and its keypoints
    /// matched to other images' keypoints on one.
    pub correspondences: usize,
    /// Those the model's pose projects within [`AGREE_PX`].
    pub model_support: usize,
    /// Those the matches' pose projects within [`AGREE_PX`].
    pub support: usize,
    /// Of the rest (neither pose projects them within [`AGREE_PX`]), those the best pose
    /// among them does: a third place the image matches ([`THIRD_PLACE_SHARE`],
    /// [`THIRD_PLACE_RATIO`]). Sought only where the matches move the image
    /// ([`ImagePlacement::moves`]; 0 for the others): nothing else asks.
    pub elsewhere: usize,
    /// How far the matches' pose moves the camera centre, over the model's spread (the median
    /// distance of its points to their centroid).
    pub moved: f64,
    /// The camera centre of the matches' pose, in the model's frame.
    pub centre: [f64; 3],
    /// The pairs (this image, another) with at least [`PAIR_MIN_CORRESPONDENCES`]
    /// correspondences, at least half of them agreeing with the matches' pose, and no fewer
    /// than agree with the model's: for a misplaced image, they place it back (`prune --model`
    /// keeps them). A pair that agrees with both poses, more with the model's, is against it
    /// and not a link (the demo's 0000 with the global mapper: three false pairs were both).
    pub links: Vec<[String; 2]>,
    /// The pairs with as many correspondences, at least half of them agreeing with the
    /// model's pose and more than with the matches': for a misplaced image, they hold it
    /// where the model put it (`prune --model` blames them).
    pub against: Vec<[String; 2]>,
    /// The matches whose correspondence agrees with the model's pose and is far from the
    /// matches' ([`HOLDING_FAR`]): for a misplaced image, what holds it where the model put
    /// it, inside pairs that may be true (a hall camera registered 98 degrees off onto an
    /// object's repeated face by a few dozen such matches among its true pairs' inliers).
    /// `prune --model` drops them from the pairs it keeps (in the report under `repair`).
    #[serde(skip)]
    pub holding: Vec<PairMatches>,
}

/// Some matches of one pair: each a keypoint of `images[0]` and one of `images[1]`.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct PairMatches {
    /// The pair's image names.
    pub images: [String; 2],
    /// The matches (sorted in [`super::repair::ModelEvidence::dropped`]).
    pub matches: Vec<[u32; 2]>,
}

impl ImagePlacement {
    /// The model put the image where its matches do not: they move it
    /// ([`ImagePlacement::moves`]), and no third place holds nearly as many correspondences
    /// ([`THIRD_PLACE_RATIO`]).
    pub fn misplaced(&self) -> bool {
        self.moves() && self.support as f64 >= THIRD_PLACE_RATIO * self.elsewhere as f64
    }

    /// The matches move the image by more than [`MISPLACED_DISTANCE`] of the model's spread
    /// and at most [`MAX_MOVED`] times it, with at least [`MIN_SUPPORT`] correspondences and
    /// [`SUPPORT_RATIO`] times the model pose's: where a third place is sought.
    pub fn moves(&self) -> bool {
        (MISPLACED_DISTANCE..=MAX_MOVED).contains(&self.moved)
            && self.support >= MIN_SUPPORT
            && self.support as f64 >= SUPPORT_RATIO * self.model_support as f64
    }

    /// Its matches name no third place ([`ImagePlacement::third_place`]), or their pose
    /// dominates the others ([`ImagePlacement::dominates`]): where the image is misplaced,
    /// the matches' pose is where it belongs. (Alone in its model, an image that pairs hold
    /// where the model put it is too: [`super::ModelCheck::takes`].)
    pub fn places(&self) -> bool {
        !self.third_place() || self.dominates()
    }

    /// Some of its pairs hold it where the model put it (`against`): its pairs take sides, a
    /// few with the model's pose and the rest with the matches'. Where none is against it, the
    /// model's pose rests on correspondences spread over pairs that agree with the matches'
    /// pose, and that pose is one copy among several.
    pub fn held_by_pairs(&self) -> bool {
        !self.against.is_empty()
    }

    /// Its matches name a third place: [`THIRD_PLACE_SHARE`] of its correspondences agree
    /// with a pose besides the model's and the matches'.
    pub fn third_place(&self) -> bool {
        !one_place(self.elsewhere, self.correspondences)
    }

    /// The matches' pose holds [`DOMINANT_SUPPORT`] times the correspondences of the model's
    /// pose and of the third place.
    pub fn dominates(&self) -> bool {
        self.dominance() >= DOMINANT_SUPPORT
    }

    /// The correspondences the matches' pose holds over the larger of those the model's pose
    /// and the third place hold.
    pub fn dominance(&self) -> f64 {
        self.support as f64 / self.model_support.max(self.elsewhere) as f64
    }
}

/// No third place holds [`THIRD_PLACE_SHARE`] of `correspondences`.
fn one_place(elsewhere: usize, correspondences: usize) -> bool {
    (elsewhere as f64) < THIRD_PLACE_SHARE * correspondences as f64
}

/// One 2D-3D correspondence of a view: its keypoint's pixel on a point of the model.
#[derive(Clone, Copy)]
struct Correspondence {
    /// The keypoint's pixel.
    xy: [f64; 2],
    /// The 3D point (index into the views' points).
    point: usize,
    /// The view whose keypoint is on the point: the view itself for its own observation.
    view: usize,
    /// The match behind it (keypoint of this view, of the other), none for an observation.
    matched: Option<[u32; 2]>,
}

/// View `v`'s correspondences: its own observations first (what the model's pose rests on);
/// then each verified match to a keypoint of another view on a point.
fn correspondences(views: &Views, v: usize) -> Vec<Correspondence> {
    let view = &views.views[v];
    let mut out: Vec<Correspondence> = (view.keypoints.iter().zip(&view.point_of))
        .filter_map(|(xy, p)| {
            p.map(|point| Correspondence {
                xy: *xy,
                point,
                view: v,
                matched: None,
            })
        })
        .collect();
    for w in (0..views.views.len()).filter(|&w| w != v) {
        let (kv, pw) = (&view.keypoints, &views.views[w].point_of);
        for [x, y] in views.pair_matches(v, w) {
            if let (Some(xy), Some(Some(p))) = (kv.get(x as usize), pw.get(y as usize)) {
                out.push(Correspondence {
                    xy: *xy,
                    point: *p,
                    view: w,
                    matched: Some([x, y]),
                });
            }
        }
    }
    out
}

/// Where the database's matches put each image of `views` (with a database): every image
/// with at least [`MIN_SUPPORT`] correspondences and a pose they agree on, in view order.
/// The evaluation compares these with the ground truth (`eval --placements`).
pub fn image_placements(views: &Views) -> Result<Vec<ImagePlacement>> {
    let spread = spread_of(&views.points);
    let placed: Vec<Option<ImagePlacement>> = (0..views.views.len())
        .into_par_iter()
        .map(|v| place(views, v, spread))
        .collect::<Result<_>>()?;
    Ok(placed.into_iter().flatten().collect())
}

/// [`image_placements`] of view `v` alone.
pub fn image_placement(views: &Views, v: usize) -> Result<Option<ImagePlacement>> {
    place(views, v, spread_of(&views.points))
}

/// The images of `views` (with a database) whose matches place them elsewhere than the model
/// ([`ImagePlacement::misplaced`]).
pub fn misplaced_images(views: &Views) -> Result<Vec<ImagePlacement>> {
    let mut placed = image_placements(views)?;
    placed.retain(ImagePlacement::misplaced);
    Ok(placed)
}

/// Where the matches of an image no model registered place it in a model: a mapper that lost
/// it (a group tied to the rest by too few matches once a selection kept only its strongest
/// pairs: lego, 8 of 100 images with COLMAP 3.8) can register it through the pairs that agree.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rejoin {
    /// Image name.
    pub image: String,
    /// The model it is placed in, as an index of the checked folders.
    pub model: usize,
    /// Its correspondences: its keypoints matched, pruned or not, to keypoints on a point of
    /// the model.
    pub correspondences: usize,
    /// Those the pose projects within [`AGREE_PX`].
    pub support: usize,
    /// The pose is the matches' second place: an earlier run's ghost had the image at the
    /// first ([`super::join::Glued::places_again`]).
    pub second_place: bool,
    /// The pairs (this image, another) with at least [`PAIR_MIN_CORRESPONDENCES`]
    /// correspondences, at least half of them agreeing with the pose: `prune --model` keeps
    /// them.
    pub links: Vec<[String; 2]>,
}

/// A clean model to place lost images in: its index among the checked folders, the model, its
/// views, and each view's index by image name.
pub struct Frame<'a> {
    /// The model's index among the checked folders.
    pub k: usize,
    /// The model (its cameras).
    pub model: &'a SparseModel,
    /// Its views (the points and keypoints on them).
    pub views: &'a Views<'a>,
    /// Each view's index, by image name.
    index: HashMap<&'a str, usize>,
}

impl<'a> Frame<'a> {
    /// Model `k` with its views.
    pub fn new(k: usize, model: &'a SparseModel, views: &'a Views<'a>) -> Frame<'a> {
        let index = (views.views.iter().enumerate())
            .map(|(w, v)| (v.name.as_str(), w))
            .collect();
        Frame {
            k,
            model,
            views,
            index,
        }
    }
}

/// Places `name`, which no model registered, in `frame` by its matches to keypoints on the
/// model's points, through the model's camera of its camera_id (refined) or else the
/// database's: the pose most of them agree with, where at least [`MIN_SUPPORT`] do (COLMAP's
/// mapper registers an image with 30 inliers, `abs_pose_min_num_inliers`) and no third place
/// holds [`THIRD_PLACE_SHARE`] of them, beside that pose and the best of the rest (its other
/// copy): a lost street camera's matches put it on every copy. Where `refuted` says an
/// earlier run's ghost had the image at the first pose, it is placed at the second, its other
/// copy, if that is not refuted too: an orbit's end that sees only an object both copies show
/// alike is placed first where the ghost had it, through the very pairs that ghost glued
/// (plain 38-5716, docs/check.md).
pub fn place_lost(
    frame: &Frame,
    name: &str,
    image: &LostImage,
    refuted: &dyn Fn(&Vector3<f64>) -> bool,
) -> Result<Option<Rejoin>> {
    let views = frame.views;
    // In view order, as a registered image's correspondences are (the RANSAC's draws follow it).
    let mut matched: Vec<(usize, &[[u32; 2]])> = (image.matches.iter())
        .filter_map(|(other, m)| Some((*frame.index.get(other.as_str())?, m.as_slice())))
        .collect();
    matched.sort_unstable_by_key(|&(w, _)| w);
    let mut c = Vec::new();
    for (w, matches) in matched {
        for &[ku, kw] in matches {
            let xy = image.keypoints.get(ku as usize);
            if let (Some(xy), Some(Some(point))) = (xy, views.views[w].point_of.get(kw as usize)) {
                let (xy, point, matched) = (*xy, *point, Some([ku, kw]));
                c.push(Correspondence {
                    xy,
                    point,
                    view: w,
                    matched,
                });
            }
        }
    }
    let camera = (frame.model.cameras.iter()).find(|c| c.camera_id == image.camera_id);
    let intrinsics = Intrinsics::from_camera(camera.unwrap_or(&image.camera));
    // The best pose, the best of what it leaves (its other copy), and a third; the second
    // and third RANSACs only where the first could place the image or is refuted.
    let refuted = |p: &Place| p.pose.is_some_and(|pose| refuted(&centre_of(&pose)));
    let first = best_place(views, &intrinsics, &c)?;
    let first_refuted = refuted(&first);
    if !first_refuted && first.support < MIN_SUPPORT {
        return Ok(None);
    }
    let second = best_place(views, &intrinsics, &first.rest)?;
    if !one_place(
        best_place(views, &intrinsics, &second.rest)?.support,
        c.len(),
    ) {
        return Ok(None);
    }
    let (place, second_place) = match first_refuted {
        false => (first, false),
        true if !refuted(&second) => (second, true),
        true => return Ok(None),
    };
    let Some(pose) = place.pose.filter(|_| place.support >= MIN_SUPPORT) else {
        return Ok(None);
    };
    // Per other view: correspondences, and those agreeing with the pose.
    let mut per_view: BTreeMap<usize, [usize; 2]> = BTreeMap::new();
    for k in &c {
        let agrees = reprojection_error(views, &intrinsics, (&pose.0, &pose.1), k) <= AGREE_PX;
        let counts = per_view.entry(k.view).or_default();
        *counts = [counts[0] + 1, counts[1] + usize::from(agrees)];
    }
    let mut links = Vec::new();
    for (w, [n, s]) in per_view {
        if n >= PAIR_MIN_CORRESPONDENCES && 2 * s >= n {
            links.push(in_name_order(name.to_string(), views.views[w].name.clone()));
        }
    }
    Ok(Some(Rejoin {
        image: name.to_string(),
        model: frame.k,
        correspondences: c.len(),
        support: place.support,
        second_place,
        links,
    }))
}

/// The pose most of some correspondences agree with (none where fewer than [`MIN_SUPPORT`]
/// are there to give one), how many do, and those it leaves.
struct Place {
    pose: Option<Pose>,
    support: usize,
    rest: Vec<Correspondence>,
}

/// The [`Place`] of correspondences `c` (to `views`' points, through `intrinsics`).
fn best_place(views: &Views, intrinsics: &Intrinsics, c: &[Correspondence]) -> Result<Place> {
    let pose = match c.len() < MIN_SUPPORT {
        true => None,
        false => pnp(views, intrinsics, c)?,
    };
    let Some((rotation, translation)) = pose else {
        return Ok(Place {
            pose: None,
            support: 0,
            rest: c.to_vec(),
        });
    };
    let (agree, rest): (Vec<_>, Vec<_>) = (c.iter()).partition(|k| {
        reprojection_error(views, intrinsics, (&rotation, &translation), k) <= AGREE_PX
    });
    Ok(Place {
        pose: Some((rotation, translation)),
        support: agree.len(),
        rest,
    })
}

/// The camera centre of a world-to-camera pose.
fn centre_of((rotation, translation): &Pose) -> Vector3<f64> {
    -(rotation.transpose() * translation)
}

/// A world-to-camera rotation and translation.
type Pose = (Matrix3<f64>, Vector3<f64>);

/// Pixels between correspondence `k`'s keypoint and its point projected through `intrinsics` at
/// `pose` (infinite where the point falls behind the camera or outside the image).
fn reprojection_error(
    views: &Views,
    intrinsics: &Intrinsics,
    (rotation, translation): (&Matrix3<f64>, &Vector3<f64>),
    k: &Correspondence,
) -> f64 {
    (intrinsics.project(&(rotation * views.points[k.point] + translation)))
        .map_or(f64::INFINITY, |q| (q[0] - k.xy[0]).hypot(q[1] - k.xy[1]))
}

/// [`image_placements`] for view `v`: `None` with too few correspondences or no pose.
fn place(views: &Views, v: usize, spread: f64) -> Result<Option<ImagePlacement>> {
    let c = correspondences(views, v);
    if c.len() < MIN_SUPPORT {
        return Ok(None);
    }
    let view = &views.views[v];
    let Some((rotation, translation)) = pnp(views, &view.intrinsics, &c)? else {
        return Ok(None);
    };
    let error = |r: &Matrix3<f64>, t: &Vector3<f64>, k: &Correspondence| {
        reprojection_error(views, &view.intrinsics, (r, t), k)
    };
    let far = HOLDING_FAR * view.intrinsics.width.hypot(view.intrinsics.height);
    // Per other view: correspondences, those agreeing with the model's pose and those
    // agreeing with the matches'; and the matches that hold the image where the model put it.
    let mut pairs: Vec<(usize, [usize; 3], Vec<[u32; 2]>)> = Vec::new();
    let (mut model_support, mut support, mut rest) = (0, 0, Vec::new());
    for k in &c {
        let off = error(&rotation, &translation, k);
        let m = usize::from(error(&view.rotation, &view.translation, k) <= AGREE_PX);
        let s = usize::from(off <= AGREE_PX);
        (model_support, support) = (model_support + m, support + s);
        if m + s == 0 {
            rest.push(*k);
        }
        let Some(matched) = k.matched else { continue };
        if pairs.last().is_none_or(|last| last.0 != k.view) {
            pairs.push((k.view, [0; 3], Vec::new()));
        }
        let last = pairs.last_mut().expect("pushed above");
        last.1 = [last.1[0] + 1, last.1[1] + m, last.1[2] + s];
        if m == 1 && off > far {
            last.2.push(matched);
        }
    }
    let centre = centre_of(&(rotation, translation));
    let moved = (centre - view.centre).norm() / spread;
    let named = |w: usize| [view.name.clone(), views.views[w].name.clone()];
    let judged = pairs.iter().filter(|p| p.1[0] >= PAIR_MIN_CORRESPONDENCES);
    let list = |keep: &dyn Fn(&[usize; 3]) -> bool| -> Vec<[String; 2]> {
        judged
            .clone()
            .filter(|p| keep(&p.1))
            .map(|p| named(p.0))
            .collect()
    };
    let links = list(&|[n, m, s]| 2 * s >= *n && s >= m);
    let against = list(&|[n, m, s]| 2 * m >= *n && m > s);
    let holding = (pairs.into_iter())
        .filter(|p| !p.2.is_empty())
        .map(|(w, _, matches)| PairMatches {
            images: named(w),
            matches,
        })
        .collect();
    let mut placement = ImagePlacement {
        image: view.name.clone(),
        correspondences: c.len(),
        model_support,
        support,
        elsewhere: 0,
        moved,
        centre: centre.into(),
        links,
        against,
        holding,
    };
    // A second RANSAC, for the few images it concerns.
    if placement.moves() {
        placement.elsewhere = best_place(views, &view.intrinsics, &rest)?.support;
    }
    Ok(Some(placement))
}

/// The pose most correspondences `c` (to `views`' points, through intrinsics `i`) agree with:
/// world-to-camera rotation and translation, from OpenCV's RANSAC (deterministic: its
/// generator starts from a fixed state).
fn pnp(views: &Views, i: &Intrinsics, c: &[Correspondence]) -> Result<Option<Pose>> {
    let object: Vector<Point3d> = c
        .iter()
        .map(|k| {
            let x = views.points[k.point];
            Point3d::new(x.x, x.y, x.z)
        })
        .collect();
    let image: Vector<Point2d> = c.iter().map(|k| Point2d::new(k.xy[0], k.xy[1])).collect();
    let camera = Mat::from_slice_2d(&i.camera_matrix())?;
    let coefficients = i.distortion();
    let distortion = Mat::from_slice(&coefficients)?;
    let (mut rvec, mut tvec, mut inliers) = (Mat::default(), Mat::default(), Mat::default());
    let found = opencv::calib3d::solve_pnp_ransac(
        &object,
        &image,
        &camera,
        &distortion,
        &mut rvec,
        &mut tvec,
        false,
        ITERATIONS,
        AGREE_PX as f32,
        0.999,
        &mut inliers,
        opencv::calib3d::SOLVEPNP_AP3P,
    )?;
    if !found {
        return Ok(None);
    }
    let (r, t) = (rvec.data_typed::<f64>()?, tvec.data_typed::<f64>()?);
    let axis = Vector3::new(r[0], r[1], r[2]);
    let rotation = Rotation3::from_scaled_axis(axis).into_inner();
    Ok(Some((rotation, Vector3::new(t[0], t[1], t[2]))))
}
