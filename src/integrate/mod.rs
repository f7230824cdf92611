//! Time integration: the grid solve and the particle update.

mod deform;
pub mod leapfrog;
pub mod musl;
pub mod predictor_corrector;

use std::fmt;

use nalgebra::SVector;

pub use deform::deform_particles;

use crate::reconstruct::GridState;
use crate::shape::DomainFault;

/// Why a run stopped early. Recorded in the run file's `message` with the step.
#[derive(Clone, Debug, PartialEq)]
pub enum Divergence {
    LeftGrid {
        particle: usize,
    },
    Jacobian {
        particle: usize,
        j: f64,
    },
    NonFinite {
        particle: usize,
        what: &'static str,
    },
    /// A reconstruction could not be solved (MLS with a singular moment matrix).
    Reconstruction(String),
    /// A particle domain could not be mapped (GIMP, CPDI).
    Domain(DomainFault),
}

impl From<DomainFault> for Divergence {
    fn from(fault: DomainFault) -> Self {
        match fault {
            DomainFault::Outside(particle) => Divergence::LeftGrid { particle },
            fault => Divergence::Domain(fault),
        }
    }
}

impl fmt::Display for Divergence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Divergence::LeftGrid { particle } => write!(f, "particle {particle} left the grid"),
            Divergence::Jacobian { particle, j } => {
                write!(f, "particle {particle} has J = {j:e} <= 0")
            }
            Divergence::NonFinite { particle, what } => {
                write!(f, "particle {particle} has a non-finite {what}")
            }
            Divergence::Reconstruction(reason) => f.write_str(reason),
            Divergence::Domain(fault) => write!(f, "{fault}"),
        }
    }
}

/// A velocity component held at zero: (node, axis).
pub type FixedDof = (u32, u8);

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
