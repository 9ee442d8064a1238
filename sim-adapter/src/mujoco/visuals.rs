//! What the MuJoCo model needs for pictures and the physics ignores (`MujocoOptions::visual_geoms`):
//! visual-only geoms that draw the links, a floor texture, a sky, lights and an offscreen buffer.
//!
//! The geoms are [`kinematics::skeleton`]'s shapes — the same stick figure the observer's robot
//! description draws — placed in the rigid body their link was merged into; the soles are drawn
//! by their collision boxes, which have the same size and place. They collide with
//! nothing (`contype` = `conaffinity` = 0, the model's default) and add no inertia (the bodies'
//! inertials are explicit, `inertiafromgeom="false"`), so the dynamics are bit-identical with and
//! without them (`sim-adapter/tests/mujoco_visuals.rs`).

use std::fmt::Write;

use kinematics::skeleton::{LinkShape, Part, Shape};
use nalgebra::{Isometry3, Point3};

/// Geom group of the visual-only geoms (the collision soles stay in group 0).
pub const VISUAL_GROUP: u32 = 2;

/// Width and height of the offscreen buffer (pixels): the largest picture the renderer draws.
pub const OFFSCREEN_SIZE: (u32, u32) = (1280, 960);

/// The `<visual>` and `<asset>` elements: offscreen buffer, light, sky and floor texture.
pub fn scene() -> String {
    let (width, height) = OFFSCREEN_SIZE;
    format!(
        r#"  <visual>
    <global offwidth="{width}" offheight="{height}"/>
    <quality shadowsize="2048"/>
    <headlight ambient="0.35 0.35 0.35" diffuse="0.5 0.5 0.5" specular="0.1 0.1 0.1"/>
  </visual>
  <asset>
    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.93 0.95 0.98" rgb2="0.78 0.84 0.92" width="256" height="256"/>
    <texture name="grid" type="2d" builtin="checker" rgb1="0.90 0.90 0.88" rgb2="0.78 0.78 0.76" width="512" height="512" mark="edge" markrgb="0.6 0.6 0.6"/>
    <material name="grid" texture="grid" texrepeat="1 1" texuniform="true" reflectance="0"/>
  </asset>
"#
    )
}

/// The floor geom's material attribute.
pub const FLOOR_MATERIAL: &str = r#" material="grid""#;

/// RGBA of each part.
fn rgba(part: Part) -> &'static str {
    match part {
        Part::Limb => "0.55 0.60 0.68 1",
        Part::Sole => "0.22 0.24 0.28 1",
        Part::Hand => "0.93 0.55 0.18 1",
    }
}

/// One visual-only geom, expressed in its rigid body's frame.
#[derive(Debug, Clone)]
pub struct VisualGeom {
    element: String,
}

impl VisualGeom {
    /// The geom of `shape`, whose link sits at `offset` in its rigid body.
    pub fn new(shape: &LinkShape, offset: &Isometry3<f64>) -> Self {
        let mut e = String::from("<geom");
        let _ = write!(e, r#" group="{VISUAL_GROUP}" rgba="{}""#, rgba(shape.part));
        match shape.shape {
            Shape::Capsule { from, to, radius } => {
                let (a, b) = (offset * Point3::from(from), offset * Point3::from(to));
                let _ = write!(
                    e,
                    r#" type="capsule" size="{radius}" fromto="{} {} {} {} {} {}""#,
                    a.x, a.y, a.z, b.x, b.y, b.z
                );
            }
            Shape::Box { pose, half_extents } => {
                let pose = offset * pose;
                let (t, q) = (pose.translation.vector, pose.rotation.quaternion());
                let h = half_extents;
                let _ = write!(
                    e,
                    r#" type="box" size="{} {} {}" pos="{} {} {}" quat="{} {} {} {}""#,
                    h.x, h.y, h.z, t.x, t.y, t.z, q.w, q.i, q.j, q.k
                );
            }
            Shape::Sphere { centre, radius } => {
                let c = offset * Point3::from(centre);
                let _ = write!(
                    e,
                    r#" type="sphere" size="{radius}" pos="{} {} {}""#,
                    c.x, c.y, c.z
                );
            }
        }
        e.push_str("/>");
        Self { element: e }
    }

    /// The `<geom …/>` element.
    pub fn element(&self) -> &str {
        &self.element
    }
}
