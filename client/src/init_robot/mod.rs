//! `walkctl init-robot`: a starting robot config derived from a robot's model, so a new robot
//! walks with values that follow from its size instead of a copy of another robot's.
//!
//! ```text
//! walkctl init-robot --urdf PATH [--name NAME] [-o OUT.toml] [overrides]
//! walkctl init-robot --dimensions FILE [--frames-from CONFIG] [--name NAME] [-o OUT.toml]
//! ```
//!
//! With a URDF it guesses the `[robot]` section ([`legs`], [`standing`], [`frames`],
//! [`groups`]), prints every guess with its basis on stderr ([`table`]), loads the guessed
//! section as walkd would, measures the robot ([`measure`]) and derives every other section
//! ([`derive`]). With a dimensions file ([`dimensions`]: a robot whose model is not public) it
//! derives the sections from those numbers and copies `[robot]` from `--frames-from`, or leaves
//! it out for the user to write. The written text ([`render`]) is checked by the `[robot]`,
//! `[postprocess]` and `[runtime]` parsers before it is written; docs/new-robot.md has the rules.

pub mod derive;
pub mod dimensions;
pub mod frames;
pub mod groups;
pub mod legs;
pub mod measure;
pub mod model;
pub mod reference;
pub mod render;
pub mod standing;
pub mod table;

use std::path::{Component, Path, PathBuf};

use anyhow::Context;
use kinematics::{ConfigFile, Robot};
use stance::{Gait, PostProcessParams};

use dimensions::RobotDimensions;
use frames::FrameOverrides;
use model::UrdfModel;

/// Arguments of `walkctl init-robot`.
#[derive(Debug, Clone, clap::Args)]
pub struct InitRobotArgs {
    /// The robot's URDF: guess the frames, measure the robot, derive the config.
    #[arg(long, value_name = "PATH", required_unless_present = "dimensions")]
    pub urdf: Option<PathBuf>,
    /// A dimensions file (TOML, docs/new-robot.md) instead of a URDF, for a robot without a
    /// public model.
    #[arg(long, value_name = "FILE", conflicts_with = "urdf")]
    pub dimensions: Option<PathBuf>,
    /// With --dimensions: copy the [robot] section of this config (else the output has none).
    #[arg(long, value_name = "CONFIG", requires = "dimensions")]
    pub frames_from: Option<PathBuf>,
    /// Robot name (config `name`, services `walk/<name>`); default: the URDF's robot name in
    /// lower case, or the dimensions file's `name`.
    #[arg(long)]
    pub name: Option<String>,
    /// Write the config here (default: standard output).
    #[arg(short = 'o', long = "output", value_name = "OUT.toml")]
    pub output: Option<PathBuf>,
    /// Also write the measured dimensions to this file (the --dimensions format).
    #[arg(long, value_name = "FILE", requires = "urdf")]
    pub save_dimensions: Option<PathBuf>,
    /// The pelvis link, instead of the guess.
    #[arg(long, value_name = "LINK", requires = "urdf")]
    pub base_link: Option<String>,
    /// The left foot link (the last link of the left leg), instead of the guess.
    #[arg(long, value_name = "LINK", requires = "urdf")]
    pub left_foot: Option<String>,
    /// The right foot link, instead of the guess.
    #[arg(long, value_name = "LINK", requires = "urdf")]
    pub right_foot: Option<String>,
    /// Sole length x width in metres (e.g. 0.2x0.08), instead of the guess.
    #[arg(long, value_name = "LxW", value_parser = parse_sole, requires = "urdf")]
    pub sole: Option<(f64, f64)>,
    /// The soles lie this far below the foot links' origins (m), instead of the guess.
    #[arg(long, value_name = "M", value_parser = SOLE_BELOW_M.parser(), requires = "urdf")]
    pub sole_below: Option<f64>,
    /// The left hand link, instead of the guess.
    #[arg(long, value_name = "LINK", requires = "urdf")]
    pub left_hand: Option<String>,
    /// The right hand link, instead of the guess.
    #[arg(long, value_name = "LINK", requires = "urdf")]
    pub right_hand: Option<String>,
}

/// `--sole-below` (m): a foot link's origin is within a metre of its sole.
const SOLE_BELOW_M: kinematics::bounds::Range = kinematics::bounds::Range::new(0.0, 1.0);

/// `--sole LxW`: each side in `[robot] sole`'s range.
fn parse_sole(text: &str) -> Result<(f64, f64), String> {
    let (length, width) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| "expected LENGTHxWIDTH in metres, e.g. 0.2x0.08".to_owned())?;
    let side = kinematics::bounds::Range::new(0.01, 1.0).parser();
    Ok((side(length)?, side(width)?))
}

/// The header's word on a `[robot]` section guessed here.
const GUESSED: &str =
    "The [robot] section is guessed from the model (walkctl printed each guess and its basis).";

/// What `walkctl init-robot` produces: the config text and what it was derived from.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The config file's text.
    pub text: String,
    /// The dimensions the sections were derived from.
    pub dimensions: RobotDimensions,
    /// The derived sections.
    pub derived: derive::DerivedSections,
}

/// Runs `walkctl init-robot`: generates the config and writes it (and the dimensions).
pub fn run(args: &InitRobotArgs) -> anyhow::Result<()> {
    let generated = generate(args, &command_line())?;
    match &args.output {
        Some(path) => {
            std::fs::write(path, &generated.text)
                .with_context(|| format!("cannot write {}", path.display()))?;
            eprintln!("wrote {}", path.display());
        }
        None => print!("{}", generated.text),
    }
    if let Some(path) = &args.save_dimensions {
        std::fs::write(path, generated.dimensions.to_toml())
            .with_context(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// The config `args` ask for, `command` recorded in its header; prints the guesses and the
/// summary on stderr and writes nothing. The URDF path in it is relative to `args.output`'s
/// directory (the working directory without one).
pub fn generate(args: &InitRobotArgs, command: &str) -> anyhow::Result<Generated> {
    let target = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from("robot.toml"));
    let (dimensions, robot_text) = match (&args.urdf, &args.dimensions) {
        (Some(urdf), _) => from_urdf(args, urdf, &target)?,
        (None, Some(file)) => from_dimensions(args, file)?,
        (None, None) => anyhow::bail!("pass --urdf PATH or --dimensions FILE"),
    };
    let robot_origin = match (&args.urdf, &args.frames_from) {
        (Some(_), _) => GUESSED.to_owned(),
        // The command line above names the file.
        (None, Some(_)) => {
            "The [robot] section is copied from the --frames-from config.".to_owned()
        }
        (None, None) => "There is no [robot] section: write one (docs/kinematics.md).".to_owned(),
    };
    let derived = derive::derive(&dimensions);
    let text = format!(
        "{}\n{}{}",
        render::header(command, &dimensions, &robot_origin, &derived.notes),
        robot_text,
        render::derived_sections(&derived)
    );
    check(&text, &target, args.urdf.is_some())?;
    eprint!("{}", table::summary(&dimensions, &derived));
    Ok(Generated {
        text,
        dimensions,
        derived,
    })
}

/// Guesses, loads and measures the robot of a URDF: its dimensions and `[robot]` text.
fn from_urdf(
    args: &InitRobotArgs,
    urdf: &Path,
    target: &Path,
) -> anyhow::Result<(RobotDimensions, String)> {
    let model = UrdfModel::load(urdf)?;
    let feet = [&args.left_foot, &args.right_foot]
        .map(|name| name.as_deref())
        .into_iter()
        .zip(["--left-foot", "--right-foot"])
        .map(|(name, option)| name.map(|n| model.link(n, option)).transpose())
        .collect::<anyhow::Result<Vec<_>>>()?;
    let legs = legs::find_legs(&model, [feet[0], feet[1]])?;
    let standing = standing::standing(&model, &legs)?;
    let overrides = FrameOverrides {
        base_link: args.base_link.clone(),
        sole: args.sole,
        sole_below: args.sole_below,
        hands: [args.left_hand.clone(), args.right_hand.clone()],
    };
    let frames = frames::guess_frames(&model, &legs, &standing.q, &overrides)?;
    let groups = groups::joint_groups(&model, &legs);
    eprint!(
        "{}",
        table::format(&table::guesses(
            &model,
            &legs,
            &frames,
            &groups,
            &standing.basis
        ))
    );
    let name = match &args.name {
        Some(name) => name.clone(),
        None => model.model.name().to_lowercase().replace(' ', "_"),
    };
    let origin = if args.name.is_some() {
        "--name".to_owned()
    } else {
        format!("{} (robot name)", urdf.display())
    };
    RobotDimensions::check_name(&name, &origin)?;
    let angles: Vec<(String, f64)> = standing
        .angles
        .iter()
        .map(|&(j, angle)| (model.joint_name(j).to_owned(), angle))
        .collect();
    let directory = match target.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let relative = relative_path(urdf, directory)?;
    let robot_text = render::RobotSection {
        name: &name,
        urdf: &relative.to_string_lossy(),
        frames: &frames,
        groups: &groups,
        standing: &angles,
        standing_basis: &standing.basis,
    }
    .text();
    let file = ConfigFile::parse(&robot_text, target)?;
    let robot = Robot::from_config(&file, Some(urdf)).map_err(|e| {
        anyhow::anyhow!("the guessed [robot] section does not load ({e}); override the guess")
    })?;
    let mut dimensions = measure::measure(&robot, &model, &legs);
    dimensions.name = name;
    Ok((dimensions, robot_text))
}

/// Reads a dimensions file and the `[robot]` text to copy.
fn from_dimensions(args: &InitRobotArgs, file: &Path) -> anyhow::Result<(RobotDimensions, String)> {
    let mut dimensions = RobotDimensions::load(file)?;
    if let Some(name) = &args.name {
        dimensions.name = name.clone();
        dimensions.check("--name")?;
    }
    let robot_text = match &args.frames_from {
        Some(config) => {
            let text = std::fs::read_to_string(config)
                .with_context(|| format!("--frames-from: cannot read {}", config.display()))?;
            render::copied_robot_section(&text, &config.display().to_string())?
        }
        None => {
            eprintln!(
                "no --frames-from: the output has no [robot] section; write one \
                 (docs/kinematics.md) before loading it"
            );
            String::new()
        }
    };
    Ok((dimensions, robot_text))
}

/// Parses the written text with the parsers of `[robot]` (when it was guessed here), each
/// gait's `[postprocess]` and `[runtime]`, so a bad guess or a derived value out of range is
/// refused before anything is written. The daemon's `[controller]` and `[gait]` parsers are
/// run by the bench crate's tests on the shipped configs.
fn check(text: &str, target: &Path, load_robot: bool) -> anyhow::Result<()> {
    let file = ConfigFile::parse(text, target)?;
    for gait in [Gait::Static, Gait::Dynamic] {
        PostProcessParams::from_config_for(&file, gait).context("derived [postprocess] refused")?;
    }
    shm_types::RuntimeConfig::from_section(file.section("runtime"), &file.origin())
        .context("derived [runtime] refused")?;
    if load_robot {
        Robot::from_config(&file, None).context("the written [robot] section does not load")?;
    }
    Ok(())
}

/// The command as typed, for the file's header (program name `walkctl`).
fn command_line() -> String {
    let mut words = vec!["walkctl".to_owned()];
    for arg in std::env::args().skip(1) {
        if arg.is_empty() || arg.contains([' ', '"', '\'']) {
            words.push(format!("'{arg}'"));
        } else {
            words.push(arg);
        }
    }
    words.join(" ")
}

/// `path` relative to `directory` (both made absolute against the working directory); the
/// absolute path when the two share nothing below the root.
pub fn relative_path(path: &Path, directory: &Path) -> anyhow::Result<PathBuf> {
    let normal = |p: &Path| -> anyhow::Result<Vec<String>> {
        let absolute =
            std::path::absolute(p).with_context(|| format!("cannot resolve {}", p.display()))?;
        let mut parts: Vec<String> = Vec::new();
        for component in absolute.components() {
            match component {
                Component::ParentDir => {
                    parts.pop();
                }
                Component::Normal(part) => parts.push(part.to_string_lossy().into_owned()),
                _ => {}
            }
        }
        Ok(parts)
    };
    let (to, from) = (normal(path)?, normal(directory)?);
    let common = to.iter().zip(&from).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return Ok(std::path::absolute(path)?);
    }
    let mut relative = PathBuf::new();
    for _ in common..from.len() {
        relative.push("..");
    }
    for part in &to[common..] {
        relative.push(part);
    }
    Ok(relative)
}
