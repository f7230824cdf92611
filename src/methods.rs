//! The method catalogue. A method is a composition of a shape function, a particle-to-grid
//! transfer and a time integrator; the paper names are presets over those parts.

use std::fmt;

use crate::reconstruct::{
    Degree, Kernel, MassMatrix, QuadratureRecipe, Recipe, Solver, TaylorRecipe, Weight,
};
use crate::shape::DomainShape;

/// Basis functions used on the background grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeKind {
    /// Piecewise-linear hat (tensor product in 2D), Gong eq 4.8.
    Linear,
    /// The hat averaged over each particle's domain (GIMP, CPDI; Gong ch. 6).
    Domain(DomainShape),
    /// Quadratic B-splines on the open knot vector 0, 0, 0, h, ..., L, L, L (tensor product
    /// in 2D): cells + 2 DOFs per axis (BSMPM; Steffen et al. 2008, Tielen et al. 2017).
    QuadraticBSpline,
    /// The hat's values with the dual-domain gradient, the hat's gradient averaged over the
    /// material under each node's hat (DDMPM; Zhang, Ma & Giguere 2011).
    DualDomain,
}

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
    /// Taylor least squares per element: stress fitted freely, density and momentum with the
    /// element's mass and momentum prescribed, integrated by Gauss quadrature (Wobbes et al.
    /// sec 3).
    Taylor(TaylorRecipe),
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

impl Method {
    /// Whether the basis takes the particles' domains from the seed lattice's sub-cells.
    pub fn reads_seed_domains(&self) -> bool {
        matches!(self.shape, ShapeKind::Domain(_))
    }
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

/// Wobbes et al. sec 5: quadratic TLS (n_b = 3 in 1D), two Gauss points per element and
/// axis, velocity and acceleration solved with the consistent mass matrix (eqs 9-11).
const TLS: TaylorRecipe = TaylorRecipe {
    degree: 2,
    gauss_points: 2,
    mass: MassMatrix::Consistent,
};

/// TLS with the lumped mass matrix, which sec 3 allows without losing conservation.
const TLS_LUMPED: TaylorRecipe = TaylorRecipe {
    mass: MassMatrix::Lumped,
    ..TLS
};

const fn on_domains(
    shape: DomainShape,
    transfer: TransferKind,
    integrator: IntegratorKind,
) -> Method {
    Method {
        shape: ShapeKind::Domain(shape),
        transfer,
        integrator,
    }
}

const fn musl_on(shape: ShapeKind, transfer: TransferKind) -> Method {
    Method {
        shape,
        transfer,
        integrator: IntegratorKind::Musl,
    }
}

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
    MethodPreset {
        name: "mpm_tls",
        method: musl_on(ShapeKind::Linear, TransferKind::Taylor(TLS)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3",
        description: "MPM with the conservative TLS mapping and the consistent mass matrix, MUSL",
    },
    MethodPreset {
        name: "mpm_tls_lumped",
        method: musl_on(ShapeKind::Linear, TransferKind::Taylor(TLS_LUMPED)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3 (lumped option)",
        description: "MPM with the conservative TLS mapping and the lumped mass matrix, MUSL",
    },
    MethodPreset {
        name: "ugimp",
        method: on_domains(
            DomainShape::FixedBox,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Bardenhagen & Kober 2004; Gong 2015, sec 6.3",
        description: "uGIMP: the hat averaged over the initial particle box, leapfrog",
    },
    MethodPreset {
        name: "cpgimp",
        method: on_domains(
            DomainShape::StretchedBox,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Bardenhagen & Kober 2004; Gong 2015, sec 6.3",
        description: "cpGIMP: the particle box stretched by the diagonal of F, leapfrog",
    },
    MethodPreset {
        name: "cpdi1",
        method: on_domains(
            DomainShape::Parallelogram,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Sadeghirad et al. 2011; Gong 2015, sec 6.4",
        description: "CPDI1: parallelogram domains r_k = F r_k^0, leapfrog",
    },
    MethodPreset {
        name: "cpdi1_musl",
        method: on_domains(
            DomainShape::Parallelogram,
            TransferKind::Shepard,
            IntegratorKind::Musl,
        ),
        source: "Sadeghirad et al. 2011 in the scheme of Tran et al. 2019, eqs 31-40",
        description: "CPDI1 with the modified update-stress-last step",
    },
    MethodPreset {
        name: "cpdi2",
        method: on_domains(
            DomainShape::Quadrilateral,
            TransferKind::Shepard,
            IntegratorKind::Leapfrog,
        ),
        source: "Sadeghirad et al. 2013; Gong 2015, secs 6.5-6.6",
        description: "CPDI2: domain corners moved with the grid velocity, leapfrog",
    },
    MethodPreset {
        name: "cpdi_mls",
        method: on_domains(
            DomainShape::Quadrilateral,
            TransferKind::FittedVelocity(IMPM.velocity),
            IntegratorKind::Leapfrog,
        ),
        source: "Gong 2015, sec 6.6 (improved CPDI)",
        description: "CPDI2 with IMPM's MLS velocity at the nodes (cubic spline), leapfrog",
    },
    MethodPreset {
        name: "bsmpm",
        method: musl_on(ShapeKind::QuadraticBSpline, TransferKind::Shepard),
        source: "Steffen et al. 2008; Tielen et al. 2017; Wobbes et al. 2018",
        description: "B-spline MPM: quadratic B-splines, open knot vector, lumped mass, MUSL",
    },
    MethodPreset {
        name: "ddmpm",
        method: musl_on(ShapeKind::DualDomain, TransferKind::Shepard),
        source: "Zhang, Ma & Giguere 2011; Wobbes et al. 2018",
        description: "dual-domain MPM: hat values, node-averaged gradient, lumped mass, MUSL",
    },
    MethodPreset {
        name: "bsmpm_tls",
        method: musl_on(ShapeKind::QuadraticBSpline, TransferKind::Taylor(TLS)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3",
        description: "B-spline MPM with the conservative TLS mapping on each knot span, MUSL",
    },
    MethodPreset {
        name: "ddmpm_tls",
        method: musl_on(ShapeKind::DualDomain, TransferKind::Taylor(TLS)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3",
        description: "dual-domain MPM with the conservative TLS mapping, MUSL",
    },
    MethodPreset {
        name: "ddmpm_tls_lumped",
        method: musl_on(ShapeKind::DualDomain, TransferKind::Taylor(TLS_LUMPED)),
        source: "Wobbes, Moller, Galavi, Vuik 2018, sec 3 (lumped option)",
        description:
            "dual-domain MPM with the conservative TLS mapping and the lumped mass matrix, MUSL",
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
        match self {
            ShapeKind::Linear => f.write_str("linear"),
            ShapeKind::Domain(shape) => write!(f, "domain({shape})"),
            ShapeKind::QuadraticBSpline => f.write_str("quadratic-bspline"),
            ShapeKind::DualDomain => f.write_str("dual-domain"),
        }
    }
}

impl fmt::Display for TransferKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TransferKind::Shepard => f.write_str("shepard"),
            TransferKind::Quadrature(recipe) => write!(f, "quadrature({recipe})"),
            TransferKind::FittedVelocity(recipe) => write!(f, "fitted-velocity({recipe})"),
            TransferKind::Taylor(recipe) => write!(f, "taylor({recipe})"),
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
