//! The visual-only geoms (`MujocoOptions::visual_geoms`) change the pictures and nothing else: the
//! model gains geoms, and a scripted run through stance, contact and single support gives
//! bit-identical states with and without them.

#![cfg(feature = "mujoco")]

use std::path::Path;
use std::sync::Arc;

use kinematic_sim::Simulator;
use kinematics::robot::Robot;
use sim_adapter::mujoco::{MujocoOptions, MujocoSim};

fn sim(name: &str, visual_geoms: bool) -> MujocoSim {
    let config = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs")
        .join(format!("{name}.toml"));
    let robot = Arc::new(Robot::load(&config, None).unwrap());
    let initial = robot.standing.clone();
    let urdf = robot.urdf.clone();
    let options = MujocoOptions {
        visual_geoms,
        ..MujocoOptions::default()
    };
    MujocoSim::new(robot, &urdf, &initial, options).unwrap()
}

/// Every state value after 2 s of commanded motion (legs and arms swaying, so the feet load
/// and unload), as raw bits.
fn scripted_run_bits(sim: &mut MujocoSim) -> Vec<u64> {
    let standing: Vec<f64> = sim.robot().standing.joints.iter().copied().collect();
    let qd = vec![0.0; standing.len()];
    let limits = sim.robot().model.joint_limits().to_vec();
    let mut bits = Vec::new();
    for k in 0..1000 {
        let q: Vec<f64> = standing
            .iter()
            .zip(&limits)
            .enumerate()
            .map(|(j, (q, l))| {
                (q + 0.03 * (k as f64 * 0.01 + j as f64).sin()).clamp(l.lower, l.upper)
            })
            .collect();
        sim.step(&q, &qd, 0.002).expect("step");
        if k % 100 == 99 {
            let m = sim.measurement();
            bits.extend(
                m.q.iter()
                    .chain(m.qd.iter())
                    .chain(m.wrenches.iter().flatten())
                    .chain(m.base.to_homogeneous().iter())
                    .chain(m.com.iter())
                    .map(|v| v.to_bits()),
            );
        }
    }
    bits
}

#[test]
fn visual_geoms_leave_the_dynamics_bit_identical() {
    for name in ["armar4", "jvrc1"] {
        let mut plain = sim(name, false);
        let mut drawn = sim(name, true);
        let extra = drawn.model().ngeom() - plain.model().ngeom();
        assert!(extra >= 20, "{name}: only {extra} visual geoms");
        assert_eq!(
            scripted_run_bits(&mut plain),
            scripted_run_bits(&mut drawn),
            "{name}: the visual geoms changed the dynamics"
        );
    }
}
