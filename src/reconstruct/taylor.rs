//! Taylor least squares (TLS, Wobbes et al. 2018, sec 2): one element's least-squares fit in
//! the Taylor basis of Luo et al. (2008). Every basis function but psi_1 = 1 has zero mean over
//! the element (eq 2), so the element integral of the fit is a_1 |Omega_e| (eq 4): prescribing
//! a_1 = c/|Omega_e| (eq 5) conserves a given integral c, and the other coefficients are then
//! the least-squares fit of the data minus that mean.
//!
//! Rank. The system is solved through the orthogonal polynomials of its normal matrix
//! (`OrthogonalBasis`, Gram-Schmidt in the order psi_1, psi_2, ...), the factorisation the IMLS
//! fits use. A basis function is unsupported when the part of it the earlier ones do not span
//! has a squared norm at the data of at most `RANK_TOLERANCE` (1e-10) of its own squared norm
//! there: sin^2 of its angle to their span. The Taylor functions are scaled by the element's
//! half-widths, so they are O(1) on the element whatever its size, and the relative test needs
//! no other scale. When a function of degree k is unsupported, the fit drops every function of
//! degree >= k (2 -> 1 -> 0) rather than the one function, so a fit is always a complete
//! polynomial of the degree it reports. Degree 0 always works: `Fixed` fits nothing (a_1 is
//! the prescribed mean), `Fitted` fits psi_1 = 1 to at least one point (the average).
//!
//! Accuracy. The normal matrix squares the condition number kappa of the basis at the data;
//! the rank test admits kappa up to about 1e5. `solve` therefore refines its first solution
//! once with the residual at the data (iterative refinement of the normal equations), which
//! brings the coefficients to the kappa eps accuracy of an orthogonal factorisation of the
//! data: three points crowded into a tenth of an element are off by 3e-8 without the step and
//! by 1e-12 with it.

use std::fmt;

use nalgebra::SVector;

use super::basis::{Degree, MAX_TERMS};
use super::solve::{add_weighted_outer, Fitted, Orthogonal, OrthogonalBasis};

/// The largest Taylor basis: the complete quadratic in 2D.
pub const MAX_TAYLOR_TERMS: usize = MAX_TERMS;

/// Number of Taylor basis functions of total degree <= degree: 1D degree+1, 2D (d+1)(d+2)/2;
/// degree <= 2.
pub fn taylor_terms(dim: usize, degree: usize) -> usize {
    Degree::new(degree)
        .unwrap_or_else(|| panic!("Taylor bases have degree 0, 1 or 2, not {degree}"))
        .terms(dim)
}

/// Total degree of basis function psi_{i+1} (index i from 0) in `dim` dimensions.
fn term_degree(dim: usize, i: usize) -> usize {
    match i {
        0 => 0,
        i if i <= dim => 1,
        _ => 2,
    }
}

/// The mean of s^2/2 over s in [-1, 1]: what the quadratic Taylor functions subtract (eq 2).
const HALF_SQUARE_MEAN: f64 = 1.0 / 6.0;

/// One element's box and its Taylor basis (Wobbes sec 2, Luo et al. 2008).
#[derive(Clone, Copy, Debug)]
pub struct TaylorCell<const D: usize> {
    lower: SVector<f64, D>,
    upper: SVector<f64, D>,
    /// x_c, y_c.
    centre: SVector<f64, D>,
    /// Delta x, Delta y: half the edge lengths.
    half: SVector<f64, D>,
}

impl<const D: usize> TaylorCell<D> {
    /// The box [lower, upper]; every edge must have positive length.
    pub fn new(lower: SVector<f64, D>, upper: SVector<f64, D>) -> Self {
        const { assert!(D == 1 || D == 2, "Taylor bases are defined in 1D and 2D") };
        assert!(
            (0..D).all(|k| upper[k] > lower[k]),
            "a Taylor cell needs upper > lower on every axis: {lower:?}, {upper:?}"
        );
        TaylorCell {
            lower,
            upper,
            centre: (lower + upper) * 0.5,
            half: (upper - lower) * 0.5,
        }
    }

    pub fn lower(&self) -> &SVector<f64, D> {
        &self.lower
    }

    pub fn upper(&self) -> &SVector<f64, D> {
        &self.upper
    }

    pub fn centre(&self) -> &SVector<f64, D> {
        &self.centre
    }

    /// Delta x (and Delta y): half the edge lengths.
    pub fn half_widths(&self) -> &SVector<f64, D> {
        &self.half
    }

    /// |Omega_e|.
    pub fn volume(&self) -> f64 {
        (self.upper - self.lower).product()
    }

    /// psi_1..psi_n at x, n = taylor_terms(D, degree); entries beyond n are zero. In 1D the
    /// basis is 1, (x-xc)/dx, (x-xc)^2/(2dx^2) - mean; in 2D the six functions of sec 2 in the
    /// order psi1..psi6 (1, x, y, x^2, y^2, xy), each of degree >= 1 with zero cell mean (eq 2).
    pub fn basis(&self, degree: usize, x: &SVector<f64, D>) -> [f64; MAX_TAYLOR_TERMS] {
        assert!(
            degree <= 2,
            "Taylor bases have degree 0, 1 or 2, not {degree}"
        );
        let s = (x - self.centre).component_div(&self.half);
        let mut psi = [0.0; MAX_TAYLOR_TERMS];
        psi[0] = 1.0;
        if degree == 0 {
            return psi;
        }
        for k in 0..D {
            psi[1 + k] = s[k];
        }
        if degree == 2 {
            for k in 0..D {
                psi[1 + D + k] = 0.5 * s[k] * s[k] - HALF_SQUARE_MEAN;
            }
            // The product has zero mean over a box: (x-xc)(y-yc)/(dx dy) as printed.
            if D == 2 {
                psi[5] = s[0] * s[1];
            }
        }
        psi
    }
}

/// Whether psi_1's coefficient is prescribed by the element integral (eq 5) or fitted with the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Conservation {
    Fitted,
    Fixed,
}

impl fmt::Display for Conservation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Conservation::Fitted => "fitted",
            Conservation::Fixed => "fixed",
        })
    }
}

impl Conservation {
    /// How many leading basis functions are not fitted: psi_1 when it is prescribed.
    fn prescribed(self) -> usize {
        match self {
            Conservation::Fitted => 0,
            Conservation::Fixed => 1,
        }
    }
}

/// One element's least-squares system: factorised once per set of points, solved for many fields.
/// Reusable: `factor` must not allocate once the buffers have grown.
#[derive(Default)]
pub struct TaylorFit<const D: usize> {
    /// psi_1..psi_n at each point, at the requested degree (the basis of a lower degree is a
    /// prefix of it).
    psi: Vec<[f64; MAX_TAYLOR_TERMS]>,
    /// The functions fitted are psi_{prescribed+1}..psi_terms.
    prescribed: usize,
    terms: usize,
    degree: usize,
    /// Orthogonal polynomials of the fitted functions' normal matrix, truncated to `degree`.
    basis: OrthogonalBasis,
}

impl<const D: usize> TaylorFit<D> {
    /// Factorises for `points` at the highest degree <= `degree` they support and returns the
    /// degree used. Never fails: a rank-deficient system drops whole degrees (2 -> 1 -> 0) in the
    /// documented way; degree 0 always works (Fixed: a_1 = mean; Fitted: the average of the values).
    /// Requires at least one point. Degrees above 2 are fitted as 2, the highest the basis has.
    pub fn factor(
        &mut self,
        cell: &TaylorCell<D>,
        degree: usize,
        conservation: Conservation,
        points: &[SVector<f64, D>],
    ) -> usize {
        assert!(!points.is_empty(), "a Taylor fit needs at least one point");
        let prescribed = conservation.prescribed();
        // More unknowns than points never have full rank, but rounding in the moments can
        // hide that when the points are nearly dependent (a deformed 2 x 2 lattice in 2D
        // passed the rank test with five quadratic unknowns), so count first.
        let mut requested = degree.min(2);
        while requested > 0 && taylor_terms(D, requested) - prescribed > points.len() {
            requested -= 1;
        }
        let terms = taylor_terms(D, requested);
        self.psi.clear();
        self.psi
            .extend(points.iter().map(|x| cell.basis(requested, x)));
        // The number of fitted functions as a constant lets the loops over them unroll.
        let (psi, basis) = (&self.psi, &mut self.basis);
        match terms - prescribed {
            0 => normal_basis::<0>(psi, prescribed, basis),
            1 => normal_basis::<1>(psi, prescribed, basis),
            2 => normal_basis::<2>(psi, prescribed, basis),
            3 => normal_basis::<3>(psi, prescribed, basis),
            4 => normal_basis::<4>(psi, prescribed, basis),
            5 => normal_basis::<5>(psi, prescribed, basis),
            MAX_TERMS => normal_basis::<MAX_TERMS>(psi, prescribed, basis),
            f => unreachable!("no Taylor fit has {f} fitted functions"),
        }
        // The first unsupported function caps the degree below its own; the polynomials before
        // it do not depend on the ones after it, so the factorisation truncates.
        let supported = (0..terms - prescribed)
            .find(|&i| !self.basis.kept[i])
            .map_or(requested, |i| {
                term_degree(D, i + prescribed).saturating_sub(1)
            });
        self.degree = supported;
        self.prescribed = prescribed;
        self.terms = taylor_terms(D, supported);
        self.basis.terms = self.terms - prescribed;
        supported
    }

    /// Coefficients a_1..a_n for `values` (one per point, order as given to `factor`). With
    /// `Conservation::Fixed`, a_1 = `mean` (= c / |Omega_e|) and the rest are the least-squares fit of
    /// values - mean; with `Fitted`, `mean` is ignored. Entries beyond n are zero. The values may
    /// be the components of a vector or tensor, fitted together entry by entry.
    pub fn solve<T: Fitted>(&self, values: &[T], mean: T) -> [T; MAX_TAYLOR_TERMS] {
        assert_eq!(
            values.len(),
            self.psi.len(),
            "one value per point of the factorisation"
        );
        // The number of fitted functions as a constant lets the per-point loops unroll.
        match self.terms - self.prescribed {
            0 => self.solve_with::<T, 0>(values, mean),
            1 => self.solve_with::<T, 1>(values, mean),
            2 => self.solve_with::<T, 2>(values, mean),
            3 => self.solve_with::<T, 3>(values, mean),
            4 => self.solve_with::<T, 4>(values, mean),
            5 => self.solve_with::<T, 5>(values, mean),
            MAX_TERMS => self.solve_with::<T, MAX_TERMS>(values, mean),
            f => unreachable!("no Taylor fit has {f} fitted functions"),
        }
    }

    /// `solve` with `F` fitted functions.
    fn solve_with<T: Fitted, const F: usize>(
        &self,
        values: &[T],
        mean: T,
    ) -> [T; MAX_TAYLOR_TERMS] {
        let zero = T::splat(0.0);
        let first = self.prescribed;
        let shift = if first == 1 { mean } else { zero };
        // A solve, then one refinement with its residual (module notes): the correction
        // converges because kappa^2 eps <= 1e-6 wherever the rank test passed.
        let mut c = [zero; MAX_TERMS];
        for _ in 0..2 {
            // <psi_j, u - shift - sum_k c_k psi_k> over the data, point by point in order.
            let mut rhs = [zero; MAX_TERMS];
            for (psi, &u) in self.psi.iter().zip(values) {
                let psi = &psi[first..][..F];
                // From -0.0, as `Sum` for f64 starts.
                let fit = (0..F).fold(T::splat(-0.0), |sum, k| sum + c[k] * psi[k]);
                let r = u - shift - fit;
                for j in 0..F {
                    rhs[j] += r * psi[j];
                }
            }
            let correction = self.basis.solve::<T, F>(&rhs);
            for j in 0..F {
                c[j] += correction[j];
            }
        }
        let mut a = [zero; MAX_TAYLOR_TERMS];
        if first == 1 {
            a[0] = mean;
        }
        a[first..self.terms].copy_from_slice(&c[..F]);
        a
    }

    /// The degree `factor` settled on.
    pub fn degree(&self) -> usize {
        self.degree
    }
}

/// Into `basis`, the orthogonal polynomials of the normal matrix sum_p psi psi^T of the `N`
/// functions from `first` on, summed point by point in order.
fn normal_basis<const N: usize>(
    psi: &[[f64; MAX_TAYLOR_TERMS]],
    first: usize,
    basis: &mut OrthogonalBasis,
) {
    // N x N, not the largest size: zeroing that much is a memset call per fit.
    let mut normal = [[0.0; N]; N];
    let normal = normal.as_flattened_mut();
    for psi in psi {
        add_weighted_outer(normal, N, 1.0, &psi[first..][..N]);
    }
    // Sized N and widened: built in the stored basis, or returned as one, it was copied
    // whole with a memcpy call per fit.
    Orthogonal::<N>::from_rows(normal, N, N).copy_into(basis);
}

#[cfg(test)]
mod tests;
