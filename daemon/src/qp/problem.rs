//! [`QpProblem`]: the controller's QP in nalgebra column-major storage, preallocated for fixed
//! maximum sizes so the controller can fill Jacobian blocks in place every tick.

use nalgebra::{DMatrix, DMatrixView, DMatrixViewMut, DVector, DVectorView, DVectorViewMut};

use super::QpError;

/// A convex QP with equality, two-sided general inequality and box constraints.
///
/// Storage is allocated once for `n` variables, at most `max_eq` equality rows and at most
/// `max_ineq` inequality rows; [`set_active_rows`](Self::set_active_rows) selects how many rows
/// are in use this tick without allocating. Only the lower triangle of `P` is read by the dense
/// solver and only the upper by clarabel, so `P` must be symmetric ([`validate`](Self::validate)
/// checks it). Infinite entries of `l`, `u`, `x_min`, `x_max` mean "no bound on that side".
#[derive(Debug, Clone, PartialEq)]
pub struct QpProblem {
    pub(super) m_eq: usize,
    pub(super) m_ineq: usize,
    pub(super) p: DMatrix<f64>,
    pub(super) q: DVector<f64>,
    pub(super) a_eq: DMatrix<f64>,
    pub(super) b_eq: DVector<f64>,
    pub(super) c: DMatrix<f64>,
    pub(super) l: DVector<f64>,
    pub(super) u: DVector<f64>,
    pub(super) x_min: DVector<f64>,
    pub(super) x_max: DVector<f64>,
}

/// Mutable views of every part of a [`QpProblem`] (active rows only), borrowed at once so the
/// controller can fill matrix rows and their bounds in the same loop.
pub struct QpPartsMut<'a> {
    /// Hessian `P` (n × n, symmetric).
    pub p: DMatrixViewMut<'a, f64>,
    /// Linear cost `q` (n).
    pub q: DVectorViewMut<'a, f64>,
    /// Equality matrix `A_eq` (m_eq × n).
    pub a_eq: DMatrixViewMut<'a, f64>,
    /// Equality right-hand side `b_eq` (m_eq).
    pub b_eq: DVectorViewMut<'a, f64>,
    /// Inequality matrix `C` (m_ineq × n).
    pub c: DMatrixViewMut<'a, f64>,
    /// Inequality lower bounds `l` (m_ineq, `-∞` allowed).
    pub l: DVectorViewMut<'a, f64>,
    /// Inequality upper bounds `u` (m_ineq, `+∞` allowed).
    pub u: DVectorViewMut<'a, f64>,
    /// Variable lower bounds (n, `-∞` allowed).
    pub x_min: DVectorViewMut<'a, f64>,
    /// Variable upper bounds (n, `+∞` allowed).
    pub x_max: DVectorViewMut<'a, f64>,
}

impl QpProblem {
    /// Allocates a problem with `n` variables and room for `max_eq` / `max_ineq` rows.
    ///
    /// Starts with all rows active, everything zero and unbounded boxes (`±∞`).
    pub fn new(n: usize, max_eq: usize, max_ineq: usize) -> Self {
        Self {
            m_eq: max_eq,
            m_ineq: max_ineq,
            p: DMatrix::zeros(n, n),
            q: DVector::zeros(n),
            a_eq: DMatrix::zeros(max_eq, n),
            b_eq: DVector::zeros(max_eq),
            c: DMatrix::zeros(max_ineq, n),
            l: DVector::from_element(max_ineq, f64::NEG_INFINITY),
            u: DVector::from_element(max_ineq, f64::INFINITY),
            x_min: DVector::from_element(n, f64::NEG_INFINITY),
            x_max: DVector::from_element(n, f64::INFINITY),
        }
    }

    /// Number of variables.
    pub fn n(&self) -> usize {
        self.q.len()
    }

    /// Capacity for equality rows.
    pub fn max_eq(&self) -> usize {
        self.b_eq.len()
    }

    /// Capacity for inequality rows.
    pub fn max_ineq(&self) -> usize {
        self.l.len()
    }

    /// Equality rows in use.
    pub fn m_eq(&self) -> usize {
        self.m_eq
    }

    /// Inequality rows in use.
    pub fn m_ineq(&self) -> usize {
        self.m_ineq
    }

    /// Selects how many equality / inequality rows are in use (no allocation).
    ///
    /// Row contents are kept, so a caller shrinking and growing again must refill the rows.
    pub fn set_active_rows(&mut self, m_eq: usize, m_ineq: usize) -> Result<(), QpError> {
        if m_eq > self.max_eq() {
            return Err(QpError::Dimension {
                what: "m_eq",
                expected: self.max_eq(),
                found: m_eq,
            });
        }
        if m_ineq > self.max_ineq() {
            return Err(QpError::Dimension {
                what: "m_ineq",
                expected: self.max_ineq(),
                found: m_ineq,
            });
        }
        self.m_eq = m_eq;
        self.m_ineq = m_ineq;
        Ok(())
    }

    /// Hessian `P` (n × n).
    pub fn p(&self) -> DMatrixView<'_, f64> {
        self.p.as_view()
    }

    /// Linear cost `q`.
    pub fn q(&self) -> DVectorView<'_, f64> {
        self.q.as_view()
    }

    /// Active equality rows of `A_eq` (m_eq × n).
    pub fn a_eq(&self) -> DMatrixView<'_, f64> {
        self.a_eq.rows(0, self.m_eq)
    }

    /// Active entries of `b_eq`.
    pub fn b_eq(&self) -> DVectorView<'_, f64> {
        self.b_eq.rows(0, self.m_eq)
    }

    /// Active inequality rows of `C` (m_ineq × n).
    pub fn c(&self) -> DMatrixView<'_, f64> {
        self.c.rows(0, self.m_ineq)
    }

    /// Active inequality lower bounds.
    pub fn l(&self) -> DVectorView<'_, f64> {
        self.l.rows(0, self.m_ineq)
    }

    /// Active inequality upper bounds.
    pub fn u(&self) -> DVectorView<'_, f64> {
        self.u.rows(0, self.m_ineq)
    }

    /// Variable lower bounds.
    pub fn x_min(&self) -> DVectorView<'_, f64> {
        self.x_min.as_view()
    }

    /// Variable upper bounds.
    pub fn x_max(&self) -> DVectorView<'_, f64> {
        self.x_max.as_view()
    }

    /// Mutable views of all parts (active rows only), to fill the problem in place.
    pub fn parts_mut(&mut self) -> QpPartsMut<'_> {
        let (m_eq, m_ineq) = (self.m_eq, self.m_ineq);
        QpPartsMut {
            p: self.p.as_view_mut(),
            q: self.q.as_view_mut(),
            a_eq: self.a_eq.rows_mut(0, m_eq),
            b_eq: self.b_eq.rows_mut(0, m_eq),
            c: self.c.rows_mut(0, m_ineq),
            l: self.l.rows_mut(0, m_ineq),
            u: self.u.rows_mut(0, m_ineq),
            x_min: self.x_min.as_view_mut(),
            x_max: self.x_max.as_view_mut(),
        }
    }

    /// Checks the active data: no NaN anywhere, `P`, `q`, `A_eq`, `b_eq`, `C` finite, `P`
    /// symmetric (relative 1e-9), bounds not `+∞` below / `-∞` above.
    ///
    /// A lower bound above its upper bound is not an input error but an infeasible problem; the
    /// solvers report it as [`QpError::Infeasible`].
    pub fn validate(&self) -> Result<(), QpError> {
        let n = self.n();
        finite_matrix("P", self.p.as_slice(), n, n)?;
        finite_vector("q", self.q.as_slice())?;
        finite_matrix("A_eq", self.a_eq.as_slice(), self.max_eq(), self.m_eq)?;
        finite_vector("b_eq", &self.b_eq.as_slice()[..self.m_eq])?;
        finite_matrix("C", self.c.as_slice(), self.max_ineq(), self.m_ineq)?;
        bounds("l", &self.l.as_slice()[..self.m_ineq], f64::INFINITY)?;
        bounds("u", &self.u.as_slice()[..self.m_ineq], f64::NEG_INFINITY)?;
        bounds("x_min", self.x_min.as_slice(), f64::INFINITY)?;
        bounds("x_max", self.x_max.as_slice(), f64::NEG_INFINITY)?;
        let p = self.p.as_slice();
        // The largest entry of a symmetric positive semidefinite matrix is on its diagonal; an
        // indefinite P fails later in the solver, so the diagonal is scale enough here.
        let tolerance = 1e-9 * (0..n).fold(0.0_f64, |m, i| m.max(p[i * n + i].abs()));
        for j in 0..n {
            for i in j + 1..n {
                if (p[i + j * n] - p[j + i * n]).abs() > tolerance {
                    return Err(QpError::InvalidInput {
                        field: "P",
                        row: i,
                        col: j,
                        what: "breaks symmetry",
                    });
                }
            }
        }
        Ok(())
    }

    /// Objective value ½ xᵀ P x + qᵀ x (no allocation).
    pub fn objective(&self, x: &[f64]) -> f64 {
        let n = self.n();
        self.p
            .as_slice()
            .chunks_exact(n.max(1))
            .zip(x)
            .zip(self.q.iter())
            .map(|((column, xj), qj)| {
                let px_j: f64 = column.iter().zip(x).map(|(p, x)| p * x).sum();
                xj * (0.5 * px_j + qj)
            })
            .sum()
    }

    /// Whether some lower bound exceeds its upper bound (a trivially infeasible problem).
    pub(crate) fn has_crossed_bounds(&self) -> bool {
        let crossed = |lo: &[f64], hi: &[f64]| lo.iter().zip(hi).any(|(a, b)| a > b);
        let m = self.m_ineq;
        crossed(&self.l.as_slice()[..m], &self.u.as_slice()[..m])
            || crossed(self.x_min.as_slice(), self.x_max.as_slice())
    }
}

fn non_finite(v: f64) -> &'static str {
    if v.is_nan() { "is NaN" } else { "is infinite" }
}

/// Whether every entry is finite: `0 · v` is ±0 for finite `v` and NaN otherwise, and the
/// branch-free sum over four lanes vectorises (the error path below then finds the entry).
fn all_finite(data: &[f64]) -> bool {
    let mut acc = [0.0; 4];
    let chunks = data.chunks_exact(4);
    let tail: f64 = chunks.remainder().iter().map(|v| 0.0 * v).sum();
    for chunk in chunks {
        for k in 0..4 {
            acc[k] += 0.0 * chunk[k];
        }
    }
    acc.iter().sum::<f64>() + tail == 0.0
}

/// Checks the first `rows` entries of each column of a column-major block with `stride` rows.
fn finite_matrix(
    field: &'static str,
    data: &[f64],
    stride: usize,
    rows: usize,
) -> Result<(), QpError> {
    if stride == 0 || (rows == stride && all_finite(data)) {
        return Ok(());
    }
    for (col, column) in data.chunks_exact(stride).enumerate() {
        if let Some(row) = column[..rows].iter().position(|v| !v.is_finite()) {
            return Err(QpError::InvalidInput {
                field,
                row,
                col,
                what: non_finite(column[row]),
            });
        }
    }
    Ok(())
}

fn finite_vector(field: &'static str, v: &[f64]) -> Result<(), QpError> {
    if all_finite(v) {
        return Ok(());
    }
    match v.iter().position(|x| !x.is_finite()) {
        Some(row) => Err(QpError::InvalidInput {
            field,
            row,
            col: 0,
            what: non_finite(v[row]),
        }),
        None => Ok(()),
    }
}

/// Bounds may be infinite on their own side only (`forbidden` is the other infinity).
fn bounds(field: &'static str, v: &[f64], forbidden: f64) -> Result<(), QpError> {
    for (i, &x) in v.iter().enumerate() {
        if x.is_nan() {
            return Err(QpError::InvalidInput {
                field,
                row: i,
                col: 0,
                what: "is NaN",
            });
        }
        if x == forbidden {
            let what = if forbidden > 0.0 {
                "is +inf (a lower bound must be below +inf)"
            } else {
                "is -inf (an upper bound must be above -inf)"
            };
            return Err(QpError::InvalidInput {
                field,
                row: i,
                col: 0,
                what,
            });
        }
    }
    Ok(())
}
