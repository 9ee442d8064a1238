//! Fault handling between real processes: a dying adapter, a dying daemon, bad submissions.

use std::time::Duration;

use client::daemon_client::SubmitError;
use shm_types::{DaemonLoopPorts, DaemonState, LinkState, SensorSample, ServiceNames};
use walk_tests::{
    start_connected, start_sim, start_walking, unique_prefix, wait_for_status, wait_until,
    walk_json,
};

const START: Duration = Duration::from_secs(20);

/// The adapter is killed mid-walk: walkd holds and reports the stale link without crashing,
/// and accepts a new sequence once an adapter is back.
#[test]
fn adapter_killed_mid_walk_daemon_holds_then_accepts_a_new_sequence() {
    let prefix = unique_prefix("adapter_killed");
    let (walkd, sim, client) = start_walking("armar4", &prefix, 1.0).unwrap();
    let (json, _) = walk_json("armar4", 1.0).unwrap();
    std::thread::sleep(Duration::from_millis(300));

    sim.signal(libc::SIGKILL);
    let status = wait_for_status(&client, "a stale link", Duration::from_secs(5), |s| {
        s.link == LinkState::Stale
    })
    .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    assert_eq!(status.state, DaemonState::Holding, "{status:?}");
    assert!(
        status.fault.as_str().contains("adapter link stale"),
        "{status:?}"
    );
    assert!(status.watchdog_trips >= 1, "{status:?}");
    assert!(walkd.is_running(), "walkd died\n{}", walkd.log());
    // While the adapter is gone nothing can execute: a submission is refused with the reason.
    match client.submit_json(&json) {
        Err(SubmitError::Refused(reason)) => assert!(reason.contains("adapter"), "{reason}"),
        other => panic!("expected a refusal, got {other:?}"),
    }

    let _sim = start_sim("armar4", &prefix, "realtime", 500.0).unwrap();
    wait_for_status(&client, "a fresh link", START, |s| {
        s.link == LinkState::Fresh
    })
    .unwrap();
    let id = client.submit_json(&json).unwrap_or_else(|e| {
        let status = client
            .status()
            .map(|s| client::daemon_client::status_json(&s));
        panic!("{e}\n{status:?}\n{}", walkd.log())
    });
    let status =
        wait_for_status(&client, "the new sequence", START, |s| s.sequence_id == id).unwrap();
    assert_eq!(status.state, DaemonState::Executing, "{status:?}");
    assert!(walkd.is_running());
}

/// walkd is killed mid-walk: the adapter's watchdog holds the posture.
#[test]
fn daemon_killed_adapter_holds_position() {
    let prefix = unique_prefix("daemon_killed");
    let (walkd, sim, _client) = start_walking("armar4", &prefix, 1.0).unwrap();

    // Watch the adapter's samples from the outside.
    let names = ServiceNames::new(&prefix).unwrap();
    let monitor = DaemonLoopPorts::open(&names, "e2e-monitor").unwrap();
    let mut sample = SensorSample::ZERO;
    let next_sample = |sample: &mut SensorSample| {
        wait_until("a sensor sample", Duration::from_secs(2), || {
            monitor.wait_for_sample(Duration::from_millis(20)).ok()?;
            monitor.take_latest_sample(sample).ok()?.then_some(())
        })
        .unwrap();
    };
    next_sample(&mut sample);
    assert!(
        !sample.adapter_holding.is_set(),
        "the adapter follows the daemon while it lives"
    );

    walkd.signal(libc::SIGKILL);
    assert!(walkd.wait_exit(Duration::from_secs(5)).is_some());
    wait_until("the adapter to hold", Duration::from_secs(2), || {
        next_sample(&mut sample);
        sample.adapter_holding.is_set().then_some(())
    })
    .unwrap_or_else(|e| panic!("{e}\n{}", sim.log()));
    let held = sample;
    for _ in 0..50 {
        next_sample(&mut sample);
        assert!(sample.adapter_holding.is_set());
        assert_eq!(sample.q(), held.q(), "joints moved while holding");
    }
    assert!(sim.is_running(), "{}", sim.log());
    assert!(sim.log().contains("holding position"), "{}", sim.log());
}

/// Bad submissions are refused with a reason that names the problem; during a walk every
/// submission is refused as busy before it is parsed, and the walk goes on to completion.
#[test]
fn invalid_submissions_are_refused_and_a_walk_goes_on() {
    let prefix = unique_prefix("invalid_submissions");
    let (walkd, _sim, client) = start_connected("armar4", &prefix, "lockstep").unwrap();
    let (json, _) = walk_json("armar4", 0.3).unwrap();
    let refused = |text: &str| match client.submit_json(text) {
        Err(SubmitError::Refused(reason)) => reason,
        other => panic!("expected a refusal, got {other:?}\n{}", walkd.log()),
    };
    let reason = refused("{ not json");
    assert!(reason.contains("invalid sequence"), "{reason}");
    let (jvrc1, _) = walk_json("jvrc1", 0.3).unwrap();
    let reason = refused(&jvrc1);
    assert!(
        reason.contains("for robot `jvrc1`, not for `armar4`"),
        "{reason}"
    );
    let mut beyond_limits: serde_json::Value = serde_json::from_str(&json).unwrap();
    beyond_limits["stances"][1]["q"][0] = serde_json::json!(100.0);
    let reason = refused(&beyond_limits.to_string());
    assert!(reason.contains("limit"), "{reason}");

    let id = client.submit_json(&json).unwrap();
    let reason = refused(&json);
    assert!(reason.contains("busy"), "{reason}");
    let reason = refused("{ not json");
    assert!(reason.contains("busy"), "{reason}");

    let status = client.status().unwrap();
    assert_eq!(status.sequence_id, id, "the walk in progress was replaced");
    assert_eq!(status.state, DaemonState::Executing, "{status:?}");
    // The walk goes on: it gets past the stance it was in when the refusals came.
    let later = wait_for_status(
        &client,
        "progress after the refusals",
        Duration::from_secs(60),
        |s| {
            s.sequence_id == id
                && (s.stance_index > status.stance_index || s.state == DaemonState::Done)
        },
    )
    .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    assert_ne!(later.state, DaemonState::Holding, "{later:?}");
}
