//! Every message type decoded from random bytes, as a hostile or broken peer could write them:
//! decoding never panics, and refuses exactly the codes and flags the contract does not define.
//!
//! Reading random bytes as a message is sound only because no message type holds a Rust `enum`
//! or `bool` (`shm_types::wire`); with the enums of protocol v1 it was undefined behaviour.
//! Each type gets `CASES` inputs; the test prints the count and the time (`--nocapture`).

use std::mem::size_of;
use std::time::Instant;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use shm_types::{
    ControlReply, ControlRequest, DaemonStatus, JointCommand, SensorSample, SimTruth, SubmitReply,
};

const CASES: u32 = 50_000;

/// A `T` with the bytes of `bytes` (of `size_of::<T>()`).
fn from_bytes<T: Copy>(bytes: &[u8]) -> T {
    assert_eq!(bytes.len(), size_of::<T>());
    // SAFETY: in bounds; every bit pattern is a valid value of a message type (see the
    // module docs), and `read_unaligned` copes with the Vec's alignment.
    unsafe { std::ptr::read_unaligned(bytes.as_ptr().cast::<T>()) }
}

/// Runs `decode` on `CASES` random messages of type `T`; half of the inputs are all zero (a
/// valid message of every type) with a few random bytes written over it, so decoding gets past
/// the first check.
fn fuzz<T: Copy>(name: &str, decode: impl Fn(&T)) {
    let size = size_of::<T>();
    let template = vec![0u8; size];
    let strategy = prop_oneof![
        proptest::collection::vec(any::<u8>(), size),
        proptest::collection::vec((0..size, any::<u8>()), 1..8).prop_map(move |edits| {
            let mut bytes = template.clone();
            for (at, byte) in edits {
                bytes[at] = byte;
            }
            bytes
        }),
    ];
    let mut runner = TestRunner::new(Config {
        cases: CASES,
        failure_persistence: None,
        ..Config::default()
    });
    let start = Instant::now();
    runner
        .run(&strategy, |bytes| {
            decode(&from_bytes::<T>(&bytes));
            Ok(())
        })
        .unwrap();
    eprintln!(
        "fuzz {name}: {CASES} inputs of {size} bytes decoded in {:.2} s, no panic",
        start.elapsed().as_secs_f64()
    );
}

#[test]
fn sensor_samples() {
    fuzz("SensorSample", |sample: &SensorSample| {
        let imu = sample.imu();
        assert_eq!(imu.is_ok(), sample.has_imu.raw() <= 1);
        assert_eq!(sample.holding().is_ok(), sample.adapter_holding.raw() <= 1);
        assert!(sample.q().len() <= shm_types::MAX_JOINTS);
        let _ = sample.qd();
    });
}

#[test]
fn joint_commands() {
    fuzz("JointCommand", |command: &JointCommand| {
        assert_eq!(command.mode.get().is_ok(), command.mode.raw() <= 1);
        let _ = (command.q_des(), command.qd_des());
    });
}

#[test]
fn daemon_statuses() {
    fuzz("DaemonStatus", |status: &DaemonStatus| {
        let defined = status.state.raw() <= 5
            && status.clock.raw() <= 1
            && status.link.raw() <= 2
            && status.adapter_holding.raw() <= 1;
        assert_eq!(status.validate().is_ok(), defined);
        let _ = (
            status.phase.as_str(),
            status.fault.as_str(),
            status.last_rejection.as_str(),
            status.state.name(),
        );
    });
}

#[test]
fn control_requests_and_replies() {
    fuzz("ControlRequest", |request: &ControlRequest| {
        let error = request.command.get().err();
        assert_eq!(error.is_none(), request.command.raw() <= 2);
        if let Some(error) = error {
            assert!(
                error
                    .to_string()
                    .contains(&request.command.raw().to_string())
            );
        }
    });
    fuzz("ControlReply", |reply: &ControlReply| {
        let _ = (
            reply.accepted.get(),
            reply.message.as_str(),
            reply.status.validate(),
        );
    });
}

#[test]
fn submit_replies_and_sim_truth() {
    fuzz("SubmitReply", |reply: &SubmitReply| {
        assert_eq!(reply.accepted.get().is_ok(), reply.accepted.raw() <= 1);
        let _ = reply.reason.as_str();
    });
    fuzz("SimTruth", |truth: &SimTruth| {
        let _ = truth.fallen.get();
    });
}
