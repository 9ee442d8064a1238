//! `walkctl bench-coverage`: the paper's Fig. 4 — for requested distances from 0.2 to 25 m,
//! generate with the learned model (for distance / scf), retarget, post-process and compare the
//! covered distance with the requested one. With `--runs N` each post-processing is also timed
//! N times (Table I of the paper on the learned sequences).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::builder::RangedU64ValueParser;
use stance::learned::coverage::{CoverageRow, DISTANCES, write_fig4};
use stance::learned::{LearnedOptions, NgramModel, Search, generate_learned};
use stance::{AffordanceSet, PostProcessor};

use crate::postprocess::{ParamOverrides, load_robot};

/// Arguments of `walkctl bench-coverage`.
#[derive(Debug, Clone, clap::Args)]
pub struct BenchCoverageArgs {
    /// Robot config (TOML with `[robot]` and `[postprocess]`), e.g. configs/armar4.toml.
    #[arg(long, value_name = "CONFIG")]
    pub robot: PathBuf,
    /// URDF to use instead of the config's `urdf` (required for HRP-4).
    #[arg(long, value_name = "PATH")]
    pub urdf: Option<PathBuf>,
    /// Trained n-gram model.
    #[arg(
        long,
        default_value = "data/models/default-ngram.json",
        value_name = "MODEL.json"
    )]
    pub model: PathBuf,
    /// Sampled sequences per distance and affordance set (seeds 0..N); 0 = the most probable
    /// sequence (beam search) only.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=100_000))]
    pub samples: u64,
    /// Time every post-processing this many times (0 = no timing), at most 100000.
    #[arg(long, default_value_t = 0, value_parser = RangedU64ValueParser::<usize>::new().range(0..=100_000))]
    pub runs: usize,
    /// Write the figure as SVG.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Print the rows as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub params: ParamOverrides,
}

/// Runs `walkctl bench-coverage`.
pub fn run(args: &BenchCoverageArgs) -> anyhow::Result<()> {
    let params = args.params.load(&args.robot)?;
    let robot = load_robot(&args.robot, args.urdf.as_deref())?;
    let model = NgramModel::from_path(&args.model)?;
    let searches: Vec<Search> = if args.samples == 0 {
        vec![Search::Beam(8)]
    } else {
        (0..args.samples).map(Search::Sample).collect()
    };
    let mut processor = PostProcessor::new(&robot, params.clone());
    let mut rows = Vec::new();
    for affordances in AffordanceSet::ALL {
        for &requested in &DISTANCES {
            for &search in &searches {
                let options = LearnedOptions {
                    distance: requested / params.scf,
                    affordances,
                    railing: None,
                    search,
                    speed: None,
                };
                let raw = generate_learned(&robot, &model, &options)
                    .with_context(|| format!("{requested} m, {affordances}, {search:?}"))?
                    .raw;
                let post = processor
                    .process(&raw)
                    .with_context(|| format!("post-processing {requested} m, {affordances}"))?;
                let mut row = CoverageRow::new(&robot.name, affordances.name(), requested, &post);
                row.post_process_us = time_post_processing(&mut processor, &raw, args.runs)?;
                rows.push(row);
            }
        }
    }
    if args.json {
        println!("{}", serde_json::json!({ "rows": rows }));
    } else {
        println!(
            "robot {} (scf {}), model {}",
            robot.name,
            params.scf,
            args.model.display()
        );
        println!(
            "{:>16} {:>10} {:>10} {:>10} {:>8} {:>10} {:>6}",
            "affordances", "requested", "covered", "rel.error", "stances", "post [us]", "cv"
        );
        for r in &rows {
            let [mean, cv] = r.post_process_us.unwrap_or([f64::NAN; 2]);
            println!(
                "{:>16} {:>10.2} {:>10.3} {:>10.3} {:>8} {:>10.1} {:>6.2}",
                r.affordances, r.requested, r.covered, r.relative_error, r.stances, mean, cv
            );
        }
    }
    if let Some(path) = &args.plot {
        write_fig4(path, &rows)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// Mean (µs) and coefficient of variation of `runs` post-processings of `raw`.
fn time_post_processing(
    processor: &mut PostProcessor<'_>,
    raw: &stance::RawSequence,
    runs: usize,
) -> anyhow::Result<Option<[f64; 2]>> {
    if runs == 0 {
        return Ok(None);
    }
    let mut out = stance::PostProcessedSequence::empty();
    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        let start = Instant::now();
        processor.process_into(raw, &mut out)?;
        times.push(start.elapsed().as_secs_f64() * 1e6);
    }
    let mean = times.iter().sum::<f64>() / runs as f64;
    let sd = (times.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / runs as f64).sqrt();
    Ok(Some([mean, sd / mean]))
}
