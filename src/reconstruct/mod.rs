//! Particle-to-grid transfers: what each method reconstructs on the grid from particle data,
//! and the local least-squares reconstructions (Shepard, MLS, IMLS) they are built from.

mod basis;
mod kernel;
mod lattice;
mod least_squares;
mod shepard;
mod solve;
#[cfg(test)]
mod tests;

use nalgebra::SVector;

pub use basis::{monomials, Degree, MAX_TERMS};
pub use kernel::{Kernel, Weight};
pub use lattice::Lattice;
pub use least_squares::{
    FitStats, Recipe, Reconstructor, SingularMoments, Solver, MAX_NODE_SUPPORT_CELLS,
};
pub use shepard::particles_to_grid;
pub use solve::{moment_matrix, Moments, OrthogonalBasis, RANK_TOLERANCE};

/// Nodal quantities assembled from the particles each step.
pub struct GridState<const D: usize> {
    /// Lumped mass m_i.
    pub mass: Vec<f64>,
    /// Momentum (m v)_i, then the velocity v_i^{s-1/2} once the grid is solved.
    pub momentum: Vec<SVector<f64, D>>,
    /// Internal plus external force f_i, then the acceleration a_i once the grid is solved.
    pub force: Vec<SVector<f64, D>>,
    /// v_i^{s+1/2}.
    pub velocity: Vec<SVector<f64, D>>,
}

impl<const D: usize> GridState<D> {
    pub fn new(nodes: usize) -> Self {
        GridState {
            mass: vec![0.0; nodes],
            momentum: vec![SVector::zeros(); nodes],
            force: vec![SVector::zeros(); nodes],
            velocity: vec![SVector::zeros(); nodes],
        }
    }

    pub fn clear(&mut self) {
        self.mass.fill(0.0);
        self.momentum.fill(SVector::zeros());
        self.force.fill(SVector::zeros());
    }
}
