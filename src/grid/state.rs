//! The nodal state a step assembles on the grid, and the velocity components held fixed.

use nalgebra::SVector;

use crate::fallible::filled;

/// A velocity component held at zero: (node, axis).
pub type FixedDof = (u32, u8);

/// Nodal quantities assembled from the particles each step.
pub struct GridState<const D: usize> {
    /// Lumped mass m_i.
    pub mass: Vec<f64>,
    /// Nodal velocity at the start of the step (v_i^{s-1/2} for leapfrog, v_i^t for MUSL).
    pub velocity: Vec<SVector<f64, D>>,
    /// Internal plus external force f_i, then the acceleration a_i once the grid is solved.
    pub force: Vec<SVector<f64, D>>,
    /// Nodal velocity at the end of the step.
    pub velocity_new: Vec<SVector<f64, D>>,
    /// Nodes at or below this mass are empty: the hat's gradient does not vanish where its
    /// value does, so a node touched only at N ~ 0 would get an unbounded acceleration.
    pub empty_mass: f64,
}

/// Empty-node threshold as a fraction of the largest particle mass.
const EMPTY_NODE_FRACTION: f64 = 1e-12;

impl<const D: usize> GridState<D> {
    pub fn new(nodes: usize, particle_mass: f64) -> Self {
        GridState {
            mass: filled(nodes, 0.0, "the nodal masses"),
            velocity: filled(nodes, SVector::zeros(), "the nodal velocities"),
            force: filled(nodes, SVector::zeros(), "the nodal forces"),
            velocity_new: filled(nodes, SVector::zeros(), "the nodal velocities"),
            empty_mass: EMPTY_NODE_FRACTION * particle_mass,
        }
    }

    pub fn clear(&mut self) {
        self.mass.fill(0.0);
        self.velocity.fill(SVector::zeros());
        self.force.fill(SVector::zeros());
    }
}
