//! The catalogue of reconstruction methods, the `method` of the reconstruction benchmarks.
//! A method fixes the polynomial basis and how the least-squares system is solved: locally
//! about each grid node (MLS, IMLS), whose weight function is a benchmark parameter because
//! the papers compare bases and solvers while leaving the weight to the reader (Gong sec 5.2)
//! or choosing it per field; or element by element in the Taylor basis (TLS), unweighted.

use std::fmt;

use crate::catalog::{Catalog, Named};
use crate::reconstruct::{Conservation, Degree, Solver};

pub struct ReconstructionMethod {
    pub name: &'static str,
    pub degree: Degree,
    pub fit: Fit,
    pub source: &'static str,
    pub description: &'static str,
}

impl Named for ReconstructionMethod {
    fn name(&self) -> &'static str {
        self.name
    }
}

/// Where a method fits and how it solves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fit {
    /// A weighted local fit about each evaluation point (the nodal benchmarks).
    Local(Solver),
    /// Taylor least squares per element, a_1 prescribed or fitted (the element-wise benchmark).
    Taylor(Conservation),
}

impl fmt::Display for Fit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Fit::Local(solver) => write!(f, "{solver}"),
            Fit::Taylor(conservation) => write!(f, "tls, a_1 {conservation}"),
        }
    }
}

impl ReconstructionMethod {
    /// Whether the method fits element by element (else about each evaluation point).
    pub fn is_elementwise(&self) -> bool {
        matches!(self.fit, Fit::Taylor(_))
    }
}

pub const METHODS: Catalog<ReconstructionMethod> = Catalog {
    kind: "reconstruction method",
    entries: &[
        ReconstructionMethod {
            name: "shepard",
            degree: Degree::CONSTANT,
            // With one basis function both solvers divide by the sum of the weights.
            fit: Fit::Local(Solver::Mls),
            source: "Gong 2015, eqs 4.6-4.8",
            description:
                "Shepard interpolation (first-order MLS): weighted average, reproduces constants",
        },
        ReconstructionMethod {
            name: "mls_linear",
            degree: Degree::LINEAR,
            fit: Fit::Local(Solver::Mls),
            source: "Gong 2015, sec 3.5 and 5.2",
            description: "second-order MLS: linear basis, moment matrix inverted",
        },
        ReconstructionMethod {
            name: "mls_quadratic",
            degree: Degree::QUADRATIC,
            fit: Fit::Local(Solver::Mls),
            source: "Gong 2015, sec 3.4",
            description: "MLS with a quadratic basis, moment matrix inverted",
        },
        ReconstructionMethod {
            name: "imls_linear",
            degree: Degree::LINEAR,
            fit: Fit::Local(Solver::Imls),
            source: "Tran et al. 2019, eqs 11-17",
            description:
                "IMLS: linear basis orthogonalised, polynomials the data cannot support dropped",
        },
        ReconstructionMethod {
            name: "imls_quadratic",
            degree: Degree::QUADRATIC,
            fit: Fit::Local(Solver::Imls),
            source: "Tran et al. 2019, eqs 11-17",
            description:
                "IMLS: quadratic basis orthogonalised, polynomials the data cannot support dropped",
        },
        ReconstructionMethod {
            name: "tls_fixed",
            degree: Degree::QUADRATIC,
            fit: Fit::Taylor(Conservation::Fixed),
            source: "Wobbes et al. 2018, sec 2, eq 5",
            description: "Taylor least squares per element, quadratic; a_1 = the element mean, \
                      which conserves the element integral",
        },
        ReconstructionMethod {
            name: "tls_fitted",
            degree: Degree::QUADRATIC,
            fit: Fit::Taylor(Conservation::Fitted),
            source: "Wobbes et al. 2018, sec 2, eq 1",
            description: "Taylor least squares per element, quadratic; every coefficient fitted",
        },
    ],
};
