//! Support polygons: the convex hull of the sole corners in contact, projected on the ground.
//!
//! Shared by the simulator (stability margin, fall detection) and the controller (the CoM
//! constraint), so both judge static stability with the same geometry. Fixed capacity, no
//! allocation: it is used on the real-time path.

use crate::robot::SoleRectangle;
use nalgebra::{Isometry3, Point3, Vector3};

/// Most points a support polygon is built from (four corners for each of four end-effectors).
pub const MAX_SUPPORT_POINTS: usize = 16;

/// A half-plane `normal · p ≤ offset` in the ground (xy) plane, `normal` a unit vector pointing out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfPlane {
    /// Outward unit normal of the edge.
    pub normal: [f64; 2],
    /// Offset such that points inside satisfy `normal · p ≤ offset`.
    pub offset: f64,
}

/// A convex polygon in the ground plane (vertices counter-clockwise), possibly degenerate
/// (a point or a segment) when fewer than three non-collinear points support the robot.
#[derive(Clone, Copy, Debug)]
pub struct SupportPolygon {
    vertices: [[f64; 2]; MAX_SUPPORT_POINTS],
    len: usize,
}

impl Default for SupportPolygon {
    fn default() -> Self {
        Self::empty()
    }
}

impl SupportPolygon {
    /// The polygon of a robot without support: every point is outside.
    pub const fn empty() -> Self {
        Self {
            vertices: [[0.0; 2]; MAX_SUPPORT_POINTS],
            len: 0,
        }
    }

    /// Resets to the empty polygon.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Replaces the polygon by the convex hull of the corners of soles `sole` at `poses` (the
    /// feet in contact), each corner's ground point passed through `map` first (`|p| p` for the
    /// soles' own polygon). At most [`MAX_SUPPORT_POINTS`] / 4 soles; allocation-free.
    pub fn set_soles<'a>(
        &mut self,
        poses: impl IntoIterator<Item = &'a Isometry3<f64>>,
        sole: &SoleRectangle,
        map: impl Fn([f64; 2]) -> [f64; 2],
    ) {
        let mut corners = [[0.0; 2]; MAX_SUPPORT_POINTS];
        let mut count = 0;
        for pose in poses {
            for corner in sole_corners(pose, sole) {
                corners[count] = map([corner.x, corner.y]);
                count += 1;
            }
        }
        self.set_hull(&corners[..count]);
    }

    /// Replaces the polygon by the convex hull of `points` (Andrew's monotone chain).
    ///
    /// # Panics
    /// If more than [`MAX_SUPPORT_POINTS`] points are given.
    pub fn set_hull(&mut self, points: &[[f64; 2]]) {
        assert!(
            points.len() <= MAX_SUPPORT_POINTS,
            "support polygon: {} points exceed the capacity {MAX_SUPPORT_POINTS}",
            points.len()
        );
        let mut sorted = [[0.0; 2]; MAX_SUPPORT_POINTS];
        sorted[..points.len()].copy_from_slice(points);
        let sorted = &mut sorted[..points.len()];
        sorted.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        let n = sorted.len();
        self.len = 0;
        if n == 0 {
            return;
        }
        // Lower hull then upper hull; `hull` holds at most n + 1 points before the final pop.
        let mut hull = [[0.0; 2]; 2 * MAX_SUPPORT_POINTS + 1];
        let mut k = 0;
        for &p in sorted.iter() {
            while k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0.0 {
                k -= 1;
            }
            hull[k] = p;
            k += 1;
        }
        let lower_len = k + 1;
        for &p in sorted.iter().rev().skip(1) {
            while k >= lower_len && cross(hull[k - 2], hull[k - 1], p) <= 0.0 {
                k -= 1;
            }
            hull[k] = p;
            k += 1;
        }
        // The last point repeats the first (except for a single input point).
        let len = if n == 1 { 1 } else { k - 1 };
        self.vertices[..len].copy_from_slice(&hull[..len]);
        self.len = len;
    }

    /// Builds the hull of `points`.
    pub fn from_points(points: &[[f64; 2]]) -> Self {
        let mut polygon = Self::empty();
        polygon.set_hull(points);
        polygon
    }

    /// The vertices, counter-clockwise.
    pub fn vertices(&self) -> &[[f64; 2]] {
        &self.vertices[..self.len]
    }

    /// Whether the polygon has an interior (at least three non-collinear vertices).
    pub fn has_area(&self) -> bool {
        self.len >= 3
    }

    /// The number of edges (half-planes) of a polygon with an interior, else 0.
    pub fn edge_count(&self) -> usize {
        if self.has_area() { self.len } else { 0 }
    }

    /// Edge `i` as an outward half-plane (`i < edge_count()`).
    pub fn edge(&self, i: usize) -> HalfPlane {
        let a = self.vertices[i];
        let b = self.vertices[(i + 1) % self.len];
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let length = dx.hypot(dy);
        // Counter-clockwise order: the outward normal is the edge direction turned clockwise.
        let normal = [dy / length, -dx / length];
        HalfPlane {
            normal,
            offset: normal[0] * a[0] + normal[1] * a[1],
        }
    }

    /// The centroid of the enclosed area (the vertex mean for degenerate polygons).
    pub fn centroid(&self) -> [f64; 2] {
        if self.len == 0 {
            return [f64::NAN; 2];
        }
        let mean = self.vertices().iter().fold([0.0; 2], |acc, v| {
            [
                acc[0] + v[0] / self.len as f64,
                acc[1] + v[1] / self.len as f64,
            ]
        });
        if !self.has_area() {
            return mean;
        }
        let (mut area, mut cx, mut cy) = (0.0, 0.0, 0.0);
        for i in 0..self.len {
            let a = [self.vertices[i][0] - mean[0], self.vertices[i][1] - mean[1]];
            let j = (i + 1) % self.len;
            let b = [self.vertices[j][0] - mean[0], self.vertices[j][1] - mean[1]];
            let w = a[0] * b[1] - b[0] * a[1];
            area += w;
            cx += (a[0] + b[0]) * w;
            cy += (a[1] + b[1]) * w;
        }
        [mean[0] + cx / (3.0 * area), mean[1] + cy / (3.0 * area)]
    }

    /// The point of the polygon shrunk by `margin` nearest to `p` (`p` itself when inside): where
    /// a point that must stay `margin` inside the support is clamped to. A polygon without an
    /// interior (a point or a segment) is not shrunk; the empty polygon leaves `p` as it is.
    pub fn nearest_inside(&self, p: [f64; 2], margin: f64) -> [f64; 2] {
        if self.len == 0 {
            return p;
        }
        if !self.has_area() {
            return self.nearest_on_boundary(p);
        }
        let shrunk = self.shrunk(margin);
        if shrunk.signed_distance(p) >= 0.0 {
            p
        } else {
            shrunk.nearest_on_boundary(p)
        }
    }

    /// The polygon with every edge moved `margin` inwards (the vertex mean if nothing remains).
    fn shrunk(&self, margin: f64) -> SupportPolygon {
        let mut shrunk = SupportPolygon::empty();
        let n = self.len;
        for i in 0..n {
            let (a, b) = (self.edge((i + n - 1) % n), self.edge(i));
            let (da, db) = (a.offset - margin, b.offset - margin);
            let det = a.normal[0] * b.normal[1] - a.normal[1] * b.normal[0];
            if det.abs() < 1e-12 {
                continue;
            }
            shrunk.vertices[shrunk.len] = [
                (da * b.normal[1] - db * a.normal[1]) / det,
                (a.normal[0] * db - b.normal[0] * da) / det,
            ];
            shrunk.len += 1;
        }
        // Too large a margin turns the polygon inside out: its vertices then lie closer than
        // `margin` to some edge.
        let within_margin = (0..shrunk.len).all(|i| {
            (0..n).all(|k| {
                let edge = self.edge(k);
                let v = shrunk.vertices[i];
                edge.offset - (edge.normal[0] * v[0] + edge.normal[1] * v[1]) >= margin - 1e-9
            })
        });
        if shrunk.len < 3 || !within_margin {
            return SupportPolygon::from_points(&[self.centroid()]);
        }
        shrunk
    }

    /// The point of the boundary nearest to `p`.
    fn nearest_on_boundary(&self, p: [f64; 2]) -> [f64; 2] {
        let mut best = (f64::INFINITY, self.vertices[0]);
        for i in 0..self.len {
            let a = self.vertices[i];
            let b = self.vertices[(i + 1) % self.len];
            let q = segment_nearest(p, a, b);
            let distance = (p[0] - q[0]).hypot(p[1] - q[1]);
            if distance < best.0 {
                best = (distance, q);
            }
        }
        best.1
    }

    /// Signed distance from `p` to the polygon boundary: positive inside (the stability margin),
    /// negative outside, `-inf` for the empty polygon.
    pub fn signed_distance(&self, p: [f64; 2]) -> f64 {
        if self.len == 0 {
            return f64::NEG_INFINITY;
        }
        let mut outside_distance = f64::INFINITY;
        for i in 0..self.len {
            let a = self.vertices[i];
            let b = self.vertices[(i + 1) % self.len];
            outside_distance = outside_distance.min(segment_distance(p, a, b));
        }
        if !self.has_area() {
            return -outside_distance;
        }
        let inside_distance = (0..self.len)
            .map(|i| {
                let edge = self.edge(i);
                edge.offset - (edge.normal[0] * p[0] + edge.normal[1] * p[1])
            })
            .fold(f64::INFINITY, f64::min);
        if inside_distance >= 0.0 {
            inside_distance
        } else {
            -outside_distance
        }
    }
}

/// The four sole corners of a foot at `sole_pose` in world coordinates (front-left, front-right,
/// back-right, back-left).
pub fn sole_corners(sole_pose: &Isometry3<f64>, sole: &SoleRectangle) -> [Vector3<f64>; 4] {
    let (hx, hy) = (0.5 * sole.length, 0.5 * sole.width);
    [(hx, hy), (hx, -hy), (-hx, -hy), (-hx, hy)]
        .map(|(x, y)| (sole_pose * Point3::new(x, y, 0.0)).coords)
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let q = segment_nearest(p, a, b);
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// The point of the segment `ab` nearest to `p`.
fn segment_nearest(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length_squared = dx * dx + dy * dy;
    let t = if length_squared > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length_squared).clamp(0.0, 1.0)
    } else {
        0.0
    };
    [a[0] + t * dx, a[1] + t * dy]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_soles_polygon_is_the_hull_of_their_corners_mapped() {
        let sole = SoleRectangle {
            length: 0.2,
            width: 0.1,
        };
        let feet = [
            Isometry3::translation(0.0, 0.1, 0.0),
            Isometry3::translation(0.0, -0.1, 0.0),
        ];
        let mut polygon = SupportPolygon::empty();
        polygon.set_soles(&feet, &sole, |p| p);
        // The rectangle spanning both soles: x in ±0.1, y in ±0.15.
        assert_eq!(polygon.vertices().len(), 4);
        assert!((polygon.signed_distance([0.0, 0.0]) - 0.1).abs() < 1e-12);
        // Each corner halved towards the origin: half the margin.
        polygon.set_soles(&feet, &sole, |[x, y]| [x / 2.0, y / 2.0]);
        assert!((polygon.signed_distance([0.0, 0.0]) - 0.05).abs() < 1e-12);
        // No sole: empty.
        polygon.set_soles(&[], &sole, |p| p);
        assert!(polygon.vertices().is_empty());
    }

    fn square() -> SupportPolygon {
        SupportPolygon::from_points(&[[0.0, 0.0], [1.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.0, 1.0]])
    }

    #[test]
    fn hull_drops_interior_points_and_is_counter_clockwise() {
        let polygon = square();
        assert_eq!(polygon.vertices().len(), 4);
        let mut area = 0.0;
        let v = polygon.vertices();
        for i in 0..v.len() {
            let j = (i + 1) % v.len();
            area += v[i][0] * v[j][1] - v[j][0] * v[i][1];
        }
        assert!((0.5 * area - 1.0).abs() < 1e-12, "area {}", 0.5 * area);
    }

    #[test]
    fn signed_distance_is_margin_inside_and_negative_outside() {
        let polygon = square();
        assert!((polygon.signed_distance([0.5, 0.5]) - 0.5).abs() < 1e-12);
        assert!((polygon.signed_distance([0.9, 0.5]) - 0.1).abs() < 1e-12);
        assert!((polygon.signed_distance([2.0, 0.5]) + 1.0).abs() < 1e-12);
        assert!((polygon.signed_distance([2.0, 2.0]) + 2f64.sqrt()).abs() < 1e-12);
        let c = polygon.centroid();
        assert!((c[0] - 0.5).abs() < 1e-12 && (c[1] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn edges_contain_the_interior() {
        let polygon = square();
        for i in 0..polygon.edge_count() {
            let e = polygon.edge(i);
            assert!(e.normal[0] * 0.5 + e.normal[1] * 0.5 < e.offset);
            let v = polygon.vertices()[i];
            assert!((e.normal[0] * v[0] + e.normal[1] * v[1] - e.offset).abs() < 1e-12);
            assert!(
                e.normal[0] * (v[0] + e.normal[0]) + e.normal[1] * (v[1] + e.normal[1]) > e.offset
            );
        }
    }

    #[test]
    fn nearest_inside_clamps_onto_the_shrunk_polygon() {
        let polygon = square();
        assert_eq!(polygon.nearest_inside([0.5, 0.5], 0.1), [0.5, 0.5]);
        let clamped = polygon.nearest_inside([2.0, 0.5], 0.1);
        assert!((clamped[0] - 0.9).abs() < 1e-12 && (clamped[1] - 0.5).abs() < 1e-12);
        let corner = polygon.nearest_inside([-1.0, -1.0], 0.1);
        assert!((corner[0] - 0.1).abs() < 1e-12 && (corner[1] - 0.1).abs() < 1e-12);
        // Inside but within the margin: moved to the margin.
        let near_edge = polygon.nearest_inside([0.5, 0.95], 0.1);
        assert!((near_edge[1] - 0.9).abs() < 1e-12);
        // A margin larger than the polygon leaves its centre.
        let centre = polygon.nearest_inside([3.0, 0.2], 0.7);
        assert!((centre[0] - 0.5).abs() < 1e-12 && (centre[1] - 0.5).abs() < 1e-12);
        let segment = SupportPolygon::from_points(&[[0.0, 0.0], [1.0, 0.0]]);
        assert_eq!(segment.nearest_inside([0.5, 1.0], 0.1), [0.5, 0.0]);
    }

    #[test]
    fn degenerate_polygons_have_no_inside() {
        let segment = SupportPolygon::from_points(&[[0.0, 0.0], [1.0, 0.0], [0.5, 0.0]]);
        assert!(!segment.has_area());
        assert!((segment.signed_distance([0.5, 1.0]) + 1.0).abs() < 1e-12);
        assert_eq!(
            SupportPolygon::empty().signed_distance([0.0, 0.0]),
            f64::NEG_INFINITY
        );
    }
}
