//! Process life cycle: SIGTERM / SIGINT shutdown, restart after `kill -9`, systemd
//! notifications.

use std::os::unix::net::UnixDatagram;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use shm_types::LinkState;
use walk_tests::{
    assert_terminates, connect_when_fresh, start_connected, start_sim, start_walkd,
    start_walkd_with_env, start_walking, unique_prefix, walk_json,
};

const START: Duration = Duration::from_secs(20);

/// SIGTERM and SIGINT make walkd hold, publish a final status and exit 0 within 1 s.
#[test]
fn walkd_exits_cleanly_within_one_second_on_sigterm_and_sigint() {
    for (signal, name) in [(libc::SIGTERM, "sigterm"), (libc::SIGINT, "sigint")] {
        let prefix = unique_prefix(name);
        let (walkd, sim, _client) = start_walking("armar4", &prefix, 0.3).unwrap();

        let sent = Instant::now();
        walkd.signal(signal);
        let status = walkd.wait_exit(Duration::from_secs(5));
        let elapsed = sent.elapsed();
        assert_eq!(
            status.and_then(|s| s.code()),
            Some(0),
            "{name}: {}",
            walkd.log()
        );
        assert!(
            elapsed < Duration::from_secs(1),
            "{name}: exit took {elapsed:?}"
        );
        let log = walkd.log();
        assert!(
            log.contains("walkd stopped"),
            "{name}: no orderly stop\n{log}"
        );

        // The adapter saw the final hold command and holds on its own once commands stop.
        assert_terminates(&sim, Duration::from_secs(5));
    }
}

/// After `kill -9` the next walkd cleans the dead process's stale resources, serves the same
/// services and runs a walk.
#[test]
fn walkd_restarts_after_kill_9_and_cleans_stale_resources() {
    let prefix = unique_prefix("restart");
    let (first, _sim, client) = start_connected("armar4", &prefix, "lockstep").unwrap();
    let first_pid = client.status().unwrap().pid;
    assert_eq!(first_pid, first.pid());
    drop(client);
    first.signal(libc::SIGKILL);
    assert!(first.wait_exit(Duration::from_secs(5)).is_some());

    // Nothing else may touch iceoryx2 until the new walkd is up: any process that creates a node
    // cleans dead nodes, and this test is about walkd doing it.
    let second = start_walkd("armar4", &prefix, "lockstep", 500.0).unwrap();
    second.wait_for_log("walkd ready", START).unwrap();
    assert!(
        second.log().contains(
            "removed stale iceoryx2 resources of dead processes (e.g. a killed walkd) nodes=2"
        ),
        "the killed daemon's two nodes were not cleaned by the new walkd\n{}",
        second.log()
    );
    let client =
        connect_when_fresh(&prefix, START).unwrap_or_else(|e| panic!("{e}\n{}", second.log()));
    let status = client.status().unwrap();
    assert_eq!(
        status.pid,
        second.pid(),
        "the status comes from the new daemon"
    );
    assert_eq!(status.link, LinkState::Fresh);
    let (json, _) = walk_json("armar4", 0.2).unwrap();
    let id = client
        .submit_json(&json)
        .unwrap_or_else(|e| panic!("{e}\n{}", second.log()));
    assert!(id >= 1);
}

/// A unix datagram socket standing in for systemd's notification socket (`NOTIFY_SOCKET`).
struct NotifySocket {
    socket: UnixDatagram,
    path: PathBuf,
    /// Every message received so far, in order.
    messages: Vec<String>,
}

impl NotifySocket {
    fn bind(name: &str) -> Self {
        let path =
            std::env::temp_dir().join(format!("walk-e2e-{name}-{}.sock", std::process::id()));
        let _ = std::fs::remove_file(&path);
        let socket = UnixDatagram::bind(&path).unwrap();
        socket
            .set_read_timeout(Some(Duration::from_millis(50)))
            .unwrap();
        Self {
            socket,
            path,
            messages: Vec::new(),
        }
    }

    /// Receives until a message satisfies `wanted` or `timeout` passes; returns its index.
    fn wait_for(&mut self, timeout: Duration, wanted: impl Fn(&str) -> bool) -> Option<usize> {
        if let Some(index) = self.messages.iter().position(|m| wanted(m)) {
            return Some(index);
        }
        let start = Instant::now();
        let mut buffer = [0u8; 4096];
        while start.elapsed() < timeout {
            if let Ok(n) = self.socket.recv(&mut buffer) {
                let message = String::from_utf8_lossy(&buffer[..n]).trim_end().to_owned();
                let hit = wanted(&message);
                self.messages.push(message);
                if hit {
                    return Some(self.messages.len() - 1);
                }
            }
        }
        None
    }

    /// Receives whatever arrives within `duration`.
    fn collect_for(&mut self, duration: Duration) {
        let _ = self.wait_for(duration, |_| false);
    }

    fn count(&self, message: &str) -> usize {
        self.messages
            .iter()
            .filter(|m| m.as_str() == message)
            .count()
    }
}

impl Drop for NotifySocket {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// walkd tells systemd READY=1 once it serves, STATUS= with its state, WATCHDOG=1 only when
/// systemd asks for it (`WATCHDOG_USEC`), and STOPPING=1 on SIGTERM before exiting 0.
#[test]
fn walkd_notifies_systemd_ready_status_watchdog_and_stopping() {
    for watchdog in [true, false] {
        let name = if watchdog {
            "notify-watchdog"
        } else {
            "notify"
        };
        let prefix = unique_prefix(name);
        let mut notify = NotifySocket::bind(name);
        let mut env = vec![("NOTIFY_SOCKET", notify.path.as_os_str())];
        if watchdog {
            // 2 s like configs/walkd@.service's WatchdogSec.
            env.push(("WATCHDOG_USEC", "2000000".as_ref()));
        }
        let walkd = start_walkd_with_env("armar4", &prefix, "realtime", 500.0, &env).unwrap();
        let _sim = start_sim("armar4", &prefix, "realtime", 500.0).unwrap();

        let ready = notify.wait_for(START, |m| m == "READY=1");
        assert!(
            ready.is_some(),
            "{name}: no READY=1 ({:?})\n{}",
            notify.messages,
            walkd.log()
        );
        let status = notify.wait_for(START, |m| m.starts_with("STATUS="));
        assert!(
            status.is_some(),
            "{name}: no STATUS= ({:?})",
            notify.messages
        );
        // The first status goes out before the adapter is connected; a later one says so.
        let fresh = notify.wait_for(START, |m| {
            m.starts_with("STATUS=") && m.contains("adapter fresh")
        });
        assert!(
            fresh.is_some(),
            "{name}: no STATUS= with a fresh adapter ({:?})",
            notify.messages
        );
        // Status (and with it the watchdog) goes out at 20 Hz: 0.5 s gives about 10.
        notify.collect_for(Duration::from_millis(500));
        let watchdogs = notify.count("WATCHDOG=1");
        if watchdog {
            assert!(
                watchdogs >= 5,
                "{name}: {watchdogs} WATCHDOG=1 in 0.5 s+ ({:?})",
                notify.messages
            );
        } else {
            assert_eq!(watchdogs, 0, "{name}: WATCHDOG=1 without WATCHDOG_USEC");
        }

        walkd.signal(libc::SIGTERM);
        let exit = walkd.wait_exit(Duration::from_secs(5));
        assert_eq!(
            exit.and_then(|s| s.code()),
            Some(0),
            "{name}: {}",
            walkd.log()
        );
        let stopping = notify.wait_for(Duration::from_secs(1), |m| m == "STOPPING=1");
        assert!(
            stopping > ready,
            "{name}: STOPPING=1 must follow READY=1 ({:?})",
            notify.messages
        );
    }
}

/// The minimal adapter example of docs/adapter.md (sim-adapter/examples/minimal_adapter.rs)
/// connects to a real walkd, serves its samples for a few periods, gets commands back and exits
/// cleanly.
#[test]
fn the_minimal_adapter_example_serves_walkd_and_exits_cleanly() {
    let prefix = unique_prefix("minimal_adapter");
    let walkd = start_walkd("armar4", &prefix, "realtime", 500.0).unwrap();
    walkd.wait_for_log("walkd ready", START).unwrap();
    let example = walk_tests::bin_dir().join("examples/minimal_adapter");
    assert!(
        example.is_file(),
        "{} missing: cargo build --release -p sim-adapter --examples",
        example.display()
    );
    let config = walk_tests::config("armar4");
    let output = std::process::Command::new(&example)
        .args([config.as_os_str(), "500".as_ref(), prefix.as_ref()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}\n{stdout}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let count = |what: &str| -> u64 {
        stdout
            .split(&format!(" {what}"))
            .next()
            .and_then(|s| s.rsplit(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no {what} count in `{stdout}`"))
    };
    assert!(count("samples") >= 500, "{stdout}");
    assert!(
        count("commands") > 400,
        "walkd answered too few samples: {stdout}\n{}",
        walkd.log()
    );
}

/// The processes a `walkctl demo` started die with it, also when it is killed outright: a
/// `walkd` and a `walk-sim` left behind in lockstep step each other on at full speed.
#[test]
fn a_killed_walkctl_takes_its_walkd_and_walk_sim_with_it() {
    let prefix = unique_prefix("killed_walkctl");
    let mut demo = std::process::Command::new(walk_tests::bin_dir().join("walkctl"))
        .args([
            "demo",
            "--robot",
            "jvrc1",
            "--clock",
            "realtime",
            "--distance",
            "5",
        ])
        .args([
            "--config",
            &walk_tests::config("jvrc1").display().to_string(),
        ])
        .args(["--service-prefix", &prefix])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("walkctl runs (build the binaries first)");
    let children_of = |pid: u32| -> Vec<u32> {
        std::fs::read_to_string(format!("/proc/{pid}/task/{pid}/children"))
            .unwrap_or_default()
            .split_whitespace()
            .filter_map(|p| p.parse().ok())
            .collect()
    };
    // Both children up and the link fresh: the demo is walking.
    let _client = connect_when_fresh(&prefix, START).unwrap();
    let children = children_of(demo.id());
    assert_eq!(children.len(), 2, "walkd and walk-sim: {children:?}");

    demo.kill().unwrap();
    demo.wait().unwrap();
    let alive = |pid: &u32| {
        std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
            !stat
                .rsplit(')')
                .next()
                .unwrap_or("")
                .trim_start()
                .starts_with('Z')
        })
    };
    let start = Instant::now();
    while children.iter().any(alive) && start.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(50));
    }
    let left: Vec<_> = children.iter().filter(|pid| alive(pid)).collect();
    for pid in &left {
        // SAFETY: kill on a pid this test saw as walkctl's child; no memory-safety conditions.
        unsafe { libc::kill(**pid as libc::pid_t, libc::SIGKILL) };
    }
    assert!(
        left.is_empty(),
        "still running after walkctl died: {left:?}"
    );
}
