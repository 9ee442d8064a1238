//! The paper's Fig. 4: how far a generated, retargeted and post-processed walk gets compared to
//! the requested distance, `(covered − requested) / requested`, over requested distances from
//! 0.2 to 25 m. Covered = the along-path displacement of the midpoint of the feet from the first
//! to the last stance of the post-processed sequence.

use std::path::{Path, PathBuf};

use kinematics::robot::EndEffector;
use nalgebra::Vector3;
use plotters::prelude::*;
use serde::Serialize;

use crate::geometry::PathFrame;
use crate::sequence::PostProcessedSequence;

/// The requested distances of Fig. 4 (m).
pub const DISTANCES: [f64; 12] = [
    0.2, 0.5, 1.0, 2.0, 3.0, 5.0, 7.5, 10.0, 12.5, 15.0, 20.0, 25.0,
];

/// One point of Fig. 4.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CoverageRow {
    /// Robot name.
    pub robot: String,
    /// Affordance set name.
    pub affordances: String,
    /// Requested distance (m).
    pub requested: f64,
    /// Covered distance after post-processing (m).
    pub covered: f64,
    /// `(covered − requested) / requested`.
    pub relative_error: f64,
    /// Number of stances.
    pub stances: usize,
    /// Post-processing time `[mean µs, coefficient of variation]`, when measured.
    pub post_process_us: Option<[f64; 2]>,
}

impl CoverageRow {
    /// A row from the requested distance and the post-processed sequence.
    pub fn new(
        robot: &str,
        affordances: &str,
        requested: f64,
        sequence: &PostProcessedSequence,
    ) -> Self {
        let covered = covered_distance(sequence);
        Self {
            robot: robot.to_owned(),
            affordances: affordances.to_owned(),
            requested,
            covered,
            relative_error: (covered - requested) / requested,
            stances: sequence.len(),
            post_process_us: None,
        }
    }
}

/// Along-path displacement of the feet midpoint from the first to the last stance (path
/// direction: the mean heading of the contact feet).
pub fn covered_distance(sequence: &PostProcessedSequence) -> f64 {
    let mid = |i: usize| {
        let t = sequence.targets(i);
        0.5 * (t[EndEffector::LeftFoot as usize].translation.vector
            + t[EndEffector::RightFoot as usize].translation.vector)
    };
    let heading: Vector3<f64> = (0..sequence.len())
        .flat_map(|i| {
            [EndEffector::LeftFoot, EndEffector::RightFoot]
                .into_iter()
                .filter(move |&f| sequence.contacts(i)[f as usize])
                .map(move |f| sequence.targets(i)[f as usize].rotation * Vector3::x())
        })
        .sum();
    let path = PathFrame::new(&mid(0), &heading)
        .or_else(|| PathFrame::new(&mid(0), &Vector3::x()))
        .expect("+x is a valid direction");
    path.along(&mid(sequence.len() - 1)) - path.along(&mid(0))
}

/// Why Fig. 4 could not be drawn.
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot draw Fig. 4: {message}")]
pub struct Fig4Error {
    path: PathBuf,
    message: String,
}

/// Draws Fig. 4 as SVG: relative error over requested distance, one series per robot and
/// affordance set.
pub fn write_fig4(path: &Path, rows: &[CoverageRow]) -> Result<(), Fig4Error> {
    draw(path, rows).map_err(|e| Fig4Error {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn draw(path: &Path, rows: &[CoverageRow]) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let (lo, hi) = rows.iter().fold((-0.1f64, 0.1f64), |(lo, hi), r| {
        (lo.min(r.relative_error), hi.max(r.relative_error))
    });
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Fig. 4: (covered − requested) / requested",
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..26.0, (lo - 0.05)..(hi + 0.05))?;
    chart
        .configure_mesh()
        .x_desc("requested distance [m]")
        .y_desc("relative error")
        .draw()?;
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for row in rows {
        let name = format!("{} {}", row.robot, row.affordances);
        match series.iter_mut().find(|(n, _)| *n == name) {
            Some((_, points)) => points.push((row.requested, row.relative_error)),
            None => series.push((name, vec![(row.requested, row.relative_error)])),
        }
    }
    for (k, (name, points)) in series.into_iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        chart.draw_series(
            points
                .into_iter()
                .map(|p| Circle::new(p, 3, color.filled())),
        )?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
