//! The paper's Fig. 6 for one walk: x, y and z over time of the CoM and both soles — target
//! (dashed), controller estimate (solid) and, where known, the simulator's truth (dotted). A
//! dynamic walk adds a row for its balance: the walking pattern's ZMP and DCM against the
//! measured ones, x and y. A walk that holds a hand adds a row for each hand's vertical force:
//! asked by walkd against measured at the wrist.

use std::path::Path;

use nalgebra::Vector3;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Points, TraceSample};

/// The balance of a dynamic walk at one instant (world x, y; m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BalanceSample {
    /// Time since the walk started (s).
    pub t: f64,
    /// The walking pattern's ZMP.
    pub zmp_reference: [f64; 2],
    /// The ZMP from the ankle wrenches (NaN while the feet carry too little).
    pub zmp_measured: [f64; 2],
    /// The walking pattern's DCM.
    pub dcm_reference: [f64; 2],
    /// The DCM of the estimated CoM.
    pub dcm_measured: [f64; 2],
}

/// The vertical force on both hands at one instant (left, right; N): what walkd asked of them
/// (`Telemetry::hand_forces_desired`) and what their wrists measured (the answered sample).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandSample {
    /// Time since the walk started (s).
    pub t: f64,
    /// Asked of each held hand (0: not held).
    pub asked: [f64; 2],
    /// The environment's vertical force on each palm, at its wrist.
    pub measured: [f64; 2],
}

/// Writes Fig. 6 of `trace` as SVG, with the balance row of `balance` and the hands row of
/// `hands` when they have samples (the hands row only when a hand was asked for a force).
pub fn write_fig6(
    file: &Path,
    title: &str,
    trace: &[TraceSample],
    balance: &[BalanceSample],
    hands: &[HandSample],
) -> anyhow::Result<()> {
    draw(file, title, trace, balance, hands)
        .map_err(|e| anyhow::anyhow!("{}: cannot draw Fig. 6: {e}", file.display()))
}

type DrawResult = Result<(), Box<dyn std::error::Error>>;
/// Picks one of the three plotted points.
type PointOf = fn(&Points) -> Vector3<f64>;
/// A panel's area.
type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// One plotted line: its points and its style.
struct Line {
    points: Vec<(f64, f64)>,
    style: Style,
}

/// How a line is drawn, and its legend entry.
#[derive(Clone, Copy)]
struct Style {
    label: &'static str,
    dashed: bool,
    colour: RGBColor,
}

impl Style {
    const fn dashed(label: &'static str, colour: RGBColor) -> Self {
        Self {
            label,
            dashed: true,
            colour,
        }
    }

    const fn solid(label: &'static str, colour: RGBColor) -> Self {
        Self {
            label,
            dashed: false,
            colour,
        }
    }
}

const TARGET: Style = Style::dashed("target", RED);
const CONTROLLER: Style = Style::solid("controller", BLUE);
const SIMULATOR: Style = Style::dashed("simulator", GREEN);
const ZMP_REFERENCE: Style = Style::dashed("ZMP reference", RED);
const ZMP_MEASURED: Style = Style::solid("ZMP measured", BLUE);
const DCM_REFERENCE: Style = Style::dashed("DCM reference", RGBColor(230, 140, 0));
const DCM_MEASURED: Style = Style::solid("DCM measured", MAGENTA);
const FORCE_ASKED: Style = Style::dashed("asked", RED);
const FORCE_MEASURED: Style = Style::solid("measured", BLUE);

fn draw(
    file: &Path,
    title: &str,
    trace: &[TraceSample],
    balance: &[BalanceSample],
    hands: &[HandSample],
) -> DrawResult {
    let hands_held = hands.iter().any(|s| s.asked.iter().any(|f| *f > 0.0));
    let rows = 3 + usize::from(!balance.is_empty()) + usize::from(hands_held);
    let root = SVGBackend::new(file, (1500, 300 * rows as u32)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let end = trace.last().map_or(1.0, |s| s.t.max(1e-3));
    let series: [(&str, PointOf); 3] = [
        ("CoM", |p| p.com),
        ("left foot", |p| p.left_foot),
        ("right foot", |p| p.right_foot),
    ];
    let row_areas = root.split_evenly((rows, 1));
    for (r, row_area) in row_areas.iter().take(3).enumerate() {
        let (name, point) = series[r];
        for (axis, area) in row_area.split_evenly((1, 3)).iter().enumerate() {
            let value = |p: &Points| point(p)[axis];
            let line = |get: &dyn Fn(&TraceSample) -> Option<f64>| -> Vec<(f64, f64)> {
                trace
                    .iter()
                    .filter_map(|s| get(s).map(|v| (s.t, v)))
                    .collect()
            };
            let lines = [
                (TARGET, line(&|s| Some(value(&s.target)))),
                (CONTROLLER, line(&|s| Some(value(&s.controller)))),
                (SIMULATOR, line(&|s| s.sim.as_ref().map(value))),
            ]
            .map(|(style, points)| Line { points, style });
            let caption = format!("{name} {}", ["x", "y", "z"][axis]);
            panel(area, &caption, end, &lines, r == 0 && axis == 0, "m")?;
        }
    }
    if let Some(row_area) = row_areas.get(3).filter(|_| !balance.is_empty()) {
        for (axis, area) in row_area.split_evenly((1, 2)).iter().enumerate() {
            let line = |get: fn(&BalanceSample) -> [f64; 2]| -> Vec<(f64, f64)> {
                balance
                    .iter()
                    .map(|s| (s.t, get(s)[axis]))
                    .filter(|(_, v)| v.is_finite())
                    .collect()
            };
            let lines = [
                (ZMP_REFERENCE, line(|s| s.zmp_reference)),
                (ZMP_MEASURED, line(|s| s.zmp_measured)),
                (DCM_REFERENCE, line(|s| s.dcm_reference)),
                (DCM_MEASURED, line(|s| s.dcm_measured)),
            ]
            .map(|(style, points)| Line { points, style });
            let caption = format!("ZMP and DCM {}", ["x", "y"][axis]);
            panel(area, &caption, end, &lines, axis == 0, "m")?;
        }
    }
    if let Some(row_area) = row_areas.last().filter(|_| hands_held) {
        for (k, area) in row_area.split_evenly((1, 2)).iter().enumerate() {
            let line = |get: fn(&HandSample) -> [f64; 2]| -> Vec<(f64, f64)> {
                hands.iter().map(|s| (s.t, get(s)[k])).collect()
            };
            let lines = [
                (FORCE_ASKED, line(|s| s.asked)),
                (FORCE_MEASURED, line(|s| s.measured)),
            ]
            .map(|(style, points)| Line { points, style });
            let caption = format!("{} hand vertical force", ["left", "right"][k]);
            panel(area, &caption, end, &lines, k == 0, "N")?;
        }
    }
    root.present()?;
    Ok(())
}

/// One panel of `lines` over `0..end` s, values in `unit`, with the legend if `legend`.
fn panel(
    area: &Area,
    caption: &str,
    end: f64,
    lines: &[Line],
    legend: bool,
    unit: &str,
) -> DrawResult {
    let (lo, hi) = lines
        .iter()
        .flat_map(|line| line.points.iter().map(|(_, v)| *v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let margin = ((hi - lo) * 0.1).max(0.005);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 14))
        .margin(6)
        .x_label_area_size(28)
        .y_label_area_size(52)
        .build_cartesian_2d(0.0..end, lo - margin..hi + margin)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc(unit)
        .light_line_style(WHITE)
        .draw()?;
    for line in lines.iter().filter(|line| !line.points.is_empty()) {
        let colour = line.style.colour;
        let style = colour.stroke_width(2);
        let drawn = if line.style.dashed {
            chart.draw_series(DashedLineSeries::new(line.points.clone(), 6, 4, style))?
        } else {
            chart.draw_series(LineSeries::new(line.points.clone(), style))?
        };
        drawn
            .label(line.style.label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], colour));
    }
    if legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace() -> Vec<TraceSample> {
        let points = Points {
            com: Vector3::new(0.0, 0.0, 0.8),
            left_foot: Vector3::new(0.0, 0.1, 0.0),
            right_foot: Vector3::new(0.0, -0.1, 0.0),
        };
        (0..3)
            .map(|i| TraceSample {
                t: f64::from(i),
                stance_index: 0,
                target: points,
                controller: points,
                sim: None,
            })
            .collect()
    }

    /// The SVG of a walk whose right hand was asked for `asked` N.
    fn drawn(asked: f64) -> String {
        let hands: Vec<HandSample> = (0..3)
            .map(|i| HandSample {
                t: f64::from(i),
                asked: [0.0, asked],
                measured: [0.0, 0.9 * asked],
            })
            .collect();
        let file = std::env::temp_dir().join(format!("fig6-{}-{asked}.svg", std::process::id()));
        write_fig6(&file, "walk", &trace(), &[], &hands).unwrap();
        let svg = std::fs::read_to_string(&file).unwrap();
        std::fs::remove_file(&file).unwrap();
        svg
    }

    #[test]
    fn a_walk_that_asks_a_hand_for_a_force_gets_a_row_of_hand_forces() {
        let svg = drawn(95.0);
        assert!(svg.contains("right hand vertical force"), "no hands row");
        assert!(
            svg.contains("\nasked\n") && svg.contains("\nmeasured\n"),
            "no legend"
        );
        assert!(
            !drawn(0.0).contains("hand vertical force"),
            "a row for hands never held"
        );
    }
}
