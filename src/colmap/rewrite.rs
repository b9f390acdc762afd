//! Invalidating unselected pairs in two_view_geometries, reversibly, in one transaction.
//!
//! An invalidated pair keeps its row with rows=0, cols=2, data=NULL, config=1 (DEGENERATE) and
//! every geometry column NULL: COLMAP's incremental mapper skips rows=0, GLOMAP/global_mapper skip
//! DEGENERATE, and a re-run matcher does not re-verify a pair whose row still exists. A trimmed
//! pair stays valid with fewer inliers (rows and data only). `matches`, `PRAGMA user_version` and
//! COLMAP's table definitions are never touched. The original rows of both go to `vgsel_backup`
//! (sql/vgsel.sql), whose untyped columns keep each value's storage class, so a restore is byte
//! for byte; `vgsel_trimmed` tells the trimmed ones.

use crate::colmap::blob::encode_pairs;
use crate::colmap::database::{data_version, Database, SqlResult};
use crate::colmap::ids::{image_ids, TwoViewConfig};
use crate::colmap::migration;
use crate::colmap::schema::{self, table_exists, TWO_VIEW_COLUMNS};
use anyhow::{anyhow, bail, Result};
use rusqlite::{Connection, Transaction, TransactionBehavior};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeSet;
use std::path::Path;

/// The project's tables (CREATE TABLE IF NOT EXISTS).
pub const VGSEL_SQL: &str = include_str!("../../sql/vgsel.sql");

/// What a prune writes into two_view_geometries, from the original rows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Edits {
    /// pair_ids of the pairs made invalid.
    pub invalidate: Vec<u64>,
    /// Pairs that stay valid with some of their inliers.
    pub trim: Vec<Trim>,
}

impl Edits {
    /// Edits that invalidate `pairs` and trim none.
    pub fn invalidating(pairs: Vec<u64>) -> Edits {
        Edits {
            invalidate: pairs,
            trim: Vec::new(),
        }
    }
}

/// A pair kept with fewer inliers: `prune --model` drops the matches that held a misplaced
/// image where a model put it, and a link's matches its placement does not explain.
#[derive(Clone, Debug, PartialEq)]
pub struct Trim {
    /// The pair.
    pub pair_id: u64,
    /// The inliers it keeps (keypoint of the pair's first image, of its second, as stored).
    pub inliers: Vec<[u32; 2]>,
}

/// What a prune records in the project's runs table: its parameters `P` (stored as JSON with
/// sorted keys; this layer does not know what they mean) and what it selected.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord<P> {
    /// The parameters the prune ran with.
    pub parameters: P,
    /// The flow F chosen (None where no flow ran).
    pub flow: Option<u64>,
    /// Images in the database.
    pub images_total: usize,
    /// Images with a selected pair.
    pub images_selected: usize,
    /// View-graph edges.
    pub pairs_total: usize,
    /// Edges left valid.
    pub pairs_selected: usize,
}

/// A row of vgsel_runs, as read back.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecordRow<P> {
    /// The row's id: 1 for the first prune, counting up.
    pub run_id: i64,
    /// UTC, ISO-8601 (`2024-05-01T12:00:00Z`).
    pub time: String,
    /// The vgsel-colmap version that pruned.
    pub tool_version: String,
    /// What it recorded.
    pub run: RunRecord<P>,
}

/// Puts every backed-up row back into two_view_geometries (re-inserting rows deleted since the
/// prune) and returns how many. Copies values column to column inside SQLite, so storage
/// classes survive; rows backed up before COLMAP 4 migrated the file are first given COLMAP's
/// migrated form. Leaves the backup table otherwise as it is.
fn put_back(conn: &Connection, columns: &[&str]) -> rusqlite::Result<usize> {
    migration::migrate_backup_to_current(conn)?;
    let set: Vec<String> = columns.iter().map(|c| format!("{c} = b.{c}")).collect();
    conn.execute(
        &format!(
            "UPDATE two_view_geometries SET {} FROM vgsel_backup AS b \
             WHERE two_view_geometries.pair_id = b.pair_id",
            set.join(", ")
        ),
        [],
    )?;
    let list = columns.join(", ");
    conn.execute(
        &format!(
            "INSERT INTO two_view_geometries (pair_id, {list}) SELECT pair_id, {list} \
             FROM vgsel_backup WHERE pair_id NOT IN (SELECT pair_id FROM two_view_geometries)"
        ),
        [],
    )?;
    conn.query_row("SELECT count(*) FROM vgsel_backup", [], |r| {
        r.get::<_, i64>(0)
    })
    .map(|n| n as usize)
}

fn ensure_writable(db: &Database) -> Result<()> {
    if db.is_read_only() {
        bail!(
            "{}: database was opened read-only; cannot rewrite it",
            db.path().display()
        );
    }
    Ok(())
}

/// Makes exactly the pairs in `edits.invalidate` invalid and trims those in `edits.trim`,
/// starting from the original rows (a previous prune is undone first), saves their original rows
/// in the backup table and appends a run record; all in one transaction.
pub fn apply<P: Serialize>(db: &mut Database, edits: &Edits, run: &RunRecord<P>) -> Result<()> {
    apply_checked(db, None, edits, run)
}

/// [`apply`] to a database the selection was planned on, refusing (nothing written) when another
/// program committed a change since [`Database::data_version`] was `read_version`: the plan
/// would overwrite that program's work with decisions made on rows it replaced.
pub fn apply_if_unchanged<P: Serialize>(
    db: &mut Database,
    read_version: i64,
    edits: &Edits,
    run: &RunRecord<P>,
) -> Result<()> {
    apply_checked(db, Some(read_version), edits, run)
}

fn apply_checked<P: Serialize>(
    db: &mut Database,
    read_version: Option<i64>,
    edits: &Edits,
    run: &RunRecord<P>,
) -> Result<()> {
    // Through a JSON value, whose maps are sorted: the stored text does not depend on field order.
    let parameters = serde_json::to_value(&run.parameters)?.to_string();
    write_transaction(db, |tx, columns, p| {
        // Inside the write transaction: no other writer can commit between check and write.
        if let Some(version) = read_version {
            unchanged_since(tx, p, version)?;
        }
        apply_in(tx, columns, p, edits, &parameters, run)
    })
}

/// Fails (one line) when another connection committed a change since `PRAGMA data_version` was
/// `read_version`.
pub(crate) fn unchanged_since(conn: &Connection, p: &Path, read_version: i64) -> Result<()> {
    if data_version(conn, p)? != read_version {
        bail!(
            "{}: another program changed the database while it was being read; nothing was written (run the prune again)",
            p.display()
        );
    }
    Ok(())
}

/// Runs `body` in one IMMEDIATE transaction of a writable database and commits it; on failure
/// the transaction rolls back and the journal is settled. `body` gets the layout's
/// two_view_geometries columns and the path for error messages.
fn write_transaction<T>(
    db: &mut Database,
    body: impl FnOnce(&Transaction, &[&'static str], &Path) -> Result<T>,
) -> Result<T> {
    ensure_writable(db)?;
    let path = db.path().to_path_buf();
    let columns = db.layout().two_view_columns.clone();
    let result = (|| {
        let tx = db
            .conn_mut()
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .sql(&path)?;
        let out = body(&tx, &columns, &path)?;
        tx.commit().sql(&path)?;
        Ok(out)
    })();
    if result.is_err() {
        settle_after_failure(db);
    }
    result
}

/// After a write fails (disk full, I/O error) SQLite can leave the rolled-back transaction's hot
/// journal beside the database until the next statement. One read plays it back now, so a failed
/// command leaves no `-journal` file behind; if that read fails too, the next open does it.
fn settle_after_failure(db: &Database) {
    let _ = db
        .conn()
        .query_row("SELECT count(*) FROM sqlite_master", [], |r| {
            r.get::<_, i64>(0)
        });
}

/// The prune's write inside `tx`: the original rows back, the edits, the run record.
fn apply_in<P>(
    tx: &Transaction,
    columns: &[&'static str],
    p: &Path,
    edits: &Edits,
    parameters: &str,
    run: &RunRecord<P>,
) -> Result<()> {
    tx.execute_batch(VGSEL_SQL).sql(p)?;
    migration::ensure_version_column(tx).sql(p)?;
    put_back(tx, columns).sql(p)?;
    tx.execute_batch("DELETE FROM vgsel_backup; DELETE FROM vgsel_trimmed;")
        .sql(p)?;
    write_edits(tx, columns, p, edits)?;
    let count = |n: usize| n as i64;
    tx.execute(
        "INSERT INTO vgsel_runs (time, tool_version, parameters, flow, images_total, \
         images_selected, pairs_total, pairs_selected, user_version) \
         VALUES (strftime('%Y-%m-%dT%H:%M:%SZ', 'now'), ?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
        rusqlite::params![
            env!("CARGO_PKG_VERSION"),
            parameters,
            run.flow.map(|f| f as i64),
            count(run.images_total),
            count(run.images_selected),
            count(run.pairs_total),
            count(run.pairs_selected),
            schema::user_version(tx).sql(p)?,
        ],
    )
    .sql(p)?;
    Ok(())
}

/// Backs up and edits each pair of `edits` (from the original rows): invalidated ones
/// cleared, trimmed ones given their kept inliers and listed in `vgsel_trimmed`. Refuses a
/// pair edited twice or without a row.
fn write_edits(tx: &Transaction, columns: &[&'static str], p: &Path, edits: &Edits) -> Result<()> {
    let unique: BTreeSet<u64> = edits.invalidate.iter().copied().collect();
    let mut trims = BTreeSet::new();
    if let Some(t) =
        (edits.trim.iter()).find(|t| unique.contains(&t.pair_id) || !trims.insert(t.pair_id))
    {
        let (a, b) = image_ids(t.pair_id);
        bail!("pair_id {} (images {a}, {b}) is edited twice (trimmed and invalidated, or trimmed twice)", t.pair_id);
    }
    let copied: Vec<&str> = TWO_VIEW_COLUMNS
        .iter()
        .map(|c| if columns.contains(c) { *c } else { "NULL" })
        .collect();
    let mut backup = tx
        .prepare(&format!(
            "INSERT INTO vgsel_backup (pair_id, {}) SELECT pair_id, {} \
             FROM two_view_geometries WHERE pair_id = ?1",
            TWO_VIEW_COLUMNS.join(", "),
            copied.join(", ")
        ))
        .sql(p)?;
    let cleared: Vec<String> = columns
        .iter()
        .map(|c| match *c {
            "rows" => "rows = 0".to_string(),
            "cols" => "cols = 2".to_string(),
            "config" => format!("config = {}", TwoViewConfig::Degenerate.code()),
            other => format!("{other} = NULL"),
        })
        .collect();
    let mut clear = tx
        .prepare(&format!(
            "UPDATE two_view_geometries SET {} WHERE pair_id = ?1",
            cleared.join(", ")
        ))
        .sql(p)?;
    let mut trim = tx
        .prepare("UPDATE two_view_geometries SET rows = ?2, cols = 2, data = ?3 WHERE pair_id = ?1")
        .sql(p)?;
    let mut trimmed = tx
        .prepare("INSERT INTO vgsel_trimmed (pair_id) VALUES (?1)")
        .sql(p)?;
    let mut back_up = |id: u64, what: &str| -> Result<i64> {
        let (a, b) = image_ids(id);
        let raw = i64::try_from(id).map_err(|_| anyhow!("pair_id {id} out of range"))?;
        if backup.execute([raw]).sql(p)? == 0 {
            bail!(
                "cannot {what} pair_id {id} (images {a}, {b}): it has no two_view_geometries row"
            );
        }
        Ok(raw)
    };
    for &id in &unique {
        clear.execute([back_up(id, "invalidate")?]).sql(p)?;
    }
    for t in &edits.trim {
        let raw = back_up(t.pair_id, "trim")?;
        let data = encode_pairs(&t.inliers);
        trim.execute(rusqlite::params![raw, t.inliers.len() as i64, data])
            .sql(p)?;
        trimmed.execute([raw]).sql(p)?;
    }
    Ok(())
}

/// Puts every backed-up row back, byte for byte, and drops the project's tables. Returns the
/// number of rows restored; fails if the database was never pruned.
pub fn restore(db: &mut Database) -> Result<usize> {
    if !db.has_backup_table()? {
        bail!("database was not pruned by vgsel-colmap");
    }
    write_transaction(db, |tx, columns, p| {
        let n = put_back(tx, columns).sql(p)?;
        tx.execute_batch(
            "DROP TABLE vgsel_backup; DROP TABLE IF EXISTS vgsel_trimmed; \
             DROP TABLE IF EXISTS vgsel_runs;",
        )
        .sql(p)?;
        Ok(n)
    })
}

/// The most recent prune's record, or None when the database has no runs table (never pruned,
/// or restored since).
pub fn last_run<P: DeserializeOwned>(db: &Database) -> Result<Option<RunRecordRow<P>>> {
    let p = db.path();
    let conn = db.conn();
    if !table_exists(conn, "vgsel_runs").sql(p)? {
        return Ok(None);
    }
    let mut stmt = conn
        .prepare(
            "SELECT run_id, time, tool_version, parameters, flow, images_total, images_selected, \
             pairs_total, pairs_selected FROM vgsel_runs ORDER BY run_id DESC LIMIT 1",
        )
        .sql(p)?;
    let mut rows = stmt.query([]).sql(p)?;
    let Some(r) = rows.next().sql(p)? else {
        return Ok(None);
    };
    let n = |i: usize| -> Result<usize> { Ok(r.get::<_, i64>(i).sql(p)? as usize) };
    let run_id: i64 = r.get(0).sql(p)?;
    let text: String = r.get(3).sql(p)?;
    let parameters = serde_json::from_str(&text).map_err(|e| {
        anyhow!(
            "{}: vgsel_runs row {run_id}: parameters this version cannot read ({e}); restore and prune again",
            p.display()
        )
    })?;
    Ok(Some(RunRecordRow {
        run_id,
        time: r.get(1).sql(p)?,
        tool_version: r.get(2).sql(p)?,
        run: RunRecord {
            parameters,
            flow: r.get::<_, Option<i64>>(4).sql(p)?.map(|f| f as u64),
            images_total: n(5)?,
            images_selected: n(6)?,
            pairs_total: n(7)?,
            pairs_selected: n(8)?,
        },
    }))
}
