//! Convex quadratic programs of the whole-body controller and their solvers.
//!
//! The problem form ([`QpProblem`]) is
//!
//! ```text
//! minimise   ½ xᵀ P x + qᵀ x
//! subject to A_eq x = b_eq              (feet in contact)
//!            l ≤ C x ≤ u                (general inequalities, ±∞ allowed on a side)
//!            x_min ≤ x ≤ x_max          (box, ±∞ allowed)
//! ```
//!
//! Two back-ends implement [`QpSolver`]:
//! - [`ClarabelSolver`]: the interior-point reference (allocates, slower, ~1e-8 accurate);
//! - [`DenseActiveSetSolver`]: Goldfarb–Idnani dual active set on faer, allocation-free after
//!   construction and warm-started from the previous active set; exact to round-off.
//!
//! A failed solve returns an error and leaves the caller's `x` untouched, so a partial iterate
//! can never be mistaken for a command.

mod clarabel_backend;
mod dense;
mod json;
mod problem;

pub use clarabel_backend::ClarabelSolver;
pub use dense::DenseActiveSetSolver;
pub use json::{QpJsonError, export_json, problem_from_json, problems_from_json};
pub use problem::{QpPartsMut, QpProblem};

/// Outcome of a successful solve, for logging and benchmarks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QpInfo {
    /// Solver iterations: active-set changes (dense) or interior-point iterations (clarabel).
    pub iterations: usize,
    /// Inequality and box constraints active at the solution (equalities not counted).
    pub active_constraints: usize,
    /// Objective value ½ xᵀ P x + qᵀ x at the returned solution.
    pub objective: f64,
}

/// Why a solve failed; the output vector is left untouched in every case.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum QpError {
    /// The constraints admit no point (conflicting rows, or a lower bound above its upper bound).
    #[error("QP is infeasible")]
    Infeasible,
    /// The iteration limit was reached before an optimum was certified.
    #[error("QP solver reached its iteration limit ({0})")]
    MaxIterations(usize),
    /// P is not positive definite (the dense solver needs it strictly convex).
    #[error("QP Hessian P is not positive definite (pivot {pivot} of the Cholesky factorisation)")]
    NotPositiveDefinite {
        /// Index of the first non-positive Cholesky pivot.
        pivot: usize,
    },
    /// The problem is unbounded below (P only positive semidefinite along a feasible ray).
    #[error("QP is unbounded below (P is not positive definite along a feasible direction)")]
    NonConvex,
    /// The solver lost accuracy or produced a non-finite iterate.
    #[error("QP solver numerical failure: {0}")]
    NumericalFailure(&'static str),
    /// An input entry is NaN, infinite where not allowed, or otherwise malformed.
    #[error("invalid QP input: {field}[{row}, {col}] {what}")]
    InvalidInput {
        /// Which field of [`QpProblem`] (`"P"`, `"q"`, `"A_eq"`, `"b_eq"`, `"C"`, `"l"`, `"u"`, `"x_min"`, `"x_max"`).
        field: &'static str,
        /// Row of the offending entry (the index for vectors).
        row: usize,
        /// Column of the offending entry (0 for vectors).
        col: usize,
        /// What is wrong with it (e.g. `"is NaN"`).
        what: &'static str,
    },
    /// Problem sizes exceed the capacity the problem or solver was built for.
    #[error("QP size mismatch: {what} is {found}, capacity/expected {expected}")]
    Dimension {
        /// Which size (`"n"`, `"x"` for the output length, `"m_eq"`, `"m_ineq"`).
        what: &'static str,
        /// The size the container was built for.
        expected: usize,
        /// The size requested or found.
        found: usize,
    },
}

/// A QP back-end: solves a [`QpProblem`] into `x` (length `problem.n()`).
///
/// On `Ok`, `x` holds the optimum. On `Err`, `x` is left unchanged.
pub trait QpSolver {
    /// Solves `problem`, writing the optimum into `x` only on success.
    fn solve(&mut self, problem: &QpProblem, x: &mut [f64]) -> Result<QpInfo, QpError>;
}
