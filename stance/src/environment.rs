//! The environment a sequence is planned in: planar support surfaces for the feet and hand
//! affordances (e.g. a railing) with the interval of the path along which they are available.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Point3, Vector2, Vector3};

/// A planar support surface: its frame (z = surface normal, the plane is its xy plane) and the
/// polygon of the supporting area in that plane. `polygon: None` is an unbounded plane (the
/// ground).
#[derive(Clone, Debug, PartialEq)]
pub struct SupportSurface {
    /// Name used in messages and files (e.g. `"ground"`).
    pub name: String,
    /// Surface frame in the world.
    pub pose: Isometry3<f64>,
    /// Vertices `[x, y]` of the supporting area in the surface frame, or `None` for no bound.
    pub polygon: Option<Vec<[f64; 2]>>,
}

impl SupportSurface {
    /// Whether this is an unbounded horizontal plane at z = 0, the flat ground a stance source
    /// generates on.
    pub fn is_ground_plane(&self) -> bool {
        self.polygon.is_none()
            && self.pose.rotation * Vector3::z() == Vector3::z()
            && self.pose.translation.z == 0.0
    }

    /// The default environment's ground: the unbounded plane z = 0.
    pub fn ground() -> Self {
        Self {
            name: "ground".to_owned(),
            pose: Isometry3::identity(),
            polygon: None,
        }
    }

    /// Elevation (world z) of the surface vertically below/above the world point `(x, y)`;
    /// `None` if that point projects outside the polygon or the surface is vertical.
    pub fn elevation_at(&self, x: f64, y: f64) -> Option<f64> {
        let z = self.plane_elevation_at(x, y)?;
        let Some(polygon) = &self.polygon else {
            return Some(z);
        };
        let local = self.pose.inverse_transform_point(&Point3::new(x, y, z));
        polygon_contains(polygon, local.x, local.y).then_some(z)
    }

    /// Elevation (world z) of the surface's plane, ignoring the polygon, vertically below/above
    /// `(x, y)`; `None` if the surface is vertical. A scene measures the step between two
    /// surfaces with it where the path crosses from one to the other, a point that may lie just
    /// outside either polygon (they need only touch within a tolerance).
    pub fn plane_elevation_at(&self, x: f64, y: f64) -> Option<f64> {
        let normal = self.pose.rotation * Vector3::z();
        if normal.z.abs() < 1e-9 {
            return None;
        }
        let origin = self.pose.translation.vector;
        // n · (p − o) = 0 with p = (x, y, z) solved for z.
        Some(origin.z - (normal.x * (x - origin.x) + normal.y * (y - origin.y)) / normal.z)
    }

    /// The part of the horizontal line `from + t · direction` (world; z ignored) that lies over
    /// the surface, as `[t_first, t_last]` (`±∞` for an unbounded plane); `None` if the line
    /// misses the polygon, `direction` has no horizontal part or the surface is vertical. Exact
    /// for convex polygons (a scene's rectangles): the terrain pass measures a surface's extent
    /// along the walking path with it, and a swing's clearance over the surfaces it passes.
    pub fn extent_along(&self, from: &Vector3<f64>, direction: &Vector3<f64>) -> Option<[f64; 2]> {
        let Some(polygon) = &self.polygon else {
            return self
                .plane_elevation_at(from.x, from.y)
                .map(|_| [f64::NEG_INFINITY, f64::INFINITY]);
        };
        let start = self.local_xy(from.x, from.y)?;
        let step = self.local_xy(from.x + direction.x, from.y + direction.y)? - start;
        let mut extent: Option<[f64; 2]> = None;
        let mut previous = polygon[polygon.len() - 1];
        for &vertex in polygon {
            let (a, b) = (Vector2::from(previous), Vector2::from(vertex));
            previous = vertex;
            let edge = b - a;
            let denominator = step.perp(&edge);
            if denominator.abs() < 1e-12 {
                continue;
            }
            let (t, u) = ((a - start).perp(&edge), (a - start).perp(&step));
            let (t, u) = (t / denominator, u / denominator);
            if (0.0..=1.0).contains(&u) {
                extent = Some(extent.map_or([t, t], |[lo, hi]| [lo.min(t), hi.max(t)]));
            }
        }
        extent.filter(|[lo, hi]| lo < hi)
    }

    /// The highest elevation (world z) of the surface under the horizontal segment from `from`
    /// to `to` (world; z ignored); `None` if the segment does not pass over it. A swing foot
    /// must clear it (pass 9).
    pub fn highest_under(&self, from: &Vector3<f64>, to: &Vector3<f64>) -> Option<f64> {
        let direction = to - from;
        if direction.xy().norm() < 1e-12 {
            return self.elevation_at(from.x, from.y);
        }
        let [lo, hi] = self.extent_along(from, &direction)?;
        let (lo, hi) = (lo.max(0.0), hi.min(1.0));
        if lo > hi {
            return None;
        }
        // The plane's elevation is affine along a straight line: highest at an end.
        let at =
            |t: f64| self.plane_elevation_at(from.x + t * direction.x, from.y + t * direction.y);
        Some(at(lo)?.max(at(hi)?))
    }

    /// Coordinates, in the surface frame's xy plane, of the point of the plane vertically
    /// below/above the world point `(x, y)`; `None` if the surface is vertical.
    fn local_xy(&self, x: f64, y: f64) -> Option<Vector2<f64>> {
        let z = self.plane_elevation_at(x, y)?;
        Some(
            self.pose
                .inverse_transform_point(&Point3::new(x, y, z))
                .xy()
                .coords,
        )
    }
}

/// Even-odd ray casting test of `(x, y)` against a closed polygon.
fn polygon_contains(polygon: &[[f64; 2]], x: f64, y: f64) -> bool {
    let mut inside = false;
    let mut previous = polygon[polygon.len() - 1];
    for &vertex in polygon {
        let ([xi, yi], [xj, yj]) = (vertex, previous);
        if (yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi {
            inside = !inside;
        }
        previous = vertex;
    }
    inside
}

/// A hand affordance along the path, e.g. a railing: a straight segment the hands may hold,
/// usable while the walker is inside `available` (metres along the walking path).
#[derive(Clone, Debug, PartialEq)]
pub struct HandAffordance {
    /// Name used in messages and files (e.g. `"railing"`).
    pub name: String,
    /// First end of the segment (the railing's axis) in the world.
    pub start: Vector3<f64>,
    /// Second end of the segment in the world.
    pub end: Vector3<f64>,
    /// Radius of the railing around its axis (m): a held palm rests this far above the axis.
    /// 0 for a stance source's own railing, a line.
    pub radius: f64,
    /// `[from, to]`: the part of the path (metres from its origin) where the affordance may be used.
    pub available: [f64; 2],
}

impl HandAffordance {
    /// The point of the segment nearest to `point`: where a hand reaching for the railing from
    /// there grasps it.
    pub fn nearest_on_axis(&self, point: &Vector3<f64>) -> Vector3<f64> {
        crate::geometry::nearest_on_segment(&self.start, &self.end, point)
    }

    /// Whether `hand` may hold the railing: it lies on that hand's side of the walk (its
    /// midpoint left of the path, `y > 0` in the walk's frame, for the left hand; right of it
    /// for the right hand). A hand does not reach across the body for a railing.
    pub fn is_on_the_side_of(&self, hand: EndEffector) -> bool {
        let middle = (self.start.y + self.end.y) / 2.0;
        match hand {
            EndEffector::LeftHand => middle > 0.0,
            EndEffector::RightHand => middle < 0.0,
            EndEffector::LeftFoot | EndEffector::RightFoot => false,
        }
    }
}

/// Support surfaces and hand affordances of a sequence.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// Surfaces the feet may stand on (at least one).
    pub surfaces: Vec<SupportSurface>,
    /// Surfaces/objects the hands may hold.
    pub hand_affordances: Vec<HandAffordance>,
}

impl Default for Environment {
    /// The ground plane z = 0 and no hand affordance.
    fn default() -> Self {
        Self {
            surfaces: vec![SupportSurface::ground()],
            hand_affordances: Vec::new(),
        }
    }
}

impl Environment {
    /// Whether every surface is an unbounded horizontal plane at z = 0: the flat ground a stance
    /// source generates on, where the terrain pass has nothing to do.
    pub fn is_flat_ground(&self) -> bool {
        self.surfaces.iter().all(SupportSurface::is_ground_plane)
    }

    /// The surface a point belongs to and its elevation there: of the surfaces under or above the
    /// point, the one vertically nearest. `None` if no surface covers the point's `(x, y)`.
    pub fn support_at(&self, point: &Vector3<f64>) -> Option<(&SupportSurface, f64)> {
        self.surfaces
            .iter()
            .filter_map(|s| s.elevation_at(point.x, point.y).map(|z| (s, z)))
            .min_by(|(_, a), (_, b)| (point.z - a).abs().total_cmp(&(point.z - b).abs()))
    }

    /// The elevation (world z) of the highest surface over `(x, y)`; `None` if none covers it.
    /// What a sole corner there stands on (a stair's tread, not the floor under it).
    pub fn highest_at(&self, x: f64, y: f64) -> Option<f64> {
        self.surfaces
            .iter()
            .filter_map(|s| s.elevation_at(x, y))
            .max_by(f64::total_cmp)
    }

    /// The highest surface (world z) under the horizontal segment from `from` to `to`; `None`
    /// if it passes over none. What a swing foot passing there must clear (pass 9).
    pub fn highest_under(&self, from: &Vector3<f64>, to: &Vector3<f64>) -> Option<f64> {
        self.surfaces
            .iter()
            .filter_map(|s| s.highest_under(from, to))
            .max_by(f64::total_cmp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    #[test]
    fn ground_is_everywhere_at_zero() {
        let env = Environment::default();
        let (surface, z) = env.support_at(&Vector3::new(12.0, -3.0, -0.4)).unwrap();
        assert_eq!(surface.name, "ground");
        assert_eq!(z, 0.0);
    }

    #[test]
    fn nearest_surface_wins_inside_its_polygon() {
        let step = SupportSurface {
            name: "step".into(),
            pose: Isometry3::translation(1.0, 0.0, 0.2),
            polygon: Some(vec![[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]),
        };
        let env = Environment {
            surfaces: vec![SupportSurface::ground(), step],
            hand_affordances: Vec::new(),
        };
        let (on_step, z) = env.support_at(&Vector3::new(1.2, 0.1, 0.17)).unwrap();
        assert_eq!((on_step.name.as_str(), z), ("step", 0.2));
        let (outside, z) = env.support_at(&Vector3::new(1.7, 0.1, 0.17)).unwrap();
        assert_eq!((outside.name.as_str(), z), ("ground", 0.0));
    }

    /// A 0.3 m tread along x at elevation 0.2, turned by `yaw` about z.
    fn tread(yaw: f64) -> SupportSurface {
        SupportSurface {
            name: "tread".into(),
            pose: Isometry3::from_parts(
                Vector3::new(1.0, 0.0, 0.2).into(),
                UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
            ),
            polygon: Some(vec![[-0.15, -0.5], [0.15, -0.5], [0.15, 0.5], [-0.15, 0.5]]),
        }
    }

    #[test]
    fn extent_along_a_line_is_where_it_crosses_the_polygon() {
        let [lo, hi] = tread(0.0)
            .extent_along(&Vector3::new(0.0, 0.1, 5.0), &Vector3::new(2.0, 0.0, 0.0))
            .unwrap();
        assert!(
            (lo - 0.425).abs() < 1e-12 && (hi - 0.575).abs() < 1e-12,
            "{lo} {hi}"
        );
        // Turned a quarter: 1 m long along x.
        let [lo, hi] = tread(std::f64::consts::FRAC_PI_2)
            .extent_along(&Vector3::new(0.0, 0.0, 0.0), &Vector3::x())
            .unwrap();
        assert!(
            (lo - 0.5).abs() < 1e-12 && (hi - 1.5).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert_eq!(
            tread(0.0).extent_along(&Vector3::new(0.0, 0.7, 0.0), &Vector3::x()),
            None,
            "passes beside it"
        );
        assert_eq!(
            SupportSurface::ground().extent_along(&Vector3::zeros(), &Vector3::x()),
            Some([f64::NEG_INFINITY, f64::INFINITY])
        );
    }

    #[test]
    fn highest_under_a_segment_is_the_highest_surface_it_passes() {
        let env = Environment {
            surfaces: vec![SupportSurface::ground(), tread(0.0)],
            hand_affordances: Vec::new(),
        };
        let z = |a: f64, b: f64| {
            env.highest_under(&Vector3::new(a, 0.0, 0.0), &Vector3::new(b, 0.0, 0.0))
        };
        assert_eq!(z(0.0, 2.0), Some(0.2), "over the tread");
        assert_eq!(z(0.0, 0.8), Some(0.0), "stops short of it");
        assert_eq!(z(0.9, 0.9), Some(0.2), "a point on it");
        let ramp = SupportSurface {
            name: "ramp".into(),
            pose: Isometry3::from_parts(
                Vector3::zeros().into(),
                UnitQuaternion::from_euler_angles(0.0, -0.1, 0.0),
            ),
            polygon: Some(vec![[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]),
        };
        let top = ramp
            .highest_under(&Vector3::new(-3.0, 0.0, 0.0), &Vector3::new(3.0, 0.0, 0.0))
            .unwrap();
        assert!(
            (top - 0.1f64.sin()).abs() < 1e-12,
            "the ramp's upper edge: {top}"
        );
    }

    #[test]
    fn tilted_surface_elevation_follows_the_plane() {
        let ramp = SupportSurface {
            name: "ramp".into(),
            pose: Isometry3::from_parts(
                Vector3::new(0.0, 0.0, 0.1).into(),
                UnitQuaternion::from_euler_angles(0.0, -0.1, 0.0),
            ),
            polygon: None,
        };
        let z = ramp.elevation_at(1.0, 5.0).unwrap();
        assert!((z - (0.1 + 0.1f64.tan())).abs() < 1e-12);
    }
}
