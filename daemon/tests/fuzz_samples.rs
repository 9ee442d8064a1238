//! walkd's sample path on raw bytes: random sensor samples, as a broken or hostile adapter
//! could write them, go through the daemon's decoding (`daemon::runtime::decode`) into the
//! controller. Nothing panics, and every command written is finite and inside the limits.
//! Prints the number of inputs and the time (`--nocapture`).

mod walk_support;

use std::mem::{offset_of, size_of};
use std::time::Instant;

use daemon::controller::{Command, Controller, SolverKind};
use daemon::runtime::decode;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use shm_types::SensorSample;

const CASES: u32 = 20_000;

#[test]
fn random_samples_never_command_outside_the_limits() {
    let robot = walk_support::robot("jvrc1");
    let config = walk_support::controller_config("jvrc1");
    let dof = robot.model.dof();
    let controller = Controller::new(robot.clone(), config, SolverKind::Dense).unwrap();
    let command = Command::new(dof);
    // A valid standing sample, as bytes: the start of half of the inputs.
    let mut standing = vec![0u8; size_of::<SensorSample>()];
    let mut put =
        |offset: usize, bytes: &[u8]| standing[offset..offset + bytes.len()].copy_from_slice(bytes);
    put(
        offset_of!(SensorSample, joint_count),
        &(dof as u32).to_ne_bytes(),
    );
    for (j, q) in robot.standing.joints.iter().enumerate() {
        put(offset_of!(SensorSample, q) + 8 * j, &q.to_ne_bytes());
    }
    let weight = robot.model.total_mass() * 9.81 / 2.0;
    for foot in 0..2 {
        put(
            offset_of!(SensorSample, wrenches) + 48 * foot + 16,
            &weight.to_ne_bytes(),
        );
    }
    let size = standing.len();
    let strategy = prop_oneof![
        proptest::collection::vec(any::<u8>(), size),
        proptest::collection::vec((0..size, any::<u8>()), 1..6).prop_map(move |edits| {
            let mut bytes = standing.clone();
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
    let limits = robot.model.joint_limits().to_vec();
    // The runner takes an `Fn`: the controller and the counts live in a cell.
    let state = std::cell::RefCell::new((controller, command, 0u64, 0u64));
    let start = Instant::now();
    runner
        .run(&strategy, |bytes| {
            let (controller, command, commands, refused) = &mut *state.borrow_mut();
            // SAFETY: in bounds; every bit pattern is a valid SensorSample (no enum or bool).
            let sample: SensorSample = unsafe { std::ptr::read_unaligned(bytes.as_ptr().cast()) };
            let commanded = match decode::measurement(&sample, dof) {
                Ok(measurement) => controller.tick(&measurement, 0.002, command),
                Err(fault) => {
                    *refused += 1;
                    controller.refuse_measurement(fault, command)
                }
            };
            let _ = controller.reset();
            if commanded {
                *commands += 1;
                for (q, limit) in command.q_des.iter().zip(&limits) {
                    prop_assert!(q.is_finite() && *q >= limit.lower && *q <= limit.upper);
                }
                prop_assert!(command.qd_des.iter().all(|v| v.is_finite()));
            }
            Ok(())
        })
        .unwrap();
    let (_, _, commands, refused) = state.into_inner();
    eprintln!(
        "fuzz samples → controller: {CASES} inputs in {:.2} s, {refused} refused by the \
         decoding, {commands} commands written, all inside the limits",
        start.elapsed().as_secs_f64()
    );
    assert!(commands > 0, "no input ever got through");
}
