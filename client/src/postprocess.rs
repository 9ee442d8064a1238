//! `walkctl postprocess`: run Algorithm 1 on a raw stance file and write the post-processed
//! sequence the daemon executes; optionally draw the paper's Fig. 3.

use std::path::{Path, PathBuf};

use anyhow::Context;
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use stance::plot::{Snapshot, write_fig3};
use stance::{ContactUnification, Gait, PostProcessParams, PostProcessor, RawSequence};

/// Command-line overrides of the config's `[postprocess]` values.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ParamOverrides {
    /// The gait whose limits to start from (`[postprocess]`, or with the dynamic gait's
    /// `[postprocess.dynamic]` overrides); the output asks walkd for that gait. Default: the
    /// config's `[gait] default`. A gait the robot cannot walk (dynamic without
    /// `[gait.dynamic]`) is refused.
    #[arg(long)]
    pub gait: Option<Gait>,
    /// Sequence scaling factor (0, 1].
    #[arg(long)]
    pub scf: Option<f64>,
    /// Maximal step size [m].
    #[arg(long)]
    pub s_max: Option<f64>,
    /// Minimal lateral foot distance [m].
    #[arg(long)]
    pub o_min: Option<f64>,
    /// Maximal lateral foot distance [m].
    #[arg(long)]
    pub o_max: Option<f64>,
    /// Swing-foot roll limit [rad].
    #[arg(long)]
    pub alpha_x: Option<f64>,
    /// Swing-foot pitch limit [rad].
    #[arg(long)]
    pub alpha_y: Option<f64>,
    /// Swing-foot yaw limit (to the walking direction) [rad].
    #[arg(long)]
    pub alpha_z: Option<f64>,
    /// Minimal swing-foot height [m].
    #[arg(long)]
    pub h_min: Option<f64>,
    /// Maximal swing-foot height [m].
    #[arg(long)]
    pub h_max: Option<f64>,
    /// How much a step's rise or drop counts against s_max on terrain (>= 1).
    #[arg(long)]
    pub rise_weight: Option<f64>,
    /// The longest step from a stair tread to the next but one [m]: one foot per stair within it.
    #[arg(long)]
    pub stair_s_max: Option<f64>,
    /// Pass 2 variant: `first` (the paper's) or `mean`.
    #[arg(long, value_parser = parse_unification)]
    pub contact_unification: Option<ContactUnification>,
}

fn parse_unification(s: &str) -> Result<ContactUnification, String> {
    match s {
        "first" => Ok(ContactUnification::First),
        "mean" => Ok(ContactUnification::Mean),
        _ => Err(format!("`{s}`: use `first` or `mean`")),
    }
}

impl ParamOverrides {
    /// The config's parameters for the gait, with these overrides applied and re-validated;
    /// refuses a gait the robot cannot walk ([`Gait::for_walk`]).
    pub fn load(&self, config: &Path) -> anyhow::Result<PostProcessParams> {
        let file = ConfigFile::load(config)?;
        let gait = Gait::for_walk(self.gait, &file)?;
        let mut p = PostProcessParams::from_config_for(&file, gait)?;
        let fields = [
            (self.scf, &mut p.scf),
            (self.s_max, &mut p.s_max),
            (self.o_min, &mut p.o_min),
            (self.o_max, &mut p.o_max),
            (self.alpha_x, &mut p.alpha_x),
            (self.alpha_y, &mut p.alpha_y),
            (self.alpha_z, &mut p.alpha_z),
            (self.h_min, &mut p.h_min),
            (self.h_max, &mut p.h_max),
            (self.rise_weight, &mut p.rise_weight),
        ];
        for (value, field) in fields {
            if let Some(value) = value {
                *field = value;
            }
        }
        p.stair_s_max = self.stair_s_max.or(p.stair_s_max);
        if let Some(mode) = self.contact_unification {
            p.contact_unification = mode;
        }
        p.validate(&format!("{} with command-line overrides", config.display()))?;
        Ok(p)
    }
}

/// Loads the robot of a config (with an optional URDF override).
pub fn load_robot(config: &Path, urdf: Option<&Path>) -> anyhow::Result<Robot> {
    Robot::load(config, urdf).with_context(|| format!("loading robot {}", config.display()))
}

/// Arguments of `walkctl postprocess`.
#[derive(Debug, Clone, clap::Args)]
pub struct PostprocessArgs {
    /// Robot config (TOML with `[robot]` and `[postprocess]`), e.g. configs/armar4.toml.
    #[arg(long, value_name = "CONFIG")]
    pub robot: PathBuf,
    /// URDF to use instead of the config's `urdf` (required for HRP-4).
    #[arg(long, value_name = "PATH")]
    pub urdf: Option<PathBuf>,
    /// Raw stance file (from `walkctl generate`).
    #[arg(value_name = "RAW.json")]
    pub input: PathBuf,
    /// Where to write the post-processed stance file.
    #[arg(short, long, value_name = "PP.json")]
    pub output: PathBuf,
    /// Directory to write Fig. 3 into (fig3_top.svg, fig3_side.svg).
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub params: ParamOverrides,
}

/// Runs `walkctl postprocess`.
pub fn run(args: &PostprocessArgs) -> anyhow::Result<()> {
    let params = args.params.load(&args.robot)?;
    let robot = load_robot(&args.robot, args.urdf.as_deref())?;
    let text = std::fs::read_to_string(&args.input)
        .with_context(|| format!("reading {}", args.input.display()))?;
    let raw = RawSequence::from_json_str(&text, &robot)
        .with_context(|| format!("{}", args.input.display()))?;
    let mut processor = PostProcessor::new(&robot, params.clone());
    let mut snapshots = Vec::new();
    let processed = processor.process_observed(&raw, |pass, poses| {
        if args.plot.is_some() {
            snapshots.push(Snapshot {
                pass,
                poses: poses.clone(),
            });
        }
    })?;
    std::fs::write(&args.output, processed.to_json_string())
        .with_context(|| format!("writing {}", args.output.display()))?;
    let poses = processed.to_poses();
    if let Some(path) = stance::passes::path_of(&poses) {
        let last = poses.len() - 1;
        let covered = stance::poses::FEET
            .iter()
            .map(|&foot| path.along(&poses.pose(last, foot).translation.vector))
            .fold(f64::NEG_INFINITY, f64::max);
        let longest = stance::derived::steps(&poses, &path)
            .iter()
            .map(|step| step.length.abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{}: {} stances, covers {covered:.2} m along the path, longest step {longest:.3} m",
            args.output.display(),
            processed.len()
        );
    }
    if let Some(dir) = &args.plot {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for file in write_fig3(dir, &snapshots, raw.environment(), &robot.sole, &params)? {
            eprintln!("{}", file.display());
        }
    }
    Ok(())
}
