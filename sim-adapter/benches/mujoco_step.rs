//! Step time of the MuJoCo backend per robot (a report, not a pass/fail test).
//!
//! `cargo bench -p sim-adapter --features mujoco --bench mujoco_step`
//!
//! Per robot: 10 s of simulated time at the daemon's default 500 Hz control rate (the physics
//! steps of the default `MujocoOptions::timestep` that fit in a call: 4 of 0.5 ms), standing and
//! then swaying the arms and torso; prints the wall time per physics step (median and 99th
//! percentile of the calls, divided by the substeps) and the real-time factor of the whole run.

use kinematic_sim::Simulator;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use kinematics::robot::Robot;
use sim_adapter::mujoco::{MujocoOptions, MujocoSim};

const ROBOTS: [(&str, &str); 2] = [
    ("armar4", "robots/armar4/armar4_fixed_hands.urdf"),
    ("jvrc1", "robots/jvrc1/jvrc1.urdf"),
];
const CONTROL_DT: f64 = 0.002;
const SIMULATED_S: f64 = 10.0;

fn main() {
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
    println!(
        "MuJoCo {} — {SIMULATED_S} s simulated per robot, control period {CONTROL_DT} s",
        mujoco_rs::mujoco_version()
    );
    for (name, urdf) in ROBOTS {
        report(
            name,
            &configs.join(format!("{name}.toml")),
            &configs.join(urdf),
        );
    }
}

fn report(name: &str, config: &Path, urdf: &Path) {
    let robot = Arc::new(Robot::load(config, None).expect("robot loads"));
    let initial = robot.standing.clone();
    let options = MujocoOptions::default();
    let substeps = (CONTROL_DT / options.timestep).round();
    let build_start = Instant::now();
    let mut sim = MujocoSim::new(robot.clone(), urdf, &initial, options).expect("model builds");
    let build = build_start.elapsed();
    let standing: Vec<f64> = initial.joints.iter().copied().collect();
    let moving: Vec<usize> = robot
        .joint_groups
        .arms
        .iter()
        .chain(&robot.joint_groups.torso)
        .copied()
        .collect();
    let (mut q, mut qd) = (standing.clone(), vec![0.0; standing.len()]);
    let calls = (SIMULATED_S / CONTROL_DT).round() as usize;
    let mut per_call_us = Vec::with_capacity(calls);
    let run_start = Instant::now();
    for k in 0..calls {
        // A gentle 0.5 Hz sway of the arms and torso after the first second.
        let t = k as f64 * CONTROL_DT;
        let amplitude = if t < 1.0 { 0.0 } else { 0.1 };
        let w = std::f64::consts::PI;
        for &j in &moving {
            q[j] = standing[j] + amplitude * (w * t).sin();
            qd[j] = amplitude * w * (w * t).cos();
        }
        let start = Instant::now();
        sim.step(&q, &qd, CONTROL_DT).expect("step");
        per_call_us.push(start.elapsed().as_secs_f64() * 1e6);
    }
    let wall = run_start.elapsed().as_secs_f64();
    per_call_us.sort_by(f64::total_cmp);
    let median = per_call_us[calls / 2] / substeps;
    let p99 = per_call_us[calls * 99 / 100] / substeps;
    println!(
        "{name:>7}: {} joints, model built in {:.1} ms; per {:.2} ms physics step: median {median:.1} µs, p99 {p99:.1} µs; \
         real-time factor {:.0}x; fallen: {}",
        robot.model.dof(),
        build.as_secs_f64() * 1e3,
        options.timestep * 1e3,
        SIMULATED_S / wall,
        sim.summary().fell,
    );
}
