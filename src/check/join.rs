//! Where two models of one mapper run sit relative to each other. A mapper that cannot cross
//! from one part of a scene to another leaves several models; after a repair has forbidden the
//! pairs that glued two copies together, one model per copy is common (the hall design:
//! docs/check.md). The database still holds matches between the models, true ones and the
//! copies' false ones, and each proposes a placement of one model in the other's frame.
//!
//! The placements are found from 3D-3D correspondences (two matched keypoints, each on a point
//! of its own model): the similarity most of them agree on, then the one most of the rest agree
//! on (sequential RANSAC, [`PLACEMENTS`] at most). Each is tested as a ghost is: the two models
//! put together must not conflict ([`super::conflict`]), and where the repair keeps its links
//! must score under [`CheckSettings::placement_threshold`]. False matches between copies
//! propose the placement that folds one copy onto the other, and where they outnumber the true
//! links (why the mapper glued the copies in the first place) it is the strongest; it
//! conflicts, and the next placement that does not joins the models. The database pairs it
//! explains are the links a mapper needs to make one model of the two (`prune --model` keeps
//! them, with only the matches the placement explains where those are enough: `Linking`).
//!
//! Only after a stronger placement conflicted: where the strongest does not, it may be a ghost
//! the check cannot see (copies that share their surroundings), and nothing tells it from a
//! true one. Measured on the peers' multi-model outputs (docs/check.md): joining the strongest
//! clean placement, 36 of 57 joins were wrong; any clean placement after any refuted one, 6 of
//! 12 (a wrong placement conflicts too, however weak). An earlier run of the repair loop can
//! have refuted that stronger placement already: a model of it that was ghosted between the two
//! models' images ([`Glued`]). The check saw that scene's ghost, so it can see its ghosts, and
//! the strongest clean placement joins (streets whose repair left two correct models, the
//! ghost's placement no longer the strongest once each copy is a model of its own), unless it
//! puts them where that ghost had them: the refuted placement again, now under the threshold
//! because each copy's model holds less unique structure than the ghost did (within
//! [`GHOST_AGAIN`] by [`Glued::offset`]).

use super::conflict::{self, Counts};
use super::evidence::{in_name_order, Evidence};
use super::settings::{is_ghost, score, CheckSettings};
use crate::colmap::model::ModelImage;
use crate::colmap::sparse::{SparseImage, SparseModel};
use crate::colmap::DEFAULT_MIN_NUM_MATCHES;
use crate::geometry::similarity::Similarity;
use crate::stats::median;
use nalgebra::{UnitQuaternion, Vector3};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// A clean model's group is misplaced when the placement its matches give moves its points by
/// more than this fraction of the model's spread (median): 5%, the evaluation's tolerance for a
/// correct camera. The correct models measured move by a fraction of a percent.
pub const MISPLACED_DISTANCE: f64 = 0.05;
/// A clean placement after the one taken is a third place where it puts the second model's
/// points farther than this fraction of the first model's spread (median) from where the
/// taken one does: closer, it is the taken placement again, refitted on other
/// correspondences. Measured in the stored loops of sessions 43-46: a hall's second orbit
/// placed twice 0.053 apart (both placements' links true); streets' pieces a building on,
/// 0.12 to 0.95 (docs/check.md, "A join with a third place").
pub const THIRD_PLACE_APART: f64 = 0.1;
/// A placement that puts the second model's cameras within this fraction of an earlier run's
/// ghost's camera spread (median) of where that ghost had them, once the first model's cameras
/// are carried onto the ghost's, is that ghost's placement again, refitted on other
/// correspondences: refuted once already ([`Glued::offset`]). Measured on every placement tried
/// in session 60's loops (docs/check.md): the ghost's placement again 0.0028-0.115, every one
/// false (0.099: a 3-image orbit end joined back beside the other orbit's end by false pairs
/// alone, plain 38-5901); the true ones 1.87 or more (plain and adjacent designs), street
/// pieces' true joins from 0.3 (session 28). Midway (geometric) between 0.115 and 0.3. Wider
/// than one image's tolerance ([`Glued::places_again`], [`MISPLACED_DISTANCE`]): a model
/// refitted from another run's points scatters more than one camera placed by its matches.
pub const GHOST_AGAIN: f64 = 0.2;
/// Images of an earlier ghost's other side a model must hold to be the frame
/// [`Glued::again_in`] judges the first side's images in: fewer fix no frame worth trusting.
pub const AGAIN_FRAME: usize = 3;
/// Placements tried per pair of models, most supported first.
pub const PLACEMENTS: usize = 3;
/// Random minimal samples (three correspondences) drawn per placement.
pub const HYPOTHESES: usize = 2000;
/// A correspondence agrees with a placement within this distance, as a fraction of the first
/// model's spread (the median distance of its points to their centroid).
pub const INLIER_DISTANCE: f64 = 0.01;
/// A placement's agreeing correspondences must spread over more than this many times the
/// agreement distance in the first model (median distance to their centroid): fewer, and they
/// agree with a placement that shrinks the second model onto one spot.
pub const DEGENERATE_EXTENT: f64 = 2.0;
/// Agreeing correspondences a placement needs at least, counted over the pairs that link the
/// models ([`PAIR_MIN_AGREEING`], [`PAIR_MIN_FRACTION`]): the positive evidence for it. Two
/// models that meet only where the images look at each other's structure from far off or at a
/// steep angle give the conflict test no sample (the hall's two orbits), so the test can refute
/// a placement but not confirm one.
pub const MIN_SUPPORT: usize = 30;
/// A database pair links the joined models when at least this many of its correspondences...
pub const PAIR_MIN_AGREEING: usize = 5;
/// ... and at least this fraction of them agree with the placement: the placement explains the
/// pair, not a few of its matches that fit by chance.
pub const PAIR_MIN_FRACTION: f64 = 0.5;

/// A database pair that links two joined models.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Link {
    /// Image of the first model.
    pub image1: String,
    /// Image of the second model.
    pub image2: String,
    /// Its correspondences (matches between points of the two models).
    pub correspondences: usize,
    /// Of those, the ones that agree with the placement.
    pub agreeing: usize,
    /// For a link kept with only its agreeing matches (`Linking`): the pair's other matches
    /// (keypoints in name order), which `prune --model` drops so that the pair is kept with
    /// those alone (in the report's `repair.dropped`). Empty for a link kept whole.
    #[serde(skip)]
    pub dropped: Vec<[u32; 2]>,
}

/// Two models joined by a placement that does not conflict.
#[derive(Clone, Debug, Serialize)]
pub struct Join {
    /// The two models, as indices of the checked folders (a model's own index twice for its
    /// group placed by [`place_group`]).
    pub models: [usize; 2],
    /// Correspondences between the two models.
    pub correspondences: usize,
    /// The placement: the second model's points x go to `scale * rotation * x + translation`
    /// in the first's frame (rotation as a row-major matrix).
    pub placement: Placement,
    /// Correspondences that agree with the placement.
    pub support: usize,
    /// Stronger placements the check called ghosted (at least one: see the module's doc),
    /// earlier runs' ghosts that put the two models onto each other included.
    pub refuted: usize,
    /// How far the placement puts the second model's cameras from where the nearest earlier
    /// run's ghost between the two had them, over that ghost's spread ([`Glued::offset`]);
    /// within [`GHOST_AGAIN`] it is that ghost again, and refuted. None without such a
    /// ghost, or where their cameras fix no frame.
    pub ghost_offset: Option<f64>,
    /// The conflicts of the two models put together, one group each.
    pub counts: Counts,
    /// Their score, as a split's ([`super::settings::score`]).
    pub score: f64,
    /// The pairs that link the models, most agreeing correspondences first.
    pub links: Vec<Link>,
    /// Every placement tried for the two models, most supported first, this one last.
    pub tried: Vec<Tried>,
}

/// Two clean models [`join_models`] tried and left apart, and why: a user who sees a scene
/// in pieces learns whether its matches could place them at all.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Apart {
    /// The two models, as indices of the checked folders.
    pub models: [usize; 2],
    /// Correspondences between the two models.
    pub correspondences: usize,
    /// Placements the check refuted, earlier runs' ghosts between the two included.
    pub refuted: usize,
    /// Why no placement joins them.
    pub reason: ApartReason,
    /// The score of the placement the reason is about ([`ApartReason::Doubtful`],
    /// [`ApartReason::NothingRefuted`], [`ApartReason::ThirdPlace`]: the one that would join).
    pub score: Option<f64>,
    /// Every placement tried for the two models, most supported first.
    pub tried: Vec<Tried>,
}

/// One placement tried for two models ([`join_models`], [`place_group`]), as the report lists
/// it: how near it came to an earlier ghost's placement and what the check made of it. Refused
/// placements are the evidence a tolerance such as [`GHOST_AGAIN`] is measured on
/// (docs/check.md).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tried {
    /// The placement, as [`Join::placement`].
    pub placement: Placement,
    /// Correspondences that agree with it.
    pub support: usize,
    /// Of those, the ones on the pairs it explains ([`PAIR_MIN_AGREEING`],
    /// [`PAIR_MIN_FRACTION`]).
    pub linked: usize,
    /// As [`Join::ghost_offset`].
    pub ghost_offset: Option<f64>,
    /// What the check made of it.
    pub verdict: TriedVerdict,
    /// Judged with trimmed links ([`Link::dropped`]), after no placement joined the two with
    /// whole pairs.
    pub trimmed: bool,
    /// Its score, where the two models were put together by it and judged.
    pub score: Option<f64>,
}

/// What the check made of a placement it tried ([`Tried`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TriedVerdict {
    /// Its correspondences lie on one spot of the first model ([`DEGENERATE_EXTENT`]): it may
    /// shrink the second model onto that spot, so it places nothing.
    OneSpot,
    /// It explains fewer than [`MIN_SUPPORT`] correspondences on pairs: no placement.
    TooFew,
    /// It puts the models where an earlier run's ghost had them: refuted unjudged.
    GhostAgain,
    /// The two models put together by it conflict: refuted.
    Conflicts,
    /// The two models put together by it do not conflict.
    Clean,
}

/// Why [`join_models`] joins two models by none of their placements.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ApartReason {
    /// No placement explains [`MIN_SUPPORT`] correspondences without a conflict: too few
    /// matches between them, or every placement they give conflicted.
    NoPlacement,
    /// The strongest placement does not conflict, but none stronger was refuted: it may be a
    /// ghost the check cannot see.
    NothingRefuted,
    /// The first placement without a conflict scores at or above the threshold under which
    /// the repair keeps its links.
    Doubtful,
    /// Their matches place the second model in a third place as well ([`THIRD_PLACE_APART`]).
    ThirdPlace,
}

/// What [`join_models`] made of each pair of clean models it tried.
#[derive(Debug, Default)]
pub struct Joins {
    /// The pairs joined.
    pub joined: Vec<Join>,
    /// The pairs left apart.
    pub apart: Vec<Apart>,
}

/// What [`join_two`] made of two models.
enum Outcome {
    /// Joined by the placement taken.
    Joined(Join),
    /// Left apart, and why.
    Apart(Apart),
}

/// A similarity as the report writes it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// Scale factor.
    pub scale: f64,
    /// Rotation matrix, rows first.
    pub rotation: [[f64; 3]; 3],
    /// Translation.
    pub translation: [f64; 3],
}

impl From<&Placement> for Similarity {
    fn from(p: &Placement) -> Similarity {
        let r = nalgebra::Matrix3::from_fn(|i, j| p.rotation[i][j]);
        Similarity {
            scale: p.scale,
            rotation: nalgebra::Rotation3::from_matrix_unchecked(r),
            translation: Vector3::from(p.translation),
        }
    }
}

impl From<&Similarity> for Placement {
    fn from(s: &Similarity) -> Placement {
        let r = s.rotation.matrix();
        Placement {
            scale: s.scale,
            rotation: [0, 1, 2].map(|i| [0, 1, 2].map(|j| r[(i, j)])),
            translation: [s.translation[0], s.translation[1], s.translation[2]],
        }
    }
}

/// An earlier run's ghosted model, as a later run's joins and misplaced images need it: the two
/// groups of images it put onto each other (its worst split), whose placement of one in the
/// other's frame conflicted, and where it put their cameras. Two models of a later run that
/// lie on its two sides were placed so once already, and refuted: a placement of theirs that
/// puts them where the ghost had them is that refuted placement again (the twin's two orbits,
/// each a clean model after the repair, proposed onto each other as the full database's ghost
/// had them, at 0.47 where the ghost scored 0.78; docs/check.md).
#[derive(Clone, Debug)]
pub struct Glued {
    /// The two groups, image names.
    pub groups: [Vec<String>; 2],
    /// The ghost's cameras of both groups, by image name.
    cameras: BTreeMap<String, ModelImage>,
}

impl Glued {
    /// The ghost `model`'s split into `groups`.
    pub fn new(model: &SparseModel, groups: [Vec<String>; 2]) -> Glued {
        let in_groups = |im: &&SparseImage| groups.iter().any(|g| g.contains(&im.image.name));
        let cameras = (model.images.iter().filter(in_groups))
            .map(|im| (im.image.name.clone(), im.image.clone()))
            .collect();
        Glued { groups, cameras }
    }

    /// The side (0 or 1) that holds more than half of `model`'s images, if one does.
    fn side(&self, model: &SparseModel) -> Option<usize> {
        let on = |g: &Vec<String>| {
            let n = model.images.iter().filter(|im| g.contains(&im.image.name));
            2 * n.count() > model.images.len()
        };
        (0..2).find(|&k| on(&self.groups[k]))
    }

    /// Whether this ghost put `a` and `b` onto each other: each lies on its own side.
    fn between(&self, a: &SparseModel, b: &SparseModel) -> bool {
        matches!((self.side(a), self.side(b)), (Some(x), Some(y)) if x != y)
    }

    /// How far `placement` (of `b` in `a`'s frame) puts `b`'s cameras from where the ghost had
    /// them beside `a`'s, once `a`'s cameras are carried onto the ghost's: the median distance
    /// over the ghost's spread. None where the cameras they share fix no frame. Within
    /// [`GHOST_AGAIN`] the placement is the ghost's again, and a join refuses it.
    pub fn offset(&self, a: &SparseModel, b: &SparseModel, placement: &Similarity) -> Option<f64> {
        let (b_here, b_ghost) = self.shared(b.images.iter());
        let to_ghost = self
            .to_ghost(a.images.iter())
            .filter(|_| !b_here.is_empty())?;
        let off = b_here.iter().zip(&b_ghost).map(|(here, ghost)| {
            (to_ghost.apply(&placement.apply(&here.centre())) - ghost.centre()).norm()
        });
        median(off).map(|m| m / self.spread())
    }

    /// Whether a pose of `image` with camera centre `centre` in `model`'s frame puts it where
    /// this ghost had it beside its other group: within [`MISPLACED_DISTANCE`] of the ghost's
    /// spread, once `model`'s cameras of that group are carried onto the ghost's. An image that
    /// sees only an object both copies show alike (an orbit's end) matches the other copy's
    /// images as well as its own neighbours, and its matches' pose can be that ghost's pose of
    /// it again (plain 38-5604 and 38-5714, 0.002-0.007; the images truly misplaced in the
    /// stored loops, 0.22 or more: docs/check.md).
    pub fn places_again(&self, model: &SparseModel, image: &str, centre: &Vector3<f64>) -> bool {
        let Some(side) = (0..2).find(|&k| self.groups[k].iter().any(|n| n == image)) else {
            return false;
        };
        let other =
            (model.images.iter()).filter(|im| self.groups[1 - side].contains(&im.image.name));
        self.to_ghost(other)
            .is_some_and(|to_ghost| self.at_ghost(&to_ghost, image, centre))
    }

    /// The images of `model` on this ghost's side with fewer of them in it, where every one
    /// sits where the ghost had it beside the other side's ([`Glued::places_again`]; that
    /// side needs [`AGAIN_FRAME`] images): the refuted placement again, inside one model. An
    /// orbit's first images see only an object both copies show alike, so they conflict with
    /// next to nothing, and a selection that keeps their pairs to the other copy puts them
    /// there again (plain 24-6201 and 24-6202: 0012, and 0012-0015, left on the first orbit's
    /// copy, called clean at 0.15-0.20; docs/check.md). Every image of the side, not some: an
    /// image the ghost grouped with that side yet had right stays clean beside its true
    /// neighbours. Empty where none is.
    pub fn again_in(&self, model: &SparseModel) -> Vec<String> {
        let side = |k: usize| -> Vec<&SparseImage> {
            let on = |im: &&SparseImage| self.groups[k].contains(&im.image.name);
            model.images.iter().filter(on).collect()
        };
        let sides = [side(0), side(1)];
        let few = usize::from(sides[1].len() < sides[0].len());
        let (moved, frame) = (&sides[few], &sides[1 - few]);
        if moved.is_empty() || frame.len() < AGAIN_FRAME {
            return Vec::new();
        }
        let Some(to_ghost) = self.to_ghost(frame.iter().copied()) else {
            return Vec::new();
        };
        let again =
            |im: &&SparseImage| self.at_ghost(&to_ghost, &im.image.name, &im.image.centre());
        match moved.iter().all(again) {
            true => moved.iter().map(|im| im.image.name.clone()).collect(),
            false => Vec::new(),
        }
    }

    /// Whether camera centre `centre` of `image`, carried by `to_ghost` into the ghost's frame,
    /// lies within [`MISPLACED_DISTANCE`] of the ghost's spread of where the ghost had it.
    fn at_ghost(&self, to_ghost: &Similarity, image: &str, centre: &Vector3<f64>) -> bool {
        self.cameras.get(image).is_some_and(|ghost| {
            (to_ghost.apply(centre) - ghost.centre()).norm() <= MISPLACED_DISTANCE * self.spread()
        })
    }

    /// The cameras of `images` this ghost has too: as given, and as the ghost had them.
    fn shared<'m>(
        &self,
        images: impl Iterator<Item = &'m SparseImage>,
    ) -> (Vec<ModelImage>, Vec<ModelImage>) {
        (images
            .filter_map(|im| Some((im.image.clone(), self.cameras.get(&im.image.name)?.clone()))))
        .unzip()
    }

    /// The similarity that carries the cameras of `images` this ghost has onto the ghost's.
    fn to_ghost<'m>(&self, images: impl Iterator<Item = &'m SparseImage>) -> Option<Similarity> {
        let (here, ghost) = self.shared(images);
        Similarity::fit(&camera_points(&here), &camera_points(&ghost))
    }

    /// The spread of the ghost's cameras (median distance to their centroid).
    fn spread(&self) -> f64 {
        let ghost: Vec<Vector3<f64>> = self.cameras.values().map(ModelImage::centre).collect();
        spread_of(&ghost)
    }
}

/// Cameras as points a similarity carries: each centre, and a point ahead of it along its view
/// at the centres' spread, so that cameras in a line (a street walked along) fix a rotation too.
fn camera_points(cameras: &[ModelImage]) -> Vec<Vector3<f64>> {
    let centres: Vec<Vector3<f64>> = cameras.iter().map(ModelImage::centre).collect();
    let reach = spread_of(&centres);
    let ahead = cameras
        .iter()
        .zip(&centres)
        .map(|(im, c)| c + reach * (im.rotation.inverse() * Vector3::z()));
    centres.iter().copied().chain(ahead).collect()
}

/// One correspondence: the second model's point, the first's, the database pair it is from, and
/// its match (keypoints in the pair's name order, as [`Evidence::matches`] holds them).
type Correspondence = (Vector3<f64>, Vector3<f64>, usize, [u32; 2]);

/// The joins among `models` (each with its check's verdict: ghosted models are not joined),
/// and the pairs left apart. Each pair of clean models with at least `min_group` images each
/// is tried; the `earlier` runs' ghosts that put the two onto each other count as refuted
/// placements.
pub fn join_models(
    models: &[(&SparseModel, bool)],
    evidence: &Evidence,
    settings: &CheckSettings,
    earlier: &[Glued],
) -> anyhow::Result<Joins> {
    let mut joins = Joins::default();
    let below = kept_below(settings);
    let usable = |m: &(&SparseModel, bool)| !m.1 && m.0.images.len() >= settings.min_group;
    for a in 0..models.len() {
        for b in a + 1..models.len() {
            if usable(&models[a]) && usable(&models[b]) {
                let pair = [models[a].0, models[b].0];
                let ghosts: Vec<&Glued> = (earlier.iter())
                    .filter(|g| g.between(pair[0], pair[1]))
                    .collect();
                match join_two([a, b], pair, evidence, settings, 0, &ghosts, below)? {
                    Outcome::Joined(join) => joins.joined.push(join),
                    Outcome::Apart(apart) => joins.apart.push(apart),
                }
            }
        }
    }
    Ok(joins)
}

/// Model `k`'s two `groups` (its worst split) placed as two models are, by the placement
/// [`join_models`] would join them with, where it moves the second group's points by more than
/// [`MISPLACED_DISTANCE`] of the model's spread.
///
/// For a clean model (`ghosted` false) that placement must come after a refuted one, as a
/// join's: the model misplaced the group as a whole. A global mapper with few true links left
/// between two copies can do this: the hall's second orbit, turned 17 degrees (docs/check.md).
///
/// For a ghosted model the model's own placement is the ghost, refuted by the check already,
/// so the first placement that scores under the placement threshold is taken: its links are
/// the true pairs across the ghost, which `prune --model` keeps while it blames the pairs that
/// glued the copies. A clean model's group misplaced keeps the ghost threshold: the placement
/// is the verdict there, measured as a detection (the README's table).
/// Measured on 18 ghosted models of the demo, hall and street designs: 328 of 329 links true,
/// where the blamed pairs held 303 true of 1,724 (docs/check.md).
pub fn place_group(
    k: usize,
    model: &SparseModel,
    groups: &[Vec<String>; 2],
    evidence: &Evidence,
    settings: &CheckSettings,
    ghosted: bool,
) -> anyhow::Result<Option<Join>> {
    if groups.iter().any(|g| g.len() < settings.min_group) {
        return Ok(None);
    }
    let [a, b] = [&groups[0], &groups[1]].map(|g| subset(model, g));
    let refuted = usize::from(ghosted);
    let below = if ghosted {
        kept_below(settings)
    } else {
        settings.threshold
    };
    let Outcome::Joined(join) =
        join_two([k, k], [&a, &b], evidence, settings, refuted, &[], below)?
    else {
        return Ok(None);
    };
    let placement = Similarity::from(&join.placement);
    let moved = apart(&b, &placement, &Similarity::identity());
    Ok((moved > MISPLACED_DISTANCE * spread(model)).then_some(join))
}

/// The score under which a placement whose links the repair keeps is taken:
/// [`CheckSettings::placement_threshold`], never above the ghost threshold. A street's group
/// placed a building further on by false pairs alone conflicts less than the ghost it would
/// replace, yet near the threshold (street 36-99's at 0.458: its six links, all false, kept,
/// the next run was the ghost again). Of the ghosts' placements in the stored loops' reports,
/// the links of those under 0.44 were 2,653 true and 49 false; of the six from 0.44 to the
/// threshold, 38 true and 33 false (docs/check.md).
fn kept_below(settings: &CheckSettings) -> f64 {
    settings.placement_threshold.min(settings.threshold)
}

/// `model`'s images named in `names`, with the points they observe.
pub(super) fn subset(model: &SparseModel, names: &[String]) -> SparseModel {
    let images: Vec<SparseImage> = model
        .images
        .iter()
        .filter(|im| names.contains(&im.image.name))
        .cloned()
        .collect();
    let ids: BTreeSet<u64> = images
        .iter()
        .flat_map(|im| im.points2d.iter().filter_map(|p| p.point3d_id))
        .collect();
    SparseModel {
        cameras: model.cameras.clone(),
        points: model
            .points
            .iter()
            .filter(|(id, _)| ids.contains(id))
            .map(|(id, p)| (*id, *p))
            .collect(),
        images,
    }
}

/// The join of models `[a, b]` (their indices `models`): the first placement of `b` in `a`'s
/// frame that does not conflict, if a stronger one did and the next one could not be taken
/// too, else why they stay [`Apart`]; `refuted` counts placements refuted before any is tried
/// (a ghost's own), and each of the earlier runs' `ghosts` between the two refuted one more,
/// and refutes its own placement again.
///
/// The next placement (of the correspondences the taken one leaves) can be a third place, as
/// a misplaced image's ([`super::resection::THIRD_PLACE_SHARE`]): where it explains pairs,
/// does not conflict either and puts the models elsewhere ([`THIRD_PLACE_APART`]), their
/// matches put them in two places the check cannot tell apart, a street's pieces a building
/// further on or two. Of the placements taken in the stored loops of sessions 43-46, the 5 with
/// such a next placement (all streets) had 8 links true of 107; every other's next placement
/// explained no pair, conflicted, or was the same place (the halls', the duplicates' and the
/// streets' right joins: docs/check.md, "A join with a third place").
///
/// Where no placement joins them and an earlier run's ghost lies between the two, the
/// placements that explained too few whole pairs are judged again, strongest first, with
/// [`Linking::Trimmed`] links: the first that does not conflict and scores under
/// `accept_below` joins them, its pairs kept with only their agreeing matches.
fn join_two(
    models: [usize; 2],
    [a, b]: [&SparseModel; 2],
    evidence: &Evidence,
    settings: &CheckSettings,
    refuted: usize,
    ghosts: &[&Glued],
    accept_below: f64,
) -> anyhow::Result<Outcome> {
    let mut refuted = refuted + ghosts.len();
    let (pairs, correspondences) = correspondences(a, b, evidence);
    let mut remaining: Vec<usize> = (0..correspondences.len()).collect();
    let mut rng = SplitMix(0);
    let tested = Tested::new(models, [a, b], evidence, settings, ghosts, &correspondences);
    let (spread, tolerance) = (tested.spread, tested.tolerance());
    let mut taken: Option<(Join, Similarity)> = None;
    let mut tried = Vec::new();
    // The placements that explained too few whole pairs, for the trimmed links.
    let mut too_few: Vec<(Similarity, Vec<usize>)> = Vec::new();
    // [`PLACEMENTS`] placements tried, and the one after a taken placement: its third place.
    for k in 0..=PLACEMENTS {
        if k == PLACEMENTS && taken.is_none() {
            break;
        }
        let Some((placement, inliers)) = ransac(&correspondences, &remaining, tolerance, &mut rng)
        else {
            break;
        };
        if inliers.len() < MIN_SUPPORT {
            break;
        }
        let links = links(
            &pairs,
            &correspondences,
            &inliers,
            evidence,
            Linking::Explained,
        );
        let after_taken = taken.is_some();
        let (test, this) = tested.test(&placement, links, &inliers)?;
        if this.verdict == TriedVerdict::TooFew {
            too_few.push((placement.clone(), inliers.clone()));
        }
        tried.push(this);
        match (test, &taken) {
            (Test::Explains, _) => {}
            (Test::Refuted, _) => refuted += 1,
            (Test::Clean(_), Some((join, at))) => {
                // A third place the check cannot refute, unless it is the taken one again.
                if apart(b, &placement, at) > THIRD_PLACE_APART * spread {
                    let score = Some(join.score);
                    return Ok(tested.apart(ApartReason::ThirdPlace, refuted, score, tried));
                }
            }
            // No ghost, so nothing weaker is taken after it, yet no better than a split the
            // check would doubt: not taken either.
            (Test::Clean(j), None) if j.score >= accept_below => {
                let score = Some(j.score);
                return Ok(tested.apart(ApartReason::Doubtful, refuted, score, tried));
            }
            // The strongest clean placement joins the models only after a stronger one
            // conflicted: without that, it may be a ghost the check cannot see (copies that
            // share their surroundings), and nothing tells it from a true one.
            (Test::Clean(j), None) if refuted == 0 => {
                let score = Some(j.score);
                return Ok(tested.apart(ApartReason::NothingRefuted, refuted, score, tried));
            }
            (Test::Clean(join), None) => taken = Some((Join { refuted, ..*join }, placement)),
        }
        if after_taken {
            break;
        }
        let used: BTreeSet<usize> = inliers.into_iter().collect();
        remaining.retain(|k| !used.contains(k));
    }
    match taken {
        Some((join, _)) => Ok(Outcome::Joined(Join { tried, ..join })),
        None => tested.with_trimmed_links(&pairs, &too_few, refuted, tried, accept_below),
    }
}

/// What the check makes of one placement of [`join_two`].
enum Test {
    /// It explains too few correspondences' pairs to place anything ([`MIN_SUPPORT`]).
    Explains,
    /// It conflicts, or puts the models where an earlier run's ghost had them.
    Refuted,
    /// It does not conflict: the join it makes (its `refuted` still to be counted).
    Clean(Box<Join>),
}

/// The models, evidence and correspondences the placements of [`join_two`] are tested on.
struct Tested<'a> {
    /// The two models' indices, as [`Join::models`].
    models: [usize; 2],
    pair: [&'a SparseModel; 2],
    evidence: &'a Evidence,
    settings: &'a CheckSettings,
    ghosts: &'a [&'a Glued],
    correspondences: &'a [Correspondence],
    /// The first model's spread (median distance of its points to their centroid): the scale
    /// of the agreement distance and of a third place.
    spread: f64,
}

impl<'a> Tested<'a> {
    /// Placements of `pair`'s second model in the first's frame, tested on `correspondences`.
    fn new(
        models: [usize; 2],
        pair: [&'a SparseModel; 2],
        evidence: &'a Evidence,
        settings: &'a CheckSettings,
        ghosts: &'a [&'a Glued],
        correspondences: &'a [Correspondence],
    ) -> Self {
        Tested {
            models,
            pair,
            evidence,
            settings,
            ghosts,
            correspondences,
            spread: spread(pair[0]),
        }
    }

    /// The agreement distance of the placements: [`INLIER_DISTANCE`] of the first's spread.
    fn tolerance(&self) -> f64 {
        INLIER_DISTANCE * self.spread
    }

    /// The last resort of [`join_two`], where no placement joined the two with whole pairs and
    /// an earlier ghost lies between them: the placements that explained `too_few` whole pairs
    /// (on `pairs`), judged with [`Linking::Trimmed`] links, strongest first; the first clean
    /// one that scores under `accept_below` joins them. Else apart, after the placements
    /// `tried`.
    fn with_trimmed_links(
        &self,
        pairs: &[[String; 2]],
        too_few: &[(Similarity, Vec<usize>)],
        mut refuted: usize,
        mut tried: Vec<Tried>,
        accept_below: f64,
    ) -> anyhow::Result<Outcome> {
        for (placement, inliers) in too_few.iter().filter(|_| !self.ghosts.is_empty()) {
            let links = links(
                pairs,
                self.correspondences,
                inliers,
                self.evidence,
                Linking::Trimmed,
            );
            let (test, this) = self.test(placement, links, inliers)?;
            tried.push(Tried {
                trimmed: true,
                ..this
            });
            match test {
                Test::Refuted => refuted += 1,
                Test::Clean(join) if join.score < accept_below => {
                    let join = Join {
                        refuted,
                        tried,
                        ..*join
                    };
                    return Ok(Outcome::Joined(join));
                }
                Test::Explains | Test::Clean(_) => {}
            }
        }
        Ok(self.apart(ApartReason::NoPlacement, refuted, None, tried))
    }

    /// The two models left apart, for `reason`, after the placements `tried`.
    fn apart(
        &self,
        reason: ApartReason,
        refuted: usize,
        score: Option<f64>,
        tried: Vec<Tried>,
    ) -> Outcome {
        Outcome::Apart(Apart {
            models: self.models,
            correspondences: self.correspondences.len(),
            refuted,
            reason,
            score,
            tried,
        })
    }

    /// `placement`, agreed with by the correspondences `inliers` on `links`, tested; with what
    /// the report lists of it.
    fn test(
        &self,
        placement: &Similarity,
        links: Vec<Link>,
        inliers: &[usize],
    ) -> anyhow::Result<(Test, Tried)> {
        let [a, b] = self.pair;
        let one_spot = degenerate(self.correspondences, inliers, self.tolerance());
        let linked: usize = links.iter().map(|l| l.agreeing).sum();
        let ghost_offset = (self.ghosts.iter())
            .filter_map(|g| g.offset(a, b, placement))
            .reduce(f64::min);
        let tried = |verdict, score| Tried {
            placement: Placement::from(placement),
            support: inliers.len(),
            linked,
            ghost_offset,
            verdict,
            score,
            trimmed: false,
        };
        if one_spot {
            return Ok((Test::Explains, tried(TriedVerdict::OneSpot, None)));
        }
        if linked < MIN_SUPPORT {
            return Ok((Test::Explains, tried(TriedVerdict::TooFew, None)));
        }
        if ghost_offset.is_some_and(|off| off <= GHOST_AGAIN) {
            // An earlier ghost's placement again: refuted then, whatever it scores now.
            return Ok((Test::Refuted, tried(TriedVerdict::GhostAgain, None)));
        }
        let (merged, from_b) = put_together(a, b, placement);
        let counts = conflict::count_model(
            &merged,
            Some(self.evidence),
            &self.settings.conflict,
            |name| from_b.contains(name),
        )?;
        let score = score(&counts, false, self.settings);
        // The check's own verdict on the two models put together.
        Ok(match is_ghost(&counts, false, self.settings) {
            true => (Test::Refuted, tried(TriedVerdict::Conflicts, Some(score))),
            false => (
                Test::Clean(Box::new(Join {
                    models: self.models,
                    correspondences: self.correspondences.len(),
                    placement: Placement::from(placement),
                    support: inliers.len(),
                    refuted: 0,
                    ghost_offset,
                    counts,
                    score,
                    links,
                    tried: Vec::new(),
                })),
                tried(TriedVerdict::Clean, Some(score)),
            ),
        })
    }
}

/// The database pairs between the two models' images (image of `a`, image of `b`) and every
/// match between keypoints that lie on a point of each model.
fn correspondences(
    a: &SparseModel,
    b: &SparseModel,
    evidence: &Evidence,
) -> (Vec<[String; 2]>, Vec<Correspondence>) {
    let in_a: BTreeSet<&str> = a.images.iter().map(|im| im.image.name.as_str()).collect();
    let (mut pairs, mut out) = (Vec::new(), Vec::new());
    for ia in &a.images {
        for ib in b
            .images
            .iter()
            .filter(|im| !in_a.contains(im.image.name.as_str()))
        {
            let (na, nb) = (&ia.image.name, &ib.image.name);
            let (key, swapped) = if na < nb {
                ((na.clone(), nb.clone()), false)
            } else {
                ((nb.clone(), na.clone()), true)
            };
            let Some(matches) = evidence.matches.get(&key) else {
                continue;
            };
            let pair = pairs.len();
            pairs.push([na.clone(), nb.clone()]);
            for m in matches {
                let (ka, kb) = if swapped { (m[1], m[0]) } else { (m[0], m[1]) };
                if let (Some(xa), Some(xb)) = (point_of(a, ia, ka), point_of(b, ib, kb)) {
                    out.push((xb, xa, pair, *m));
                }
            }
        }
    }
    (pairs, out)
}

/// The model point keypoint `k` of `image` lies on, if any.
fn point_of(model: &SparseModel, image: &SparseImage, k: u32) -> Option<Vector3<f64>> {
    let id = image.points2d.get(k as usize)?.point3d_id?;
    model
        .points
        .get(&id)
        .map(|p| Vector3::new(p[0], p[1], p[2]))
}

/// A seeded generator (splitmix64) for RANSAC's samples: the check stays deterministic, and the
/// tool without the evaluation tooling needs no random-number crate (scripts/ci/test.sh).
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Three distinct entries of `from` (at least three long).
    fn three_of(&mut self, from: &[usize]) -> Vec<usize> {
        let mut picked: Vec<usize> = Vec::with_capacity(3);
        while picked.len() < 3 {
            let k = (self.next() % from.len() as u64) as usize;
            if !picked.contains(&k) {
                picked.push(k);
            }
        }
        picked.into_iter().map(|k| from[k]).collect()
    }
}

/// The median distance of the model's points to their centroid.
fn spread(model: &SparseModel) -> f64 {
    let points: Vec<Vector3<f64>> = model
        .points
        .values()
        .map(|p| Vector3::new(p[0], p[1], p[2]))
        .collect();
    spread_of(&points)
}

/// The median distance of `points` to their centroid (0 without points): the scale the check's
/// distances are measured in.
pub(super) fn spread_of(points: &[Vector3<f64>]) -> f64 {
    let centroid = points.iter().sum::<Vector3<f64>>() / points.len().max(1) as f64;
    median(points.iter().map(|p| (p - centroid).norm())).unwrap_or(0.0)
}

/// How far placements `p` and `q` put `model`'s points from each other (median).
fn apart(model: &SparseModel, p: &Similarity, q: &Similarity) -> f64 {
    median(model.points.values().map(|x| {
        let x = Vector3::new(x[0], x[1], x[2]);
        (p.apply(&x) - q.apply(&x)).norm()
    }))
    .unwrap_or(0.0)
}

/// The similarity (second model's frame -> first's) most of the `remaining` correspondences
/// agree with within `tolerance`, refitted on them, with those that agree after the refit.
fn ransac(
    c: &[Correspondence],
    remaining: &[usize],
    tolerance: f64,
    rng: &mut SplitMix,
) -> Option<(Similarity, Vec<usize>)> {
    if remaining.len() < 3 {
        return None;
    }
    let agreeing = |s: &Similarity| -> Vec<usize> {
        remaining
            .iter()
            .copied()
            .filter(|&k| (s.apply(&c[k].0) - c[k].1).norm() < tolerance)
            .collect()
    };
    let fit = |set: &[usize]| {
        let from: Vec<_> = set.iter().map(|&k| c[k].0).collect();
        let to: Vec<_> = set.iter().map(|&k| c[k].1).collect();
        Similarity::fit(&from, &to)
    };
    let mut best: Option<(Similarity, Vec<usize>)> = None;
    for _ in 0..HYPOTHESES {
        let set = rng.three_of(remaining);
        let Some(s) = fit(&set) else { continue };
        let inliers = agreeing(&s);
        if best.as_ref().is_none_or(|b| inliers.len() > b.1.len()) {
            best = Some((s, inliers));
        }
    }
    let (s, inliers) = best?;
    // One least-squares refit on the agreeing correspondences, kept if it loses none.
    match fit(&inliers).map(|r| (agreeing(&r), r)) {
        Some((refit, r)) if refit.len() >= inliers.len() => Some((r, refit)),
        _ => Some((s, inliers)),
    }
}

/// Whether the agreeing correspondences `inliers` lie on one spot of the first model: a
/// placement that shrinks the second model onto it (its scale near 0) agrees with every
/// correspondence there, and places nothing (a street's group of 10 images: 43,458 such
/// correspondences).
fn degenerate(c: &[Correspondence], inliers: &[usize], tolerance: f64) -> bool {
    let targets = inliers.iter().map(|&k| c[k].1);
    let centroid = targets.clone().sum::<Vector3<f64>>() / inliers.len().max(1) as f64;
    median(targets.map(|t| (t - centroid).norm())).unwrap_or(0.0) <= DEGENERATE_EXTENT * tolerance
}

/// Model `a` with `b`'s images (those `a` lacks) and points carried into `a`'s frame by
/// `placement`, point ids after `a`'s; and the names of the images from `b`.
pub(crate) fn put_together(
    a: &SparseModel,
    b: &SparseModel,
    placement: &Similarity,
) -> (SparseModel, BTreeSet<String>) {
    let mut merged = a.clone();
    let offset = a.points.keys().next_back().map_or(0, |id| id + 1);
    for camera in &b.cameras {
        if !merged
            .cameras
            .iter()
            .any(|c| c.camera_id == camera.camera_id)
        {
            merged.cameras.push(camera.clone());
        }
    }
    let names: BTreeSet<String> = a.images.iter().map(|im| im.image.name.clone()).collect();
    let mut from_b = BTreeSet::new();
    let inverse = placement.rotation.inverse();
    for im in b.images.iter().filter(|im| !names.contains(&im.image.name)) {
        // x_cam = R_c x + t_c with x = R^T (x' - T) / s; scaled by s (a pose's scale does not
        // change what it sees): R_c' = R_c R^T, t_c' = s t_c - R_c' T.
        let rotation_matrix = im.image.rotation.to_rotation_matrix() * inverse;
        let translation =
            placement.scale * im.image.translation - (rotation_matrix * placement.translation);
        let mut moved = im.clone();
        moved.image = ModelImage {
            rotation: UnitQuaternion::from_rotation_matrix(&rotation_matrix),
            translation,
            ..im.image.clone()
        };
        for p in &mut moved.points2d {
            p.point3d_id = p.point3d_id.map(|id| id + offset);
        }
        from_b.insert(im.image.name.clone());
        merged.images.push(moved);
    }
    for (id, p) in &b.points {
        let x = placement.apply(&Vector3::new(p[0], p[1], p[2]));
        merged.points.insert(id + offset, [x[0], x[1], x[2]]);
    }
    (merged, from_b)
}

/// Which pairs link two models under a placement, and with which of their matches the repair
/// keeps them ([`links`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Linking {
    /// The pairs the placement explains: at least [`PAIR_MIN_FRACTION`] of their
    /// correspondences agree. A pair that also holds a second place, as many correspondences
    /// the placement does not explain as a mapper needs to use a pair
    /// ([`DEFAULT_MIN_NUM_MATCHES`]), is kept with only its agreeing matches where those too
    /// are that many; any other is kept whole. A street's pair that sees one building in both
    /// images and the next building in one of them holds matches of both places: kept whole,
    /// its matches of the next building led the mapper to draw 12 cameras a building along
    /// (street 30-6303, session 64: 45 of its 90 correspondences agreed with the true join);
    /// trimmed, the same database mapped 30 of 30. Trimmed of its disagreeing correspondences
    /// alone, keeping its matches on no point, it did not (docs/check.md).
    Explained,
    /// Every pair with [`PAIR_MIN_AGREEING`] agreeing correspondences, whatever share of
    /// theirs that is, kept with those alone: the links of two orbits whose true placement
    /// explains no whole pair, because every pair that holds its correspondences holds more
    /// of the ghost's (plain 38-6014: 5-39 agreeing of 96-317 matches; trimmed so, the mapper
    /// makes one correct model with every mapper tried: docs/check.md).
    Trimmed,
}

impl Linking {
    /// Whether a pair with `agreeing` of its `total` correspondences agreeing links the models.
    fn links(self, agreeing: usize, total: usize) -> bool {
        agreeing >= PAIR_MIN_AGREEING
            && (self == Linking::Trimmed || agreeing as f64 >= PAIR_MIN_FRACTION * total as f64)
    }

    /// Whether such a link is kept with only its agreeing matches.
    fn trims(self, agreeing: usize, total: usize) -> bool {
        let two_places =
            agreeing >= DEFAULT_MIN_NUM_MATCHES && total - agreeing >= DEFAULT_MIN_NUM_MATCHES;
        self == Linking::Trimmed || two_places
    }
}

/// The pairs that link two models under a placement (`linking`), most agreeing first, with
/// their correspondences among `inliers`; for a link kept trimmed, the pair's other matches
/// (from the database) as [`Link::dropped`].
fn links(
    pairs: &[[String; 2]],
    c: &[Correspondence],
    inliers: &[usize],
    evidence: &Evidence,
    linking: Linking,
) -> Vec<Link> {
    let (total, agreeing) = per_pair(c, inliers);
    let mut out: Vec<Link> = (agreeing.into_iter())
        .filter(|(p, m)| linking.links(m.len(), total[p]))
        .map(|(p, m)| {
            let dropped = if linking.trims(m.len(), total[&p]) {
                let [first, second] = in_name_order(pairs[p][0].clone(), pairs[p][1].clone());
                let all = evidence.matches.get(&(first, second));
                (all.into_iter().flatten())
                    .filter(|x| !m.contains(*x))
                    .copied()
                    .collect()
            } else {
                Vec::new()
            };
            Link {
                image1: pairs[p][0].clone(),
                image2: pairs[p][1].clone(),
                correspondences: total[&p],
                agreeing: m.len(),
                dropped,
            }
        })
        .collect();
    by_agreeing(&mut out);
    out
}

/// Per database pair (its index), the matches that agree with a placement.
type AgreeingByPair = BTreeMap<usize, BTreeSet<[u32; 2]>>;

/// Each pair's correspondences (by pair index), and of them the matches that agree with a
/// placement (those of `inliers`): what [`links`] keeps pairs by.
fn per_pair(c: &[Correspondence], inliers: &[usize]) -> (BTreeMap<usize, usize>, AgreeingByPair) {
    let mut total: BTreeMap<usize, usize> = BTreeMap::new();
    c.iter().for_each(|x| *total.entry(x.2).or_default() += 1);
    let mut agreeing = AgreeingByPair::new();
    for &k in inliers {
        agreeing.entry(c[k].2).or_default().insert(c[k].3);
    }
    (total, agreeing)
}

/// Links most agreeing correspondences first, then by name.
fn by_agreeing(links: &mut [Link]) {
    links.sort_by(|x, y| {
        y.agreeing
            .cmp(&x.agreeing)
            .then((&x.image1, &x.image2).cmp(&(&y.image1, &y.image2)))
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Correspondences whose first-model points lie on one spot place nothing; spread out,
    /// they do.
    #[test]
    fn correspondences_on_one_spot_are_degenerate() {
        let at = |x: f64| {
            (
                Vector3::new(x, 0.0, 0.0),
                Vector3::new(0.001 * x, 0.0, 0.0),
                0,
                [0, 0],
            )
        };
        let c: Vec<Correspondence> = (0..50).map(|k| at(f64::from(k))).collect();
        let all: Vec<usize> = (0..50).collect();
        assert!(degenerate(&c, &all, 0.1));
        assert!(!degenerate(&c, &all, 0.001));
    }
}
