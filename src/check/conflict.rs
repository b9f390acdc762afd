//! Conflicting observations between two groups of images (after Heinly et al., ECCV 2014):
//! where a point that group A saw projects into an image b of group B that looks at it from
//! nearly the same direction, b saw something there too. If some of what b saw there is also
//! A's, the two groups agree about that place; if all of it is b's group's alone, b sees other
//! structure exactly where A's is: the two groups are copies placed onto each other.

use super::views::Views;
use serde::Serialize;

/// How the conflicts are counted.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ConflictSettings {
    /// Largest angle, in degrees, between b's ray to the point and the ray of an image of A that
    /// saw it: beyond it, b might not see the point as A did (other side, occlusion, scale).
    pub max_angle_deg: f64,
    /// Neighbourhood radius around the projection, as a fraction of the image diagonal.
    pub radius: f64,
    /// Triangulated keypoints b needs in the neighbourhood for the sample to count.
    pub min_neighbours: usize,
}

/// Counts of one split, both directions together.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Counts {
    /// Samples (a point of one group projected into an image of the other that did not see
    /// it) whose neighbourhood holds only structure of the image's own group.
    pub conflicting: usize,
    /// Samples whose neighbourhood holds structure both groups saw.
    pub agreeing: usize,
    /// Samples where the image saw the point itself.
    pub seen: usize,
}

impl Counts {
    /// Conflicting samples over all that were judged; 0 without samples.
    pub fn ratio(&self) -> f64 {
        let judged = self.conflicting + self.agreeing;
        if judged == 0 {
            0.0
        } else {
            self.conflicting as f64 / judged as f64
        }
    }
}

/// What each point is to a split: seen by the `false` side, the `true` side, or both.
fn membership(views: &Views, side: &[bool]) -> Vec<[bool; 2]> {
    views
        .observers
        .iter()
        .map(|track| {
            let mut m = [false; 2];
            for &v in track {
                m[usize::from(side[v])] = true;
            }
            m
        })
        .collect()
}

/// The conflicts of the split `side` (true: group B) in both directions.
pub fn count(views: &Views, side: &[bool], settings: &ConflictSettings) -> Counts {
    let member = membership(views, side);
    let mut counts = Counts::default();
    for (k, track) in views.observers.iter().enumerate() {
        for b in 0..views.views.len() {
            let group = usize::from(side[b]);
            // Only points the other group saw.
            if !member[k][1 - group] {
                continue;
            }
            if track.binary_search(&b).is_ok() {
                counts.seen += 1;
                continue;
            }
            let from: Vec<usize> = track
                .iter()
                .copied()
                .filter(|&a| usize::from(side[a]) != group)
                .collect();
            let ours = |j: usize| member[j][1 - group];
            match judge(views, k, b, &from, &ours, settings) {
                Some(true) => counts.conflicting += 1,
                Some(false) => counts.agreeing += 1,
                None => {}
            }
        }
    }
    counts
}

/// How one sample ends: `None` when not judged (behind, outside, too oblique, nothing near).
/// `ours(j)` says whether point `j` belongs to the projecting side.
fn judge(
    views: &Views,
    k: usize,
    b: usize,
    from: &[usize],
    ours: &dyn Fn(usize) -> bool,
    settings: &ConflictSettings,
) -> Option<bool> {
    let x = views.points[k];
    let view = &views.views[b];
    let ray = (x - view.centre).normalize();
    let cos_max = settings.max_angle_deg.to_radians().cos();
    let close = from
        .iter()
        .any(|&a| ray.dot(&(x - views.views[a].centre).normalize()) >= cos_max);
    if !close {
        return None;
    }
    let at = views.project(b, k)?;
    let radius = settings.radius * view.intrinsics.width.hypot(view.intrinsics.height);
    let mut n = 0;
    for j in views.neighbours(b, at, radius) {
        if ours(j) {
            return Some(false);
        }
        n += 1;
    }
    (n >= settings.min_neighbours).then_some(true)
}

/// The conflicts between two single images `a` and `b`, both ways: their points the other did
/// not see, projected into the other.
pub fn pair_counts(views: &Views, a: usize, b: usize, settings: &ConflictSettings) -> Counts {
    let mut counts = Counts::default();
    for (from, to) in [(a, b), (b, a)] {
        let ours = |j: usize| views.observers[j].binary_search(&from).is_ok();
        for &k in &views.seen_by[from] {
            if views.observers[k].binary_search(&to).is_ok() {
                counts.seen += 1;
                continue;
            }
            match judge(views, k, to, &[from], &ours, settings) {
                Some(true) => counts.conflicting += 1,
                Some(false) => counts.agreeing += 1,
                None => {}
            }
        }
    }
    counts
}
