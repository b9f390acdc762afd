//! What a wrong model still says about the database's pairs. Where the check can tell which
//! images a model placed consistently with each other (each group of a ghost's split, or every
//! image but the ones it places elsewhere), a pair of two such images whose verified matches
//! the model mostly holds as two different points is one the mapper refused: in a street of
//! identical buildings, the false pairs between look-alike views (docs/check.md, "Pairs the
//! model refused"). `prune --model` blames them with the glue, so the next selection cannot
//! take them instead: without this, a camera placed back from its look-alike's spot left the
//! look-alike's own false pairs to its neighbours free, and the next run put the look-alike
//! there (street seed 72). Where the capture is one sequence (`--sequence`), an image and the
//! next belong together whatever the model says: a model that holds their matches apart is
//! folded ([`neighbours_apart`]).

use super::resection::AGREE_PX;
use super::splits::Sets;
use super::views::Views;
use std::collections::HashMap;

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
        match held(views, a, b, None) {
            Some(Held::Apart) => judged.push((a, b)),
            Some(Held::Joined) => {
                tied.union(a, b);
            }
            None => {}
        }
    }
    let mut out: Vec<[String; 2]> = judged
        .into_iter()
        .filter(|&(a, b)| tied.find(a) == tied.find(b))
        .map(|(a, b)| views.name_pair(a, b))
        .collect();
    out.sort();
    out
}

/// What a model says of one pair's matches, where it says enough ([`MIN_HELD`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Held {
    /// More than [`APART_RATIO`] times as many matches held apart as held as one point:
    /// refused.
    Apart,
    /// At least as many held as one point as held apart: confirmed.
    Joined,
}

/// How the model holds the matches of views `a` and `b` ([`Views::matches_held`], `within`
/// its pixels): refused, confirmed, or neither.
fn held(views: &Views, a: usize, b: usize, within: Option<f64>) -> Option<Held> {
    let (joined, apart) = views.matches_held(a, b, within);
    if joined + apart < MIN_HELD {
        None
    } else if apart as f64 > APART_RATIO * joined as f64 {
        Some(Held::Apart)
    } else {
        (joined >= apart).then_some(Held::Joined)
    }
}

/// The pairs of views next to each other in `order` (every image's name, in capture order)
/// whose matches the model holds apart ([`MIN_HELD`], [`APART_RATIO`]; two points that each
/// project within [`AGREE_PX`] of the other's keypoint count as one), as name pairs in name
/// order, sorted. Where the capture is one sequence, an image and the next saw the same scene,
/// so their matches are true: a model that holds them as two surfaces put one of the two on
/// another copy. On the lab photographs' folds the pairs across the fold are held apart
/// (Books' frames 13 and 14: none of their matches as one point, 110 as two), in their correct
/// models as one. Only the next image: two frames apart, a correct model of the lab Street
/// already holds a pair's matches apart (docs/check.md, "The capture order").
pub fn neighbours_apart(views: &Views, order: &[String]) -> Vec<[String; 2]> {
    let rank: HashMap<&str, usize> = (order.iter().enumerate())
        .map(|(k, name)| (name.as_str(), k))
        .collect();
    let position = |v: usize| rank.get(views.views[v].name.as_str()).copied();
    let mut out: Vec<[String; 2]> = (views.matches.keys())
        .filter(|&&(a, b)| match (position(a), position(b)) {
            (Some(x), Some(y)) => x.abs_diff(y) == 1,
            _ => false,
        })
        .filter(|&&(a, b)| held(views, a, b, Some(AGREE_PX)) == Some(Held::Apart))
        .map(|&(a, b)| views.name_pair(a, b))
        .collect();
    out.sort();
    out
}
