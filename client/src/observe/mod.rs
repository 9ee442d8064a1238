//! The observer: `walkctl record` and `walkctl view`, and `--record` of `walkctl demo` and
//! `walkctl evaluate`.
//!
//! An observer is an extra subscriber of a running daemon's `telemetry`, `sensors`, `commands`
//! and `status` services (it polls; it adds no event listener, so walkd's control loop does no
//! extra work for it). It turns what it reads into Foxglove channels — a transform for every link
//! from the measured joint angles and the estimated base, joints, wrenches, the controller's
//! estimate and targets, the support polygon, ZMP/DCM, phases, faults, timing and the robot's
//! description — and logs them to a Foxglove SDK context whose sinks are an MCAP file
//! ([`Recording`]) or the Foxglove WebSocket server ([`LiveView`]), or both. walkd itself opens
//! no socket and writes no file. `docs/observe.md` documents every channel.
//!
//! Modules: [`source`] polls the services, [`observer`] pairs and logs, [`channels`] (with
//! [`links`], [`scene`], [`schemas`], [`description`]) builds the messages, [`mcap_sink`] and
//! [`live`] are the sinks, [`report`] counts what was received and lost.

pub mod channels;
pub mod description;
pub mod links;
pub mod live;
pub mod mcap_sink;
pub mod observer;
pub mod report;
pub mod scene;
pub mod schemas;
pub mod source;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context as _;
use foxglove::Context;
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use shm_types::RuntimeConfig;

use crate::args::DURATION_S;
use shm_types::process::{install_termination_handler, termination_requested};

pub use live::LiveView;
pub use mcap_sink::{RecordedChannel, Recording, RecordingSummary};
pub use observer::Observer;
pub use report::ObserverReport;

/// Which daemon to observe and the robot it controls.
#[derive(Debug, Clone, clap::Args)]
pub struct ObserveTarget {
    /// Robot config: the robot model (for the link transforms and the description) and
    /// `[runtime] service_prefix`.
    #[arg(long)]
    pub config: PathBuf,
    /// URDF overriding the config's (required for HRP-4).
    #[arg(long)]
    pub urdf: Option<PathBuf>,
    /// Service prefix of the daemon, overriding the config's.
    #[arg(long)]
    pub service_prefix: Option<String>,
}

impl ObserveTarget {
    /// The service prefix and the robot.
    pub fn load(&self) -> anyhow::Result<(String, Arc<Robot>)> {
        let file = ConfigFile::load(&self.config)?;
        let runtime = RuntimeConfig::from_section(file.section("runtime"), &file.origin())?;
        let robot = Robot::from_config(&file, self.urdf.as_deref())?;
        let prefix = self
            .service_prefix
            .clone()
            .unwrap_or(runtime.service_prefix);
        Ok((prefix, Arc::new(robot)))
    }
}

/// Arguments of `walkctl record`.
#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    #[command(flatten)]
    pub target: ObserveTarget,
    /// The MCAP file to write (replaced if it exists).
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: PathBuf,
    /// Stop after this many seconds, 0.01-1e6 (default: at SIGINT / SIGTERM).
    #[arg(long, value_name = "S", value_parser = DURATION_S.parser())]
    pub duration: Option<f64>,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `walkctl view`.
#[derive(Debug, clap::Args)]
pub struct ViewArgs {
    #[command(flatten)]
    pub target: ObserveTarget,
    /// Address to listen on (127.0.0.1: this machine only).
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Port of the Foxglove WebSocket server.
    #[arg(long, default_value_t = 8765)]
    pub port: u16,
    /// Stop after this many seconds, 0.01-1e6 (default: at SIGINT / SIGTERM).
    #[arg(long, value_name = "S", value_parser = DURATION_S.parser())]
    pub duration: Option<f64>,
    /// Also record to this MCAP file.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
}

/// An observer writing an MCAP file: the recorder of `walkctl record`, `demo --record` and
/// `evaluate --record`.
pub struct Recorder {
    recording: Recording,
    observer: Observer,
    _context: Arc<Context>,
}

/// What a finished recorder wrote and saw.
#[derive(Debug, Clone)]
pub struct RecorderOutcome {
    /// The file's summary.
    pub summary: RecordingSummary,
    /// What the observer received and lost.
    pub report: ObserverReport,
}

impl Recorder {
    /// Starts recording the daemon on `prefix` (controlling `robot`) to `path`.
    pub fn start(prefix: &str, robot: Arc<Robot>, path: &Path) -> anyhow::Result<Self> {
        let context = Context::new();
        let recording = Recording::create(path, &context)?;
        let observer = Observer::start(prefix, robot, &context)?;
        Ok(Self {
            recording,
            observer,
            _context: context,
        })
    }

    /// Whether a write to the file failed: the recording is over (see [`Recorder::finish`]).
    pub fn failed(&self) -> bool {
        self.recording.failed()
    }

    /// Stops observing, writes the observer's report as the metadata record `observer` and
    /// finishes the file.
    pub fn finish(self) -> anyhow::Result<RecorderOutcome> {
        let report = self.observer.finish()?;
        let metadata: BTreeMap<String, String> = report
            .json()
            .as_object()
            .into_iter()
            .flatten()
            .map(|(k, v)| (k.clone(), v.to_string()))
            .collect();
        self.recording.metadata("observer", metadata)?;
        let summary = self.recording.finish()?;
        Ok(RecorderOutcome { summary, report })
    }
}

/// Waits until `duration` (if any) passes, SIGINT / SIGTERM arrives or the recording `failed`.
fn wait_for_end(duration: Option<f64>, failed: impl Fn() -> bool) {
    install_termination_handler();
    let start = Instant::now();
    while !termination_requested()
        && !failed()
        && duration.is_none_or(|d| start.elapsed().as_secs_f64() < d)
    {
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `walkctl record`: records the daemon's streams to an MCAP file until the duration ends, a
/// signal arrives or a write fails, then prints what the file holds (or why it failed).
pub fn run_record(args: &RecordArgs) -> anyhow::Result<()> {
    let (prefix, robot) = args.target.load()?;
    let recorder = Recorder::start(&prefix, robot, &args.output)?;
    if !args.json {
        eprintln!(
            "recording walkd on `{prefix}` to {}{}",
            args.output.display(),
            args.duration
                .map_or_else(|| " until Ctrl-C".to_owned(), |d| format!(" for {d} s"))
        );
    }
    wait_for_end(args.duration, || recorder.failed());
    let outcome = recorder.finish()?;
    print_outcome(&outcome, args.json);
    Ok(())
}

/// Prints a recorder's outcome (text or one JSON object).
pub fn print_outcome(outcome: &RecorderOutcome, json: bool) {
    if json {
        let channels: serde_json::Map<String, serde_json::Value> = outcome
            .summary
            .channels
            .iter()
            .map(|c| (c.topic.clone(), c.messages.into()))
            .collect();
        println!(
            "{}",
            serde_json::json!({
                "file": outcome.summary.path,
                "bytes": outcome.summary.bytes,
                "messages": outcome.summary.messages,
                "duration_s": outcome.summary.duration_s(),
                "channels": channels,
                "observer": outcome.report.json(),
            })
        );
    } else {
        print!("{}", outcome.summary);
        println!("observer:\n{}", outcome.report);
    }
}

/// `walkctl view`: serves the daemon's streams live over the Foxglove WebSocket protocol (and
/// records them with `--record`) until the duration ends or a signal arrives.
pub fn run_view(args: &ViewArgs) -> anyhow::Result<()> {
    let (prefix, robot) = args.target.load()?;
    let context = Context::new();
    let live = LiveView::serve(&context, &args.host, args.port)?;
    let recording = args
        .record
        .as_deref()
        .map(|path| Recording::create(path, &context))
        .transpose()?;
    let observer = Observer::start(&prefix, robot, &context)
        .with_context(|| format!("observing walkd on `{prefix}`"))?;
    eprintln!(
        "serving walkd on `{prefix}` at ws://{}:{} — in Foxglove: Open connection → Foxglove \
         WebSocket → ws://{}:{}",
        args.host,
        live.port(),
        args.host,
        live.port()
    );
    wait_for_end(args.duration, || {
        recording.as_ref().is_some_and(Recording::failed)
    });
    let report = observer.finish()?;
    live.stop();
    if let Some(recording) = recording {
        print!("{}", recording.finish()?);
    }
    println!("observer:\n{report}");
    Ok(())
}
