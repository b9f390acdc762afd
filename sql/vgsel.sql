-- vgsel-colmap's own tables inside a COLMAP database. The vgsel_ prefix keeps them clear of
-- COLMAP's names; COLMAP ignores tables it does not know.

-- Original two_view_geometries rows of the pairs a prune invalidated. Apart from pair_id the
-- columns have no declared type on purpose: no type means no type affinity, so every value keeps
-- its exact SQLite storage class (INTEGER stays INTEGER, a zero-length blob stays a blob) and a
-- restore is byte for byte. Columns the database's layout lacks hold NULL.
CREATE TABLE IF NOT EXISTS vgsel_backup (
    pair_id  INTEGER PRIMARY KEY NOT NULL,
    rows, cols, data, config, F, E, H, qvec, tvec, camera1, camera2
);

-- The backed-up pairs a prune kept with fewer inliers rather than invalidated (`prune --model`
-- drops the matches that held a misplaced image where a model put it): their rows in
-- two_view_geometries stay valid, with the remaining inliers.
CREATE TABLE IF NOT EXISTS vgsel_trimmed (
    pair_id  INTEGER PRIMARY KEY NOT NULL
);

-- One row per prune, for reports and for telling a user what was done to the file.
CREATE TABLE IF NOT EXISTS vgsel_runs (
    run_id          INTEGER PRIMARY KEY,
    time            TEXT    NOT NULL,  -- UTC, ISO-8601
    tool_version    TEXT    NOT NULL,
    parameters      TEXT    NOT NULL,  -- JSON
    flow            INTEGER,
    images_total    INTEGER NOT NULL,
    images_selected INTEGER NOT NULL,
    pairs_total     INTEGER NOT NULL,
    pairs_selected  INTEGER NOT NULL,
    -- PRAGMA user_version when the backup was taken: a restore after COLMAP 4 migrated the
    -- file replays the migration on the backup (src/colmap/migration.rs). Added to older runs tables.
    user_version    INTEGER
);
