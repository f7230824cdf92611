//! The mass matrix a transfer solves its nodal velocity and acceleration with, lumped or
//! consistent, with the fixed velocity components removed from the system (the constrained
//! projection) rather than zeroed after an unconstrained solve.

use nalgebra::SVector;

use super::banded::BandMatrix;
use super::GridState;
use crate::integrate::{Divergence, FixedDof};

/// Which mass matrix the nodal velocity and acceleration are solved with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MassMatrix {
    /// M_ij = int rho N_i N_j over the transfer's quadrature, solved by a banded Cholesky
    /// factorisation.
    Consistent,
    /// Its row sums m_i = int rho N_i (partition of unity), as conservative as the consistent
    /// one.
    Lumped,
}

/// Assembles and solves M x = b per velocity component on the DOFs that carry mass and are
/// free in that component; x is zero elsewhere.
pub struct MassSolver<const D: usize> {
    kind: MassMatrix,
    /// Per DOF and component: held at zero.
    fixed: Vec<[bool; D]>,
    /// The consistent matrix in DOF numbering, and per component its factor restricted to
    /// the DOFs listed in `free[k]`.
    matrix: BandMatrix,
    bandwidth: usize,
    factors: Vec<BandMatrix>,
    free: Vec<Vec<u32>>,
    rhs: Vec<f64>,
    /// sum_i p_i of the last `solve_momenta`: the momentum the DOFs received.
    received: SVector<f64, D>,
}

impl<const D: usize> MassSolver<D> {
    pub fn new(kind: MassMatrix, num_dofs: usize, fixed: &[FixedDof]) -> Self {
        let mut mask = vec![[false; D]; num_dofs];
        for &(i, k) in fixed {
            mask[i as usize][k as usize] = true;
        }
        MassSolver {
            kind,
            fixed: mask,
            matrix: BandMatrix::default(),
            bandwidth: 0,
            factors: vec![BandMatrix::default(); D],
            free: vec![Vec::new(); D],
            rhs: Vec::new(),
            received: SVector::zeros(),
        }
    }

    pub fn is_consistent(&self) -> bool {
        self.kind == MassMatrix::Consistent
    }

    /// Starts a new consistent matrix with `bandwidth` sub-diagonals (the largest DOF
    /// distance within one point's stencil).
    pub fn reset(&mut self, bandwidth: usize) {
        self.bandwidth = bandwidth;
        self.matrix.reset(self.fixed.len(), bandwidth);
    }

    /// Adds `value` to M_ij and M_ji.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        self.matrix.add(i, j, value);
    }

    /// Factorises, per component, the consistent matrix restricted to the DOFs whose lumped
    /// mass exceeds `empty_mass` and that are free in that component. A pivot that is not
    /// positive stops the run with the DOF.
    pub fn factor(&mut self, mass: &[f64], empty_mass: f64) -> Result<(), Divergence> {
        for k in 0..D {
            let free = &mut self.free[k];
            free.clear();
            free.extend(
                (0..mass.len())
                    .filter(|&i| mass[i] > empty_mass && !self.fixed[i][k])
                    .map(|i| i as u32),
            );
            let factor = &mut self.factors[k];
            factor.reset(free.len(), self.bandwidth);
            for a in 0..free.len() {
                let i = free[a] as usize;
                for b in (0..=a).rev() {
                    let j = free[b] as usize;
                    if i - j > self.bandwidth {
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
            })?;
        }
        Ok(())
    }

    /// Solves M v = p in place for nodal momenta p, keeping sum_i p_i, the momentum the DOFs
    /// received before the solve and the boundary conditions (`received_momentum`).
    pub fn solve_momenta(
        &mut self,
        mass: &[f64],
        empty_mass: f64,
        momenta: &mut [SVector<f64, D>],
    ) {
        self.received = momenta.iter().sum();
        self.solve(mass, empty_mass, momenta);
    }

    /// sum_i p_i of the last `solve_momenta`.
    pub fn received_momentum(&self) -> SVector<f64, D> {
        self.received
    }

    /// Solves M x = b in place for a nodal field; the consistent matrix must be factorised.
    /// `mass` is the lumped mass, which the lumped kind divides by.
    pub fn solve(&mut self, mass: &[f64], empty_mass: f64, field: &mut [SVector<f64, D>]) {
        match self.kind {
            MassMatrix::Lumped => {
                for (i, x) in field.iter_mut().enumerate() {
                    let m = mass[i];
                    for k in 0..D {
                        x[k] = if m > empty_mass && !self.fixed[i][k] {
                            x[k] / m
                        } else {
                            0.0
                        };
                    }
                }
            }
            MassMatrix::Consistent => {
                let mut rhs = std::mem::take(&mut self.rhs);
                for k in 0..D {
                    let free = &self.free[k];
                    rhs.clear();
                    rhs.extend(free.iter().map(|&i| field[i as usize][k]));
                    self.factors[k].solve(&mut rhs);
                    for x in field.iter_mut() {
                        x[k] = 0.0;
                    }
                    for (&i, &x) in free.iter().zip(&rhs) {
                        field[i as usize][k] = x;
                    }
                }
                self.rhs = rhs;
            }
        }
    }

    /// The grid solve with this matrix: a = M^-1 f, v_new = v + kick a, fixed components
    /// and empty DOFs held at zero. Afterwards `force` holds a.
    pub fn solve_grid(&mut self, grid: &mut GridState<D>, kick: f64) {
        self.solve(&grid.mass, grid.empty_mass, &mut grid.force);
        for i in 0..grid.mass.len() {
            grid.velocity_new[i] = grid.velocity[i] + grid.force[i] * kick;
        }
    }
}
