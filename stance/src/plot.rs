//! The paper's Fig. 3 as SVG: the feet after each pass of Algorithm 1 seen from above (left
//! foot green, right foot blue, contact poses with a red border; held hands as magenta dots,
//! which the hand pass puts on their railing) and a side view of the swing foot heights.
//! Coordinates are along / across the walking path.

use std::path::{Path, PathBuf};

use kinematics::robot::{EndEffector, SoleRectangle};
use nalgebra::Point3;
use plotters::prelude::*;

use crate::environment::Environment;
use crate::geometry::PathFrame;
use crate::params::PostProcessParams;
use crate::passes::{Pass, path_of};
use crate::poses::{FEET, HANDS, PoseSequence};

/// The poses right after one pass.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// The pass that produced the poses.
    pub pass: Pass,
    /// The poses after it.
    pub poses: PoseSequence,
}

/// Why a figure could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot draw the figure: {message}")]
pub struct PlotError {
    path: PathBuf,
    message: String,
}

/// Writes `fig3_top.svg` (one panel per pass) and `fig3_side.svg` into `dir` and returns their
/// paths. `snapshots` are the poses after each pass, in order.
pub fn write_fig3(
    dir: &Path,
    snapshots: &[Snapshot],
    environment: &Environment,
    sole: &SoleRectangle,
    params: &PostProcessParams,
) -> Result<Vec<PathBuf>, PlotError> {
    // The walking path of the result is the one the passes used (see `passes::path_of`).
    let Some(path) = snapshots.last().and_then(|s| path_of(&s.poses)) else {
        return Ok(Vec::new());
    };
    let top = dir.join("fig3_top.svg");
    draw_top(&top, snapshots, &path, sole).map_err(|e| PlotError {
        path: top.clone(),
        message: e.to_string(),
    })?;
    let side = dir.join("fig3_side.svg");
    draw_side(&side, snapshots, &path, environment, params).map_err(|e| PlotError {
        path: side.clone(),
        message: e.to_string(),
    })?;
    Ok(vec![top, side])
}

type DrawResult = Result<(), Box<dyn std::error::Error>>;

/// The sole outline of `foot` in stance `i`, in path coordinates (along, lateral).
fn outline(
    poses: &PoseSequence,
    i: usize,
    foot: EndEffector,
    path: &PathFrame,
    sole: &SoleRectangle,
) -> Vec<(f64, f64)> {
    let (l, w) = (sole.length / 2.0, sole.width / 2.0);
    [(l, w), (-l, w), (-l, -w), (l, -w), (l, w)]
        .iter()
        .map(|&(x, y)| {
            let p = poses.pose(i, foot) * Point3::new(x, y, 0.0);
            (path.along(&p.coords), path.lateral(&p.coords))
        })
        .collect()
}

fn range(values: impl Iterator<Item = f64>, margin: f64) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo.is_finite() {
        lo - margin..hi + margin
    } else {
        -1.0..1.0
    }
}

fn draw_top(
    file: &Path,
    snapshots: &[Snapshot],
    path: &PathFrame,
    sole: &SoleRectangle,
) -> DrawResult {
    let root = SVGBackend::new(file, (1400, 230 * snapshots.len() as u32)).into_drawing_area();
    root.fill(&WHITE)?;
    for (area, snapshot) in root
        .split_evenly((snapshots.len(), 1))
        .iter()
        .zip(snapshots)
    {
        let poses = &snapshot.poses;
        let outlines: Vec<_> = (0..poses.len())
            .flat_map(|i| FEET.map(|foot| (i, foot)))
            .map(|(i, foot)| {
                (
                    poses.in_contact(i, foot),
                    foot,
                    outline(poses, i, foot, path, sole),
                )
            })
            .collect();
        let held: Vec<(f64, f64)> = (0..poses.len())
            .flat_map(|i| HANDS.map(|hand| (i, hand)))
            .filter(|&(i, hand)| poses.in_contact(i, hand))
            .map(|(i, hand)| {
                let p = poses.pose(i, hand).translation.vector;
                (path.along(&p), path.lateral(&p))
            })
            .collect();
        let along = range(
            outlines
                .iter()
                .flat_map(|(_, _, o)| o.iter().map(|p| p.0))
                .chain(held.iter().map(|p| p.0)),
            0.1,
        );
        let lateral = range(
            outlines
                .iter()
                .flat_map(|(_, _, o)| o.iter().map(|p| p.1))
                .chain(held.iter().map(|p| p.1)),
            0.05,
        );
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("after {}", caption(snapshot.pass)),
                ("sans-serif", 16),
            )
            .margin(8)
            .x_label_area_size(24)
            .y_label_area_size(48)
            .build_cartesian_2d(along, lateral)?;
        chart
            .configure_mesh()
            .x_desc("along path [m]")
            .y_desc("lateral [m]")
            .draw()?;
        for (contact, foot, points) in outlines {
            let colour = if foot == EndEffector::LeftFoot {
                GREEN
            } else {
                BLUE
            };
            chart.draw_series(std::iter::once(PathElement::new(
                points.clone(),
                colour.stroke_width(1),
            )))?;
            if contact {
                chart.draw_series(std::iter::once(PathElement::new(
                    points,
                    RED.stroke_width(2),
                )))?;
            }
        }
        chart.draw_series(
            held.into_iter()
                .map(|p| Circle::new(p, 3, MAGENTA.filled())),
        )?;
    }
    root.present()?;
    Ok(())
}

/// One series of the side view: the pass, its colour, (along path, height) points.
type SideSeries = (Pass, RGBColor, Vec<(f64, f64)>);

/// `line 9 of Algorithm 1: limitOrthogonalFeetDistance`, or the name of a pass not in it.
fn caption(pass: Pass) -> String {
    match pass.line() {
        Some(line) => format!("line {line} of Algorithm 1: {}", pass.name()),
        None => pass.name().to_owned(),
    }
}

/// The passes whose swing heights the side view shows: the raw heights on the floor, after the
/// step-size limits, and the result.
const SIDE_VIEW: [(Pass, RGBColor); 3] = [
    (Pass::MoveStancesUp, RGBColor(150, 150, 150)),
    (Pass::LimitToMaxStepSize, RGBColor(230, 140, 0)),
    (Pass::LimitSwingFootHeight, RGBColor(0, 0, 0)),
];

fn draw_side(
    file: &Path,
    snapshots: &[Snapshot],
    path: &PathFrame,
    environment: &Environment,
    params: &PostProcessParams,
) -> DrawResult {
    let series: Vec<SideSeries> = SIDE_VIEW
        .iter()
        .filter_map(|&(pass, colour)| {
            snapshots
                .iter()
                .find(|s| s.pass == pass)
                .map(|s| (pass, colour, &s.poses))
        })
        .map(|(pass, colour, poses)| {
            let points = crate::derived::swing_heights(poses, pass.environment(environment))
                .iter()
                .enumerate()
                .filter_map(|(i, h)| {
                    h.map(|h| {
                        (
                            path.along(&poses.pose(i, h.foot).translation.vector),
                            h.height,
                        )
                    })
                })
                .collect();
            (pass, colour, points)
        })
        .collect();
    let along = range(
        series.iter().flat_map(|(_, _, p)| p.iter().map(|q| q.0)),
        0.1,
    );
    let height = range(
        series
            .iter()
            .flat_map(|(_, _, p)| p.iter().map(|q| q.1))
            .chain([0.0, params.h_max]),
        0.02,
    );
    let root = SVGBackend::new(file, (1400, 420)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "swing-foot height above its surface (single support)",
            ("sans-serif", 16),
        )
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(along.clone(), height)?;
    chart
        .configure_mesh()
        .x_desc("along path [m]")
        .y_desc("height [m]")
        .draw()?;
    for limit in [params.h_min, params.h_max] {
        chart.draw_series(LineSeries::new(
            [(along.start, limit), (along.end, limit)],
            RED.stroke_width(1),
        ))?;
    }
    for (pass, colour, points) in series {
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?
            .label(format!("after {}", caption(pass)))
            .legend(move |(x, y)| Circle::new((x, y), 3, colour.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE)
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
