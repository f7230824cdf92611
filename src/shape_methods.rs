//! The catalogue of grid bases, the `method` of the `shape_functions` benchmark: the LME basis
//! of Molinos et al. and, for comparison, the hat it tends to for large gamma and the quadratic
//! and cubic B-splines.

use crate::catalog::{Catalog, Named};
use crate::shape::SplineDegree;
use std::fmt;

/// Which basis a method evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Basis {
    /// Local maximum entropy with the run's gamma and tolerance.
    Lme,
    /// The piecewise-linear hat.
    Linear,
    /// A B-spline, its DOFs at the Greville abscissae.
    BSpline(SplineDegree),
}

impl fmt::Display for Basis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Basis::Lme => f.write_str("lme"),
            Basis::Linear => f.write_str("linear"),
            Basis::BSpline(degree) => write!(f, "{}_bspline", degree.word()),
        }
    }
}

pub struct ShapeMethod {
    pub name: &'static str,
    pub basis: Basis,
    pub source: &'static str,
    pub description: &'static str,
}

impl Named for ShapeMethod {
    fn name(&self) -> &'static str {
        self.name
    }
}

pub const METHODS: Catalog<ShapeMethod> = Catalog {
    kind: "grid basis",
    entries: &[
        ShapeMethod {
            name: "lme",
            basis: Basis::Lme,
            source: "Molinos et al., sec 5, eqs 32-38",
            description: "local maximum-entropy basis, locality gamma and cut-off tolerance",
        },
        ShapeMethod {
            name: "linear",
            basis: Basis::Linear,
            source: "Gong 2015, eq 4.8",
            description: "piecewise-linear hat (tensor product in 2D)",
        },
        ShapeMethod {
            name: "quadratic_bspline",
            basis: Basis::BSpline(SplineDegree::Quadratic),
            source: "Steffen et al. 2008; Wobbes et al. 2018",
            description: "quadratic B-spline on the open knot vector",
        },
        ShapeMethod {
            name: "cubic_bspline",
            basis: Basis::BSpline(SplineDegree::Cubic),
            source: "de Boor 1978; Steffen et al. 2008",
            description: "cubic B-spline on the open knot vector",
        },
    ],
};
