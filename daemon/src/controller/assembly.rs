//! Builds the tick's QP over ν = (v_base, ω_base, q̇) from the tasks and constraints:
//!
//! ```text
//! min  Σ_k w_k ‖J_k ν − v*_k‖² + λ‖ν‖²        v*_k = feed-forward + K_k · error_k
//! s.t. J_c ν = c + v_c                         feet in contact (c: bounded anchor correction,
//!                                              v_c: the dynamic gait's foot compliance)
//!      n_eᵀ J_com,xy ν ≤ k_s (d_e − m − n_eᵀ c) CoM stays in the support polygon shrunk by m
//!                                              (static gait only)
//!      q̇ within velocity limits and (q_min + margin − q_cmd)/dt ≤ q̇ ≤ (q_max − margin − q_cmd)/dt
//!      |v_base|, |ω_base| ≤ max_base_speed, |ω_x|, |ω_y| ≤ max_base_tilt_speed (roll/pitch rate)
//! ```
//!
//! The position limits act on `q_cmd`, the joint command the controller integrates (the servos
//! track it), not on the measured angle: bounding the measured angle with a one-tick (1/dt)
//! correction would feed the servo's tracking lag back into the integrated command and make a
//! joint resting at its bound oscillate.
//!
//! Tasks: CoM x/y (and z at a constant height in the dynamic gait, whose ZMP-feasible CoM
//! set-point replaces the polygon constraint), end-effector poses, upright base, posture (the
//! dynamic gait may weigh the torso joints' posture apart). The legs' posture reference is the
//! standing posture, not the stance's `q_S`: the feet and CoM tasks place the legs, and `q_S`'s
//! legs come from the post-processing IK, which may crouch to reach a held hand's target
//! (JVRC-1's knees at 1.24 rad, where single support holds more than their 100 N·m; with it, the
//! static gait's 5 m walks with a hand tipped in 4 of 20). Jacobian blocks are accumulated
//! over their structurally non-zero columns only, so a foot task costs a few hundred flops.
//! Everything is preallocated at construction.

use kinematics::configuration::Configuration;
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{DMatrix, DVector, Isometry3, UnitQuaternion, Vector3};

use kinematics::ground::{MAX_SUPPORT_POINTS, SupportPolygon};

use super::config::ControllerConfig;
use super::machine::{Balance, PoseTarget, Targets};
use crate::qp::QpProblem;

/// Equality rows: six per foot in contact.
pub(crate) const MAX_EQUALITY_ROWS: usize = 12;
/// Inequality rows: one per support polygon edge.
pub(crate) const MAX_INEQUALITY_ROWS: usize = MAX_SUPPORT_POINTS;

/// Preallocated QP and the Jacobian scratch used to fill it.
pub(crate) struct QpAssembler {
    problem: QpProblem,
    jacobian: DMatrix<f64>,
    com_jacobian: DMatrix<f64>,
    /// Structurally non-zero Jacobian columns of each end-effector frame.
    columns: [Vec<usize>; 4],
    all_columns: Vec<usize>,
    /// Base orientation of the standing posture: "upright" means no roll/pitch relative to it.
    upright_reference: UnitQuaternion<f64>,
    polygon: SupportPolygon,
    /// Whether each joint belongs to `[robot.joint_groups] torso`.
    torso_joints: Vec<bool>,
    /// Whether each joint is a torso joint turning the upper body about the vertical
    /// (`torso_yaw_posture_weight`).
    torso_yaw_joints: Vec<bool>,
    /// Whether each joint belongs to `[robot.joint_groups] legs`.
    leg_joints: Vec<bool>,
    /// Whether each joint moves each hand (left, right) and is no torso joint: its arm.
    arm_joints: [Vec<bool>; 2],
    /// The base's yaw (relative to the standing orientation) when a hand began to carry weight,
    /// kept while one does.
    held_yaw: Option<f64>,
}

impl QpAssembler {
    pub fn new(robot: &Robot) -> Self {
        let model = &robot.model;
        let nv = model.nv();
        let mut jacobian = DMatrix::zeros(6, nv);
        // Columns that are zero at two unrelated configurations are zero structurally (the
        // joint is not on the frame's chain).
        let mut kinematics = Kinematics::new(model);
        let mut probe = robot.standing.clone();
        let mut nonzero = [
            vec![false; nv],
            vec![false; nv],
            vec![false; nv],
            vec![false; nv],
        ];
        for offset in [0.0, 0.3] {
            for (j, limit) in model.joint_limits().iter().enumerate() {
                let q = robot.standing.joints[j] + offset * (1.0 + 0.1 * j as f64).sin();
                probe.joints[j] = q.clamp(limit.lower, limit.upper);
            }
            kinematics.update(model, &probe);
            for e in EndEffector::ALL {
                kinematics.frame_jacobian(model, robot.frame(e), &mut jacobian);
                for (col, flag) in nonzero[e as usize].iter_mut().enumerate() {
                    *flag |= jacobian.column(col).iter().any(|v| *v != 0.0);
                }
            }
        }
        let torso_joints: Vec<bool> = (0..model.dof())
            .map(|j| robot.joint_groups.torso.contains(&j))
            .collect();
        let torso_yaw_joints = vertical_axes(robot, &mut kinematics, &mut jacobian)
            .into_iter()
            .zip(&torso_joints)
            .map(|(vertical, &torso)| vertical && torso)
            .collect();
        let arm_joints = EndEffector::HANDS.map(|hand| {
            (0..model.dof())
                .map(|j| nonzero[hand as usize][6 + j] && !torso_joints[j])
                .collect()
        });
        let columns = nonzero.map(|flags| {
            flags
                .iter()
                .enumerate()
                .filter(|(col, flag)| **flag || *col < 6)
                .map(|(col, _)| col)
                .collect()
        });
        Self {
            problem: QpProblem::new(nv, MAX_EQUALITY_ROWS, MAX_INEQUALITY_ROWS),
            jacobian,
            com_jacobian: DMatrix::zeros(3, nv),
            columns,
            all_columns: (0..nv).collect(),
            upright_reference: robot.standing.base.rotation,
            polygon: SupportPolygon::empty(),
            torso_joints,
            torso_yaw_joints,
            leg_joints: (0..model.dof())
                .map(|j| robot.joint_groups.legs.contains(&j))
                .collect(),
            arm_joints,
            held_yaw: None,
        }
    }

    /// The QP of the last [`assemble`](Self::assemble).
    pub fn problem(&self) -> &QpProblem {
        &self.problem
    }

    /// Fills the QP for this tick. `kinematics` must be updated at `configuration`;
    /// `command` is the last joint command (the integrator the solution advances).
    #[allow(clippy::too_many_arguments)]
    pub fn assemble(
        &mut self,
        robot: &Robot,
        config: &ControllerConfig,
        kinematics: &Kinematics,
        configuration: &Configuration,
        command: &DVector<f64>,
        targets: &Targets,
        posture: &DVector<f64>,
        dt: f64,
    ) {
        let model = &robot.model;
        let nv = model.nv();
        let feet_in_contact = [EndEffector::LeftFoot, EndEffector::RightFoot]
            .iter()
            .filter(|f| targets.contacts[**f as usize])
            .count();
        let m_ineq = match targets.balance {
            Balance::SupportPolygon { .. } => {
                targets.com_support(&robot.sole, &mut self.polygon);
                self.polygon.edge_count()
            }
            Balance::Pendulum(_) => 0,
        };
        self.problem
            .set_active_rows(6 * feet_in_contact, m_ineq)
            .expect("row counts within the preallocated capacity");
        let qp = self.problem.parts_mut();
        let (mut p, mut q) = (qp.p, qp.q);
        p.fill(0.0);
        q.fill(0.0);
        for i in 0..nv {
            p[(i, i)] = config.regularization;
        }

        // CoM x/y, and its height when the gait holds it.
        kinematics.com_jacobian(model, &mut self.com_jacobian);
        let com = kinematics.com();
        let held = match targets.balance {
            Balance::SupportPolygon { height } => height,
            Balance::Pendulum(height) => Some(height),
        };
        let (com_rows, height, height_velocity) =
            held.map_or((2, com.z, 0.0), |held| (3, held.height, held.velocity));
        // The set-point is where the feet's load is centred; the hands' load moves the CoM's.
        let com_target = targets.hand_load.com_of(targets.com);
        let com_feed_forward = targets.hand_load.com_velocity_of(targets.com_velocity);
        let com_velocity = [
            com_feed_forward.x + config.com_gain * (com_target.x - com.x),
            com_feed_forward.y + config.com_gain * (com_target.y - com.y),
            height_velocity + config.com_gain * (height - com.z),
        ];
        add_task(
            &mut p,
            &mut q,
            &self.com_jacobian,
            com_rows,
            &self.all_columns,
            config.com_weight,
            &com_velocity,
        );

        // End-effector poses (feet in contact are constrained below instead).
        for e in EndEffector::ALL {
            let Some(target) = targets.end_effectors[e as usize] else {
                continue;
            };
            let frame = robot.frame(e);
            kinematics.frame_jacobian(model, frame, &mut self.jacobian);
            let pose = kinematics.frame_pose(model, frame);
            let desired = pose_velocity(&pose, &target, config.pose_gain);
            let weight = if targets.unloading == Some(e) {
                config.unload_foot_weight
            } else if e.is_foot() {
                config.foot_weight
            } else {
                config.hand_weight
            };
            add_task(
                &mut p,
                &mut q,
                &self.jacobian,
                6,
                &self.columns[e as usize],
                weight,
                &desired,
            );
        }

        // Upright base: no roll or pitch relative to the standing orientation, yaw left free,
        // except while a hand carries weight: then the base keeps the yaw it had when it began to.
        // Leaning on a held hand, JVRC-1's QP twisted the pelvis 0.36 rad towards the rail (hip
        // yaw is cheap under the legs' weak posture task), and untwisting it when the hand let go
        // rocked the robot from foot to foot until it fell.
        // The base Jacobian's angular rows are the identity on ω.
        let relative = configuration.base.rotation * self.upright_reference.inverse();
        let (_, _, yaw) = relative.euler_angles();
        let leaning = targets.hand_load.share() > 0.0;
        self.held_yaw = leaning.then(|| self.held_yaw.unwrap_or(yaw));
        let upright = UnitQuaternion::from_euler_angles(0.0, 0.0, self.held_yaw.unwrap_or(yaw));
        let tilt = (upright * relative.inverse()).scaled_axis();
        for k in 0..3 {
            p[(3 + k, 3 + k)] += config.torso_weight;
            q[3 + k] -= config.torso_weight * config.torso_gain * tilt[k];
        }

        // Posture: the stance's, the legs' standing one, and the torso joints at their own
        // weight when the gait asks for it. The arm of a hand that carries weight is not driven
        // through the pose task's null space (its reference is where it is): the next stance's
        // arm posture swung JVRC-1's wrist at 0.4 rad/s while its palm leant on a rail with 130 N,
        // and the palm came off it.
        let carrying = EndEffector::HANDS.map(|hand| targets.hand_load.carries(hand));
        for j in 0..model.dof() {
            let weight = match targets.torso_posture_weight {
                Some(weight) if self.torso_joints[j] => weight,
                _ if self.torso_yaw_joints[j] => config
                    .torso_yaw_posture_weight
                    .unwrap_or(config.posture_weight),
                _ => config.posture_weight,
            };
            let carrying_arm = (0..2).any(|h| carrying[h] && self.arm_joints[h][j]);
            let reference = if self.leg_joints[j] {
                robot.standing.joints[j]
            } else if carrying_arm {
                configuration.joints[j]
            } else {
                posture[j]
            };
            let error = reference - configuration.joints[j];
            p[(6 + j, 6 + j)] += weight;
            q[6 + j] -= weight * config.posture_gain * error;
        }

        // Feet in contact do not move: J_c ν = K (anchor − pose), which is 0 while the estimate
        // agrees with the anchor and pulls back the second-order drift of J_c ν = 0 otherwise.
        let (mut a_eq, mut b_eq) = (qp.a_eq, qp.b_eq);
        let mut row = 0;
        for foot in [EndEffector::LeftFoot, EndEffector::RightFoot] {
            if !targets.contacts[foot as usize] {
                continue;
            }
            let frame = robot.frame(foot);
            kinematics.frame_jacobian(model, frame, &mut self.jacobian);
            a_eq.rows_mut(row, 6).copy_from(&self.jacobian);
            let hold = PoseTarget {
                pose: targets.anchors[foot as usize],
                velocity: [0.0; 6],
            };
            let correction = pose_velocity(
                &kinematics.frame_pose(model, frame),
                &hold,
                config.pose_gain,
            );
            // The correction is meant for the small drift of J_c ν = 0. A foot that touches down
            // while the stance sole rolls on its edge is estimated millimetres off the ground it
            // is anchored to; correcting that at the full gain kicks the leg into the ground and
            // the robot off its other foot, so the correction speed is bounded.
            let scale = speed_scale(&correction[..3], config.max_anchor_correction_speed).min(
                speed_scale(&correction[3..], config.max_anchor_correction_angular_speed),
            );
            let compliance = &targets.contact_velocity[foot as usize];
            for (k, value) in correction.iter().enumerate() {
                b_eq[row + k] = value * scale + compliance[k];
            }
            row += 6;
        }

        // CoM ground projection inside the shrunk support polygon.
        let (mut c, mut l, mut u) = (qp.c, qp.l, qp.u);
        for i in 0..m_ineq {
            let edge = self.polygon.edge(i);
            for col in 0..nv {
                c[(i, col)] = edge.normal[0] * self.com_jacobian[(0, col)]
                    + edge.normal[1] * self.com_jacobian[(1, col)];
            }
            let slack = edge.offset
                - config.support_margin_m
                - (edge.normal[0] * com.x + edge.normal[1] * com.y);
            l[i] = f64::NEG_INFINITY;
            u[i] = config.support_gain.min(1.0 / dt) * slack;
        }

        // Velocity and position limits.
        let (mut x_min, mut x_max) = (qp.x_min, qp.x_max);
        // The base's roll and pitch rates (ω_x, ω_y) have their own, usually tighter, bound: a
        // pelvis that tilts fast (a robot with little ankle roll shifts its CoM partly by rolling
        // the pelvis) exerts a reaction torque on the stance sole that rolls it over its edge.
        let tilt_speed = config.max_base_speed.min(config.max_base_tilt_speed);
        for k in 0..6 {
            let bound = if k == 3 || k == 4 {
                tilt_speed
            } else {
                config.max_base_speed
            };
            x_min[k] = -bound;
            x_max[k] = bound;
        }
        for (j, limit) in model.joint_limits().iter().enumerate() {
            let speed = config.velocity_limit_scale * limit.velocity;
            let qj = command[j];
            let lower = (-speed).max((limit.lower + config.joint_limit_margin_rad - qj) / dt);
            let upper = speed.min((limit.upper - config.joint_limit_margin_rad - qj) / dt);
            // Outside the margin the bound pulls back inside; never cross the bounds.
            x_min[6 + j] = lower.min(upper);
            x_max[6 + j] = upper.max(lower);
        }
    }
}

/// A joint axis this close to the vertical (rad) turns what it carries about the vertical.
const VERTICAL_AXIS_RAD: f64 = std::f64::consts::FRAC_PI_6;

/// Whether each joint's axis lies within [`VERTICAL_AXIS_RAD`] of the vertical in the standing
/// posture, read off the hands' Jacobians (a revolute joint's angular column is its axis in the
/// world); a joint that moves neither hand reads false.
fn vertical_axes(
    robot: &Robot,
    kinematics: &mut Kinematics,
    jacobian: &mut DMatrix<f64>,
) -> Vec<bool> {
    let model = &robot.model;
    kinematics.update(model, &robot.standing);
    let mut vertical = vec![false; model.dof()];
    for hand in EndEffector::HANDS {
        kinematics.frame_jacobian(model, robot.frame(hand), jacobian);
        for (j, flag) in vertical.iter_mut().enumerate() {
            let axis = jacobian.fixed_view::<3, 1>(3, 6 + j).into_owned();
            let norm = axis.norm();
            *flag |= norm > 0.5 && axis.z.abs() > norm * VERTICAL_AXIS_RAD.cos();
        }
    }
    vertical
}

/// Desired frame velocity: feed-forward plus proportional correction of the pose error.
fn pose_velocity(pose: &Isometry3<f64>, target: &PoseTarget, gain: f64) -> [f64; 6] {
    let position_error = target.pose.translation.vector - pose.translation.vector;
    let rotation_error: Vector3<f64> =
        (target.pose.rotation * pose.rotation.inverse()).scaled_axis();
    let mut desired = target.velocity;
    for k in 0..3 {
        desired[k] += gain * position_error[k];
        desired[3 + k] += gain * rotation_error[k];
    }
    desired
}

/// The factor (≤ 1) that scales the velocity `v` down to at most `max` in norm.
fn speed_scale(v: &[f64], max: f64) -> f64 {
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if norm > max { max / norm } else { 1.0 }
}

/// Adds `w ‖J ν − v*‖²` (first `rows` rows of `jacobian`, non-zero `columns` only):
/// P += w JᵀJ, q −= w Jᵀ v*.
fn add_task(
    p: &mut nalgebra::DMatrixViewMut<'_, f64>,
    q: &mut nalgebra::DVectorViewMut<'_, f64>,
    jacobian: &DMatrix<f64>,
    rows: usize,
    columns: &[usize],
    weight: f64,
    desired: &[f64],
) {
    for (a, &ca) in columns.iter().enumerate() {
        let col_a = jacobian.column(ca);
        let mut rhs = 0.0;
        for r in 0..rows {
            rhs += col_a[r] * desired[r];
        }
        q[ca] -= weight * rhs;
        for &cb in &columns[..=a] {
            let col_b = jacobian.column(cb);
            let mut dot = 0.0;
            for r in 0..rows {
                dot += col_a[r] * col_b[r];
            }
            p[(ca, cb)] += weight * dot;
            if ca != cb {
                p[(cb, ca)] += weight * dot;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::controller::hand_support::HandSupport;
    use crate::controller::machine::StateMachine;
    use kinematics::robot::SoleRectangle;

    /// JVRC-1's robot and `[controller]`.
    fn jvrc1() -> (Robot, ControllerConfig) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/jvrc1.toml");
        let robot = Robot::load(&path, None).expect("the JVRC-1 config loads");
        let config = ControllerConfig::from_config_file(&path).expect("its [controller] loads");
        (robot, config)
    }

    /// The linear term of the QP at the standing posture with `targets`, `posture` as the
    /// stance's `q_S`.
    fn linear_term(
        robot: &Robot,
        config: &ControllerConfig,
        posture: &DVector<f64>,
        targets: &Targets,
    ) -> DVector<f64> {
        let mut kinematics = Kinematics::new(&robot.model);
        kinematics.update(&robot.model, &robot.standing);
        let mut assembler = QpAssembler::new(robot);
        assembler.assemble(
            robot,
            config,
            &kinematics,
            &robot.standing,
            &robot.standing.joints,
            targets,
            posture,
            0.002,
        );
        assembler.problem().q().into_owned()
    }

    /// Which of `joints` the stance's posture pulls with `targets`: the QP's linear term at the
    /// joint changes when the stance's angle of every one of them does (by 0.5 rad).
    fn pulled<const N: usize>(
        robot: &Robot,
        config: &ControllerConfig,
        targets: &Targets,
        joints: [usize; N],
    ) -> [bool; N] {
        let standing = robot.standing.joints.clone();
        let mut moved = standing.clone();
        for joint in joints {
            moved[joint] -= 0.5;
        }
        let a = linear_term(robot, config, &standing, targets);
        let b = linear_term(robot, config, &moved, targets);
        joints.map(|joint| (a[6 + joint] - b[6 + joint]).abs() > 1e-4)
    }

    #[test]
    fn the_legs_posture_is_the_standing_one_and_the_arms_follow_the_stance() {
        let (robot, config) = jvrc1();
        let joint = |name| robot.model.joint_index(name).expect("a JVRC-1 joint");
        let sole = SoleRectangle {
            length: 0.2,
            width: 0.08,
        };
        // Before a walk: no contact, no task.
        let machine = StateMachine::new(&config, sole, 600.0);
        let [knee, elbow] = pulled(
            &robot,
            &config,
            machine.targets(),
            [joint("R_KNEE"), joint("R_ELBOW_P")],
        );
        assert!(!knee, "a stance's knee angle pulls the knee");
        assert!(elbow, "the stance's elbow angle does not pull the elbow");
    }

    #[test]
    fn the_torso_yaw_posture_weight_holds_the_waist_joints_that_turn_about_the_vertical() {
        let (robot, config) = jvrc1();
        let joint = |name| robot.model.joint_index(name).expect("a JVRC-1 joint");
        let assembler = QpAssembler::new(&robot);
        let yaw = |name| assembler.torso_yaw_joints[joint(name)];
        assert!(yaw("WAIST_Y"));
        assert!(!yaw("WAIST_P") && !yaw("WAIST_R") && !yaw("R_HIP_Y") && !yaw("NECK_Y"));
        // The stance's waist yaw pulls 10 times as hard at 10 times the weight, its pitch not
        // at all harder.
        let pull = |config: &ControllerConfig, name| {
            let standing = robot.standing.joints.clone();
            let mut moved = standing.clone();
            moved[joint(name)] -= 0.5;
            let targets = Targets::none();
            let a = linear_term(&robot, config, &standing, &targets);
            let b = linear_term(&robot, config, &moved, &targets);
            (a[6 + joint(name)] - b[6 + joint(name)]).abs()
        };
        let held = ControllerConfig {
            torso_yaw_posture_weight: Some(10.0 * config.posture_weight),
            ..config
        };
        let ratio = pull(&held, "WAIST_Y") / pull(&config, "WAIST_Y");
        assert!((ratio - 10.0).abs() < 1e-9, "{ratio}");
        assert!((pull(&held, "WAIST_P") - pull(&config, "WAIST_P")).abs() < 1e-12);
    }

    #[test]
    fn the_arm_of_a_hand_that_carries_weight_keeps_where_it_is() {
        let (robot, config) = jvrc1();
        let joint = |name| robot.model.joint_index(name).expect("a JVRC-1 joint");
        // The right hand held and measured carrying 100 N.
        let mut targets = Targets::none();
        targets.contacts = [true, true, false, true];
        let mut support = HandSupport::default();
        for _ in 0..1000 {
            support.update(&targets.contacts, None, &config, 600.0, 0.01);
            support.sense(&[250.0, 250.0, 0.0, 100.0], 0.01);
        }
        targets.hand_load = support.load(&targets.anchors, 600.0);
        assert!(targets.hand_load.carries(EndEffector::RightHand));
        let [right_elbow, left_elbow] = pulled(
            &robot,
            &config,
            &targets,
            [joint("R_ELBOW_P"), joint("L_ELBOW_P")],
        );
        assert!(
            !right_elbow,
            "the stance's elbow angle pulls the carrying arm"
        );
        assert!(left_elbow, "the free arm no longer follows the stance");
    }
}
