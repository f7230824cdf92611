//! Time integration: the grid solve and the particle update.

mod deform;
mod kind;
pub mod leapfrog;
pub mod musl;
pub mod predictor_corrector;

use nalgebra::SVector;

pub use deform::deform_particles;
pub use kind::{IntegratorKind, INTEGRATORS, INTEGRATOR_NAMES};

use crate::grid::{FixedDof, GridState};

/// The grid solve (Gong eqs 4.23-4.24, Tran eqs 32-33): a_i = f_i / m_i, then
/// v_i^new = v_i + kick a_i, with empty nodes at rest and fixed components held at zero.
/// Afterwards `force` holds a_i.
pub fn solve_grid<const D: usize>(grid: &mut GridState<D>, fixed: &[FixedDof], kick: f64) {
    for i in 0..grid.mass.len() {
        let m = grid.mass[i];
        if m > grid.empty_mass {
            grid.force[i] /= m;
        } else {
            grid.velocity[i] = SVector::zeros();
            grid.force[i] = SVector::zeros();
        }
    }
    for &(i, k) in fixed {
        grid.velocity[i as usize][k as usize] = 0.0;
        grid.force[i as usize][k as usize] = 0.0;
    }
    for i in 0..grid.mass.len() {
        grid.velocity_new[i] = grid.velocity[i] + grid.force[i] * kick;
    }
}

/// Holds the fixed velocity components of a nodal field at zero.
pub fn apply_fixed<const D: usize>(velocity: &mut [SVector<f64, D>], fixed: &[FixedDof]) {
    for &(i, k) in fixed {
        velocity[i as usize][k as usize] = 0.0;
    }
}
