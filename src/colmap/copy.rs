//! Copies of a COLMAP database that are never half-written: the backup-API copy for
//! `prune --output`, the pruned copy (copy beside the target, prune it, rename), and the clean-up
//! of temporaries a killed run left behind.

use crate::colmap::database::{sql_error, Database, SqlResult};
use crate::colmap::rewrite::{apply, unchanged_since, Edits, RunRecord};
use anyhow::{anyhow, bail, Context, Result};
use rusqlite::OpenFlags;
use serde::Serialize;
use std::path::Path;

/// Copies `input` to a temporary file beside `out`, prunes the copy, then renames it to `out`:
/// `out` is never half-written, and the temporary file is removed on failure. With
/// `read_version` (the [`Database::data_version`] a plan read the input at) the copy is refused
/// when another program changed the input since, so it is exactly what the plan saw.
pub fn write_pruned_copy<P: Serialize>(
    input: &Database,
    read_version: Option<i64>,
    out: &Path,
    edits: &Edits,
    run: &RunRecord<P>,
) -> Result<()> {
    let name = out
        .file_name()
        .context("the pruned copy's path names no file")?
        .to_string_lossy();
    remove_stale_temporaries(out);
    let tmp = out.with_file_name(format!(".{name}.vgsel-tmp-{}", std::process::id()));
    let result = (|| {
        copy_from(input, read_version, &tmp, true)?;
        let mut copy = Database::open(&tmp)?;
        apply(&mut copy, edits, run)?;
        drop(copy);
        std::fs::rename(&tmp, out)
            .with_context(|| format!("cannot move the pruned copy to {}", out.display()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
        let journal = format!(
            "{}-journal",
            tmp.file_name().unwrap_or_default().to_string_lossy()
        );
        let _ = std::fs::remove_file(tmp.with_file_name(journal));
    }
    result
}

/// Removes temporary copies of `dst` (and their journals) that a killed vgsel-colmap left beside
/// it: names `.NAME.vgsel-tmp-PID…` or `..NAME.vgsel-tmp-PID…` whose process no longer runs.
/// A SIGKILL cannot be cleaned up after at the time, so the next run does it.
pub fn remove_stale_temporaries(dst: &Path) {
    let (Some(dir), Some(name)) = (dst.parent(), dst.file_name()) else {
        return;
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let prefix = format!(".{}.vgsel-tmp-", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = file
            .strip_prefix(&prefix)
            .or_else(|| file.strip_prefix(&format!(".{prefix}")))
        else {
            continue;
        };
        let pid: String = rest.chars().take_while(char::is_ascii_digit).collect();
        if !pid.is_empty() && !Path::new("/proc").join(&pid).exists() {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Copies a COLMAP database for `prune --output`: SQLite's online backup API into a temporary
/// file beside `dst`, then a rename, so `dst` is never half-written and a concurrent writer to
/// `src` cannot tear the copy. Refuses an existing `dst` unless `overwrite`; never modifies `src`.
pub fn copy_database(src: &Path, dst: &Path, overwrite: bool) -> Result<()> {
    // Validates src as a COLMAP database (with the usual one-line errors) and opens it read-only.
    copy_from(&Database::open_read_only(src)?, None, dst, overwrite)
}

/// [`copy_database`] from an open database; with `read_version`, only if no other program
/// changed it since its [`Database::data_version`] was that.
fn copy_from(
    source: &Database,
    read_version: Option<i64>,
    dst: &Path,
    overwrite: bool,
) -> Result<()> {
    let src = source.path();
    if dst.is_dir() {
        bail!("cannot write {}: it is a directory", dst.display());
    }
    if dst.exists() {
        let same = match (src.canonicalize(), dst.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        if same {
            bail!(
                "cannot copy {} onto itself; give a different output path",
                src.display()
            );
        }
        if !overwrite {
            bail!(
                "output {} already exists (refusing to overwrite it)",
                dst.display()
            );
        }
    }
    let name = dst
        .file_name()
        .ok_or_else(|| anyhow!("output path {} has no file name", dst.display()))?;
    let tmp = dst.with_file_name(format!(
        ".{}.vgsel-tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| -> Result<()> {
        let _ = std::fs::remove_file(&tmp);
        let conn = source.conn();
        if read_version.is_some() {
            // One read transaction around check and copy: the backup then copies this snapshot
            // (SQLite's backup reuses the source connection's open transaction).
            conn.execute_batch("BEGIN").sql(src)?;
        }
        let copied = read_version
            .map_or(Ok(()), |v| unchanged_since(conn, src, v))
            .and_then(|()| {
                conn.backup(rusqlite::DatabaseName::Main, &tmp, None)
                    .map_err(|e| anyhow!("cannot copy {} to {}: {e}", src.display(), dst.display()))
            });
        if read_version.is_some() {
            let _ = conn.execute_batch("COMMIT");
        }
        copied?;
        // Reopen to be sure the copy is a readable database before it takes dst's name.
        crate::colmap::wal::open_for_reading(&tmp, OpenFlags::empty())
            .and_then(|c| c.query_row("PRAGMA quick_check", [], |r| r.get::<_, String>(0)))
            .map_err(|e| sql_error(&tmp, e))
            .and_then(|s| {
                if s == "ok" {
                    Ok(())
                } else {
                    Err(anyhow!(
                        "{}: copy failed its integrity check: {s}",
                        tmp.display()
                    ))
                }
            })?;
        std::fs::rename(&tmp, dst)
            .map_err(|e| anyhow!("cannot rename {} to {}: {e}", tmp.display(), dst.display()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
