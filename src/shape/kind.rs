//! The shape functions a method can run on, by name: the registry that experiment files'
//! `shape` parameter and the method presets choose from.

use std::fmt;

use super::{DomainShape, DualIntegrals, SplineDegree, DEFAULT_TOLERANCE};
use crate::catalog::{names_of, Catalog, Entry, Parts};
use crate::grid::Dofs;

/// Basis functions used on the background grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeKind {
    /// Piecewise-linear hat (tensor product in 2D), Gong eq 4.8.
    Linear,
    /// The hat averaged over each particle's domain (GIMP, CPDI; Gong ch. 6).
    Domain(DomainShape),
    /// B-splines on the open knot vector, e.g. 0, 0, 0, h, ..., L, L, L for the quadratic
    /// (tensor product in 2D): cells + degree DOFs per axis (BSMPM; Steffen et al. 2008,
    /// Tielen et al. 2017).
    BSpline(SplineDegree),
    /// The hat's values with the dual-domain gradient, the hat's gradient averaged over the
    /// material under each node's hat (DDMPM; Zhang, Ma & Giguere 2011), the integrals taken
    /// as given.
    DualDomain(DualIntegrals),
    /// Local maximum-entropy functions on the grid nodes (Arroyo & Ortiz 2006; Molinos et al.
    /// sec 5), with the locality gamma and the neighbour cut-off of the run.
    LocalMaxEnt(LmeSettings),
}

/// The parameters of the LME basis: gamma = beta h^2 and the prior weight exp(-beta r^2) below
/// which a node is left out of a point's stencil.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LmeSettings {
    pub gamma: f64,
    pub tolerance: f64,
}

impl fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ShapeKind::Linear => f.write_str("linear"),
            ShapeKind::Domain(shape) => write!(f, "domain({shape})"),
            ShapeKind::BSpline(degree) => write!(f, "{}-bspline", degree.word()),
            ShapeKind::DualDomain(DualIntegrals::Particles) => {
                f.write_str("dual-domain(particles)")
            }
            ShapeKind::DualDomain(DualIntegrals::ActiveCells) => f.write_str("dual-domain(cells)"),
            ShapeKind::LocalMaxEnt(lme) => {
                write!(f, "lme(gamma={}, tolerance={})", lme.gamma, lme.tolerance)
            }
        }
    }
}

/// The LME basis before a run gives it its gamma.
pub const LME_UNSET: ShapeKind = ShapeKind::LocalMaxEnt(LmeSettings {
    gamma: f64::NAN,
    tolerance: DEFAULT_TOLERANCE,
});

const ENTRIES: &[Entry<ShapeKind>] = &[
    Entry {
        name: "linear",
        value: ShapeKind::Linear,
        description: "the linear hat (Gong eq 4.8)",
    },
    Entry {
        name: "ugimp",
        value: ShapeKind::Domain(DomainShape::FixedBox),
        description: "the hat averaged over the initial particle box (uGIMP)",
    },
    Entry {
        name: "cpgimp",
        value: ShapeKind::Domain(DomainShape::StretchedBox),
        description: "the hat averaged over the box stretched by the diagonal of F (cpGIMP)",
    },
    Entry {
        name: "cpdi1",
        value: ShapeKind::Domain(DomainShape::Parallelogram),
        description: "the hat averaged over the parallelogram F r_k^0 (CPDI1)",
    },
    Entry {
        name: "cpdi2",
        value: ShapeKind::Domain(DomainShape::Quadrilateral),
        description: "the hat averaged over the quadrilateral of the moved corners (CPDI2)",
    },
    Entry {
        name: "quadratic_bspline",
        value: ShapeKind::BSpline(SplineDegree::Quadratic),
        description: "quadratic B-splines on the open knot vector (BSMPM)",
    },
    Entry {
        name: "cubic_bspline",
        value: ShapeKind::BSpline(SplineDegree::Cubic),
        description: "cubic B-splines on the open knot vector",
    },
    Entry {
        name: "dual_domain",
        value: ShapeKind::DualDomain(DualIntegrals::Particles),
        description: "hat values, gradients averaged by particle sums over each node's dual \
                          domain (DDMPM)",
    },
    Entry {
        name: "dual_domain_cells",
        value: ShapeKind::DualDomain(DualIntegrals::ActiveCells),
        description: "the dual-domain gradient integrated exactly over the active cells",
    },
    Entry {
        name: "lme",
        value: LME_UNSET,
        description: "local max-ent functions on the nodes, gamma from the run (Molinos et al.)",
    },
];

pub const SHAPES: Parts<ShapeKind> = Catalog {
    kind: "shape function",
    entries: ENTRIES,
};

/// The names the `shape` parameter takes.
pub const SHAPE_NAMES: [&str; ENTRIES.len()] = names_of(ENTRIES);

impl ShapeKind {
    /// Where the basis puts its DOFs: the B-spline's at the Greville abscissae, every other
    /// basis's at the grid nodes.
    pub fn dofs(&self) -> Dofs {
        match self {
            ShapeKind::BSpline(degree) => degree.dofs(),
            ShapeKind::Linear
            | ShapeKind::Domain(_)
            | ShapeKind::DualDomain(_)
            | ShapeKind::LocalMaxEnt(_) => Dofs::Nodes,
        }
    }

    /// Whether the basis takes the particles' domains from the seed lattice's sub-cells.
    pub fn reads_seed_domains(&self) -> bool {
        matches!(self, ShapeKind::Domain(_))
    }

    /// The registry's name of this kind of basis (any LME settings).
    pub fn name(&self) -> &'static str {
        match self {
            ShapeKind::LocalMaxEnt(_) => "lme",
            kind => SHAPES
                .name_of(kind)
                .expect("every shape kind is registered"),
        }
    }
}
