//! The mass matrix a transfer solves its nodal velocity and acceleration with, lumped or
//! consistent, with the fixed velocity components removed from the system (the constrained
//! projection) rather than zeroed after an unconstrained solve.

use std::ops::Range;

use nalgebra::SVector;

use super::banded::BandMatrix;
use super::conjugate_gradients::{
    precondition_lumped, Breakdown, ConjugateGradients, MAX_ITERATIONS,
};
use super::diagonals::SymmetricDiagonals;
use super::line_sums::LineSums;
use crate::divergence::Divergence;
use crate::grid::{FixedDof, GridState};
use crate::shape::Stencils;

/// Which mass matrix the nodal velocity and acceleration are solved with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MassMatrix {
    /// M_ij = int rho N_i N_j over the transfer's quadrature, solved by a band Cholesky
    /// factorisation where the band is narrow (1D) and by conjugate gradients where it is a
    /// grid row wide (2D).
    Consistent,
    /// Its row sums m_i = int rho N_i (partition of unity), as conservative as the consistent
    /// one.
    Lumped,
}

/// The band Cholesky factorisation is taken while bandwidth^2, its work per DOF, stays
/// within this many times the stored entries per row, which with the iteration count set the
/// work per DOF of the conjugate gradients. Measured on the 2D manufactured solution
/// (docs/NOTES.md, the consistent-mass solve): the two break even near 16 cells for the hat
/// and the dual-domain basis; every 1D basis has a band of at most 3 and is factorised.
const DIRECT_SOLVE_RATIO: usize = 64;

/// Assembles and solves M x = b per velocity component on the DOFs that carry mass and are
/// free in that component; x is zero elsewhere.
pub struct MassSolver<const D: usize> {
    kind: MassMatrix,
    /// Per DOF and component: held at zero.
    fixed: Vec<[bool; D]>,
    /// The consistent matrix in DOF numbering.
    matrix: SymmetricDiagonals,
    /// Whether this step's matrix is factorised (else solved by conjugate gradients).
    direct: bool,
    /// Direct: per component its factor restricted to the DOFs listed in `free[k]`.
    factors: Vec<BandMatrix>,
    free: Vec<Vec<u32>>,
    /// The component whose factor each component solves with.
    factor_of: [usize; D],
    /// Iterative: per component 1 / m_i on its DOFs, zero elsewhere.
    inverse_lumped: Vec<Vec<f64>>,
    /// DOFs per axis of the lattice.
    per_axis: usize,
    /// Iterative in 2D: per component the line-sum preconditioner on its DOFs, used where it
    /// factorised (`with_lines`); the lumped one otherwise.
    lines: Vec<LineSums>,
    with_lines: [bool; D],
    iterations: ConjugateGradients,
    /// Per component its right-hand side, then its solution.
    rhs: [Vec<f64>; D],
    /// sum_i p_i of the last `solve_momenta`: the momentum the DOFs received.
    received: SVector<f64, D>,
}

impl<const D: usize> MassSolver<D> {
    /// A solver on a lattice of `per_axis` DOFs per axis.
    pub fn new(kind: MassMatrix, per_axis: usize, fixed: &[FixedDof]) -> Self {
        let num_dofs = per_axis.pow(D as u32);
        let mut mask = vec![[false; D]; num_dofs];
        for &(i, k) in fixed {
            mask[i as usize][k as usize] = true;
        }
        MassSolver {
            kind,
            fixed: mask,
            matrix: SymmetricDiagonals::default(),
            direct: true,
            factors: vec![BandMatrix::default(); D],
            free: vec![Vec::new(); D],
            factor_of: std::array::from_fn(|k| k),
            inverse_lumped: vec![Vec::new(); D],
            per_axis,
            lines: vec![LineSums::default(); D],
            with_lines: [false; D],
            iterations: ConjugateGradients::default(),
            rhs: std::array::from_fn(|_| Vec::new()),
            received: SVector::zeros(),
        }
    }

    pub fn is_consistent(&self) -> bool {
        self.kind == MassMatrix::Consistent
    }

    /// Whether the last `prepare` factorised the matrix.
    #[cfg(test)]
    pub(crate) fn is_direct(&self) -> bool {
        self.direct
    }

    /// Whether the last `prepare` gave every component the line-sum preconditioner.
    #[cfg(test)]
    pub(crate) fn uses_line_sums(&self) -> bool {
        self.with_lines.iter().all(|&lines| lines)
    }

    /// Starts a new consistent matrix whose entries lie at most `bandwidth` off the diagonal
    /// (the largest DOF distance within one point's stencil).
    pub fn reset(&mut self, bandwidth: usize) {
        self.matrix.reset(self.fixed.len(), bandwidth);
    }

    /// Adds one point's share `scale` N_i N_j to M_ij and M_ji for every pair of its stencil
    /// entries (`nodes`, `values`), i by entry and then j <= i by entry. A zero is not
    /// stored: the block stencils list nodes their point does not reach (the dual-domain
    /// gradient's, the particle domains'), whose zeros would widen the matrix's pattern and
    /// every product with it.
    #[inline]
    pub fn add_point(&mut self, nodes: &[u32], values: &[f64], scale: f64) {
        for (&i, &n_i) in nodes.iter().zip(values) {
            if n_i == 0.0 {
                continue;
            }
            let (i, scaled) = (i as usize, scale * n_i);
            for (&j, &n_j) in nodes.iter().zip(values) {
                let value = scaled * n_j;
                if j as usize <= i && value != 0.0 {
                    self.matrix.add(i, j as usize, value);
                }
            }
        }
    }

    /// `add_point` for each of `points` of `stencils` in turn, with the share `scale(p)` of
    /// point p: the same sums to the bit. A run of consecutive points on the same nodes (the
    /// Gauss points of one element, the particles of one cell) is summed in a dense block
    /// that starts from the stored entries and is stored back once (`add_run`).
    pub fn add_points(
        &mut self,
        stencils: &Stencils<D>,
        points: Range<usize>,
        scale: impl Fn(usize) -> f64,
    ) {
        let mut start = points.start;
        while start < points.end {
            let nodes = stencils.values_of(start).0;
            let end = (start + 1..points.end)
                .find(|&p| stencils.values_of(p).0 != nodes)
                .unwrap_or(points.end);
            let summed = end - start > 1
                && match nodes.len() {
                    4 => self.add_run::<4>(stencils, start..end, &scale),
                    9 => self.add_run::<9>(stencils, start..end, &scale),
                    16 => self.add_run::<16>(stencils, start..end, &scale),
                    _ => false,
                };
            if !summed {
                for p in start..end {
                    let (nodes, values) = stencils.values_of(p);
                    self.add_point(nodes, values, scale(p));
                }
            }
            start = end;
        }
    }

    /// A run of points on the same N nodes summed in a dense block: every product
    /// (scale N_a) N_b added to its block entry, and the entries with node b <= node a stored
    /// back. Each stored entry receives the terms `add_point` gives it, in the same order; the
    /// zeros `add_point` skips add nothing here (a sum that starts from +0 never becomes -0).
    /// False, with the matrix untouched, where that cannot hold: a share or value that is not
    /// finite,
    /// a node listed twice (the padding of a value stencil), or a pair off the stored
    /// diagonals (`add_point` stores the diagonals in the order their first terms come).
    fn add_run<const N: usize>(
        &mut self,
        stencils: &Stencils<D>,
        run: Range<usize>,
        scale: &impl Fn(usize) -> f64,
    ) -> bool {
        let nodes: &[u32; N] = stencils.values_of(run.start).0.try_into().expect("N nodes");
        let mut block = [[0.0; N]; N];
        let mut position = [[0; N]; N];
        for a in 0..N {
            for b in 0..N {
                let (i, j) = (nodes[a], nodes[b]);
                if j > i {
                    continue;
                }
                if j == i && a != b {
                    return false;
                }
                let Some(at) = self.matrix.position(i as usize, j as usize) else {
                    return false;
                };
                position[a][b] = at;
                block[a][b] = self.matrix.stored_value(at);
            }
        }
        let finite =
            |p| scale(p).is_finite() && stencils.values_of(p).1.iter().all(|v| v.is_finite());
        if !run.clone().all(finite) {
            return false;
        }
        for p in run {
            let values: &[f64; N] = stencils.values_of(p).1.try_into().expect("N values");
            let n = scale(p);
            for a in 0..N {
                let scaled = n * values[a];
                for b in 0..N {
                    block[a][b] += scaled * values[b];
                }
            }
        }
        for a in 0..N {
            for b in 0..N {
                if nodes[b] <= nodes[a] {
                    self.matrix.store(position[a][b], block[a][b]);
                }
            }
        }
        true
    }

    /// Prepares the solves with the assembled matrix on, per component, the DOFs whose lumped
    /// mass `mass` exceeds `empty_mass` and that are free in that component: the factors, or
    /// the preconditioners of the conjugate gradients.
    pub fn prepare(&mut self, mass: &[f64], empty_mass: f64) -> Result<(), Divergence> {
        let bandwidth = self.matrix.bandwidth();
        self.direct = bandwidth * bandwidth <= DIRECT_SOLVE_RATIO * self.matrix.entries_per_row();
        if self.direct {
            return self.factor(mass, empty_mass);
        }
        let fixed = &self.fixed;
        for (k, inverse) in self.inverse_lumped.iter_mut().enumerate() {
            inverse.clear();
            inverse.extend((0..mass.len()).map(|i| {
                if solved_for(fixed, mass, empty_mass, i, k) {
                    1.0 / mass[i]
                } else {
                    0.0
                }
            }));
        }
        for k in 0..D {
            let inverse = &self.inverse_lumped[k];
            // A line sum that is not positive definite (a matrix far from a product of 1D
            // ones) leaves the component with the lumped preconditioner.
            self.with_lines[k] = D == 2
                && self.lines[k]
                    .prepare(&self.matrix, self.per_axis, |i| inverse[i] > 0.0)
                    .unwrap_or(false);
        }
        Ok(())
    }

    /// Factorises, per component, the consistent matrix restricted to its DOFs; a component
    /// with the same DOFs as an earlier one shares its factor. A pivot that is not positive
    /// stops the run with the DOF.
    fn factor(&mut self, mass: &[f64], empty_mass: f64) -> Result<(), Divergence> {
        for k in 0..D {
            let mut free = std::mem::take(&mut self.free[k]);
            free.clear();
            free.extend(
                (0..mass.len())
                    .filter(|&i| solved_for(&self.fixed, mass, empty_mass, i, k))
                    .map(|i| i as u32),
            );
            let shared = (0..k).find(|&l| self.free[self.factor_of[l]] == free);
            self.free[k] = free;
            match shared {
                Some(l) => self.factor_of[k] = self.factor_of[l],
                None => {
                    self.factor_of[k] = k;
                    self.factor_component(k)?;
                }
            }
        }
        Ok(())
    }

    fn factor_component(&mut self, k: usize) -> Result<(), Divergence> {
        let free = &self.free[k];
        let factor = &mut self.factors[k];
        let bandwidth = self.matrix.bandwidth();
        factor.reset(free.len(), bandwidth);
        for a in 0..free.len() {
            let i = free[a] as usize;
            for b in (0..=a).rev() {
                let j = free[b] as usize;
                if i - j > bandwidth {
                    break;
                }
                factor.add(a, b, self.matrix.get(i, j));
            }
        }
        factor.factor().map_err(|e| {
            Divergence::Reconstruction(format!(
                "the consistent mass matrix is not positive definite at DOF {} (pivot {:e})",
                free[e.row], e.pivot
            ))
        })
    }

    /// Solves M v = p in place for nodal momenta p, keeping sum_i p_i, the momentum the DOFs
    /// received before the solve and the boundary conditions (`received_momentum`).
    pub fn solve_momenta(
        &mut self,
        mass: &[f64],
        empty_mass: f64,
        momenta: &mut [SVector<f64, D>],
    ) -> Result<(), Divergence> {
        self.received = momenta.iter().sum();
        self.solve(mass, empty_mass, momenta)
    }

    /// sum_i p_i of the last `solve_momenta`.
    pub fn received_momentum(&self) -> SVector<f64, D> {
        self.received
    }

    /// Solves M x = b in place for a nodal field; the consistent matrix must be prepared.
    /// `mass` is the lumped mass, which the lumped kind divides by.
    pub fn solve(
        &mut self,
        mass: &[f64],
        empty_mass: f64,
        field: &mut [SVector<f64, D>],
    ) -> Result<(), Divergence> {
        if self.kind == MassMatrix::Lumped {
            for (i, x) in field.iter_mut().enumerate() {
                for k in 0..D {
                    x[k] = if solved_for(&self.fixed, mass, empty_mass, i, k) {
                        x[k] / mass[i]
                    } else {
                        0.0
                    };
                }
            }
            return Ok(());
        }
        if self.direct {
            for (k, rhs) in self.rhs.iter_mut().enumerate() {
                let free = &self.free[k];
                rhs.clear();
                rhs.extend(free.iter().map(|&i| field[i as usize][k]));
                self.factors[self.factor_of[k]].solve(rhs);
                for x in field.iter_mut() {
                    x[k] = 0.0;
                }
                for (&i, &x) in free.iter().zip(rhs.iter()) {
                    field[i as usize][k] = x;
                }
            }
            return Ok(());
        }
        for (k, rhs) in self.rhs.iter_mut().enumerate() {
            rhs.clear();
            rhs.extend(field.iter().map(|x| x[k]));
        }
        // The components together, each with its own preconditioner.
        let (lines, inverse_lumped, with_lines) =
            (&mut self.lines, &self.inverse_lumped, self.with_lines);
        let solved = self.iterations.solve_columns(
            &self.matrix,
            |k, r, z| {
                if with_lines[k] {
                    lines[k].apply(r, z);
                } else {
                    precondition_lumped(&inverse_lumped[k], r, z);
                }
            },
            self.rhs.each_mut().map(Vec::as_mut_slice),
        );
        // The first component that broke down, as solving them one after another reports it.
        for (k, (solved, rhs)) in solved.into_iter().zip(&self.rhs).enumerate() {
            solved.map_err(breakdown_message)?;
            for (x, &value) in field.iter_mut().zip(rhs) {
                x[k] = value;
            }
        }
        Ok(())
    }

    /// The grid solve with this matrix: a = M^-1 f, v_new = v + kick a, fixed components
    /// and empty DOFs held at zero. Afterwards `force` holds a.
    pub fn solve_grid(&mut self, grid: &mut GridState<D>, kick: f64) -> Result<(), Divergence> {
        self.solve(&grid.mass, grid.empty_mass, &mut grid.force)?;
        for i in 0..grid.mass.len() {
            grid.velocity_new[i] = grid.velocity[i] + grid.force[i] * kick;
        }
        Ok(())
    }
}

/// Whether component k of DOF i is solved for: it carries mass and is not held.
#[inline]
fn solved_for<const D: usize>(
    fixed: &[[bool; D]],
    mass: &[f64],
    empty_mass: f64,
    i: usize,
    k: usize,
) -> bool {
    mass[i] > empty_mass && !fixed[i][k]
}

fn breakdown_message(breakdown: Breakdown) -> Divergence {
    Divergence::Reconstruction(match breakdown {
        Breakdown::NotPositiveDefinite(curvature) => format!(
            "the consistent mass matrix is not positive definite (conjugate gradients met \
             p^T M p = {curvature:e})"
        ),
        Breakdown::NotConverged(residual) => format!(
            "the consistent mass solve did not converge in {MAX_ITERATIONS} conjugate-gradient \
             iterations (relative residual {residual:e})"
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Lcg;

    /// Runs of points on shared nodes, as `add_points` sums them, against `add_point` point
    /// by point: the same diagonals in the same order and every entry the same to the bit.
    /// The runs have 4, 9, 16 and 5 nodes (5 has no block), each its own node set, with zero
    /// values, a repeated node of zero value (a value stencil's padding) and a NaN among them.
    #[test]
    fn runs_of_points_sum_as_point_by_point() {
        let (per_axis, points) = (12, 400);
        let mut rng = Lcg::new(17);
        let mut stencils = Stencils::<2>::new(16, points);
        let mut p = 0;
        while p < points {
            let len = [4, 9, 16, 5][(rng.unit() * 4.0) as usize % 4];
            let corner = (rng.unit() * 100.0) as u32;
            let nodes: Vec<u32> = (0..len as u32)
                .map(|e| corner + e % 4 + per_axis as u32 * (e / 4))
                .collect();
            let run = (1 + (rng.unit() * 9.0) as usize).min(points - p);
            for q in p..p + run {
                let entries = q * 16..(q + 1) * 16;
                stencils.weight[entries.clone()].fill(0.0);
                for (e, &node) in nodes.iter().enumerate() {
                    stencils.node[q * 16 + e] = node;
                    stencils.weight[q * 16 + e] = match rng.unit() {
                        u if u < 0.05 => 0.0,
                        u if u < 0.06 => f64::NAN,
                        u => u - 0.1,
                    };
                }
                for e in len..16 {
                    stencils.node[q * 16 + e] = nodes[0];
                }
                if len == 9 && rng.unit() < 0.3 {
                    // Padding: the last entry repeats the first node with a zero value.
                    stencils.node[q * 16 + 8] = nodes[0];
                    stencils.weight[q * 16 + 8] = 0.0;
                }
            }
            p += run;
        }
        // Cut every point to its own length: the runs share a stencil width of 16, so each
        // width is tested through a stencil table of its own.
        for width in [4, 9, 16, 5] {
            let mut table = Stencils::<2>::new(width, points);
            for q in 0..points {
                let (nodes, values) = stencils.values_of(q);
                table.node[q * width..(q + 1) * width].copy_from_slice(&nodes[..width]);
                table.weight[q * width..(q + 1) * width].copy_from_slice(&values[..width]);
            }
            let scale = |p: usize| 1.0 + (p as f64 * 0.37).sin();
            let fixed = [];
            let mut by_runs = MassSolver::<2>::new(MassMatrix::Consistent, per_axis, &fixed);
            let mut by_points = MassSolver::<2>::new(MassMatrix::Consistent, per_axis, &fixed);
            by_runs.reset(table.bandwidth());
            by_points.reset(table.bandwidth());
            by_runs.add_points(&table, 0..points, scale);
            for q in 0..points {
                let (nodes, values) = table.values_of(q);
                by_points.add_point(nodes, values, scale(q));
            }
            assert_eq!(by_runs.matrix.distances(), by_points.matrix.distances());
            let n = by_points.matrix.order();
            for i in 0..n {
                for j in 0..=i {
                    let (a, b) = (by_runs.matrix.get(i, j), by_points.matrix.get(i, j));
                    assert_eq!(a.to_bits(), b.to_bits(), "width {width}, entry ({i}, {j})");
                }
            }
        }
    }
}
