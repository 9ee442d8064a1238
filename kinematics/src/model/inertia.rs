//! Physical plausibility of a link's rotational inertia.

use nalgebra::{Matrix3, SymmetricEigen};

/// Why an inertia tensor is not physically valid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InertiaDefect {
    /// An eigenvalue is zero or negative.
    NotPositiveDefinite { smallest_eigenvalue: f64 },
    /// One principal moment exceeds the sum of the other two.
    TriangleInequality { moments: [f64; 3] },
}

impl std::fmt::Display for InertiaDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NotPositiveDefinite {
                smallest_eigenvalue,
            } => write!(
                f,
                "inertia is not positive definite (smallest eigenvalue {smallest_eigenvalue:e})"
            ),
            Self::TriangleInequality { moments } => write!(
                f,
                "principal moments {moments:?} break the triangle inequality (each must be <= the sum of the other two)"
            ),
        }
    }
}

/// Checks positive definiteness and the triangle inequality of the principal moments.
pub(super) fn check(inertia: &Matrix3<f64>) -> Result<(), InertiaDefect> {
    let eigen = SymmetricEigen::new(*inertia);
    let moments = [
        eigen.eigenvalues[0],
        eigen.eigenvalues[1],
        eigen.eigenvalues[2],
    ];
    let smallest = moments.iter().copied().fold(f64::INFINITY, f64::min);
    if smallest <= 0.0 {
        return Err(InertiaDefect::NotPositiveDefinite {
            smallest_eigenvalue: smallest,
        });
    }
    let sum: f64 = moments.iter().sum();
    // Relative slack for rounding in vendored files (moments written with 6 significant digits).
    let slack = 1e-9 * sum;
    if moments.iter().any(|&m| m > sum - m + slack) {
        return Err(InertiaDefect::TriangleInequality { moments });
    }
    Ok(())
}
