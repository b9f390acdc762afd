//! Everything that knows COLMAP's files: the SQLite database (read, rewrite, restore, copy) and
//! sparse models. The rest of the crate sees COLMAP only through these types.

pub mod blob;
pub mod copy;
pub mod database;
pub mod ids;
pub mod migration;
pub mod model;
pub mod rewrite;
pub mod schema;
pub mod sparse;
pub mod wal;

/// COLMAP's default `--Mapper.min_num_matches`: fewer verified inliers make no view-graph edge.
pub const DEFAULT_MIN_NUM_MATCHES: usize = 15;
