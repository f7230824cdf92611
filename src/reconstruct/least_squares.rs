//! Local least-squares reconstruction of particle data at a lattice of evaluation points
//! (Gong sec 3.5, Tran eqs 1-17): u^h(x_e) = sum_p phi_p(x_e) u_p with
//! phi_p(x_e) = w(x_e - x_p) q((x_p - x_e)/h) . c_e. Two ways to apply it:
//! * `fit` then `apply`: the fit (weights, moments, solve) is done once per particle
//!   configuration and applied to any number of fields, each application forming the shape
//!   functions from the stored entries as it goes. For wide data (the quadrature fields).
//! * `fit_apply`, for a velocity fit applied once: u^h(x_e) = c_e . b_e with the weighted
//!   moments of the data b_e = sum_p w q u_p summed in the same pass as the moment matrix,
//!   so one pass over the entries fits and applies, and nothing per entry is stored. The same
//!   operator as `apply`, its sums in another order: it differs from `apply` by round-off.
//!   Per entry it costs T D multiply-adds where `apply` costs T + D and a second pass, which
//!   pays for velocities and not for the quadrature fields' 1 + D^2 + D components.
//!
//! `VelocityFit` picks between them for the nodal velocity of a run.

use std::fmt;
use std::ops::{AddAssign, Mul};

use nalgebra::SVector;
use num_traits::Zero;

use super::basis::{degree_of, monomials, Degree, MAX_TERMS};
use super::kernel::Kernel;
use super::lattice::Lattice;
use super::solve::{mls_coefficients, Moments, Orthogonal};
use crate::grid::Grid;

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
    /// The most lattice points one particle reaches along an axis.
    slots: usize,
    /// Per particle of the last `fit`, the lattice points it reaches along each axis
    /// (`tabulate`); its entries are their tensor product, from which `apply` forms
    /// phi_p(x_e). Storing the axes, not the entries, keeps a particle's record to D of
    /// them, from which each entry is one product of weights again.
    reach: Vec<[usize; D]>,
    /// Per particle, `D * slots` of each: the lattice index part, (x_p - x_e)/h along the
    /// axis and the 1D weight factor, axis k's from slot `k * slots`.
    axis_index: Vec<usize>,
    axis_offset: Vec<f64>,
    axis_factor: Vec<f64>,
    /// Per evaluation point, its moment matrix packed as `packed_len` describes, then its c_e.
    moments: Vec<f64>,
    /// Per evaluation point, the moments b_e = sum_p w q u_p of the velocities of the last
    /// `fit_apply`, `terms` per point.
    velocity_moments: Vec<SVector<f64, D>>,
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
            slots: per_axis,
            reach: Vec::new(),
            axis_index: Vec::new(),
            axis_offset: Vec::new(),
            axis_factor: Vec::new(),
            moments: vec![0.0; points * packed_len(terms)],
            velocity_moments: Vec::new(),
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
        // The basis size (and the packed moment matrix's, `P`) as constants lets the
        // per-entry loops over terms unroll and a point's matrix be indexed as one array.
        match self.terms {
            1 => self.fit_with::<1, 1>(x),
            2 => self.fit_with::<2, { packed_len(2) }>(x),
            3 => self.fit_with::<3, { packed_len(3) }>(x),
            MAX_TERMS => self.fit_with::<MAX_TERMS, { packed_len(MAX_TERMS) }>(x),
            t => unreachable!("no basis has {t} terms"),
        }
    }

    /// Fits at `x` and writes u^h of the velocities `v` to `out` in one pass (module doc).
    pub fn fit_apply(
        &mut self,
        x: &[SVector<f64, D>],
        v: &[SVector<f64, D>],
        out: &mut [SVector<f64, D>],
    ) -> Result<FitStats, SingularMoments> {
        // The entries of an earlier `fit` do not belong to this one.
        self.reach.clear();
        match self.terms {
            1 => self.fit_apply_with::<1, 1>(x, v, out),
            2 => self.fit_apply_with::<2, { packed_len(2) }>(x, v, out),
            3 => self.fit_apply_with::<3, { packed_len(3) }>(x, v, out),
            MAX_TERMS => self.fit_apply_with::<MAX_TERMS, { packed_len(MAX_TERMS) }>(x, v, out),
            t => unreachable!("no basis has {t} terms"),
        }
    }

    fn fit_apply_with<const T: usize, const P: usize>(
        &mut self,
        x: &[SVector<f64, D>],
        v: &[SVector<f64, D>],
        out: &mut [SVector<f64, D>],
    ) -> Result<FitStats, SingularMoments> {
        self.moments.fill(0.0);
        self.velocity_moments.clear();
        self.velocity_moments
            .resize(self.lattice.len() * T, SVector::zeros());
        let a = self.moments.as_chunks_mut::<P>().0;
        let b_of = self.velocity_moments.as_chunks_mut::<T>().0;
        let degree = degree_of::<T, D>();
        let mut q = [0.0; MAX_TERMS];
        let mut index = [[0usize; MAX_PER_AXIS]; D];
        let mut offset = [[0.0f64; MAX_PER_AXIS]; D];
        let mut factor = [[0.0f64; MAX_PER_AXIS]; D];
        for (xp, &vp) in x.iter().zip(v) {
            let tables = AxisTables {
                slots: MAX_PER_AXIS,
                reach: tabulate(
                    &self.lattice,
                    self.radius,
                    &self.recipe.kernel,
                    xp,
                    MAX_PER_AXIS,
                    index.as_flattened_mut(),
                    offset.as_flattened_mut(),
                    factor.as_flattened_mut(),
                ),
                index: index.as_flattened(),
                offset: offset.as_flattened(),
                factor: factor.as_flattened(),
            };
            tables.for_each_entry(|e, w, d| {
                monomials(degree, d, &mut q);
                add_moments::<T, P>(&mut a[e], w, &q);
                add_velocity_moments::<T, D>(&mut b_of[e], w, &q, vp);
            });
        }
        let stats = self.solve::<T, P>()?;
        // u^h(x_e) = c_e . b_e, zero where no particle reaches.
        let b_of = self.velocity_moments.as_chunks::<T>().0;
        let coeffs = self.coeffs.as_chunks::<T>().0;
        for (e, ((u, b), c)) in out.iter_mut().zip(b_of).zip(coeffs).enumerate() {
            *u = SVector::zeros();
            if self.covered[e] {
                for k in 0..T {
                    *u += b[k] * c[k];
                }
            }
        }
        Ok(stats)
    }

    fn fit_with<const T: usize, const P: usize>(
        &mut self,
        x: &[SVector<f64, D>],
    ) -> Result<FitStats, SingularMoments> {
        debug_assert_eq!(degree_of::<T, D>(), self.recipe.degree);
        debug_assert_eq!(P, packed_len(T));
        self.gather_weights::<T, P>(x);
        self.solve::<T, P>()
    }

    /// Pass one: the lattice points each particle reaches, axis by axis, and the moment
    /// matrices, summed particle by particle in order.
    fn gather_weights<const T: usize, const P: usize>(&mut self, x: &[SVector<f64, D>]) {
        let record = D * self.slots;
        self.reach.resize(x.len(), [0; D]);
        self.axis_index.resize(x.len() * record, 0);
        self.axis_offset.resize(x.len() * record, 0.0);
        self.axis_factor.resize(x.len() * record, 0.0);
        self.moments.fill(0.0);
        let a = self.moments.as_chunks_mut::<P>().0;
        let degree = degree_of::<T, D>();
        let mut q = [0.0; MAX_TERMS];
        let records = self
            .reach
            .iter_mut()
            .zip(self.axis_index.chunks_exact_mut(record))
            .zip(self.axis_offset.chunks_exact_mut(record))
            .zip(self.axis_factor.chunks_exact_mut(record));
        for (xp, (((reach, index), offset), factor)) in x.iter().zip(records) {
            *reach = tabulate(
                &self.lattice,
                self.radius,
                &self.recipe.kernel,
                xp,
                self.slots,
                index,
                offset,
                factor,
            );
            let tables = AxisTables {
                slots: self.slots,
                reach: *reach,
                index,
                offset,
                factor,
            };
            tables.for_each_entry(|e, w, d| {
                monomials(degree, d, &mut q);
                add_moments::<T, P>(&mut a[e], w, &q);
            });
        }
    }

    /// The particles' tables of the last `fit`, in order.
    fn tables(&self) -> impl Iterator<Item = AxisTables<'_, D>> {
        let record = D * self.slots;
        let records = self
            .reach
            .iter()
            .zip(self.axis_index.chunks_exact(record))
            .zip(self.axis_offset.chunks_exact(record))
            .zip(self.axis_factor.chunks_exact(record));
        records.map(|(((&reach, index), offset), factor)| AxisTables {
            slots: self.slots,
            reach,
            index,
            offset,
            factor,
        })
    }

    /// The coefficients c_e at every evaluation point.
    fn solve<const T: usize, const P: usize>(&mut self) -> Result<FitStats, SingularMoments> {
        let mut stats = FitStats::default();
        let packed = self.moments.as_chunks::<P>().0;
        for (e, packed) in packed.iter().enumerate() {
            let a = unpack::<T, P>(packed);
            let a = &a[..];
            let c = &mut self.coeffs[e * T..][..T];
            self.covered[e] = a[0] > 0.0;
            if !self.covered[e] {
                c.fill(0.0);
                continue;
            }
            stats.fits += 1;
            match self.recipe.solver {
                Solver::Mls => {
                    let solved =
                        mls_coefficients::<T>(a, MAX_TERMS, T).ok_or_else(|| SingularMoments {
                            point: e,
                            position: self.lattice.point(e).iter().copied().collect(),
                        })?;
                    c.copy_from_slice(&solved[..T]);
                }
                Solver::Imls => {
                    let basis = Orthogonal::<T>::from_rows(a, MAX_TERMS, T);
                    if basis.rank() < T {
                        stats.rank_deficient += 1;
                    }
                    c.copy_from_slice(&basis.shape_coefficients::<T>());
                }
            }
        }
        Ok(stats)
    }

    /// u^h at every evaluation point from particle values `values` (same order as the fit),
    /// with each entry's shape function phi_p(x_e) = w q((x_p - x_e)/h) . c_e taken as it is
    /// used: a fit applied once (the leapfrog steps) does not store and reread it.
    pub fn apply<V>(&self, values: &[V], out: &mut [V])
    where
        V: Copy + Zero + AddAssign + Mul<f64, Output = V>,
    {
        match self.terms {
            1 => self.apply_with::<1, V>(values, out),
            2 => self.apply_with::<2, V>(values, out),
            3 => self.apply_with::<3, V>(values, out),
            MAX_TERMS => self.apply_with::<MAX_TERMS, V>(values, out),
            t => unreachable!("no basis has {t} terms"),
        }
    }

    fn apply_with<const T: usize, V>(&self, values: &[V], out: &mut [V])
    where
        V: Copy + Zero + AddAssign + Mul<f64, Output = V>,
    {
        out.fill(V::zero());
        assert!(
            values.len() <= self.reach.len(),
            "more values than particles in the last `fit`"
        );
        let degree = degree_of::<T, D>();
        let coeffs = self.coeffs.as_chunks::<T>().0;
        let mut q = [0.0; MAX_TERMS];
        for (&value, tables) in values.iter().zip(self.tables()) {
            tables.for_each_entry(|e, w, d| {
                if w == 0.0 {
                    return;
                }
                monomials(degree, d, &mut q);
                let c = &coeffs[e];
                let phi = w * q[..T].iter().zip(c).map(|(q, c)| q * c).sum::<f64>();
                if phi != 0.0 {
                    out[e] += value * phi;
                }
            });
        }
    }
}

/// Tabulates, axis by axis, the lattice points within `radius` cells of `xp`: axis k's
/// n-th in slot `k * slots + n` of `index` (its part of the lattice index), `offset`
/// ((x_p - x_e)/h along the axis) and `factor` (the 1D weight). Returns their count per
/// axis.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn tabulate<const D: usize>(
    lattice: &Lattice<D>,
    radius: f64,
    kernel: &Kernel,
    xp: &SVector<f64, D>,
    slots: usize,
    index: &mut [usize],
    offset: &mut [f64],
    factor: &mut [f64],
) -> [usize; D] {
    let inv_scale = 1.0 / kernel.scale;
    let weight = kernel.weight;
    let mut reach = [0; D];
    for k in 0..D {
        let stride = lattice.stride(k);
        let index = &mut index[k * slots..][..slots];
        let offset = &mut offset[k * slots..][..slots];
        let factor = &mut factor[k * slots..][..slots];
        reach[k] = lattice.near_on_axis(k, xp[k], radius, |j, i, dk| {
            index[j] = i * stride;
            offset[j] = -dk;
            factor[j] = weight.eval(dk.abs() * inv_scale);
        });
    }
    reach
}

/// One particle's lattice points along each axis, as `tabulate` leaves them; its entries
/// are their tensor product.
struct AxisTables<'a, const D: usize> {
    slots: usize,
    reach: [usize; D],
    index: &'a [usize],
    offset: &'a [f64],
    factor: &'a [f64],
}

impl<const D: usize> AxisTables<'_, D> {
    /// Calls `visit(e, w, d)` for every entry, the first axis fastest, with the lattice
    /// point e, the weight w(x_e - x_p) = w_0 w_1 in axis order and the offset
    /// d = (x_p - x_e)/h.
    #[inline(always)]
    fn for_each_entry(&self, mut visit: impl FnMut(usize, f64, &SVector<f64, D>)) {
        const { assert!(D == 1 || D == 2, "the fits' bases are 1D and 2D") };
        let axis = |k: usize| {
            let (at, n) = (k * self.slots, self.reach[k]);
            let tables = (&self.index[at..][..n], &self.offset[at..][..n]);
            tables.0.iter().zip(tables.1).zip(&self.factor[at..][..n])
        };
        let mut d = SVector::<f64, D>::zeros();
        // A row along the first axis, its index part and the second axis's weight factor
        // (none in 1D) taken once.
        let mut row = |row_index: usize, factor_1: Option<f64>, d: &mut SVector<f64, D>| {
            for ((&i, &d_0), &w_0) in axis(0) {
                let w = factor_1.map_or(w_0, |w_1| w_0 * w_1);
                d[0] = d_0;
                visit(i + row_index, w, d);
            }
        };
        if D == 1 {
            row(0, None, &mut d);
        } else {
            for ((&row_index, &d_1), &w_1) in axis(1) {
                d[1] = d_1;
                row(row_index, Some(w_1), &mut d);
            }
        }
    }
}

/// The least-squares fit of the particle velocities at the grid nodes, refitted every step.
/// A run that rebuilds the nodal velocity from the moved particles (MUSL) applies the step's
/// fit twice and keeps its entries (`fit`, `apply`); otherwise it is fitted and applied in one
/// pass (`fit_apply`), which is cheaper for one application and differs from the other by
/// round-off.
pub struct VelocityFit<const D: usize> {
    fit: Reconstructor<D>,
    remaps: bool,
}

impl<const D: usize> VelocityFit<D> {
    pub fn new(recipe: Recipe, grid: &Grid<D>, remaps: bool) -> Self {
        VelocityFit {
            fit: Reconstructor::new(recipe, Lattice::nodes(grid)),
            remaps,
        }
    }

    /// The nodal velocity `out` from the particles at `x` with velocities `v`.
    pub fn map(
        &mut self,
        x: &[SVector<f64, D>],
        v: &[SVector<f64, D>],
        out: &mut [SVector<f64, D>],
    ) -> Result<FitStats, SingularMoments> {
        if !self.remaps {
            return self.fit.fit_apply(x, v, out);
        }
        let stats = self.fit.fit(x)?;
        self.fit.apply(v, out);
        Ok(stats)
    }

    /// The last mapping's fit applied to the velocities `v` now.
    pub fn remap(&self, v: &[SVector<f64, D>], out: &mut [SVector<f64, D>]) {
        assert!(
            self.remaps,
            "a velocity fit built without remapping remapped"
        );
        self.fit.apply(v, out);
    }
}

/// A moment matrix A = sum w q q^T packed for summing: row 0, then rows 1.. without their
/// first entry, row-major. The monomials start with q_0 = 1, so entry (r, 0) would receive
/// (w q_r) 1 = w q_r, the bits that (0, r) receives as (w 1) q_r: column 0 below row 0 is
/// row 0's copy, and leaving it out keeps each datum's sums to the entries that differ.
const fn packed_len(terms: usize) -> usize {
    terms + (terms - 1) * (terms - 1)
}

/// a += w q q^T, packed.
#[inline(always)]
fn add_moments<const T: usize, const P: usize>(a: &mut [f64; P], w: f64, q: &[f64; MAX_TERMS]) {
    debug_assert_eq!(q[0], 1.0);
    let wq: [f64; T] = std::array::from_fn(|r| w * q[r]);
    for s in 0..T {
        a[s] += wq[0] * q[s];
    }
    for r in 1..T {
        for s in 1..T {
            a[T + (r - 1) * (T - 1) + s - 1] += wq[r] * q[s];
        }
    }
}

/// b += u (w q), term by term; an entry of zero weight adds nothing, whatever u holds.
#[inline(always)]
fn add_velocity_moments<const T: usize, const D: usize>(
    b: &mut [SVector<f64, D>; T],
    w: f64,
    q: &[f64; MAX_TERMS],
    u: SVector<f64, D>,
) {
    if w == 0.0 {
        return;
    }
    for k in 0..T {
        b[k] += u * (w * q[k]);
    }
}

/// The row-major matrix of packed moments, row length `MAX_TERMS`.
#[inline(always)]
fn unpack<const T: usize, const P: usize>(packed: &[f64; P]) -> Moments {
    let mut a = [0.0; MAX_TERMS * MAX_TERMS];
    a[..T].copy_from_slice(&packed[..T]);
    for r in 1..T {
        a[r * MAX_TERMS] = packed[r];
        let row = &packed[T + (r - 1) * (T - 1)..][..T - 1];
        a[r * MAX_TERMS + 1..][..T - 1].copy_from_slice(row);
    }
    a
}
