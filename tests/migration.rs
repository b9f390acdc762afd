//! Restore and re-prune after COLMAP 4 migrated a pruned 3.8 database, on the hand-made fixture
//! with COLMAP 4's migration of two_view_geometries written out in SQL (tests/colmap4.rs does
//! the same with the real COLMAP 4.2).

use crate::support::*;
use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::colmap::ids::pair_id;
use vgsel_colmap::colmap::rewrite::{apply, restore, Edits, RunRecord};

/// What COLMAP 4.2 does to a 3.8 database when it opens it, for the values of the fixture: the
/// placeholder pose (identity and zero translation, or a zero quaternion) and empty or zero
/// F/E/H become NULL, user_version becomes 4.2.1's.
fn colmap4_opens(path: &std::path::Path) {
    let hex = |v: &[f64]| -> String { f64_blob(v).iter().map(|b| format!("{b:02X}")).collect() };
    let (identity, zero3, zero4) = (hex(&[1.0, 0.0, 0.0, 0.0]), hex(&[0.0; 3]), hex(&[0.0; 4]));
    let mut sql = format!(
        "UPDATE two_view_geometries SET qvec = NULL, tvec = NULL \
         WHERE (qvec = X'{identity}' AND tvec = X'{zero3}') OR qvec = X'{zero4}';"
    );
    for m in ["F", "E", "H"] {
        sql += &format!(
            "UPDATE two_view_geometries SET {m} = NULL WHERE {m} = X'' OR {m} = zeroblob(72);"
        );
    }
    exec(path, &(sql + "PRAGMA user_version = 4020100;"));
}

fn prune(path: &std::path::Path, pairs: &[(u32, u32)]) {
    let mut db = Database::open(path).unwrap();
    let ids: Vec<u64> = pairs.iter().map(|&(a, b)| pair_id(a, b)).collect();
    let run = RunRecord {
        parameters: serde_json::json!({}),
        flow: None,
        images_total: 4,
        images_selected: 4,
        pairs_total: 4,
        pairs_selected: 4 - pairs.len(),
    };
    apply(&mut db, &Edits::invalidating(ids.clone()), &run).unwrap();
}

/// The pairs pruned hold every case of the migration: (1, 2) the placeholder pose, (1, 3) an
/// empty E, (1, 4) empty F and H.
const PRUNED: [(u32, u32); 3] = [(1, 2), (1, 3), (1, 4)];

#[test]
fn restore_after_migration_gives_colmap4s_form_of_the_original() {
    // Legacy: a runs table from a vgsel-colmap that did not record user_version.
    for legacy in [false, true] {
        let (dir, db) = fixture(Schema::V38);
        let migrated = dir.path().join("migrated.db");
        std::fs::copy(&db, &migrated).unwrap();
        colmap4_opens(&migrated);
        assert_ne!(
            dump(&migrated, "two_view_geometries"),
            dump(&db, "two_view_geometries")
        );
        prune(&db, &PRUNED);
        if legacy {
            exec(&db, "ALTER TABLE vgsel_runs DROP COLUMN user_version");
        }
        colmap4_opens(&db);
        let mut opened = Database::open(&db).unwrap();
        restore(&mut opened).unwrap();
        drop(opened);
        assert_eq!(
            dump(&db, "two_view_geometries"),
            dump(&migrated, "two_view_geometries"),
            "legacy runs table: {legacy}"
        );
    }
}

#[test]
fn reprune_after_migration_keeps_colmap4s_form() {
    let (dir, db) = fixture(Schema::V38);
    let migrated = dir.path().join("migrated.db");
    std::fs::copy(&db, &migrated).unwrap();
    colmap4_opens(&migrated);
    prune(&db, &PRUNED);
    colmap4_opens(&db);
    // The second prune keeps (1, 2) and (1, 4): they come back in COLMAP 4's form.
    prune(&db, &[(1, 3)]);
    assert_eq!(run_versions(&db), [Some(3800), Some(4_020_100)]);
    let now = dump(&db, "two_view_geometries");
    let want = dump(&migrated, "two_view_geometries");
    for pair in [(1, 2), (1, 4), (2, 3), (3, 4)] {
        assert_eq!(row_of(&now, pair), row_of(&want, pair), "{pair:?}");
    }
    let mut opened = Database::open(&db).unwrap();
    restore(&mut opened).unwrap();
    drop(opened);
    assert_eq!(dump(&db, "two_view_geometries"), want);
}
