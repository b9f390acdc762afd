//! `inspect`: prints the view graph's figures (images, pairs, components, degrees, pruned or
//! not), as text or JSON.

use super::args::DatabaseArg;
use anyhow::Result;
use clap::Args;

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct InspectArgs {
    #[command(flatten)]
    database: DatabaseArg,
    /// A pair counts when it has at least this many verified inliers (as --Mapper.min_num_matches).
    #[arg(long, default_value_t = vgsel_colmap::selection::pipeline::DEFAULT_MIN_NUM_MATCHES)]
    min_num_matches: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &InspectArgs) -> Result<()> {
    let db = args.database.open(true)?;
    let images = db.images()?;
    let pairs = db.verified_pairs()?;
    let graph =
        vgsel_colmap::scene::view_graph::ViewGraph::build(&images, &pairs, args.min_num_matches);
    let stats = graph.stats();
    let pruned = db.is_pruned()?;
    if args.json {
        let value = serde_json::json!({
            "database_path": args.database.database_path.display().to_string(),
            "images_total": images.len(),
            "pairs_verified": pairs.len(),
            "view_graph": stats,
            "pruned_by_vgsel_colmap": pruned,
        });
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
    Ok(())
}
