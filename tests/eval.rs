//! `eval` on models made from a generated ground truth: a similarity-transformed copy is all
//! correct; moved cameras, a split into sub-models and missing images are counted as such.

use nalgebra::{Rotation3, Vector3};
use std::path::Path;
use vgsel_colmap::eval::score::score;
use vgsel_colmap::eval::synth::{generate, write_gt_model, GroundTruth, SceneSpec};

fn truth(dir: &Path) -> GroundTruth {
    let spec = SceneSpec {
        num_images: 12,
        num_points: 1500,
        seed: 5,
        ..Default::default()
    };
    generate(&spec, &dir.join("db.db")).unwrap()
}

/// The same cameras in a world moved by x -> s R x + t.
fn transformed(gt: &GroundTruth, keep: impl Fn(usize) -> bool) -> GroundTruth {
    let (s, r, t) = (
        3.0,
        Rotation3::from_euler_angles(0.2, 1.0, -0.4),
        Vector3::new(5.0, -2.0, 1.0),
    );
    let mut out = gt.clone();
    out.images = gt
        .images
        .iter()
        .enumerate()
        .filter(|(k, _)| keep(*k))
        .map(|(_, im)| {
            let mut im = im.clone();
            im.rotation *= r.inverse();
            im.centre = s * (r * im.centre) + t;
            im.translation = -(im.rotation * im.centre);
            im
        })
        .collect();
    out
}

/// The whole transformed copy with camera 0 moved onto camera 6's pose: one camera wrong.
fn camera_0_on_6(gt: &GroundTruth) -> GroundTruth {
    let mut ghost = transformed(gt, |_| true);
    let other = ghost.images[6].clone();
    ghost.images[0].centre = other.centre;
    ghost.images[0].rotation = other.rotation;
    ghost.images[0].translation = other.translation;
    ghost
}

fn write(gt: &GroundTruth, dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    write_gt_model(gt, dir).unwrap();
}

#[test]
fn a_similar_model_is_all_correct_and_a_moved_camera_is_not() {
    let dir = tempfile::tempdir().unwrap();
    let gt = truth(dir.path());
    write(&gt, &dir.path().join("gt"));
    write(&transformed(&gt, |_| true), &dir.path().join("sparse/0"));
    let s = score(&dir.path().join("sparse"), &dir.path().join("gt")).unwrap();
    assert_eq!(
        (s.models, s.registered, s.correct, s.images_ground_truth),
        (1, 12, 12, 12)
    );
    assert!(s.median_position_error.unwrap() < 1e-9);

    // Move one camera to another camera's place: registered, not correct.
    write(&camera_0_on_6(&gt), &dir.path().join("ghost"));
    let s = score(&dir.path().join("ghost"), &dir.path().join("gt")).unwrap();
    assert_eq!((s.registered, s.correct), (12, 11));
    let wrong: Vec<&str> = s
        .images
        .iter()
        .filter(|i| !i.correct)
        .map(|i| i.name.as_str())
        .collect();
    assert_eq!(wrong, vec![gt.images[0].name.as_str()]);
}

#[test]
fn sub_models_are_scored_separately_and_missing_images_are_not_registered() {
    let dir = tempfile::tempdir().unwrap();
    let gt = truth(dir.path());
    write(&gt, &dir.path().join("gt"));
    write(&transformed(&gt, |k| k < 5), &dir.path().join("sparse/0"));
    write(
        &transformed(&gt, |k| (6..10).contains(&k)),
        &dir.path().join("sparse/1"),
    );
    let s = score(&dir.path().join("sparse"), &dir.path().join("gt")).unwrap();
    assert_eq!((s.models, s.registered, s.correct), (2, 9, 9));
    assert_eq!(s.wrong_registrations, 0);
    assert!(s.images.iter().any(|i| i.model == 1));
}

/// An image registered in two sub-models, right in one and wrong in the other (a mapper's
/// small second copy beside a ghost), is correct with its best score, and its wrong
/// registration is counted apart.
#[test]
fn an_image_wrong_in_one_sub_model_and_right_in_another_is_a_wrong_registration() {
    let dir = tempfile::tempdir().unwrap();
    let gt = truth(dir.path());
    write(&gt, &dir.path().join("gt"));
    write(&camera_0_on_6(&gt), &dir.path().join("sparse/0"));
    write(&transformed(&gt, |k| k < 4), &dir.path().join("sparse/1"));
    let s = score(&dir.path().join("sparse"), &dir.path().join("gt")).unwrap();
    assert_eq!((s.models, s.registered, s.correct), (2, 12, 12));
    assert_eq!(s.wrong_registrations, 1);
}
