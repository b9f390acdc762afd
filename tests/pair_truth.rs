//! Pair labels from ground-truth epipolar geometry, on generated databases whose true poses are
//! known: every pair is true under the right poses, and most are false under turned poses.

use nalgebra::Rotation3;
use vgsel_colmap::eval::pair_truth::report;
use vgsel_colmap::eval::synth::{generate, write_gt_model, SceneSpec};

#[test]
fn pairs_are_true_under_the_true_poses_and_false_under_turned_cameras() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("db.db");
    let spec = SceneSpec {
        num_images: 12,
        num_points: 1500,
        seed: 4,
        ..Default::default()
    };
    let mut gt = generate(&spec, &db).unwrap();
    write_gt_model(&gt, &dir.path().join("gt")).unwrap();
    let labels = report(&db, &dir.path().join("gt"), None, 15).unwrap();
    assert!(labels.counts.used > 20, "{labels:?}");
    assert_eq!(labels.counts.true_pairs, labels.counts.used, "{labels:?}");
    assert_eq!(labels.counts.true_graph_components, 1);

    // Every camera turned by up to 12 degrees, about an axis that changes from image to image.
    for (k, im) in gt.images.iter_mut().enumerate() {
        let k = k as f64;
        let turn = Rotation3::from_euler_angles(0.15 * k.sin(), 0.15 * (1.7 * k).cos(), 0.0);
        im.rotation = turn * im.rotation;
        im.translation = -(im.rotation * im.centre);
    }
    write_gt_model(&gt, &dir.path().join("turned")).unwrap();
    let turned = report(&db, &dir.path().join("turned"), Some(&db), 15).unwrap();
    assert!(
        turned.counts.false_pairs * 10 >= turned.counts.used * 9,
        "{turned:?}"
    );
    // The baseline is the database itself: nothing removed, every true pair kept.
    assert_eq!(turned.false_removed, Some(0));
    assert_eq!(turned.true_kept, Some(turned.counts.true_pairs));
}
