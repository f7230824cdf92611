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
use std::ops::AddAssign;

use nalgebra::SVector;

use super::basis::{degree_of, monomials, Degree, MAX_TERMS};
use super::kernel::{Kernel, Weight};
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
    reach: Vec<Reach<D>>,
    /// Per particle, `D * slots` of each: (x_p - x_e)/h along the axis and the 1D weight
    /// factor of the points in reach, axis k's from slot `k * slots`.
    axis_offset: Vec<f64>,
    axis_factor: Vec<f64>,
    /// Room for a fit's sums, per pair of evaluation points (`Pairing`): each of its
    /// components for both points side by side. They are the moment matrix, packed as
    /// `packed_len` describes, and in `fit_apply` the moments b_e = sum_p w q u_p of the
    /// velocities, term k's component l at `packed_len + 2 k + l` (`sum_components`). A row
    /// of a particle's entries reaches consecutive points, so two of its entries add to a
    /// pair's sums at once. Zero between fits (`ZeroSums`).
    pair_sums: ZeroSums,
    /// How the next fit pairs the points: the pairing under which most rows of the last
    /// one began a pair.
    pairing: Pairing,
    /// How the last fit paired the points: its sums, its coefficients and the sums of its
    /// applications.
    fit_pairing: Pairing,
    /// Which particles the next fit takes two at a time: the pairing under which most pairs
    /// of the last one reached the same points.
    particle_pairing: ParticlePairing,
    /// Which particles the last fit took two at a time; its applications take the same.
    fit_particle_pairing: ParticlePairing,
    /// The coefficients c_e of the last fit, per pair of points as the sums are: term k's
    /// of both points at `T * pair + k`.
    coeffs: Vec<[f64; 2]>,
    /// Room for `apply`'s sums, per pair of points as the fit's: component c's of both
    /// points at `N * pair + c`, for values of N components. Zero between applications.
    applied: ZeroSums,
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
            axis_offset: Vec::new(),
            axis_factor: Vec::new(),
            pair_sums: ZeroSums::default(),
            pairing: Pairing::default(),
            fit_pairing: Pairing::default(),
            particle_pairing: ParticlePairing::default(),
            fit_particle_pairing: ParticlePairing::default(),
            coeffs: vec![[0.0; 2]; pair_count(points) * terms],
            applied: ZeroSums::default(),
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

    /// The phase of the next fit's pairing of the points (`Pairing`).
    #[cfg(test)]
    pub(super) fn pairing_phase(&self) -> usize {
        self.pairing.phase
    }

    /// The phase of the next fit's pairing of the particles (`ParticlePairing`).
    #[cfg(test)]
    pub(super) fn particle_pairing_phase(&self) -> usize {
        self.particle_pairing.phase
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
            1 => self.fit_apply_with::<1, 1, { sum_components(1) }>(x, v, out),
            2 => self.fit_apply_with::<2, { packed_len(2) }, { sum_components(2) }>(x, v, out),
            3 => self.fit_apply_with::<3, { packed_len(3) }, { sum_components(3) }>(x, v, out),
            MAX_TERMS => self.fit_apply_with::<
                MAX_TERMS,
                { packed_len(MAX_TERMS) },
                { sum_components(MAX_TERMS) },
            >(x, v, out),
            t => unreachable!("no basis has {t} terms"),
        }
    }

    fn fit_apply_with<const T: usize, const P: usize, const S: usize>(
        &mut self,
        x: &[SVector<f64, D>],
        v: &[SVector<f64, D>],
        out: &mut [SVector<f64, D>],
    ) -> Result<FitStats, SingularMoments> {
        const { assert!(D <= 2 && S == sum_components(T) && P == packed_len(T)) };
        let pairing = self.pairing;
        let points = self.lattice.len();
        let mut pairs = PairSums::<S>::zeroed(&mut self.pair_sums, points, pairing);
        let degree = degree_of::<T, D>();
        let search = Search::new(&self.lattice, self.radius, &self.recipe.kernel);
        let mut tables = [PointTables::<D>::new(), PointTables::new()];
        let particles = self.particle_pairing;
        let mut votes = ParticleVotes::default();
        let alone = |pairs: &mut PairSums<'_, S>,
                     votes: &mut ParticleVotes<D>,
                     room: &mut PointTables<D>,
                     xp,
                     vp| {
            let a = room.record().tabulate(&search, xp);
            votes.note(a.reach);
            pairs.add_particle::<T, P, D, true>(&a, degree, vp);
        };
        let ((x_head, x_pairs, x_tail), (v_head, v_pairs, v_tail)) =
            (particles.split(x), particles.split(v));
        for (xp, &vp) in x_head.iter().zip(v_head) {
            alone(&mut pairs, &mut votes, &mut tables[0], xp, vp);
        }
        for (xp, vp) in x_pairs.iter().zip(v_pairs) {
            let [a, b] = &mut tables;
            let (a, b) = (a.record(), b.record());
            let tables = (a.tabulate(&search, &xp[0]), b.tabulate(&search, &xp[1]));
            votes.note(tables.0.reach);
            votes.note(tables.1.reach);
            add_particle_pair::<T, P, S, D, true>(&mut pairs, tables, degree, *vp);
        }
        for (xp, &vp) in x_tail.iter().zip(v_tail) {
            alone(&mut pairs, &mut votes, &mut tables[0], xp, vp);
        }
        self.pairing = pairs.best_pairing();
        self.particle_pairing = votes.best(particles);
        self.fit_particle_pairing = particles;
        let stats = solve_points::<T, P, S, D>(
            &self.recipe,
            &self.lattice,
            pairing,
            self.pair_sums.chunks_mut::<S>(),
            &mut self.coeffs,
            &mut self.covered,
        )?;
        self.fit_pairing = pairing;
        // u^h(x_e) = c_e . b_e, zero where no particle reaches.
        let coeffs = self.coeffs.as_chunks::<T>().0;
        let covered = &self.covered;
        self.pair_sums
            .read_each::<S, _>(points, pairing, out, |e, u, sums, lane| {
                *u = SVector::zeros();
                if covered[e] {
                    let c = &coeffs[pairing.slot(e).0];
                    for k in 0..T {
                        let b_k = SVector::<f64, D>::from_fn(|l, _| sums[P + 2 * k + l][lane]);
                        *u += b_k * c[k][lane];
                    }
                }
            });
        Ok(stats)
    }

    fn fit_with<const T: usize, const P: usize>(
        &mut self,
        x: &[SVector<f64, D>],
    ) -> Result<FitStats, SingularMoments> {
        debug_assert_eq!(degree_of::<T, D>(), self.recipe.degree);
        debug_assert_eq!(P, packed_len(T));
        let pairing = self.gather_weights::<T, P>(x);
        self.fit_pairing = pairing;
        let stats = solve_points::<T, P, P, D>(
            &self.recipe,
            &self.lattice,
            pairing,
            self.pair_sums.chunks_mut::<P>(),
            &mut self.coeffs,
            &mut self.covered,
        )?;
        self.pair_sums.mark_zero();
        Ok(stats)
    }

    /// Pass one: the lattice points each particle reaches, axis by axis, and the moment
    /// matrices, summed particle by particle in order. Returns how the sums' points are
    /// paired.
    fn gather_weights<const T: usize, const P: usize>(&mut self, x: &[SVector<f64, D>]) -> Pairing {
        let record = D * self.slots;
        self.reach.resize(x.len(), Reach::default());
        self.axis_offset.resize(x.len() * record, 0.0);
        self.axis_factor.resize(x.len() * record, 0.0);
        let pairing = self.pairing;
        let mut pairs = PairSums::<P>::zeroed(&mut self.pair_sums, self.lattice.len(), pairing);
        let degree = degree_of::<T, D>();
        let search = Search::new(&self.lattice, self.radius, &self.recipe.kernel);
        let slots = self.slots;
        let mut records = self
            .reach
            .iter_mut()
            .zip(self.axis_offset.chunks_exact_mut(record))
            .zip(self.axis_factor.chunks_exact_mut(record))
            .map(|((reach, offset), factor)| Record {
                slots,
                reach,
                offset,
                factor,
            });
        let particles = self.particle_pairing;
        let mut votes = ParticleVotes::default();
        let alone = |pairs: &mut PairSums<'_, P>, votes: &mut ParticleVotes<D>, record, xp| {
            let a = Record::tabulate(record, &search, xp);
            votes.note(a.reach);
            pairs.add_particle::<T, P, D, false>(&a, degree, SVector::zeros());
        };
        let (x_head, x_pairs, x_tail) = particles.split(x);
        for xp in x_head {
            let record = records.next().expect("a record");
            alone(&mut pairs, &mut votes, record, xp);
        }
        for xp in x_pairs {
            let (a, b) = (records.next(), records.next());
            let (a, b) = (a.expect("a record"), b.expect("a record"));
            let tables = (a.tabulate(&search, &xp[0]), b.tabulate(&search, &xp[1]));
            votes.note(tables.0.reach);
            votes.note(tables.1.reach);
            let u = [SVector::zeros(); 2];
            add_particle_pair::<T, P, P, D, false>(&mut pairs, tables, degree, u);
        }
        for xp in x_tail {
            let record = records.next().expect("a record");
            alone(&mut pairs, &mut votes, record, xp);
        }
        self.pairing = pairs.best_pairing();
        self.particle_pairing = votes.best(particles);
        self.fit_particle_pairing = particles;
        pairing
    }

    /// The particles' tables of the last `fit`, in order.
    fn tables(&self) -> impl Iterator<Item = AxisTables<'_, D>> {
        let record = D * self.slots;
        let records = self
            .reach
            .iter()
            .zip(self.axis_offset.chunks_exact(record))
            .zip(self.axis_factor.chunks_exact(record));
        let row_stride = self.lattice.stride(D - 1);
        records.map(move |((&reach, offset), factor)| AxisTables {
            slots: self.slots,
            reach,
            row_stride,
            offset,
            factor,
        })
    }

    /// u^h at every evaluation point from particle values `values` (same order as the fit),
    /// with each entry's shape function phi_p(x_e) = w q((x_p - x_e)/h) . c_e taken as it is
    /// used: a fit applied once (the leapfrog steps) does not store and reread it.
    pub fn apply<V: Components>(&mut self, values: &[V], out: &mut [V]) {
        match self.terms {
            1 => self.apply_with::<1, V>(values, out),
            2 => self.apply_with::<2, V>(values, out),
            3 => self.apply_with::<3, V>(values, out),
            MAX_TERMS => self.apply_with::<MAX_TERMS, V>(values, out),
            t => unreachable!("no basis has {t} terms"),
        }
    }

    fn apply_with<const T: usize, V: Components>(&mut self, values: &[V], out: &mut [V]) {
        // A last component that copies another in every value has that one's sums to the
        // bit: each point receives the same terms in the same order.
        let last = V::COUNT - 1;
        let copied = V::LAST_MAY_COPY.filter(|&of| {
            values
                .iter()
                .all(|v| v.component(last).to_bits() == v.component(of).to_bits())
        });
        // The count of components summed as a constant, for the per-entry loops over them.
        match (V::COUNT, copied) {
            (1, None) => self.apply_components::<T, 1, V>(values, out, None),
            (2, None) => self.apply_components::<T, 2, V>(values, out, None),
            (3, None) => self.apply_components::<T, 3, V>(values, out, None),
            (7, None) => self.apply_components::<T, 7, V>(values, out, None),
            (7, copied) => self.apply_components::<T, 6, V>(values, out, copied),
            (n, _) => unreachable!("no value has {n} components"),
        }
    }

    /// `apply` summing the first `N` components of the values; a last component beyond
    /// them takes the sums of component `copied`. The sums are kept per pair of points as the
    /// fit's (`applied`): a row's entries land on consecutive points, so two of them take
    /// their shape functions and add to each component's two sums at once.
    fn apply_components<const T: usize, const N: usize, V: Components>(
        &mut self,
        values: &[V],
        out: &mut [V],
        copied: Option<usize>,
    ) {
        assert!(
            values.len() <= self.reach.len(),
            "more values than particles in the last `fit`"
        );
        let pairing = self.fit_pairing;
        // Taken out of `self` while its tables are read, and put back with its room.
        let mut applied = std::mem::take(&mut self.applied);
        let points = self.lattice.len();
        let sums = applied.zeroed::<N>(points);
        let degree = degree_of::<T, D>();
        let coeffs = self.coeffs.as_chunks::<T>().0;
        let components = |v: &V| std::array::from_fn::<f64, N, _>(|c| v.component(c));
        // Two particles at a time, as the fit summed them: where they reach the same points,
        // each point's sums are loaded and stored once for both.
        let mut tables = self.tables();
        let one = |sums: &mut [[[f64; 2]; N]], tables: &AxisTables<'_, D>, u| {
            apply_particle::<T, N, D>(sums, pairing, tables, u, coeffs, degree);
        };
        let (head, pairs, tail) = self.fit_particle_pairing.split(values);
        for value in head {
            let a = tables.next().expect("a fit entry");
            one(sums, &a, components(value));
        }
        for [value_a, value_b] in pairs {
            let (a, b) = (tables.next(), tables.next());
            let (a, b) = (a.expect("a fit entry"), b.expect("a fit entry"));
            let (u_a, u_b) = (components(value_a), components(value_b));
            if a.same_points(&b) {
                for_each_row([&a, &b], |rows| {
                    apply_rows::<T, N, D, 2>(sums, pairing, rows, [u_a, u_b], coeffs, degree);
                });
            } else {
                one(sums, &a, u_a);
                one(sums, &b, u_b);
            }
        }
        for (value, last) in tail.iter().zip(tables) {
            one(sums, &last, components(value));
        }
        let source = |c: usize| match copied {
            Some(of) if c == N => of,
            _ => c,
        };
        applied.read_each::<N, _>(points, pairing, out, |_, out, sums, lane| {
            *out = V::from_components(|c| sums[source(c)][lane]);
        });
        self.applied = applied;
    }
}

/// A value the fits are applied to, by its components: `Reconstructor::apply` sums each
/// component apart, two evaluation points at a time.
pub trait Components: Copy {
    /// How many: 1, 2, 3 or 7 (`Reconstructor::apply_with`).
    const COUNT: usize;
    /// A component the last one may copy (the quadrature fields: a symmetric stress). Where
    /// it does in every value, `apply` sums the last component once, as that one.
    const LAST_MAY_COPY: Option<usize> = None;
    fn component(&self, c: usize) -> f64;
    fn from_components(component: impl Fn(usize) -> f64) -> Self;
}

impl Components for f64 {
    const COUNT: usize = 1;

    fn component(&self, _: usize) -> f64 {
        *self
    }

    fn from_components(component: impl Fn(usize) -> f64) -> Self {
        component(0)
    }
}

impl<const D: usize> Components for SVector<f64, D> {
    const COUNT: usize = D;

    fn component(&self, c: usize) -> f64 {
        self[c]
    }

    fn from_components(component: impl Fn(usize) -> f64) -> Self {
        SVector::from_fn(|c, _| component(c))
    }
}

/// Pairs of points that hold `points` evaluation points under either phase of `Pairing`.
fn pair_count(points: usize) -> usize {
    points / 2 + 1
}

/// Sums, per pair of points, that are zero between uses: a use reads each pair once and
/// zeroes it there (`zero_when_read`), where it is in cache, instead of the next use clearing
/// the whole array, by then out of cache, before it sums. A use that stops before it has
/// read every pair (a singular fit) leaves them to be cleared by the next.
#[derive(Default)]
struct ZeroSums {
    sums: Vec<[f64; 2]>,
    zero: bool,
}

impl ZeroSums {
    /// All zero, for `points` evaluation points as pairs of `S` components: sized for either
    /// phase of `Pairing` (a pair more than the points need), so that they keep their length,
    /// and their allocation, when the phase changes.
    fn zeroed<const S: usize>(&mut self, points: usize) -> &mut [[[f64; 2]; S]] {
        if !self.zero {
            self.sums.fill([0.0; 2]);
        }
        self.sums.resize(pair_count(points) * S, [0.0; 2]);
        self.zero = false;
        self.sums.as_chunks_mut::<S>().0
    }

    /// The sums as pairs of `S` components, as the last `zeroed` gave them.
    fn chunks_mut<const S: usize>(&mut self) -> &mut [[[f64; 2]; S]] {
        self.sums.as_chunks_mut::<S>().0
    }

    /// Every pair was read and zeroed since the last `zeroed`: the next need not clear them.
    fn mark_zero(&mut self) {
        self.zero = true;
    }

    /// Reads the sums of the lattice's `points` into `out`, one each from the first, in
    /// order: `read(e, out[e], e's pair's sums, e's lane)`, zeroing each pair once its last
    /// point is read. After all `points`, every pair is zero.
    #[inline(always)]
    fn read_each<const S: usize, O>(
        &mut self,
        points: usize,
        pairing: Pairing,
        out: &mut [O],
        mut read: impl FnMut(usize, &mut O, &[[f64; 2]; S], usize),
    ) {
        let pairs = self.chunks_mut::<S>();
        for (e, out) in out.iter_mut().enumerate() {
            let (pair, lane) = pairing.slot(e);
            read(e, out, &pairs[pair], lane);
            zero_when_read(pairs, pair, lane, e + 1 == points);
        }
        if out.len() == points {
            self.mark_zero();
        }
    }
}

/// Zeroes pair `pair` once its last point is read: at its second lane, or at the lattice's
/// last point.
#[inline(always)]
fn zero_when_read<const S: usize>(
    pairs: &mut [[[f64; 2]; S]],
    pair: usize,
    lane: usize,
    last_point: bool,
) {
    if lane == 1 || last_point {
        pairs[pair] = [[0.0; 2]; S];
    }
}

/// u^h += sum_p phi_p(x_e) u_p over the rows `rows` of `M` particles that reach the same
/// points, with their values' components `u`: per point, particle by particle, each entry's
/// shape function phi_p(x_e) = w q((x_p - x_e)/h) . c_e taken as it is used, two entries at
/// a time where they share a pair of points. It walks the row as `add_rows` does: one walker
/// shared by both, taking the entries as closures, was not inlined and cost `imls` 24 % more
/// instructions (docs/NOTES.md).
#[inline(always)]
fn apply_rows<const T: usize, const N: usize, const D: usize, const M: usize>(
    applied: &mut [[[f64; 2]; N]],
    pairing: Pairing,
    rows: &[Row<'_, D>; M],
    u: [[f64; N]; M],
    coeffs: &[[[f64; 2]; T]],
    degree: Degree,
) {
    let n = rows[0].factor.len();
    let (mut pair, lane) = pairing.slot(rows[0].first);
    let mut j = 0;
    if lane == 1 {
        apply_entries::<T, N, D, 1, M>(&mut applied[pair], &coeffs[pair], 1, j, rows, u, degree);
        (j, pair) = (1, pair + 1);
    }
    while j + 2 <= n {
        apply_entries::<T, N, D, 2, M>(&mut applied[pair], &coeffs[pair], 0, j, rows, u, degree);
        (j, pair) = (j + 2, pair + 1);
    }
    if j < n {
        apply_entries::<T, N, D, 1, M>(&mut applied[pair], &coeffs[pair], 0, j, rows, u, degree);
    }
}

/// `apply_rows` over every row of one particle's entries, its tables `tables`. One copy
/// serves every particle applied alone: inlined at each, the copies cost more than the call.
#[inline(never)]
fn apply_particle<const T: usize, const N: usize, const D: usize>(
    applied: &mut [[[f64; 2]; N]],
    pairing: Pairing,
    tables: &AxisTables<'_, D>,
    u: [f64; N],
    coeffs: &[[[f64; 2]; T]],
    degree: Degree,
) {
    for_each_row([tables], |rows| {
        apply_rows::<T, N, D, 1>(applied, pairing, rows, [u], coeffs, degree);
    });
}

/// `L` consecutive entries of the `M` particles' rows from their `j`-th, on lanes
/// `lane..lane + L` of one pair of points with coefficients `coeffs`: each component's sum
/// += u phi, particle by particle.
#[inline(always)]
fn apply_entries<const T: usize, const N: usize, const D: usize, const L: usize, const M: usize>(
    applied: &mut [[f64; 2]; N],
    coeffs: &[[f64; 2]; T],
    lane: usize,
    j: usize,
    rows: &[Row<'_, D>; M],
    u: [[f64; N]; M],
    degree: Degree,
) {
    let phi: [[f64; L]; M] = std::array::from_fn(|m| {
        std::array::from_fn(|l| {
            let row = &rows[m];
            let w_0 = row.factor[j + l];
            let w = row.factor_1.map_or(w_0, |w_1| w_0 * w_1);
            let mut d = row.across;
            d[0] = row.offset[j + l];
            let mut q = [0.0; MAX_TERMS];
            monomials(degree, &d, &mut q);
            w * q[..T]
                .iter()
                .zip(coeffs)
                .map(|(q, c)| q * c[lane + l])
                .sum::<f64>()
        })
    });
    for (c, sums) in applied.iter_mut().enumerate() {
        add_terms::<L, M>(sums, lane, |m, l| u[m][c] * phi[m][l]);
    }
}

/// The coefficients c_e at every evaluation point of `lattice`, from its packed moment
/// matrix, the first `P` of its `S` sums in `pairs` under `pairing`; whether a particle
/// reached it in `covered`. Where the sums are the moment matrix alone (`S == P`), each pair
/// is zeroed once read (`ZeroSums`); else the velocity moments after it are still to be read.
fn solve_points<const T: usize, const P: usize, const S: usize, const D: usize>(
    recipe: &Recipe,
    lattice: &Lattice<D>,
    pairing: Pairing,
    pairs: &mut [[[f64; 2]; S]],
    coeffs: &mut [[f64; 2]],
    covered: &mut [bool],
) -> Result<FitStats, SingularMoments> {
    const { assert!(P <= S) };
    let mut stats = FitStats::default();
    let coeffs = coeffs.as_chunks_mut::<T>().0;
    let points = covered.len();
    for (e, covered) in covered.iter_mut().enumerate() {
        let (pair, lane) = pairing.slot(e);
        let a = unpack::<T, P>(&std::array::from_fn(|c| pairs[pair][c][lane]));
        if S == P {
            zero_when_read(pairs, pair, lane, e + 1 == points);
        }
        let a = &a[..];
        *covered = a[0] > 0.0;
        let mut c = [0.0; T];
        if *covered {
            stats.fits += 1;
            match recipe.solver {
                Solver::Mls => {
                    let solved =
                        mls_coefficients::<T>(a, MAX_TERMS, T).ok_or_else(|| SingularMoments {
                            point: e,
                            position: lattice.point(e).iter().copied().collect(),
                        })?;
                    c.copy_from_slice(&solved[..T]);
                }
                Solver::Imls => {
                    let basis = Orthogonal::<T>::from_rows(a, MAX_TERMS, T);
                    if basis.rank() < T {
                        stats.rank_deficient += 1;
                    }
                    c = basis.shape_coefficients::<T>();
                }
            }
        }
        for (k, c) in c.into_iter().enumerate() {
            coeffs[pair][k][lane] = c;
        }
    }
    Ok(stats)
}

/// Tabulates, axis by axis, the lattice points within `search.radius` cells of `xp` whose
/// 1D weight is positive, a run of consecutive points: axis k's n-th in slot
/// `k * slots + n` of `offset` ((x_p - x_e)/h along the axis) and `factor` (the weight).
/// Returns where each axis's run begins and its length. A point left out lies at the edge
/// of the support (|d| / scale rounded to the weight's radius) and adds nothing to any sum;
/// so every entry's weight, a product of factors no smaller than about 1e-48, is positive,
/// and the sums need no test for zero.
#[inline(always)]
fn tabulate<const D: usize>(
    search: &Search<'_, D>,
    xp: &SVector<f64, D>,
    slots: usize,
    offset: &mut [f64],
    factor: &mut [f64],
) -> Reach<D> {
    // The weight's kind is taken once a particle, not at each point it reaches.
    let tables = (slots, offset, factor);
    match search.kernel.weight {
        Weight::Hat => tabulate_with(search, xp, tables, |r| Weight::Hat.eval(r)),
        Weight::QuadraticSpline => {
            tabulate_with(search, xp, tables, |r| Weight::QuadraticSpline.eval(r))
        }
        Weight::CubicSpline => tabulate_with(search, xp, tables, |r| Weight::CubicSpline.eval(r)),
    }
}

/// `tabulate` with the weight w(r) `eval`.
#[inline(always)]
fn tabulate_with<const D: usize>(
    search: &Search<'_, D>,
    xp: &SVector<f64, D>,
    (slots, offset, factor): (usize, &mut [f64], &mut [f64]),
    eval: impl Fn(f64) -> f64,
) -> Reach<D> {
    let (lattice, radius, inv_scale) = (search.lattice, search.radius, 1.0 / search.kernel.scale);
    let mut reach = Reach::default();
    for k in 0..D {
        let offset = &mut offset[k * slots..][..slots];
        let factor = &mut factor[k * slots..][..slots];
        let (mut n, mut last) = (0, 0);
        lattice.near_on_axis(k, xp[k], radius, |i, dk| {
            let w = eval(dk.abs() * inv_scale);
            if w > 0.0 {
                offset[n] = -dk;
                factor[n] = w;
                n += 1;
                last = i;
            }
        });
        // The weight falls with the distance, so the points kept are a run: the last one
        // and their count place it.
        reach.first[k] = (last + 1).saturating_sub(n) * lattice.stride(k);
        reach.count[k] = n;
    }
    reach
}

/// Where one particle's entries lie: along each axis, a run of `count` consecutive lattice
/// points from the one whose lattice index part is `first`. Its entries are the runs'
/// tensor product.
#[derive(Clone, Copy, Debug)]
struct Reach<const D: usize> {
    first: [usize; D],
    count: [usize; D],
}

impl<const D: usize> Reach<D> {
    /// Whether `other` is the same runs: the same entries.
    #[inline(always)]
    fn same_points(&self, other: &Self) -> bool {
        (0..D).all(|k| {
            let n = self.count[k];
            n == other.count[k] && (n == 0 || self.first[k] == other.first[k])
        })
    }
}

impl<const D: usize> Default for Reach<D> {
    fn default() -> Self {
        Reach {
            first: [0; D],
            count: [0; D],
        }
    }
}

/// Room for one particle's `AxisTables`, for a fit that does not keep them (`fit_apply`).
struct PointTables<const D: usize> {
    reach: Reach<D>,
    offset: [[f64; MAX_PER_AXIS]; D],
    factor: [[f64; MAX_PER_AXIS]; D],
}

impl<const D: usize> PointTables<D> {
    fn new() -> Self {
        PointTables {
            reach: Reach::default(),
            offset: [[0.0; MAX_PER_AXIS]; D],
            factor: [[0.0; MAX_PER_AXIS]; D],
        }
    }

    /// Its room, as a `Record` to fill.
    #[inline(always)]
    fn record(&mut self) -> Record<'_, D> {
        Record {
            slots: MAX_PER_AXIS,
            reach: &mut self.reach,
            offset: self.offset.as_flattened_mut(),
            factor: self.factor.as_flattened_mut(),
        }
    }
}

/// Where `tabulate` searches: the lattice, the kernel's support radius in cells and the kernel.
struct Search<'a, const D: usize> {
    lattice: &'a Lattice<D>,
    radius: f64,
    kernel: &'a Kernel,
}

impl<'a, const D: usize> Search<'a, D> {
    fn new(lattice: &'a Lattice<D>, radius: f64, kernel: &'a Kernel) -> Self {
        Search {
            lattice,
            radius,
            kernel,
        }
    }
}

/// Room for one particle's `AxisTables`, `slots` per axis.
struct Record<'a, const D: usize> {
    slots: usize,
    reach: &'a mut Reach<D>,
    offset: &'a mut [f64],
    factor: &'a mut [f64],
}

impl<'a, const D: usize> Record<'a, D> {
    /// Fills the record for a particle at `xp` (`tabulate`) and reads it as its tables.
    #[inline(always)]
    fn tabulate(self, search: &Search<'_, D>, xp: &SVector<f64, D>) -> AxisTables<'a, D> {
        *self.reach = tabulate(search, xp, self.slots, self.offset, self.factor);
        AxisTables {
            slots: self.slots,
            reach: *self.reach,
            row_stride: search.lattice.stride(D - 1),
            offset: self.offset,
            factor: self.factor,
        }
    }
}

/// One particle's lattice points along each axis, as `tabulate` leaves them; its entries
/// are their tensor product.
struct AxisTables<'a, const D: usize> {
    slots: usize,
    reach: Reach<D>,
    /// The lattice stride of the last axis: from one row of entries to the next.
    row_stride: usize,
    offset: &'a [f64],
    factor: &'a [f64],
}

impl<const D: usize> AxisTables<'_, D> {
    /// Whether `other` reaches the same lattice points: then their entries' rows are the
    /// same, each with its own weights and offsets.
    #[inline(always)]
    fn same_points(&self, other: &Self) -> bool {
        self.reach.same_points(&other.reach)
    }
}

/// Calls `visit` for every row of entries along the first axis of `M` particles that reach
/// the same points (`AxisTables::same_points`), in the order of the second axis's points
/// (one row in 1D), with each particle's row. A row's lattice points are consecutive: the first axis's points
/// in reach are a run of indices, of stride 1.
#[inline(always)]
fn for_each_row<const D: usize, const M: usize>(
    tables: [&AxisTables<'_, D>; M],
    mut visit: impl FnMut(&[Row<'_, D>; M]),
) {
    const { assert!(D == 1 || D == 2, "the fits' bases are 1D and 2D") };
    let lead = tables[0];
    debug_assert!(tables.iter().all(|t| t.same_points(lead)));
    let n = lead.reach.count[0];
    if n == 0 {
        return;
    }
    let first = lead.reach.first[0];
    if D == 1 {
        visit(&tables.map(|t| Row {
            first,
            offset: &t.offset[..n],
            factor: &t.factor[..n],
            factor_1: None,
            across: SVector::zeros(),
        }));
        return;
    }
    for r in 0..lead.reach.count[1] {
        let row_index = lead.reach.first[D - 1] + r * lead.row_stride;
        visit(&tables.map(|t| {
            let mut across = SVector::zeros();
            across[D - 1] = t.offset[t.slots + r];
            Row {
                first: row_index + first,
                offset: &t.offset[..n],
                factor: &t.factor[..n],
                factor_1: Some(t.factor[t.slots + r]),
                across,
            }
        }));
    }
}

/// One row of a particle's entries along the first axis: lattice points `first`,
/// `first + 1`, ..., with the first axis's offsets and weight factors, the other axis's
/// factor (none in 1D) and its offset in `across` (whose first component is unused).
struct Row<'a, const D: usize> {
    first: usize,
    offset: &'a [f64],
    factor: &'a [f64],
    factor_1: Option<f64>,
    across: SVector<f64, D>,
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
    pub fn remap(&mut self, v: &[SVector<f64, D>], out: &mut [SVector<f64, D>]) {
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

/// Components of `fit_apply`'s sums per point: the packed moment matrix and the velocity
/// moments, two per term (the second unused in 1D).
const fn sum_components(terms: usize) -> usize {
    packed_len(terms) + 2 * terms
}

/// Which evaluation points share a pair of `Reconstructor::pair_sums`: pair m holds points
/// 2m - phase and 2m + 1 - phase. A row that begins a pair adds its entries two at a time
/// from its first; one that begins on a pair's second point adds its first (and, of an even
/// number, its last) entry alone, at about half again the cost of a pair's. On a lattice of
/// two points per cell, the rows of even length all begin on one parity (particles two per
/// cell and axis: every row of IMLS's field fit), and `phase` makes them begin pairs. Only
/// where the sums are kept depends on it, not what is summed or in what order.
#[derive(Clone, Copy, Debug, Default)]
struct Pairing {
    phase: usize,
}

impl Pairing {
    /// The pair holding point `e`, and its lane there.
    #[inline(always)]
    fn slot(self, e: usize) -> (usize, usize) {
        let shifted = e + self.phase;
        (shifted / 2, shifted % 2)
    }
}

/// Which consecutive particles a fit takes two at a time (`add_particle_pair`): particles
/// p and p + 1 for every p of the parity `phase`, the first alone under phase 1. Where two
/// reach the same points, each point's sums are loaded and stored once for both. Which pairs
/// do depends on the lattice: particles two per cell and axis on IMLS's lattice of two Gauss
/// points per cell reach the same points across a cell face (phase 1), on the nodes within a
/// cell (phase 0). The particles' sums run in their order under either phase, so only the
/// cost depends on it.
#[derive(Clone, Copy, Debug, Default)]
struct ParticlePairing {
    phase: usize,
}

impl ParticlePairing {
    /// The particles' `items` as the fit takes them: those before the first pair, the
    /// pairs, and one left after them.
    fn split<T>(self, items: &[T]) -> (&[T], &[[T; 2]], &[T]) {
        let (head, rest) = items.split_at(self.phase.min(items.len()));
        let (pairs, tail) = rest.as_chunks::<2>();
        (head, pairs, tail)
    }
}

/// Counts, for each phase of `ParticlePairing`, the pairs of a fit's particles, noted in
/// order, that reach the same points (`Reach::same_points`, the test `add_particle_pair`
/// makes).
struct ParticleVotes<const D: usize> {
    last: Reach<D>,
    noted: usize,
    shared: [usize; 2],
}

impl<const D: usize> Default for ParticleVotes<D> {
    fn default() -> Self {
        ParticleVotes {
            // No particle's runs (no count is usize::MAX): the first one noted pairs with none.
            last: Reach {
                first: [usize::MAX; D],
                count: [usize::MAX; D],
            },
            noted: 0,
            shared: [0; 2],
        }
    }
}

impl<const D: usize> ParticleVotes<D> {
    /// The next particle reaches `reach`.
    #[inline(always)]
    fn note(&mut self, reach: Reach<D>) {
        // Particles noted - 1 and noted: a pair under the phase of noted - 1.
        self.shared[(self.noted + 1) % 2] += usize::from(reach.same_points(&self.last));
        self.last = reach;
        self.noted += 1;
    }

    /// The phase under which more pairs reached the same points; `current` on a tie.
    fn best(&self, current: ParticlePairing) -> ParticlePairing {
        let other = 1 - current.phase;
        if self.shared[other] > self.shared[current.phase] {
            ParticlePairing { phase: other }
        } else {
            current
        }
    }
}

/// The sums of one fit under `pairing`, and how many rows began on each lane.
struct PairSums<'a, const S: usize> {
    sums: &'a mut [[[f64; 2]; S]],
    pairing: Pairing,
    starts: [usize; 2],
}

impl<'a, const S: usize> PairSums<'a, S> {
    /// `sums` zeroed for `points` evaluation points, as pairs of `S` components.
    fn zeroed(sums: &'a mut ZeroSums, points: usize, pairing: Pairing) -> Self {
        PairSums {
            sums: sums.zeroed::<S>(points),
            pairing,
            starts: [0; 2],
        }
    }

    /// Adds one particle's entries (`add_rows`), its tables `tables`. One copy serves every
    /// particle added alone: inlined at each, the copies cost more than the call.
    #[inline(never)]
    fn add_particle<const T: usize, const P: usize, const D: usize, const VELOCITY: bool>(
        &mut self,
        tables: &AxisTables<'_, D>,
        degree: Degree,
        u: SVector<f64, D>,
    ) {
        for_each_row([tables], |rows| {
            add_rows::<T, P, S, D, 1, VELOCITY>(self, rows, degree, [u]);
        });
    }

    /// The pairing under which most of this fit's rows would have begun a pair.
    fn best_pairing(&self) -> Pairing {
        let phase = self.pairing.phase;
        Pairing {
            phase: if self.starts[1] > self.starts[0] {
                1 - phase
            } else {
                phase
            },
        }
    }
}

/// Adds two consecutive particles' entries (`add_rows`), with their velocities for a
/// `fit_apply`: together where they reach the same points (`ParticlePairing`), so that
/// each point's sums are loaded and stored once for both; else one after the other.
#[inline(always)]
fn add_particle_pair<
    const T: usize,
    const P: usize,
    const S: usize,
    const D: usize,
    const VELOCITY: bool,
>(
    pairs: &mut PairSums<'_, S>,
    (a, b): (AxisTables<'_, D>, AxisTables<'_, D>),
    degree: Degree,
    u: [SVector<f64, D>; 2],
) {
    if a.same_points(&b) {
        for_each_row([&a, &b], |rows| {
            add_rows::<T, P, S, D, 2, VELOCITY>(pairs, rows, degree, u);
        });
    } else {
        pairs.add_particle::<T, P, D, VELOCITY>(&a, degree, u[0]);
        pairs.add_particle::<T, P, D, VELOCITY>(&b, degree, u[1]);
    }
}

/// Adds the entries of the rows of `M` particles that reach the same points (their rows
/// `rows`, their velocities `u`) to `pairs` (`Reconstructor::pair_sums`): a += w q q^T and
/// b += u (w q) each, two entries at a time where they share a pair of points, and each
/// point's sums loaded and stored once for the M particles. Each entry of a particle lands
/// on its own point and the particles are added in order, so the sums of every point run in
/// particle order, as they would one entry at a time.
#[inline(always)]
fn add_rows<
    const T: usize,
    const P: usize,
    const S: usize,
    const D: usize,
    const M: usize,
    const VELOCITY: bool,
>(
    pairs: &mut PairSums<'_, S>,
    rows: &[Row<'_, D>; M],
    degree: Degree,
    u: [SVector<f64, D>; M],
) {
    let n = rows[0].factor.len();
    let (mut pair, lane) = pairs.pairing.slot(rows[0].first);
    pairs.starts[lane] += 1;
    let sums = &mut *pairs.sums;
    let mut j = 0;
    if lane == 1 {
        add_entries::<T, P, S, D, 1, M, VELOCITY>(&mut sums[pair], 1, j, rows, degree, u);
        (j, pair) = (1, pair + 1);
    }
    while j + 2 <= n {
        add_entries::<T, P, S, D, 2, M, VELOCITY>(&mut sums[pair], 0, j, rows, degree, u);
        (j, pair) = (j + 2, pair + 1);
    }
    if j < n {
        add_entries::<T, P, S, D, 1, M, VELOCITY>(&mut sums[pair], 0, j, rows, degree, u);
    }
}

/// `L` consecutive entries of the `M` particles' rows from their `j`-th, on lanes
/// `lane..lane + L` of one pair of points: a += w q q^T (packed) and b += u (w q), term by
/// term, particle by particle.
#[inline(always)]
fn add_entries<
    const T: usize,
    const P: usize,
    const S: usize,
    const D: usize,
    const L: usize,
    const M: usize,
    const VELOCITY: bool,
>(
    sums: &mut [[f64; 2]; S],
    lane: usize,
    j: usize,
    rows: &[Row<'_, D>; M],
    degree: Degree,
    u: [SVector<f64, D>; M],
) {
    let w: [[f64; L]; M] = std::array::from_fn(|m| {
        std::array::from_fn(|l| {
            let w_0 = rows[m].factor[j + l];
            rows[m].factor_1.map_or(w_0, |w_1| w_0 * w_1)
        })
    });
    let q: [[[f64; MAX_TERMS]; L]; M] = std::array::from_fn(|m| {
        std::array::from_fn(|l| {
            let mut d = rows[m].across;
            d[0] = rows[m].offset[j + l];
            let mut q = [0.0; MAX_TERMS];
            monomials(degree, &d, &mut q);
            q
        })
    });
    let wq: [[[f64; T]; L]; M] = std::array::from_fn(|m| {
        std::array::from_fn(|l| std::array::from_fn(|r| w[m][l] * q[m][l][r]))
    });
    for s in 0..T {
        add_terms::<L, M>(&mut sums[s], lane, |m, l| wq[m][l][0] * q[m][l][s]);
    }
    for r in 1..T {
        for s in 1..T {
            let c = T + (r - 1) * (T - 1) + s - 1;
            add_terms::<L, M>(&mut sums[c], lane, |m, l| wq[m][l][r] * q[m][l][s]);
        }
    }
    if !VELOCITY {
        return;
    }
    for k in 0..T {
        for c in 0..D {
            let b = &mut sums[P + 2 * k + c];
            add_terms::<L, M>(b, lane, |m, l| u[m][c] * (w[m][l] * q[m][l][k]));
        }
    }
}

/// One component's sums on lanes `lane..lane + L`: each adds `term(m, l)` for particle m in
/// order.
#[inline(always)]
fn add_terms<const L: usize, const M: usize>(
    sums: &mut [f64; 2],
    lane: usize,
    term: impl Fn(usize, usize) -> f64,
) {
    for l in 0..L {
        for m in 0..M {
            sums[lane + l] += term(m, l);
        }
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
