//! What the database adds to a model: the verified pairs a mapper could use (the pairs that join
//! two groups), and every match as it was verified, pruned or not. Where keypoints of an image b
//! around a point's projection are matched to keypoints of an image a around a's own
//! observation of that point, a and b saw the same structure there, even if the model holds it
//! as two tracks: a selection that drops the pairs between neighbouring images splits their
//! tracks, and the same surface comes out twice at the same place. Without this the check takes
//! such a model for two copies (measured on Cup and Books: docs/check.md).

use crate::colmap::database::Database;
use crate::colmap::sparse::SparseModel;
use anyhow::Result;
use std::collections::{BTreeMap, BTreeSet, HashSet};

/// Image names of a pair, in name order.
pub type NamePair = (String, String);

/// The database's side of the check, read once for every model.
#[derive(Clone, Debug, Default)]
pub struct Evidence {
    /// Verified pairs not invalidated by a prune, with their inliers: the pairs a mapper run on
    /// the database could use.
    pub pairs: BTreeMap<NamePair, usize>,
    /// Every originally verified pair's inlier matches (keypoint in the first image of the
    /// name pair, keypoint in the second), pruned or not: a prune does not change what the
    /// images saw.
    pub matches: BTreeMap<NamePair, Vec<[u32; 2]>>,
    /// Every image's name, sorted: the capture order where the names sort in it.
    pub images: Vec<String>,
}

impl Evidence {
    /// Reads the pairs and matches of `db`.
    pub fn load(db: &Database) -> Result<Evidence> {
        let names: BTreeMap<u32, String> = db
            .images()?
            .into_iter()
            .map(|im| (im.image_id, im.name))
            .collect();
        let ordered = |a: u32, b: u32| -> Option<(NamePair, bool)> {
            let (na, nb) = (names.get(&a)?, names.get(&b)?);
            Some(if na < nb {
                ((na.clone(), nb.clone()), false)
            } else {
                ((nb.clone(), na.clone()), true)
            })
        };
        let invalid: HashSet<u64> = db.invalidated_pair_ids()?;
        let (mut pairs, mut matches) = (BTreeMap::new(), BTreeMap::new());
        // One read of two_view_geometries: each row's inliers are its matches, and their count
        // is the pair's inliers (rows).
        for p in db.verified_pairs()? {
            let Some((key, swapped)) = ordered(p.image_id1, p.image_id2) else {
                continue;
            };
            if !invalid.contains(&crate::colmap::ids::pair_id(p.image_id1, p.image_id2)) {
                pairs.insert(key.clone(), p.inliers.len());
            }
            let inliers = if swapped {
                p.inliers.iter().map(|m| [m[1], m[0]]).collect()
            } else {
                p.inliers
            };
            matches.insert(key, inliers);
        }
        let mut images: Vec<String> = names.into_values().collect();
        images.sort();
        Ok(Evidence {
            pairs,
            matches,
            images,
        })
    }

    /// The images that a pair a mapper would use (at least `min_num_matches` inliers) links and
    /// that no model of `models` registered, in name order. COLMAP 3.8 relaxes its initial
    /// pair (16 degrees, then 8) only while it has no model at all, so a piece of the view
    /// graph that a repair's blame cut off, whose neighbours see their surroundings under small
    /// angles (a street walked past), starts no model in the run that registers the rest; a
    /// second run on these images alone starts one (README; docs/check.md, "Pieces that start no
    /// model"). COLMAP 4's incremental mapper relaxes while images are left over.
    pub fn unregistered(&self, models: &[SparseModel], min_num_matches: usize) -> Vec<String> {
        let registered: HashSet<&str> = (models.iter())
            .flat_map(|m| &m.images)
            .map(|im| im.image.name.as_str())
            .collect();
        let linked: BTreeSet<&String> = (self.pairs.iter())
            .filter(|(_, &inliers)| inliers >= min_num_matches)
            .flat_map(|((a, b), _)| [a, b])
            .collect();
        (linked.into_iter())
            .filter(|name| !registered.contains(name.as_str()))
            .cloned()
            .collect()
    }
}
