//! Helpers for the multi-process end-to-end tests: find the binaries, start and stop real
//! `walkd` / `walk-sim` / `walkctl` processes on a service prefix of their own, and talk to the
//! daemon through the client library.
//!
//! The binaries come from `WALK_BIN_DIR`, else from the workspace's `target/release` (build them
//! first: `cargo build --release --bins`).

/// Peers that write raw message bytes to walkd's services.
pub mod hostile;
/// The controller walking under MuJoCo physics, in one process (feature `mujoco`).
#[cfg(feature = "mujoco")]
pub mod physics;

use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use client::daemon_client::DaemonClient;
use shm_types::{DaemonStatus, LinkState};

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

/// A child process that is killed if the test ends while it still runs. Its stderr goes to a
/// log file that [`Proc::log`] returns for failure messages.
pub struct Proc {
    name: String,
    child: Child,
    log: PathBuf,
}

impl Proc {
    /// Starts `binary` (from [`bin_dir`]) with `args`.
    pub fn start(binary: &str, args: &[String]) -> anyhow::Result<Self> {
        Self::start_with_env(binary, args, &[])
    }

    /// Starts `binary` like [`Proc::start`], with extra environment variables (e.g. systemd's
    /// `NOTIFY_SOCKET`).
    pub fn start_with_env(
        binary: &str,
        args: &[String],
        env: &[(&str, &std::ffi::OsStr)],
    ) -> anyhow::Result<Self> {
        let path = bin_dir().join(binary);
        anyhow::ensure!(
            path.is_file(),
            "{} missing: build the binaries first (cargo build --release --bins) or set WALK_BIN_DIR",
            path.display()
        );
        static COUNTER: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let log =
            std::env::temp_dir().join(format!("walk-e2e-{}-{binary}-{n}.log", std::process::id()));
        let child = Command::new(&path)
            .args(args)
            .envs(env.iter().copied())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log)?)
            .spawn()
            .with_context(|| format!("cannot start {}", path.display()))?;
        Ok(Self {
            name: binary.to_owned(),
            child,
            log,
        })
    }

    /// Process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Sends `signal` (e.g. `libc::SIGTERM`, `libc::SIGKILL`).
    pub fn signal(&self, signal: i32) {
        // SAFETY: kill on our own child's pid has no memory-safety preconditions.
        unsafe { libc::kill(self.child.id() as libc::pid_t, signal) };
    }

    /// Whether the process still runs.
    pub fn is_running(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }

    /// Waits up to `timeout` for the exit; `None` if it still runs.
    pub fn wait_exit(&mut self, timeout: Duration) -> Option<ExitStatus> {
        let start = Instant::now();
        loop {
            if let Ok(Some(status)) = self.child.try_wait() {
                return Some(status);
            }
            if start.elapsed() > timeout {
                return None;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// Waits until the process's stderr contains `text`.
    pub fn wait_for_log(&self, text: &str, timeout: Duration) -> anyhow::Result<()> {
        wait_until(
            &format!("`{text}` in the log of {}", self.name),
            timeout,
            || {
                std::fs::read_to_string(&self.log)
                    .ok()
                    .filter(|log| log.contains(text))
                    .map(|_| ())
            },
        )
        .with_context(|| self.log())
    }

    /// The process's stderr so far (for failure messages).
    pub fn log(&self) -> String {
        let text = std::fs::read_to_string(&self.log).unwrap_or_default();
        format!("--- {} stderr ---\n{text}", self.name)
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        if self.is_running() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
        let _ = std::fs::remove_file(&self.log);
    }
}

/// Common arguments of walkd and walk-sim.
fn process_args(robot: &str, prefix: &str, clock: &str, rate_hz: f64) -> Vec<String> {
    vec![
        "--config".into(),
        config(robot).display().to_string(),
        "--service-prefix".into(),
        prefix.into(),
        "--clock".into(),
        clock.into(),
        "--rate-hz".into(),
        rate_hz.to_string(),
    ]
}

/// Starts `walkd` for `robot` on `prefix` (memory locking off: tests run unprivileged).
pub fn start_walkd(robot: &str, prefix: &str, clock: &str, rate_hz: f64) -> anyhow::Result<Proc> {
    start_walkd_with_env(robot, prefix, clock, rate_hz, &[])
}

/// Starts `walkd` like [`start_walkd`], with extra environment variables.
pub fn start_walkd_with_env(
    robot: &str,
    prefix: &str,
    clock: &str,
    rate_hz: f64,
    env: &[(&str, &std::ffi::OsStr)],
) -> anyhow::Result<Proc> {
    let mut args = process_args(robot, prefix, clock, rate_hz);
    args.push("--no-lock-memory".into());
    Proc::start_with_env("walkd", &args, env)
}

/// Starts `walk-sim --physics kinematic` for `robot` on `prefix`.
pub fn start_sim(robot: &str, prefix: &str, clock: &str, rate_hz: f64) -> anyhow::Result<Proc> {
    let mut args = process_args(robot, prefix, clock, rate_hz);
    args.extend(["--physics".into(), "kinematic".into()]);
    Proc::start("walk-sim", &args)
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
    wait_until("walkd with a fresh adapter link", timeout, || {
        let client = DaemonClient::connect(prefix).ok()?;
        let fresh = client.is_running() && client.status().ok()?.link == LinkState::Fresh;
        fresh.then_some(client)
    })
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

/// A post-processed forward walk of `distance` metres for `robot` (JSON) and its stance count.
pub fn walk_json(robot: &str, distance: f64) -> anyhow::Result<(String, usize)> {
    let config = config(robot);
    let model = kinematics::robot::Robot::load(&config, None)?;
    client::demo::walk_sequence(&model, &config, distance, 1)
}
