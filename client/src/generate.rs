//! `walkctl generate`: a human-like, impeded raw stance sequence for a robot, from the learned
//! n-gram model (`--model`) or the synthetic generator (`stance::learned::source`).

use std::path::PathBuf;

use anyhow::{Context, anyhow};
use kinematics::ConfigFile;
use kinematics::bounds::Range;
use stance::learned::{SourceArgs, SpeedRequest};
use stance::{AffordanceSet, Gait, GenerateOptions, Scene};

use crate::args::{DISTANCE_M, SPEED_M_S};
use crate::pace::walking_speed;
use crate::postprocess::{ParamOverrides, load_robot};

/// Arguments of `walkctl generate`.
#[derive(Debug, Clone, clap::Args)]
pub struct GenerateArgs {
    /// Robot config (TOML with `[robot]` and `[postprocess]`), e.g. configs/armar4.toml.
    #[arg(long, value_name = "CONFIG")]
    pub robot: PathBuf,
    /// URDF to use instead of the config's `urdf` (required for HRP-4).
    #[arg(long, value_name = "PATH")]
    pub urdf: Option<PathBuf>,
    /// Distance the post-processed walk should cover [m]; the raw sequence is generated for
    /// D / scf (the paper's rule), with scf from `[postprocess]` or `--scf`.
    /// Through a `--scene`: its path's first D m, at most its length (default the whole path).
    #[arg(long, value_name = "D", value_parser = DISTANCE_M.parser(), required_unless_present = "scene")]
    pub distance: Option<f64>,
    /// Walk through this scene (docs/scenes.md) from its start towards its goal (the whole path
    /// or its first `--distance` metres), and the raw sequence carries the scene's surfaces and
    /// railings (in the walk's frame, starting at the origin) for `walkctl postprocess` to put
    /// the walk and its held hands onto. A held hand needs a scene with a railing.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Generate exactly D metres (no division by scf).
    #[arg(long)]
    pub raw_distance: bool,
    /// Support affordances: feet, feet+left-hand or feet+right-hand (a railing along the path).
    #[arg(long, default_value = "feet", value_name = "SET")]
    pub affordances: AffordanceSet,
    /// Part of the (post-processed) path where the railing may be held, `FROM:TO` in metres;
    /// scaled by 1 / scf like the distance. Default: the whole walk.
    #[arg(long, value_name = "FROM:TO", value_parser = parse_interval)]
    pub railing: Option<[f64; 2]>,
    /// Seed of the deterministic random source.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Walking speed to pace the walk for (m/s, 0.01-3, after post-processing): step length and
    /// stance durations from the model's gait law (docs/learning.md). Needs --model.
    #[arg(long, value_name = "V", value_parser = SPEED_M_S.parser(), requires = "model")]
    pub speed: Option<f64>,
    /// Where to write the raw stance file.
    #[arg(short, long, value_name = "RAW.json")]
    pub output: PathBuf,
    #[command(flatten)]
    pub params: ParamOverrides,
    #[command(flatten)]
    pub source: SourceArgs,
}

/// `FROM:TO`, each a point of the path: in [0, the longest walk].
fn parse_interval(text: &str) -> Result<[f64; 2], String> {
    let (from, to) = text.split_once(':').ok_or("expected FROM:TO, e.g. 0:2.5")?;
    let parse = Range::new(0.0, DISTANCE_M.max).parser();
    let point = |s: &str| parse(s).map_err(|e| format!("`{s}`: {e}"));
    Ok([point(from)?, point(to)?])
}

/// Runs `walkctl generate`.
pub fn run(args: &GenerateArgs) -> anyhow::Result<()> {
    // The gait only picks the limits here (`scf`, and with --speed the timing limits), but
    // a walk the robot cannot make is refused now, before anything is written, rather than by
    // walkd.
    let file = ConfigFile::load(&args.robot)?;
    let gait = Gait::for_walk(args.params.gait, &file)?;
    let speed = walking_speed(args.speed, &file, gait)?;
    let robot = load_robot(&args.robot, args.urdf.as_deref())?;
    let scf = args.params.load(&args.robot)?.scf;
    let scale = if args.raw_distance { 1.0 } else { 1.0 / scf };
    let scene = args.scene.as_deref().map(Scene::from_path).transpose()?;
    let walk_distance = match &scene {
        Some(scene) => scene.walk_length(args.distance).context("--distance")?,
        None => args
            .distance
            .expect("clap requires --distance without --scene"),
    };
    let distance = walk_distance * scale;
    let railing = args
        .railing
        .unwrap_or([0.0, walk_distance])
        .map(|s| s * scale);
    let options = GenerateOptions {
        distance,
        affordances: args.affordances,
        seed: args.seed,
    };
    let sourced = args.source.load()?.generate(
        &robot,
        &options,
        Some(railing),
        speed.map(|speed| SpeedRequest { speed, scf }),
    )?;
    if let Some(gait) = &sourced.gait {
        eprintln!("{}", gait.describe());
    }
    if let Some([position, orientation]) = sourced.largest_ik_error {
        eprintln!(
            "retargeted {} stances: largest IK error {position:.1e} m, {orientation:.1e} rad",
            sourced.raw.len()
        );
    }
    let raw = match &scene {
        Some(scene) => sourced
            .raw
            .in_environment(scene.walk_environment())
            .map_err(|refusal| {
                anyhow!(
                    "scene \"{}\": {refusal}; use --affordances feet or a scene with a \
                     [[railing]]",
                    scene.name
                )
            })?,
        None => sourced.raw,
    };
    std::fs::write(&args.output, raw.to_json_string())
        .with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "{}: {} stances, {distance:.2} m raw, affordances {}, seed {}",
        args.output.display(),
        raw.len(),
        args.affordances,
        args.seed
    );
    Ok(())
}
