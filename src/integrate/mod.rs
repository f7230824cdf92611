//! Time integration: the grid solve and the particle update.

pub mod leapfrog;

use std::fmt;

/// Why a run stopped early. Recorded in the run file's `message` with the step.
#[derive(Clone, Debug, PartialEq)]
pub enum Divergence {
    LeftGrid { particle: usize },
    Jacobian { particle: usize, j: f64 },
    NonFinite { particle: usize, what: &'static str },
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
        }
    }
}
