//! The check's picture: cameras from above, coloured by group, over the model's points, with
//! the model's links between the groups.

use super::views::Views;
use anyhow::{anyhow, Result};
use nalgebra::Vector3;
use plotters::prelude::*;
use std::path::Path;

/// Points drawn at most (every k-th, so the SVG stays small).
const MAX_POINTS: usize = 4000;

/// One colour per group (a ghost of more than two copies has more), in turn.
const GROUP_COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(230, 85, 13),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(214, 39, 40),
    RGBColor(140, 86, 75),
];

/// The plane "from above": the images' mean up direction (COLMAP's image y points down) is
/// the normal; world x (or z) projected onto the plane is the first axis.
fn top_axes(views: &Views) -> [Vector3<f64>; 2] {
    let up: Vector3<f64> = views
        .views
        .iter()
        .map(|v| -(v.rotation.transpose() * Vector3::y()))
        .sum();
    let up = up.try_normalize(1e-9).unwrap_or(Vector3::z());
    let first = [Vector3::x(), Vector3::z(), Vector3::y()]
        .into_iter()
        .map(|a| a - up * up.dot(&a))
        .find(|a| a.norm() > 0.3)
        .unwrap_or(Vector3::x())
        .normalize();
    [first, up.cross(&first)]
}

/// Writes the top view of `views`, each image coloured by its group in `group` (0, 1, ...:
/// [`super::ModelCheck::groups`]), to `path` (SVG), titled `title`.
pub fn top_view(views: &Views, group: &[usize], title: &str, path: &Path) -> Result<()> {
    let axes = top_axes(views);
    let flat = |x: &Vector3<f64>| (axes[0].dot(x), axes[1].dot(x));
    let centres: Vec<(f64, f64)> = views.views.iter().map(|v| flat(&v.centre)).collect();
    let step = views.points.len().div_ceil(MAX_POINTS).max(1);
    let points: Vec<(f64, f64)> = views.points.iter().step_by(step).map(flat).collect();
    // Frame the cameras and the central 90% of the points.
    let mut xs: Vec<f64> = centres.iter().map(|c| c.0).collect();
    let mut ys: Vec<f64> = centres.iter().map(|c| c.1).collect();
    let mut px: Vec<f64> = points.iter().map(|p| p.0).collect();
    let mut py: Vec<f64> = points.iter().map(|p| p.1).collect();
    for (all, some) in [(&mut xs, &mut px), (&mut ys, &mut py)] {
        some.sort_by(f64::total_cmp);
        if !some.is_empty() {
            all.push(some[some.len() / 20]);
            all.push(some[some.len() * 19 / 20]);
        }
    }
    let range = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |r, x| (r.0.min(*x), r.1.max(*x)));
        let pad = ((hi - lo) * 0.08).max(1e-6);
        (lo - pad, hi + pad)
    };
    let ((x0, x1), (y0, y1)) = (range(&xs), range(&ys));
    let err = |e: &dyn std::fmt::Debug| anyhow!("cannot draw {}: {e:?}", path.display());
    let root = SVGBackend::new(path, (800, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(15)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(&e))?;
    let grey = RGBColor(190, 190, 190);
    chart
        .draw_series(
            points
                .iter()
                .filter(|p| p.0 > x0 && p.0 < x1 && p.1 > y0 && p.1 < y1)
                .map(|p| Circle::new(*p, 1, grey.filled())),
        )
        .map_err(|e| err(&e))?;
    let arrow = 0.04 * (x1 - x0).max(y1 - y0);
    for k in 0..=group.iter().copied().max().unwrap_or(0) {
        let colour = GROUP_COLOURS[k % GROUP_COLOURS.len()];
        let members: Vec<usize> = (0..group.len()).filter(|&v| group[v] == k).collect();
        let ends = members.iter().map(|&v| {
            let dir = views.views[v].rotation.transpose() * Vector3::z();
            let (dx, dy) = (axes[0].dot(&dir), axes[1].dot(&dir));
            let norm = dx.hypot(dy).max(1e-9);
            let c = centres[v];
            PathElement::new(
                [c, (c.0 + arrow * dx / norm, c.1 + arrow * dy / norm)],
                colour.stroke_width(2),
            )
        });
        chart.draw_series(ends).map_err(|e| err(&e))?;
        chart
            .draw_series(
                members
                    .iter()
                    .map(|&v| Circle::new(centres[v], 5, colour.filled())),
            )
            .map_err(|e| err(&e))?
            .label(format!("group {} ({} images)", k + 1, members.len()))
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}
