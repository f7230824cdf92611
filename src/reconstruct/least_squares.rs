//! Local least-squares reconstruction of particle data at a lattice of evaluation points
//! (Gong sec 3.5, Tran eqs 1-17): u^h(x_e) = sum_p phi_p(x_e) u_p with
//! phi_p(x_e) = w(x_e - x_p) q((x_p - x_e)/h) . c_e. The fit (moments, solve, shape
//! functions) is done once per particle configuration and applied to any number of fields.

use std::fmt;
use std::ops::{AddAssign, Mul};

use nalgebra::SVector;
use num_traits::Zero;

use super::basis::{monomials, Degree, MAX_TERMS};
use super::kernel::Kernel;
use super::lattice::Lattice;
use super::solve::{add_weighted_outer, mls_coefficients, Moments, OrthogonalBasis};

/// How the local system is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Invert the moment matrix (Gong); a singular matrix stops the run.
    Mls,
    /// Orthogonal basis, no inversion; unsupported polynomials are dropped (Tran).
    Imls,
}

impl fmt::Display for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Solver::Mls => "mls",
            Solver::Imls => "imls",
        })
    }
}

/// Everything that defines a reconstruction except where it is evaluated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Recipe {
    pub kernel: Kernel,
    pub degree: Degree,
    pub solver: Solver,
}

/// Counters of one fit: evaluation points with data in reach, and how many of those lost
/// rank (IMLS dropped a polynomial).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FitStats {
    pub fits: usize,
    pub rank_deficient: usize,
}

impl AddAssign for FitStats {
    fn add_assign(&mut self, other: FitStats) {
        self.fits += other.fits;
        self.rank_deficient += other.rank_deficient;
    }
}

impl fmt::Display for Recipe {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}[{}, degree {}]",
            self.solver,
            self.kernel,
            self.degree.value()
        )
    }
}

/// The MLS moment matrix at an evaluation point is singular.
#[derive(Clone, Debug, PartialEq)]
pub struct SingularMoments {
    pub point: usize,
    pub position: Vec<f64>,
}

impl fmt::Display for SingularMoments {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "MLS moment matrix is singular at evaluation point {} (x = {:?}): too few \
             particles in its support for the basis",
            self.point, self.position
        )
    }
}

/// Largest number of lattice points one particle reaches along an axis.
const MAX_PER_AXIS: usize = 32;

/// The widest support radius, in cells, that `Reconstructor::new` accepts on a lattice of
/// grid nodes: an open interval of 2 r cells meets at most 2 r + 1 nodes per axis.
pub const MAX_NODE_SUPPORT_CELLS: f64 = ((MAX_PER_AXIS - 2) / 2) as f64;

pub struct Reconstructor<const D: usize> {
    recipe: Recipe,
    lattice: Lattice<D>,
    terms: usize,
    radius: f64,
    /// Entries per particle: the reachable lattice points, padded with zero weights.
    stride: usize,
    point: Vec<u32>,
    /// (x_p - x_e)/h of each entry.
    offset: Vec<SVector<f64, D>>,
    /// The weight w(x_e - x_p) after pass one, the shape function phi_p(x_e) after the fit.
    phi: Vec<f64>,
    /// Per evaluation point, the row-major terms x terms moment matrix, then c_e.
    moments: Vec<f64>,
    coeffs: Vec<f64>,
    covered: Vec<bool>,
}

impl<const D: usize> Reconstructor<D> {
    pub fn new(recipe: Recipe, lattice: Lattice<D>) -> Self {
        let radius = recipe.kernel.radius_cells();
        let per_axis = lattice.max_per_axis(radius);
        assert!(
            per_axis <= MAX_PER_AXIS,
            "kernel support {radius} cells reaches {per_axis} points per axis"
        );
        let terms = recipe.degree.terms(D);
        let points = lattice.len();
        Reconstructor {
            recipe,
            terms,
            radius,
            stride: per_axis.pow(D as u32),
            point: Vec::new(),
            offset: Vec::new(),
            phi: Vec::new(),
            moments: vec![0.0; points * terms * terms],
            coeffs: vec![0.0; points * terms],
            covered: vec![false; points],
            lattice,
        }
    }

    pub fn lattice(&self) -> &Lattice<D> {
        &self.lattice
    }

    pub fn recipe(&self) -> &Recipe {
        &self.recipe
    }

    /// Whether any particle reached evaluation point `e` in the last fit.
    pub fn covered(&self, e: usize) -> bool {
        self.covered[e]
    }

    /// Builds the shape functions for particles at `x`. Points no particle reaches get
    /// zero shape functions and are not counted.
    pub fn fit(&mut self, x: &[SVector<f64, D>]) -> Result<FitStats, SingularMoments> {
        self.gather_weights(x);
        let stats = self.solve()?;
        self.finish_shape_functions();
        Ok(stats)
    }

    /// Pass one: the lattice points each particle reaches, their weights and offsets, and
    /// the moment matrices, summed particle by particle in order.
    fn gather_weights(&mut self, x: &[SVector<f64, D>]) {
        let n = x.len() * self.stride;
        self.point.resize(n, 0);
        self.offset.resize(n, SVector::zeros());
        self.phi.resize(n, 0.0);
        self.moments.fill(0.0);
        let mut near = [[(0usize, 0.0f64); MAX_PER_AXIS]; D];
        // The weight is a tensor product: its 1D factors are computed once per axis.
        let mut axis_weight = [[0.0f64; MAX_PER_AXIS]; D];
        let mut count = [0usize; D];
        let inv_scale = 1.0 / self.recipe.kernel.scale;
        let weight = self.recipe.kernel.weight;
        let mut q = [0.0; MAX_TERMS];
        let t = self.terms;
        for (p, xp) in x.iter().enumerate() {
            for k in 0..D {
                count[k] = self
                    .lattice
                    .near_on_axis(k, xp[k], self.radius, &mut near[k]);
                for j in 0..count[k] {
                    axis_weight[k][j] = weight.eval(near[k][j].1.abs() * inv_scale);
                }
            }
            let base = p * self.stride;
            let total: usize = count.iter().product();
            for slot in 0..self.stride {
                let entry = base + slot;
                if slot >= total {
                    self.point[entry] = 0;
                    self.phi[entry] = 0.0;
                    continue;
                }
                let mut rest = slot;
                let mut e = 0;
                let mut w = 1.0;
                let mut d = SVector::<f64, D>::zeros();
                for k in 0..D {
                    let j = rest % count[k];
                    rest /= count[k];
                    let (i, dk) = near[k][j];
                    e += i * self.lattice.stride(k);
                    d[k] = -dk;
                    w *= axis_weight[k][j];
                }
                self.point[entry] = e as u32;
                self.offset[entry] = d;
                self.phi[entry] = w;
                monomials(self.recipe.degree, &d, &mut q);
                add_weighted_outer(&mut self.moments[e * t * t..(e + 1) * t * t], t, w, &q[..t]);
            }
        }
    }

    /// The coefficients c_e at every evaluation point.
    fn solve(&mut self) -> Result<FitStats, SingularMoments> {
        let t = self.terms;
        let mut stats = FitStats::default();
        for e in 0..self.lattice.len() {
            let a = &self.moments[e * t * t..(e + 1) * t * t];
            let c = &mut self.coeffs[e * t..(e + 1) * t];
            self.covered[e] = a[0] > 0.0;
            if !self.covered[e] {
                c.fill(0.0);
                continue;
            }
            let mut full: Moments = [0.0; MAX_TERMS * MAX_TERMS];
            for r in 0..t {
                full[r * MAX_TERMS..r * MAX_TERMS + t].copy_from_slice(&a[r * t..(r + 1) * t]);
            }
            stats.fits += 1;
            let solved = match self.recipe.solver {
                Solver::Mls => mls_coefficients(&full, t).ok_or_else(|| SingularMoments {
                    point: e,
                    position: self.lattice.point(e).iter().copied().collect(),
                })?,
                Solver::Imls => {
                    let basis = OrthogonalBasis::from_moments(&full, t);
                    if basis.rank() < t {
                        stats.rank_deficient += 1;
                    }
                    basis.shape_coefficients()
                }
            };
            c.copy_from_slice(&solved[..t]);
        }
        Ok(stats)
    }

    /// Pass two: phi_p(x_e) = w q((x_p - x_e)/h) . c_e for every entry.
    fn finish_shape_functions(&mut self) {
        let t = self.terms;
        let mut q = [0.0; MAX_TERMS];
        for entry in 0..self.phi.len() {
            let w = self.phi[entry];
            if w == 0.0 {
                continue;
            }
            let e = self.point[entry] as usize;
            monomials(self.recipe.degree, &self.offset[entry], &mut q);
            let c = &self.coeffs[e * t..(e + 1) * t];
            self.phi[entry] = w * (0..t).map(|j| q[j] * c[j]).sum::<f64>();
        }
    }

    /// u^h at every evaluation point from particle values `values` (same order as the fit).
    pub fn apply<T>(&self, values: &[T], out: &mut [T])
    where
        T: Copy + Zero + AddAssign + Mul<f64, Output = T>,
    {
        out.fill(T::zero());
        for (p, &value) in values.iter().enumerate() {
            let base = p * self.stride;
            for entry in base..base + self.stride {
                let phi = self.phi[entry];
                if phi != 0.0 {
                    out[self.point[entry] as usize] += value * phi;
                }
            }
        }
    }
}
