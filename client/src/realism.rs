//! `walkctl realism`: the realism table of an already trained model against a held-out
//! demonstration folder — the same table `walkctl learn --holdout` prints after training.

use std::path::{Path, PathBuf};

use stance::learned::realism::compare;
use stance::learned::{NgramModel, load_folder};

/// Arguments of `walkctl realism`.
#[derive(Debug, Clone, clap::Args)]
pub struct RealismArgs {
    /// The trained model (e.g. data/models/default-ngram.json).
    #[arg(long, value_name = "MODEL.json")]
    pub model: PathBuf,
    /// The held-out demonstration folder, with a demo.toml (e.g. data/demonstrations/gaitkit).
    #[arg(long, value_name = "DIR")]
    pub holdout: PathBuf,
}

/// Runs `walkctl realism`.
pub fn run(args: &RealismArgs) -> anyhow::Result<()> {
    let model = NgramModel::from_path(&args.model)?;
    print_comparison(&model, &args.holdout)
}

/// Prints the realism table of `model` against the walkers of the held-out folder `dir`: step
/// length and width, step time, cadence, single and double support, SI and normalised by leg
/// length, held-out vs generated with the relative errors (`stance::learned::realism`).
pub fn print_comparison(model: &NgramModel, dir: &Path) -> anyhow::Result<()> {
    let held_out = load_folder(dir)?;
    let names: Vec<&str> = held_out.iter().map(|d| d.name.as_str()).collect();
    let name = format!("held-out {}", names.join(", "));
    print!("{}", compare(model, &name, &held_out)?);
    Ok(())
}
