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
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shm_types::RuntimeConfig;
use walk_bench::command::BenchArgs;

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
    for (flag, range) in [
        ("--distance", Some(DISTANCE_M)),
        ("--rate-hz", Some(RATE_HZ)),
        ("--seed", None),
    ] {
        flags.push(Flag::new("walkctl demo", flag, range, |arg| {
            parse::<client::demo::DemoArgs>(&["demo", arg]).map(drop)
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
    for flag in ["--order", "--discount", "--max-clusters"] {
        flags.push(Flag::new("walkctl learn", flag, None, |arg| {
            parse::<client::learn::LearnArgs>(&["learn", "--demos", "d", "-o", "m.json", arg])
                .map(drop)
        }));
    }
    for (flag, range) in [
        ("--distances", Some(DISTANCE_M)),
        ("--runs", None),
        ("--first-seed", None),
    ] {
        flags.push(Flag::new("walkctl evaluate", flag, range, |arg| {
            let args = parse::<client::evaluate::EvaluateArgs>(&["evaluate", arg])?;
            args.cells.requests().map(drop).map_err(|e| e.to_string())
        }));
    }
    for flag in ["--samples", "--runs"] {
        let cfg = cfg.clone();
        flags.push(Flag::new(
            "walkctl bench-coverage",
            flag,
            None,
            move |arg| {
                let line = ["bench-coverage", "--robot", &cfg, arg];
                parse::<client::bench_coverage::BenchCoverageArgs>(&line).map(drop)
            },
        ));
    }
    for flag in ["--runs", "--seed"] {
        let cfg = cfg.clone();
        flags.push(Flag::new(
            "walkctl bench-postprocess",
            flag,
            None,
            move |arg| {
                let line = ["bench-postprocess", "--robot", &cfg, arg];
                parse::<client::bench_postprocess::BenchPostprocessArgs>(&line).map(drop)
            },
        ));
    }
    flags.push(Flag::new("walkctl watch", "--timeout-s", None, |arg| {
        parse::<client::watch::WatchArgs>(&["watch", arg]).map(drop)
    }));
    {
        let cfg = cfg.clone();
        flags.push(Flag::new(
            "walkctl record",
            "--duration",
            Some(DURATION_S),
            move |arg| {
                let line = ["record", "--config", &cfg, "-o", "walk.mcap", arg];
                parse::<client::observe::RecordArgs>(&line).map(drop)
            },
        ));
    }
    for (flag, range) in [("--duration", Some(DURATION_S)), ("--port", None)] {
        let cfg = cfg.clone();
        flags.push(Flag::new("walkctl view", flag, range, move |arg| {
            parse::<client::observe::ViewArgs>(&["view", "--config", &cfg, arg]).map(drop)
        }));
    }
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
            args.cells.requests().map(drop).map_err(|e| e.to_string())
        }));
    }
    flags
}

/// The values tried for `flag`: hostile ones and random ones over many magnitudes, shaped as
/// the flag takes them (`FROM:TO` for `--railing`, `x,y,z` for `--pelvis-com-offset`).
fn values(flag: &str, rng: &mut ChaCha8Rng) -> Vec<String> {
    let mut numbers: Vec<String> = [
        "0",
        "-0",
        "-1",
        "1",
        "0.5",
        "1e-300",
        "1e300",
        "-1e300",
        "NaN",
        "nan",
        "inf",
        "-inf",
        "4294967295",
        "4294967296",
        "-2147483649",
        "9223372036854775807",
        "18446744073709551615",
        "18446744073709551616",
        "340282366920938463463374607431768211456",
        "1e400",
        "",
        "fast",
    ]
    .map(str::to_owned)
    .to_vec();
    for _ in 0..RANDOM_VALUES {
        let magnitude = 10f64.powf(rng.random_range(-12.0..12.0));
        let sign = if rng.random_bool(0.8) { 1.0 } else { -1.0 };
        numbers.push(if rng.random_bool(0.4) {
            format!("{}", (sign * magnitude).round() as i64)
        } else {
            format!("{:?}", sign * magnitude)
        });
    }
    match flag {
        "--railing" => numbers
            .iter()
            .flat_map(|v| [format!("0:{v}"), format!("{v}:1")])
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
    assert!(
        panics.is_empty(),
        "{} panics:\n{}",
        panics.len(),
        panics.join("\n")
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
