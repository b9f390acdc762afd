//! Conflicting observations between two groups of images (after Heinly et al., ECCV 2014):
//! where a point that group A saw projects into an image b of group B that looks at it from
//! nearly the same direction, b saw something there too. If some of what b saw there is also
//! A's, the two groups agree about that place; if all of it is b's group's alone, b sees other
//! structure exactly where A's is: the two groups are copies placed onto each other, unless the
//! database matched b's keypoints there to A's (the same structure, kept as two tracks:
//! [`super::evidence`]).

use super::evidence::Evidence;
use super::views::Views;
use crate::colmap::sparse::SparseModel;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// How the conflicts are counted.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConflictSettings {
    /// Largest angle, in degrees, between b's ray to the point and the ray of an image of A that
    /// saw it: beyond it, b might not see the point as A did (other side, occlusion, scale).
    pub max_angle_deg: f64,
    /// Largest ratio (either way) between b's distance to the point and that image of A's: at
    /// another scale b detects other features there (closer, finer texture; farther, only the
    /// coarse), which is no conflict. The same image of A must pass both tests.
    pub max_scale: f64,
    /// Neighbourhood radius around the projection, as a fraction of the image diagonal.
    pub radius: f64,
    /// Triangulated keypoints b needs in the neighbourhood for the sample to count.
    pub min_neighbours: usize,
    /// What a bare sample weighs against a conflicting one (0: bare samples are not judged).
    /// A bare sample is one where b has no keypoint at all near the projection: b sees a
    /// surface without texture where A's textured structure is. Copies that share plain
    /// surroundings conflict mostly so: the copy's structure, put where the other copy's
    /// cameras see bare walls (the plain design's ghosts, docs/check.md). It weighs less than a
    /// conflict, as a textureless occluder or a feature budget leaves a place bare too.
    pub bare_weight: f64,
    /// Images a triangulated point needs to count as its group's own structure in a split's
    /// count ([`count`]; 2: every point). A point two images saw rests on one pair's matches
    /// alone, and a false pair between repeated facades, which the epipolar test passes where
    /// the cameras move along the repetition, puts such points off every surface while both
    /// cameras stay right: they conflict wherever they project (docs/check.md). A point one
    /// image observes, which no mapper keeps, still counts. Records made before it counted
    /// every point.
    #[serde(default = "every_point")]
    pub min_track: usize,
}

/// [`ConflictSettings::min_track`] of records made before it: every point.
fn every_point() -> usize {
    2
}

/// Counts of one split, both directions together.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Counts {
    /// Samples (a point of one group projected into an image of the other that did not see
    /// it) whose neighbourhood holds only structure of the image's own group.
    pub conflicting: usize,
    /// Samples whose neighbourhood holds structure both groups saw, or keypoints the database
    /// matched to the projecting image's around the point.
    pub agreeing: usize,
    /// Of the agreeing, those only the database's matches showed.
    pub matched: usize,
    /// Points both sides saw: the structure they share, not judged (for one image alone, see
    /// [`count_alone`]).
    pub seen: usize,
    /// Samples whose neighbourhood holds no keypoint at all (counted only with a
    /// [`ConflictSettings::bare_weight`]).
    pub bare: usize,
}

impl Counts {
    /// The conflicting samples, each bare one counted `bare_weight`.
    pub fn conflicts(&self, bare_weight: f64) -> f64 {
        self.conflicting as f64 + bare_weight * self.bare as f64
    }

    /// The judged samples: [`Counts::conflicts`] and the agreeing ones.
    pub fn judged(&self, bare_weight: f64) -> f64 {
        self.conflicts(bare_weight) + self.agreeing as f64
    }

    /// [`Counts::conflicts`] over [`Counts::judged`]; 0 without samples.
    pub fn ratio(&self, bare_weight: f64) -> f64 {
        let judged = self.judged(bare_weight);
        if judged == 0.0 {
            0.0
        } else {
            self.conflicts(bare_weight) / judged
        }
    }
}

/// What each point is to a split: seen by the `false` side, the `true` side, or both; read
/// from a point's track the first time it is asked for. A split's count asks for the points
/// the smaller group reaches and their neighbours in the images judged, not every point of the
/// model: reading every track for each of some 4n splits took a seventh of the check's time at
/// 400 and 800 images (docs/check.md).
struct Membership<'a> {
    views: &'a Views<'a>,
    side: &'a [bool],
    /// By point: 0 not read yet, else 1 + (seen by false) + 2 × (seen by true).
    known: Vec<std::cell::Cell<u8>>,
}

impl<'a> Membership<'a> {
    fn new(views: &'a Views<'a>, side: &'a [bool]) -> Self {
        let known = vec![std::cell::Cell::new(0); views.points.len()];
        Membership { views, side, known }
    }

    /// Whether the `false` and the `true` side observe point `k`.
    fn of(&self, k: usize) -> [bool; 2] {
        let mut code = self.known[k].get();
        if code == 0 {
            let mut m = [false; 2];
            for &v in &self.views.observers[k] {
                m[usize::from(self.side[v])] = true;
            }
            code = 1 + u8::from(m[0]) + 2 * u8::from(m[1]);
            self.known[k].set(code);
        }
        [(code - 1) & 1 == 1, (code - 1) & 2 == 2]
    }
}

/// For each point, the views that could judge it: those that did not observe it but look at
/// it as one of its observers did (the angle and scale gates of [`ConflictSettings`]), in view
/// order. A split's count visits these instead of every view: found once, they keep a model's
/// check from growing with its images cubed (points times views, for each of some 4n splits).
pub struct Reach {
    /// By point: the views that could judge it.
    views: Vec<Vec<usize>>,
    /// By view: the points it observes or could judge, in point order.
    points: Vec<Vec<usize>>,
}

impl Reach {
    /// The views within the gates of each point of `views`.
    pub fn new(views: &Views, settings: &ConflictSettings) -> Reach {
        // Two cameras within the gates of a point stand at most `apart` times the first one's
        // distance to it apart (the law of cosines at the largest angle and either scale).
        let cos = settings.max_angle_deg.to_radians().cos();
        let apart = [settings.max_scale, 1.0 / settings.max_scale]
            .iter()
            .map(|s| (1.0 + s * s - 2.0 * s * cos).max(0.0).sqrt())
            .fold(0.0, f64::max)
            * (1.0 + 1e-6);
        let n = views.views.len();
        let centre = |v: usize| views.views[v].centre;
        // Each view's others by distance, as far as any point it saw allows.
        let near: Vec<Vec<(f64, usize)>> = (0..n)
            .map(|a| {
                let farthest = (views.seen_by[a].iter())
                    .map(|&k| (views.points[k] - centre(a)).norm())
                    .fold(0.0, f64::max);
                let mut near: Vec<(f64, usize)> = (0..n)
                    .filter(|&b| b != a)
                    .map(|b| ((centre(b) - centre(a)).norm(), b))
                    .filter(|&(d, _)| d <= apart * farthest)
                    .collect();
                near.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                near
            })
            .collect();
        let mut taken = vec![usize::MAX; n];
        let reach = (views.observers.iter().enumerate())
            .map(|(k, track)| {
                let x = views.points[k];
                let mut out = Vec::new();
                for &a in track {
                    let limit = apart * (x - centre(a)).norm();
                    for &(_, b) in near[a].iter().take_while(|(d, _)| *d <= limit) {
                        if taken[b] != k
                            && track.binary_search(&b).is_err()
                            && within_gates(views, &x, a, b, settings)
                        {
                            taken[b] = k;
                            out.push(b);
                        }
                    }
                }
                out.sort_unstable();
                out
            })
            .collect::<Vec<Vec<usize>>>();
        let mut points = vec![Vec::new(); n];
        for (k, (track, judging)) in views.observers.iter().zip(&reach).enumerate() {
            track.iter().chain(judging).for_each(|&v| points[v].push(k));
        }
        Reach {
            views: reach,
            points,
        }
    }

    /// The views that could judge point `k`, in view order.
    pub fn of(&self, k: usize) -> &[usize] {
        &self.views[k]
    }
}

/// Whether view `b` looks at point `x` as view `a` does: from nearly its direction and its
/// distance.
pub(super) fn within_gates(
    views: &Views,
    x: &Vector3<f64>,
    a: usize,
    b: usize,
    settings: &ConflictSettings,
) -> bool {
    let to_b = x - views.views[b].centre;
    let to_a = x - views.views[a].centre;
    let scale = to_b.norm() / to_a.norm();
    to_b.normalize().dot(&to_a.normalize()) >= settings.max_angle_deg.to_radians().cos()
        && scale <= settings.max_scale
        && scale * settings.max_scale >= 1.0
}

/// The conflicts of the split `side` (true: group B) in both directions, judged on the points
/// one group alone saw (Heinly et al.'s unique structure). A point both groups saw is what they
/// share: the duplicate structure that glued two copies, or the overlap of a correct model. It
/// agrees wherever it projects, and in a street of identical facades in front of a unique wall
/// that agreement outweighed the wall's conflicts (a block of 15 cameras two buildings off:
/// 0.45 with shared points, 0.64 without; correct streets' worst splits went down as well).
pub fn count(views: &Views, reach: &Reach, side: &[bool], settings: &ConflictSettings) -> Counts {
    let member = Membership::new(views, side);
    let mut counts = Counts::default();
    // A point counts only where it reaches both groups (observed in one, judged in the other):
    // every such point is among those the smaller group reaches.
    let smaller = usize::from(side.iter().filter(|&&s| s).count() * 2 <= side.len());
    let mut visited = vec![false; views.points.len()];
    // The observations of the point judged: (view, keypoint), one buffer for every point.
    let mut from: Vec<(usize, u32)> = Vec::new();
    let reached = (0..side.len())
        .filter(|&v| usize::from(side[v]) == smaller)
        .flat_map(|v| &reach.points[v]);
    for &k in reached {
        if std::mem::replace(&mut visited[k], true) {
            continue;
        }
        let owner = match member.of(k) {
            [true, true] => {
                counts.seen += 1;
                continue;
            }
            [_, owner] => owner,
        };
        if (2..settings.min_track).contains(&views.observers[k].len()) {
            continue;
        }
        from.clear();
        from.extend(views.observations(k));
        let ours = |j: usize| member.of(j)[usize::from(owner)];
        for &b in reach.of(k).iter().filter(|&&b| side[b] != owner) {
            counts.add(judge(views, k, b, &from, &ours, settings));
        }
    }
    counts
}

/// [`count`] on `model`'s views built afresh (two models put together, or one with images left
/// out), split into the images `in_b` names (group B) and the rest.
pub fn count_model(
    model: &SparseModel,
    evidence: Option<&Evidence>,
    settings: &ConflictSettings,
    in_b: impl Fn(&str) -> bool,
) -> anyhow::Result<Counts> {
    let views = Views::new(model, settings.radius, evidence)?;
    let side: Vec<bool> = views.views.iter().map(|v| in_b(&v.name)).collect();
    let reach = Reach::new(&views, settings);
    Ok(count(&views, &reach, &side, settings))
}

/// [`count`] of the split that puts view `b` alone in one group, in one pass over the points
/// `b` saw or could judge: what `b` saw, judged in every other view; what the others saw and
/// `b` did not, judged in `b`. Unlike [`count`], the points `b` shares with others are judged:
/// one image has no structure of its own (every point it observes has other observers), and a
/// camera on the wrong copy shows in where its points fall in the views that missed them.
pub fn count_alone(views: &Views, reach: &Reach, b: usize, settings: &ConflictSettings) -> Counts {
    let mut counts = Counts::default();
    for &k in &reach.points[b] {
        let track = &views.observers[k];
        match track.binary_search(&b) {
            Ok(at) => {
                counts.seen += usize::from(track.len() > 1);
                let from = [(b, views.observed_at[k][at])];
                let ours = |j: usize| views.observers[j].binary_search(&b).is_ok();
                for &v in reach.of(k) {
                    counts.add(judge(views, k, v, &from, &ours, settings));
                }
            }
            Err(_) => {
                let from: Vec<(usize, u32)> = views.observations(k).collect();
                let ours = |j: usize| views.observers[j].iter().any(|&v| v != b);
                counts.add(judge(views, k, b, &from, &ours, settings));
            }
        }
    }
    counts
}

/// For each view `v`, what each group of the split `side` saw alone (every other view of the
/// group counted, `v` left out), judged in `v`: `[false side, true side]`. An image agrees
/// with its own copy's structure and conflicts with the other's wherever the other copy's
/// structure projects into it; this reads that per image against whole groups, where a link's
/// count reads it against one other image, and a copy's images that see only the repeated
/// object agree with the other copy's too (docs/check.md).
pub fn leanings(
    views: &Views,
    reach: &Reach,
    side: &[bool],
    settings: &ConflictSettings,
) -> Vec<[Counts; 2]> {
    use rayon::prelude::*;
    let mut within = vec![[0u32; 2]; views.points.len()];
    for (k, track) in views.observers.iter().enumerate() {
        track
            .iter()
            .for_each(|&v| within[k][usize::from(side[v])] += 1);
    }
    (0..side.len())
        .into_par_iter()
        .map(|v| {
            let mut counts = [Counts::default(); 2];
            let mut from: Vec<(usize, u32)> = Vec::new();
            for &k in &reach.points[v] {
                let g = match within[k] {
                    [_, 0] => 0,
                    [0, _] => 1,
                    _ => continue,
                };
                if views.observers[k].binary_search(&v).is_ok() {
                    continue;
                }
                from.clear();
                from.extend(views.observations(k));
                // The points near the projection are `v`'s own: of group `g` through another
                // view of it.
                let own = u32::from(usize::from(side[v]) == g);
                let ours = |j: usize| within[j][g] > own;
                counts[g].add(judge(views, k, v, &from, &ours, settings));
            }
            counts
        })
        .collect()
}

/// How a sample ended.
pub(super) enum Sample {
    /// Only the image's own group's structure near the projection.
    Conflicting,
    /// Structure both groups saw near the projection.
    Agreeing,
    /// Only the own group's, but the database matched it to the projecting image's.
    Matched,
    /// No keypoint at all near the projection.
    Bare,
}

impl Counts {
    pub(super) fn add(&mut self, sample: Option<Sample>) {
        match sample {
            Some(Sample::Conflicting) => self.conflicting += 1,
            Some(Sample::Agreeing) => self.agreeing += 1,
            Some(Sample::Matched) => {
                self.agreeing += 1;
                self.matched += 1;
            }
            Some(Sample::Bare) => self.bare += 1,
            None => {}
        }
    }
}

/// How one sample ends: `None` when not judged (behind, outside, too oblique or far off in
/// scale, nothing triangulated near; without a bare weight, nothing near at all). `from` are
/// the projecting side's observations of point `k` (view, keypoint); `ours(j)` says whether
/// point `j` belongs to the projecting side.
pub(super) fn judge(
    views: &Views,
    k: usize,
    b: usize,
    from: &[(usize, u32)],
    ours: &dyn Fn(usize) -> bool,
    settings: &ConflictSettings,
) -> Option<Sample> {
    let x = views.points[k];
    if !from
        .iter()
        .any(|&(a, _)| within_gates(views, &x, a, b, settings))
    {
        return None;
    }
    let at = views.project(b, k)?;
    let radius = views.radius(b, settings.radius);
    let mut n = 0;
    for j in views.neighbours(b, at, radius) {
        if ours(j) {
            return Some(Sample::Agreeing);
        }
        n += 1;
    }
    if n < settings.min_neighbours {
        let bare = settings.bare_weight > 0.0 && !views.keypoint_near(b, at, radius);
        return bare.then_some(Sample::Bare);
    }
    let matched = from.iter().any(|&(a, keypoint)| {
        let seen = views.views[a].keypoints[keypoint as usize];
        views.matched_near((a, seen, views.radius(a, settings.radius)), (b, at, radius))
    });
    Some(if matched {
        Sample::Matched
    } else {
        Sample::Conflicting
    })
}

/// The conflicts between two single images `a` and `b`, both ways: their points the other did
/// not see, projected into the other.
pub fn pair_counts(views: &Views, a: usize, b: usize, settings: &ConflictSettings) -> Counts {
    let mut counts = Counts::default();
    for (from, to) in [(a, b), (b, a)] {
        let ours = |j: usize| views.observers[j].binary_search(&from).is_ok();
        for &k in &views.seen_by[from] {
            if views.observers[k].binary_search(&to).is_ok() {
                // Once, from the first image's side.
                counts.seen += usize::from(from == a);
                continue;
            }
            let Ok(at) = views.observers[k].binary_search(&from) else {
                continue;
            };
            let observation = (from, views.observed_at[k][at]);
            counts.add(judge(views, k, to, &[observation], &ours, settings));
        }
    }
    counts
}
