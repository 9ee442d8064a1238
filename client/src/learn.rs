//! `walkctl learn`: train the n-gram stance model on demonstration folders (each with a
//! `demo.toml` manifest) and write it as JSON, report the gait law fitted on the walkers, and
//! optionally realism against a held-out folder.

use std::path::PathBuf;

use anyhow::Context;
use clap::builder::RangedU64ValueParser;
use kinematics::bounds::Range;
use stance::learned::gait_law::{walker_table, walkers_of};
use stance::learned::{
    Demonstration, GaitLaw, NgramModel, TrainOptions, load_folder, segment, taxonomy_label,
};

/// Arguments of `walkctl learn`.
#[derive(Debug, Clone, clap::Args)]
pub struct LearnArgs {
    /// Demonstration folders, each with a demo.toml (e.g. data/demonstrations/gaitalytics).
    #[arg(long, value_name = "DIR", num_args = 1.., required = true)]
    pub demos: Vec<PathBuf>,
    /// Demonstration folders whose level walkers enter only the gait law (step length and
    /// timing over speed), not the n-gram (e.g. data/demonstrations/gaitkit-walkers).
    #[arg(long, value_name = "DIR", num_args = 1..)]
    pub gait_demos: Vec<PathBuf>,
    /// Where to write the model.
    #[arg(short, long, value_name = "MODEL.json")]
    pub output: PathBuf,
    /// Order n of the n-gram, 1-10.
    #[arg(long, default_value_t = 3, value_parser = RangedU64ValueParser::<usize>::new().range(1..=10))]
    pub order: usize,
    /// Absolute discount of the smoothing, 0.01-0.99.
    #[arg(long, default_value_t = 0.75, value_parser = Range::new(0.01, 0.99).parser())]
    pub discount: f64,
    /// Largest number of pose clusters per taxonomy class, 1-1000.
    #[arg(long, default_value_t = 8, value_parser = RangedU64ValueParser::<usize>::new().range(1..=1000))]
    pub max_clusters: usize,
    /// Do not add left-right mirrored copies of the demonstrations.
    #[arg(long)]
    pub no_mirror: bool,
    /// A held-out demonstration folder: print the realism table of generated sequences against
    /// it (as `walkctl realism` does).
    #[arg(long, value_name = "DIR")]
    pub holdout: Option<PathBuf>,
}

/// Runs `walkctl learn`.
pub fn run(args: &LearnArgs) -> anyhow::Result<()> {
    let (demos, gait_demos) = (load_folders(&args.demos)?, load_folders(&args.gait_demos)?);
    let options = TrainOptions {
        order: args.order,
        discount: args.discount,
        max_clusters: args.max_clusters,
        mirror: !args.no_mirror,
        ..TrainOptions::default()
    };
    for demo in &demos {
        let keyframes = segment(demo, &options.segment).keyframes;
        let mut classes: Vec<(String, usize)> = Vec::new();
        for k in &keyframes {
            let label = taxonomy_label(k.contacts);
            match classes.iter_mut().find(|(l, _)| *l == label) {
                Some((_, n)) => *n += 1,
                None => classes.push((label, 1)),
            }
        }
        let classes: Vec<String> = classes.iter().map(|(l, n)| format!("{l} {n}")).collect();
        eprintln!(
            "{}: {} frames at {} Hz, {} stances ({})",
            demo.name,
            demo.len(),
            demo.rate,
            keyframes.len(),
            classes.join(", ")
        );
    }
    let model = NgramModel::train_with_gait_walkers(&demos, &gait_demos, &options)?;
    std::fs::write(&args.output, model.to_json_string() + "\n")
        .with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "{}: order {}, {} tokens, {} contexts, human pelvis height {:.3} m",
        args.output.display(),
        model.order,
        model.tokens.len(),
        model.counts.len(),
        model.human_pelvis_height
    );
    print_gait_law(&model, demos.iter().chain(&gait_demos));
    if let Some(dir) = &args.holdout {
        crate::realism::print_comparison(&model, dir)?;
    }
    Ok(())
}

/// The trials of all the folders `dirs`, in order.
fn load_folders(dirs: &[PathBuf]) -> anyhow::Result<Vec<Demonstration>> {
    let mut demos = Vec::new();
    for dir in dirs {
        demos.extend(load_folder(dir)?);
    }
    Ok(demos)
}

/// Prints the walkers the gait law is fitted on (with the reason for each trial left out) and
/// the law stored in the model, or why the model has none.
fn print_gait_law<'a>(model: &NgramModel, demos: impl Iterator<Item = &'a Demonstration>) {
    println!("gait law walkers (level ground, ≥ 3 complete steps; medians over the steps):");
    let (walkers, left_out) = walkers_of(demos);
    for (name, reason) in &left_out {
        println!("{name}: left out: {reason}");
    }
    print!("{}", walker_table(&walkers));
    match &model.gait_law {
        Some(law) => println!("{law}"),
        None => println!(
            "no gait law stored in the model: {}",
            GaitLaw::fit(&walkers).err().unwrap_or_default()
        ),
    }
}
