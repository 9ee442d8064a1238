//! Helpers for the multi-process end-to-end tests: find the binaries, start and stop real
//! `walkd` / `walk-sim` / `walkctl` processes on a service prefix of their own, and talk to the
//! daemon through the client library.
//!
//! The binaries come from `WALK_BIN_DIR`, else from the workspace's `target/release` (build them
//! first: `cargo build --release --bins`).

/// Peers that write raw message bytes to walkd's services.
pub mod hostile;

use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use client::daemon_client::DaemonClient;
use client::process::{Launch, Process};
use shm_types::DaemonStatus;
use shm_types::process::Physics;

/// The workspace root.
pub fn workspace_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Where the binaries under test are.
pub fn bin_dir() -> PathBuf {
    std::env::var_os("WALK_BIN_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_dir().join("target/release"))
}

/// `configs/<robot>.toml`.
pub fn config(robot: &str) -> PathBuf {
    workspace_dir()
        .join("configs")
        .join(format!("{robot}.toml"))
}

/// A service prefix no other test (or test run) uses.
pub fn unique_prefix(test: &str) -> String {
    format!("walk-e2e/{test}/{}", std::process::id())
}

/// How a test starts walkd and walk-sim for `robot` on `prefix`.
fn launch(robot: &str, prefix: &str, clock: &str, rate_hz: f64) -> Launch {
    Launch {
        bin_dir: bin_dir(),
        config: config(robot),
        prefix: prefix.to_owned(),
        clock: clock.parse().expect("realtime or lockstep"),
        rate_hz: Some(rate_hz),
        urdf: None,
    }
}

/// Starts `walkd` for `robot` on `prefix` (memory locking off: tests run unprivileged).
pub fn start_walkd(
    robot: &str,
    prefix: &str,
    clock: &str,
    rate_hz: f64,
) -> anyhow::Result<Process> {
    start_walkd_with_env(robot, prefix, clock, rate_hz, &[])
}

/// Starts `walkd` like [`start_walkd`], with extra environment variables (e.g. systemd's
/// `NOTIFY_SOCKET`).
pub fn start_walkd_with_env(
    robot: &str,
    prefix: &str,
    clock: &str,
    rate_hz: f64,
    env: &[(&str, &std::ffi::OsStr)],
) -> anyhow::Result<Process> {
    check_binaries()?;
    launch(robot, prefix, clock, rate_hz).walkd(&["--no-lock-memory"], env)
}

/// Starts `walk-sim --physics kinematic` for `robot` on `prefix`.
pub fn start_sim(robot: &str, prefix: &str, clock: &str, rate_hz: f64) -> anyhow::Result<Process> {
    check_binaries()?;
    launch(robot, prefix, clock, rate_hz).walk_sim(Physics::Kinematic, &[])
}

/// Fails with how to build them if the binaries under test are missing.
fn check_binaries() -> anyhow::Result<()> {
    for binary in ["walkd", "walk-sim", "walkctl"] {
        let path = bin_dir().join(binary);
        anyhow::ensure!(
            path.is_file(),
            "{} missing: build the binaries first (cargo build --release --bins) or set WALK_BIN_DIR",
            path.display()
        );
    }
    Ok(())
}

/// Polls `condition` every 10 ms until it holds or `timeout` passes (then the error names `what`).
pub fn wait_until<T>(
    what: &str,
    timeout: Duration,
    mut condition: impl FnMut() -> Option<T>,
) -> anyhow::Result<T> {
    let start = Instant::now();
    loop {
        if let Some(value) = condition() {
            return Ok(value);
        }
        if start.elapsed() > timeout {
            bail!("timed out after {timeout:?} waiting for {what}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Connects to the daemon on `prefix` once it serves and its adapter link is fresh.
pub fn connect_when_fresh(prefix: &str, timeout: Duration) -> anyhow::Result<DaemonClient> {
    client::daemon_client::connect_when_fresh(prefix, &[], timeout)
}

/// Connects to the daemon on `prefix`, whatever its adapter link.
pub fn connect(prefix: &str) -> anyhow::Result<DaemonClient> {
    DaemonClient::connect(prefix)
}

/// Runs `walkctl` with `args` to its end; its stdout, or an error with its stderr.
pub fn run_walkctl(args: &[&str]) -> anyhow::Result<String> {
    let output = Command::new(bin_dir().join("walkctl"))
        .args(args)
        .output()
        .context("cannot run walkctl")?;
    if !output.status.success() {
        bail!(
            "walkctl {} failed ({}): {}",
            args.join(" "),
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// Polls the daemon's status until `condition` holds.
pub fn wait_for_status(
    client: &DaemonClient,
    what: &str,
    timeout: Duration,
    condition: impl Fn(&DaemonStatus) -> bool,
) -> anyhow::Result<DaemonStatus> {
    wait_until(what, timeout, || {
        client.status().ok().filter(|s| condition(s))
    })
}

/// How long a test waits for walkd and walk-sim to come up and link.
const START: Duration = Duration::from_secs(20);

/// Starts walkd and walk-sim for `robot` on `prefix` at 500 Hz on `clock` (`realtime` or
/// `lockstep`); returns (walkd, walk-sim, a client) once the adapter link is fresh.
pub fn start_connected(
    robot: &str,
    prefix: &str,
    clock: &str,
) -> anyhow::Result<(Process, Process, DaemonClient)> {
    let walkd = start_walkd(robot, prefix, clock, 500.0)?;
    let sim = start_sim(robot, prefix, clock, 500.0)?;
    let client = connect_when_fresh(prefix, START)?;
    Ok((walkd, sim, client))
}

/// Starts walkd and walk-sim for `robot` on `prefix` in real time at 500 Hz and submits a walk of
/// `distance` metres; returns (walkd, walk-sim, a client) once it executes.
pub fn start_walking(
    robot: &str,
    prefix: &str,
    distance: f64,
) -> anyhow::Result<(Process, Process, DaemonClient)> {
    let (walkd, sim, client) = start_connected(robot, prefix, "realtime")?;
    let (json, _) = walk_json(robot, distance)?;
    client.submit_json(&json)?;
    wait_for_status(&client, "executing", START, |s| {
        s.state == shm_types::DaemonState::Executing
    })?;
    Ok((walkd, sim, client))
}

/// Sends SIGTERM to `process` and asserts that it exits with status 0 within `within` (its log
/// otherwise).
pub fn assert_terminates(process: &Process, within: Duration) {
    process.signal(libc::SIGTERM);
    let exit = process.wait_exit(within);
    assert_eq!(exit.and_then(|s| s.code()), Some(0), "{}", process.log());
}

/// A post-processed forward walk of `distance` metres for `robot` (JSON) and its stance count.
pub fn walk_json(robot: &str, distance: f64) -> anyhow::Result<(String, usize)> {
    let file = kinematics::ConfigFile::load(&config(robot))?;
    let model = kinematics::robot::Robot::from_config(&file, None)?;
    let sequence = client::demo::walk_sequence(&model, &file, distance, 1, stance::Gait::Static)?;
    Ok((sequence.to_json_string(), sequence.len()))
}
