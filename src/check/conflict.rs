//! Conflicting observations between two groups of images (after Heinly et al., ECCV 2014):
//! where a point that group A saw projects into an image b of group B that looks at it from
//! nearly the same direction, b saw something there too. If some of what b saw there is also
//! A's, the two groups agree about that place; if all of it is b's group's alone, b sees other
//! structure exactly where A's is: the two groups are copies placed onto each other, unless the
//! database matched b's keypoints there to A's (the same structure, kept as two tracks:
//! [`super::evidence`]).

use super::views::Views;
use serde::Serialize;

/// How the conflicts are counted.
#[derive(Clone, Copy, Debug, Serialize)]
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
            let from: Vec<(usize, u32)> = track
                .iter()
                .copied()
                .zip(views.observed_at[k].iter().copied())
                .filter(|&(a, _)| usize::from(side[a]) != group)
                .collect();
            let ours = |j: usize| member[j][1 - group];
            counts.add(judge(views, k, b, &from, &ours, settings));
        }
    }
    counts
}

/// [`count`] of the split that puts view `b` alone in one group, in one pass over the points
/// instead of one per view: what `b` saw, judged in every other view; what the others saw and
/// `b` did not, judged in `b`.
pub fn count_alone(views: &Views, b: usize, settings: &ConflictSettings) -> Counts {
    let mut counts = Counts::default();
    for (k, track) in views.observers.iter().enumerate() {
        match track.binary_search(&b) {
            Ok(at) => {
                if track.len() > 1 {
                    // Seen by b and by others: seen in b, and in each other observer.
                    counts.seen += track.len();
                }
                let from = [(b, views.observed_at[k][at])];
                let ours = |j: usize| views.observers[j].binary_search(&b).is_ok();
                for v in (0..views.views.len()).filter(|v| track.binary_search(v).is_err()) {
                    counts.add(judge(views, k, v, &from, &ours, settings));
                }
            }
            Err(_) => {
                let from: Vec<(usize, u32)> = track
                    .iter()
                    .copied()
                    .zip(views.observed_at[k].iter().copied())
                    .collect();
                let ours = |j: usize| views.observers[j].iter().any(|&v| v != b);
                counts.add(judge(views, k, b, &from, &ours, settings));
            }
        }
    }
    counts
}

/// How a sample ended.
enum Sample {
    /// Only the image's own group's structure near the projection.
    Conflicting,
    /// Structure both groups saw near the projection.
    Agreeing,
    /// Only the own group's, but the database matched it to the projecting image's.
    Matched,
}

impl Counts {
    fn add(&mut self, sample: Option<Sample>) {
        match sample {
            Some(Sample::Conflicting) => self.conflicting += 1,
            Some(Sample::Agreeing) => self.agreeing += 1,
            Some(Sample::Matched) => {
                self.agreeing += 1;
                self.matched += 1;
            }
            None => {}
        }
    }
}

/// How one sample ends: `None` when not judged (behind, outside, too oblique or far off in
/// scale, nothing near). `from` are the projecting side's observations of point `k` (view,
/// keypoint); `ours(j)` says whether point `j` belongs to the projecting side.
fn judge(
    views: &Views,
    k: usize,
    b: usize,
    from: &[(usize, u32)],
    ours: &dyn Fn(usize) -> bool,
    settings: &ConflictSettings,
) -> Option<Sample> {
    let x = views.points[k];
    let view = &views.views[b];
    let to_b = x - view.centre;
    let (ray_b, distance_b) = (to_b.normalize(), to_b.norm());
    let cos_max = settings.max_angle_deg.to_radians().cos();
    let close = from.iter().any(|&(a, _)| {
        let to_a = x - views.views[a].centre;
        let scale = distance_b / to_a.norm();
        ray_b.dot(&to_a.normalize()) >= cos_max
            && scale <= settings.max_scale
            && scale * settings.max_scale >= 1.0
    });
    if !close {
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
        return None;
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
                counts.seen += 1;
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
