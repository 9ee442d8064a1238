//! The daemon process: `walkd --config CONFIG [--urdf PATH] [--rate-hz F] [--clock realtime|lockstep]`.
//!
//! Threads:
//! - the **control thread** ([`control_loop`]) waits for sensor samples, ticks the controller at a
//!   fixed rate (or once per sample in lockstep), sends joint commands and, after each command,
//!   the tick's telemetry for observers ([`telemetry`]); it allocates, frees, locks and logs
//!   nothing per tick;
//! - the **main thread** ([`service`]) serves sequence submissions and control requests, publishes
//!   the status at `[runtime] status_rate_hz`, and talks to systemd.
//!
//! They share only lock-free slots and atomics ([`shared`], [`handoff`], [`snapshot`], and
//! [`trust`]: the adapter walkd follows, pinned by its iceoryx2 identity).
//!
//! Monitoring cannot stop control: when `telemetry` or `status` has no free publisher slot (or
//! `telemetry` cannot be opened), walkd starts and controls without it, and says so once in its
//! log and in the status.
//!
//! Signals: SIGTERM / SIGINT → the controller holds, a final hold command and a final `stopping`
//! status go out, services are released, exit 0.
//!
//! Exit codes ([`shm_types::process::exit_code`]): 0 clean shutdown, 1 runtime failure,
//! 2 bad command line, 3 config or model error, 4 IPC error (e.g. a peer of another protocol
//! version), 5 controller could not be built.

mod control_loop;
pub mod decode;
mod fault_log;
mod handoff;
mod realtime;
mod sample_gate;
mod service;
mod shared;
mod snapshot;
mod stats;
mod telemetry;
mod trust;

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::Ordering;

use kinematics::ConfigFile;
use kinematics::robot::Robot;
use shm_types::process::{exit_code, install_termination_handler, termination_requested};
use shm_types::{
    ClockMode, DaemonLoopPorts, DaemonServicePorts, DaemonStatus, RuntimeConfig, RuntimeOverrides,
    ServiceNames,
};

use crate::controller::{Controller, ControllerConfig, GaitConfig, SolverKind};
use control_loop::{ControlLoop, LoopTiming};
use service::{Acceptance, ServiceLoop, SubmissionLimits};
use shared::Shared;

/// Command line of the daemon: `walkd`'s whole command line.
#[derive(Debug, Clone, clap::Parser)]
#[command(name = "walkd", version, about = "The real-time walking daemon.")]
pub struct DaemonArgs {
    /// Robot config file (`[robot]`, `[controller]` and `[runtime]` are used).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// URDF overriding the one named in the config (required for HRP-4).
    #[arg(long)]
    pub urdf: Option<PathBuf>,
    /// Control rate, overriding `[runtime] rate_hz`.
    #[arg(long)]
    pub rate_hz: Option<f64>,
    /// realtime: fixed rate on absolute deadlines; lockstep: one tick per received sample.
    #[arg(long, default_value = "realtime")]
    pub clock: ClockMode,
    /// Service prefix, overriding `[runtime] service_prefix` (e.g. to run several daemons).
    #[arg(long)]
    pub service_prefix: Option<String>,
    /// SCHED_FIFO priority of the control thread, overriding `[runtime] fifo_priority`.
    #[arg(long)]
    pub fifo_priority: Option<i32>,
    /// CPU to pin the control thread to, overriding `[runtime] cpu`.
    #[arg(long)]
    pub cpu: Option<usize>,
    /// Skip `mlockall` even if `[runtime] lock_memory = true`.
    #[arg(long)]
    pub no_lock_memory: bool,
    /// Busy-wait time around each expected sample (µs), overriding `[runtime] spin_us`.
    #[arg(long)]
    pub spin_us: Option<u32>,
    /// Replaces one config value before it is checked, `section.key=value` (repeatable): e.g.
    /// the stabilizer parts a kinematic simulator's rigid robot cannot use
    /// (`client::process::kinematic_sim_settings`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
}

impl DaemonArgs {
    /// The flags that replace `[runtime]` keys.
    pub fn runtime_overrides(&self) -> RuntimeOverrides {
        RuntimeOverrides {
            rate_hz: self.rate_hz,
            service_prefix: self.service_prefix.clone(),
            fifo_priority: self.fifo_priority,
            cpu: self.cpu,
            spin_us: self.spin_us,
        }
    }
}

/// A failure with the exit code it maps to.
struct Failure {
    code: u8,
    error: anyhow::Error,
}

fn fail(code: u8) -> impl FnOnce(anyhow::Error) -> Failure {
    move |error| Failure { code, error }
}

/// Runs the daemon until SIGTERM / SIGINT; returns the documented exit code.
pub fn main(args: &DaemonArgs) -> ExitCode {
    let (writer, _log_guard) = tracing_appender::non_blocking(std::io::stderr());
    tracing_subscriber::fmt()
        .with_writer(writer)
        .with_ansi(false)
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info")),
        )
        .init();
    match run(args) {
        Ok(()) => ExitCode::from(exit_code::OK),
        Err(Failure { code, error }) => {
            tracing::error!("{error:#}");
            ExitCode::from(code)
        }
    }
}

/// Everything loaded from the config before any thread starts.
struct Setup {
    runtime: RuntimeConfig,
    robot: Arc<Robot>,
    controller_config: ControllerConfig,
    gaits: GaitConfig,
}

fn load(args: &DaemonArgs) -> Result<Setup, Failure> {
    let config = args.config.as_deref().ok_or_else(|| {
        fail(exit_code::USAGE)(anyhow::anyhow!(
            "--config CONFIG is required to run the daemon"
        ))
    })?;
    // The config file is read and parsed once; each part validates its own section.
    let mut file = ConfigFile::load(config).map_err(|e| fail(exit_code::CONFIG)(e.into()))?;
    for assignment in &args.overrides {
        file.set(assignment)
            .map_err(|e| fail(exit_code::USAGE)(anyhow::Error::from(e).context("--set")))?;
    }
    let runtime = RuntimeConfig::from_section(file.section("runtime"), &file.origin())
        .map_err(|e| fail(exit_code::CONFIG)(e.into()))?;
    let mut runtime = args
        .runtime_overrides()
        .apply(runtime)
        .map_err(|e| fail(exit_code::USAGE)(e.into()))?;
    runtime.lock_memory &= !args.no_lock_memory;
    let robot = Robot::from_config(&file, args.urdf.as_deref())
        .map_err(|e| fail(exit_code::CONFIG)(e.into()))?;
    let controller_config =
        ControllerConfig::from_config(&file).map_err(|e| fail(exit_code::CONFIG)(e.into()))?;
    let gaits = GaitConfig::from_config(&file).map_err(|e| fail(exit_code::CONFIG)(e.into()))?;
    Ok(Setup {
        runtime,
        robot: Arc::new(robot),
        controller_config,
        gaits,
    })
}

fn run(args: &DaemonArgs) -> Result<(), Failure> {
    let Setup {
        runtime,
        robot,
        controller_config,
        gaits,
    } = load(args)?;
    let controller = Controller::new(Arc::clone(&robot), controller_config, SolverKind::Dense)
        .map_err(|e| fail(exit_code::CONTROLLER)(e.into()))?;
    let names = ServiceNames::new(&runtime.service_prefix)
        .map_err(|e| fail(exit_code::CONFIG)(e.into()))?;
    install_termination_handler();
    if runtime.lock_memory {
        realtime::lock_memory();
    }
    let ports =
        DaemonServicePorts::open(&names, "walkd").map_err(|e| fail(exit_code::IPC)(e.into()))?;
    if ports.cleaned_dead_nodes() > 0 {
        tracing::warn!(
            nodes = ports.cleaned_dead_nodes(),
            "removed stale iceoryx2 resources of dead processes (e.g. a killed walkd)"
        );
    }
    if let Some(error) = ports.status_off() {
        tracing::warn!(
            "status publication off: {error}; walkd controls without it (clients ask for the \
             status instead)"
        );
    }
    let shared = Arc::new(Shared::new());
    let (status_out, status_in) = snapshot::snapshot(DaemonStatus::INITIAL);
    let timing = LoopTiming {
        clock: args.clock,
        period_ns: (1e9 / runtime.rate_hz) as u64,
        watchdog_periods: runtime.watchdog_periods,
        lockstep_timeout_ns: runtime.lockstep_timeout_ms * 1_000_000,
        status_interval_ns: (1e9 / runtime.status_rate_hz) as u64,
        spin_ns: u64::from(runtime.spin_us) * 1000,
    };
    let (control_thread, telemetry_off) =
        spawn_control_thread(&names, &runtime, controller, &shared, status_out, timing)?;
    if let Some(error) = &telemetry_off {
        tracing::warn!(
            "telemetry off: {error}; walkd controls without it (observers get no telemetry)"
        );
    }
    let mut service = ServiceLoop::new(
        ports,
        Arc::clone(&shared),
        status_in,
        Acceptance {
            robot,
            config: controller_config,
            gaits,
            limits: SubmissionLimits {
                max_bytes: runtime.max_submission_bytes,
                max_stances: runtime.max_stances,
            },
        },
        runtime.status_rate_hz,
        telemetry_off.is_some(),
    );
    let _ = sd_notify::notify(&[sd_notify::NotifyState::Ready]);
    tracing::info!(
        prefix = names.prefix(),
        clock = args.clock.name(),
        rate_hz = runtime.rate_hz,
        "walkd ready"
    );
    let served = service.run(|| !termination_requested() && !control_thread.is_finished());
    let _ = sd_notify::notify(&[sd_notify::NotifyState::Stopping]);
    shared.stop.store(true, Ordering::Relaxed);
    let stats = control_thread
        .join()
        .map_err(|_| fail(exit_code::FAILURE)(anyhow::anyhow!("the control thread panicked")))?;
    // The control thread wrote its final `stopping` status; publish it before releasing services.
    service
        .publish_status()
        .map_err(|e| fail(exit_code::IPC)(e.into()))?;
    served.map_err(|e| fail(exit_code::IPC)(e.into()))?;
    let stats = stats.map_err(|e| fail(exit_code::IPC)(e.into()))?;
    log_timing(&stats);
    tracing::info!(
        ticks = stats.ticks,
        deadline_misses = stats.deadline_misses,
        stale_periods = stats.stale_periods,
        watchdog_trips = stats.watchdog_trips,
        telemetry_failures = stats.telemetry_failures,
        "walkd stopped"
    );
    Ok(())
}

/// Logs the timer wake-up lateness and how each recorded deadline miss came about, so a
/// latency report can tell OS wake-up stalls from late samples and long ticks.
fn log_timing(stats: &stats::LoopStats) {
    if !stats.wakeup.is_empty() {
        let us = |ns: u64| ns as f64 / 1000.0;
        let wakeup = &stats.wakeup;
        tracing::info!(
            p50_us = us(wakeup.value_at_quantile(0.5)),
            p99_us = us(wakeup.value_at_quantile(0.99)),
            p999_us = us(wakeup.value_at_quantile(0.999)),
            max_us = us(wakeup.max()),
            over_100us = wakeup.count_between(100_000, u64::MAX),
            over_500us = wakeup.count_between(500_000, u64::MAX),
            over_1ms = wakeup.count_between(1_000_000, u64::MAX),
            count = wakeup.len(),
            "timer wake-up lateness"
        );
    }
    if stats.deadline_misses > 0 {
        let causes = stats.miss_causes;
        tracing::info!(
            adapter_late = causes.adapter_late,
            pickup = causes.pickup,
            tick = causes.tick,
            "deadline miss causes (periods with a late command; swallowed periods not included)"
        );
    }
    for miss in stats.misses.records() {
        tracing::info!(
            at_s = miss.at_ns as f64 * 1e-9,
            wake_late_us = miss.wake_late_ns as f64 / 1000.0,
            sample_offset_us = miss.sample_offset_ns as f64 / 1000.0,
            pickup_us = miss.pickup_ns as f64 / 1000.0,
            tick_us = miss.tick_ns as f64 / 1000.0,
            late_us = miss.late_ns as f64 / 1000.0,
            "deadline miss"
        );
    }
}

/// The control thread, as [`spawn_control_thread`] started it.
type ControlThread = std::thread::JoinHandle<Result<stats::LoopStats, shm_types::ShmError>>;

/// Starts the control thread; returns once its ports are open (or failed to open), with why it
/// publishes no telemetry (if it does not).
fn spawn_control_thread(
    names: &ServiceNames,
    runtime: &RuntimeConfig,
    controller: Controller,
    shared: &Arc<Shared>,
    status_out: snapshot::SnapshotWriter<DaemonStatus>,
    mut timing: LoopTiming,
) -> Result<(ControlThread, Option<String>), Failure> {
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let names = names.clone();
    let shared = Arc::clone(shared);
    let (priority, cpu) = (runtime.fifo_priority, runtime.cpu);
    let thread = std::thread::Builder::new()
        .name("walkd-control".to_owned())
        .spawn(move || {
            realtime::minimize_timer_slack();
            if let Some(cpu) = cpu {
                realtime::pin_to_cpu(cpu);
            }
            let fifo = priority.is_some_and(realtime::set_fifo_priority);
            if timing.spin_ns > 0 && !fifo {
                // Under normal scheduling a busy-waiting thread only takes CPU time from the
                // adapter and everything else (measured: more deadline misses, not fewer).
                tracing::warn!(
                    spin_us = timing.spin_ns / 1000,
                    "spin_us ignored: busy-waiting needs the control thread on SCHED_FIFO (fifo_priority)"
                );
                timing.spin_ns = 0;
            }
            let ports = match DaemonLoopPorts::open(&names, "walkd-control") {
                Ok(ports) => {
                    let _ = ready_tx.send(Ok(ports.telemetry_off().map(ToString::to_string)));
                    ports
                }
                Err(error) => {
                    let _ = ready_tx.send(Err(error));
                    return Ok(stats::LoopStats::new());
                }
            };
            ControlLoop::new(controller, ports, shared, status_out, timing).run()
        })
        .map_err(|e| fail(exit_code::FAILURE)(e.into()))?;
    match ready_rx.recv() {
        Ok(Ok(telemetry_off)) => Ok((thread, telemetry_off)),
        Ok(Err(error)) => Err(fail(exit_code::IPC)(error.into())),
        Err(_) => Err(fail(exit_code::FAILURE)(anyhow::anyhow!(
            "the control thread died at start"
        ))),
    }
}
