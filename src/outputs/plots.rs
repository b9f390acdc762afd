//! `--plots DIR`: the selection curve (the paper's Figure 3) and COLMAP-style match matrix, as SVG.

use crate::selection::pipeline::Plan;
use anyhow::{anyhow, Context, Result};
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Images per axis above which the match matrix bins images, to keep the SVG small.
const MAX_CELLS: usize = 600;

/// (F, fraction of the network's images selected, fraction of its pairs selected).
pub type Point = (u64, [f64; 2]);

/// Writes `selection_curve.svg` and `match_matrix.svg` into `dir` (created if missing) and
/// returns their paths. Draws what the plan recorded; the curve past the chosen F is there when
/// the pipeline ran with [`CURVE_FACTOR`].
pub fn write(plan: &Plan, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let curve_path = dir.join("selection_curve.svg");
    selection_curve(&curve_points(plan), plan, &curve_path)?;
    let matrix_path = dir.join("match_matrix.svg");
    match_matrix(plan, &matrix_path)?;
    Ok(vec![curve_path, matrix_path])
}

/// How far past the chosen F the selection curve goes: to show what more flow would buy.
pub const CURVE_FACTOR: u64 = 4;

/// The curve for F = 1, 2, ... up to [`CURVE_FACTOR`] times the chosen F, no further than the
/// flow selecting every pair, as fractions of the network's images and pairs.
pub fn curve_points(plan: &Plan) -> Vec<Point> {
    let problem = &plan.network.problem;
    let images = problem.image_costs.len().max(1) as f64;
    let pairs = problem.pairs.len().max(1) as f64;
    plan.search
        .curve_to(problem, CURVE_FACTOR)
        .iter()
        .map(|p| {
            (
                p.flow,
                [
                    p.images_selected as f64 / images,
                    p.pairs_selected as f64 / pairs,
                ],
            )
        })
        .collect()
}

fn plot_error<E: std::fmt::Debug>(path: &Path) -> impl FnOnce(E) -> anyhow::Error + '_ {
    move |e| anyhow!("cannot draw {}: {e:?}", path.display())
}

fn selection_curve(points: &[Point], plan: &Plan, path: &Path) -> Result<()> {
    let root = SVGBackend::new(path, (800, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error(path))?;
    let chosen = plan.search.selection.flow.max(1) as f64;
    let x_max = points.last().map_or(2.0, |p| p.0 as f64).max(chosen * 1.5);
    let mut chart = ChartBuilder::on(&root)
        .caption("Selection against total flow F", ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d((1f64..x_max).log_scale(), 0f64..1.05f64)
        .map_err(plot_error(path))?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .x_desc("flow F (log scale)")
        .y_desc("fraction selected")
        .draw()
        .map_err(plot_error(path))?;
    for (k, (label, color)) in [("images", BLUE), ("pairs", RED)].into_iter().enumerate() {
        let line = points.iter().map(|p| (p.0 as f64, p.1[k]));
        chart
            .draw_series(LineSeries::new(line, color.stroke_width(2)))
            .map_err(plot_error(path))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
    }
    let marker = if plan.search.capped {
        format!("F = {} (capped: full graph)", plan.search.selection.flow)
    } else {
        format!("chosen F = {}", plan.search.selection.flow)
    };
    chart
        .draw_series(DashedLineSeries::new(
            [(chosen, 0.0), (chosen, 1.05)],
            6,
            4,
            BLACK.into(),
        ))
        .map_err(plot_error(path))?
        .label(marker)
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(plot_error(path))?;
    root.present().map_err(plot_error(path))
}

/// What one image pair is in the match matrix; later variants win when images are binned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Cell {
    /// Verified, but with too few inliers to be a view-graph edge: left alone.
    Weak,
    Removed,
    Kept,
}

const CELLS: [(Cell, RGBColor, &str); 3] = [
    (Cell::Kept, RGBColor(31, 119, 180), "kept"),
    (
        Cell::Removed,
        RGBColor(230, 85, 13),
        "removed by the selection",
    ),
    (
        Cell::Weak,
        RGBColor(189, 189, 189),
        "too few inliers (left alone)",
    ),
];

fn match_matrix(plan: &Plan, path: &Path) -> Result<()> {
    let mut ids: Vec<u32> = plan.images.iter().map(|im| im.image_id).collect();
    ids.sort_unstable();
    let n = ids.len().max(1);
    let bins = n.min(MAX_CELLS);
    let bin = |id: u32| ids.binary_search(&id).map_or(0, |k| k * bins / n);
    // Ordered, so the SVG is the same file on every run.
    let mut cells: BTreeMap<(usize, usize), Cell> = BTreeMap::new();
    let mut mark = |a: u32, b: u32, cell: Cell| {
        let (x, y) = (bin(a), bin(b));
        for key in [(x, y), (y, x)] {
            let c = cells.entry(key).or_insert(cell);
            *c = (*c).max(cell);
        }
    };
    for p in &plan.pairs {
        mark(p.image_id1, p.image_id2, Cell::Weak);
    }
    for (e, &kept) in plan.graph.edges.iter().zip(&plan.search.selection.pairs) {
        let (a, b) = (
            plan.graph.image_ids[e.i as usize],
            plan.graph.image_ids[e.j as usize],
        );
        mark(a, b, if kept { Cell::Kept } else { Cell::Removed });
    }

    let root = SVGBackend::new(path, (960, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error(path))?;
    let (matrix, legend) = root.split_horizontally(700);
    let caption = if bins < n {
        format!("Match matrix ({n} images in {bins} bins, by image_id)")
    } else {
        format!("Match matrix ({n} images, by image_id)")
    };
    let b = bins as f64;
    let mut chart = ChartBuilder::on(&matrix)
        .caption(caption, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(0f64..b, b..0f64)
        .map_err(plot_error(path))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(if bins < n { "image bin" } else { "image index" })
        .y_desc(if bins < n { "image bin" } else { "image index" })
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .draw()
        .map_err(plot_error(path))?;
    for (kind, color, _) in CELLS {
        chart
            .draw_series(
                cells
                    .iter()
                    .filter(|(_, &c)| c == kind)
                    .map(|(&(x, y), _)| {
                        let (x, y) = (x as f64, y as f64);
                        Rectangle::new([(x, y), (x + 1.0, y + 1.0)], color.filled())
                    }),
            )
            .map_err(plot_error(path))?;
    }
    let entries = CELLS
        .iter()
        .map(|&(_, color, label)| (color.filled(), label))
        .chain([(BLACK.stroke_width(1), "never matched")]);
    for (k, (style, label)) in entries.enumerate() {
        let y = 60 + 28 * k as i32;
        legend
            .draw(&Rectangle::new([(5, y), (21, y + 16)], style))
            .map_err(plot_error(path))?;
        legend
            .draw(&Text::new(label, (28, y + 2), ("sans-serif", 14)))
            .map_err(plot_error(path))?;
    }
    root.present().map_err(plot_error(path))
}
