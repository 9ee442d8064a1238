//! [`ClarabelSolver`]: the interior-point reference back-end (allocates per solve).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

use super::{QpError, QpInfo, QpProblem, QpSolver};

/// Reference solver: converts the problem to clarabel's conic form (equalities as a zero cone,
/// finite inequality sides and bounds as a nonnegative cone) and runs its interior-point method.
pub struct ClarabelSolver {
    settings: DefaultSettings<f64>,
}

impl ClarabelSolver {
    /// Clarabel with its default tolerances (≈1e-8), quiet.
    pub fn new() -> Self {
        Self::with_settings(DefaultSettings {
            verbose: false,
            ..DefaultSettings::default()
        })
    }

    /// Clarabel with tight tolerances (1e-12 gap and feasibility), used as a high-precision
    /// reference in tests.
    pub fn high_precision() -> Self {
        Self::with_settings(DefaultSettings {
            verbose: false,
            tol_gap_abs: 1e-12,
            tol_gap_rel: 1e-12,
            tol_feas: 1e-12,
            tol_ktratio: 1e-10,
            max_iter: 400,
            ..DefaultSettings::default()
        })
    }

    /// Clarabel with caller-chosen settings.
    pub fn with_settings(settings: DefaultSettings<f64>) -> Self {
        Self { settings }
    }
}

impl Default for ClarabelSolver {
    fn default() -> Self {
        Self::new()
    }
}

/// One row of the stacked constraint matrix `A x + s = b`, `s ∈ cone`.
struct ConicRows {
    /// Entries per column: (row, value).
    cols: Vec<Vec<(usize, f64)>>,
    b: Vec<f64>,
}

impl ConicRows {
    fn push_row(&mut self, entries: impl Iterator<Item = (usize, f64)>, rhs: f64) {
        let row = self.b.len();
        for (j, v) in entries {
            if v != 0.0 {
                self.cols[j].push((row, v));
            }
        }
        self.b.push(rhs);
    }

    fn into_csc(self) -> (CscMatrix<f64>, Vec<f64>) {
        let m = self.b.len();
        let n = self.cols.len();
        let mut colptr = Vec::with_capacity(n + 1);
        let mut rowval = Vec::new();
        let mut nzval = Vec::new();
        colptr.push(0);
        for col in self.cols {
            for (r, v) in col {
                rowval.push(r);
                nzval.push(v);
            }
            colptr.push(rowval.len());
        }
        (CscMatrix::new(m, n, colptr, rowval, nzval), self.b)
    }
}

impl QpSolver for ClarabelSolver {
    fn solve(&mut self, problem: &QpProblem, x: &mut [f64]) -> Result<QpInfo, QpError> {
        problem.validate()?;
        let n = problem.n();
        if x.len() != n {
            return Err(QpError::Dimension {
                what: "x",
                expected: n,
                found: x.len(),
            });
        }
        if problem.has_crossed_bounds() {
            return Err(QpError::Infeasible);
        }
        let p = problem.p();
        let mut p_colptr = vec![0];
        let mut p_rowval = Vec::new();
        let mut p_nzval = Vec::new();
        for j in 0..n {
            for i in 0..=j {
                if p[(i, j)] != 0.0 {
                    p_rowval.push(i);
                    p_nzval.push(p[(i, j)]);
                }
            }
            p_colptr.push(p_rowval.len());
        }
        let p_csc = CscMatrix::new(n, n, p_colptr, p_rowval, p_nzval);

        let mut rows = ConicRows {
            cols: vec![Vec::new(); n],
            b: Vec::new(),
        };
        let (a, b_eq) = (problem.a_eq(), problem.b_eq());
        for i in 0..problem.m_eq() {
            rows.push_row((0..n).map(|j| (j, a[(i, j)])), b_eq[i]);
        }
        let m_zero = rows.b.len();
        // Nonnegative rows: every finite side as `row · x ≤ rhs`, remembered for the active count.
        let (c, l, u) = (problem.c(), problem.l(), problem.u());
        for i in 0..problem.m_ineq() {
            if u[i].is_finite() {
                rows.push_row((0..n).map(|j| (j, c[(i, j)])), u[i]);
            }
            if l[i].is_finite() {
                rows.push_row((0..n).map(|j| (j, -c[(i, j)])), -l[i]);
            }
        }
        let (x_min, x_max) = (problem.x_min(), problem.x_max());
        for j in 0..n {
            if x_max[j].is_finite() {
                rows.push_row(std::iter::once((j, 1.0)), x_max[j]);
            }
            if x_min[j].is_finite() {
                rows.push_row(std::iter::once((j, -1.0)), -x_min[j]);
            }
        }
        let m_nonneg = rows.b.len() - m_zero;
        let (a_csc, b) = rows.into_csc();
        let mut cones = Vec::with_capacity(2);
        if m_zero > 0 {
            cones.push(SupportedConeT::ZeroConeT(m_zero));
        }
        if m_nonneg > 0 {
            cones.push(SupportedConeT::NonnegativeConeT(m_nonneg));
        }
        let q: Vec<f64> = problem.q().iter().copied().collect();
        let mut solver = DefaultSolver::new(&p_csc, &q, &a_csc, &b, &cones, self.settings.clone())
            .map_err(|_| QpError::NumericalFailure("clarabel rejected the problem data"))?;
        solver.solve();
        let sol = &solver.solution;
        match sol.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {}
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                return Err(QpError::Infeasible);
            }
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => {
                return Err(QpError::NonConvex);
            }
            SolverStatus::MaxIterations => {
                return Err(QpError::MaxIterations(sol.iterations as usize));
            }
            _ => return Err(QpError::NumericalFailure("clarabel did not converge")),
        }
        if sol.x.iter().any(|v| !v.is_finite()) {
            return Err(QpError::NumericalFailure(
                "clarabel returned a non-finite solution",
            ));
        }
        let active_constraints = sol.s[m_zero..]
            .iter()
            .zip(&b[m_zero..])
            .filter(|&(s, rhs)| *s <= 1e-7 * (1.0 + rhs.abs()))
            .count();
        x.copy_from_slice(&sol.x);
        Ok(QpInfo {
            iterations: sol.iterations as usize,
            active_constraints,
            objective: problem.objective(x),
        })
    }
}
