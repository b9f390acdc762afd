//! `generate`: writes synthetic test data: a matched COLMAP database with its ground truth, a
//! view graph for `solve`, or rendered images with ground-truth poses.

use super::args::choice;
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use std::path::PathBuf;
use vgsel_colmap::eval::render::{self, SceneKind};
use vgsel_colmap::eval::synth;
use vgsel_colmap::flow::graph_file;
use vgsel_colmap::flow::synthetic_graph::{self, Arrangement};

#[derive(Subcommand)]
pub enum GenerateCommand {
    /// A matched COLMAP 3.8 database of cameras orbiting a synthetic scene, with its ground truth.
    Database(GenerateDatabaseArgs),
    /// A synthetic view graph of the paper's supplement in the `solve` text format.
    Graph(GenerateGraphArgs),
    /// Rendered PNG images of a textured scene (DIR/images) with ground-truth poses (DIR/gt, and
    /// DIR/gt/scene.json, from which `eval --labels` rebuilds the surfaces).
    Images(GenerateImagesArgs),
}

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct GenerateGraphArgs {
    /// The graph file to write.
    #[arg(long, value_name = "FILE")]
    output: PathBuf,
    /// Images (vertices), at least 2.
    #[arg(long, value_parser = clap::value_parser!(u64).range(2..))]
    images: u64,
    /// Pairs (edges), at most images x (images - 1) / 2.
    #[arg(long)]
    pairs: u64,
    #[arg(long, value_parser = choice::<Arrangement>(), default_value = "loop")]
    arrangement: Arrangement,
    /// The random generator's seed: the same seed gives the same graph.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct GenerateImagesArgs {
    #[arg(long, value_parser = choice::<SceneKind>(), default_value = "room")]
    scene: SceneKind,
    /// Output folder (images/ and gt/ are created in it).
    #[arg(long, value_name = "DIR")]
    output: PathBuf,
    /// Images to render.
    #[arg(long, default_value_t = 20)]
    num_images: usize,
    /// The random generator's seed (textures, placements): the same seed gives the same images.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(Args)]
#[command(rename_all = "snake_case")]
pub struct GenerateDatabaseArgs {
    /// The database to create (must not exist).
    #[arg(long, value_name = "DB")]
    output: PathBuf,
    /// Also write the ground-truth poses here as a COLMAP text model.
    #[arg(long, value_name = "DIR")]
    ground_truth: Option<PathBuf>,
    #[arg(long, default_value_t = 24)]
    num_images: usize,
    #[arg(long, default_value_t = 6000)]
    num_points: usize,
    /// Half-angle of the cone a point is seen from: narrower means fewer pairs per image.
    #[arg(long, default_value_t = 55.0)]
    view_cone_degrees: f64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Duplicate-structure scene: two copies of the object, the second turned by this yaw
    /// (degrees), with ground-truth pair labels; see `duplicate_scene`.
    #[arg(long, value_name = "DEG")]
    duplicate_yaw: Option<f64>,
    /// Store this focal length as an uncalibrated guess (prior_focal_length = 0, F only).
    #[arg(long, value_name = "PX")]
    stored_focal: Option<f64>,
}

pub fn run(command: &GenerateCommand) -> Result<()> {
    match command {
        GenerateCommand::Database(args) => run_database(args),
        GenerateCommand::Images(args) => {
            render::Scene::build(args.scene, args.num_images, args.seed)
                .and_then(|scene| scene.write(&args.output))
        }
        GenerateCommand::Graph(args) => run_graph(args),
    }
}

/// Overview images of a generated duplicate scene (they link the two camera groups).
const DUPLICATE_OVERVIEW_IMAGES: usize = 4;

fn run_database(args: &GenerateDatabaseArgs) -> Result<()> {
    let spec = synth::SceneSpec {
        num_images: args.num_images,
        num_points: args.num_points,
        view_cone_degrees: args.view_cone_degrees,
        seed: args.seed,
        scene: match args.duplicate_yaw {
            Some(yaw_degrees) => synth::SyntheticScene::Duplicate {
                yaw_degrees,
                overview_images: DUPLICATE_OVERVIEW_IMAGES,
            },
            None => synth::SyntheticScene::Orbit,
        },
        stored_focal: args.stored_focal,
        ..Default::default()
    };
    let gt = synth::generate(&spec, &args.output)?;
    if let Some(dir) = &args.ground_truth {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        synth::write_gt_model(&gt, dir)?;
    }
    Ok(())
}

fn run_graph(args: &GenerateGraphArgs) -> Result<()> {
    let (n, e) = (args.images, args.pairs);
    if e > n * (n - 1) / 2 {
        bail!(
            "--pairs {e} do not fit {n} images (at most {})",
            n * (n - 1) / 2
        );
    }
    let problem = synthetic_graph::generate(n as usize, e as usize, args.arrangement, args.seed);
    std::fs::write(&args.output, graph_file::write(&problem))
        .with_context(|| format!("cannot write graph {}", args.output.display()))
}
