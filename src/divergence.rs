//! Why a run stopped early, and why a particle domain could not be mapped: what every
//! layer of a step may report, recorded in the run file.

use std::fmt;

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

/// Why the stencils of a particle could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DomainFault {
    /// The particle (or, for CPDI2, a corner of its domain) left the grid.
    Outside(usize),
    /// The domain spans more than `max_cells` cells along some axis (the most its stencil
    /// block covers).
    TooWide { particle: usize, max_cells: usize },
    /// The domain has no positive volume (an inverted quadrilateral).
    Inverted(usize),
    /// A CPDI2 corner left the grid.
    CornerOutside(usize),
}

impl fmt::Display for DomainFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DomainFault::Outside(p) => write!(f, "particle {p} left the grid"),
            DomainFault::TooWide {
                particle,
                max_cells,
            } => write!(
                f,
                "the domain of particle {particle} spans more than {max_cells} cells"
            ),
            DomainFault::Inverted(p) => write!(f, "the domain of particle {p} is inverted"),
            DomainFault::CornerOutside(c) => write!(f, "domain corner {c} left the grid"),
        }
    }
}
