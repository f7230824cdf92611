//! The particle-to-grid transfers a method can map with, by name: the registry that
//! experiment files' `transfer` parameter and the method presets choose from, with the recipes
//! of the papers' transfers.

use std::fmt;

use super::{
    BodyForceFit, Degree, Kernel, MassMatrix, NodalVelocity, QuadratureRecipe, Recipe, Solver,
    TaylorRecipe, Weight,
};
use crate::catalog::{names_of, Catalog, Entry, Parts};

/// How particle data reaches the grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransferKind {
    /// Mass-weighted nodal averages (Shepard interpolation with w = M_p N_i), Gong sec 4.3.1.
    Shepard,
    /// Least-squares fits evaluated at nodes and quadrature points (IMPM, IMLS-MPM).
    Quadrature(QuadratureRecipe),
    /// Mass and forces lumped as in `Shepard`, the nodal velocity a least-squares fit of the
    /// particle velocities (improved CPDI, Gong sec 6.6).
    FittedVelocity(Recipe),
    /// The sums of `Shepard` solved with the consistent mass matrix of the particle
    /// quadrature, M_ij = sum_p M_p N_ip N_jp, for the velocity (Wobbes et al. eq 8 with the
    /// full matrix), the acceleration and MUSL's remap.
    ConsistentMass,
    /// Taylor least squares per element: stress fitted freely, density and momentum with the
    /// element's mass and momentum prescribed, integrated by Gauss quadrature (Wobbes et al.
    /// sec 3).
    Taylor(TaylorRecipe),
}

impl fmt::Display for TransferKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TransferKind::Shepard => f.write_str("shepard"),
            TransferKind::ConsistentMass => f.write_str("consistent-mass"),
            TransferKind::Quadrature(recipe) => write!(f, "quadrature({recipe})"),
            TransferKind::FittedVelocity(recipe) => write!(f, "fitted-velocity({recipe})"),
            TransferKind::Taylor(recipe) => write!(f, "taylor({recipe})"),
        }
    }
}

const fn recipe(weight: Weight, scale: f64, solver: Solver) -> Recipe {
    Recipe {
        kernel: Kernel { weight, scale },
        degree: Degree::LINEAR,
        solver,
    }
}

/// Gong sec 5.3, eq 5.6: the nodal velocity by linear MLS with the cubic spline.
pub const IMPM_VELOCITY: Recipe = recipe(Weight::CubicSpline, 1.0, Solver::Mls);

/// Gong sec 5.3: velocity by linear MLS with the cubic spline, density, stress and body
/// force by linear MLS with the quadratic spline at the cell centres.
pub const IMPM: QuadratureRecipe = QuadratureRecipe {
    velocity: NodalVelocity::Fit(IMPM_VELOCITY),
    fields: recipe(Weight::QuadraticSpline, 1.0, Solver::Mls),
    gauss_points: 1,
    body_force: BodyForceFit::Separate,
};

/// IMPM's field fits and cell-centre quadrature (Gong eqs 5.7-5.14) with the original MPM's
/// mass-weighted nodal velocity in place of eq 5.6: the field half of IMPM alone.
pub const IMPM_FIELDS: QuadratureRecipe = QuadratureRecipe {
    velocity: NodalVelocity::Shepard,
    ..IMPM
};

/// Tran eqs 24-31: velocity by IMLS with the hat weight, density, stress and body force by
/// IMLS with the quadratic spline at 2 Gauss points per cell and axis, which integrate
/// N_i times a linear field exactly. The quadratic spline is scaled with h as Gong does;
/// `imls_eq27` scales it with 2h as Tran's eq 27 prints.
pub const IMLS: QuadratureRecipe = QuadratureRecipe {
    velocity: NodalVelocity::Fit(recipe(Weight::Hat, 1.0, Solver::Imls)),
    fields: recipe(Weight::QuadraticSpline, 1.0, Solver::Imls),
    gauss_points: 2,
    body_force: BodyForceFit::Separate,
};

/// IMLS-MPM as the CPLS code of Tran et al. runs it (`Compute_Interpolator_IMLS_MPM`,
/// `Interpolate_Particle_To_Grid_MLS`): the fields at the cell centre (one point per cell),
/// the body force as one fit of rho_p b_p.
pub const IMLS_CPLS: QuadratureRecipe = QuadratureRecipe {
    gauss_points: 1,
    body_force: BodyForceFit::Product,
    ..IMLS
};

pub const IMLS_EQ27: QuadratureRecipe = QuadratureRecipe {
    fields: recipe(Weight::QuadraticSpline, 2.0, Solver::Imls),
    ..IMLS
};

/// Wobbes et al. sec 5: quadratic TLS (n_b = 3 in 1D), two Gauss points per element and
/// axis, velocity and acceleration solved with the consistent mass matrix (eqs 9-11).
pub const TLS: TaylorRecipe = TaylorRecipe {
    degree: 2,
    gauss_points: 2,
    mass: MassMatrix::Consistent,
};

/// TLS with the lumped mass matrix, which sec 3 allows without losing conservation.
pub const TLS_LUMPED: TaylorRecipe = TaylorRecipe {
    mass: MassMatrix::Lumped,
    ..TLS
};

const ENTRIES: &[Entry<TransferKind>] = &[
    Entry {
        name: "shepard",
        value: TransferKind::Shepard,
        description: "mass-weighted nodal averages, lumped mass (Gong sec 4.3.1)",
    },
    Entry {
        name: "consistent_mass",
        value: TransferKind::ConsistentMass,
        description: "the Shepard sums solved with the consistent mass matrix (Wobbes et al. eq 8)",
    },
    Entry {
        name: "impm",
        value: TransferKind::Quadrature(IMPM),
        description: "MLS velocity at the nodes, MLS density and stress at cell centres (Gong \
                      ch. 5)",
    },
    Entry {
        name: "impm_fields",
        value: TransferKind::Quadrature(IMPM_FIELDS),
        description: "IMPM's field fits at cell centres with the mass-weighted nodal velocity",
    },
    Entry {
        name: "mls_velocity",
        value: TransferKind::FittedVelocity(IMPM_VELOCITY),
        description: "lumped mass and forces, the nodal velocity IMPM's MLS fit (Gong sec 6.6)",
    },
    Entry {
        name: "imls",
        value: TransferKind::Quadrature(IMLS),
        description: "IMLS velocity at the nodes, IMLS fields at 2 Gauss points (Tran et al.)",
    },
    Entry {
        name: "imls_cpls",
        value: TransferKind::Quadrature(IMLS_CPLS),
        description: "IMLS fields and rho b at the cell centre, as the CPLS code runs them",
    },
    Entry {
        name: "imls_eq27",
        value: TransferKind::Quadrature(IMLS_EQ27),
        description: "IMLS with the field weight scaled by 2h, as Tran's eq 27 prints",
    },
    Entry {
        name: "tls",
        value: TransferKind::Taylor(TLS),
        description: "Taylor least squares per element, consistent mass (Wobbes et al. sec 3)",
    },
    Entry {
        name: "tls_lumped",
        value: TransferKind::Taylor(TLS_LUMPED),
        description: "Taylor least squares per element, lumped mass",
    },
];

pub const TRANSFERS: Parts<TransferKind> = Catalog {
    kind: "transfer",
    entries: ENTRIES,
};

/// The names the `transfer` parameter takes.
pub const TRANSFER_NAMES: [&str; ENTRIES.len()] = names_of(ENTRIES);
