//! The method catalogue. A method is a composition of a shape function, a particle-to-grid
//! transfer and a time integrator; the paper names are presets over those parts.

use std::fmt;

use crate::reconstruct::{Degree, Kernel, QuadratureRecipe, Recipe, Solver, Weight};

/// Basis functions used on the background grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeKind {
    /// Piecewise-linear hat (tensor product in 2D), Gong eq 4.8.
    Linear,
}

/// How particle data reaches the grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransferKind {
    /// Mass-weighted nodal averages (Shepard interpolation with w = M_p N_i), Gong sec 4.3.1.
    Shepard,
    /// Least-squares fits evaluated at nodes and quadrature points (IMPM, IMLS-MPM).
    Quadrature(QuadratureRecipe),
}

/// How the grid equations are advanced in time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Leapfrog with half-step velocities and the particle update of Gong sec 4.4.
    Leapfrog,
    /// Whole-step velocities, particles moved first, velocity gradient from the nodal
    /// velocity rebuilt from the moved particles (Tran eqs 31-40; Sulsky's MUSL).
    Musl,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Method {
    pub shape: ShapeKind,
    pub transfer: TransferKind,
    pub integrator: IntegratorKind,
}

pub struct MethodPreset {
    pub name: &'static str,
    pub method: Method,
    pub source: &'static str,
    pub description: &'static str,
}

const fn recipe(weight: Weight, scale: f64, solver: Solver) -> Recipe {
    Recipe {
        kernel: Kernel { weight, scale },
        degree: Degree::LINEAR,
        solver,
    }
}

/// Gong sec 5.3: velocity by linear MLS with the cubic spline, density, stress and body
/// force by linear MLS with the quadratic spline at the cell centres.
const IMPM: QuadratureRecipe = QuadratureRecipe {
    velocity: recipe(Weight::CubicSpline, 1.0, Solver::Mls),
    fields: recipe(Weight::QuadraticSpline, 1.0, Solver::Mls),
    gauss_points: 1,
};

/// Tran eqs 24-31: velocity by IMLS with the hat weight, density, stress and body force by
/// IMLS with the quadratic spline at 2 Gauss points per cell and axis, which integrate
/// N_i times a linear field exactly. The quadratic spline is scaled with h as Gong does;
/// `imls_eq27` scales it with 2h as Tran's eq 27 prints.
const IMLS: QuadratureRecipe = QuadratureRecipe {
    velocity: recipe(Weight::Hat, 1.0, Solver::Imls),
    fields: recipe(Weight::QuadraticSpline, 1.0, Solver::Imls),
    gauss_points: 2,
};

const IMLS_EQ27: QuadratureRecipe = QuadratureRecipe {
    fields: recipe(Weight::QuadraticSpline, 2.0, Solver::Imls),
    ..IMLS
};

const PRESETS: &[MethodPreset] = &[
    MethodPreset {
        name: "mpm",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Shepard,
            integrator: IntegratorKind::Leapfrog,
        },
        source: "Gong 2015, ch. 4",
        description: "original MPM: linear hat basis, lumped mass, leapfrog",
    },
    MethodPreset {
        name: "mpm_musl",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Shepard,
            integrator: IntegratorKind::Musl,
        },
        source: "Sulsky et al. 1994; Tran et al. 2019, eqs 31-40 with Shepard mapping",
        description: "original MPM mapping with the modified update-stress-last step",
    },
    MethodPreset {
        name: "impm",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMPM),
            integrator: IntegratorKind::Leapfrog,
        },
        source: "Gong 2015, ch. 5",
        description: "improved MPM: MLS velocity at nodes, MLS density/stress at cell centres",
    },
    MethodPreset {
        name: "imls",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMLS),
            integrator: IntegratorKind::Musl,
        },
        source: "Tran, Berzins, Solowski 2019",
        description: "IMLS-MPM: IMLS velocity at nodes, IMLS fields at 2 Gauss points, MUSL",
    },
    MethodPreset {
        name: "imls_eq27",
        method: Method {
            shape: ShapeKind::Linear,
            transfer: TransferKind::Quadrature(IMLS_EQ27),
            integrator: IntegratorKind::Musl,
        },
        source: "Tran, Berzins, Solowski 2019, eq 27 as printed",
        description: "IMLS-MPM with the field weight scaled by 2h (support 3h)",
    },
];

pub fn presets() -> &'static [MethodPreset] {
    PRESETS
}

pub fn preset(name: &str) -> Option<&'static MethodPreset> {
    PRESETS.iter().find(|p| p.name == name)
}

pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

impl fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ShapeKind::Linear => "linear",
        })
    }
}

impl fmt::Display for TransferKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TransferKind::Shepard => f.write_str("shepard"),
            TransferKind::Quadrature(recipe) => write!(f, "quadrature({recipe})"),
        }
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            IntegratorKind::Leapfrog => "leapfrog",
            IntegratorKind::Musl => "musl",
        })
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "shape={} transfer={} integrate={}",
            self.shape, self.transfer, self.integrator
        )
    }
}
