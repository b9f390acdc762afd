//! COLMAP 4's in-place migration of two_view_geometries, replayed on the rows vgsel-colmap backed
//! up, so a `restore` after COLMAP 4 opened a pruned database gives back what COLMAP would have
//! made of the original rows.
//!
//! Every COLMAP 4.x rewrites an older database as soon as it opens it (`PostMigrateTables` in
//! src/colmap/scene/database_sqlite.cc, the same in 4.0.0 to 4.2): it adds missing columns
//! (NULL), and for a database whose `user_version` is at most 3.13.0.0 sets `qvec = tvec = NULL`
//! where the pose is 3.x's "not set" placeholder (a zero quaternion, or the identity with a zero
//! translation); for one at most 3.14.0.0 it sets each of F, E, H that is all zeros to NULL. Then
//! it writes its own `user_version` (4.2.1: 4020100). COLMAP never sees `vgsel_backup`, so rows
//! backed up at 3.8 keep the placeholders, which COLMAP 4 would read back as real relative poses.
//! [`migrate_backup`] applies those steps to the backup, with COLMAP's exact tests.

use rusqlite::types::ValueRef;
use rusqlite::{Connection, OptionalExtension};

use super::schema::{column_names, user_version};

/// `MakeDatabaseVersionNumber(3, 13, 0, 0)`: databases at or below it get the pose step.
const POSE_PLACEHOLDERS_UP_TO: i64 = 3_130_000;
/// `MakeDatabaseVersionNumber(3, 14, 0, 0)`: databases at or below it get the F/E/H step.
const ZERO_MATRICES_UP_TO: i64 = 3_140_000;

/// Whether COLMAP migrating a database from schema `from` to `to` runs the step of `threshold`:
/// it runs when the opened database was at or below the threshold, and every COLMAP writing a
/// newer version than the threshold has the step.
fn step_runs(threshold: i64, from: i64, to: i64) -> bool {
    from <= threshold && threshold < to
}

/// The bytes COLMAP's `ReadStaticMatrixBlob` reads as `n` float64 values: `Some(values)` for a
/// blob or text of 8n bytes, `Some(zeros)` for an empty one; `None` where COLMAP would throw
/// (any other size; numbers, which SQLite hands over as text of the wrong size) and so could not
/// have migrated the database.
fn read_matrix(value: ValueRef, n: usize) -> Option<Vec<f64>> {
    let bytes = match value {
        ValueRef::Blob(b) | ValueRef::Text(b) => b,
        ValueRef::Null | ValueRef::Integer(_) | ValueRef::Real(_) => return None,
    };
    if bytes.is_empty() {
        return Some(vec![0.0; n]);
    }
    (bytes.len() == 8 * n).then(|| {
        bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("chunk of 8")))
            .collect()
    })
}

fn all_zero(values: &[f64]) -> bool {
    values.iter().all(|&v| v == 0.0)
}

/// 3.x's "pose not set": a zero quaternion, or the identity (w, x, y, z) = (1, 0, 0, 0) with a
/// zero translation. Compared as COLMAP does, with floating-point `==` (so -0.0 is zero: 3.8
/// writes (0, -0, -0, -0)).
fn is_pose_placeholder(qvec: &[f64], tvec: &[f64]) -> bool {
    let identity = qvec[0] == 1.0 && all_zero(&qvec[1..]) && all_zero(tvec);
    identity || all_zero(qvec)
}

/// Rewrites the `vgsel_backup` rows, backed up when the database was at schema `from`, into the
/// form COLMAP's migration to schema `to` would have given them in two_view_geometries. Returns
/// how many rows changed; does nothing when `to` is not newer than `from`.
pub fn migrate_backup(conn: &Connection, from: i64, to: i64) -> rusqlite::Result<usize> {
    let poses = step_runs(POSE_PLACEHOLDERS_UP_TO, from, to);
    let matrices = step_runs(ZERO_MATRICES_UP_TO, from, to);
    if !poses && !matrices {
        return Ok(0);
    }
    let mut updates: Vec<(i64, Vec<&str>)> = Vec::new();
    {
        let mut stmt = conn.prepare("SELECT pair_id, qvec, tvec, F, E, H FROM vgsel_backup")?;
        let mut rows = stmt.query([])?;
        while let Some(row) = rows.next()? {
            let mut cleared = Vec::new();
            if poses {
                let (q, t) = (row.get_ref(1)?, row.get_ref(2)?);
                if let (Some(q), Some(t)) = (read_matrix(q, 4), read_matrix(t, 3)) {
                    if is_pose_placeholder(&q, &t) {
                        cleared.extend(["qvec", "tvec"]);
                    }
                }
            }
            if matrices {
                for (i, name) in [(3, "F"), (4, "E"), (5, "H")] {
                    if read_matrix(row.get_ref(i)?, 9).is_some_and(|m| all_zero(&m)) {
                        cleared.push(name);
                    }
                }
            }
            if !cleared.is_empty() {
                updates.push((row.get(0)?, cleared));
            }
        }
    }
    for (pair_id, cleared) in &updates {
        let set: Vec<String> = cleared.iter().map(|c| format!("{c} = NULL")).collect();
        conn.execute(
            &format!(
                "UPDATE vgsel_backup SET {} WHERE pair_id = ?1",
                set.join(", ")
            ),
            [pair_id],
        )?;
    }
    Ok(updates.len())
}

/// Adds `vgsel_runs.user_version` to a runs table made by a vgsel-colmap that did not record it.
pub fn ensure_version_column(conn: &Connection) -> rusqlite::Result<()> {
    if !has_version_column(conn)? {
        conn.execute_batch("ALTER TABLE vgsel_runs ADD COLUMN user_version INTEGER")?;
    }
    Ok(())
}

fn has_version_column(conn: &Connection) -> rusqlite::Result<bool> {
    Ok(column_names(conn, "vgsel_runs")?
        .iter()
        .any(|c| c == "user_version"))
}

/// The schema version the backup rows were taken at: the last run's `user_version`. 0 (older
/// than every COLMAP) when a vgsel-colmap that did not record it made the backup; the steps are
/// idempotent on rows COLMAP 4 wrote, so replaying them there changes nothing COLMAP 4 would not.
fn backup_version(conn: &Connection) -> rusqlite::Result<i64> {
    if !has_version_column(conn)? {
        return Ok(0);
    }
    let last: Option<Option<i64>> = conn
        .query_row(
            "SELECT user_version FROM vgsel_runs ORDER BY run_id DESC LIMIT 1",
            [],
            |r| r.get(0),
        )
        .optional()?;
    Ok(last.flatten().unwrap_or(0))
}

/// Brings the backup rows to the database's current schema (see [`migrate_backup`]); run before
/// they are put back.
pub fn migrate_backup_to_current(conn: &Connection) -> rusqlite::Result<usize> {
    migrate_backup(conn, backup_version(conn)?, user_version(conn)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_follow_colmaps_version_gates() {
        assert!(step_runs(POSE_PLACEHOLDERS_UP_TO, 3800, 4_020_100));
        assert!(step_runs(ZERO_MATRICES_UP_TO, 0, 4_000_000));
        assert!(!step_runs(POSE_PLACEHOLDERS_UP_TO, 3800, 3800));
        assert!(!step_runs(POSE_PLACEHOLDERS_UP_TO, 4_010_100, 4_020_100));
        // A 4.x database that COLMAP 3.8 reopened (it writes 3800) is not migrated backwards.
        assert!(!step_runs(POSE_PLACEHOLDERS_UP_TO, 4_020_100, 3800));
    }

    #[test]
    fn placeholders_are_compared_as_floats() {
        assert!(is_pose_placeholder(
            &[0.0, -0.0, -0.0, -0.0],
            &[0.0, 0.0, 0.0]
        ));
        assert!(is_pose_placeholder(&[0.0; 4], &[1.0, 2.0, 3.0]));
        assert!(is_pose_placeholder(
            &[1.0, 0.0, -0.0, 0.0],
            &[-0.0, 0.0, 0.0]
        ));
        assert!(!is_pose_placeholder(
            &[1.0, 0.0, 0.0, 0.0],
            &[0.0, 0.0, 1.0]
        ));
        assert!(!is_pose_placeholder(&[0.5, 0.5, 0.5, 0.5], &[0.0; 3]));
    }

    #[test]
    fn matrices_read_as_colmap_reads_them() {
        assert_eq!(read_matrix(ValueRef::Blob(&[]), 3), Some(vec![0.0; 3]));
        assert_eq!(read_matrix(ValueRef::Text(b""), 3), Some(vec![0.0; 3]));
        assert_eq!(read_matrix(ValueRef::Blob(&[0; 16]), 3), None);
        assert_eq!(read_matrix(ValueRef::Integer(0), 3), None);
        assert_eq!(read_matrix(ValueRef::Null, 3), None);
        let bytes: Vec<u8> = [1.5f64, -2.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            read_matrix(ValueRef::Blob(&bytes), 2),
            Some(vec![1.5, -2.0])
        );
    }
}
