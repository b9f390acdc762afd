//! Reading a COLMAP database (3.8 layout through today's): cameras, images, keypoints, matches and
//! two-view geometries, with every blob's size checked.
//!
//! Columns are always selected by name and optional ones detected with `PRAGMA table_info`,
//! because COLMAP adds and drops columns between versions. Errors are one line and name the file,
//! table and ids involved, since they usually mean a corrupt or foreign database.
//!
//! Schema versions: `PRAGMA user_version` is read; values below 5,000,000 are accepted (0 = written
//! by a script, 3800/3900 = COLMAP 3.x, major*1e6 + minor*1e4 + patch*100 = COLMAP 4.x and main).
//! A value of 5,000,000 or more is a COLMAP major version we have never seen and is refused, so we
//! never rewrite a layout whose meaning we do not know.

use anyhow::{anyhow, bail, Result};
use rusqlite::types::ValueRef;
use rusqlite::{Connection, ErrorCode, OpenFlags, OptionalExtension};
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::time::Duration;

use super::ids::{camera_model_name, camera_model_num_params, image_ids, pair_id};

/// How long a statement waits for another process's lock before failing (COLMAP GUI, a running
/// matcher); long enough for a short write, short enough not to look hung.
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(5);

/// The newest COLMAP major version whose database layout is known; see the module docs.
pub const NEWEST_KNOWN_MAJOR: i64 = 4;

/// Tables every COLMAP version since 3.x has; without them the file is not a COLMAP database.
pub const REQUIRED_TABLES: [&str; 6] = [
    "cameras",
    "images",
    "keypoints",
    "descriptors",
    "matches",
    "two_view_geometries",
];

/// two_view_geometries columns after pair_id, in the order the project's backup table stores
/// them. The first four are required; the others exist depending on the COLMAP version.
pub const TWO_VIEW_COLUMNS: [&str; 11] = [
    "rows", "cols", "data", "config", "F", "E", "H", "qvec", "tvec", "camera1", "camera2",
];

/// Which optional parts of COLMAP's layout a database has.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// `PRAGMA user_version` (3800 for COLMAP 3.8, 0 when a script created the file).
    pub user_version: i64,
    /// The members of [`TWO_VIEW_COLUMNS`] that two_view_geometries has, in that order.
    pub two_view_columns: Vec<&'static str>,
    /// descriptors.type (COLMAP 4.0 and later).
    pub descriptors_type: bool,
    /// images.prior_* columns (COLMAP 3.8/3.9 and databases migrated from them).
    pub image_priors: bool,
    /// rigs/frames tables (COLMAP 3.12 and later).
    pub rigs: bool,
}

impl Layout {
    pub fn has_two_view_column(&self, column: &str) -> bool {
        self.two_view_columns.contains(&column)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub camera_id: u32,
    pub model_id: i32,
    pub width: u32,
    pub height: u32,
    pub params: Vec<f64>,
    /// COLMAP's prior_focal_length: false when the focal length was only guessed.
    pub prior_focal_length: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub image_id: u32,
    pub name: String,
    pub camera_id: u32,
}

/// A geometrically verified pair as COLMAP stored it before any prune (read from the project's
/// backup table where vgsel-colmap has invalidated it).
#[derive(Clone, Debug, PartialEq)]
pub struct VerifiedPair {
    pub image_id1: u32,
    pub image_id2: u32,
    pub config: i32,
    /// Inlier correspondences: keypoint index in image_id1, keypoint index in image_id2.
    pub inliers: Vec<[u32; 2]>,
}

/// The geometry of a verified pair (as originally verified), without its inliers. Matrices are
/// in pair order (image_id1 -> image_id2); `None` where COLMAP stored nothing (NULL or empty).
/// 3.8 stores all-zero qvec/tvec when it did not estimate a pose: do not trust zeros.
#[derive(Clone, Debug, PartialEq)]
pub struct TwoViewGeometry {
    pub image_id1: u32,
    pub image_id2: u32,
    pub config: i32,
    pub num_inliers: usize,
    pub f: Option<[f64; 9]>,
    pub e: Option<[f64; 9]>,
    pub h: Option<[f64; 9]>,
    pub qvec: Option<[f64; 4]>,
    pub tvec: Option<[f64; 3]>,
}

/// Turns an SQLite error into a one-line message naming the file; lock and "not a database"
/// errors get wording a user can act on.
pub(crate) fn sql_error(path: &Path, err: rusqlite::Error) -> anyhow::Error {
    let shown = path.display();
    match err.sqlite_error_code() {
        Some(ErrorCode::DatabaseBusy) | Some(ErrorCode::DatabaseLocked) => {
            anyhow!("{shown}: database is locked by another process (close it and retry, or wait longer with --lock_timeout)")
        }
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

/// `rusqlite::Result` -> `anyhow::Result` with [`sql_error`]'s wording.
pub(crate) trait SqlResult<T> {
    fn sql(self, path: &Path) -> Result<T>;
}

impl<T> SqlResult<T> for rusqlite::Result<T> {
    fn sql(self, path: &Path) -> Result<T> {
        self.map_err(|e| sql_error(path, e))
    }
}

/// A blob column's bytes; NULL is None. Other storage classes are an error, not a silent cast.
fn blob<'a>(value: ValueRef<'a>, what: &dyn Fn() -> String) -> Result<Option<&'a [u8]>> {
    match value {
        ValueRef::Blob(b) => Ok(Some(b)),
        ValueRef::Null => Ok(None),
        other => bail!("{}: expected a BLOB, found {:?}", what(), other.data_type()),
    }
}

/// Checks rows/cols/bytes of a row-major matrix blob and returns rows.
fn check_matrix(
    what: &dyn Fn() -> String,
    rows: i64,
    cols: i64,
    data: Option<&[u8]>,
    scalar_bytes: u64,
) -> Result<usize> {
    if rows < 0 || cols < 0 {
        bail!("{}: negative size {rows} x {cols}", what());
    }
    let expected = (rows as u64)
        .checked_mul(cols as u64)
        .and_then(|n| n.checked_mul(scalar_bytes))
        .ok_or_else(|| anyhow!("{}: size {rows} x {cols} overflows", what()))?;
    let actual = data.map_or(0, |d| d.len() as u64);
    if actual != expected {
        bail!(
            "{}: data has {actual} bytes, expected {expected} ({rows} rows x {cols} cols x {scalar_bytes} bytes)",
            what()
        );
    }
    Ok(rows as usize)
}

/// Keypoint (x, y) of a keypoints row: float32 rows x cols, cols in {2, 4, 6}.
pub fn decode_keypoints_xy(
    image_id: u32,
    rows: i64,
    cols: i64,
    data: Option<&[u8]>,
) -> Result<Vec<[f32; 2]>> {
    if ![2, 4, 6].contains(&cols) {
        bail!("keypoints of image {image_id}: {cols} columns, expected 2, 4 or 6");
    }
    let what = || format!("keypoints of image {image_id}");
    let n = check_matrix(&what, rows, cols, data, 4)?;
    let data = data.unwrap_or(&[]);
    let stride = cols as usize * 4;
    let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    Ok((0..n)
        .map(|i| {
            let r = &data[i * stride..];
            [f(&r[0..4]), f(&r[4..8])]
        })
        .collect())
}

/// A matches or two_view_geometries data blob: uint32 rows x 2. `what` names the row in errors.
pub fn decode_matches(
    what: &str,
    rows: i64,
    cols: i64,
    data: Option<&[u8]>,
) -> Result<Vec<[u32; 2]>> {
    if cols != 2 && !(rows == 0 && data.is_none_or(|d| d.is_empty())) {
        bail!("{what}: {cols} columns, expected 2");
    }
    let what_fn = || what.to_string();
    let n = check_matrix(&what_fn, rows, if rows == 0 { 0 } else { 2 }, data, 4)?;
    let data = data.unwrap_or(&[]);
    let u = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    Ok((0..n)
        .map(|i| [u(&data[i * 8..i * 8 + 4]), u(&data[i * 8 + 4..i * 8 + 8])])
        .collect())
}

/// A fixed-size float64 blob (F/E/H: N = 9, qvec: 4, tvec: 3). NULL and zero-length blobs mean
/// "not set" (COLMAP reads both that way) and give None; any other size is an error. The values
/// are returned as stored: check `is_finite` before use.
pub fn decode_f64_array<const N: usize>(
    what: &str,
    data: Option<&[u8]>,
) -> Result<Option<[f64; N]>> {
    let data = match data {
        None => return Ok(None),
        Some([]) => return Ok(None),
        Some(d) => d,
    };
    if data.len() != N * 8 {
        bail!(
            "{what}: blob has {} bytes, expected {} ({N} float64)",
            data.len(),
            N * 8
        );
    }
    let mut out = [0.0; N];
    for (o, c) in out.iter_mut().zip(data.chunks_exact(8)) {
        *o = f64::from_le_bytes(c.try_into().expect("chunk of 8"));
    }
    Ok(Some(out))
}

/// A 3x3 row-major float64 matrix blob (F, E or H): 72 bytes, or None when not set.
pub fn decode_mat3(what: &str, data: Option<&[u8]>) -> Result<Option<[f64; 9]>> {
    decode_f64_array::<9>(what, data)
}

fn image_id_of(value: i64, what: &dyn Fn() -> String) -> Result<u32> {
    u32::try_from(value).map_err(|_| anyhow!("{}: image id {value} out of range", what()))
}

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
        // No SQLITE_OPEN_CREATE: a mistyped path must fail, not leave an empty database behind.
        let mode = if read_only {
            OpenFlags::SQLITE_OPEN_READ_ONLY
        } else {
            OpenFlags::SQLITE_OPEN_READ_WRITE
        };
        let fail = |e: rusqlite::Error| {
            let msg = sql_error(path, e).to_string();
            let reason = msg
                .strip_prefix(&format!("{shown}: "))
                .unwrap_or(&msg)
                .to_string();
            anyhow!("cannot open COLMAP database {shown}: {reason}")
        };
        let conn = Connection::open_with_flags(path, mode | OpenFlags::SQLITE_OPEN_NO_MUTEX)
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

    pub fn path(&self) -> &Path {
        &self.path
    }
    pub fn layout(&self) -> &Layout {
        &self.layout
    }
    pub fn is_read_only(&self) -> bool {
        self.read_only
    }
    /// Changes how long statements wait for another process's lock (default [`BUSY_TIMEOUT`]).
    pub fn set_busy_timeout(&self, timeout: Duration) -> Result<()> {
        self.conn.busy_timeout(timeout).sql(&self.path)
    }
    pub(crate) fn conn(&self) -> &Connection {
        &self.conn
    }
    pub(crate) fn conn_mut(&mut self) -> &mut Connection {
        &mut self.conn
    }

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
        decode_keypoints_xy(image_id, row.get(0).sql(p)?, row.get(1).sql(p)?, data)
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
                f: decode_mat3(&what("F"), get(3, "F")?)?,
                e: decode_mat3(&what("E"), get(4, "E")?)?,
                h: decode_mat3(&what("H"), get(5, "H")?)?,
                qvec: decode_f64_array::<4>(&what("qvec"), get(6, "qvec")?)?,
                tvec: decode_f64_array::<3>(&what("tvec"), get(7, "tvec")?)?,
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

pub(crate) fn table_exists(conn: &Connection, name: &str) -> rusqlite::Result<bool> {
    conn.query_row(
        "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?1",
        [name],
        |_| Ok(()),
    )
    .optional()
    .map(|o| o.is_some())
}

fn column_names(conn: &Connection, table: &str) -> rusqlite::Result<Vec<String>> {
    let mut stmt = conn.prepare(&format!("PRAGMA table_info({table})"))?;
    let names = stmt.query_map([], |r| r.get::<_, String>(1))?;
    names.collect()
}

/// Reads user_version and the tables' columns; refuses what is not (or not yet) COLMAP.
fn detect_layout(conn: &Connection) -> Result<Layout> {
    let user_version: i64 = conn.pragma_query_value(None, "user_version", |r| r.get(0))?;
    let mut stmt = conn.prepare("SELECT name FROM sqlite_master WHERE type = 'table'")?;
    let tables: HashSet<String> = stmt
        .query_map([], |r| r.get::<_, String>(0))?
        .collect::<rusqlite::Result<_>>()?;
    let missing: Vec<&str> = REQUIRED_TABLES
        .iter()
        .copied()
        .filter(|t| !tables.contains(*t))
        .collect();
    if !missing.is_empty() {
        bail!(
            "not a COLMAP database: missing table{} {}",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", ")
        );
    }
    if !(0..(NEWEST_KNOWN_MAJOR + 1) * 1_000_000).contains(&user_version) {
        bail!(
            "unknown schema version {user_version} (PRAGMA user_version; known: COLMAP 3.x to {NEWEST_KNOWN_MAJOR}.x); \
             this COLMAP is newer than vgsel-colmap"
        );
    }
    let tvg = column_names(conn, "two_view_geometries")?;
    let missing: Vec<&str> = ["pair_id", "rows", "cols", "data", "config"]
        .into_iter()
        .filter(|c| !tvg.iter().any(|t| t == c))
        .collect();
    if !missing.is_empty() {
        bail!(
            "not a COLMAP database: two_view_geometries lacks column(s) {}",
            missing.join(", ")
        );
    }
    let two_view_columns = TWO_VIEW_COLUMNS
        .into_iter()
        .filter(|c| tvg.iter().any(|t| t == c))
        .collect();
    let descriptors_type = column_names(conn, "descriptors")?
        .iter()
        .any(|c| c == "type");
    let image_priors = column_names(conn, "images")?
        .iter()
        .any(|c| c == "prior_qw");
    Ok(Layout {
        user_version,
        two_view_columns,
        descriptors_type,
        image_priors,
        rigs: tables.contains("rigs"),
    })
}
