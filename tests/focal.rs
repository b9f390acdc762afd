//! Focal-length estimation on a generated database whose camera carries COLMAP's guess
//! (1.2 × max(width, height), prior_focal_length = 0) and UNCALIBRATED geometries.

use vgsel_colmap::colmap::database::Database;
use vgsel_colmap::eval::synth::{generate, SceneSpec};
use vgsel_colmap::selection::arc_rules::Overrides;
use vgsel_colmap::selection::parameters::{Given, Parameters};
use vgsel_colmap::selection::pipeline::plan;

#[test]
fn guessed_focal_length_is_replaced_by_the_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("guessed.db");
    let spec = SceneSpec {
        num_images: 16,
        num_points: 3000,
        stored_focal: Some(1.2 * 480.0),
        seed: 5,
        ..SceneSpec::default()
    };
    generate(&spec, &path).unwrap();
    let db = Database::open_read_only(&path).unwrap();
    let given = Given {
        flow: Some(4),
        ..Given::default()
    };
    let parameters = Parameters::resolve(given).unwrap();
    let p = plan(
        &db,
        &parameters,
        &Overrides::default(),
        Default::default(),
        &|_| {},
    )
    .unwrap();
    assert_eq!(p.focal_estimates.len(), 1);
    let e = &p.focal_estimates[0];
    assert_eq!(e.guessed, 576.0);
    assert!(
        (e.estimated - spec.focal).abs() < 0.02 * spec.focal,
        "estimated {} for a true {}",
        e.estimated,
        spec.focal
    );
}
