//! `latency-report`: sensor→command latency, tick jitter and deadline misses of the real system.
//!
//! For each control rate (default 500 Hz and 1 kHz) and each load (idle, and a busy-loop process
//! on every core), it starts real `walkd` and `walk-sim --physics kinematic` processes (found
//! next to this executable) on a service prefix of its own, submits a long walk, lets it run for
//! `--seconds` (default 60), reads the daemon's statistics and prints a Markdown report with the
//! percentiles and histograms. Not a test: targets are reported, not asserted.
//!
//! ```text
//! cargo build --release --bins && target/release/latency-report [--seconds 60] [--rates 500,1000] [--fifo-priority 80]
//! ```

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use clap::Parser;
use kinematics::robot::Robot;
use shm_types::{
    ClientPorts, ControlCommand, DaemonStatus, HISTOGRAM_BUCKETS, LinkState, LogHistogram,
    ServiceNames,
};

/// Measure walkd's real-time behaviour under idle and loaded conditions.
#[derive(Parser)]
#[command(name = "latency-report", version, about)]
struct Args {
    /// Robot config.
    #[arg(long, default_value = "configs/armar4.toml")]
    config: PathBuf,
    /// Length of each run.
    #[arg(long, default_value_t = 60)]
    seconds: u64,
    /// Control rates to measure (Hz).
    #[arg(long, value_delimiter = ',', default_value = "500,1000")]
    rates: Vec<f64>,
    /// SCHED_FIFO priority for walkd's control thread (degrades with a warning if not
    /// permitted); walk-sim then runs one below it under `chrt -f`, like a real-time adapter.
    #[arg(long)]
    fifo_priority: Option<i32>,
    /// Internal: burn one CPU until killed (the load generator).
    #[arg(long, hide = true)]
    burn: bool,
}

/// Child processes, killed when dropped.
struct Children(Vec<Child>);

impl Children {
    fn terminate(&mut self) {
        for child in &self.0 {
            // SAFETY: kill on our own child's pid has no memory-safety preconditions.
            unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
        }
        for child in &mut self.0 {
            let start = Instant::now();
            while matches!(child.try_wait(), Ok(None)) && start.elapsed() < Duration::from_secs(5) {
                std::thread::sleep(Duration::from_millis(10));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        self.0.clear();
    }
}

impl Drop for Children {
    fn drop(&mut self) {
        self.terminate();
    }
}

fn sibling(name: &str) -> anyhow::Result<PathBuf> {
    let path = std::env::current_exe()?
        .parent()
        .context("executable has no directory")?
        .join(name);
    anyhow::ensure!(
        path.is_file(),
        "{} missing: cargo build --release --bins",
        path.display()
    );
    Ok(path)
}

fn spawn(path: &Path, args: &[String]) -> anyhow::Result<Child> {
    Command::new(path)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .with_context(|| format!("cannot start {}", path.display()))
}

/// One busy-loop process per core.
fn start_load() -> anyhow::Result<Children> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let me = std::env::current_exe()?;
    let mut load = Children(Vec::new());
    for _ in 0..cores {
        load.0.push(spawn(&me, &["--burn".to_owned()])?);
    }
    Ok(load)
}

/// A long post-processed walk for the robot (so it walks during the whole run).
fn long_walk(config: &Path) -> anyhow::Result<String> {
    let robot = Robot::load(config, None)?;
    let params = stance::PostProcessParams::from_config_path(config)?;
    let raw = stance::generate(
        &robot,
        &stance::GenerateOptions {
            distance: 20.0 / params.scf,
            affordances: stance::AffordanceSet::Feet,
            seed: 7,
        },
    )?;
    Ok(stance::PostProcessor::new(&robot, params)
        .process(&raw)?
        .to_json_string())
}

/// Runs walkd + walk-sim at `rate_hz` for `seconds` and returns the daemon's final status.
fn measure(
    args: &Args,
    walk: &str,
    rate_hz: f64,
    loaded: bool,
) -> anyhow::Result<(DaemonStatus, bool)> {
    let prefix = format!("walk-latency/{}/{}", std::process::id(), rate_hz as u64);
    let common = vec![
        "--config".to_owned(),
        args.config.display().to_string(),
        "--service-prefix".to_owned(),
        prefix.clone(),
        "--clock".to_owned(),
        "realtime".to_owned(),
        "--rate-hz".to_owned(),
        rate_hz.to_string(),
    ];
    let mut walkd_args = common.clone();
    if let Some(priority) = args.fifo_priority {
        walkd_args.extend(["--fifo-priority".to_owned(), priority.to_string()]);
    }
    let mut sim_args = common;
    sim_args.extend(["--physics".to_owned(), "kinematic".to_owned()]);
    let _load = if loaded { Some(start_load()?) } else { None };
    let mut system = Children(vec![spawn(&sibling("walkd")?, &walkd_args)?]);
    let sim = sibling("walk-sim")?;
    system.0.push(match args.fifo_priority {
        Some(priority) => {
            let mut chrt_args = vec!["-f".to_owned(), (priority - 1).max(1).to_string()];
            chrt_args.push(sim.display().to_string());
            chrt_args.extend(sim_args);
            spawn(Path::new("chrt"), &chrt_args)?
        }
        None => spawn(&sim, &sim_args)?,
    });

    let names = ServiceNames::new(&prefix)?;
    let start = Instant::now();
    let client = loop {
        if let Ok(client) = ClientPorts::connect(&names, "latency-report")
            && client.daemon_present()
            && let Ok(reply) = client.control(ControlCommand::Query, Duration::from_secs(2))
            && reply.status.link == LinkState::Fresh
        {
            break client;
        }
        if start.elapsed() > Duration::from_secs(30) {
            bail!("walkd at {rate_hz} Hz did not start");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let walking = client
        .submit(walk.as_bytes(), Duration::from_secs(10))?
        .accepted;
    std::thread::sleep(Duration::from_secs(args.seconds));
    let status = client
        .control(ControlCommand::Query, Duration::from_secs(5))?
        .status;
    system.terminate();
    Ok((status, walking))
}

fn histogram_rows(name: &str, histogram: &LogHistogram) -> String {
    let total: u64 = histogram.counts.iter().sum();
    let mut out = format!("{name} ({total} samples):\n\n| bucket (µs) | count |\n|---|---|\n");
    let last = histogram.counts.iter().rposition(|&c| c > 0).unwrap_or(0);
    for (b, count) in histogram.counts.iter().enumerate().take(last + 1) {
        let high = if b + 1 == HISTOGRAM_BUCKETS {
            "∞".to_owned()
        } else {
            LogHistogram::bucket_floor_us(b + 1).to_string()
        };
        out.push_str(&format!(
            "| [{}, {high}) | {count} |\n",
            LogHistogram::bucket_floor_us(b)
        ));
    }
    out
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    if args.burn {
        let mut x = 0u64;
        loop {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
    }
    let walk = long_walk(&args.config)?;
    println!("# walkd latency report\n");
    println!(
        "{} s per run, robot config {}, {} CPU(s); load = one busy-loop process per CPU; \
         SCHED_FIFO: {}.\n",
        args.seconds,
        args.config.display(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        args.fifo_priority.map_or("off".to_owned(), |p| format!(
            "walkd {p}, walk-sim {}",
            (p - 1).max(1)
        ))
    );
    println!(
        "| rate | load | walking | ticks | deadline misses | stale periods | tick p50/p99/max (µs) | sensor→command p50/p99/max (µs) | jitter p50/p99/max (µs) | p99 latency − p99 tick (µs) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut details = String::new();
    for &rate in &args.rates {
        for loaded in [false, true] {
            let load = if loaded { "all CPUs busy" } else { "idle" };
            let (s, walking) = measure(&args, &walk, rate, loaded)?;
            let triple =
                |l: &shm_types::LatencySummary| format!("{:.1}/{:.1}/{:.1}", l.p50, l.p99, l.max);
            println!(
                "| {rate} Hz | {load} | {} ({}) | {} | {} | {} | {} | {} | {} | {:.1} |",
                if walking { "yes" } else { "no" },
                s.state.name(),
                s.ticks,
                s.deadline_misses,
                s.stale_periods,
                triple(&s.tick_us),
                triple(&s.latency_us),
                triple(&s.jitter_us),
                s.latency_us.p99 - s.tick_us.p99,
            );
            details.push_str(&format!("\n## {rate} Hz, {load}\n\n"));
            details.push_str(&histogram_rows(
                "sensor→command latency",
                &s.latency_histogram,
            ));
            details.push('\n');
            details.push_str(&histogram_rows("tick jitter", &s.jitter_histogram));
            details.push('\n');
            details.push_str(&histogram_rows("tick compute time", &s.tick_histogram));
        }
    }
    println!("{details}");
    Ok(())
}
