//! [`DenseActiveSetSolver`]: Goldfarb–Idnani dual active-set method, allocation-free after
//! construction and warm-started from the previous solve's active set.
//!
//! The method (Goldfarb & Idnani 1983, as in quadprog/eiquadprog) starts from the optimum under
//! the equalities alone, then repeatedly adds the most violated inequality, dropping active ones
//! whose multiplier would turn negative. Every iterate is optimal for the constraints in its
//! active set, so the result is exact to round-off once nothing is violated. A final refresh
//! recomputes `x` and the multipliers from the factorisation to remove the drift of the
//! incremental steps.
//!
//! Warm start: the previous active inequalities are added to the factorisation after the
//! equalities, `(x, u)` is computed exactly for that set, and constraints with negative
//! multipliers are dropped until the pair is dual feasible; the dual method continues from there.

mod factors;

use factors::{Factors, Normal};

use super::{QpError, QpInfo, QpProblem, QpSolver};

/// A constraint is violated when its normalised slack is below
/// `-FEASIBILITY_TOL · (1 + |rhs| / ‖normal‖)`.
const FEASIBILITY_TOL: f64 = 1e-11;

/// One constraint of the problem, in the form `nᵀ x ≥ rhs` (or `=` for equalities).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Constraint {
    /// Row `i` of `A_eq x = b_eq`.
    Eq(usize),
    /// `C_i x ≥ l_i`.
    Lower(usize),
    /// `−C_i x ≥ −u_i`.
    Upper(usize),
    /// `x_j ≥ x_min_j`.
    MinBound(usize),
    /// `−x_j ≥ −x_max_j`.
    MaxBound(usize),
}

/// Dense dual active-set QP solver for strictly convex problems (P positive definite).
///
/// Sized at construction for `n` variables, up to `max_eq` equality and `max_ineq` inequality
/// rows; `solve` performs no allocation. Keeps the active set of the last successful solve and
/// starts the next solve from it.
pub struct DenseActiveSetSolver {
    n: usize,
    max_eq: usize,
    max_ineq: usize,
    max_iterations: usize,
    factors: Factors,
    x: Vec<f64>,
    /// Multipliers of the active constraints (same order as `active`).
    u: Vec<f64>,
    /// Scratch for right-hand sides of the active set.
    rhs: Vec<f64>,
    active: Vec<Constraint>,
    /// Number of equalities in `active` (always its first entries).
    n_eq: usize,
    /// Per inequality key (see [`Self::key`]): whether it is active.
    is_active: Vec<bool>,
    /// `C x` for the active rows.
    c_x: Vec<f64>,
    /// `1 / ‖C_i‖` for the active rows (1 for zero rows).
    inv_row_norm: Vec<f64>,
    warm: Vec<Constraint>,
    n_warm: usize,
    /// Equality rows found linearly dependent on earlier ones in this solve.
    dependent_eq: Vec<usize>,
}

impl DenseActiveSetSolver {
    /// Allocates all workspace for `n` variables, `max_eq` equalities and `max_ineq`
    /// two-sided inequality rows.
    pub fn new(n: usize, max_eq: usize, max_ineq: usize) -> Self {
        Self {
            n,
            max_eq,
            max_ineq,
            max_iterations: 10 * (n + max_eq + 2 * max_ineq) + 10,
            factors: Factors::new(n),
            x: vec![0.0; n],
            u: vec![0.0; n],
            rhs: vec![0.0; n],
            active: vec![Constraint::Eq(0); n],
            n_eq: 0,
            is_active: vec![false; 2 * max_ineq + 2 * n],
            c_x: vec![0.0; max_ineq],
            inv_row_norm: vec![0.0; max_ineq],
            warm: vec![Constraint::Eq(0); n],
            n_warm: 0,
            dependent_eq: vec![0; max_eq],
        }
    }

    /// Caps active-set changes per solve (default `10 · (n + max_eq + 2 max_ineq) + 10`).
    pub fn set_max_iterations(&mut self, max_iterations: usize) {
        self.max_iterations = max_iterations;
    }

    /// Forgets the stored active set, so the next solve starts cold.
    pub fn reset_warm_start(&mut self) {
        self.n_warm = 0;
    }

    #[inline(always)]
    fn key(&self, c: Constraint) -> Option<usize> {
        match c {
            Constraint::Eq(_) => None,
            Constraint::Lower(i) => Some(2 * i),
            Constraint::Upper(i) => Some(2 * i + 1),
            Constraint::MinBound(j) => Some(2 * self.max_ineq + 2 * j),
            Constraint::MaxBound(j) => Some(2 * self.max_ineq + 2 * j + 1),
        }
    }

    fn check_dimensions(&self, problem: &QpProblem, x: &[f64]) -> Result<(), QpError> {
        let mismatch = |what, expected, found| {
            Err(QpError::Dimension {
                what,
                expected,
                found,
            })
        };
        if problem.n() != self.n {
            return mismatch("n", self.n, problem.n());
        }
        if x.len() != self.n {
            return mismatch("x", self.n, x.len());
        }
        if problem.m_eq() > self.max_eq {
            return mismatch("m_eq", self.max_eq, problem.m_eq());
        }
        if problem.m_ineq() > self.max_ineq {
            return mismatch("m_ineq", self.max_ineq, problem.m_ineq());
        }
        Ok(())
    }

    /// Loads the normal of `c` (dense ones into the factor workspace).
    #[inline(always)]
    fn load_normal(&mut self, problem: &QpProblem, c: Constraint) -> Normal {
        let (matrix, row, sign) = match c {
            Constraint::Eq(i) => (&problem.a_eq, i, 1.0),
            Constraint::Lower(i) => (&problem.c, i, 1.0),
            Constraint::Upper(i) => (&problem.c, i, -1.0),
            Constraint::MinBound(index) => return Normal::Unit { index, sign: 1.0 },
            Constraint::MaxBound(index) => return Normal::Unit { index, sign: -1.0 },
        };
        let rows = matrix.nrows();
        let data = matrix.as_slice();
        for (j, v) in self.factors.normal.iter_mut().enumerate() {
            *v = sign * data[j * rows + row];
        }
        Normal::Dense
    }

    /// Right-hand side of `c` in the form `nᵀ x ≥ rhs`.
    #[inline(always)]
    fn rhs(problem: &QpProblem, c: Constraint) -> f64 {
        match c {
            Constraint::Eq(i) => problem.b_eq[i],
            Constraint::Lower(i) => problem.l[i],
            Constraint::Upper(i) => -problem.u[i],
            Constraint::MinBound(j) => problem.x_min[j],
            Constraint::MaxBound(j) => -problem.x_max[j],
        }
    }

    /// Adds the constraint whose step was just computed, with multiplier `multiplier`.
    #[inline(always)]
    fn activate(&mut self, c: Constraint, multiplier: f64) {
        let iq = self.factors.iq;
        self.u[iq] = multiplier;
        self.active[iq] = c;
        if let Some(k) = self.key(c) {
            self.is_active[k] = true;
        }
        self.factors.add();
    }

    /// Drops active constraint `pos`.
    #[inline(always)]
    fn deactivate(&mut self, pos: usize) {
        if let Some(k) = self.key(self.active[pos]) {
            self.is_active[k] = false;
        }
        let iq = self.factors.iq;
        self.active.copy_within(pos + 1..iq, pos);
        self.u.copy_within(pos + 1..iq, pos);
        self.factors.remove(pos);
    }

    /// Recomputes `x` and the multipliers exactly from the factorisation of the active set.
    #[inline(always)]
    fn refresh_primal_dual(&mut self, problem: &QpProblem) {
        let iq = self.factors.iq;
        for k in 0..iq {
            self.rhs[k] = Self::rhs(problem, self.active[k]);
        }
        self.factors.primal_dual(
            problem.q.as_slice(),
            &mut self.rhs,
            &mut self.x,
            &mut self.u,
        );
    }

    /// Builds the starting active set: every independent equality, then the previous solve's
    /// inequalities (warm start); computes the exact `(x, u)` for it and drops warm constraints
    /// with negative multipliers until the pair is dual feasible. Returns the number dropped.
    #[inline(always)]
    fn initial_active_set(&mut self, problem: &QpProblem) -> Result<usize, QpError> {
        let mut n_dependent = 0;
        for i in 0..problem.m_eq {
            let normal = self.load_normal(problem, Constraint::Eq(i));
            if self.factors.compute_d(normal) {
                self.dependent_eq[n_dependent] = i;
                n_dependent += 1;
            } else {
                self.activate(Constraint::Eq(i), 0.0);
            }
        }
        self.n_eq = self.factors.iq;
        for w in 0..self.n_warm {
            let c = self.warm[w];
            let valid = match c {
                Constraint::Lower(i) | Constraint::Upper(i) => i < problem.m_ineq,
                _ => true,
            };
            if !valid || !Self::rhs(problem, c).is_finite() || self.factors.iq == self.n {
                continue;
            }
            let normal = self.load_normal(problem, c);
            if !self.factors.compute_d(normal) {
                self.activate(c, 0.0);
            }
        }
        let mut dropped = 0;
        loop {
            self.refresh_primal_dual(problem);
            let worst = (self.n_eq..self.factors.iq)
                .filter(|&k| self.u[k] < 0.0)
                .min_by(|&a, &b| self.u[a].total_cmp(&self.u[b]));
            match worst {
                Some(k) => {
                    self.deactivate(k);
                    dropped += 1;
                }
                None => break,
            }
        }
        // A dependent equality row is implied by the independent ones: it must hold at x.
        for k in 0..n_dependent {
            let i = self.dependent_eq[k];
            let normal = self.load_normal(problem, Constraint::Eq(i));
            let value = self.factors.normal_dot(normal, &self.x);
            if (value - problem.b_eq[i]).abs() > 1e-9 * (1.0 + problem.b_eq[i].abs() + value.abs())
            {
                return Err(QpError::Infeasible);
            }
        }
        Ok(dropped)
    }

    /// `x += t z` (if `primal`) and `u -= t r` on the active multipliers.
    #[inline(always)]
    fn take_step(&mut self, t: f64, primal: bool) {
        if primal {
            for (xi, zi) in self.x.iter_mut().zip(&self.factors.z) {
                *xi += t * zi;
            }
        }
        let iq = self.factors.iq;
        for (ui, ri) in self.u[..iq].iter_mut().zip(&self.factors.r_step[..iq]) {
            *ui -= t * ri;
        }
    }

    /// The most violated inactive inequality, if any (normalised slack).
    #[inline(always)]
    fn most_violated(&mut self, problem: &QpProblem) -> Option<Constraint> {
        let (n, m) = (self.n, problem.m_ineq);
        let rows = problem.c.nrows();
        let data = problem.c.as_slice();
        self.c_x[..m].fill(0.0);
        for j in 0..n {
            let xj = self.x[j];
            for (cx, cij) in self.c_x[..m].iter_mut().zip(&data[j * rows..j * rows + m]) {
                *cx += cij * xj;
            }
        }
        let mut best = None;
        let mut best_violation = 0.0;
        // Infinite sides give an infinite slack and drop out at the first comparison.
        let mut consider = |key: usize, c: Constraint, slack: f64, rhs: f64, inv_norm: f64| {
            if slack >= 0.0 || self.is_active[key] {
                return;
            }
            let violation = slack * inv_norm;
            if violation < -FEASIBILITY_TOL * (1.0 + rhs.abs() * inv_norm)
                && violation < best_violation
            {
                best_violation = violation;
                best = Some(c);
            }
        };
        let (l, u) = (problem.l.as_slice(), problem.u.as_slice());
        for i in 0..m {
            let (cx, inv_norm) = (self.c_x[i], self.inv_row_norm[i]);
            consider(2 * i, Constraint::Lower(i), cx - l[i], l[i], inv_norm);
            consider(2 * i + 1, Constraint::Upper(i), u[i] - cx, u[i], inv_norm);
        }
        let base = 2 * self.max_ineq;
        let (x_min, x_max) = (problem.x_min.as_slice(), problem.x_max.as_slice());
        for j in 0..n {
            let xj = self.x[j];
            consider(
                base + 2 * j,
                Constraint::MinBound(j),
                xj - x_min[j],
                x_min[j],
                1.0,
            );
            consider(
                base + 2 * j + 1,
                Constraint::MaxBound(j),
                x_max[j] - xj,
                x_max[j],
                1.0,
            );
        }
        best
    }

    /// Adds violated constraint `c`, dropping blocking ones (steps 2a–2c of Goldfarb–Idnani).
    #[inline(always)]
    fn add_violated(
        &mut self,
        problem: &QpProblem,
        c: Constraint,
        iterations: &mut usize,
    ) -> Result<(), QpError> {
        let normal = self.load_normal(problem, c);
        let rhs = Self::rhs(problem, c);
        let mut u_plus = 0.0;
        loop {
            *iterations += 1;
            if *iterations > self.max_iterations {
                return Err(QpError::MaxIterations(self.max_iterations));
            }
            let dependent = self.factors.compute_d(normal);
            self.factors.compute_z_r();
            let iq = self.factors.iq;
            // Partial (dual) step: largest step keeping active inequality multipliers ≥ 0.
            let mut t_dual = f64::INFINITY;
            let mut blocking = None;
            for k in self.n_eq..iq {
                let rk = self.factors.r_step[k];
                // Rounding can leave a multiplier at −1e-17; never step backwards.
                let ratio = (self.u[k] / rk).max(0.0);
                if rk > 0.0 && ratio < t_dual {
                    t_dual = ratio;
                    blocking = Some(k);
                }
            }
            // Full step: makes `c` hold with equality.
            let t_full = if dependent {
                f64::INFINITY
            } else {
                (rhs - self.factors.normal_dot(normal, &self.x)) / self.factors.d2_norm_sq()
            };
            let t = t_dual.min(t_full);
            if t == f64::INFINITY {
                return Err(QpError::Infeasible);
            }
            self.take_step(t, !dependent);
            u_plus += t;
            match blocking {
                Some(k) if t_dual < t_full => self.deactivate(k),
                _ => {
                    self.activate(c, u_plus);
                    return Ok(());
                }
            }
        }
    }

    /// Runs the method, on x86-64 CPUs with AVX2 through a copy of the whole solve compiled
    /// for AVX2 (all inner loops are `#[inline(always)]` so they vectorise 4-wide there).
    fn run(&mut self, problem: &QpProblem) -> Result<QpInfo, QpError> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the running CPU supports AVX2, checked just above.
            return unsafe { self.run_avx2(problem) };
        }
        self.run_portable(problem)
    }

    /// [`Self::run_portable`] compiled with AVX2 enabled.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn run_avx2(&mut self, problem: &QpProblem) -> Result<QpInfo, QpError> {
        self.run_portable(problem)
    }

    /// The Goldfarb–Idnani iteration.
    #[inline(always)]
    fn run_portable(&mut self, problem: &QpProblem) -> Result<QpInfo, QpError> {
        let (m, rows) = (problem.m_ineq, problem.c.nrows());
        let norms = &mut self.inv_row_norm[..m];
        norms.fill(0.0);
        for column in problem.c.as_slice().chunks_exact(rows.max(1)) {
            for (norm, cij) in norms.iter_mut().zip(column) {
                *norm += cij * cij;
            }
        }
        for norm in norms {
            *norm = if *norm > 0.0 { 1.0 / norm.sqrt() } else { 1.0 };
        }
        self.is_active.fill(false);
        self.factors.reset(problem.p.as_slice())?;
        let mut iterations = self.initial_active_set(problem)?;
        // `initial_active_set` ends with an exact refresh.
        let mut refreshed = true;
        loop {
            match self.most_violated(problem) {
                Some(c) => {
                    self.add_violated(problem, c, &mut iterations)?;
                    refreshed = false;
                }
                None if refreshed => break,
                None => {
                    self.refresh_primal_dual(problem);
                    // The exact multipliers of a weakly active constraint may round below 0.
                    for u in &mut self.u[self.n_eq..self.factors.iq] {
                        *u = u.max(0.0);
                    }
                    refreshed = true;
                }
            }
        }
        self.check_solution(problem)?;
        Ok(QpInfo {
            iterations,
            active_constraints: self.factors.iq - self.n_eq,
            objective: problem.objective(&self.x),
        })
    }

    /// Final sanity check: finite and the equalities hold.
    #[inline(always)]
    fn check_solution(&mut self, problem: &QpProblem) -> Result<(), QpError> {
        if self.x.iter().any(|v| !v.is_finite()) {
            return Err(QpError::NumericalFailure("non-finite iterate"));
        }
        let x_norm = self.x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for i in 0..problem.m_eq {
            let normal = self.load_normal(problem, Constraint::Eq(i));
            let ax = self.factors.normal_dot(normal, &self.x);
            let row_norm = self
                .factors
                .normal
                .iter()
                .fold(0.0_f64, |m, v| m.max(v.abs()));
            let scale = 1.0 + problem.b_eq[i].abs() + row_norm * x_norm;
            if (ax - problem.b_eq[i]).abs() > 1e-8 * scale {
                return Err(QpError::NumericalFailure("equality residual too large"));
            }
        }
        Ok(())
    }
}

impl QpSolver for DenseActiveSetSolver {
    fn solve(&mut self, problem: &QpProblem, x: &mut [f64]) -> Result<QpInfo, QpError> {
        self.check_dimensions(problem, x)?;
        problem.validate()?;
        if problem.has_crossed_bounds() {
            return Err(QpError::Infeasible);
        }
        let info = self.run(problem)?;
        x.copy_from_slice(&self.x);
        let n_ineq = self.factors.iq - self.n_eq;
        self.warm[..n_ineq].copy_from_slice(&self.active[self.n_eq..self.factors.iq]);
        self.n_warm = n_ineq;
        Ok(info)
    }
}
