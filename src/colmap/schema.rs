//! Which COLMAP layout a database has: its schema version and the optional columns and tables of
//! 3.8 through today's, detected by name (`PRAGMA table_info`) because COLMAP adds and drops
//! columns between versions.
//!
//! Schema versions: `PRAGMA user_version` is read; values below 5,000,000 are accepted (0 = written
//! by a script, 3800/3900 = COLMAP 3.x, major*1e6 + minor*1e4 + patch*100 = COLMAP 4.x and main).
//! A value of 5,000,000 or more is a COLMAP major version we have never seen and is refused, so we
//! never rewrite a layout whose meaning we do not know.

use anyhow::{bail, Result};
use rusqlite::{Connection, OptionalExtension};
use std::collections::HashSet;

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
    /// Whether two_view_geometries has `column` (a member of [`TWO_VIEW_COLUMNS`]).
    pub fn has_two_view_column(&self, column: &str) -> bool {
        self.two_view_columns.contains(&column)
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

pub(crate) fn column_names(conn: &Connection, table: &str) -> rusqlite::Result<Vec<String>> {
    let mut stmt = conn.prepare(&format!("PRAGMA table_info({table})"))?;
    let names = stmt.query_map([], |r| r.get::<_, String>(1))?;
    names.collect()
}

/// `PRAGMA user_version` now (inside a caller's transaction too).
pub(crate) fn user_version(conn: &Connection) -> rusqlite::Result<i64> {
    conn.pragma_query_value(None, "user_version", |r| r.get(0))
}

/// Reads user_version and the tables' columns; refuses what is not (or not yet) COLMAP.
pub(crate) fn detect_layout(conn: &Connection) -> Result<Layout> {
    let user_version = user_version(conn)?;
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
