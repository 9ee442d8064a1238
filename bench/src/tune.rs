//! `walk-tune`: the fastest dynamic gait a robot walks without a fall, searched under MuJoCo.
//!
//! A derived config (`walkctl init-robot`) scales JVRC-1's step timing and length to the robot
//! by dynamic similarity; whether the robot walks them is a question for the physics. The tuner
//! asks it over the two parameters that set the speed, each as a factor on the config's values:
//! - **timing**: `[gait.dynamic] single_support_s` and `double_support_s`, scaled together;
//! - **step length**: `[postprocess.dynamic] s_max` and `scf`, scaled together (scf maps the
//!   generated stride onto s_max), with `[controller] max_step_m` raised to fit.
//!
//! For each timing factor, slowest first, it walks the step factors from the longest down and
//! keeps the first that walks every cell (affordance sets × distances × seeds) `done`: a longer
//! step that fails is not retried with a shorter timing. Of those, the fastest by mean speed
//! wins. Every setting tried is reported; `--write` puts the winner into the config file in place
//! (the keys' lines are rewritten, the rest of the file is kept byte for byte).

use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, bail};
use daemon::controller::{ControllerConfig, GaitConfig};
use kinematics::ConfigFile;
use kinematics::bounds::Range;
use serde::Serialize;
use stance::{Gait, PostProcessParams};

use crate::matrix::{self, MatrixArgs};

/// Arguments of `walk-tune`.
#[derive(Debug, clap::Parser)]
#[command(
    name = "walk-tune",
    version,
    about = "Search the dynamic gait's step timing and step length under MuJoCo (in process) for \
             the fastest setting that walks every affordance set, distance and seed without a fall"
)]
pub struct TuneArgs {
    /// The walks of each setting, and the robot (its config is the starting point).
    #[command(flatten)]
    pub matrix: MatrixArgs,
    /// Factors on the config's single- and double-support times to try (each 0.3-3).
    #[arg(long, value_delimiter = ',', default_value = "0.8,0.9,1,1.1,1.2",
          value_parser = Range::new(0.3, 3.0).parser())]
    pub timing_scales: Vec<f64>,
    /// Factors on the config's dynamic s_max and scf to try (each 0.3-3).
    #[arg(long, value_delimiter = ',', default_value = "0.6,0.7,0.8,0.9,1,1.1,1.2",
          value_parser = Range::new(0.3, 3.0).parser())]
    pub step_scales: Vec<f64>,
    /// Rewrite the winning values into the config file (`--robot`) in place.
    #[arg(long)]
    pub write: bool,
}

/// The config values the tuner scales (its starting point).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SpeedKeys {
    /// `[gait.dynamic] single_support_s` (s).
    pub single_support_s: f64,
    /// `[gait.dynamic] double_support_s` (s).
    pub double_support_s: f64,
    /// `[postprocess.dynamic] s_max` (m).
    pub s_max: f64,
    /// `[postprocess.dynamic] scf`.
    pub scf: f64,
    /// `[controller] max_step_m` (m).
    pub max_step_m: f64,
}

/// The margin kept between the longest planned step and the controller's refusal bound (m).
const MAX_STEP_MARGIN_M: f64 = 0.02;

impl SpeedKeys {
    /// The effective values of `file` (its own, or the parsers' defaults).
    pub fn of(file: &ConfigFile) -> anyhow::Result<Self> {
        let gaits = GaitConfig::from_config(file)?;
        let dynamic = gaits
            .dynamic()
            .map_err(|reason| anyhow::anyhow!("{reason}"))?;
        let params = PostProcessParams::from_config_for(file, Gait::Dynamic)?;
        let controller = ControllerConfig::from_config(file)?;
        Ok(Self {
            single_support_s: dynamic.single_support_s,
            double_support_s: dynamic.double_support_s,
            s_max: params.s_max,
            scf: params.scf,
            max_step_m: controller.max_step_m,
        })
    }

    /// These values with the timing scaled by `timing` and the step by `step`, rounded to what
    /// a config states (ms, mm, 1e-3).
    pub fn scaled(&self, timing: f64, step: f64) -> Self {
        let round = |value: f64| (value * 1000.0).round() / 1000.0;
        let s_max = round(self.s_max * step);
        Self {
            single_support_s: round(self.single_support_s * timing),
            double_support_s: round(self.double_support_s * timing),
            s_max,
            scf: round(self.scf * step),
            max_step_m: self.max_step_m.max(round(s_max + MAX_STEP_MARGIN_M)),
        }
    }

    /// The `section.key=value` assignments that put these values into a config.
    pub fn assignments(&self) -> [(&'static str, &'static str, f64); 5] {
        [
            ("gait.dynamic", "single_support_s", self.single_support_s),
            ("gait.dynamic", "double_support_s", self.double_support_s),
            ("postprocess.dynamic", "s_max", self.s_max),
            ("postprocess.dynamic", "scf", self.scf),
            ("controller", "max_step_m", self.max_step_m),
        ]
    }
}

/// One setting tried.
#[derive(Clone, Debug, Serialize)]
pub struct Trial {
    /// Timing and step factors.
    pub timing_scale: f64,
    pub step_scale: f64,
    /// The values walked.
    pub keys: SpeedKeys,
    /// Walks `done` without a fall, of all.
    pub done: usize,
    pub runs: usize,
    /// Mean and smallest speed of the walks (m/s; `None` if one never stepped).
    pub speed_mean_m_s: Option<f64>,
    pub speed_min_m_s: Option<f64>,
}

impl Trial {
    fn walks_everything(&self) -> bool {
        self.done == self.runs
    }
}

/// What the search found.
#[derive(Clone, Debug, Serialize)]
pub struct TuneReport {
    /// The config's own values.
    pub start: SpeedKeys,
    /// Every setting walked, in order.
    pub trials: Vec<Trial>,
    /// The fastest setting that walked everything (an index into `trials`).
    pub best: Option<usize>,
}

/// Runs `walk-tune`: 0 with a setting that walks everything, 1 without, 2 on bad input.
pub fn main(args: &TuneArgs) -> ExitCode {
    match run(args) {
        Ok(report) if report.best.is_some() => ExitCode::SUCCESS,
        Ok(_) => {
            eprintln!("walk-tune: no setting tried walked every cell without a fall");
            ExitCode::from(1)
        }
        Err(error) => {
            eprintln!("walk-tune: {error:#}");
            ExitCode::from(2)
        }
    }
}

fn run(args: &TuneArgs) -> anyhow::Result<TuneReport> {
    if args.matrix.gait == Some(Gait::Static) {
        bail!("--gait static: walk-tune tunes the dynamic gait's speed");
    }
    if !args.matrix.overrides.is_empty() {
        bail!("--set: walk-tune sets the speed keys itself; edit the config for the others");
    }
    let file = ConfigFile::load(&args.matrix.robot)?;
    let start = SpeedKeys::of(&file)?;
    let mut timings = args.timing_scales.clone();
    timings.sort_by(|a, b| b.total_cmp(a));
    let mut steps = args.step_scales.clone();
    steps.sort_by(|a, b| b.total_cmp(a));
    let mut trials = Vec::new();
    for &timing in &timings {
        for &step in &steps {
            let keys = start.scaled(timing, step);
            let trial = walk(args, &file, timing, step, keys)?;
            eprintln!("{}", describe(&trial));
            let walked = trial.walks_everything();
            trials.push(trial);
            if walked {
                break;
            }
        }
    }
    let best = trials
        .iter()
        .enumerate()
        .filter(|(_, t)| t.walks_everything())
        .max_by(|(_, a), (_, b)| {
            a.speed_mean_m_s
                .unwrap_or(0.0)
                .total_cmp(&b.speed_mean_m_s.unwrap_or(0.0))
        })
        .map(|(i, _)| i);
    let report = TuneReport {
        start,
        trials,
        best,
    };
    if args.matrix.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", table(&report));
    }
    if let (Some(best), true) = (best, args.write) {
        write_keys(&args.matrix.robot, &report.trials[best].keys)?;
        eprintln!(
            "walk-tune: wrote the winning values into {}",
            args.matrix.robot.display()
        );
    }
    Ok(report)
}

/// Walks the matrix of `args` with `keys` in place of the config's.
fn walk(
    args: &TuneArgs,
    file: &ConfigFile,
    timing_scale: f64,
    step_scale: f64,
    keys: SpeedKeys,
) -> anyhow::Result<Trial> {
    let mut config = file.clone();
    for (section, key, value) in keys.assignments() {
        config.set(&format!("{section}.{key}={value}"))?;
    }
    let report = matrix::walk_matrix(&config, &args.matrix, Gait::Dynamic)?;
    let speeds: Vec<f64> = report
        .runs
        .iter()
        .filter_map(|r| r.record.speed_m_s)
        .collect();
    let all_stepped = speeds.len() == report.runs.len() && !speeds.is_empty();
    Ok(Trial {
        timing_scale,
        step_scale,
        keys,
        done: report.done,
        runs: report.runs.len(),
        speed_mean_m_s: all_stepped.then(|| speeds.iter().sum::<f64>() / speeds.len() as f64),
        speed_min_m_s: all_stepped.then(|| speeds.iter().copied().fold(f64::INFINITY, f64::min)),
    })
}

fn describe(trial: &Trial) -> String {
    let k = &trial.keys;
    format!(
        "timing ×{:.2} (single {:.3} s, double {:.3} s), step ×{:.2} (s_max {:.3} m, scf {:.3}): \
         {}/{} done, speed mean {} min {}",
        trial.timing_scale,
        k.single_support_s,
        k.double_support_s,
        trial.step_scale,
        k.s_max,
        k.scf,
        trial.done,
        trial.runs,
        client::evaluate::speed_cell(trial.speed_mean_m_s),
        client::evaluate::speed_cell(trial.speed_min_m_s),
    )
}

fn table(report: &TuneReport) -> String {
    let mut out = String::from("settings tried:\n");
    for (i, trial) in report.trials.iter().enumerate() {
        let mark = if Some(i) == report.best {
            "best"
        } else {
            "    "
        };
        let _ = writeln!(out, "{mark} {}", describe(trial));
    }
    if let Some(best) = report.best {
        out.push_str("\nthe fastest setting that walked everything:\n");
        let mut section = "";
        for (s, key, value) in report.trials[best].keys.assignments() {
            if s != section {
                let _ = writeln!(out, "[{s}]");
                section = s;
            }
            let _ = writeln!(out, "{key} = {value}");
        }
    }
    out
}

/// Rewrites the five keys' lines of the config file at `path` in place; a key missing from its
/// table is added right after the table's header, a missing table at the end.
fn write_keys(path: &Path, keys: &SpeedKeys) -> anyhow::Result<()> {
    let mut text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    for (section, key, value) in keys.assignments() {
        text = set_line(&text, section, key, value);
    }
    // What was written must still be a valid config with those values.
    let written = ConfigFile::parse(&text, path)?;
    if SpeedKeys::of(&written)? != *keys {
        bail!(
            "rewriting {} did not give the tuned values; it was left as it was",
            path.display()
        );
    }
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// `text` with `key = value` in `[section]`: the key's line replaced (its comment becomes
/// `# walk-tune`), or added after the header, or the table appended.
fn set_line(text: &str, section: &str, key: &str, value: f64) -> String {
    let line = format!("{key} = {value}  # walk-tune");
    let header = format!("[{section}]");
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    match lines.iter().position(|l| l.trim() == header) {
        None => lines.extend([String::new(), header, line]),
        Some(start) => {
            let end = lines[start + 1..]
                .iter()
                .position(|l| l.trim_start().starts_with('['))
                .map_or(lines.len(), |i| start + 1 + i);
            let names_key = |l: &String| {
                let t = l.trim_start();
                t.contains('=') && t.split('=').next().unwrap_or("").trim() == key
            };
            match (start + 1..end).find(|&i| names_key(&lines[i])) {
                Some(i) => lines[i] = line,
                None => lines.insert(start + 1, line),
            }
        }
    }
    let mut joined = lines.join("\n");
    joined.push('\n');
    joined
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[postprocess]\ns_max = 0.24 # static\n\n[postprocess.dynamic]\n\
                        s_max = 0.48  # comment\nscf = 0.46\n\n[controller]\ncom_weight = 10.0\n";

    #[test]
    fn a_key_line_is_replaced_in_its_own_table_only() {
        let text = set_line(TEXT, "postprocess.dynamic", "s_max", 0.4);
        assert!(
            text.contains("[postprocess]\ns_max = 0.24 # static\n"),
            "{text}"
        );
        assert!(
            text.contains("[postprocess.dynamic]\ns_max = 0.4  # walk-tune\nscf = 0.46\n"),
            "{text}"
        );
    }

    #[test]
    fn a_missing_key_goes_under_its_header_and_a_missing_table_at_the_end() {
        let text = set_line(TEXT, "controller", "max_step_m", 0.5);
        assert!(
            text.contains("[controller]\nmax_step_m = 0.5  # walk-tune\ncom_weight = 10.0\n"),
            "{text}"
        );
        let text = set_line(TEXT, "gait.dynamic", "single_support_s", 0.5);
        assert!(
            text.ends_with("\n[gait.dynamic]\nsingle_support_s = 0.5  # walk-tune\n"),
            "{text}"
        );
        let text = set_line(TEXT, "postprocess", "h_min", 0.02);
        assert!(
            text.starts_with("[postprocess]\nh_min = 0.02  # walk-tune\ns_max = 0.24"),
            "{text}"
        );
    }

    #[test]
    fn scaling_keeps_the_step_inside_the_controllers_bound() {
        let start = SpeedKeys {
            single_support_s: 0.55,
            double_support_s: 0.25,
            s_max: 0.48,
            scf: 0.46,
            max_step_m: 0.5,
        };
        let longer = start.scaled(0.9, 1.2);
        assert_eq!(
            (longer.single_support_s, longer.double_support_s),
            (0.495, 0.225)
        );
        assert_eq!((longer.s_max, longer.scf), (0.576, 0.552));
        assert!((longer.max_step_m - 0.596).abs() < 1e-12);
        assert_eq!(start.scaled(1.0, 0.5).max_step_m, 0.5, "never lowered");
    }
}
