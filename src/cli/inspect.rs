//! `inspect`: prints the view graph's figures (images, pairs, components, degrees, pruned or
//! not), as text or JSON; with `--tracks`, the feature tracks the mapper builds from the pairs.

use super::args::DatabaseArg;
use anyhow::Result;
use clap::Args;
use serde::Serialize;
use std::collections::HashSet;
use vgsel_colmap::colmap::database::{Database, Image, VerifiedPair};
use vgsel_colmap::colmap::ids::pair_id;
use vgsel_colmap::scene::{view_graph::ViewGraph, Scene};
use vgsel_colmap::selection::track_completion::{TrackSet, MIN_TRACK_LENGTH};

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct InspectArgs {
    #[command(flatten)]
    database: DatabaseArg,
    /// A pair counts when it has at least this many verified inliers (as --Mapper.min_num_matches).
    #[arg(long, default_value_t = vgsel_colmap::colmap::DEFAULT_MIN_NUM_MATCHES)]
    min_num_matches: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Also the feature tracks the mapper builds from the pairs it uses (those with enough
    /// inliers, and on a pruned database those the prune kept): keypoints on tracks, the mean
    /// track length a keypoint sees, and each image's keypoints on tracks of three or more
    /// observations (what prune's track completion counts).
    #[arg(long)]
    tracks: bool,
}

/// Feature tracks through a set of pairs.
#[derive(Serialize)]
struct TrackStats {
    /// Pairs whose inliers make the tracks.
    pairs: usize,
    /// Keypoints on tracks of two or more observations.
    keypoints_on_tracks: u64,
    /// Mean track length a keypoint on a track sees.
    mean_track_length: f64,
    /// Every image of the database, by image_id.
    images: Vec<ImageTracks>,
}

#[derive(Serialize)]
struct ImageTracks {
    image_id: u32,
    name: String,
    /// Keypoints on tracks of at least MIN_TRACK_LENGTH observations.
    keypoints_on_long_tracks: usize,
}

/// The tracks through every verified pair with enough inliers (`verified`) and through those of
/// them the database holds valid now (`used`: the same unless pruned).
#[derive(Serialize)]
struct Tracks {
    verified: TrackStats,
    used: TrackStats,
}

fn tracks(
    db: &Database,
    images: &[Image],
    pairs: &[VerifiedPair],
    graph: &ViewGraph,
    min_num_matches: usize,
) -> Result<Tracks> {
    // Tracks read only how many keypoints each image has, not where they lie.
    let counts = db.keypoint_counts()?;
    let keypoints = graph
        .image_ids
        .iter()
        .map(|id| vec![[0.0; 2]; counts.get(id).copied().unwrap_or(0)])
        .collect();
    let scene = Scene::new(graph, pairs, keypoints, vec![(0, 0); graph.num_vertices()]);
    let valid = db.used_pair_ids(min_num_matches)?;
    let used: HashSet<usize> = (0..graph.edges.len())
        .filter(|&e| {
            let p = &pairs[graph.edges[e].pair];
            valid.contains(&pair_id(p.image_id1, p.image_id2))
        })
        .collect();
    let stats = |keep: &dyn Fn(usize) -> bool| {
        let mut set = TrackSet::build(&scene, keep);
        let mut images: Vec<ImageTracks> = images
            .iter()
            .map(|im| ImageTracks {
                image_id: im.image_id,
                name: im.name.clone(),
                keypoints_on_long_tracks: graph
                    .image_ids
                    .binary_search(&im.image_id)
                    .map_or(0, |v| {
                        set.observations_on_tracks(v as u32, MIN_TRACK_LENGTH)
                    }),
            })
            .collect();
        images.sort_by_key(|im| im.image_id);
        TrackStats {
            pairs: (0..graph.edges.len()).filter(|&e| keep(e)).count(),
            keypoints_on_tracks: set.keypoints_on_tracks(),
            mean_track_length: set.mean_length(),
            images,
        }
    };
    Ok(Tracks {
        verified: stats(&|_| true),
        used: stats(&|e| used.contains(&e)),
    })
}

/// The text lines of `--tracks`: the used pairs' tracks, and on a pruned database each figure
/// of the verified pairs' beside it.
fn print_tracks(t: &Tracks, pruned: bool) {
    let of = |used: String, verified: String| {
        if pruned {
            format!("{used} (of {verified} verified)")
        } else {
            used
        }
    };
    let (u, v) = (&t.used, &t.verified);
    println!(
        "tracks            {} keypoints on tracks through {} pairs",
        of(
            u.keypoints_on_tracks.to_string(),
            v.keypoints_on_tracks.to_string()
        ),
        of(u.pairs.to_string(), v.pairs.to_string())
    );
    println!(
        "mean track length {}",
        of(
            format!("{:.2}", u.mean_track_length),
            format!("{:.2}", v.mean_track_length)
        )
    );
    let mut fewest: Vec<(&ImageTracks, &ImageTracks)> = u.images.iter().zip(&v.images).collect();
    fewest.sort_by_key(|(im, _)| (im.keypoints_on_long_tracks, im.image_id));
    let shown: Vec<String> = fewest
        .iter()
        .take(5)
        .map(|(im, all)| {
            let n = of(
                im.keypoints_on_long_tracks.to_string(),
                all.keypoints_on_long_tracks.to_string(),
            );
            format!("{} {}", im.name, n)
        })
        .collect();
    println!(
        "fewest on tracks  of >= {MIN_TRACK_LENGTH} observations: {}",
        shown.join(", ")
    );
}

pub fn run(args: &InspectArgs) -> Result<()> {
    let db = args.database.open(true)?;
    let images = db.images()?;
    let pairs = db.verified_pairs()?;
    let graph =
        vgsel_colmap::scene::view_graph::ViewGraph::build(&images, &pairs, args.min_num_matches);
    let stats = graph.stats();
    let pruned = db.is_pruned()?;
    let tracks = if args.tracks {
        Some(tracks(&db, &images, &pairs, &graph, args.min_num_matches)?)
    } else {
        None
    };
    if args.json {
        let mut value = serde_json::json!({
            "database_path": args.database.database_path.display().to_string(),
            "images_total": images.len(),
            "pairs_verified": pairs.len(),
            "view_graph": stats,
            "pruned_by_vgsel_colmap": pruned,
        });
        if let Some(t) = &tracks {
            value["tracks"] = serde_json::to_value(t)?;
        }
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!(
        "database          {}",
        args.database.database_path.display()
    );
    println!(
        "images            {} ({} in the view graph, {} without verified pairs)",
        images.len(),
        stats.images,
        stats.isolated_images
    );
    println!(
        "verified pairs    {} ({} with >= {} inliers)",
        pairs.len(),
        stats.pairs,
        args.min_num_matches
    );
    println!("components        {}", stats.components);
    println!(
        "degree            min {}  median {}  mean {:.1}  max {}",
        stats.degree_min, stats.degree_median, stats.degree_mean, stats.degree_max
    );
    println!(
        "pruned            {}",
        if pruned {
            "yes (figures above are of the original pairs; `restore` undoes it)"
        } else {
            "no"
        }
    );
    if let Some(t) = &tracks {
        print_tracks(t, pruned);
    }
    Ok(())
}
