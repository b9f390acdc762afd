//! The write stage: the COLMAP 3.8 database, rows as `colmap feature_extractor` and
//! `colmap exhaustive_matcher` write them.

use crate::colmap::blob::{encode_f32, encode_f64, encode_mat3, encode_pairs};
use crate::eval::synth::matching::PairRows;
use crate::eval::synth::observe::ImageObservations;
use crate::eval::synth::spec::SceneSpec;
use crate::eval::synth::truth::{GtCamera, GtImage};
use anyhow::{Context, Result};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rusqlite::{params, Connection, Statement, Transaction};
use std::path::Path;

/// A new database at `path` with the COLMAP 3.8 schema.
pub(super) fn create(path: &Path) -> Result<Connection> {
    let conn = Connection::open(path).with_context(|| format!("creating {}", path.display()))?;
    conn.execute_batch(include_str!("../../../sql/colmap-3.8.sql"))
        .context("creating the COLMAP 3.8 schema")?;
    Ok(conn)
}

/// The camera (with [`SceneSpec::stored_focal`] if set), the images, their keypoints (random
/// scale and orientation) and descriptors.
pub(super) fn write_images(
    tx: &Transaction,
    spec: &SceneSpec,
    camera: &GtCamera,
    images: &[GtImage],
    observations: &[ImageObservations],
    rng: &mut ChaCha8Rng,
) -> Result<()> {
    let mut stored_params = camera.params.clone();
    stored_params[0] = spec.stored_focal.unwrap_or(spec.focal);
    tx.execute(
        "INSERT INTO cameras(camera_id, model, width, height, params, prior_focal_length) \
         VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
        params![
            camera.camera_id,
            camera.model_id,
            camera.width,
            camera.height,
            encode_f64(&stored_params),
            spec.stored_focal.is_none()
        ],
    )?;
    let mut ins_image =
        tx.prepare("INSERT INTO images(image_id, name, camera_id) VALUES (?1, ?2, ?3)")?;
    let mut ins_kp =
        tx.prepare("INSERT INTO keypoints(image_id, rows, cols, data) VALUES (?1, ?2, 6, ?3)")?;
    let mut ins_desc =
        tx.prepare("INSERT INTO descriptors(image_id, rows, cols, data) VALUES (?1, ?2, 128, ?3)")?;
    for (im, obs) in images.iter().zip(observations) {
        ins_image.execute(params![im.image_id, im.name, camera.camera_id])?;
        let mut values = Vec::with_capacity(obs.keypoints.len() * 6);
        for kp in &obs.keypoints {
            let scale: f32 = rng.gen_range(1.5..6.0);
            let angle: f32 = rng.gen_range(0.0..std::f32::consts::TAU);
            let (s, c) = angle.sin_cos();
            values.extend([kp[0], kp[1], scale * c, -scale * s, scale * s, scale * c]);
        }
        ins_kp.execute(params![
            im.image_id,
            obs.keypoints.len(),
            encode_f32(&values)
        ])?;
        if spec.random_descriptors {
            let mut d = vec![0u8; obs.keypoints.len() * 128];
            rng.fill(&mut d[..]);
            ins_desc.execute(params![im.image_id, obs.keypoints.len(), d])?;
        } else {
            ins_desc.execute(params![im.image_id, 0, None::<Vec<u8>>])?;
        }
    }
    Ok(())
}

/// Writes pairs' `matches` and `two_view_geometries` rows; a failed pair gets the row 3.8
/// writes (rows 0, cols 2, data NULL, config 0, F..tvec NULL).
pub(super) struct PairWriter<'t> {
    matches: Statement<'t>,
    geometries: Statement<'t>,
}

impl<'t> PairWriter<'t> {
    pub fn new(tx: &'t Transaction) -> Result<PairWriter<'t>> {
        Ok(PairWriter {
            matches: tx
                .prepare("INSERT INTO matches(pair_id, rows, cols, data) VALUES (?1, ?2, 2, ?3)")?,
            geometries: tx.prepare(
                "INSERT INTO two_view_geometries(pair_id, rows, cols, data, config, F, E, H, qvec, tvec) \
                 VALUES (?1, ?2, 2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
            )?,
        })
    }

    pub fn write(&mut self, pair: &PairRows) -> Result<()> {
        let data = (!pair.matches.is_empty()).then(|| encode_pairs(&pair.matches));
        self.matches
            .execute(params![pair.pair_id, pair.matches.len(), data])?;
        match &pair.verified {
            None => {
                let null = None::<Vec<u8>>;
                self.geometries.execute(params![
                    pair.pair_id,
                    0,
                    null,
                    0,
                    null,
                    null,
                    null,
                    null,
                    null
                ])?;
            }
            Some(v) => {
                self.geometries.execute(params![
                    pair.pair_id,
                    v.inliers.len(),
                    encode_pairs(&v.inliers),
                    v.config.code(),
                    encode_mat3(&v.f),
                    v.e.as_ref().map(encode_mat3),
                    encode_mat3(&v.h),
                    encode_f64(&v.qvec),
                    encode_f64(&v.tvec)
                ])?;
            }
        }
        Ok(())
    }
}
