//! The catalogue of reconstruction methods, the `method` of the reconstruction benchmarks.
//! A method fixes the polynomial basis and how the local least-squares system is solved; the
//! weight function is a benchmark parameter, because the papers compare bases and solvers
//! while leaving the weight to the reader (Gong sec 5.2) or choosing it per field.

use crate::reconstruct::{Degree, Solver};

pub struct ReconstructionMethod {
    pub name: &'static str,
    pub degree: Degree,
    pub solver: Solver,
    pub source: &'static str,
    pub description: &'static str,
}

const METHODS: &[ReconstructionMethod] = &[
    ReconstructionMethod {
        name: "shepard",
        degree: Degree::CONSTANT,
        // With one basis function both solvers divide by the sum of the weights.
        solver: Solver::Mls,
        source: "Gong 2015, eqs 4.6-4.8",
        description:
            "Shepard interpolation (first-order MLS): weighted average, reproduces constants",
    },
    ReconstructionMethod {
        name: "mls_linear",
        degree: Degree::LINEAR,
        solver: Solver::Mls,
        source: "Gong 2015, sec 3.5 and 5.2",
        description: "second-order MLS: linear basis, moment matrix inverted",
    },
    ReconstructionMethod {
        name: "mls_quadratic",
        degree: Degree::QUADRATIC,
        solver: Solver::Mls,
        source: "Gong 2015, sec 3.4",
        description: "MLS with a quadratic basis, moment matrix inverted",
    },
    ReconstructionMethod {
        name: "imls_linear",
        degree: Degree::LINEAR,
        solver: Solver::Imls,
        source: "Tran et al. 2019, eqs 11-17",
        description:
            "IMLS: linear basis orthogonalised, polynomials the data cannot support dropped",
    },
    ReconstructionMethod {
        name: "imls_quadratic",
        degree: Degree::QUADRATIC,
        solver: Solver::Imls,
        source: "Tran et al. 2019, eqs 11-17",
        description:
            "IMLS: quadratic basis orthogonalised, polynomials the data cannot support dropped",
    },
];

pub fn methods() -> &'static [ReconstructionMethod] {
    METHODS
}

pub fn method(name: &str) -> Option<&'static ReconstructionMethod> {
    METHODS.iter().find(|m| m.name == name)
}

pub fn method_names() -> Vec<&'static str> {
    METHODS.iter().map(|m| m.name).collect()
}
