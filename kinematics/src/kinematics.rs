//! Forward kinematics, centre of mass and Jacobians in a reusable workspace.
//!
//! [`Kinematics::update`] evaluates every link pose and the centre of mass in one pass over the
//! links in depth-first order; the Jacobian functions then read those results. When only a few
//! frame poses are needed, [`Kinematics::update_frames`] evaluates just the links on their ancestor
//! chains (a [`FrameSet`] precomputed once). Nothing allocates after [`Kinematics::new`].

use nalgebra::{DMatrix, Isometry3, Vector3};

use crate::configuration::Configuration;
use crate::model::{Body, FrameId, JointMotion, LinkId, Model};

/// World poses of all links, the centre of mass, and the per-joint data the Jacobians need.
#[derive(Debug, Clone)]
pub struct Kinematics {
    /// World pose of every link.
    poses: Vec<Isometry3<f64>>,
    /// World direction of every actuated joint's axis.
    axes: Vec<Vector3<f64>>,
    /// Per link: Σ mᵢ·cᵢ over the link's subtree (world frame).
    subtree_moments: Vec<Vector3<f64>>,
    com: Vector3<f64>,
}

/// The links [`Kinematics::update_frames`] must evaluate to pose a fixed set of frames: the union
/// of the frames' ancestor chains (base to attached link), in link order so parents come first.
/// Built once per model and frame list, so the update itself does not allocate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameSet {
    /// Link indices in increasing (depth-first, parent-first) order, without duplicates.
    links: Vec<usize>,
    /// Link count of the model the set was built for (guards against mixing models).
    link_count: usize,
}

impl FrameSet {
    /// The ancestor links of `frames` in `model`.
    ///
    /// # Panics
    /// If a frame id does not belong to `model`.
    pub fn new(model: &Model, frames: &[FrameId]) -> Self {
        let bodies = model.bodies();
        let mut needed = vec![false; bodies.len()];
        for &frame in frames {
            let mut link = Some(model.frame_link(frame).index());
            while let Some(l) = link {
                if needed[l] {
                    break;
                }
                needed[l] = true;
                link = bodies[l].parent;
            }
        }
        let links = (0..bodies.len()).filter(|&l| needed[l]).collect();
        Self {
            links,
            link_count: bodies.len(),
        }
    }

    /// The links evaluated, in evaluation order.
    pub fn links(&self) -> impl ExactSizeIterator<Item = LinkId> + '_ {
        self.links.iter().map(|&l| LinkId(l))
    }
}

impl Kinematics {
    /// Allocates a workspace for `model` (all links at the identity until the first update).
    pub fn new(model: &Model) -> Self {
        Self {
            poses: vec![Isometry3::identity(); model.link_count()],
            axes: vec![Vector3::zeros(); model.dof()],
            subtree_moments: vec![Vector3::zeros(); model.link_count()],
            com: Vector3::zeros(),
        }
    }

    /// Forward kinematics of every link and the centre of mass at `q`. Does not allocate.
    ///
    /// # Panics
    /// If `q.joints` does not have `model.dof()` entries or the workspace was built for another model.
    pub fn update(&mut self, model: &Model, q: &Configuration) {
        self.assert_fits(model, q, "Kinematics::update");
        let bodies = model.bodies();
        for (i, body) in bodies.iter().enumerate() {
            let pose = self.place_link(body, q);
            self.subtree_moments[i] =
                (pose.translation.vector + pose.rotation * body.com) * body.mass;
            self.poses[i] = pose;
        }
        for i in (1..bodies.len()).rev() {
            if let Some(parent) = bodies[i].parent {
                let moment = self.subtree_moments[i];
                self.subtree_moments[parent] += moment;
            }
        }
        let total = model.total_mass();
        self.com = if total > 0.0 {
            self.subtree_moments[0] / total
        } else {
            self.poses[0].translation.vector
        };
    }

    /// Forward kinematics of only the links on the ancestor chains of `frames` at `q`: afterwards
    /// [`Kinematics::frame_pose`] of those frames (and [`Kinematics::link_pose`] of those links)
    /// equal what [`Kinematics::update`] gives, while every other link pose, the centre of mass,
    /// and all Jacobians still hold stale values from an earlier update and must not be read.
    /// Does not allocate.
    ///
    /// # Panics
    /// If `q.joints` does not have `model.dof()` entries, or the workspace or `frames` was built
    /// for another model.
    pub fn update_frames(&mut self, model: &Model, q: &Configuration, frames: &FrameSet) {
        self.assert_fits(model, q, "Kinematics::update_frames");
        assert_eq!(
            frames.link_count,
            model.link_count(),
            "Kinematics::update_frames: frame set of another model"
        );
        let bodies = model.bodies();
        for &link in &frames.links {
            self.poses[link] = self.place_link(&bodies[link], q);
        }
    }

    /// Panics, naming `caller`, unless `q` and this workspace are of `model`.
    fn assert_fits(&self, model: &Model, q: &Configuration, caller: &str) {
        assert_eq!(q.joints.len(), model.dof(), "{caller}: wrong joint count");
        assert_eq!(
            self.poses.len(),
            model.link_count(),
            "{caller}: workspace of another model"
        );
    }

    /// World pose of `body` from its parent's (already updated) pose and its joint value; records
    /// the world axis of its joint. Shared by both updates so their poses agree bit for bit.
    #[inline(always)]
    fn place_link(&mut self, body: &Body, q: &Configuration) -> Isometry3<f64> {
        let Some(parent) = body.parent else {
            return q.base;
        };
        let mut pose = self.poses[parent] * body.origin;
        match body.motion {
            JointMotion::Fixed => {}
            JointMotion::Revolute { axis, index } => {
                self.axes[index] = pose.rotation * axis.into_inner();
                pose.rotation *= nalgebra::UnitQuaternion::from_axis_angle(&axis, q.joints[index]);
            }
            JointMotion::Prismatic { axis, index } => {
                let world_axis = pose.rotation * axis.into_inner();
                self.axes[index] = world_axis;
                pose.translation.vector += world_axis * q.joints[index];
            }
        }
        pose
    }

    /// World pose of a link (after [`Kinematics::update`]).
    pub fn link_pose(&self, link: LinkId) -> &Isometry3<f64> {
        &self.poses[link.index()]
    }

    /// World pose of a frame added with [`Model::add_frame`].
    pub fn frame_pose(&self, model: &Model, frame: FrameId) -> Isometry3<f64> {
        self.poses[model.frame_link(frame).index()] * model.frame_offset(frame)
    }

    /// Centre of mass in the world frame.
    pub fn com(&self) -> Vector3<f64> {
        self.com
    }

    /// Jacobian of `frame`: ν ↦ (linear velocity of the frame origin; angular velocity), both in
    /// the world frame. Rows 0..3 linear, 3..6 angular; columns follow ν = (v, ω, q̇).
    ///
    /// # Panics
    /// If `out` is not 6 × `model.nv()`.
    pub fn frame_jacobian(&self, model: &Model, frame: FrameId, out: &mut DMatrix<f64>) {
        let link = model.frame_link(frame).index();
        let point = self.frame_pose(model, frame).translation.vector;
        self.point_jacobian(model, link, &point, out);
    }

    /// Jacobian of a link frame, same convention as [`Kinematics::frame_jacobian`].
    ///
    /// # Panics
    /// If `out` is not 6 × `model.nv()`.
    pub fn link_jacobian(&self, model: &Model, link: LinkId, out: &mut DMatrix<f64>) {
        let point = self.poses[link.index()].translation.vector;
        self.point_jacobian(model, link.index(), &point, out);
    }

    /// Jacobian of the centre of mass: ν ↦ ċ in the world frame (3 × nv).
    ///
    /// # Panics
    /// If `out` is not 3 × `model.nv()`.
    pub fn com_jacobian(&self, model: &Model, out: &mut DMatrix<f64>) {
        assert_eq!(
            out.shape(),
            (3, model.nv()),
            "com_jacobian: out must be 3 x nv"
        );
        let total = model.total_mass();
        let lever = self.com - self.poses[0].translation.vector;
        let data = out.as_mut_slice();
        // Base linear velocity moves the CoM one to one; base rotation about its origin: ω × lever.
        data[..18].copy_from_slice(&[
            1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, //
            0.0, -lever.z, lever.y, lever.z, 0.0, -lever.x, -lever.y, lever.x, 0.0,
        ]);
        if total <= 0.0 {
            data[18..].fill(0.0);
            return;
        }
        for (joint, column) in data[18..].chunks_exact_mut(3).enumerate() {
            let link = model.joint_link(joint);
            let axis = self.axes[joint];
            let value = match model.bodies()[link].motion {
                JointMotion::Prismatic { .. } => axis * (model.subtree_mass(link) / total),
                _ => {
                    let anchor = self.poses[link].translation.vector;
                    let moment = self.subtree_moments[link] - anchor * model.subtree_mass(link);
                    axis.cross(&moment) / total
                }
            };
            column.copy_from_slice(value.as_slice());
        }
    }

    fn point_jacobian(
        &self,
        model: &Model,
        link: usize,
        point: &Vector3<f64>,
        out: &mut DMatrix<f64>,
    ) {
        assert_eq!(
            out.shape(),
            (6, model.nv()),
            "frame_jacobian: out must be 6 x nv"
        );
        let lever = point - self.poses[0].translation.vector;
        let data = out.as_mut_slice();
        data.fill(0.0);
        // Base columns: v ↦ (v, 0); ω ↦ (ω × lever, ω).
        data[0] = 1.0;
        data[7] = 1.0;
        data[14] = 1.0;
        data[18..36].copy_from_slice(&[
            0.0, -lever.z, lever.y, 1.0, 0.0, 0.0, //
            lever.z, 0.0, -lever.x, 0.0, 1.0, 0.0, //
            -lever.y, lever.x, 0.0, 0.0, 0.0, 1.0,
        ]);
        for &joint in model.supporting_joints(link) {
            let joint_link = model.joint_link(joint);
            let axis = self.axes[joint];
            let column = &mut data[36 + 6 * joint..42 + 6 * joint];
            match model.bodies()[joint_link].motion {
                JointMotion::Prismatic { .. } => column[..3].copy_from_slice(axis.as_slice()),
                _ => {
                    let linear = axis.cross(&(point - self.poses[joint_link].translation.vector));
                    column[..3].copy_from_slice(linear.as_slice());
                    column[3..].copy_from_slice(axis.as_slice());
                }
            }
        }
    }
}
