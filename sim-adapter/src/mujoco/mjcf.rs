//! Writes the MuJoCo model (MJCF) of a robot standing on a floor, or in a scene's terrain.
//!
//! Generated from the URDF's kinematics and inertials (see `bodies`) rather than loaded with
//! MuJoCo's URDF importer, so no mesh is needed and every modelling choice is explicit:
//! - a free joint on the base and an infinite floor plane at z = 0 (with a [`Terrain`], the
//!   plane at its base, and its surface boxes and railing capsules: see `terrain`);
//! - one hinge/slide joint per actuated joint, with the URDF position limits, armature and
//!   damping, and the URDF effort limit as the bound on its actuators' torque (motor
//!   saturation; a URDF effort of 0 or none leaves it unbounded);
//! - collision geometry only where contact is meaningful: one box per foot, the configured sole
//!   rectangle with its bottom face on the sole frame, colliding with the ground; one sphere per
//!   hand, `[robot] palm_radius` around the hand frame, colliding with the railings and the
//!   ground (a hand that reaches the ground in a fall lands on it);
//! - with a [`Terrain`], a capsule along each leg bone (below), colliding with the floor and the
//!   terrain only;
//! - sites at every end-effector frame, the four FT frames (ankles and wrists) and the base (the
//!   IMU);
//! - per joint a position and a velocity actuator (the servo), in model joint order; a joint
//!   weaker than [`SERVO_REFERENCE_EFFORT_NM`] has its gains and armature scaled down
//!   ([`servo_scale`]);
//! - IMU sensors (orientation, gyro, accelerometer) at the base site;
//! - with `visual_geoms`, what pictures need and the physics ignores ([`visuals`](super::visuals)):
//!   visual-only geoms of the links in geom group [`VISUAL_GROUP`](super::visuals::VISUAL_GROUP)
//!   (no collision: `contype` = `conaffinity` = 0 by default; no inertia: `inertiafromgeom` is
//!   false), a floor texture, a sky and an offscreen buffer.
//!
//! Collision classes: the environment's geoms set `contype`, the robot's `conaffinity`, so the
//! robot never collides with itself. Bit [`GROUND_BIT`]: the floor and the terrain's surfaces
//! against the soles, the palms and the leg capsules. Bit [`RAILING_BIT`]: the railings, against
//! the palms. A palm's contact with a railing is friction only (the railing's, 1.0): no grip,
//! no weld, so a hand carries load by pressing on the rail.
//!
//! Leg bones: for each body moved by a `[robot.joint_groups] legs` joint, a capsule from its
//! origin (the joint) to each child body's origin, [`leg_radius`] thick, hidden in geom group
//! [`LEG_GROUP`] (the skeleton draws the legs). Bones shorter than
//! [`kinematics::skeleton::MIN_SEGMENT`] (coincident axes of a hip or an ankle) are skipped, and
//! the foot body has no child: the shin's capsule ends at the ankle, whose height above the sole
//! (0.108 m on JVRC-1, 0.089 m on ARMAR-4) exceeds the radius, so flat ground never reaches it.

use std::fmt::Write;

use kinematics::model::{FrameId, JointLimits, Model};
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Translation3, Vector3};

use super::MujocoError;
use super::bodies::{MassProperties, RigidBodies};
use super::options::MujocoOptions;
use super::terrain::Terrain;
use super::visuals::{self, VisualGeom};

/// The motor torque (N·m) the default servo gains and armature were tuned for: JVRC-1's URDF
/// effort on every joint. See [`servo_scale`].
pub const SERVO_REFERENCE_EFFORT_NM: f64 = 100.0;

/// The factor on a joint's servo gains and armature: its effort limit over
/// [`SERVO_REFERENCE_EFFORT_NM`], at most 1 (1 without a limit). At the default gains a 100 N·m
/// joint saturates at 1 mrad of position error and 0.1 rad/s of velocity error; a weaker joint
/// would saturate earlier and act as a bang-bang controller: iCub's 37 N·m knees and ankles
/// chattered under walkd's closed loop in their first double support (foot forces jumping
/// between 0 and 931 N under a 324 N robot). Scaled, every joint saturates no earlier than a
/// 100 N·m one, and the servo's stability margin kp·h²/armature is unchanged. Stronger joints
/// keep the default, bit for bit.
pub fn servo_scale(limits: &JointLimits) -> f64 {
    effort_bound(limits).map_or(1.0, |effort| (effort / SERVO_REFERENCE_EFFORT_NM).min(1.0))
}

/// The joint's motor torque bound: its URDF effort, unless that is 0 or absent (unbounded).
fn effort_bound(limits: &JointLimits) -> Option<f64> {
    Some(limits.effort).filter(|effort| effort.is_finite() && *effort > 0.0)
}

/// Name of the floating base's free joint.
pub(crate) const FREE_JOINT: &str = "floating_base";
/// Site name of the IMU at the floating base origin (the URDF root link).
pub(crate) const IMU_SITE: &str = "imu";
/// Site names of the FT frames, in `EndEffector` order (ankles, then wrists).
pub(crate) const FT_SITES: [&str; 4] = [
    "left_foot_ft",
    "right_foot_ft",
    "left_hand_ft",
    "right_hand_ft",
];
/// Geom names of the end-effectors' collision geoms, in `EndEffector` order: the sole boxes,
/// then the palm spheres.
pub(crate) const CONTACT_GEOMS: [&str; 4] = ["left_sole", "right_sole", "left_palm", "right_palm"];
/// Collision bit of the ground: the floor and the terrain's surfaces (`contype`), the soles, the
/// palms and the leg capsules (`conaffinity`).
pub(crate) const GROUND_BIT: u32 = 1;
/// Collision bit of the railings (`contype`) and the palms (`conaffinity`).
pub(crate) const RAILING_BIT: u32 = 2;
/// Geom group of the leg capsules: not drawn (MuJoCo draws groups 0–2 by default).
pub(crate) const LEG_GROUP: u32 = 3;
/// Name prefixes of the terrain's surface boxes, railing capsules and the leg capsules.
pub(crate) const SURFACE_PREFIX: &str = "surface/";
pub(crate) const RAILING_PREFIX: &str = "railing/";
pub(crate) const LEG_PREFIX: &str = "leg/";
/// Sliding friction of a railing: a hand's grip, whatever the soles' `friction` option.
const RAILING_FRICTION: f64 = 1.0;
/// The leg capsules' radius is this fraction of the sole width: a leg about as wide as its foot.
const LEG_RADIUS_PER_SOLE_WIDTH: f64 = 0.5;
/// Colours of the terrain in pictures.
const SURFACE_RGBA: &str = "0.80 0.76 0.70 1";
const RAILING_RGBA: &str = "0.55 0.35 0.20 1";
/// Sensor data layout: base orientation quaternion (w, x, y, z), gyro, accelerometer.
pub(crate) const IMU_QUAT: std::ops::Range<usize> = 0..4;
pub(crate) const IMU_GYRO: std::ops::Range<usize> = 4..7;
pub(crate) const IMU_ACCEL: std::ops::Range<usize> = 7..10;

/// Site name of an end-effector frame.
pub(crate) fn end_effector_site(effector: EndEffector) -> &'static str {
    effector.name()
}

/// Radius of the leg capsules of `robot` (m): half its sole width (0.04 m on JVRC-1, 0.062 m
/// on ARMAR-4).
fn leg_radius(robot: &Robot) -> f64 {
    robot.sole.width * LEG_RADIUS_PER_SOLE_WIDTH
}

/// The MJCF document of `robot` built from `bodies`, on the flat floor or in `terrain`.
pub(crate) fn write(
    robot: &Robot,
    bodies: &RigidBodies,
    options: &MujocoOptions,
    terrain: Option<&Terrain>,
) -> Result<String, MujocoError> {
    let mut xml = String::with_capacity(64 * 1024);
    let o = options;
    // `write!` into a String cannot fail; the results are ignored throughout.
    let _ = writeln!(xml, r#"<mujoco model="{}">"#, escape(robot.model.name()));
    let _ = writeln!(
        xml,
        r#"  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>"#
    );
    let _ = writeln!(
        xml,
        r#"  <option timestep="{}" integrator="implicitfast" gravity="0 0 -{}" cone="elliptic" impratio="{}"/>"#,
        o.timestep,
        kinematics::ground::GRAVITY,
        o.impratio
    );
    let _ = writeln!(xml, "  <default>");
    let _ = writeln!(
        xml,
        r#"    <joint armature="{}" damping="{}"/>"#,
        o.armature, o.joint_damping
    );
    let _ = writeln!(
        xml,
        r#"    <geom contype="0" conaffinity="0" condim="3" friction="{} 0.005 0.0001" solref="{} 1"/>"#,
        o.friction, o.contact_time_constant
    );
    let _ = writeln!(xml, "  </default>");
    if o.visual_geoms {
        xml.push_str(&visuals::scene());
    }
    let _ = writeln!(xml, "  <worldbody>");
    // The floor collides with whatever has conaffinity 1: the feet (and the leg capsules).
    let floor_material = if o.visual_geoms {
        visuals::FLOOR_MATERIAL
    } else {
        ""
    };
    let floor_position = match terrain {
        None => String::new(),
        Some(terrain) => format!(r#" pos="0 0 {}""#, terrain.base()),
    };
    let _ = writeln!(
        xml,
        r#"    <geom name="floor" type="plane" size="0 0 1"{floor_position} contype="{GROUND_BIT}"{floor_material}/>"#
    );
    let mut attachments = Attachments::collect(robot, bodies, o.sole_thickness)?;
    if let Some(terrain) = terrain {
        write_terrain(&mut xml, terrain);
        attachments.add_leg_bones(robot, bodies);
    }
    if o.visual_geoms {
        attachments.add_visuals(robot, bodies)?;
    }
    write_body(&mut xml, robot, bodies, &attachments, o, 0, 2);
    let _ = writeln!(xml, "  </worldbody>");
    let _ = writeln!(xml, "  <actuator>");
    let limits = robot.model.joint_limits();
    for (joint, limits) in robot.model.joint_names().iter().zip(limits) {
        let name = escape(joint);
        let scale = servo_scale(limits);
        let _ = writeln!(
            xml,
            r#"    <position joint="{name}" kp="{}"/>"#,
            o.servo_stiffness * scale
        );
        let _ = writeln!(
            xml,
            r#"    <velocity joint="{name}" kv="{}"/>"#,
            o.servo_damping * scale
        );
    }
    let _ = writeln!(xml, "  </actuator>");
    let _ = writeln!(xml, "  <sensor>");
    let _ = writeln!(
        xml,
        r#"    <framequat objtype="site" objname="{IMU_SITE}"/>"#
    );
    let _ = writeln!(xml, r#"    <gyro site="{IMU_SITE}"/>"#);
    let _ = writeln!(xml, r#"    <accelerometer site="{IMU_SITE}"/>"#);
    let _ = writeln!(xml, "  </sensor>");
    let _ = writeln!(xml, "</mujoco>");
    Ok(xml)
}

/// The static geoms of `terrain` in the worldbody: a box per surface, a capsule per railing.
fn write_terrain(xml: &mut String, terrain: &Terrain) {
    for surface in terrain.boxes() {
        let h = &surface.half;
        let _ = writeln!(
            xml,
            r#"    <geom name="{SURFACE_PREFIX}{}" type="box" size="{} {} {}" {} contype="{GROUND_BIT}" rgba="{SURFACE_RGBA}"/>"#,
            escape(&surface.name),
            h.x,
            h.y,
            h.z,
            pose_attributes(&surface.pose)
        );
    }
    for (railing, radius) in terrain.railings() {
        let _ = writeln!(
            xml,
            r#"    <geom name="{RAILING_PREFIX}{}" type="capsule" size="{radius}" {} contype="{RAILING_BIT}" friction="{RAILING_FRICTION} 0.005 0.0001" rgba="{RAILING_RGBA}"/>"#,
            escape(&railing.name),
            fromto(&railing.start, &railing.end)
        );
    }
}

/// A site or geom hung on a rigid body.
struct Attachment {
    body: usize,
    pose: Isometry3<f64>,
    kind: AttachmentKind,
}

enum AttachmentKind {
    Site(&'static str),
    /// A foot collision box: (name, half extents).
    SoleBox(&'static str, Vector3<f64>),
    /// A hand collision sphere: (name, radius).
    Palm(&'static str, f64),
    /// A leg bone's collision capsule from the body origin to `end`, in the body frame (the
    /// attachment pose is unused).
    LegBone {
        name: String,
        end: Vector3<f64>,
        radius: f64,
    },
    /// A visual-only geom (its pose is in the geom; the attachment pose is unused).
    Visual(VisualGeom),
}

struct Attachments(Vec<Attachment>);

impl Attachments {
    fn collect(
        robot: &Robot,
        bodies: &RigidBodies,
        sole_thickness: f64,
    ) -> Result<Self, MujocoError> {
        let mut all = vec![Attachment {
            body: 0,
            pose: Isometry3::identity(),
            kind: AttachmentKind::Site(IMU_SITE),
        }];
        for effector in EndEffector::ALL {
            let (body, pose) = place_frame(&robot.model, bodies, robot.frame(effector))?;
            all.push(Attachment {
                body,
                pose,
                kind: AttachmentKind::Site(end_effector_site(effector)),
            });
        }
        let half = Vector3::new(robot.sole.length, robot.sole.width, sole_thickness) / 2.0;
        let ft_frames = robot.ft_sensors.iter().chain(&robot.wrist_ft_sensors);
        for ((effector, geom), (&ft_frame, ft_site)) in EndEffector::ALL
            .into_iter()
            .zip(CONTACT_GEOMS)
            .zip(ft_frames.zip(FT_SITES))
        {
            let (body, frame) = place_frame(&robot.model, bodies, robot.frame(effector))?;
            let (pose, kind) = if effector.is_foot() {
                // The box's bottom face lies on the sole plane: its centre is half a thickness
                // above.
                let pose = frame * Translation3::new(0.0, 0.0, half.z);
                (pose, AttachmentKind::SoleBox(geom, half))
            } else {
                (frame, AttachmentKind::Palm(geom, robot.palm_radius))
            };
            all.push(Attachment { body, pose, kind });
            let (body, pose) = place_frame(&robot.model, bodies, ft_frame)?;
            all.push(Attachment {
                body,
                pose,
                kind: AttachmentKind::Site(ft_site),
            });
        }
        Ok(Self(all))
    }

    /// Adds a collision capsule along each bone of the legs (see the module docs).
    fn add_leg_bones(&mut self, robot: &Robot, bodies: &RigidBodies) {
        let radius = leg_radius(robot);
        let legs = &robot.joint_groups.legs;
        for (index, body) in bodies.bodies.iter().enumerate() {
            if !body.joint.as_ref().is_some_and(|j| legs.contains(&j.index)) {
                continue;
            }
            for child in bodies.bodies.iter().filter(|c| c.parent == Some(index)) {
                let end = child.origin.translation.vector;
                if end.norm() < kinematics::skeleton::MIN_SEGMENT {
                    continue;
                }
                self.0.push(Attachment {
                    body: index,
                    pose: Isometry3::identity(),
                    kind: AttachmentKind::LegBone {
                        name: format!("{LEG_PREFIX}{}/{}", body.name, child.name),
                        end,
                        radius,
                    },
                });
            }
        }
    }

    /// Adds the visual-only geoms of every link's skeleton shapes.
    fn add_visuals(&mut self, robot: &Robot, bodies: &RigidBodies) -> Result<(), MujocoError> {
        let shapes = kinematics::skeleton::skeleton(robot);
        // The collision boxes draw the soles already (same size and place).
        for shape in shapes
            .iter()
            .filter(|s| s.part != kinematics::skeleton::Part::Sole)
        {
            let link = robot.model.link_name(shape.link);
            let placement = bodies.links.get(link).ok_or_else(|| {
                MujocoError::ModelMismatch(format!("link '{link}' is not a link of the URDF"))
            })?;
            self.0.push(Attachment {
                body: placement.body,
                pose: Isometry3::identity(),
                kind: AttachmentKind::Visual(VisualGeom::new(shape, &placement.offset)),
            });
        }
        Ok(())
    }
}

/// Body index and pose in that body of a kinematic-model frame.
fn place_frame(
    model: &Model,
    bodies: &RigidBodies,
    frame: FrameId,
) -> Result<(usize, Isometry3<f64>), MujocoError> {
    let link = model.link_name(model.frame_link(frame));
    let placement = bodies.links.get(link).ok_or_else(|| {
        MujocoError::ModelMismatch(format!(
            "frame '{}' is attached to link '{link}', which the URDF does not have",
            model.frame_name(frame)
        ))
    })?;
    Ok((placement.body, placement.offset * model.frame_offset(frame)))
}

fn write_body(
    xml: &mut String,
    robot: &Robot,
    bodies: &RigidBodies,
    attachments: &Attachments,
    options: &MujocoOptions,
    index: usize,
    depth: usize,
) {
    let body = &bodies.bodies[index];
    let pad = "  ".repeat(depth);
    let _ = writeln!(
        xml,
        r#"{pad}<body name="{}" {}>"#,
        escape(&body.name),
        pose_attributes(&body.origin)
    );
    match &body.joint {
        None => {
            let _ = writeln!(xml, r#"{pad}  <freejoint name="{FREE_JOINT}"/>"#);
        }
        Some(joint) => {
            let limits = &robot.model.joint_limits()[joint.index];
            let kind = if joint.revolute { "hinge" } else { "slide" };
            let range = if limits.lower.is_finite() && limits.upper.is_finite() {
                format!(r#" range="{} {}""#, limits.lower, limits.upper)
            } else {
                String::new()
            };
            // The motor's torque saturation: MuJoCo clamps the sum of the joint's actuators
            // (the servo's position and velocity terms) to the URDF effort limit.
            let effort = effort_bound(limits).map_or_else(String::new, |effort| {
                format!(
                    r#" actuatorfrclimited="true" actuatorfrcrange="{} {}""#,
                    -effort, effort
                )
            });
            // A weaker motor's rotor: the armature scales with the servo's gains (the
            // actuators), so the stability margin kp·h²/armature is the same on every joint.
            let scale = servo_scale(limits);
            let armature = if scale < 1.0 {
                format!(r#" armature="{}""#, options.armature * scale)
            } else {
                String::new()
            };
            let a = joint.axis;
            let _ = writeln!(
                xml,
                r#"{pad}  <joint name="{}" type="{kind}" axis="{} {} {}"{range}{effort}{armature}/>"#,
                escape(&joint.name),
                a.x,
                a.y,
                a.z
            );
        }
    }
    write_inertial(xml, &pad, &model_error(robot, bodies, index, options));
    for attachment in attachments.0.iter().filter(|a| a.body == index) {
        match attachment.kind {
            AttachmentKind::Site(name) => {
                let _ = writeln!(
                    xml,
                    r#"{pad}  <site name="{name}" {}/>"#,
                    pose_attributes(&attachment.pose)
                );
            }
            AttachmentKind::SoleBox(name, half) => {
                let _ = writeln!(
                    xml,
                    r#"{pad}  <geom name="{name}" type="box" size="{} {} {}" conaffinity="1" {}/>"#,
                    half.x,
                    half.y,
                    half.z,
                    pose_attributes(&attachment.pose)
                );
            }
            AttachmentKind::Palm(name, radius) => {
                let _ = writeln!(
                    xml,
                    r#"{pad}  <geom name="{name}" type="sphere" size="{radius}" conaffinity="{}" {}/>"#,
                    GROUND_BIT | RAILING_BIT,
                    pose_attributes(&attachment.pose)
                );
            }
            AttachmentKind::LegBone {
                ref name,
                end,
                radius,
            } => {
                let _ = writeln!(
                    xml,
                    r#"{pad}  <geom name="{}" type="capsule" size="{radius}" {} conaffinity="{GROUND_BIT}" group="{LEG_GROUP}"/>"#,
                    escape(name),
                    fromto(&Vector3::zeros(), &end)
                );
            }
            AttachmentKind::Visual(ref geom) => {
                let _ = writeln!(xml, "{pad}  {}", geom.element());
            }
        }
    }
    for child in (0..bodies.bodies.len()).filter(|&c| bodies.bodies[c].parent == Some(index)) {
        write_body(xml, robot, bodies, attachments, options, child, depth + 1);
    }
    let _ = writeln!(xml, "{pad}</body>");
}

/// Body `index`'s mass properties with the options' model error (`mass_scale`,
/// `pelvis_com_offset`) applied.
fn model_error(
    robot: &Robot,
    bodies: &RigidBodies,
    index: usize,
    options: &MujocoOptions,
) -> MassProperties {
    let mut mass = bodies.bodies[index].mass;
    mass.mass *= options.mass_scale;
    mass.inertia *= options.mass_scale;
    let pelvis = bodies.links.get(robot.model.link_name(robot.base_link));
    if pelvis.is_some_and(|link| link.body == index) {
        mass.com += Vector3::from(options.pelvis_com_offset);
    }
    mass
}

fn write_inertial(xml: &mut String, pad: &str, mass: &MassProperties) {
    if mass.mass <= 0.0 {
        return;
    }
    let (c, i) = (&mass.com, &mass.inertia);
    let _ = writeln!(
        xml,
        r#"{pad}  <inertial pos="{} {} {}" mass="{}" fullinertia="{} {} {} {} {} {}"/>"#,
        c.x,
        c.y,
        c.z,
        mass.mass,
        i[(0, 0)],
        i[(1, 1)],
        i[(2, 2)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 2)]
    );
}

/// `pos` and `quat` (w x y z) attributes of a pose, full precision.
fn pose_attributes(pose: &Isometry3<f64>) -> String {
    let t = &pose.translation.vector;
    let q = pose.rotation.quaternion();
    format!(
        r#"pos="{} {} {}" quat="{} {} {} {}""#,
        t.x, t.y, t.z, q.w, q.i, q.j, q.k
    )
}

/// The `fromto` attribute of a capsule, full precision.
fn fromto(from: &Vector3<f64>, to: &Vector3<f64>) -> String {
    format!(
        r#"fromto="{} {} {} {} {} {}""#,
        from.x, from.y, from.z, to.x, to.y, to.z
    )
}

/// Escapes a name for an XML attribute value.
fn escape(name: &str) -> String {
    name.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    fn configs() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs")
    }

    fn model(name: &str) -> (Robot, RigidBodies) {
        let robot = Robot::load(&configs().join(format!("{name}.toml")), None).unwrap();
        let urdf = urdf_rs::read_file(&robot.urdf).unwrap();
        let bodies = RigidBodies::from_urdf(&urdf, &robot.model).unwrap();
        (robot, bodies)
    }

    /// FNV-1a, 64 bits: a fingerprint of a document that does not depend on the Rust release.
    fn fingerprint(text: &str) -> u64 {
        text.bytes().fold(0xcbf2_9ce4_8422_2325, |hash, byte| {
            (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3)
        })
    }

    #[test]
    fn without_a_terrain_the_model_is_the_flat_floor_one() {
        // Fingerprints and lengths of the documents written before terrain existed: flat walks
        // simulate the same model as then, plus the palms and the wrist FT sites (4 lines) and
        // the friction's stiffness (`impratio`, an attribute of the option line), at a finer
        // physics step (the option line's `timestep`, compared as the 1 ms it then was).
        for (name, visual_geoms, hash, length) in [
            ("jvrc1", true, 0xf8c7_5ae0_ad90_45b8, 23057),
            ("jvrc1", false, 0x58e2_14e4_fe88_b33c, 18344),
            ("armar4", true, 0x6b8e_868a_fcae_04e6, 24546),
            ("armar4", false, 0x4e47_2ea1_3357_23e1, 18853),
        ] {
            let (robot, bodies) = model(name);
            let options = MujocoOptions {
                visual_geoms,
                ..MujocoOptions::default()
            };
            let written = write(&robot, &bodies, &options, None).unwrap();
            let hands = ["left_palm", "right_palm", "left_hand_ft", "right_hand_ft"]
                .map(|name| format!(r#"name="{name}""#));
            let (added, kept): (Vec<&str>, Vec<&str>) = written
                .split_inclusive('\n')
                .partition(|line| hands.iter().any(|name| line.contains(name.as_str())));
            assert_eq!(added.len(), 4, "{name}: {added:?}");
            let stiffness = format!(r#" impratio="{}""#, options.impratio);
            assert_eq!(written.matches(&stiffness).count(), 1, "{name}");
            let step = format!(r#"timestep="{}""#, options.timestep);
            assert_eq!(written.matches(&step).count(), 1, "{name}");
            let xml = kept
                .concat()
                .replace(&stiffness, "")
                .replace(&step, r#"timestep="0.001""#);
            assert_eq!(
                (fingerprint(&xml), xml.len()),
                (hash, length),
                "{name}, visual geoms {visual_geoms}"
            );
        }
    }

    #[test]
    fn a_terrain_adds_its_geoms_and_the_leg_bones() {
        let (robot, bodies) = model("jvrc1");
        let scene = stance::Scene::from_path(&configs().join("scenes/railing.toml")).unwrap();
        let terrain = Terrain::from_scene(&scene).unwrap();
        let options = MujocoOptions::default();
        let xml = write(&robot, &bodies, &options, Some(&terrain)).unwrap();
        let flat = write(&robot, &bodies, &options, None).unwrap();
        let added: Vec<&str> = xml.lines().filter(|l| !flat.contains(*l)).collect();
        let floor = format!(
            r#"    <geom name="floor" type="plane" size="0 0 1" pos="0 0 -{}" contype="1" material="grid"/>"#,
            super::super::DEPTH_BELOW
        );
        assert_eq!(added[0], floor);
        assert!(added[1].contains(r#"name="surface/ground" type="box" size="4 1.5 0.025""#));
        assert!(added[2].contains(r#"name="railing/railing" type="capsule" size="0.02""#));
        assert!(added[2].contains(r#"contype="2" friction="1 0.005 0.0001""#));
        // Per leg: the thigh (hip to knee) and the shin (knee to ankle); the hips' and ankles'
        // coincident axes give no bone.
        let bones: Vec<&str> = added[3..]
            .iter()
            .map(|l| l.trim().split('"').nth(1).unwrap())
            .collect();
        assert_eq!(
            bones,
            [
                "leg/R_HIP_Y_S/R_KNEE_S",
                "leg/R_KNEE_S/R_ANKLE_R_S",
                "leg/L_HIP_Y_S/L_KNEE_S",
                "leg/L_KNEE_S/L_ANKLE_R_S"
            ]
        );
        for line in &added[3..] {
            assert!(
                line.contains(r#"size="0.04""#) && line.contains(r#"conaffinity="1" group="3""#),
                "{line}"
            );
        }
    }
}
