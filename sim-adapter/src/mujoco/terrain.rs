//! The world of a scene (`stance::Scene`, docs/scenes.md) as MuJoCo geometry: what the robot
//! stands on and what it may hit.
//!
//! - Each support surface becomes a static box whose top face is exactly the surface's rectangle
//!   (same centre, yaw and pitch), extruded along its normal down to the *base*, [`DEPTH_BELOW`]
//!   under the scene's lowest surface point: stairs are solid to the ground, so a toe cannot pass
//!   under a tread. A tilted box reaches the base under its highest point and goes deeper
//!   elsewhere; its ends are square to its slope, so its low end leans in below the low edge:
//!   a crack of zero width at the edge, nothing can enter it.
//! - The infinite floor plane lies at the base too, below every surface and coplanar with none:
//!   the robot stands on the scene's surfaces, and a foot or leg that leaves them lands on the
//!   ground around the scene instead of falling forever.
//! - Each railing becomes a capsule along its segment with its radius.
//!
//! The elevation of the terrain under a point ([`Terrain::elevation_at`]) is what the
//! simulator's base height is measured from.

use kinematics::configuration::Configuration;
use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use stance::environment::HandAffordance;
use stance::{Scene, SupportSurface};

use super::MujocoError;

/// How far (m) the base of the terrain, where the boxes end and the floor plane lies, is below
/// the scene's lowest surface point.
pub const DEPTH_BELOW: f64 = 0.05;

/// A support surface as a box: its name, the pose of its centre and its half extents (x, y along
/// the surface, z along its normal).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TerrainBox {
    pub name: String,
    pub pose: Isometry3<f64>,
    pub half: Vector3<f64>,
}

/// The MuJoCo geometry of a scene, and where the robot starts in it; see the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    scene: Scene,
    boxes: Vec<TerrainBox>,
    base: f64,
}

impl Terrain {
    /// The geometry of `scene`. A scene read by `Scene::from_path` always converts; a scene built
    /// by hand is refused if a surface is not a rectangle centred on its frame, or a railing has
    /// no radius (a capsule needs one > 0).
    pub fn from_scene(scene: &Scene) -> Result<Self, MujocoError> {
        let environment = &scene.environment;
        if let Some(railing) = environment
            .hand_affordances
            .iter()
            .find(|r| r.radius <= 0.0)
        {
            return Err(MujocoError::BadTerrain(format!(
                "railing \"{}\" has radius {} m, a capsule needs one > 0",
                railing.name, railing.radius
            )));
        }
        let rectangles = environment
            .surfaces
            .iter()
            .map(|surface| {
                let half = rectangle(surface.polygon.as_deref()).ok_or_else(|| {
                    MujocoError::BadTerrain(format!(
                        "surface \"{}\" is not a rectangle centred on its frame",
                        surface.name
                    ))
                })?;
                Ok((surface, half))
            })
            .collect::<Result<Vec<_>, MujocoError>>()?;
        let corner_heights = |surface: &SupportSurface, [x, y]: [f64; 2]| {
            [(-x, -y), (x, -y), (x, y), (-x, y)]
                .map(|(u, v)| (surface.pose * Point3::new(u, v, 0.0)).z)
        };
        let base = rectangles
            .iter()
            .flat_map(|&(surface, half)| corner_heights(surface, half))
            .fold(f64::INFINITY, f64::min)
            - DEPTH_BELOW;
        let boxes = rectangles
            .iter()
            .map(|&(surface, half)| {
                let highest = corner_heights(surface, half)
                    .into_iter()
                    .fold(f64::NEG_INFINITY, f64::max);
                // A slab `t` thick along its normal n is t / n_z thick vertically.
                let normal_z = (surface.pose.rotation * Vector3::z()).z;
                let thickness = (highest - base) * normal_z;
                TerrainBox {
                    name: surface.name.clone(),
                    pose: surface.pose * Translation3::new(0.0, 0.0, -thickness / 2.0),
                    half: Vector3::new(half[0], half[1], thickness / 2.0),
                }
            })
            .collect();
        Ok(Self {
            scene: scene.clone(),
            boxes,
            base,
        })
    }

    /// The scene the terrain was built from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// `posture` stood at the scene's start ([`Scene::place`]).
    pub fn place(&self, posture: &Configuration) -> Configuration {
        self.scene.place(posture)
    }

    /// Elevation (world z) of the terrain under `(x, y)`: the highest surface there, else the
    /// floor plane around the scene.
    pub fn elevation_at(&self, x: f64, y: f64) -> f64 {
        self.scene
            .environment
            .highest_at(x, y)
            .map_or(self.base, |z| z.max(self.base))
    }

    /// World z of the floor plane and of the boxes' bottom: [`DEPTH_BELOW`] under the lowest
    /// surface point.
    pub(crate) fn base(&self) -> f64 {
        self.base
    }

    /// The surfaces as boxes, in the scene's order.
    pub(crate) fn boxes(&self) -> &[TerrainBox] {
        &self.boxes
    }

    /// The railings, each with its radius (a capsule along its segment), in the scene's order.
    pub(crate) fn railings(&self) -> impl Iterator<Item = (&HandAffordance, f64)> {
        self.scene
            .environment
            .hand_affordances
            .iter()
            .map(|railing| (railing, railing.radius))
    }
}

/// Half length and half width of a rectangle centred on the origin and aligned with the axes,
/// given as its four corners in any order; `None` for another polygon.
fn rectangle(polygon: Option<&[[f64; 2]]>) -> Option<[f64; 2]> {
    let corners = polygon.filter(|p| p.len() == 4)?;
    let [x, y] = [0, 1].map(|k| corners.iter().map(|c| c[k].abs()).fold(0.0, f64::max));
    let on_corner = |c: &[f64; 2]| (c[0].abs() - x).abs() < 1e-9 && (c[1].abs() - y).abs() < 1e-9;
    // One corner in each quadrant.
    let quadrants = corners.iter().fold(0u8, |seen, c| {
        seen | 1 << (2 * u8::from(c[0] > 0.0) + u8::from(c[1] > 0.0))
    });
    (x > 0.0 && y > 0.0 && corners.iter().all(on_corner) && quadrants == 0b1111).then_some([x, y])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn terrain(text: &str) -> Terrain {
        Terrain::from_scene(&Scene::from_toml_str(text, Path::new("test.toml")).unwrap()).unwrap()
    }

    const RAMP: &str = r#"
        format_version = 1
        name = "ramp"
        [path]
        start = [0.5, 0.0]
        goal = [2.5, 0.0]
        [[surface]]
        name = "floor"
        center = [0.5, 0.0, 0.0]
        size = [1.0, 1.0]
        [[surface]]
        name = "ramp"
        center = [1.9659258262890683, 0.0, 0.25881904510252074]
        size = [2.0, 1.0]
        pitch_deg = 15.0
    "#;

    #[test]
    fn boxes_keep_the_top_face_and_reach_the_base() {
        let terrain = terrain(RAMP);
        assert!(
            (terrain.base() + DEPTH_BELOW).abs() < 1e-12,
            "{}",
            terrain.base()
        );
        let [floor, ramp] = terrain.boxes() else {
            panic!("two boxes")
        };
        // The floor: its top face at z = 0, its bottom on the base.
        assert!((floor.pose.translation.z + DEPTH_BELOW / 2.0).abs() < 1e-12);
        assert!((floor.half.z - DEPTH_BELOW / 2.0).abs() < 1e-12);
        // The ramp: its top face's centre is the surface's centre, its normal the surface's.
        let top = ramp.pose * Point3::new(0.0, 0.0, ramp.half.z);
        let centre = Vector3::new(1.9659258262890683, 0.0, 0.25881904510252074);
        assert!((top.coords - centre).norm() < 1e-12);
        let along = ramp.pose.rotation * Vector3::x();
        assert!((along.z / along.x - 15f64.to_radians().tan()).abs() < 1e-12);
        // Straight under its highest point (its +x edge) its bottom face is on the base.
        let high = ramp.pose * Point3::new(ramp.half.x, 0.0, ramp.half.z);
        let normal = ramp.pose.rotation * Vector3::z();
        let bottom_below_high = high.z - 2.0 * ramp.half.z / normal.z;
        assert!((bottom_below_high - terrain.base()).abs() < 1e-12);
    }

    #[test]
    fn the_elevation_is_the_surface_under_the_point_or_the_base() {
        let terrain = terrain(RAMP);
        assert_eq!(terrain.elevation_at(0.5, 0.3), 0.0);
        let on_ramp = terrain.elevation_at(1.5, 0.0);
        assert!(
            (on_ramp - 0.5 * 15f64.to_radians().tan()).abs() < 1e-9,
            "{on_ramp}"
        );
        assert_eq!(terrain.elevation_at(0.5, 0.6), terrain.base());
    }

    #[test]
    fn only_centred_rectangles_are_boxes() {
        let square = [[-1.0, -2.0], [1.0, -2.0], [1.0, 2.0], [-1.0, 2.0]];
        assert_eq!(rectangle(Some(&square)), Some([1.0, 2.0]));
        let shifted = [[0.0, -2.0], [2.0, -2.0], [2.0, 2.0], [0.0, 2.0]];
        assert_eq!(rectangle(Some(&shifted)), None);
        let corner_twice = [[-1.0, -2.0], [1.0, -2.0], [1.0, 2.0], [1.0, 2.0]];
        assert_eq!(rectangle(Some(&corner_twice)), None);
        assert_eq!(rectangle(Some(&square[..3])), None);
        assert_eq!(rectangle(None), None);
    }
}
