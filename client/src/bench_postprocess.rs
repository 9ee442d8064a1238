//! `walkctl bench-postprocess`: the paper's Table I protocol — post-processing time for walks of
//! 0.2 to 25 m, 1000 runs each, timed from the raw sequence in memory (`q_S`, contacts,
//! translations; forward kinematics included) to the post-processed sequence.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::builder::RangedU64ValueParser;
use serde::Serialize;
use stance::{AffordanceSet, GenerateOptions, PostProcessedSequence, PostProcessor, generate};

use crate::postprocess::{ParamOverrides, load_robot};

/// Table I of the paper: (length [m], mean [µs], CV).
pub const PAPER_TABLE_I: [(f64, f64, f64); 7] = [
    (0.2, 153.0, 0.19),
    (1.0, 244.0, 0.17),
    (5.0, 674.0, 0.11),
    (10.0, 1185.0, 0.07),
    (15.0, 1672.0, 0.08),
    (20.0, 2187.0, 0.08),
    (25.0, 2681.0, 0.09),
];

/// Arguments of `walkctl bench-postprocess`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchPostprocessArgs {
    /// Robot config (TOML with `[robot]` and `[postprocess]`), e.g. configs/armar4.toml.
    #[arg(long, value_name = "CONFIG")]
    pub robot: PathBuf,
    /// URDF to use instead of the config's `urdf` (required for HRP-4).
    #[arg(long, value_name = "PATH")]
    pub urdf: Option<PathBuf>,
    /// Post-processings per length, 1-10000000.
    #[arg(long, default_value_t = 1000, value_parser = RangedU64ValueParser::<usize>::new().range(1..=10_000_000))]
    pub runs: usize,
    /// Support affordances of the generated walks.
    #[arg(long, default_value = "feet", value_name = "SET")]
    pub affordances: AffordanceSet,
    /// Seed of the generated walks.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print `{"rows":[{"length_m":..,"mean_us":..,"cv":..,"us_per_m":..}, ...]}` instead of a table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub params: ParamOverrides,
}

/// One measured row of Table I.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Row {
    /// Requested length to cover [m] (the raw walk is generated for length / scf).
    pub length_m: f64,
    /// Mean post-processing time [µs].
    pub mean_us: f64,
    /// Coefficient of variation of the time (standard deviation / mean).
    pub cv: f64,
    /// Mean time per metre of requested length [µs/m].
    pub us_per_m: f64,
}

#[derive(Serialize)]
struct Report {
    rows: Vec<Row>,
}

/// Mean and coefficient of variation of `samples`.
fn mean_cv(samples: &[f64]) -> (f64, f64) {
    let n = samples.len() as f64;
    let mean = samples.iter().sum::<f64>() / n;
    let variance = samples.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, variance.sqrt() / mean)
}

/// Runs `walkctl bench-postprocess`.
pub fn run(args: &BenchPostprocessArgs) -> anyhow::Result<()> {
    anyhow::ensure!(args.runs >= 2, "--runs must be at least 2");
    let params = args.params.load(&args.robot)?;
    let robot = load_robot(&args.robot, args.urdf.as_deref())?;
    let mut processor = PostProcessor::new(&robot, params.clone());
    let mut output = PostProcessedSequence::empty();
    let mut samples = vec![0.0; args.runs];
    let mut rows = Vec::new();
    let mut details = Vec::new(); // (stances, median µs) for the table
    for (length, _, _) in PAPER_TABLE_I {
        let options = GenerateOptions {
            distance: length / params.scf,
            affordances: args.affordances,
            seed: args.seed,
        };
        let raw = generate(&robot, &options).with_context(|| format!("generating {length} m"))?;
        processor.process_into(&raw, &mut output)?; // warm-up: grows every buffer once
        for sample in &mut samples {
            let start = Instant::now();
            processor.process_into(&raw, &mut output)?;
            *sample = start.elapsed().as_secs_f64() * 1e6;
        }
        std::hint::black_box(&output);
        let (mean_us, cv) = mean_cv(&samples);
        samples.sort_by(f64::total_cmp);
        details.push((raw.len(), samples[samples.len() / 2]));
        rows.push(Row {
            length_m: length,
            mean_us,
            cv,
            us_per_m: mean_us / length,
        });
    }
    if args.json {
        println!("{}", serde_json::to_string(&Report { rows })?);
        return Ok(());
    }
    println!(
        "Table I: post-processing time, {} ({} runs per length, affordances {}, scf {}, seed {})",
        robot.name, args.runs, args.affordances, params.scf, args.seed
    );
    println!(
        "{:>10} {:>8} {:>11} {:>6} {:>9} {:>11} | {:>15} {:>8} {:>12}",
        "length[m]",
        "stances",
        "mean[µs]",
        "CV",
        "µs/m",
        "median[µs]",
        "paper mean[µs]",
        "paper CV",
        "paper µs/m"
    );
    for ((row, (_, paper_mean, paper_cv)), (n, median)) in
        rows.iter().zip(PAPER_TABLE_I).zip(details)
    {
        println!(
            "{:>10.1} {:>8} {:>11.2} {:>6.3} {:>9.3} {:>11.2} | {:>15.0} {:>8.2} {:>12.0}",
            row.length_m,
            n,
            row.mean_us,
            row.cv,
            row.us_per_m,
            median,
            paper_mean,
            paper_cv,
            paper_mean / row.length_m
        );
    }
    Ok(())
}
