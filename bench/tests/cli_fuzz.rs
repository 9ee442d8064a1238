//! Every number on a command line, fuzzed: for every numeric flag of walkd, walkctl's
//! subcommands, walk-bench and physics-matrix, random and hostile values are parsed by the
//! binary's own argument struct and run through the checks the binary makes before it starts
//! (walkd's `[runtime]` overrides, the post-processing overrides, the matrix's cells and model
//! error). None may panic; each value is accepted (inside its range where the range is a shared
//! one) or refused by an error naming the flag. walk-sim, whose arguments live in its binary, is
//! fuzzed by running it (tests/e2e/bad_input.rs).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use clap::Parser;
use client::args::{DISTANCE_M, DURATION_S, RATE_HZ};
use daemon::runtime::DaemonArgs;
use kinematics::ConfigFile;
use kinematics::bounds::Range;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use shm_types::RuntimeConfig;
use walk_bench::command::BenchArgs;

mod fuzz_values;

/// Random values tried per flag, besides the fixed hostile ones.
const RANDOM_VALUES: usize = 24;

/// A `clap::Args` struct of a walkctl subcommand as a command line of its own.
#[derive(Parser)]
struct Command<A: clap::Args> {
    #[command(flatten)]
    args: A,
}

/// Parses `line` into `A` (a subcommand's arguments); clap's error text names the flag.
fn parse<A: clap::Args>(line: &[&str]) -> Result<A, String> {
    Command::<A>::try_parse_from(line)
        .map(|command| command.args)
        .map_err(|e| e.to_string())
}

/// The robot config every command line uses.
fn config() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/jvrc1.toml")
        .display()
        .to_string()
}

/// Parses a command line with one flag's `flag=value` and runs the command's checks.
type Check = Box<dyn Fn(&str) -> Result<(), String>>;

/// One numeric flag: the command it belongs to, the range a value it accepts must lie in (when
/// that range is one of the shared ones), and how the command parses and checks `flag=value`.
struct Flag {
    command: &'static str,
    flag: &'static str,
    range: Option<Range>,
    check: Check,
}

impl Flag {
    fn new(
        command: &'static str,
        flag: &'static str,
        range: Option<Range>,
        check: impl Fn(&str) -> Result<(), String> + 'static,
    ) -> Self {
        Self {
            command,
            flag,
            range,
            check: Box::new(check),
        }
    }
}

/// The `flags` of the walkctl subcommand whose arguments are `A`, checked by parsing alone: the
/// command line `base` (the subcommand and what it requires) and `flag=value`.
fn parsed<A: clap::Args + 'static>(
    base: &[&str],
    flags: &[(&'static str, Option<Range>)],
) -> Vec<Flag> {
    let base: Vec<String> = base.iter().map(|arg| (*arg).to_owned()).collect();
    let command: &'static str = format!("walkctl {}", base[0]).leak();
    flags
        .iter()
        .map(|&(flag, range)| {
            let base = base.clone();
            Flag::new(command, flag, range, move |arg| {
                let line: Vec<&str> = base.iter().map(String::as_str).chain([arg]).collect();
                parse::<A>(&line).map(drop)
            })
        })
        .collect()
}

/// The flags of walkd and walkctl (the client's argument structs).
fn daemon_and_client_flags() -> Vec<Flag> {
    let cfg = config();
    let runtime = {
        let file = ConfigFile::load(Path::new(&cfg)).unwrap();
        RuntimeConfig::from_section(file.section("runtime"), &file.origin()).unwrap()
    };
    let mut flags = Vec::new();
    for flag in ["--rate-hz", "--fifo-priority", "--cpu", "--spin-us"] {
        let (cfg, runtime) = (cfg.clone(), runtime.clone());
        let range = (flag == "--rate-hz").then_some(RATE_HZ);
        flags.push(Flag::new("walkd", flag, range, move |arg| {
            let args = DaemonArgs::try_parse_from(["walkd", "--config", &cfg, arg])
                .map_err(|e| e.to_string())?;
            let applied = args.runtime_overrides().apply(runtime.clone());
            applied.map(drop).map_err(|e| e.to_string())
        }));
    }
    let postprocess_flags = [
        "--scf",
        "--s-max",
        "--o-min",
        "--o-max",
        "--alpha-x",
        "--alpha-y",
        "--alpha-z",
        "--h-min",
        "--h-max",
    ];
    for flag in ["--distance", "--railing", "--seed", "--beam"]
        .into_iter()
        .chain(postprocess_flags)
    {
        let cfg = cfg.clone();
        let range = (flag == "--distance").then_some(DISTANCE_M);
        flags.push(Flag::new("walkctl generate", flag, range, move |arg| {
            let mut line = vec!["generate", "--robot", &cfg, "-o", "raw.json", arg];
            if flag != "--distance" {
                line.push("--distance=1");
            }
            let args = parse::<client::generate::GenerateArgs>(&line)?;
            args.params
                .load(Path::new(&cfg))
                .map_err(|e| format!("{e:#}"))?;
            args.source.load().map(drop).map_err(|e| e.to_string())
        }));
    }
    for flag in postprocess_flags {
        let cfg = cfg.clone();
        flags.push(Flag::new("walkctl postprocess", flag, None, move |arg| {
            let line = [
                "postprocess",
                "--robot",
                &cfg,
                "raw.json",
                "-o",
                "pp.json",
                arg,
            ];
            let args = parse::<client::postprocess::PostprocessArgs>(&line)?;
            args.params
                .load(Path::new(&cfg))
                .map(drop)
                .map_err(|e| format!("{e:#}"))
        }));
    }
    for (flag, range) in [
        ("--distances", Some(DISTANCE_M)),
        ("--runs", None),
        ("--first-seed", None),
    ] {
        flags.push(Flag::new("walkctl evaluate", flag, range, |arg| {
            let args = parse::<client::evaluate::EvaluateArgs>(&["evaluate", arg])?;
            args.cells
                .requests(None)
                .map(drop)
                .map_err(|e| e.to_string())
        }));
    }
    let m = "m.json".to_owned();
    flags.extend(parsed::<client::demo::DemoArgs>(
        &["demo"],
        &[
            ("--distance", Some(DISTANCE_M)),
            ("--rate-hz", Some(RATE_HZ)),
            ("--seed", None),
        ],
    ));
    flags.extend(parsed::<client::learn::LearnArgs>(
        &["learn", "--demos", "d", "-o", &m],
        &[
            ("--order", None),
            ("--discount", None),
            ("--max-clusters", None),
        ],
    ));
    flags.extend(parsed::<client::bench_coverage::BenchCoverageArgs>(
        &["bench-coverage", "--robot", &cfg],
        &[("--samples", None), ("--runs", None)],
    ));
    flags.extend(parsed::<client::bench_postprocess::BenchPostprocessArgs>(
        &["bench-postprocess", "--robot", &cfg],
        &[("--runs", None), ("--seed", None)],
    ));
    flags.extend(parsed::<client::init_robot::InitRobotArgs>(
        &["init-robot", "--urdf", "robot.urdf"],
        &[("--sole", None), ("--sole-below", None)],
    ));
    flags.extend(parsed::<client::watch::WatchArgs>(
        &["watch"],
        &[("--timeout-s", None)],
    ));
    flags.extend(parsed::<client::observe::RecordArgs>(
        &["record", "--config", &cfg, "-o", "walk.mcap"],
        &[("--duration", Some(DURATION_S))],
    ));
    flags.extend(parsed::<client::observe::ViewArgs>(
        &["view", "--config", &cfg],
        &[("--duration", Some(DURATION_S)), ("--port", None)],
    ));
    flags
}

/// The flags of walk-bench and physics-matrix.
fn bench_flags() -> Vec<Flag> {
    let cfg = config();
    let mut flags = Vec::new();
    for (flag, range) in [
        ("--distance", Some(DISTANCE_M)),
        ("--rate-hz", Some(RATE_HZ)),
        ("--seed", None),
        ("--beam", None),
    ] {
        let cfg = cfg.clone();
        flags.push(Flag::new("walk-bench", flag, range, move |arg| {
            let mut line = vec!["walk-bench", "--robot", &cfg, arg];
            if flag != "--distance" {
                line.push("--distance=1");
            }
            let args = BenchArgs::try_parse_from(line).map_err(|e| e.to_string())?;
            args.source.load().map(drop).map_err(|e| e.to_string())
        }));
    }
    #[cfg(feature = "mujoco")]
    for (flag, range) in [
        ("--rate-hz", Some(RATE_HZ)),
        ("--mass-scale", None),
        ("--impratio", None),
        ("--timestep", None),
        ("--pelvis-com-offset", None),
        ("--push-impulse", None),
        ("--push-step", None),
        ("--push-duration", None),
        ("--jobs", None),
        ("--distances", Some(DISTANCE_M)),
        ("--runs", None),
        ("--first-seed", None),
    ] {
        use walk_bench::matrix::{MatrixArgs, walk_options};
        let cfg = cfg.clone();
        flags.push(Flag::new("physics-matrix", flag, range, move |arg| {
            let args = MatrixArgs::try_parse_from(["physics-matrix", "--robot", &cfg, arg])
                .map_err(|e| e.to_string())?;
            walk_options(&args, stance::Gait::Static).map_err(|e| format!("{e:#}"))?;
            args.cells
                .requests(None)
                .map(drop)
                .map_err(|e| e.to_string())
        }));
    }
    flags
}

/// The values tried for `flag`: hostile ones and random ones over many magnitudes, shaped as
/// the flag takes them (`FROM:TO` for `--railing`, `x,y,z` for `--pelvis-com-offset`, `LxW`
/// for `--sole`).
fn values(flag: &str, rng: &mut ChaCha8Rng) -> Vec<String> {
    let mut numbers: Vec<String> = fuzz_values::HOSTILE.map(str::to_owned).to_vec();
    numbers.push(String::new());
    numbers.extend(fuzz_values::random(rng, RANDOM_VALUES));
    match flag {
        "--railing" => numbers
            .iter()
            .flat_map(|v| [format!("0:{v}"), format!("{v}:1")])
            .collect(),
        "--sole" => numbers
            .iter()
            .flat_map(|v| [format!("0.2x{v}"), format!("{v}x0.08")])
            .collect(),
        "--pelvis-com-offset" | "--distances" => numbers
            .iter()
            .flat_map(|v| [v.clone(), format!("0,{v},0")])
            .collect(),
        _ => numbers,
    }
}

#[test]
fn every_command_line_number_is_in_range_or_refused_by_flag_and_nothing_panics() {
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    let (mut tried, mut panics, mut wrong) = (0, Vec::new(), Vec::new());
    let flags: Vec<Flag> = daemon_and_client_flags()
        .into_iter()
        .chain(bench_flags())
        .collect();
    for flag in &flags {
        // A refusal names the flag, or the config key it replaces (`--s-max`: `s_max`).
        let key = flag.flag.trim_start_matches('-').replace('-', "_");
        for value in values(flag.flag, &mut rng) {
            tried += 1;
            let arg = format!("{}={value}", flag.flag);
            let case = format!("{} {arg}", flag.command);
            match catch_unwind(AssertUnwindSafe(|| (flag.check)(&arg))) {
                Err(_) => panics.push(case),
                Ok(Err(error)) if !(error.contains(flag.flag) || error.contains(&key)) => {
                    wrong.push(format!("{case}: the error names no flag: {error}"));
                }
                Ok(Err(_)) => {}
                Ok(Ok(())) => {
                    let outside = flag.range.is_some_and(|range| {
                        value
                            .split(',')
                            .any(|v| !v.parse().is_ok_and(|v| range.contains(v)))
                    });
                    if outside {
                        wrong.push(format!("{case}: accepted outside {:?}", flag.range));
                    }
                }
            }
        }
    }
    eprintln!(
        "command-line fuzzing: {tried} values of {} flags tried, {} panics",
        flags.len(),
        panics.len()
    );
    fuzz_values::assert_clean(&panics, &wrong);
}
