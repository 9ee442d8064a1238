//! Process life cycle: SIGTERM / SIGINT shutdown, restart after `kill -9`.

use std::time::{Duration, Instant};

use shm_types::{DaemonState, LinkState};
use walk_tests::{
    connect_when_fresh, start_sim, start_walkd, unique_prefix, wait_for_status, walk_json,
};

const START: Duration = Duration::from_secs(20);

/// SIGTERM and SIGINT make walkd hold, publish a final status and exit 0 within 1 s.
#[test]
fn walkd_exits_cleanly_within_one_second_on_sigterm_and_sigint() {
    for (signal, name) in [(libc::SIGTERM, "sigterm"), (libc::SIGINT, "sigint")] {
        let prefix = unique_prefix(name);
        let mut walkd = start_walkd("armar4", &prefix, "realtime", 500.0).unwrap();
        let mut sim = start_sim("armar4", &prefix, "realtime", 500.0).unwrap();
        let client = connect_when_fresh(&prefix, START).unwrap();
        let (json, _) = walk_json("armar4", 0.3).unwrap();
        client.submit_json(&json).unwrap();
        wait_for_status(&client, "executing", START, |s| {
            s.state == DaemonState::Executing
        })
        .unwrap();

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
        sim.signal(libc::SIGTERM);
        let status = sim.wait_exit(Duration::from_secs(5));
        assert_eq!(status.and_then(|s| s.code()), Some(0), "{}", sim.log());
    }
}

/// After `kill -9` the next walkd cleans the dead process's stale resources, serves the same
/// services and runs a walk.
#[test]
fn walkd_restarts_after_kill_9_and_cleans_stale_resources() {
    let prefix = unique_prefix("restart");
    let mut first = start_walkd("armar4", &prefix, "lockstep", 500.0).unwrap();
    let _sim = start_sim("armar4", &prefix, "lockstep", 500.0).unwrap();
    let client = connect_when_fresh(&prefix, START).unwrap();
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
