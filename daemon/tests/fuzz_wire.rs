//! Every message type read from random bytes, as a hostile or broken peer could write them, and
//! walkd's sample path on such bytes: decoding never panics and refuses exactly the codes and
//! flags the contract does not define; a sample decoded by the daemon
//! (`daemon::runtime::decode`) and ticked by the controller never yields a command outside the
//! joint limits. Each test prints its number of inputs and the time (`--nocapture`).
//!
//! Reading random bytes as a message is sound only because no message type holds a Rust `enum`
//! or `bool` (`shm_types::wire`); with the enums of protocol v1 it was undefined behaviour.

use std::cell::RefCell;
use std::mem::{offset_of, size_of};
use std::time::Instant;

use daemon::controller::{Command, Controller, ControllerConfig, SolverKind};
use daemon::runtime::decode;
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use shm_types::{
    ControlReply, ControlRequest, DaemonStatus, JointCommand, SensorSample, SimTruth, SubmitReply,
};

/// Inputs per message type.
const CASES: u32 = 50_000;

/// A `T` with the bytes of `bytes` (of `size_of::<T>()`).
fn from_bytes<T: Copy>(bytes: &[u8]) -> T {
    assert_eq!(bytes.len(), size_of::<T>());
    // SAFETY: in bounds; every bit pattern is a valid value of a message type (see the
    // module docs), and `read_unaligned` copes with the Vec's alignment.
    unsafe { std::ptr::read_unaligned(bytes.as_ptr().cast::<T>()) }
}

/// Runs `decode` on `cases` random messages of type `T`: half are random bytes, half are
/// `template` with a few random bytes written over it, so decoding gets past the first check.
fn fuzz<T: Copy>(name: &str, cases: u32, template: Vec<u8>, mut decode: impl FnMut(&T)) {
    let size = size_of::<T>();
    assert_eq!(template.len(), size);
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
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    // The runner takes an `Fn`: the decoder, with its state, lives in a cell.
    let decode = RefCell::new(&mut decode);
    let start = Instant::now();
    runner
        .run(&strategy, |bytes| {
            (decode.borrow_mut())(&from_bytes::<T>(&bytes));
            Ok(())
        })
        .unwrap();
    eprintln!(
        "fuzz {name}: {cases} inputs of {size} bytes decoded in {:.2} s, no panic",
        start.elapsed().as_secs_f64()
    );
}

/// All zero bytes: a valid message of every type.
fn zeros<T>() -> Vec<u8> {
    vec![0; size_of::<T>()]
}

/// [`fuzz`] of [`CASES`] messages of type `T` around the all-zero message.
fn fuzz_message<T: Copy>(name: &str, check: impl FnMut(&T)) {
    fuzz(name, CASES, zeros::<T>(), check);
}

#[test]
fn sensor_samples() {
    fuzz_message("SensorSample", |sample: &SensorSample| {
        assert_eq!(sample.imu().is_ok(), sample.has_imu.raw() <= 1);
        assert_eq!(sample.holding().is_ok(), sample.adapter_holding.raw() <= 1);
        assert!(sample.q().len() <= shm_types::MAX_JOINTS);
        let _ = sample.qd();
    });
}

#[test]
fn joint_commands() {
    fuzz_message("JointCommand", |command: &JointCommand| {
        assert_eq!(command.mode.get().is_ok(), command.mode.raw() <= 1);
        let _ = (command.q_des(), command.qd_des());
    });
}

#[test]
fn daemon_statuses() {
    fuzz_message("DaemonStatus", |status: &DaemonStatus| {
        let defined = status.state.raw() <= 6
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
    fuzz_message("ControlRequest", |request: &ControlRequest| {
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
    fuzz_message("ControlReply", |reply: &ControlReply| {
        let _ = (
            reply.accepted.get(),
            reply.message.as_str(),
            reply.status.validate(),
        );
    });
}

#[test]
fn submit_replies_and_sim_truth() {
    fuzz_message("SubmitReply", |reply: &SubmitReply| {
        assert_eq!(reply.accepted.get().is_ok(), reply.accepted.raw() <= 1);
        let _ = reply.reason.as_str();
    });
    fuzz_message("SimTruth", |truth: &SimTruth| {
        let _ = truth.fallen.get();
    });
}

/// A JVRC-1 standing still, as the bytes of a sensor sample.
fn standing_sample_bytes(robot: &Robot) -> Vec<u8> {
    let mut bytes = zeros::<SensorSample>();
    let mut put = |offset: usize, value: &[u8]| {
        bytes[offset..offset + value.len()].copy_from_slice(value);
    };
    let dof = robot.model.dof();
    put(
        offset_of!(SensorSample, joint_count),
        &(dof as u32).to_ne_bytes(),
    );
    for (j, q) in robot.standing.joints.iter().enumerate() {
        put(offset_of!(SensorSample, q) + 8 * j, &q.to_ne_bytes());
    }
    let weight = robot.model.total_mass() * kinematics::ground::GRAVITY / 2.0;
    for foot in 0..2 {
        put(
            offset_of!(SensorSample, wrenches) + 48 * foot + 16,
            &weight.to_ne_bytes(),
        );
    }
    bytes
}

#[test]
fn random_samples_never_command_outside_the_limits() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/jvrc1.toml");
    let file = ConfigFile::load(&path).unwrap();
    let robot = std::sync::Arc::new(Robot::from_config(&file, None).unwrap());
    let config = ControllerConfig::from_config(&file).unwrap();
    let dof = robot.model.dof();
    let limits = robot.model.joint_limits().to_vec();
    let mut controller = Controller::new(robot.clone(), config, SolverKind::Dense).unwrap();
    let mut command = Command::new(dof);
    let (mut commands, mut refused) = (0u64, 0u64);
    let cases = 20_000;
    fuzz(
        "SensorSample → controller",
        cases,
        standing_sample_bytes(&robot),
        |sample: &SensorSample| {
            let commanded = match decode::measurement(sample, dof) {
                Ok(measurement) => controller.tick(&measurement, 0.002, &mut command),
                Err(fault) => {
                    refused += 1;
                    controller.refuse_measurement(fault, 0.002, &mut command)
                }
            };
            let _ = controller.reset();
            if commanded {
                commands += 1;
                for (q, limit) in command.q_des.iter().zip(&limits) {
                    assert!(
                        q.is_finite() && *q >= limit.lower && *q <= limit.upper,
                        "q_des {q}"
                    );
                }
                assert!(command.qd_des.iter().all(|v| v.is_finite()));
            }
        },
    );
    eprintln!(
        "  of the {cases}: {refused} refused by the decoding, {commands} commands written, all \
         inside the limits"
    );
    assert!(commands > 0, "no input ever got through");
}
