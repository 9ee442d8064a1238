//! The Goldfarb–Idnani factorisation `J = L⁻ᵀ Q`, `Jᵀ N = [R; 0]` of the active constraint
//! normals `N`, updated by a Householder reflection when a constraint is added and by Givens
//! rotations when one is dropped.
//!
//! All matrices are `n × n` column-major `Vec<f64>` buffers allocated once. The Cholesky
//! factorisation and `J = L⁻ᵀ` come from faer; the O(n²) updates are plain loops over
//! contiguous columns, because at n ≈ 40 faer's dispatch overhead outweighs the arithmetic of a
//! single rank-one update.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{
    LltParams, LltRegularization, cholesky_in_place, cholesky_in_place_scratch,
};
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::ReborrowMut;
use faer::{Auto, MatMut, MatRef, Par, Spec};

use crate::qp::QpError;

/// The normal vector of one constraint: dense (held in [`Factors::normal`]) or a signed unit
/// vector (box constraints, whose products with `J` are single rows).
#[derive(Debug, Clone, Copy)]
pub(super) enum Normal {
    /// The normal is stored in `Factors::normal`.
    Dense,
    /// The normal is `sign · e_index`.
    Unit { index: usize, sign: f64 },
}

/// `J`, `R` and the step vectors of the dual active-set method.
pub(super) struct Factors {
    n: usize,
    /// Number of active constraints (columns of `R` in use).
    pub(super) iq: usize,
    /// Cholesky factor `L` of `P` (lower triangle; column-major n × n).
    chol: Vec<f64>,
    /// `J = L⁻ᵀ Q` (column-major n × n); its first `iq` columns span the active normals.
    j: Vec<f64>,
    /// Upper-triangular `R` of `Jᵀ N = [R; 0]` (column-major, first `iq` columns in use).
    r: Vec<f64>,
    /// `1 / R_kk`, so the triangular solves multiply instead of divide.
    r_inv_diag: Vec<f64>,
    /// `d = Jᵀ n` for the constraint being considered.
    d: Vec<f64>,
    /// Primal step direction `z = J₂ d₂`.
    pub(super) z: Vec<f64>,
    /// Dual step direction `r = R⁻¹ d₁` (first `iq` entries).
    pub(super) r_step: Vec<f64>,
    /// Dense constraint normal loaded by the caller.
    pub(super) normal: Vec<f64>,
    /// Scratch `J₂ v` of the Householder update in [`Self::add`].
    householder: Vec<f64>,
    /// faer's scratch for the Cholesky factorisation, sized at construction.
    mem: MemBuffer,
}

/// A constraint is linearly dependent on the active ones when `‖d₂‖ ≤ DEPENDENCE_TOL · ‖d‖`.
const DEPENDENCE_TOL: f64 = 1e-10;

/// A Cholesky pivot `L_ii² ≤ PIVOT_TOL · max_i P_ii` counts as not positive definite.
const PIVOT_TOL: f64 = 1e-15;

impl Factors {
    /// Allocates the buffers for `n` variables.
    pub(super) fn new(n: usize) -> Self {
        let params = cholesky_params();
        Self {
            n,
            iq: 0,
            chol: vec![0.0; n * n],
            j: vec![0.0; n * n],
            r: vec![0.0; n * n],
            r_inv_diag: vec![0.0; n],
            d: vec![0.0; n],
            z: vec![0.0; n],
            r_step: vec![0.0; n],
            normal: vec![0.0; n],
            householder: vec![0.0; n],
            mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(n, Par::Seq, params)),
        }
    }

    /// Factorises `P = L Lᵀ` (lower triangle of the column-major `p`) and sets `J = L⁻ᵀ`, no
    /// active constraints.
    #[inline(always)]
    pub(super) fn reset(&mut self, p: &[f64]) -> Result<(), QpError> {
        let n = self.n;
        self.iq = 0;
        let mut l = MatMut::from_column_major_slice_mut(&mut self.chol, n, n);
        l.copy_from(MatRef::from_column_major_slice(p, n, n));
        cholesky_in_place(
            l.rb_mut(),
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            cholesky_params(),
        )
        .map_err(
            |faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index }| {
                QpError::NotPositiveDefinite { pivot: index }
            },
        )?;
        let max_diag = (0..n).map(|i| p[i * n + i]).fold(0.0, f64::max);
        if let Some(pivot) = (0..n).find(|&i| {
            let lii = l[(i, i)];
            lii * lii <= PIVOT_TOL * max_diag
        }) {
            return Err(QpError::NotPositiveDefinite { pivot });
        }
        self.invert_factor();
        Ok(())
    }

    /// `J = L⁻ᵀ`: solves `L Y = I` with faer in the (still unused) `R` buffer, then transposes.
    ///
    /// `Y` is lower triangular, so column panel `k₀..k₀+w` only involves the trailing block
    /// `L[k₀.., k₀..]`. Panels are narrow enough that every product inside faer's recursive
    /// solve stays within its allocation-free small-matrix kernels (m·n·k ≤ 16³); at n ≈ 40 this
    /// is about 3× faster than faer's recursive triangular inverse.
    #[inline(always)]
    fn invert_factor(&mut self) {
        const SMALL_PRODUCT: usize = 16 * 16 * 16;
        let n = self.n;
        let l = MatRef::from_column_major_slice(&self.chol, n, n);
        let y = &mut self.r;
        y.fill(0.0);
        for i in 0..n {
            y[i * n + i] = 1.0;
        }
        let mut k0 = 0;
        while k0 < n {
            let m = n - k0;
            // The recursion multiplies at most (m/2 × m/2) by (m/2 × w).
            let width = (SMALL_PRODUCT / (m * m).div_ceil(4)).clamp(1, m);
            let panel =
                MatMut::from_column_major_slice_with_stride_mut(&mut y[k0 * n + k0..], m, width, n);
            solve_lower_triangular_in_place(l.submatrix(k0, k0, m, m), panel, Par::Seq);
            k0 += width;
        }
        for (k, column) in self.j.chunks_exact_mut(n).enumerate() {
            for (i, jik) in column.iter_mut().enumerate() {
                *jik = y[i * n + k];
            }
        }
    }

    #[inline(always)]
    fn col(&self, k: usize) -> &[f64] {
        &self.j[k * self.n..(k + 1) * self.n]
    }

    /// Computes `d = Jᵀ n`; returns whether `n` is linearly dependent on the active normals.
    #[inline(always)]
    pub(super) fn compute_d(&mut self, normal: Normal) -> bool {
        let n = self.n;
        match normal {
            Normal::Dense => {
                for k in 0..n {
                    self.d[k] = dot(&self.j[k * n..(k + 1) * n], &self.normal);
                }
            }
            Normal::Unit { index, sign } => {
                for k in 0..n {
                    self.d[k] = sign * self.j[k * n + index];
                }
            }
        }
        let d2 = self.d2_norm_sq();
        let d_all = dot(&self.d, &self.d);
        d2 <= DEPENDENCE_TOL * DEPENDENCE_TOL * d_all
    }

    /// `‖d₂‖² = zᵀ n`, the curvature of the primal step along the constraint.
    #[inline(always)]
    pub(super) fn d2_norm_sq(&self) -> f64 {
        let d2 = &self.d[self.iq..];
        dot(d2, d2)
    }

    /// From `d`: the primal direction `z = J₂ d₂` and dual direction `r = R⁻¹ d₁`.
    #[inline(always)]
    pub(super) fn compute_z_r(&mut self) {
        let n = self.n;
        self.z.fill(0.0);
        for k in self.iq..n {
            axpy(self.d[k], &self.j[k * n..(k + 1) * n], &mut self.z);
        }
        let iq = self.iq;
        self.r_step[..iq].copy_from_slice(&self.d[..iq]);
        self.solve_r(iq);
    }

    /// `v ← R⁻¹ v` on `r_step[..iq]` (back substitution, column oriented).
    #[inline(always)]
    fn solve_r(&mut self, iq: usize) {
        let n = self.n;
        for k in (0..iq).rev() {
            let col = &self.r[k * n..k * n + k + 1];
            self.r_step[k] *= self.r_inv_diag[k];
            let vk = self.r_step[k];
            for (v, rik) in self.r_step[..k].iter_mut().zip(col) {
                *v -= rik * vk;
            }
        }
    }

    /// `nᵀ x` for the loaded normal.
    #[inline(always)]
    pub(super) fn normal_dot(&self, normal: Normal, x: &[f64]) -> f64 {
        match normal {
            Normal::Dense => dot(&self.normal, x),
            Normal::Unit { index, sign } => sign * x[index],
        }
    }

    /// Appends the constraint whose `d` was last computed to the active set: one Householder
    /// reflection `H` maps `d₂` onto its first axis and updates `J₂ ← J₂ H`; `d₁` and the
    /// reflected pivot become the new column of `R`.
    #[inline(always)]
    pub(super) fn add(&mut self) {
        let (n, iq) = (self.n, self.iq);
        let tail = dot(&self.d[iq + 1..], &self.d[iq + 1..]);
        if tail > 0.0 {
            let alpha = self.d[iq];
            let norm = (alpha * alpha + tail).sqrt();
            // Reflect onto −sign(α)‖d₂‖ so that v₀ = α − β does not cancel.
            let beta = if alpha >= 0.0 { -norm } else { norm };
            let v0 = alpha - beta;
            let tau = 2.0 / (v0 * v0 + tail);
            let w = &mut self.householder;
            w.fill(0.0);
            for k in iq..n {
                let vk = if k == iq { v0 } else { self.d[k] };
                axpy(vk, &self.j[k * n..(k + 1) * n], w);
            }
            for k in iq..n {
                let vk = if k == iq { v0 } else { self.d[k] };
                axpy(-tau * vk, w, &mut self.j[k * n..(k + 1) * n]);
            }
            self.d[iq] = beta;
            self.d[iq + 1..].fill(0.0);
        }
        self.r[iq * n..iq * n + iq + 1].copy_from_slice(&self.d[..=iq]);
        self.r_inv_diag[iq] = 1.0 / self.d[iq];
        self.iq += 1;
    }

    /// Removes active constraint `pos` (0-based) and restores `R` to triangular form.
    #[inline(always)]
    pub(super) fn remove(&mut self, pos: usize) {
        let n = self.n;
        for i in pos..self.iq - 1 {
            self.r.copy_within((i + 1) * n..(i + 1) * n + i + 2, i * n);
        }
        self.iq -= 1;
        let iq = self.iq;
        for jj in pos..iq {
            let (a, b) = (self.r[jj * n + jj], self.r[jj * n + jj + 1]);
            if b == 0.0 {
                continue;
            }
            let h = (a * a + b * b).sqrt();
            let (c, s) = (a / h, b / h);
            self.r[jj * n + jj] = h;
            self.r[jj * n + jj + 1] = 0.0;
            for k in jj + 1..iq {
                let (x, y) = (self.r[k * n + jj], self.r[k * n + jj + 1]);
                self.r[k * n + jj] = c * x + s * y;
                self.r[k * n + jj + 1] = -s * x + c * y;
            }
            rotate_columns(&mut self.j, n, jj, c, s);
        }
        for jj in pos..iq {
            self.r_inv_diag[jj] = 1.0 / self.r[jj * n + jj];
        }
    }

    /// Exact primal-dual pair of the equality-constrained problem on the active set:
    /// `x = J₁ R⁻ᵀ b − J₂ J₂ᵀ q`, `u = R⁻¹ (R⁻ᵀ b + J₁ᵀ q)`, where `rhs[..iq]` holds `b`.
    /// Writes `x` and `u[..iq]`; uses `rhs` as scratch.
    #[inline(always)]
    pub(super) fn primal_dual(&mut self, q: &[f64], rhs: &mut [f64], x: &mut [f64], u: &mut [f64]) {
        let (n, iq) = (self.n, self.iq);
        for i in 0..iq {
            let col = &self.r[i * n..i * n + i + 1];
            rhs[i] = (rhs[i] - dot(&col[..i], &rhs[..i])) * self.r_inv_diag[i];
        }
        for k in 0..n {
            self.d[k] = dot(self.col(k), q);
        }
        x.fill(0.0);
        for (k, column) in self.j.chunks_exact(n).enumerate() {
            let coef = if k < iq { rhs[k] } else { -self.d[k] };
            axpy(coef, column, x);
        }
        for ((r, w), v) in self.r_step[..iq].iter_mut().zip(&rhs[..iq]).zip(&self.d) {
            *r = w + v;
        }
        self.solve_r(iq);
        u[..iq].copy_from_slice(&self.r_step[..iq]);
    }
}

/// faer's unblocked (SIMD) Cholesky at every size: its blocked variant, used above n = 64 by
/// default, multiplies through the `gemm` crate, which allocates packing buffers per call.
fn cholesky_params() -> Spec<LltParams, f64> {
    LltParams {
        recursion_threshold: usize::MAX,
        ..Auto::<f64>::auto()
    }
    .into()
}

#[inline(always)]
fn rotate_columns(m: &mut [f64], n: usize, first: usize, c: f64, s: f64) {
    let (left, right) = m[first * n..(first + 2) * n].split_at_mut(n);
    for (a, b) in left.iter_mut().zip(right) {
        let (x, y) = (*a, *b);
        *a = c * x + s * y;
        *b = c * y - s * x;
    }
}

/// Dot product with eight independent partial sums, so it vectorises (AVX2 in the
/// multiversioned solve, see [`super::DenseActiveSetSolver`]).
#[inline(always)]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 8];
    let (mut ca, mut cb) = (a.chunks_exact(8), b.chunks_exact(8));
    for (x, y) in (&mut ca).zip(&mut cb) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
}

#[inline(always)]
pub(super) fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}
