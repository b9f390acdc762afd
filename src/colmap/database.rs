//! Reading a COLMAP database (3.8 layout through today's): cameras, images, keypoints, matches and
//! two-view geometries, with every blob's size checked.
//!
//! Columns are always selected by name and optional ones detected with `PRAGMA table_info`,
//! because COLMAP adds and drops columns between versions. Errors are one line and name the file,
//! table and ids involved, since they usually mean a corrupt or foreign database.
//! Which layout a database has is [`super::schema`]'s to say.

use anyhow::{anyhow, bail, Result};
use rusqlite::{Connection, ErrorCode, OpenFlags};
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::time::Duration;

use super::blob::{blob, decode_f64_array, decode_keypoints_xy, decode_mat3, decode_matches};
use super::blob::{usable_mat3, usable_vec};
use super::ids::{camera_model_name, camera_model_num_params, image_ids, pair_id, MAX_NUM_IMAGES};
use super::schema::{detect_layout, table_exists, Layout};

/// How long a statement waits for another process's lock before failing (COLMAP GUI, a running
/// matcher); long enough for a short write, short enough not to look hung.
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(5);

/// A row of COLMAP's cameras table: the intrinsics that [`crate::geometry`] needs to undistort
/// keypoints and to judge focal lengths.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// COLMAP's camera_id, which images refer to.
    pub camera_id: u32,
    /// COLMAP's camera model number (0 SIMPLE_PINHOLE … 10); it fixes the layout of `params`.
    pub model_id: i32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The model's parameters in COLMAP's order (focal length(s), principal point, distortion);
    /// the length matches the model, checked on reading.
    pub params: Vec<f64>,
    /// COLMAP's prior_focal_length: false when the focal length was only guessed.
    pub prior_focal_length: bool,
}

/// A row of COLMAP's images table: what ties an image id to its file and its camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// COLMAP's image_id, the key of keypoints and half of every pair_id.
    pub image_id: u32,
    /// File name relative to the image folder, as COLMAP stored it.
    pub name: String,
    /// The [`Camera`] whose intrinsics the image uses.
    pub camera_id: u32,
}

/// A geometrically verified pair as COLMAP stored it before any prune (read from the project's
/// backup table where vgsel-colmap has invalidated it).
#[derive(Clone, Debug, PartialEq)]
pub struct VerifiedPair {
    /// The smaller image id of the pair (COLMAP's pair order).
    pub image_id1: u32,
    /// The larger image id of the pair.
    pub image_id2: u32,
    /// COLMAP's two-view configuration (2 CALIBRATED, 3 UNCALIBRATED, 4 PLANAR, …).
    pub config: i32,
    /// Inlier correspondences: keypoint index in image_id1, keypoint index in image_id2.
    pub inliers: Vec<[u32; 2]>,
}

/// The geometry of a verified pair (as originally verified), without its inliers. Matrices are
/// in pair order (image_id1 -> image_id2); `None` where COLMAP stored nothing (NULL or empty)
/// or nothing usable ([`super::blob::usable_mat3`], [`super::blob::usable_vec`]).
/// 3.8 stores all-zero qvec/tvec when it did not estimate a pose: do not trust zeros.
#[derive(Clone, Debug, PartialEq)]
pub struct TwoViewGeometry {
    /// The smaller image id of the pair (COLMAP's pair order).
    pub image_id1: u32,
    /// The larger image id of the pair.
    pub image_id2: u32,
    /// COLMAP's two-view configuration (2 CALIBRATED, 3 UNCALIBRATED, 4 PLANAR, …).
    pub config: i32,
    /// Number of inlier correspondences (the row's `rows`), always > 0 here.
    pub num_inliers: usize,
    /// Fundamental matrix, row-major, with x2^T F x1 = 0.
    pub f: Option<[f64; 9]>,
    /// Essential matrix, row-major, with x2^T E x1 = 0 in normalised coordinates.
    pub e: Option<[f64; 9]>,
    /// Homography, row-major, mapping image_id1's pixels to image_id2's.
    pub h: Option<[f64; 9]>,
    /// Rotation of the relative pose cam2_from_cam1 as a unit quaternion (w, x, y, z).
    pub qvec: Option<[f64; 4]>,
    /// Translation of cam2_from_cam1, of arbitrary scale (two views cannot fix it).
    pub tvec: Option<[f64; 3]>,
}

/// Another process held a lock on the database for longer than the lock timeout. A type of its
/// own so that a front end can say how to wait longer.
#[derive(Debug)]
pub struct Locked {
    /// The database.
    pub path: PathBuf,
}

impl std::fmt::Display for Locked {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "{}: database is locked by another process (close it and retry, or wait longer)",
            self.path.display()
        )
    }
}

impl std::error::Error for Locked {}

/// Turns an SQLite error into a one-line message naming the file; lock and "not a database"
/// errors get wording a user can act on.
pub(crate) fn sql_error(path: &Path, err: rusqlite::Error) -> anyhow::Error {
    let shown = path.display();
    match err.sqlite_error_code() {
        Some(ErrorCode::DatabaseBusy) | Some(ErrorCode::DatabaseLocked) => Locked {
            path: path.to_path_buf(),
        }
        .into(),
        Some(ErrorCode::NotADatabase) => anyhow!("{shown}: file is not a database"),
        Some(ErrorCode::DatabaseCorrupt) => {
            anyhow!("{shown}: database file is corrupt or truncated ({err})")
        }
        Some(ErrorCode::DiskFull) => anyhow!("{shown}: disk full while writing ({err})"),
        Some(ErrorCode::SystemIoFailure) => {
            anyhow!("{shown}: disk I/O error (disk full, over a file size limit, or failing?)")
        }
        Some(ErrorCode::ReadOnly) => anyhow!("{shown}: database is read-only ({err})"),
        _ => anyhow!("{shown}: SQLite error: {err}"),
    }
}

/// [`Database::data_version`] on any connection to the file at `path` (a write transaction's too).
pub(crate) fn data_version(conn: &Connection, path: &Path) -> Result<i64> {
    conn.pragma_query_value(None, "data_version", |r| r.get(0))
        .sql(path)
}

/// `rusqlite::Result` -> `anyhow::Result` with [`sql_error`]'s wording.
pub(crate) trait SqlResult<T> {
    fn sql(self, path: &Path) -> Result<T>;
}

impl<T> SqlResult<T> for rusqlite::Result<T> {
    fn sql(self, path: &Path) -> Result<T> {
        self.map_err(|e| sql_error(path, e))
    }
}

/// An image id as COLMAP can pair it: below [`MAX_NUM_IMAGES`], or pair_ids would be ambiguous.
fn image_id_of(value: i64, what: &dyn Fn() -> String) -> Result<u32> {
    u32::try_from(value)
        .ok()
        .filter(|&id| (id as u64) < MAX_NUM_IMAGES)
        .ok_or_else(|| {
            anyhow!(
                "{}: image id {value} out of range (COLMAP allows 0 to {})",
                what(),
                MAX_NUM_IMAGES - 1
            )
        })
}

/// An open COLMAP database and its detected [`Layout`]: the only way the crate reads one, so
/// every read checks sizes and ids and reports errors naming the file.
pub struct Database {
    conn: Connection,
    path: PathBuf,
    layout: Layout,
    read_only: bool,
}

impl Database {
    /// Opens an existing COLMAP database for reading and writing; fails with a one-line reason
    /// when the file is missing, not SQLite, or lacks COLMAP's tables.
    pub fn open(path: &Path) -> Result<Database> {
        Self::open_with_lock_timeout(path, false, BUSY_TIMEOUT)
    }
    /// Like [`Database::open`] but read-only, for commands that must not change the file.
    pub fn open_read_only(path: &Path) -> Result<Database> {
        Self::open_with_lock_timeout(path, true, BUSY_TIMEOUT)
    }

    /// [`Database::open`] or [`Database::open_read_only`], waiting up to `lock_timeout` for
    /// another process's lock in every statement, opening included.
    pub fn open_with_lock_timeout(
        path: &Path,
        read_only: bool,
        lock_timeout: Duration,
    ) -> Result<Database> {
        let shown = path.display();
        match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                bail!("cannot open COLMAP database {shown}: no such file")
            }
            Err(e) => bail!("cannot open COLMAP database {shown}: {e}"),
            Ok(m) if m.is_dir() => bail!("cannot open COLMAP database {shown}: it is a directory"),
            Ok(_) => {}
        }
        let fail = |e: rusqlite::Error| {
            let msg = sql_error(path, e).to_string();
            let reason = msg
                .strip_prefix(&format!("{shown}: "))
                .unwrap_or(&msg)
                .to_string();
            anyhow!("cannot open COLMAP database {shown}: {reason}")
        };
        // No SQLITE_OPEN_CREATE: a mistyped path must fail, not leave an empty database behind.
        let conn = if read_only {
            crate::colmap::wal::open_for_reading(path, OpenFlags::SQLITE_OPEN_NO_MUTEX)
        } else {
            Connection::open_with_flags(
                path,
                OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX,
            )
        }
        .map_err(fail)?;
        conn.busy_timeout(lock_timeout).map_err(fail)?;
        let layout = detect_layout(&conn).map_err(|e| match e.downcast::<rusqlite::Error>() {
            Ok(sqlite) => fail(sqlite),
            Err(other) => anyhow!("cannot open COLMAP database {shown}: {other}"),
        })?;
        Ok(Database {
            conn,
            path: path.to_path_buf(),
            layout,
            read_only,
        })
    }

    /// The file's path as given, for messages.
    pub fn path(&self) -> &Path {
        &self.path
    }
    /// The optional columns and tables this database has, detected when it was opened.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }
    /// Whether it was opened read-only, so writers can refuse early with a clear message.
    pub fn is_read_only(&self) -> bool {
        self.read_only
    }
    /// Changes how long statements wait for another process's lock (default [`BUSY_TIMEOUT`]).
    pub fn set_busy_timeout(&self, timeout: Duration) -> Result<()> {
        self.conn.busy_timeout(timeout).sql(&self.path)
    }

    /// SQLite's `PRAGMA data_version`: changes exactly when another connection (this process
    /// or another) commits a change to the file, in rollback-journal and WAL mode alike.
    pub fn data_version(&self) -> Result<i64> {
        data_version(&self.conn, &self.path)
    }

    pub(crate) fn conn(&self) -> &Connection {
        &self.conn
    }
    pub(crate) fn conn_mut(&mut self) -> &mut Connection {
        &mut self.conn
    }

    /// Every camera, by camera_id; fails on an unknown model or a params blob of the wrong size.
    pub fn cameras(&self) -> Result<Vec<Camera>> {
        let p = &self.path;
        let mut stmt = self
            .conn
            .prepare(
                "SELECT camera_id, model, width, height, params, prior_focal_length \
                 FROM cameras ORDER BY camera_id",
            )
            .sql(p)?;
        let mut rows = stmt.query([]).sql(p)?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().sql(p)? {
            let id: i64 = row.get(0).sql(p)?;
            let camera_id =
                u32::try_from(id).map_err(|_| anyhow!("camera_id {id} out of range"))?;
            let model_id: i32 = row.get(1).sql(p)?;
            let what = || format!("params of camera {camera_id}");
            let Some(n) = camera_model_num_params(model_id) else {
                bail!("camera {camera_id}: unknown camera model {model_id} (known: 0 to 10)");
            };
            let bytes = blob(row.get_ref(4).sql(p)?, &what)?.unwrap_or(&[]);
            if bytes.len() != n * 8 {
                bail!(
                    "camera {camera_id}: params blob has {} bytes, expected {} ({n} float64 for {})",
                    bytes.len(),
                    n * 8,
                    camera_model_name(model_id).unwrap_or("?")
                );
            }
            let params = bytes
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("chunk of 8")))
                .collect();
            let dim = |v: i64| {
                u32::try_from(v).map_err(|_| anyhow!("camera {camera_id}: size {v} out of range"))
            };
            out.push(Camera {
                camera_id,
                model_id,
                width: dim(row.get(2).sql(p)?)?,
                height: dim(row.get(3).sql(p)?)?,
                params,
                prior_focal_length: row.get::<_, i64>(5).sql(p)? != 0,
            });
        }
        Ok(out)
    }

    /// Every image, by image_id.
    pub fn images(&self) -> Result<Vec<Image>> {
        let p = &self.path;
        let mut stmt = self
            .conn
            .prepare("SELECT image_id, name, camera_id FROM images ORDER BY image_id")
            .sql(p)?;
        let mut rows = stmt.query([]).sql(p)?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().sql(p)? {
            let what = || "images".to_string();
            let image_id = image_id_of(row.get(0).sql(p)?, &what)?;
            let cam: i64 = row.get(2).sql(p)?;
            out.push(Image {
                image_id,
                name: row.get(1).sql(p)?,
                camera_id: u32::try_from(cam)
                    .map_err(|_| anyhow!("image {image_id}: camera_id {cam} out of range"))?,
            });
        }
        Ok(out)
    }

    /// Keypoint count of every image with a keypoints row, without reading the blobs.
    pub fn keypoint_counts(&self) -> Result<BTreeMap<u32, usize>> {
        let p = &self.path;
        let mut stmt = self
            .conn
            .prepare("SELECT image_id, rows FROM keypoints")
            .sql(p)?;
        let mut rows = stmt.query([]).sql(p)?;
        let mut out = BTreeMap::new();
        while let Some(row) = rows.next().sql(p)? {
            let what = || "keypoints".to_string();
            let id = image_id_of(row.get(0).sql(p)?, &what)?;
            let n: i64 = row.get(1).sql(p)?;
            let n = usize::try_from(n)
                .map_err(|_| anyhow!("keypoints of image {id}: negative row count {n}"))?;
            out.insert(id, n);
        }
        Ok(out)
    }

    /// Keypoint (x, y) positions of one image; empty when the image has no keypoints row.
    pub fn keypoints_xy(&self, image_id: u32) -> Result<Vec<[f32; 2]>> {
        let p = &self.path;
        let mut stmt = self
            .conn
            .prepare_cached("SELECT rows, cols, data FROM keypoints WHERE image_id = ?1")
            .sql(p)?;
        let mut rows = stmt.query([image_id]).sql(p)?;
        let Some(row) = rows.next().sql(p)? else {
            return Ok(Vec::new());
        };
        let what = || format!("keypoints of image {image_id}");
        let data = blob(row.get_ref(2).sql(p)?, &what)?;
        let xy = decode_keypoints_xy(image_id, row.get(0).sql(p)?, row.get(1).sql(p)?, data)?;
        // Negative or outside the image is accepted (other extractors write such positions);
        // NaN or infinite is no position at all.
        if let Some(k) = xy
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            bail!(
                "{}: keypoint {k} is at ({}, {}), not a finite position",
                what(),
                xy[k][0],
                xy[k][1]
            );
        }
        Ok(xy)
    }

    /// pair_id of every two_view_geometries row with at least `min_rows` inliers now (a pruned
    /// row has rows = 0): the pairs `colmap mapper --Mapper.min_num_matches` would use.
    pub fn used_pair_ids(&self, min_rows: usize) -> Result<HashSet<u64>> {
        self.pair_ids(
            "SELECT pair_id FROM two_view_geometries WHERE rows >= ?1",
            [min_rows as i64],
        )
    }

    /// pair_ids of the pairs a prune invalidated (their original rows are in the backup table,
    /// and they are not among the trimmed ones, which stay valid); empty when the database was
    /// never pruned.
    pub fn invalidated_pair_ids(&self) -> Result<HashSet<u64>> {
        if !self.has_backup_table()? {
            return Ok(HashSet::new());
        }
        let trimmed = if table_exists(&self.conn, "vgsel_trimmed").sql(&self.path)? {
            " WHERE pair_id NOT IN (SELECT pair_id FROM vgsel_trimmed)"
        } else {
            ""
        };
        self.pair_ids(&format!("SELECT pair_id FROM vgsel_backup{trimmed}"), [])
    }

    /// The pair_id column of a query's rows.
    fn pair_ids(&self, sql: &str, params: impl rusqlite::Params) -> Result<HashSet<u64>> {
        let p = &self.path;
        let mut stmt = self.conn.prepare(sql).sql(p)?;
        let ids = stmt
            .query_map(params, |r| r.get::<_, i64>(0))
            .sql(p)?
            .map(|r| r.map(|id| id as u64))
            .collect::<Result<_, _>>()
            .sql(p)?;
        Ok(ids)
    }

    /// Whether the project's backup table exists (even if empty).
    pub fn has_backup_table(&self) -> Result<bool> {
        table_exists(&self.conn, "vgsel_backup").sql(&self.path)
    }

    /// SELECT of the two_view_geometries rows as originally verified (rows > 0), ordered by
    /// pair_id: pair_id, then `columns` (members of [`TWO_VIEW_COLUMNS`]). Pruned rows come from
    /// the backup; columns the layout lacks read as NULL.
    fn original_rows_sql(&self, columns: &[&str]) -> Result<String> {
        let backup = self.has_backup_table()?;
        let expr = |c: &str| -> String {
            let current = if self.layout.has_two_view_column(c) {
                format!("t.{c}")
            } else {
                "NULL".to_string()
            };
            if backup {
                format!("CASE WHEN b.pair_id IS NULL THEN {current} ELSE b.{c} END")
            } else {
                current
            }
        };
        let list: Vec<String> = columns.iter().map(|c| expr(c)).collect();
        let join = if backup {
            " LEFT JOIN vgsel_backup AS b ON b.pair_id = t.pair_id"
        } else {
            ""
        };
        Ok(format!(
            "SELECT t.pair_id, {} FROM two_view_geometries AS t{join} WHERE {} > 0 ORDER BY t.pair_id",
            list.join(", "),
            expr("rows")
        ))
    }

    fn image_id_set(&self) -> Result<HashSet<u32>> {
        Ok(self.images()?.into_iter().map(|i| i.image_id).collect())
    }

    /// Decodes a pair_id column and checks both images exist.
    fn pair_images(&self, raw: i64, images: &HashSet<u32>) -> Result<(u32, u32)> {
        let id = u64::try_from(raw)
            .map_err(|_| anyhow!("two_view_geometries: negative pair_id {raw}"))?;
        let (a, b) = image_ids(id);
        // Beyond 2147483647 x 2147483647 the first id does not fit: the ids would name other
        // images, and the write would touch another row.
        if pair_id(a, b) != id {
            bail!("two_view_geometries: pair_id {id} is not the pair_id of two image ids");
        }
        if a == b {
            bail!("two_view_geometries pair_id {id} pairs image {a} with itself");
        }
        for image in [a, b] {
            if !images.contains(&image) {
                bail!(
                    "two_view_geometries pair_id {id} (images {a}, {b}) names image {image}, which is not in the images table"
                );
            }
        }
        Ok((a, b))
    }

    /// Every two_view_geometries row with rows > 0, as originally verified (pruned rows come
    /// from the backup). Inlier indices are checked against the keypoint counts.
    pub fn verified_pairs(&self) -> Result<Vec<VerifiedPair>> {
        let p = &self.path;
        let counts = self.keypoint_counts()?;
        let images = self.image_id_set()?;
        let sql = self.original_rows_sql(&["rows", "cols", "data", "config", "F", "E", "H"])?;
        let mut stmt = self.conn.prepare(&sql).sql(p)?;
        let mut rows = stmt.query([]).sql(p)?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().sql(p)? {
            let (a, b) = self.pair_images(row.get(0).sql(p)?, &images)?;
            let what = format!("two_view_geometries pair ({a}, {b})");
            let data = blob(row.get_ref(3).sql(p)?, &|| what.clone())?;
            let inliers = decode_matches(&what, row.get(1).sql(p)?, row.get(2).sql(p)?, data)?;
            for (k, image) in [(0, a), (1, b)] {
                let n = counts.get(&image).copied().unwrap_or(0);
                if let Some(m) = inliers.iter().find(|m| m[k] as usize >= n) {
                    bail!(
                        "{what}: inlier keypoint index {} >= {n}, the keypoint count of image {image}",
                        m[k]
                    );
                }
            }
            for (i, name) in [(5, "F"), (6, "E"), (7, "H")] {
                let bytes = blob(row.get_ref(i).sql(p)?, &|| format!("{what} {name}"))?;
                decode_mat3(&format!("{what} {name}"), bytes)?;
            }
            out.push(VerifiedPair {
                image_id1: a,
                image_id2: b,
                config: row.get(4).sql(p)?,
                inliers,
            });
        }
        Ok(out)
    }

    /// The geometry of every verified pair (rows > 0, as originally verified), by pair_id.
    pub fn geometries(&self) -> Result<Vec<TwoViewGeometry>> {
        let p = &self.path;
        let images = self.image_id_set()?;
        let sql = self.original_rows_sql(&["rows", "config", "F", "E", "H", "qvec", "tvec"])?;
        let mut stmt = self.conn.prepare(&sql).sql(p)?;
        let mut rows = stmt.query([]).sql(p)?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().sql(p)? {
            let (a, b) = self.pair_images(row.get(0).sql(p)?, &images)?;
            let what = |name: &str| format!("two_view_geometries pair ({a}, {b}) {name}");
            let get = |i: usize, name: &str| -> Result<Option<&[u8]>> {
                blob(row.get_ref(i).sql(p)?, &|| what(name))
            };
            let n: i64 = row.get(1).sql(p)?;
            out.push(TwoViewGeometry {
                image_id1: a,
                image_id2: b,
                config: row.get(2).sql(p)?,
                num_inliers: n as usize,
                f: usable_mat3(decode_mat3(&what("F"), get(3, "F")?)?),
                e: usable_mat3(decode_mat3(&what("E"), get(4, "E")?)?),
                h: usable_mat3(decode_mat3(&what("H"), get(5, "H")?)?),
                qvec: usable_vec(decode_f64_array::<4>(&what("qvec"), get(6, "qvec")?)?),
                tvec: usable_vec(decode_f64_array::<3>(&what("tvec"), get(7, "tvec")?)?),
            });
        }
        Ok(out)
    }

    /// Raw (unverified) matches of a pair, oriented as (image_a, image_b) given; empty when the
    /// pair has no matches row.
    pub fn matches(&self, image_a: u32, image_b: u32) -> Result<Vec<[u32; 2]>> {
        if image_a == image_b {
            bail!("matches: a pair needs two different images (got {image_a} twice)");
        }
        let p = &self.path;
        let mut stmt = self
            .conn
            .prepare_cached("SELECT rows, cols, data FROM matches WHERE pair_id = ?1")
            .sql(p)?;
        let id = pair_id(image_a, image_b) as i64;
        let mut rows = stmt.query([id]).sql(p)?;
        let Some(row) = rows.next().sql(p)? else {
            return Ok(Vec::new());
        };
        let what = format!(
            "matches of pair ({}, {})",
            image_a.min(image_b),
            image_a.max(image_b)
        );
        let data = blob(row.get_ref(2).sql(p)?, &|| what.clone())?;
        let mut m = decode_matches(&what, row.get(0).sql(p)?, row.get(1).sql(p)?, data)?;
        if image_a > image_b {
            m.iter_mut().for_each(|x| x.swap(0, 1));
        }
        Ok(m)
    }

    /// Whether vgsel-colmap has pruned this database (its backup table holds rows).
    pub fn is_pruned(&self) -> Result<bool> {
        if !self.has_backup_table()? {
            return Ok(false);
        }
        self.conn
            .query_row("SELECT EXISTS (SELECT 1 FROM vgsel_backup)", [], |r| {
                r.get::<_, bool>(0)
            })
            .sql(&self.path)
    }
}
