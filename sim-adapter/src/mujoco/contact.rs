//! Force-torque readings of the soles and palms from MuJoCo's contact forces.
//!
//! Each ankle FT sensor reads the resultant of the environment's contact forces on that foot's
//! sole, each wrist FT sensor those on that hand's palm, as the wrench the environment exerts on
//! the robot, taken about the configured FT frame origin in world-aligned axes (the convention of
//! the controller's `Measurement` and of the kinematic simulator). Read right after the
//! constraint solve, while the contact list, the solved forces and the body poses all belong to
//! the same state.

use kinematics::robot::EndEffector;
use mujoco_rs::prelude::{MjData, MjModel};
use nalgebra::{Matrix3, Vector3};

/// Contact-derived quantities of the four end-effectors, in `EndEffector` order (left foot,
/// right foot, left hand, right hand: `shm_types::WRENCH_ORDER`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Contacts {
    /// (force xyz, torque xyz) of the environment on each end-effector about its FT frame origin.
    pub wrenches: [[f64; 6]; 4],
    /// Whether each end-effector touches anything.
    pub touching: [bool; 4],
    /// Deepest penetration of a sole into the terrain (m, ≥ 0).
    pub penetration: f64,
}

impl Contacts {
    /// Adds `share` of `reading`, for the mean over a control period's physics steps (touching
    /// in any of them, the deepest penetration).
    pub fn add(&mut self, reading: &Contacts, share: f64) {
        for (sum, wrench) in self.wrenches.iter_mut().zip(&reading.wrenches) {
            for (s, w) in sum.iter_mut().zip(wrench) {
                *s += w * share;
            }
        }
        for (any, touching) in self.touching.iter_mut().zip(reading.touching) {
            *any |= touching;
        }
        self.penetration = self.penetration.max(reading.penetration);
    }
}

/// MuJoCo ids the contact reading needs, in `EndEffector` order.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ContactIds {
    /// Collision geom of each end-effector: a foot's sole box, a hand's palm sphere.
    pub geoms: [usize; 4],
    /// FT frame site of each end-effector (ankle or wrist).
    pub ft_sites: [usize; 4],
}

/// Sums the contact forces on each end-effector into wrenches about its FT frame.
pub(crate) fn read(data: &MjData<Box<MjModel>>, ids: &ContactIds) -> Contacts {
    let mut out = Contacts::default();
    let sites = data.site_xpos();
    let contacts = data.contact();
    for (index, contact) in contacts.iter().enumerate() {
        let (g1, g2) = (contact.geom[0] as usize, contact.geom[1] as usize);
        // MuJoCo's contact force acts on geom2, from geom1, along the normal pointing from
        // geom1 to geom2; flip it when the end-effector is geom1.
        let (effector, sign) = match ids.geoms.iter().position(|&g| g == g2) {
            Some(effector) => (effector, 1.0),
            None => match ids.geoms.iter().position(|&g| g == g1) {
                Some(effector) => (effector, -1.0),
                None => continue,
            },
        };
        out.touching[effector] = true;
        if EndEffector::ALL[effector].is_foot() {
            out.penetration = out.penetration.max(-contact.dist);
        }
        let local = data.contact_force(index);
        // Rows of `frame` are the contact axes (normal, tangent 1, tangent 2) in world coordinates.
        let axes = Matrix3::from_row_slice(&contact.frame).transpose();
        let force = axes * Vector3::new(local[0], local[1], local[2]) * sign;
        let torque = axes * Vector3::new(local[3], local[4], local[5]) * sign;
        let arm = Vector3::from(contact.pos) - Vector3::from(sites[ids.ft_sites[effector]]);
        let moment = torque + arm.cross(&force);
        let wrench = &mut out.wrenches[effector];
        for k in 0..3 {
            wrench[k] += force[k];
            wrench[k + 3] += moment[k];
        }
    }
    out
}
