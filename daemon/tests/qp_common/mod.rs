//! Shared helpers of the QP tests and benchmark: seeded controller-like random problems, a KKT
//! certificate independent of any solver, and an exact KKT solve at a given active set.
#![allow(dead_code)] // each test binary uses a different subset

use daemon::qp::{QpInfo, QpProblem};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// How the Hessian is conditioned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Conditioning {
    /// Task weights 1..10 and a unit posture task: cond(P) ≈ 1e2–1e4.
    Well,
    /// Task weights spanning 1e3 (CoM) down to 1e-6 (posture), as the
    /// controller's low posture weight produces: cond(P) ≈ 1e8–1e9 (regularisation 1e-5).
    Ill,
}

/// How far the constraints sit from the equality-constrained optimum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Activity {
    /// Every inequality and bound holds strictly at the equality-constrained optimum: none active.
    None,
    /// Constraints tight around a feasible point away from that optimum: several active.
    Some,
}

/// Shape of a controller-like QP: decision variable (6 base DoF + joints), contact rows,
/// support-polygon rows.
#[derive(Debug, Clone, Copy)]
pub struct Shape {
    pub n: usize,
    pub m_eq: usize,
    pub m_ineq: usize,
}

impl Shape {
    /// `n` variables, `m_eq` equality rows and `m_ineq` inequality rows.
    pub const fn new(n: usize, m_eq: usize, m_ineq: usize) -> Self {
        Self { n, m_eq, m_ineq }
    }
}

fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    rng.random_range(lo..hi)
}

fn random_matrix(rng: &mut ChaCha8Rng, rows: usize, cols: usize, scale: f64) -> DMatrix<f64> {
    DMatrix::from_fn(rows, cols, |_, _| scale * uniform(rng, -1.0, 1.0))
}

/// `P = Σ w_k J_kᵀ J_k + λ I` and `q = −Σ w_k J_kᵀ e_k` over CoM (2 rows), two end-effector poses
/// (6 rows each), torso orientation (3 rows) and posture (joints).
fn tasks(
    rng: &mut ChaCha8Rng,
    n: usize,
    conditioning: Conditioning,
) -> (DMatrix<f64>, DVector<f64>) {
    let (weights, posture_weight, lambda) = match conditioning {
        Conditioning::Well => ([10.0, 3.0, 3.0, 1.0], 1.0, 1e-2),
        Conditioning::Ill => ([1e3, 1e2, 1e2, 10.0], 1e-6, 1e-5),
    };
    let mut p = DMatrix::identity(n, n) * lambda;
    let mut q = DVector::zeros(n);
    for (rows, w) in [2, 6, 6, 3].into_iter().zip(weights) {
        let j = random_matrix(rng, rows, n, 0.5);
        let e = DVector::from_fn(rows, |_, _| uniform(rng, -1.0, 1.0));
        p += w * j.transpose() * &j;
        q -= w * j.transpose() * e;
    }
    for i in 6..n {
        p[(i, i)] += posture_weight;
        q[i] -= posture_weight * uniform(rng, -1.0, 1.0);
    }
    // Exact symmetry, as the controller's assembly guarantees.
    let p = (&p + p.transpose()) * 0.5;
    (p, q)
}

/// The KKT system `[P Aᵀ; A 0] [x; ν] = [−q; b]` of `min ½xᵀPx + qᵀx, A x = b`.
fn kkt_system(
    p: &DMatrix<f64>,
    q: &DVector<f64>,
    a: &DMatrix<f64>,
    b: &DVector<f64>,
) -> (DMatrix<f64>, DVector<f64>) {
    let (n, m) = (p.nrows(), a.nrows());
    let mut k = DMatrix::zeros(n + m, n + m);
    k.view_mut((0, 0), (n, n)).copy_from(p);
    k.view_mut((n, 0), (m, n)).copy_from(a);
    k.view_mut((0, n), (n, m)).copy_from(&a.transpose());
    let mut rhs = DVector::zeros(n + m);
    rhs.rows_mut(0, n).copy_from(&(-q));
    rhs.rows_mut(n, m).copy_from(b);
    (k, rhs)
}

/// Solves the equality-constrained QP `min ½xᵀPx + qᵀx, A x = b` through its KKT system.
pub fn equality_optimum(
    p: &DMatrix<f64>,
    q: &DVector<f64>,
    a: &DMatrix<f64>,
    b: &DVector<f64>,
) -> DVector<f64> {
    let (k, rhs) = kkt_system(p, q, a, b);
    let sol = k
        .lu()
        .solve(&rhs)
        .expect("KKT matrix of a generated problem is regular");
    sol.rows(0, p.nrows()).into_owned()
}

/// A seeded controller-like strictly convex QP that is feasible by construction.
///
/// Equalities are random rows through a random point `x_f`; inequality rows and joint bounds
/// (indices ≥ 6; the base stays free) get random margins around either the equality-constrained
/// optimum (`Activity::None`) or `x_f` (`Activity::Some`); about 15% of sides are left infinite.
pub fn controller_like(
    rng: &mut ChaCha8Rng,
    shape: Shape,
    conditioning: Conditioning,
    activity: Activity,
) -> QpProblem {
    let Shape { n, m_eq, m_ineq } = shape;
    let (p, q) = tasks(rng, n, conditioning);
    let a = random_matrix(rng, m_eq, n, 1.0);
    let x_f = DVector::from_fn(n, |_, _| uniform(rng, -0.2, 0.2));
    let b = &a * &x_f;
    let c = random_matrix(rng, m_ineq, n, 0.3);
    let center = match activity {
        Activity::None => equality_optimum(&p, &q, &a, &b),
        Activity::Some => x_f,
    };
    let (lo_margin, hi_margin) = match activity {
        Activity::None => (0.05, 0.5),
        Activity::Some => (0.1, 0.5),
    };
    let mut problem = QpProblem::new(n, m_eq, m_ineq);
    let c_center = &c * &center;
    {
        let mut parts = problem.parts_mut();
        parts.p.copy_from(&p);
        parts.q.copy_from(&q);
        parts.a_eq.copy_from(&a);
        parts.b_eq.copy_from(&b);
        parts.c.copy_from(&c);
        let margin = |rng: &mut ChaCha8Rng| uniform(rng, lo_margin, hi_margin);
        for i in 0..m_ineq {
            let (lo, hi) = (c_center[i] - margin(rng), c_center[i] + margin(rng));
            parts.l[i] = side(rng, lo, f64::NEG_INFINITY);
            parts.u[i] = side(rng, hi, f64::INFINITY);
        }
        for j in 6..n {
            let (lo, hi) = (center[j] - margin(rng), center[j] + margin(rng));
            parts.x_min[j] = side(rng, lo, f64::NEG_INFINITY);
            parts.x_max[j] = side(rng, hi, f64::INFINITY);
        }
    }
    problem
}

fn side(rng: &mut ChaCha8Rng, value: f64, infinite: f64) -> f64 {
    if rng.random_bool(0.15) {
        infinite
    } else {
        value
    }
}

/// One constraint row in `nᵀ x ≥ rhs` (or `=`) form, for certificates.
pub struct Row {
    pub normal: DVector<f64>,
    pub rhs: f64,
    pub equality: bool,
}

/// All finite constraint rows of `problem` in `nᵀ x ≥ rhs` / `nᵀ x = rhs` form.
pub fn rows(problem: &QpProblem) -> Vec<Row> {
    let n = problem.n();
    let mut out = Vec::new();
    for i in 0..problem.m_eq() {
        out.push(Row {
            normal: problem.a_eq().row(i).transpose(),
            rhs: problem.b_eq()[i],
            equality: true,
        });
    }
    for i in 0..problem.m_ineq() {
        let row = problem.c().row(i).transpose();
        push_sides(&mut out, row, problem.l()[i], problem.u()[i]);
    }
    for j in 0..n {
        let e = DVector::from_fn(n, |i, _| if i == j { 1.0 } else { 0.0 });
        push_sides(&mut out, e, problem.x_min()[j], problem.x_max()[j]);
    }
    out
}

/// The rows `normalᵀ x ≥ lo` and `−normalᵀ x ≥ −hi` of a two-sided constraint, each only if
/// that side is finite.
fn push_sides(out: &mut Vec<Row>, normal: DVector<f64>, lo: f64, hi: f64) {
    if lo.is_finite() {
        out.push(Row {
            normal: normal.clone(),
            rhs: lo,
            equality: false,
        });
    }
    if hi.is_finite() {
        out.push(Row {
            normal: -normal,
            rhs: -hi,
            equality: false,
        });
    }
}

/// Residuals of the KKT conditions at `x`, each scaled to be dimensionless.
#[derive(Debug, Clone, Copy)]
pub struct Kkt {
    /// Largest constraint violation, divided by `1 + ‖row‖·‖x‖∞ + |rhs|`.
    pub primal: f64,
    /// `‖P x + q − Nᵀλ‖∞ / (1 + ‖P‖∞‖x‖∞ + ‖q‖∞)` with least-squares multipliers on the active rows.
    pub stationarity: f64,
    /// Most negative inequality multiplier, divided by `1 + ‖λ‖∞` (0 if none negative).
    pub dual: f64,
    /// Number of active inequality rows (slack ≤ `active_tol`).
    pub active: usize,
}

impl Kkt {
    /// Worst of the three residuals.
    pub fn worst(&self) -> f64 {
        self.primal.max(self.stationarity).max(self.dual)
    }
}

/// Computes the KKT residuals of `x` for `problem`; rows whose scaled slack is at most
/// `active_tol` are taken as active. Independent of any solver's internal state.
pub fn kkt(problem: &QpProblem, x: &DVector<f64>, active_tol: f64) -> Kkt {
    let rows = rows(problem);
    let x_inf = x.amax();
    let mut primal: f64 = 0.0;
    let mut active = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        let scale = 1.0 + row.normal.amax() * x_inf + row.rhs.abs();
        let slack = (row.normal.dot(x) - row.rhs) / scale;
        let violation = if row.equality {
            slack.abs()
        } else {
            (-slack).max(0.0)
        };
        primal = primal.max(violation);
        if row.equality || slack <= active_tol {
            active.push(k);
        }
    }
    let p = problem.p().into_owned();
    let gradient = &p * x + problem.q();
    let n_mat = DMatrix::from_fn(x.len(), active.len(), |i, k| rows[active[k]].normal[i]);
    let lambda = if active.is_empty() {
        DVector::zeros(0)
    } else {
        n_mat
            .clone()
            .svd(true, true)
            .solve(&gradient, 1e-14)
            .expect("SVD solve")
    };
    let residual = &gradient - &n_mat * &lambda;
    let stationarity = residual.amax() / (1.0 + p.amax() * x_inf + problem.q().amax());
    let lambda_scale = 1.0 + lambda.amax();
    let dual = active
        .iter()
        .zip(lambda.iter())
        .filter(|&(&k, _)| !rows[k].equality)
        .map(|(_, &l)| (-l / lambda_scale).max(0.0))
        .fold(0.0, f64::max);
    let n_active_ineq = active.iter().filter(|&&k| !rows[k].equality).count();
    Kkt {
        primal,
        stationarity,
        dual,
        active: n_active_ineq,
    }
}

/// Asserts that `x`, the solution `info` reports, satisfies the KKT conditions of `problem` to
/// 1e-9 and that `info` counts the active inequalities the certificate finds; `case` names the
/// problem in the messages.
pub fn assert_certified(problem: &QpProblem, x: &DVector<f64>, info: &QpInfo, case: &str) {
    let cert = kkt(problem, x, 1e-9);
    assert!(cert.worst() <= 1e-9, "{case}: dense KKT residuals {cert:?}");
    assert_eq!(
        info.active_constraints, cert.active,
        "{case}: reported vs certified active count"
    );
}

/// The exact optimum for the active set identified at `x` (rows with scaled slack ≤
/// `active_tol`): the KKT system with those rows as equalities, solved by LU with one step of
/// iterative refinement.
pub fn exact_at_active_set(problem: &QpProblem, x: &DVector<f64>, active_tol: f64) -> DVector<f64> {
    let x_inf = x.amax();
    let active: Vec<Row> = rows(problem)
        .into_iter()
        .filter(|row| {
            let scale = 1.0 + row.normal.amax() * x_inf + row.rhs.abs();
            row.equality || (row.normal.dot(x) - row.rhs) / scale <= active_tol
        })
        .collect();
    let a = DMatrix::from_fn(active.len(), x.len(), |i, j| active[i].normal[j]);
    let b = DVector::from_fn(active.len(), |i, _| active[i].rhs);
    let p = problem.p().into_owned();
    let q = problem.q().into_owned();
    let (k, rhs) = kkt_system(&p, &q, &a, &b);
    let lu = k.clone().lu();
    let mut sol = lu.solve(&rhs).expect("regular KKT system");
    let correction = lu.solve(&(&rhs - &k * &sol)).expect("regular KKT system");
    sol += correction;
    sol.rows(0, p.nrows()).into_owned()
}

/// |a − b| / (1 + |b|), for objective values.
pub fn rel_gap(a: f64, b: f64) -> f64 {
    (a - b).abs() / (1.0 + b.abs())
}

/// ‖a − b‖∞ / (1 + ‖b‖∞).
pub fn rel_dist(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax() / (1.0 + b.amax())
}

/// cond₂(P) from its symmetric eigenvalues.
pub fn condition_number(problem: &QpProblem) -> f64 {
    let eig = problem.p().into_owned().symmetric_eigenvalues();
    eig.max() / eig.min()
}
