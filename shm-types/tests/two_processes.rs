//! Real two-process tests: this test binary re-executes itself as the peer process.

use std::process::Command;
use std::time::Duration;

use shm_types::{
    AdapterPorts, ClientPorts, ControlCommand, ControlReply, DaemonLoopPorts, DaemonServicePorts,
    DaemonStatus, JointCommand, SensorSample, ServiceNames, ShmError, SubmitReply,
};

/// Environment variable that turns the re-executed test binary into the peer.
const PEER_PREFIX: &str = "SHM_TYPES_PEER_PREFIX";
const ROUNDS: u64 = 200;
const TIMEOUT: Duration = Duration::from_secs(5);

fn unique_prefix(test: &str) -> String {
    format!("walk-test/shm-types/{test}/{}", std::process::id())
}

/// The daemon side runs here; the adapter and client side run in a child process.
#[test]
fn daemon_and_adapter_exchange_samples_commands_and_requests() {
    if let Ok(prefix) = std::env::var(PEER_PREFIX) {
        run_peer(&prefix);
        return;
    }
    let prefix = unique_prefix("exchange");
    let names = ServiceNames::new(&prefix).unwrap();
    let ports = DaemonLoopPorts::open(&names, "daemon-loop").unwrap();
    let services = DaemonServicePorts::open(&names, "daemon-services").unwrap();
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "daemon_and_adapter_exchange_samples_commands_and_requests",
            "--nocapture",
        ])
        .env(PEER_PREFIX, &prefix)
        .spawn()
        .unwrap();

    // Answer every sample with a command that doubles q[0] and echoes the sample's seq.
    let mut sample = SensorSample::ZERO;
    let mut answered = 0;
    while answered < ROUNDS {
        assert!(
            ports.wait_for_sample(TIMEOUT).unwrap(),
            "no sample announced"
        );
        while ports.take_latest_sample(&mut sample).unwrap() {
            assert_eq!(sample.joint_count, 3);
            ports
                .send_command(|command| {
                    command.seq = sample.seq;
                    command.answers_seq = sample.seq;
                    command.joint_count = sample.joint_count;
                    command.q_des[0] = 2.0 * sample.q[0];
                })
                .unwrap();
            answered = sample.seq;
        }
    }

    // Serve one submission and one control request from the child's client ports.
    let (mut submissions, mut controls) = (0, 0);
    let start = std::time::Instant::now();
    while submissions == 0 || controls == 0 {
        assert!(start.elapsed() < TIMEOUT, "requests did not arrive");
        let mut status = DaemonStatus::INITIAL;
        status.ticks = ROUNDS;
        services.publish_status(&status).unwrap();
        if services
            .serve_submission(|json| {
                assert_eq!(json, br#"{"stances":[]}"#);
                SubmitReply::accepted(42)
            })
            .unwrap()
        {
            submissions += 1;
        }
        if services
            .serve_control(|command| ControlReply {
                accepted: (command == Ok(ControlCommand::Hold)).into(),
                status,
                ..ControlReply::default()
            })
            .unwrap()
        {
            controls += 1;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(child.wait().unwrap().success(), "peer process failed");
}

/// The child: an adapter that checks every answer, then a client that submits and controls.
fn run_peer(prefix: &str) {
    let names = ServiceNames::new(prefix).unwrap();
    let adapter = AdapterPorts::open(&names, "adapter").unwrap();
    let mut command = JointCommand::ZERO;
    for seq in 1..=ROUNDS {
        adapter
            .publish_sample(|sample| {
                sample.seq = seq;
                sample.joint_count = 3;
                sample.q[0] = seq as f64;
            })
            .unwrap();
        loop {
            assert!(
                adapter.wait_for_command(TIMEOUT).unwrap(),
                "no command for sample {seq}"
            );
            if adapter.take_latest_command(&mut command).unwrap() && command.answers_seq == seq {
                break;
            }
        }
        assert_eq!(command.q_des(), &[2.0 * seq as f64, 0.0, 0.0]);
    }

    let client = ClientPorts::connect(&names, "client").unwrap();
    assert!(client.daemon_present());
    let reply = client.submit(br#"{"stances":[]}"#, TIMEOUT).unwrap();
    assert!(reply.accepted.is_set());
    assert_eq!(reply.sequence_id, 42);
    let reply = client.control(ControlCommand::Hold, TIMEOUT).unwrap();
    assert!(reply.accepted.is_set());
    assert_eq!(reply.status.ticks, ROUNDS);
    assert_eq!(client.next_status(TIMEOUT).unwrap().ticks, ROUNDS);
}

#[test]
fn a_client_without_daemon_gets_a_clear_error() {
    let names = ServiceNames::new(&unique_prefix("absent")).unwrap();
    match ClientPorts::connect(&names, "client") {
        Err(ShmError::NotRunning { service }) => assert!(service.ends_with("/status")),
        Err(other) => panic!("expected NotRunning, got {other}"),
        Ok(_) => panic!("connected to a daemon that does not exist"),
    }
}

#[test]
fn invalid_prefixes_are_rejected_with_the_name() {
    assert!(matches!(
        ServiceNames::new(""),
        Err(ShmError::InvalidServiceName { .. })
    ));
}
