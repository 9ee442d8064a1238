//! The `walkd` and `walk-sim` children of `walkctl evaluate` and `walkctl demo`: found next to
//! `walkctl`'s own executable, their stderr kept in a temporary log file for error messages, and
//! the wait until the started daemon is ready.

use std::cell::RefCell;
use std::ffi::OsString;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};

use crate::daemon_client::DaemonClient;

/// How long a child may take to exit after SIGTERM before it is killed.
const STOP_TIMEOUT: Duration = Duration::from_secs(5);

/// A child process whose stderr goes to a temporary log file; killed if dropped while it runs.
pub(crate) struct Process {
    name: &'static str,
    child: RefCell<Child>,
    log: PathBuf,
}

/// How a child ended when it was stopped.
pub(crate) struct Stopped {
    /// Why the stop was not clean (a failure exit status, or it ignored SIGTERM and was killed);
    /// `None` when it exited successfully.
    pub(crate) problem: Option<String>,
    /// Everything it wrote to stderr.
    pub(crate) log: String,
}

impl Process {
    /// Starts `name` (from `walkctl`'s directory) with `args`.
    pub(crate) fn start(name: &'static str, args: &[OsString]) -> anyhow::Result<Self> {
        let binary = std::env::current_exe()?
            .parent()
            .map(|dir| dir.join(name))
            .filter(|path| path.is_file())
            .with_context(|| format!("`{name}` not found next to walkctl (build all binaries)"))?;
        static COUNT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let log =
            std::env::temp_dir().join(format!("walkctl-{}-{name}-{n}.log", std::process::id()));
        let child = Command::new(&binary)
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log)?)
            .spawn()
            .with_context(|| format!("cannot start {}", binary.display()))?;
        Ok(Self {
            name,
            child: RefCell::new(child),
            log,
        })
    }

    /// Fails with the child's log if it has already exited.
    pub(crate) fn check_running(&self) -> anyhow::Result<()> {
        if let Ok(Some(status)) = self.child.borrow_mut().try_wait() {
            bail!(
                "{} exited during start-up ({status}):\n{}",
                self.name,
                self.log_text()
            );
        }
        Ok(())
    }

    /// SIGTERM, then waits up to 5 s (then SIGKILL).
    pub(crate) fn stop(self) -> anyhow::Result<Stopped> {
        let mut child = self.child.borrow_mut();
        // SAFETY: kill with the pid of our own child has no memory-safety preconditions.
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
        let start = Instant::now();
        let problem = loop {
            if let Some(status) = child.try_wait()? {
                break (!status.success()).then(|| format!("{} exited with {status}", self.name));
            }
            if start.elapsed() > STOP_TIMEOUT {
                child.kill()?;
                child.wait()?;
                break Some(format!("{} did not stop on SIGTERM; killed", self.name));
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        drop(child);
        Ok(Stopped {
            problem,
            log: self.log_text(),
        })
    }

    fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }
}

/// Waits until the daemon on `prefix` serves with a fresh adapter link, failing with a child's
/// log as soon as one of `processes` exits.
pub(crate) fn connect_when_fresh(
    prefix: &str,
    processes: &[&Process],
    timeout: Duration,
) -> anyhow::Result<DaemonClient> {
    let start = Instant::now();
    loop {
        for process in processes {
            process.check_running()?;
        }
        if let Ok(client) = DaemonClient::connect(prefix)
            && client.is_running()
            && let Ok(status) = client.status()
            && status.link == shm_types::LinkState::Fresh
        {
            return Ok(client);
        }
        if start.elapsed() > timeout {
            bail!(
                "walkd on `{prefix}` did not get fresh samples within {} s",
                timeout.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        let child = self.child.get_mut();
        if matches!(child.try_wait(), Ok(None)) {
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = std::fs::remove_file(&self.log);
    }
}
