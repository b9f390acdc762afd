//! What the database adds to a model: the verified pairs a mapper could use (the pairs that join
//! two groups), and every match as it was verified, pruned or not. Where keypoints of an image b
//! around a point's projection are matched to keypoints of an image a around a's own
//! observation of that point, a and b saw the same structure there, even if the model holds it
//! as two tracks: a selection that drops the pairs between neighbouring images splits their
//! tracks, and the same surface comes out twice at the same place. Without this the check takes
//! such a model for two copies (measured on Cup and Books: docs/check.md).

use crate::colmap::database::Database;
use crate::colmap::ids::camera_model_name;
use crate::colmap::model::ModelCamera;
use crate::colmap::sparse::SparseModel;
use anyhow::{Context, Result};
use std::collections::{BTreeMap, BTreeSet, HashSet};

/// Image names of a pair, in name order.
pub type NamePair = (String, String);

/// The names `a` and `b` in name order, as pairs are listed in reports and repair lists.
pub fn in_name_order(a: String, b: String) -> [String; 2] {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}

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
    /// Images no model registered, as the database has them, read by
    /// [`Evidence::read_lost`] for placing them in a model by their matches
    /// ([`super::resection::place_lost`]). Empty until then.
    pub lost_images: BTreeMap<String, LostImage>,
}

/// What placing an image without a pose needs: its keypoints and its camera.
#[derive(Clone, Debug)]
pub struct LostImage {
    /// COLMAP's camera_id: the model's camera of that id, refined, is used where it has one.
    pub camera_id: u32,
    /// The database's camera (the mapper's starting guess).
    pub camera: ModelCamera,
    /// Keypoint positions, by keypoint index.
    pub keypoints: Vec<[f64; 2]>,
    /// Its verified matches, pruned or not, per other image: (this image's keypoint, the
    /// other's).
    pub matches: Vec<(String, Vec<[u32; 2]>)>,
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
            lost_images: BTreeMap::new(),
        })
    }

    /// The images with a verified pair of at least `min_num_matches` inliers, pruned or not,
    /// that no model of `models` registered, in name order: the cameras a user lost, whether
    /// the mapper failed to register them or a selection left them out. The repair places them
    /// by their matches ([`super::resection::place_lost`]).
    pub fn lost(&self, models: &[SparseModel], min_num_matches: usize) -> Vec<String> {
        let matched = self.matches.iter().map(|(pair, m)| (pair, m.len()));
        not_registered(models, matched, min_num_matches)
    }

    /// Reads the keypoints and camera of each image of `names` from `db` into
    /// [`Evidence::lost_images`] (only these: a large database's keypoints are not all needed).
    pub fn read_lost<'a>(
        &mut self,
        db: &Database,
        names: impl IntoIterator<Item = &'a String>,
    ) -> Result<()> {
        let images: BTreeMap<String, _> = (db.images()?.into_iter())
            .map(|im| (im.name.clone(), im))
            .collect();
        let cameras: BTreeMap<u32, _> = (db.cameras()?.into_iter())
            .map(|c| (c.camera_id, c))
            .collect();
        for name in names {
            let image = images
                .get(name)
                .with_context(|| format!("no image `{name}`"))?;
            let c = cameras.get(&image.camera_id).with_context(|| {
                format!(
                    "image {name} names camera {}, which the database lacks",
                    image.camera_id
                )
            })?;
            let camera = ModelCamera {
                camera_id: c.camera_id,
                model: camera_model_name(c.model_id).unwrap_or("?").to_string(),
                width: c.width,
                height: c.height,
                params: c.params.clone(),
            };
            let keypoints = (db.keypoints_xy(image.image_id)?.into_iter())
                .map(|[x, y]| [f64::from(x), f64::from(y)])
                .collect();
            let lost = LostImage {
                camera_id: image.camera_id,
                camera,
                keypoints,
                matches: Vec::new(),
            };
            self.lost_images.insert(name.clone(), lost);
        }
        self.gather_lost_matches();
        Ok(())
    }

    /// Fills each [`LostImage`]'s matches from [`Evidence::matches`], in one pass.
    pub(crate) fn gather_lost_matches(&mut self) {
        for ((a, b), m) in &self.matches {
            if let Some(u) = self.lost_images.get_mut(a) {
                u.matches.push((b.clone(), m.clone()));
            }
            if let Some(u) = self.lost_images.get_mut(b) {
                u.matches
                    .push((a.clone(), m.iter().map(|&[x, y]| [y, x]).collect()));
            }
        }
    }

    /// The images that a pair a mapper would use (at least `min_num_matches` inliers) links and
    /// that no model of `models` registered, in name order. COLMAP 3.8 relaxes its initial
    /// pair (16 degrees, then 8) only while it has no model at all, so a piece of the view
    /// graph that a repair's blame cut off, whose neighbours see their surroundings under small
    /// angles (a street walked past), starts no model in the run that registers the rest; a
    /// second run on these images alone starts one (README; docs/check.md, "Pieces that start no
    /// model"). COLMAP 4's incremental mapper relaxes while images are left over.
    pub fn unregistered(&self, models: &[SparseModel], min_num_matches: usize) -> Vec<String> {
        let linked = self.pairs.iter().map(|(pair, &inliers)| (pair, inliers));
        not_registered(models, linked, min_num_matches)
    }
}

/// The images of the `pairs` (with their inliers) of at least `min_num_matches` inliers that no
/// model of `models` registered, in name order.
fn not_registered<'a>(
    models: &[SparseModel],
    pairs: impl Iterator<Item = (&'a NamePair, usize)>,
    min_num_matches: usize,
) -> Vec<String> {
    let registered = registered(models);
    let linked: BTreeSet<&String> = pairs
        .filter(|(_, inliers)| *inliers >= min_num_matches)
        .flat_map(|((a, b), _)| [a, b])
        .collect();
    (linked.into_iter())
        .filter(|name| !registered.contains(name.as_str()))
        .cloned()
        .collect()
}

/// The names of the images some model of `models` registered.
pub fn registered(models: &[SparseModel]) -> HashSet<&str> {
    (models.iter())
        .flat_map(|m| &m.images)
        .map(|im| im.image.name.as_str())
        .collect()
}
