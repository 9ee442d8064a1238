//! Ground-plane geometry shared by the controller, the simulators, post-processing and the
//! evaluation: gravity, the support polygon of the soles in contact, and planar (x, y, yaw)
//! frames. One definition, so the controller and the simulators judge support the same way.

mod planar;
mod support;

pub use planar::{planar_frame, sequence_alignment, yaw};
pub use support::{HalfPlane, MAX_SUPPORT_POINTS, SupportPolygon, sole_corners};

/// Gravitational acceleration (m/s², along −z).
pub const GRAVITY: f64 = 9.81;
