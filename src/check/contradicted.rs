//! What a wrong model still says about the database's pairs. Where the check can tell which
//! images a model placed consistently with each other (each group of a ghost's split, or every
//! image but the ones it places elsewhere), a pair of two such images whose verified matches
//! the model mostly holds as two different points is one the mapper refused: in a street of
//! identical buildings, the false pairs between look-alike views (docs/check.md, "Pairs the
//! model refused"). `prune --model` blames them with the glue, so the next selection cannot
//! take them instead: without this, a camera placed back from its look-alike's spot left the
//! look-alike's own false pairs to its neighbours free, and the next run put the look-alike
//! there (street seed 72).

use super::splits::Sets;
use super::views::Views;

/// A pair is judged with at least this many of its matches on points in both images...
pub const MIN_HELD: usize = 20;
/// ... and refused where the model holds more than this many times as many of them apart as
/// it holds as one point; it confirms the pair where it holds at least as many as one point.
pub const APART_RATIO: f64 = 1.5;

/// The pairs of views `group` puts in one group (views without a group are not judged) whose
/// matches the model holds apart ([`MIN_HELD`], [`APART_RATIO`]), as name pairs in name order,
/// sorted. Only pairs the confirmed pairs of that group connect: two images a group's other
/// pairs do not tie to it (a street's two cameras placed a building off inside a ghost's
/// group, seed 79) are not placed consistently with it, and refusing their pairs to it would
/// tear them off.
pub fn refused_pairs(views: &Views, group: &[Option<bool>]) -> Vec<[String; 2]> {
    let mut judged = Vec::new();
    let mut tied = Sets::new(views.views.len());
    // The pairs with matches; the components do not depend on their order.
    for &(a, b) in views.matches.keys() {
        if group[a].is_none() || group[a] != group[b] {
            continue;
        }
        let (joined, apart) = views.matches_held(a, b);
        if joined + apart < MIN_HELD {
            continue;
        }
        if apart as f64 > APART_RATIO * joined as f64 {
            judged.push((a, b));
        } else if joined >= apart {
            tied.union(a, b);
        }
    }
    let mut out: Vec<[String; 2]> = judged
        .into_iter()
        .filter(|&(a, b)| tied.find(a) == tied.find(b))
        .map(|(a, b)| {
            let (x, y) = (&views.views[a].name, &views.views[b].name);
            [x.min(y).clone(), x.max(y).clone()]
        })
        .collect();
    out.sort();
    out
}
