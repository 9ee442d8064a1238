//! The URDF as `walkctl init-robot` reads it: the validated kinematic model (forward kinematics,
//! masses) plus what that model leaves out and the guesses need — which link hangs on which
//! joint, which joints are fixed, the joint axes, the links' inertia tensors and their primitive
//! (box, cylinder, sphere) collision or visual geometry. Meshes are not read (the vendored models
//! ship none), so a link drawn only by meshes has no geometry here.

use std::path::{Path, PathBuf};

use anyhow::Context;
use kinematics::model::pose_from_xyz_rpy;
use kinematics::{Configuration, Isometry3, Kinematics, LinkId, Model, Vector3};
use nalgebra::Matrix3;

/// A primitive shape of a link, in that link's frame (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// A box centred at `pose` with half extents along its axes.
    Box {
        /// Pose of the box centre in the link frame.
        pose: Isometry3<f64>,
        /// Half extents along the box axes.
        half: Vector3<f64>,
    },
    /// A cylinder (or capsule, its caps included) along the z axis of `pose`.
    Cylinder {
        /// Pose of the cylinder centre in the link frame.
        pose: Isometry3<f64>,
        /// Radius.
        radius: f64,
        /// Half the length along the axis (with a capsule's caps).
        half_length: f64,
    },
    /// A sphere.
    Sphere {
        /// Centre in the link frame.
        centre: Vector3<f64>,
        /// Radius.
        radius: f64,
    },
}

impl Primitive {
    /// Lowest and highest coordinate of the shape along the unit `direction`, for a link at
    /// `link` (its world pose).
    pub fn extent(&self, link: &Isometry3<f64>, direction: &Vector3<f64>) -> (f64, f64) {
        match self {
            Primitive::Box { pose, half } => {
                let world = link * pose;
                let centre = world.translation.vector.dot(direction);
                let reach: f64 = (0..3)
                    .map(|axis| {
                        let column = world.rotation * Vector3::ith(axis, 1.0);
                        column.dot(direction).abs() * half[axis]
                    })
                    .sum();
                (centre - reach, centre + reach)
            }
            Primitive::Cylinder {
                pose,
                radius,
                half_length,
            } => {
                let world = link * pose;
                let centre = world.translation.vector.dot(direction);
                let axis = (world.rotation * Vector3::z()).dot(direction).abs();
                let reach = axis * half_length + radius * (1.0 - axis * axis).max(0.0).sqrt();
                (centre - reach, centre + reach)
            }
            Primitive::Sphere { centre, radius } => {
                let centre = (link * nalgebra::Point3::from(*centre))
                    .coords
                    .dot(direction);
                (centre - radius, centre + radius)
            }
        }
    }
}

/// What the URDF says about one link besides what [`Model`] keeps.
#[derive(Debug, Clone)]
pub struct LinkFacts {
    /// The joint that attaches the link to its parent (`None` for the root).
    pub joint: Option<String>,
    /// The model-order index of that joint when it is actuated (fixed and mimic joints: `None`).
    pub actuated: Option<usize>,
    /// The actuated joint's axis in the link frame (unit; zero for fixed joints).
    pub axis: Vector3<f64>,
    /// Rotational inertia about the link's centre of mass, in the link frame.
    pub inertia: Matrix3<f64>,
    /// Primitive collision shapes, or the primitive visual shapes when there are none.
    pub shapes: Vec<Primitive>,
    /// Whether `shapes` came from `<collision>` (else from `<visual>`).
    pub shapes_from_collision: bool,
}

/// A URDF loaded for guessing: the kinematic model and the facts per link.
#[derive(Debug, Clone)]
pub struct UrdfModel {
    /// Where the URDF was read from.
    pub path: PathBuf,
    /// The validated kinematic model.
    pub model: Model,
    /// Facts per link, indexed like [`Model::link_names`].
    pub links: Vec<LinkFacts>,
    /// The link each actuated joint moves, in model order.
    joint_links: Vec<LinkId>,
    /// Children of each link.
    children: Vec<Vec<LinkId>>,
}

/// Shapes smaller than this (m) in every direction are placeholders, not geometry.
const MIN_SHAPE: f64 = 1e-4;

impl UrdfModel {
    /// Reads and validates the URDF at `path` (the same validation as every robot load).
    pub fn load(path: &Path) -> anyhow::Result<UrdfModel> {
        let model = Model::from_urdf_path(path)
            .with_context(|| format!("{}: invalid URDF", path.display()))?;
        let robot = urdf_rs::read_file(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read URDF: {e}", path.display()))?;
        let mut links: Vec<Option<LinkFacts>> = vec![None; model.link_count()];
        let mut joint_links = vec![LinkId::BASE; model.dof()];
        for link in &robot.links {
            let id = model
                .link_index(&link.name)
                .expect("the model has every URDF link");
            let joint = robot.joints.iter().find(|j| j.child.link == link.name);
            let actuated = joint.and_then(|j| model.joint_index(&j.name));
            if let Some(index) = actuated {
                joint_links[index] = id;
            }
            let axis = match (joint, actuated) {
                (Some(j), Some(_)) => Vector3::from(j.axis.xyz.0).normalize(),
                _ => Vector3::zeros(),
            };
            let collision: Vec<Primitive> = link
                .collision
                .iter()
                .filter_map(|c| primitive(&c.origin, &c.geometry))
                .collect();
            let from_collision = !collision.is_empty();
            let shapes = if from_collision {
                collision
            } else {
                link.visual
                    .iter()
                    .filter_map(|v| primitive(&v.origin, &v.geometry))
                    .collect()
            };
            let i = &link.inertial.inertia;
            let tensor = Matrix3::new(
                i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
            );
            let rotation = pose_from_xyz_rpy([0.0; 3], link.inertial.origin.rpy.0).rotation;
            let r = rotation.to_rotation_matrix().into_inner();
            links[id.index()] = Some(LinkFacts {
                joint: joint.map(|j| j.name.clone()),
                actuated,
                axis,
                inertia: r * tensor * r.transpose(),
                shapes,
                shapes_from_collision: from_collision,
            });
        }
        let links: Vec<LinkFacts> = links
            .into_iter()
            .map(|l| l.expect("every model link is a URDF link"))
            .collect();
        let mut children = vec![Vec::new(); model.link_count()];
        for link in model.link_ids() {
            if let Some(parent) = model.link_parent(link) {
                children[parent.index()].push(link);
            }
        }
        Ok(UrdfModel {
            path: path.to_owned(),
            model,
            links,
            joint_links,
            children,
        })
    }

    /// The facts of `link`.
    pub fn facts(&self, link: LinkId) -> &LinkFacts {
        &self.links[link.index()]
    }

    /// The name of `link`.
    pub fn name(&self, link: LinkId) -> &str {
        self.model.link_name(link)
    }

    /// Looks a link up by name, with an error naming the option that gave it.
    pub fn link(&self, name: &str, option: &str) -> anyhow::Result<LinkId> {
        self.model.link_index(name).ok_or_else(|| {
            anyhow::anyhow!(
                "{option} {name}: {} has no link '{name}'",
                self.path.display()
            )
        })
    }

    /// The link that actuated joint `joint` (model order) moves.
    pub fn joint_link(&self, joint: usize) -> LinkId {
        self.joint_links[joint]
    }

    /// The name of actuated joint `joint`.
    pub fn joint_name(&self, joint: usize) -> &str {
        &self.model.joint_names()[joint]
    }

    /// The children of `link`.
    pub fn children(&self, link: LinkId) -> &[LinkId] {
        &self.children[link.index()]
    }

    /// `link` and its ancestors up to the root, nearest first.
    pub fn ancestry(&self, link: LinkId) -> Vec<LinkId> {
        let mut path = vec![link];
        let mut current = link;
        while let Some(parent) = self.model.link_parent(current) {
            path.push(parent);
            current = parent;
        }
        path
    }

    /// The deepest link that is an ancestor of (or equal to) both `a` and `b`.
    pub fn common_ancestor(&self, a: LinkId, b: LinkId) -> LinkId {
        let above_b = self.ancestry(b);
        self.ancestry(a)
            .into_iter()
            .find(|l| above_b.contains(l))
            .unwrap_or(LinkId::BASE)
    }

    /// The actuated joints between `ancestor` (excluded) and `link` (its own joint included),
    /// from `ancestor` down.
    pub fn chain(&self, ancestor: LinkId, link: LinkId) -> Vec<usize> {
        let mut joints: Vec<usize> = self
            .ancestry(link)
            .into_iter()
            .take_while(|&l| l != ancestor)
            .filter_map(|l| self.facts(l).actuated)
            .collect();
        joints.reverse();
        joints
    }

    /// `link` and every link welded to it below (reached through fixed joints only).
    pub fn rigid_group(&self, link: LinkId) -> Vec<LinkId> {
        let mut group = vec![link];
        let mut next = 0;
        while next < group.len() {
            let current = group[next];
            next += 1;
            for &child in self.children(current) {
                if self.facts(child).actuated.is_none() {
                    group.push(child);
                }
            }
        }
        group
    }

    /// `link` and all its descendants.
    pub fn subtree(&self, link: LinkId) -> Vec<LinkId> {
        let mut all = vec![link];
        let mut next = 0;
        while next < all.len() {
            let current = all[next];
            next += 1;
            all.extend_from_slice(self.children(current));
        }
        all
    }

    /// Whether any link below `link` is moved by an actuated joint.
    pub fn has_actuated_descendant(&self, link: LinkId) -> bool {
        self.subtree(link)
            .into_iter()
            .skip(1)
            .any(|l| self.facts(l).actuated.is_some())
    }
}

/// A URDF geometry as a primitive in the link frame, or `None` for meshes and placeholders.
fn primitive(origin: &urdf_rs::Pose, geometry: &urdf_rs::Geometry) -> Option<Primitive> {
    let pose = pose_from_xyz_rpy(origin.xyz.0, origin.rpy.0);
    let shape = match geometry {
        urdf_rs::Geometry::Box { size } => Primitive::Box {
            pose,
            half: Vector3::from(size.0) / 2.0,
        },
        urdf_rs::Geometry::Cylinder { radius, length } => Primitive::Cylinder {
            pose,
            radius: *radius,
            half_length: length / 2.0,
        },
        urdf_rs::Geometry::Capsule { radius, length } => Primitive::Cylinder {
            pose,
            radius: *radius,
            half_length: length / 2.0 + radius,
        },
        urdf_rs::Geometry::Sphere { radius } => Primitive::Sphere {
            centre: pose.translation.vector,
            radius: *radius,
        },
        urdf_rs::Geometry::Mesh { .. } => return None,
    };
    let big = match shape {
        Primitive::Box { half, .. } => half.max() * 2.0 >= MIN_SHAPE,
        Primitive::Cylinder {
            radius,
            half_length,
            ..
        } => radius.max(half_length) * 2.0 >= MIN_SHAPE,
        Primitive::Sphere { radius, .. } => radius * 2.0 >= MIN_SHAPE,
    };
    big.then_some(shape)
}

/// The model's links and joints in one configuration, in the model's root frame.
pub struct Posed<'a> {
    model: &'a UrdfModel,
    kinematics: Kinematics,
}

impl<'a> Posed<'a> {
    /// Forward kinematics of `model` at `q`.
    pub fn new(model: &'a UrdfModel, q: &Configuration) -> Self {
        let mut kinematics = Kinematics::new(&model.model);
        kinematics.update(&model.model, q);
        Self { model, kinematics }
    }

    /// World pose of `link`.
    pub fn link(&self, link: LinkId) -> Isometry3<f64> {
        *self.kinematics.link_pose(link)
    }

    /// World position of actuated joint `joint` (its child link's origin).
    pub fn joint_origin(&self, joint: usize) -> Vector3<f64> {
        self.link(self.model.joint_link(joint)).translation.vector
    }

    /// World axis of actuated joint `joint` (unit).
    pub fn joint_axis(&self, joint: usize) -> Vector3<f64> {
        let link = self.model.joint_link(joint);
        self.link(link).rotation * self.model.facts(link).axis
    }

    /// World centre of mass of `link`.
    pub fn link_com(&self, link: LinkId) -> Vector3<f64> {
        let pose = self.link(link);
        (pose * nalgebra::Point3::from(*self.model.model.link_com(link))).coords
    }

    /// The whole model's centre of mass.
    pub fn com(&self) -> Vector3<f64> {
        self.kinematics.com()
    }

    /// Mass, centre of mass and inertia about it (world axes) of a set of links.
    pub fn mass_properties(&self, links: &[LinkId]) -> (f64, Vector3<f64>, Matrix3<f64>) {
        let model = &self.model.model;
        let mass: f64 = links.iter().map(|&l| model.link_mass(l)).sum();
        if mass <= 0.0 {
            return (0.0, Vector3::zeros(), Matrix3::zeros());
        }
        let com = links
            .iter()
            .map(|&l| self.link_com(l) * model.link_mass(l))
            .sum::<Vector3<f64>>()
            / mass;
        let mut inertia = Matrix3::zeros();
        for &l in links {
            let m = model.link_mass(l);
            let r = self.link(l).rotation.to_rotation_matrix().into_inner();
            let d = self.link_com(l) - com;
            inertia += r * self.model.facts(l).inertia * r.transpose()
                + m * (Matrix3::identity() * d.dot(&d) - d * d.transpose());
        }
        (mass, com, inertia)
    }
}
