//! Behaviour of the kinematic simulator on the vendored robots.

use std::path::PathBuf;
use std::sync::Arc;

use kinematic_sim::{JointVectorError, KinematicSim, SimError, SimOptions, Simulator};
use kinematics::ground::GRAVITY;
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};

fn robot(name: &str) -> Arc<Robot> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../configs/{name}.toml"));
    Arc::new(Robot::load(&path, None).expect("vendored robot loads"))
}

/// A simulator of `robot` standing, the standing joint angles (a command to edit) and zero joint
/// velocities.
fn standing(robot: &Arc<Robot>) -> (KinematicSim, Vec<f64>, Vec<f64>) {
    let sim = KinematicSim::new(robot.clone(), robot.standing.clone()).unwrap();
    let q: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let zeros = vec![0.0; q.len()];
    (sim, q, zeros)
}

fn leg_joint(robot: &Robot, prefix_left: bool, contains: &str) -> usize {
    let legs = &robot.joint_groups.legs;
    let half = legs.len() / 2;
    let side = if prefix_left == (robot.name == "armar4") {
        &legs[..half]
    } else {
        &legs[half..]
    };
    *side
        .iter()
        .find(|&&j| {
            robot.model.joint_names()[j]
                .to_lowercase()
                .contains(contains)
        })
        .expect("leg joint exists")
}

/// A simulator of `robot` standing that judges by the ZMP, its CoM acceleration filtered with
/// time constant `zmp_filter_s`.
fn judged_by_zmp(robot: &Arc<Robot>, zmp_filter_s: f64) -> KinematicSim {
    let options = SimOptions {
        judge_by_zmp: true,
        zmp_filter_s,
        ..SimOptions::default()
    };
    KinematicSim::with_options(robot.clone(), robot.standing.clone(), options).expect("standing")
}

/// Both ankle pitch joints (left, right).
fn ankle_pitches(robot: &Robot) -> [usize; 2] {
    [
        leg_joint(robot, true, "ankle_p"),
        leg_joint(robot, false, "ankle_p"),
    ]
}

/// The feet's ground wrenches summed at the world origin: the moments about x and y that put
/// their resultant at the centre of pressure (`p_y = m_x / F_z`, `p_x = m_y / F_z`), and the
/// normal force `F_z`.
fn feet_resultant(robot: &Robot, sim: &KinematicSim) -> (f64, f64, f64) {
    let m = sim.measurement();
    let mut kinematics = Kinematics::new(&robot.model);
    kinematics.update(&robot.model, sim.configuration());
    let (mut moment_x, mut moment_y, mut normal) = (0.0, 0.0, 0.0);
    for (slot, foot) in [EndEffector::LeftFoot, EndEffector::RightFoot]
        .iter()
        .enumerate()
    {
        let w = m.wrenches[*foot as usize];
        let o = kinematics
            .frame_pose(&robot.model, robot.ft_sensors[slot])
            .translation
            .vector;
        moment_x += o.y * w[2] - o.z * w[1] + w[3];
        moment_y += o.x * w[2] - o.z * w[0] - w[4];
        normal += w[2];
    }
    (moment_x, moment_y, normal)
}

#[test]
fn standing_robot_is_supported_by_both_feet_with_its_weight() {
    for name in ["jvrc1", "armar4"] {
        let robot = robot(name);
        let sim = KinematicSim::new(robot.clone(), robot.standing.clone()).unwrap();
        let m = sim.measurement();
        assert_eq!(m.contacts, [true, true, false, false], "{name}");
        let total: f64 = m.wrenches.iter().map(|w| w[2]).sum();
        let weight = robot.model.total_mass() * GRAVITY;
        assert!(
            (total - weight).abs() < 1e-6 * weight,
            "{name}: {total} vs {weight}"
        );
        assert!(m.safety.stability_margin > 0.0, "{name}");
        assert_eq!(m.safety.contact_slip, 0.0);
        // Moment balance: the resultant of the ground forces acts below the CoM.
        // Moment about the world origin: r × F + τ; its x part must equal (c × W)_x.
        let (moment_x, _, _) = feet_resultant(&robot, &sim);
        assert!(
            (moment_x - m.com.y * weight).abs() < 1e-6 * weight,
            "{name}: {moment_x}"
        );
    }
}

#[test]
fn holding_still_keeps_everything_fixed_and_deterministic() {
    let robot = robot("jvrc1");
    let (mut a, q, zeros) = standing(&robot);
    for _ in 0..100 {
        a.step(&q, &zeros, 0.002).unwrap();
    }
    let start = robot.standing.base.translation.vector;
    assert!((a.configuration().base.translation.vector - start).norm() < 1e-12);
    assert_eq!(a.summary().max_contact_slip, 0.0);
    assert_eq!(a.summary().joint_limit_violations, 0);
}

#[test]
fn bending_one_knee_lifts_that_foot_and_releases_it() {
    let robot = robot("jvrc1");
    let (mut sim, mut q, zeros) = standing(&robot);
    let hip = leg_joint(&robot, false, "hip_p");
    let knee = leg_joint(&robot, false, "knee");
    for _ in 0..50 {
        q[hip] -= 0.004;
        q[knee] += 0.008;
        sim.step(&q, &zeros, 0.002).unwrap();
    }
    // Swinging the free leg around moves nothing that stands.
    let ankle = leg_joint(&robot, false, "ankle_p");
    for _ in 0..50 {
        q[ankle] += 0.004;
        q[hip] -= 0.004;
        sim.step(&q, &zeros, 0.002).unwrap();
        assert!(
            sim.measurement().safety.contact_slip < 1e-12,
            "slip {}",
            sim.measurement().safety.contact_slip
        );
    }
    let m = sim.measurement();
    assert!(
        !m.contacts[EndEffector::RightFoot as usize],
        "right foot lifted off"
    );
    assert!(m.contacts[EndEffector::LeftFoot as usize]);
    assert_eq!(m.wrenches[EndEffector::RightFoot as usize][2], 0.0);
    // The CoM sits between the feet, so standing on the left foot alone is a fall.
    assert!(m.safety.stability_margin < 0.0);
    assert!(sim.summary().fell);
}

#[test]
fn commands_beyond_limits_stop_there_and_are_counted_and_bad_commands_are_refused() {
    let robot = robot("jvrc1");
    let (mut sim, mut q, zeros) = standing(&robot);
    let arm = robot.joint_groups.arms[0];
    q[arm] = robot.model.joint_limits()[arm].upper + 0.5;
    sim.step(&q, &zeros, 0.002).unwrap();
    assert_eq!(sim.measurement().safety.limit_violations, 1);
    assert_eq!(
        sim.measurement().q[arm],
        robot.model.joint_limits()[arm].upper
    );
    q[arm] = f64::NAN;
    assert!(
        matches!(sim.step(&q, &zeros, 0.002), Err(SimError::Command(JointVectorError::NonFinite { index, .. })) if index == arm)
    );
    assert!(matches!(
        sim.step(&q[1..], &zeros, 0.002),
        Err(SimError::Command(JointVectorError::Length { .. }))
    ));
}

#[test]
fn a_robot_in_the_air_is_refused() {
    let robot = robot("jvrc1");
    let mut lifted = robot.standing.clone();
    lifted.base.translation.vector.z += 0.1;
    assert!(matches!(
        KinematicSim::new(robot, lifted),
        Err(SimError::NotStanding { .. })
    ));
}

#[test]
fn moving_every_joint_in_single_support_keeps_the_stance_foot_in_place() {
    // Regression: composing the base with inverse poses every step used to let the quaternion
    // norm error double per step until the base diverged.
    let robot = robot("jvrc1");
    let (mut sim, mut q, zeros) = standing(&robot);
    let (hip, knee) = (
        leg_joint(&robot, false, "hip_p"),
        leg_joint(&robot, false, "knee"),
    );
    for _ in 0..50 {
        q[hip] -= 0.004;
        q[knee] += 0.008;
        sim.step(&q, &zeros, 0.005).unwrap();
    }
    assert_eq!(sim.measurement().contacts, [true, false, false, false]);
    for k in 0..2000 {
        for (j, (v, limit)) in q.iter_mut().zip(robot.model.joint_limits()).enumerate() {
            *v = (*v + 0.002 * ((j * 7 + k) as f64).sin()).clamp(limit.lower, limit.upper);
        }
        sim.step(&q, &zeros, 0.005).unwrap();
        assert!(
            sim.measurement().safety.contact_slip < 1e-12,
            "step {k}: slip {}",
            sim.measurement().safety.contact_slip
        );
    }
}

#[test]
fn a_dynamic_walk_is_judged_by_the_zmp_of_its_com_motion() {
    let robot = robot("jvrc1");
    let mut sim = judged_by_zmp(&robot, 0.0);
    // Both ankles pitch the body back and forth at 1.5 Hz: the CoM accelerates along x.
    let ankles = ankle_pitches(&robot);
    let dt = 0.002;
    let mut coms = Vec::new();
    for k in 0..300 {
        let mut q = robot.standing.joints.clone();
        let swing = 0.005 * (std::f64::consts::TAU * 1.5 * f64::from(k) * dt).sin();
        for &j in &ankles {
            q[j] += swing;
        }
        let rate = (&q - sim.measurement().q.clone()) / dt;
        sim.step(q.as_slice(), rate.as_slice(), dt).unwrap();
        let m = sim.measurement();
        coms.push(m.com);
        if coms.len() < 3 {
            continue;
        }
        let n = coms.len();
        let acceleration = (coms[n - 1] - 2.0 * coms[n - 2] + coms[n - 3]) / (dt * dt);
        let zmp = coms[n - 1].x - acceleration.x * coms[n - 1].z / (GRAVITY + acceleration.z);
        // The resultant of the synthetic wrenches acts at that ZMP with m (g + z̈).
        let (_, moment, normal) = feet_resultant(&robot, &sim);
        let weight = robot.model.total_mass() * (GRAVITY + acceleration.z);
        assert!(
            (normal - weight).abs() < 1e-6 * weight,
            "tick {k}: {normal} vs {weight}"
        );
        assert!((moment / normal - zmp).abs() < 1e-9, "tick {k}");
        assert!(
            m.safety.stability_margin > 0.0,
            "tick {k}: the ZMP stays on the feet"
        );
    }
}

#[test]
fn re_placing_the_base_between_inconsistent_feet_is_not_motion_for_the_zmp() {
    // Regression: the ZMP's CoM acceleration differentiated the base re-placed when the feet's
    // shares changed between anchors the command does not agree with (a swing foot still moving
    // as it touches down). The shares follow the ZMP's lever rule, so the CoM jump moved the ZMP,
    // which moved the shares further: at JVRC-1's first dynamic touchdown the ZMP left the
    // support. Here the right foot is slid 0.3 mm sideways while both feet are anchored, then
    // the robot holds still: nothing moves but the base between the two placements.
    let robot = robot("jvrc1");
    let mut sim = judged_by_zmp(&robot, SimOptions::default().zmp_filter_s);
    let (hip, ankle) = (
        leg_joint(&robot, false, "hip_r"),
        leg_joint(&robot, false, "ankle_r"),
    );
    let mut q = robot.standing.joints.clone();
    let dt = 0.001;
    let mut worst_offset: f64 = 0.0;
    for k in 0..1500 {
        let mut rate = nalgebra::DVector::zeros(q.len());
        if k < 100 {
            (rate[hip], rate[ankle]) = (4e-6 / dt, -4e-6 / dt);
            q += &rate * dt;
        }
        sim.step(q.as_slice(), rate.as_slice(), dt).unwrap();
        let m = sim.measurement();
        assert_eq!(m.contacts, [true, true, false, false], "step {k}");
        assert!(
            m.safety.stability_margin > 0.0,
            "step {k}: ZMP margin {}",
            m.safety.stability_margin
        );
        // The ZMP is where the resultant of the synthetic wrenches acts.
        let (moment, _, normal) = feet_resultant(&robot, &sim);
        // Once the slide's own deceleration has left the ZMP filter.
        if k >= 400 {
            worst_offset = worst_offset.max((moment / normal - m.com.y).abs());
        }
    }
    assert!(
        sim.summary().max_contact_slip > 1e-4,
        "the feet disagree: slip {}",
        sim.summary().max_contact_slip
    );
    assert!(
        worst_offset < 1e-6,
        "holding still, the ZMP stays under the CoM: {worst_offset} m off"
    );
}

#[test]
fn a_setpoint_applied_again_is_a_missed_command_not_a_stop() {
    // Over processes in real time a command that comes a period late (the controller skipped a
    // tick) leaves the adapter applying its last setpoint again. The ideal servos then stand
    // still for a step and go on; counted as motion, that stop at walking pace decelerates the
    // rigid robot within one step and its ZMP left the feet by 0.1-1 m (a `walkctl demo
    // --gait dynamic --physics kinematic` in real time "fell" at every lost tick). A controller
    // that moves never sends the same setpoint twice (each one moves on by its rate), so a
    // setpoint given again with a non-zero rate is a missed command: the joints hold and the
    // ZMP's motion history skips the step.
    let robot = robot("jvrc1");
    let mut sim = judged_by_zmp(&robot, SimOptions::default().zmp_filter_s);
    // Both ankles pitch the body forward, the rate rising smoothly to 0.1 rad/s over 0.4 s (the
    // CoM then moves at about 0.09 m/s), as the controller would command it.
    let ankles = ankle_pitches(&robot);
    let dt = 0.002;
    let mut q = robot.standing.joints.clone();
    let mut rate = nalgebra::DVector::zeros(q.len());
    for k in 0..300 {
        let t = f64::from(k) * dt;
        let missed = k == 250;
        if !missed {
            let speed = 0.1 * (1.0 - (std::f64::consts::PI * (t / 0.4).min(1.0)).cos()) / 2.0;
            for &j in &ankles {
                rate[j] = speed;
            }
            q += &rate * dt;
        }
        let before = sim.measurement().q.clone();
        sim.step(q.as_slice(), rate.as_slice(), dt).unwrap();
        let m = sim.measurement();
        if missed {
            assert_eq!(m.q, before, "the joints hold through a missed command");
        }
        assert!(
            m.safety.stability_margin > 0.01,
            "step {k}: ZMP margin {} m",
            m.safety.stability_margin
        );
    }
}

/// A ground that is a surface at `height` where y > 0 (under the left foot) and nothing
/// elsewhere.
#[derive(Debug)]
struct LeftSideOnly {
    height: f64,
}

impl kinematic_sim::Ground for LeftSideOnly {
    fn height_at(&self, _x: f64, y: f64) -> Option<f64> {
        (y > 0.0).then_some(self.height)
    }
}

/// On a [`kinematic_sim::Ground`] a foot stands where a surface is under its sole: with a surface
/// under the left foot only, the left foot is anchored and the right has nothing to stand on; a
/// surface 5 cm above the soles is 5 cm of penetration; one 5 cm below them holds nothing up.
#[test]
fn feet_stand_on_the_ground_under_them() {
    let robot = robot("jvrc1");
    let on = |height: f64| {
        KinematicSim::on_ground(
            robot.clone(),
            robot.standing.clone(),
            SimOptions::default(),
            Arc::new(LeftSideOnly { height }),
        )
    };
    let sim = on(0.0).expect("the left foot stands");
    assert_eq!(sim.measurement().contacts, [true, false, false, false]);
    let sim = on(0.05).expect("the left foot stands, sunk in");
    assert!((sim.measurement().safety.penetration - 0.05).abs() < 1e-3);
    match on(-0.05) {
        Err(SimError::NotStanding { lowest_m }) => assert!((lowest_m - 0.05).abs() < 1e-3),
        other => panic!("stood on nothing: {:?}", other.map(|_| ())),
    }
}
