//! Child processes: `walkd` and `walk-sim` started by `walkctl demo` and `walkctl evaluate`,
//! the processes of the latency report, and those of the end-to-end tests. One implementation:
//! each child's stderr goes to a temporary log (for error messages and for reading what it
//! reported), it is stopped with SIGTERM and a grace period, it is killed if dropped while it
//! runs, and it gets SIGTERM from the kernel if the thread that started it dies.

use std::cell::RefCell;
use std::ffi::{OsStr, OsString};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use kinematics::ConfigFile;
use shm_types::ClockMode;
use shm_types::process::Physics;
use stance::Gait;

/// How long a child may take to exit after SIGTERM before it is killed.
pub const STOP_TIMEOUT: Duration = Duration::from_secs(5);

/// A child process whose stderr goes to a temporary log file; killed if dropped while it runs,
/// and sent SIGTERM by the kernel when the thread that started it dies, so a `walkctl demo` or
/// `evaluate` killed outright (SIGKILL, a crash) leaves no `walkd` and `walk-sim` behind: in
/// lockstep the two would otherwise step each other on, at full speed, until killed by hand.
pub struct Process {
    name: String,
    child: RefCell<Child>,
    log: PathBuf,
}

/// How a child ended when it was stopped.
pub struct Stopped {
    /// Why the stop was not clean (a failure exit status, or it ignored SIGTERM and was killed);
    /// `None` when it exited successfully.
    pub problem: Option<String>,
    /// Everything it wrote to stderr.
    pub log: String,
}

/// `name` in the directory of the running executable (where cargo puts all the binaries).
pub fn sibling(name: &str) -> anyhow::Result<PathBuf> {
    let path = executable_dir()?.join(name);
    anyhow::ensure!(
        path.is_file(),
        "`{}` missing: build all binaries (cargo build --release --workspace --bins)",
        path.display()
    );
    Ok(path)
}

/// In a forked child before `exec`: asks the kernel for SIGTERM when the thread that forked it
/// dies (`PR_SET_PDEATHSIG`), and gives up if `parent` already died before that took effect.
fn die_with_parent(parent: u32) -> std::io::Result<()> {
    // SAFETY: prctl with PR_SET_PDEATHSIG and a signal number has no memory-safety
    // preconditions; getppid has none.
    unsafe {
        if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM) != 0 {
            return Err(std::io::Error::last_os_error());
        }
        if libc::getppid() as u32 != parent {
            return Err(std::io::Error::from_raw_os_error(libc::ESRCH));
        }
    }
    Ok(())
}

impl Process {
    /// Starts `program` with `args` and the extra environment `env`.
    pub fn start(
        program: &Path,
        args: impl IntoIterator<Item = impl AsRef<OsStr>>,
        env: &[(&str, &OsStr)],
    ) -> anyhow::Result<Self> {
        let name = program.file_name().map_or_else(
            || program.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        static COUNT: AtomicU32 = AtomicU32::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let log = std::env::temp_dir().join(format!("walk-{}-{name}-{n}.log", std::process::id()));
        let mut command = Command::new(program);
        command
            .args(args)
            .envs(env.iter().copied())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log)?);
        let parent = std::process::id();
        // SAFETY: the closure runs in the forked child before `exec` and makes only
        // async-signal-safe system calls (prctl, getppid), allocating nothing.
        unsafe {
            command.pre_exec(move || die_with_parent(parent));
        }
        let child = command
            .spawn()
            .with_context(|| format!("cannot start {}", program.display()))?;
        Ok(Self {
            name,
            child: RefCell::new(child),
            log,
        })
    }

    /// Process id.
    pub fn pid(&self) -> u32 {
        self.child.borrow().id()
    }

    /// Sends `signal` (e.g. `libc::SIGTERM`, `libc::SIGKILL`).
    pub fn signal(&self, signal: i32) {
        // SAFETY: kill on our own child's pid has no memory-safety preconditions.
        unsafe { libc::kill(self.pid() as libc::pid_t, signal) };
    }

    /// Whether the process still runs.
    pub fn is_running(&self) -> bool {
        matches!(self.child.borrow_mut().try_wait(), Ok(None))
    }

    /// Waits up to `timeout` for the exit; `None` if it still runs.
    pub fn wait_exit(&self, timeout: Duration) -> Option<ExitStatus> {
        let start = Instant::now();
        loop {
            if let Ok(Some(status)) = self.child.borrow_mut().try_wait() {
                return Some(status);
            }
            if start.elapsed() > timeout {
                return None;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// Fails with the child's log if it has already exited.
    pub fn check_running(&self) -> anyhow::Result<()> {
        if let Ok(Some(status)) = self.child.borrow_mut().try_wait() {
            bail!("{} exited ({status}):\n{}", self.name, self.log_text());
        }
        Ok(())
    }

    /// Waits until the child's stderr contains `text`.
    pub fn wait_for_log(&self, text: &str, timeout: Duration) -> anyhow::Result<()> {
        let start = Instant::now();
        while !self.log_text().contains(text) {
            if start.elapsed() > timeout {
                bail!(
                    "timed out after {timeout:?} waiting for `{text}` in the log of {}\n{}",
                    self.name,
                    self.log()
                );
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        Ok(())
    }

    /// SIGTERM, then waits up to [`STOP_TIMEOUT`] (then SIGKILL).
    pub fn stop(self) -> anyhow::Result<Stopped> {
        self.signal(libc::SIGTERM);
        let mut child = self.child.borrow_mut();
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

    /// The child's stderr so far, headed by its name (for failure messages).
    pub fn log(&self) -> String {
        format!("--- {} stderr ---\n{}", self.name, self.log_text())
    }

    /// The child's stderr so far.
    pub fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
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

/// Children started together, stopped together (newest first); stopped when dropped.
#[derive(Default)]
pub struct Processes(pub Vec<Process>);

impl Processes {
    /// SIGTERM to each child (newest first), waiting up to [`STOP_TIMEOUT`] each, then SIGKILL;
    /// returns what went wrong.
    pub fn shut_down(&mut self) -> anyhow::Result<Vec<String>> {
        let mut problems = Vec::new();
        while let Some(child) = self.0.pop() {
            problems.extend(child.stop()?.problem);
        }
        Ok(problems)
    }
}

impl Drop for Processes {
    fn drop(&mut self) {
        // On an error path: stop them gracefully; the error being returned matters more.
        let _ = self.shut_down();
    }
}

/// How to start a `walkd` and its `walk-sim` on one service prefix: the options both take.
#[derive(Debug, Clone)]
pub struct Launch {
    /// Where the binaries are.
    pub bin_dir: PathBuf,
    /// The robot config.
    pub config: PathBuf,
    /// The service prefix of both.
    pub prefix: String,
    /// Realtime or lockstep.
    pub clock: ClockMode,
    /// Control (and sample) rate overriding the config's.
    pub rate_hz: Option<f64>,
    /// URDF overriding the config's.
    pub urdf: Option<PathBuf>,
}

impl Launch {
    /// The options both processes take.
    pub fn common_args(&self) -> Vec<OsString> {
        let mut args: Vec<OsString> = vec![
            "--config".into(),
            self.config.clone().into(),
            "--service-prefix".into(),
            self.prefix.clone().into(),
            "--clock".into(),
            self.clock.name().into(),
        ];
        if let Some(rate) = self.rate_hz {
            args.extend(["--rate-hz".into(), rate.to_string().into()]);
        }
        if let Some(urdf) = &self.urdf {
            args.extend(["--urdf".into(), urdf.clone().into()]);
        }
        args
    }

    /// Starts `walkd` with `extra` arguments and environment.
    pub fn walkd(&self, extra: &[&str], env: &[(&str, &OsStr)]) -> anyhow::Result<Process> {
        let mut args = self.common_args();
        args.extend(extra.iter().map(OsString::from));
        Process::start(&self.bin_dir.join("walkd"), args, env)
    }

    /// The arguments of `walk-sim` with `physics`.
    pub fn walk_sim_args(&self, physics: Physics) -> Vec<OsString> {
        let mut args = self.common_args();
        args.extend(["--physics".into(), physics.name().into()]);
        args
    }

    /// Starts `walk-sim` with `physics` and `extra` arguments.
    pub fn walk_sim(&self, physics: Physics, extra: &[OsString]) -> anyhow::Result<Process> {
        let mut args = self.walk_sim_args(physics);
        args.extend_from_slice(extra);
        Process::start(&self.bin_dir.join("walk-sim"), args, &[])
    }
}

/// The config values a controller runs with against the kinematic simulator, as `section.key=value`
/// assignments (`walkd --set`; `walk_bench::kinematic_gaits` applies them in process). Its robot
/// is rigid: the stabilizer parts that act through contact compliance, foot damping and tilt
/// damping, turn its whole body instead of shifting its centres of pressure, and their loops
/// diverge (docs/controller.md, "The kinematic simulator and dynamic walks"). Its soles are flat
/// contacts, released once lifted above their anchors, so a toe-off's raised heel reads as a
/// foot let go: toe-off is off too. None for a config
/// without `[gait.dynamic]`: it has no stabilizer, and setting these keys would create one.
pub fn kinematic_sim_settings(file: &ConfigFile) -> &'static [&'static str] {
    let dynamic = file
        .section("gait")
        .is_some_and(|gait| gait.get("dynamic").is_some());
    if dynamic {
        &[
            "gait.dynamic.stabilizer.foot_damping=false",
            "gait.dynamic.stabilizer.tilt_damping=false",
            "gait.dynamic.toe_off_rad=0",
        ]
    } else {
        &[]
    }
}

/// What `walkd` and `walk-sim` take beyond [`Launch::common_args`] to walk one gait on one
/// simulator as `walk-bench` does in process: against the kinematic simulator, walkd without
/// the stabilizer parts its rigid robot cannot use, and for the dynamic gait walk-sim judging
/// by the ZMP.
#[derive(Debug, Clone, Default)]
pub struct PlantArgs {
    /// Extra arguments of `walkd`.
    pub walkd: Vec<&'static str>,
    /// Extra arguments of `walk-sim`.
    pub walk_sim: Vec<OsString>,
}

impl PlantArgs {
    /// The arguments for walks of `gait` with the config `file` on `physics`.
    pub fn new(physics: Physics, gait: Gait, file: &ConfigFile) -> Self {
        let mut args = Self::default();
        if physics == Physics::Kinematic {
            for setting in kinematic_sim_settings(file) {
                args.walkd.extend(["--set", setting]);
            }
            if gait == Gait::Dynamic {
                args.walk_sim.push("--judge-by-zmp".into());
            }
        }
        args
    }
}

/// The directory of the running executable (where cargo puts all the binaries).
pub fn executable_dir() -> anyhow::Result<PathBuf> {
    Ok(std::env::current_exe()?
        .parent()
        .context("the executable has no directory")?
        .to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_kinematic_simulator_gets_plant_arguments() {
        let parse = |text: &str| ConfigFile::parse(text, Path::new("robot.toml")).unwrap();
        let dynamic = parse("[gait.dynamic]\nsingle_support_s = 0.6\n");
        let walkd = [
            "--set",
            "gait.dynamic.stabilizer.foot_damping=false",
            "--set",
            "gait.dynamic.stabilizer.tilt_damping=false",
            "--set",
            "gait.dynamic.toe_off_rad=0",
        ];
        let walk = PlantArgs::new(Physics::Kinematic, Gait::Dynamic, &dynamic);
        assert_eq!(walk.walkd, walkd);
        assert_eq!(walk.walk_sim, ["--judge-by-zmp"]);
        // A static walk is judged by the CoM; walkd is set up the same.
        let walk = PlantArgs::new(Physics::Kinematic, Gait::Static, &dynamic);
        assert_eq!(walk.walkd, walkd);
        assert!(walk.walk_sim.is_empty());
        // Without [gait.dynamic] there is no stabilizer to tune, and none is created.
        let static_only = parse("[gait]\ndefault = \"static\"\n");
        let walk = PlantArgs::new(Physics::Kinematic, Gait::Static, &static_only);
        assert!(walk.walkd.is_empty());
        // MuJoCo's robot is compliant and its physics judges itself.
        let walk = PlantArgs::new(Physics::Mujoco, Gait::Dynamic, &dynamic);
        assert!(walk.walkd.is_empty() && walk.walk_sim.is_empty());
    }
}
