//! `latency-report`: sensor→command latency, tick jitter and deadline misses of the real system.
//!
//! For each control rate (default 500 Hz and 1 kHz) and each load (idle, and a busy-loop process
//! on every core), it starts real `walkd` and `walk-sim --physics kinematic` processes (found
//! next to this executable) on a service prefix of its own, submits a long walk, lets it run for
//! `--seconds` (default 60), reads the daemon's statistics and prints a Markdown report with the
//! percentiles and histograms, plus walkd's own timing log: how late its timer wake-ups came and,
//! for each deadline miss, where the time went (wake-up, sample, pickup, tick). Not a test:
//! targets are reported, not asserted.
//!
//! ```text
//! cargo build --release --bins && target/release/latency-report [--seconds 60] [--rates 500,1000] \
//!     [--loads idle,busy] [--spin-us N] [--fifo-priority 80]
//! ```

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use clap::Parser;
use client::args::RATE_HZ;
use client::process::{Launch, Process, Processes, executable_dir};
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use shm_types::process::Physics;
use shm_types::{
    ClientPorts, ClockMode, ControlCommand, DaemonStatus, HISTOGRAM_BUCKETS, LinkState,
    LogHistogram, ServiceNames,
};

/// Measure walkd's real-time behaviour under idle and loaded conditions.
#[derive(Parser)]
#[command(name = "latency-report", version, about)]
struct Args {
    /// Robot config.
    #[arg(long, default_value = "configs/armar4.toml")]
    config: PathBuf,
    /// Length of each run (s, 1-86400).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u64).range(1..=86_400))]
    seconds: u64,
    /// Control rates to measure (Hz, each 10-10000).
    #[arg(long, value_delimiter = ',', default_value = "500,1000", value_parser = RATE_HZ.parser())]
    rates: Vec<f64>,
    /// Load conditions to measure at each rate.
    #[arg(long, value_delimiter = ',', default_value = "idle,busy")]
    loads: Vec<Load>,
    /// walkd's busy-wait time around each expected sample (µs, 0-10000), overriding
    /// `[runtime] spin_us`.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=10_000))]
    spin_us: Option<u32>,
    /// SCHED_FIFO priority for walkd's control thread, 1-99 (degrades with a warning if not
    /// permitted); walk-sim then runs one below it under `chrt -f`, like a real-time adapter.
    #[arg(long, value_parser = clap::value_parser!(i32).range(1..=99))]
    fifo_priority: Option<i32>,
    /// Internal: burn one CPU until killed (the load generator).
    #[arg(long, hide = true)]
    burn: bool,
}

/// The CPU load during a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Load {
    /// Nothing but the measured processes.
    Idle,
    /// One busy-loop process per CPU.
    Busy,
}

impl Load {
    fn describe(self) -> &'static str {
        match self {
            Self::Idle => "idle",
            Self::Busy => "all CPUs busy",
        }
    }
}

/// What one run measured.
struct Measurement {
    /// The daemon's status at the end of the run.
    status: DaemonStatus,
    /// Whether the long walk was accepted.
    walking: bool,
    /// walkd's timing log lines (timer wake-up lateness, deadline misses).
    timing_log: Vec<String>,
    /// The system's 1-minute load average when the run started (other processes included).
    load_average: String,
    /// CPU walkd used during the run (100 = one core busy).
    walkd_cpu_percent: f64,
}

/// One busy-loop process per core.
fn start_load() -> anyhow::Result<Processes> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let me = std::env::current_exe()?;
    let mut load = Processes::default();
    for _ in 0..cores {
        load.0.push(Process::start(&me, ["--burn"], &[])?);
    }
    Ok(load)
}

/// A long post-processed walk for the robot (so it walks during the whole run).
fn long_walk(config: &Path) -> anyhow::Result<String> {
    let file = ConfigFile::load(config)?;
    let robot = Robot::from_config(&file, None)?;
    let gait = stance::Gait::configured_default(&file)?;
    let json = client::demo::walk_sequence(&robot, &file, 20.0, 7, gait)?.to_json_string();
    Ok(json)
}

/// walkd's log lines about its timing (see `daemon::runtime`), without the timestamp.
fn timing_lines(log: &str) -> Vec<String> {
    log.lines()
        .filter(|line| line.contains("timer wake-up lateness") || line.contains("deadline miss"))
        .map(|line| {
            line.split_once(": ")
                .map_or(line, |(_, rest)| rest)
                .to_owned()
        })
        .collect()
}

/// Runs walkd + walk-sim at `rate_hz` for `seconds` and returns what the daemon measured.
fn measure(args: &Args, walk: &str, rate_hz: f64, load: Load) -> anyhow::Result<Measurement> {
    let launch = Launch {
        bin_dir: executable_dir()?,
        config: args.config.clone(),
        prefix: format!("walk-latency/{}/{}", std::process::id(), rate_hz as u64),
        clock: ClockMode::Realtime,
        rate_hz: Some(rate_hz),
        urdf: None,
    };
    let prefix = launch.prefix.clone();
    let mut walkd_args = Vec::new();
    if let Some(priority) = args.fifo_priority {
        walkd_args.extend(["--fifo-priority".to_owned(), priority.to_string()]);
    }
    if let Some(spin_us) = args.spin_us {
        walkd_args.extend(["--spin-us".to_owned(), spin_us.to_string()]);
    }
    let load_average = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|text| text.split_whitespace().next().map(str::to_owned))
        .unwrap_or_else(|| "?".to_owned());
    let _load = match load {
        Load::Idle => None,
        Load::Busy => Some(start_load()?),
    };
    let walkd_args: Vec<&str> = walkd_args.iter().map(String::as_str).collect();
    let walkd = launch.walkd(&walkd_args, &[])?;
    let walkd_pid = walkd.pid();
    let mut system = Processes(vec![walkd]);
    let sim = launch.walk_sim_args(Physics::Kinematic);
    system.0.push(match args.fifo_priority {
        // A real-time adapter: one priority below walkd's control thread.
        Some(priority) => {
            let mut chrt_args: Vec<OsString> =
                vec!["-f".into(), (priority - 1).max(1).to_string().into()];
            chrt_args.push(launch.bin_dir.join("walk-sim").into());
            chrt_args.extend(sim);
            Process::start(Path::new("chrt"), chrt_args, &[])?
        }
        None => launch.walk_sim(Physics::Kinematic, &[])?,
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
        .accepted
        .is_set();
    let (cpu_start, wall_start) = (cpu_seconds(walkd_pid)?, Instant::now());
    std::thread::sleep(Duration::from_secs(args.seconds));
    let walkd_cpu_percent =
        100.0 * (cpu_seconds(walkd_pid)? - cpu_start) / wall_start.elapsed().as_secs_f64();
    let status = client
        .control(ControlCommand::Query, Duration::from_secs(5))?
        .status;
    system.0.pop().map(Process::stop).transpose()?;
    let log = system.0.pop().context("walkd")?.stop()?.log;
    Ok(Measurement {
        status,
        walking,
        timing_log: timing_lines(&log),
        load_average,
        walkd_cpu_percent,
    })
}

/// CPU time (user + system, all threads) process `pid` used so far, from `/proc/<pid>/stat`.
fn cpu_seconds(pid: u32) -> anyhow::Result<f64> {
    let path = format!("/proc/{pid}/stat");
    let stat = std::fs::read_to_string(&path).with_context(|| format!("cannot read {path}"))?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let fields: Vec<&str> = stat
        .rsplit_once(')')
        .map_or("", |(_, rest)| rest)
        .split_whitespace()
        .collect();
    let ticks = |index: usize| -> anyhow::Result<f64> {
        fields
            .get(index)
            .and_then(|field| field.parse::<f64>().ok())
            .with_context(|| format!("{path}: field {} is not a number", index + 3))
    };
    // SAFETY: sysconf has no memory-safety preconditions.
    let ticks_per_second = unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64;
    Ok((ticks(11)? + ticks(12)?) / ticks_per_second)
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
         SCHED_FIFO: {}; walkd spin: {}.\n",
        args.seconds,
        args.config.display(),
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        args.fifo_priority.map_or("off".to_owned(), |p| format!(
            "walkd {p}, walk-sim {}",
            (p - 1).max(1)
        )),
        args.spin_us
            .map_or("[runtime] spin_us of the config".to_owned(), |us| format!(
                "{us} µs"
            )),
    );
    println!(
        "| rate | load | load avg at start | walking | ticks | deadline misses | stale periods | tick p50/p99/max (µs) | sensor→command p50/p99/max (µs) | jitter p50/p99/max (µs) | p99 latency − p99 tick (µs) | walkd CPU |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut details = String::new();
    for &rate in &args.rates {
        for &load in &args.loads {
            let Measurement {
                status: s,
                walking,
                timing_log,
                load_average,
                walkd_cpu_percent,
            } = measure(&args, &walk, rate, load)?;
            let triple =
                |l: &shm_types::LatencySummary| format!("{:.1}/{:.1}/{:.1}", l.p50, l.p99, l.max);
            println!(
                "| {rate} Hz | {} | {load_average} | {} ({}) | {} | {} | {} | {} | {} | {} | {:.1} | {walkd_cpu_percent:.0} % |",
                load.describe(),
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
            details.push_str(&format!("\n## {rate} Hz, {}\n\n", load.describe()));
            details.push_str(&histogram_rows(
                "sensor→command latency",
                &s.latency_histogram,
            ));
            details.push('\n');
            details.push_str(&histogram_rows("tick jitter", &s.jitter_histogram));
            details.push('\n');
            details.push_str(&histogram_rows("tick compute time", &s.tick_histogram));
            details.push_str("\nwalkd's timing log (µs; a miss: timer wake-up lateness, sample stamp − expected, stamp → picked up, tick, command after deadline):\n\n```text\n");
            for line in &timing_log {
                details.push_str(line);
                details.push('\n');
            }
            details.push_str("```\n");
        }
    }
    println!("{details}");
    Ok(())
}
