//! What a checked run tells `prune --model` about the database's pairs: the pairs a wrong
//! model glued or held a misplaced image by (blamed), those that place models, groups and
//! images back (links, rejoin), and the matches that held an image where it is not (dropped),
//! gathered over the repair loop's runs in the order they ran.

use super::evidence::{in_name_order, Evidence};
use super::settings::CheckSettings;
use super::{check_run, join, resection, JoiningPair, RunCheck};
use crate::colmap::sparse::SparseModel;
use anyhow::{Context, Result};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// What a mapper's output says about the database's pairs (`prune --model DIR`; `repair` in
/// `check`'s report).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ModelEvidence {
    /// In each model the check finds ghosted, the pairs across its worst split that share 3D
    /// points: the pairs whose matches glued one copy onto the other. Pairs across the split that
    /// share no point are not blamed: in a ghosted model they are mostly the true links the
    /// mapper could not use (measured on the demo scene: docs/check.md). Sorted.
    pub blamed: Vec<[String; 2]>,
    /// The pairs that link clean models the database's matches place in one frame without a
    /// conflict ([`join`]), and the two groups of a model that misplaced one of them
    /// ([`join::place_group`]): what the mapper needs to place them right. Sorted.
    pub links: Vec<[String; 2]>,
    /// The matches that hold the misplaced images where the model put them
    /// ([`resection::ImagePlacement::holding`]), and those of a trimmed link against its
    /// placement ([`join::Link::dropped`]), per pair in name order: `prune --model` drops them
    /// from the pairs it keeps. Sorted.
    pub dropped: Vec<resection::PairMatches>,
    /// The pairs that place an image no model registered in a clean model
    /// ([`resection::Rejoin`]): kept unless a ghost of any run blamed them. Sorted.
    pub rejoin: Vec<[String; 2]>,
}

impl RunCheck<'_> {
    /// What `prune --model` takes from this run: the blamed pairs of its ghosted models, and
    /// the pairs linking the clean models it joins, the groups it found misplaced and the
    /// ghosts' second groups where the matches place them (kept over the blame). Empty
    /// when a repair turn has nothing to act on (the loop's scripts stop there).
    pub fn evidence(&self) -> ModelEvidence {
        let mut blamed = BTreeSet::new();
        // A ghost that is its misplaced images is theirs: blaming every pair across its split
        // would tear the model (street seed 19: one camera a building off, a split of 16
        // against 28 images at 0.51; its 323 pairs blamed, the next run registered 28 of 44).
        // An image alone keeps its own blame.
        for worst in self
            .models
            .iter()
            .filter(|c| c.ghosted && !c.ghost_of_images)
            .flat_map(|c| &c.worst)
        {
            for p in worst
                .joining_pairs
                .iter()
                .filter(|p| blames(p, worst.alone()))
            {
                blamed.insert([p.image1.clone(), p.image2.clone()]);
            }
        }
        // The misplaced images whose matches agree on where they belong.
        let images = self
            .models
            .iter()
            .filter(|c| !c.ghost_of_groups())
            .flat_map(|c| c.misplaced_images.iter().filter(|m| c.takes(m)));
        for pair in images.clone().flat_map(|m| &m.against) {
            blamed.insert(pair.clone());
        }
        for pair in self.models.iter().flat_map(|c| &c.refused) {
            blamed.insert(pair.clone());
        }
        // Each pair's matches in name order, merged where both images are misplaced.
        let mut dropped: BTreeMap<[String; 2], BTreeSet<[u32; 2]>> = BTreeMap::new();
        for h in images.clone().flat_map(|m| &m.holding) {
            let (key, matches) = name_ordered(h);
            dropped.entry(key).or_default().extend(matches);
        }
        let mut links = BTreeSet::new();
        for [a, b] in images.flat_map(|m| &m.links).cloned() {
            links.insert(in_name_order(a, b));
        }
        let placed = self
            .models
            .iter()
            .flat_map(|c| c.misplaced.iter().chain(&c.ghost_placement));
        for l in self
            .joins
            .joined
            .iter()
            .chain(placed)
            .flat_map(|j| &j.links)
        {
            let key = in_name_order(l.image1.clone(), l.image2.clone());
            if !l.dropped.is_empty() {
                dropped.entry(key.clone()).or_default().extend(&l.dropped);
            }
            links.insert(key);
        }
        let rejoin = (self.rejoined.iter())
            .flat_map(|r| r.links.iter().cloned())
            .collect::<BTreeSet<_>>();
        ModelEvidence {
            blamed: blamed.into_iter().collect(),
            links: links.into_iter().collect(),
            rejoin: rejoin.into_iter().collect(),
            dropped: (dropped.into_iter())
                .map(|(images, m)| resection::PairMatches {
                    images,
                    matches: m.into_iter().collect(),
                })
                .collect(),
        }
    }
}

/// A pair's matches with the pair in name order, each match's keypoints swapped to follow.
fn name_ordered(h: &resection::PairMatches) -> ([String; 2], Vec<[u32; 2]>) {
    let [a, b] = h.images.clone();
    match a < b {
        true => ([a, b], h.matches.clone()),
        false => ([b, a], h.matches.iter().map(|&[x, y]| [y, x]).collect()),
    }
}

/// Whether a pair joining a ghost's two groups glued them: it shares points in the model. For
/// an image alone on the wrong copy, only where the model also holds at least as many of its
/// matches as one point as it holds apart: its true neighbours' matches land on the next
/// copy's points (street seeds 1 and 2: none of their 20 true pairs sharing points is blamed,
/// 8 of the 32 false ones are), and sparing them lets the next run place it. Two groups blame
/// every pair sharing points: across a street ghost's split 200 of the 204 false pairs are
/// held apart too (other copies), and would be spared (docs/check.md).
pub(super) fn blames(p: &JoiningPair, alone: bool) -> bool {
    p.shared_points > 0 && (!alone || p.matches_joined >= p.matches_apart)
}

/// The models of each of the repair loop's runs `dirs` (model folders or mappers'
/// output_paths; `option` names them in errors).
pub fn read_runs(dirs: &[std::path::PathBuf], option: &str) -> Result<Vec<Vec<SparseModel>>> {
    let read = |dir: &std::path::Path| -> Result<Vec<SparseModel>> {
        let dirs = crate::colmap::model::model_dirs(dir)?;
        dirs.iter()
            .map(|d| crate::colmap::sparse::read_sparse_model(d))
            .collect()
    };
    (dirs.iter())
        .map(|dir| read(dir).with_context(|| format!("reading {option} {}", dir.display())))
        .collect()
}

/// The repair's evidence from the repair loop's runs (`runs`, read from `dirs` in the order
/// they ran; `option` names them in errors), each checked with the database's `evidence`
/// after the ghosts of the runs before it ([`RunCheck::glued`]), `earlier`'s first (runs whose
/// blame is not taken): each run's evidence, and the ghosts of them all for a later run's
/// joins.
pub fn loop_evidence(
    dirs: &[std::path::PathBuf],
    runs: &[Vec<SparseModel>],
    option: &str,
    evidence: &Evidence,
    settings: &CheckSettings,
    mut earlier: Vec<join::Glued>,
) -> Result<(Vec<ModelEvidence>, Vec<join::Glued>)> {
    let mut found = Vec::new();
    for (dir, models) in dirs.iter().zip(runs) {
        let run = check_run(models, Some(evidence), settings, &earlier)
            .with_context(|| format!("checking {option} {}", dir.display()))?;
        found.push(run.evidence());
        earlier.extend(run.glued(models));
    }
    Ok((found, earlier))
}
