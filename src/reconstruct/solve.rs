//! The local least-squares solve at one evaluation point: from the moment matrix
//! A = sum_p w_p q_p q_p^T to the coefficients c with shape functions phi_p = w_p q_p . c.
//! MLS inverts A (Gaussian elimination, as Gong does); IMLS orthogonalises the basis
//! (Tran eq 16) and needs no inversion (eq 11), dropping the polynomials the data cannot
//! support (eq 17).

use nalgebra::{SMatrix, SVector};

use super::basis::{monomials, Degree, MAX_TERMS};
use super::kernel::Kernel;

/// A polynomial is dropped (IMLS) or the moment matrix declared singular (MLS) when the part
/// of it the data can see is at most this fraction of its weighted norm. For IMLS the ratio
/// <p_i, p_i> / <q_i, q_i> is sin^2 of the angle between q_i and the span of the earlier
/// basis: 1e-10 is an angle of 1e-5 rad. Rounding puts a truly dependent monomial near
/// 1e-16 and a supported one above about 1e-4 for the point sets MPM produces, so the
/// threshold separates the two cases by orders of magnitude either way.
pub const RANK_TOLERANCE: f64 = 1e-10;

/// Row-major m x m moment matrix, m <= MAX_TERMS.
pub type Moments = [f64; MAX_TERMS * MAX_TERMS];

/// The moment matrix A = sum_p w(d_p) q(d_p) q(d_p)^T of the offsets d_p = (x_p - x)/h of the
/// data from one evaluation point x, and the number of basis terms.
pub fn moment_matrix<const D: usize>(
    kernel: &Kernel,
    degree: Degree,
    offsets: &[SVector<f64, D>],
) -> (Moments, usize) {
    let mut a = [0.0; MAX_TERMS * MAX_TERMS];
    let mut q = [0.0; MAX_TERMS];
    let terms = degree.terms(D);
    for d in offsets {
        monomials(degree, d, &mut q);
        add_weighted_outer(&mut a, MAX_TERMS, kernel.eval(d), &q[..terms]);
    }
    (a, terms)
}

/// a += w q q^T for a row-major matrix with row length `stride`.
#[inline]
pub(super) fn add_weighted_outer(a: &mut [f64], stride: usize, w: f64, q: &[f64]) {
    for (r, &qr) in q.iter().enumerate() {
        let wq = w * qr;
        for (s, &qs) in q.iter().enumerate() {
            a[r * stride + s] += wq * qs;
        }
    }
}

/// The weighted orthogonal polynomials p_i = sum_j coeffs[i][j] q_j of Tran eq 16, built
/// from the inner products <q_i, q_j> = A_ij (eq 7).
/// Sized for up to `S` terms: `MAX_TERMS` where the basis size is known only at run time
/// (`OrthogonalBasis`), the size itself where it is a constant, which spares a per-point solve
/// the clearing of arrays for terms it does not have.
#[derive(Clone, Debug)]
pub struct Orthogonal<const S: usize> {
    pub terms: usize,
    /// Unit lower-triangular: p_i = q_i - sum_{k<i} (<q_i, p_k>/<p_k, p_k>) p_k.
    pub coeffs: [[f64; S]; S],
    /// <p_i, p_i>.
    pub norms: [f64; S],
    /// Whether p_i is supported by the data (else it is left out of every sum).
    pub kept: [bool; S],
}

pub type OrthogonalBasis = Orthogonal<MAX_TERMS>;

impl<const S: usize> Default for Orthogonal<S> {
    fn default() -> Self {
        Orthogonal {
            terms: 0,
            coeffs: [[0.0; S]; S],
            norms: [0.0; S],
            kept: [false; S],
        }
    }
}

impl OrthogonalBasis {
    pub fn from_moments(a: &Moments, terms: usize) -> Self {
        Self::from_rows(a, MAX_TERMS, terms)
    }
}

impl<const S: usize> Orthogonal<S> {
    /// `from_moments` of a row-major matrix with row length `stride`. Always inlined so that
    /// callers with a fixed basis size get the loops unrolled.
    #[inline(always)]
    pub(super) fn from_rows(a: &[f64], stride: usize, terms: usize) -> Self {
        debug_assert!(terms <= S);
        let mut basis = Orthogonal {
            terms,
            ..Self::default()
        };
        for i in 0..terms {
            let mut c = [0.0; S];
            c[i] = 1.0;
            for k in 0..i {
                if !basis.kept[k] {
                    continue;
                }
                let ck = &basis.coeffs[k];
                let q_i_dot_p_k: f64 = (0..=k).map(|j| ck[j] * a[i * stride + j]).sum();
                let ratio = q_i_dot_p_k / basis.norms[k];
                for j in 0..=k {
                    c[j] -= ratio * ck[j];
                }
            }
            let norm = quadratic_form(a, stride, &c, i + 1);
            basis.coeffs[i] = c;
            basis.norms[i] = norm;
            basis.kept[i] = norm > RANK_TOLERANCE * a[i * stride + i];
        }
        basis
    }

    /// This basis in `wide`, sized for more terms: a copy the size of this basis, not of
    /// `wide`, whose entries from `S` on keep what they held (every use stops at `terms`).
    #[inline(always)]
    pub(super) fn copy_into<const W: usize>(&self, wide: &mut Orthogonal<W>) {
        debug_assert!(S <= W);
        wide.terms = self.terms;
        for i in 0..S {
            wide.coeffs[i][..S].copy_from_slice(&self.coeffs[i]);
        }
        wide.norms[..S].copy_from_slice(&self.norms);
        wide.kept[..S].copy_from_slice(&self.kept);
    }

    pub fn rank(&self) -> usize {
        self.kept[..self.terms].iter().filter(|&&k| k).count()
    }

    /// p_i at a point whose monomials are `q`.
    pub fn eval(&self, i: usize, q: &[f64]) -> f64 {
        (0..=i).map(|j| self.coeffs[i][j] * q[j]).sum()
    }

    /// c of phi_p = w_p q_p . c: u^h = sum_i p_i(x) <p_i, u>/<p_i, p_i> (eq 11, 13) with
    /// p_i(x) = coeffs[i][0] because the monomials vanish at the evaluation point. `N` is
    /// the basis size, `terms`.
    #[inline]
    pub fn shape_coefficients<const N: usize>(&self) -> [f64; S] {
        let mut first = [0.0; S];
        first[0] = 1.0;
        self.solve::<f64, N>(&first)
    }

    /// The least-squares coefficients c of sum_j c_j q_j from rhs_j = <q_j, u>:
    /// c = sum_i p_i <p_i, u>/<p_i, p_i> over the kept polynomials (the pseudo-inverse of the
    /// moment matrix applied to rhs), with <p_i, u> = sum_j coeffs[i][j] rhs_j. The data may be
    /// several fields at once (`Fitted`), each solved with a scalar's arithmetic. `N` is the
    /// basis size, `terms`, as a constant so that the loops unroll.
    #[inline]
    pub fn solve<T: Fitted, const N: usize>(&self, rhs: &[T; S]) -> [T; S] {
        debug_assert_eq!(N, self.terms);
        let mut out = [T::splat(0.0); S];
        for i in 0..N {
            if !self.kept[i] {
                continue;
            }
            // From -0.0, as `Sum` for f64 starts.
            let p_i_dot_u = (0..=i).fold(T::splat(-0.0), |sum, j| sum + rhs[j] * self.coeffs[i][j]);
            let scale = p_i_dot_u / self.norms[i];
            for j in 0..=i {
                out[j] += scale * self.coeffs[i][j];
            }
        }
        out
    }
}

/// Data a least-squares fit takes: a scalar, or a small matrix of them (the components of a
/// velocity or a stress), whose entries are fitted side by side, each with the arithmetic of
/// a scalar fit, so that one pass over the points serves every component.
pub trait Fitted:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<f64, Output = Self>
    + std::ops::Div<f64, Output = Self>
    + std::ops::AddAssign
{
    /// Every entry `x`.
    fn splat(x: f64) -> Self;
}

impl Fitted for f64 {
    fn splat(x: f64) -> Self {
        x
    }
}

impl<const R: usize, const C: usize> Fitted for SMatrix<f64, R, C> {
    fn splat(x: f64) -> Self {
        SMatrix::repeat(x)
    }
}

/// c^T A c over the leading `n` entries, A row-major with row length `stride`.
#[inline(always)]
fn quadratic_form<const S: usize>(a: &[f64], stride: usize, c: &[f64; S], n: usize) -> f64 {
    let mut sum = 0.0;
    for i in 0..n {
        let row: f64 = (0..n).map(|j| a[i * stride + j] * c[j]).sum();
        sum += c[i] * row;
    }
    sum
}

/// MLS: c = A^-1 e_1 by Gaussian elimination with partial pivoting (Gong sec 5.4), A
/// row-major with row length `stride`. `None` when a pivot is at most `RANK_TOLERANCE` times
/// the largest diagonal entry. Always inlined so that callers with a fixed basis size get
/// the loops unrolled.
#[inline(always)]
pub fn mls_coefficients<const S: usize>(
    a: &[f64],
    stride: usize,
    terms: usize,
) -> Option<[f64; S]> {
    let n = terms;
    debug_assert!(n <= S);
    let scale = (0..n).map(|i| a[i * stride + i]).fold(0.0, f64::max);
    // S x S, the basis size where it is a constant: zeroing the largest size is a memset
    // call per evaluation point.
    let mut m = [[0.0; S]; S];
    for r in 0..n {
        m[r][..n].copy_from_slice(&a[r * stride..r * stride + n]);
    }
    let mut rhs = [0.0; S];
    rhs[0] = 1.0;
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&r, &s| m[r][col].abs().total_cmp(&m[s][col].abs()))
            .expect("non-empty range");
        let p = m[pivot][col];
        // NaN moments are singular too.
        if p.abs() <= RANK_TOLERANCE * scale || p.is_nan() {
            return None;
        }
        if pivot != col {
            m.swap(col, pivot);
            rhs.swap(col, pivot);
        }
        for r in col + 1..n {
            let factor = m[r][col] / p;
            for j in col..n {
                m[r][j] -= factor * m[col][j];
            }
            rhs[r] -= factor * rhs[col];
        }
    }
    let mut c = [0.0; S];
    for r in (0..n).rev() {
        let tail: f64 = (r + 1..n).map(|j| m[r][j] * c[j]).sum();
        c[r] = (rhs[r] - tail) / m[r][r];
    }
    Some(c)
}
