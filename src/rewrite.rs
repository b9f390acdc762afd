//! Invalidating unselected pairs in two_view_geometries, reversibly, in one transaction.
//! (helper "database" implements)

use crate::database::Database;
use anyhow::Result;

/// What a prune records in the project's runs table.
#[derive(Clone, Debug)]
pub struct RunRecord {
    /// JSON of the parameters used.
    pub parameters: String,
    pub flow: Option<u64>,
    pub images_total: usize,
    pub images_selected: usize,
    pub pairs_total: usize,
    pub pairs_selected: usize,
}

/// Makes exactly the pairs in `invalidate` (pair_ids) invalid, starting from the original rows
/// (a previous prune is undone first), saves their original rows in the backup table and appends
/// a run record; all in one transaction.
pub fn apply(_db: &mut Database, _invalidate: &[u64], _run: &RunRecord) -> Result<()> {
    todo!()
}

/// Puts every backed-up row back, byte for byte, and drops the project's tables. Returns the
/// number of rows restored; fails if the database was never pruned.
pub fn restore(_db: &mut Database) -> Result<usize> {
    todo!()
}

pub fn copy_database(
    _src: &std::path::Path,
    _dst: &std::path::Path,
    _overwrite: bool,
) -> Result<()> {
    todo!()
}
