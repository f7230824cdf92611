//! `shape_functions`: a grid basis evaluated on a lattice of points of a small uniform grid,
//! with no time stepping (Molinos et al. sec 5, Fig 3: the LME basis for several gamma beside
//! the hat it tends to). The run's `method` names the basis (`shape_methods`).

use nalgebra::SVector;

use super::limits::{check_count, largest, per_axis_total, power};
use super::{BenchmarkInfo, BenchmarkKind, Build, ParamDefault, ParamKind, ParamSpec};
use crate::grid::Domain;
use crate::params::{get_f64, get_usize, ParamError, Params};
use crate::shape::{LmeParamError, LocalMaxEnt, DEFAULT_TOLERANCE};

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "dim",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(1),
        unit: "1",
        doc: "dimension of the grid, 1 or 2",
    },
    ParamSpec {
        key: "cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(6),
        unit: "1",
        doc: "cells of size h = 1 per axis on [0, cells]",
    },
    ParamSpec {
        key: "gamma",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(0.8),
        unit: "1",
        doc: "LME locality gamma = beta h^2 (lme only)",
    },
    ParamSpec {
        key: "tolerance",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(DEFAULT_TOLERANCE),
        unit: "1",
        doc: "LME cut-off: nodes whose exp(-beta |x - x_a|^2) is below it are left out",
    },
    ParamSpec {
        key: "points",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(20),
        unit: "1",
        doc: "evaluation points per cell and axis (a lattice from 0 to cells, ends included)",
    },
];

pub const INFO: BenchmarkInfo = BenchmarkInfo {
    name: "shape_functions",
    kind: BenchmarkKind::ShapeFunctions,
    // Runs take the dimension of their `dim`; this is the largest.
    build: Build::Points { dim: 2 },
    source: "Molinos et al., sec 5, Fig 3",
    description:
        "a grid basis (LME, hat, quadratic or cubic B-spline) and its gradient on a lattice of \
                  points, with its consistency errors",
    params: PARAMS,
    check,
    time_step: None,
};

/// One evaluation problem, resolved from validated parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeProblem {
    pub dim: usize,
    pub cells: usize,
    pub gamma: f64,
    pub tolerance: f64,
    pub points: usize,
}

impl ShapeProblem {
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        check(params)?;
        Ok(ShapeProblem {
            dim: get_usize(params, "dim")?,
            cells: get_usize(params, "cells")?,
            gamma: get_f64(params, "gamma")?,
            tolerance: get_f64(params, "tolerance")?,
            points: get_usize(params, "points")?,
        })
    }

    /// [0, cells]^D.
    pub fn domain<const D: usize>(&self) -> Domain<D> {
        Domain {
            lower: SVector::zeros(),
            upper: SVector::repeat(self.cells as f64),
            cells: self.cells,
        }
    }

    /// The coordinates of the lattice along one axis: `points` per cell from 0, and `cells`.
    pub fn axis_coordinates(&self) -> Vec<f64> {
        let n = self.cells * self.points;
        (0..=n).map(|k| k as f64 / self.points as f64).collect()
    }

    /// The LME basis of these parameters in `D` dimensions.
    pub fn lme<const D: usize>(&self) -> Result<LocalMaxEnt<D>, LmeParamError> {
        LocalMaxEnt::with_tolerance(self.gamma, self.tolerance)
    }
}

/// `dim` is 1 or 2, gamma and tolerance give an LME basis in that dimension (checked
/// whatever the method, so that an axis of gamma means the same for every run), and the
/// lattice has at most `MAX_POINTS` points.
fn check(params: &Params) -> Result<(), ParamError> {
    let dim = get_usize(params, "dim")?;
    let (gamma, tolerance) = (get_f64(params, "gamma")?, get_f64(params, "tolerance")?);
    let lme = match dim {
        1 => LocalMaxEnt::<1>::with_tolerance(gamma, tolerance).map(|_| ()),
        2 => LocalMaxEnt::<2>::with_tolerance(gamma, tolerance).map(|_| ()),
        _ => {
            return Err(ParamError::new(
                "dim",
                format!("dim = {dim}; valid: 1, 2 (the dimensions of the LME kernel)"),
            ))
        }
    };
    lme.map_err(|e| {
        // A tolerance outside (0, 1) is the tolerance's fault, anything else gamma's.
        let key = if tolerance < 1.0 {
            "gamma"
        } else {
            "tolerance"
        };
        ParamError::new(key, e.to_string())
    })?;
    // The lattice holds the grid's nodes among its points, which bounds them too.
    let (cells, points) = (get_usize(params, "cells")?, get_usize(params, "points")?);
    check_count(
        cells
            .checked_mul(points)
            .and_then(|n| n.checked_add(1))
            .and_then(|n| per_axis_total(n, dim)),
        "evaluation points",
        &format!(
            "(cells points + 1){} with cells = {cells} and points = {points}",
            power(dim)
        ),
        largest(&[("cells", cells), ("points", points)]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::default_params;
    use crate::params::ParamValue;

    fn with(pairs: &[(&str, ParamValue)]) -> Params {
        let mut params = default_params(PARAMS);
        for (key, value) in pairs {
            params.insert(key.to_string(), value.clone());
        }
        params
    }

    #[test]
    fn checks_gamma_against_the_dimension() {
        assert!(check(&with(&[])).is_ok());
        // -ln(1e-6) = 13.8 bounds gamma in 1D, 0.8 times it in 2D.
        let gamma = ("gamma", ParamValue::Float(12.0));
        assert!(check(&with(std::slice::from_ref(&gamma))).is_ok());
        let e = check(&with(&[gamma, ("dim", ParamValue::Int(2))])).unwrap_err();
        assert_eq!(e.key, "gamma");
        assert!(e.message.contains("in 2D"), "{e}");
        let e = check(&with(&[("tolerance", ParamValue::Float(2.0))])).unwrap_err();
        assert_eq!(e.key, "tolerance");
        let e = check(&with(&[("dim", ParamValue::Int(3))])).unwrap_err();
        assert!(e.message.contains("valid: 1, 2"), "{e}");
    }

    #[test]
    fn the_lattice_spans_the_grid() {
        let problem = ShapeProblem::from_params(&with(&[
            ("cells", ParamValue::Int(2)),
            ("points", ParamValue::Int(4)),
        ]))
        .unwrap();
        let xs = problem.axis_coordinates();
        assert_eq!(xs.len(), 9);
        assert_eq!((xs[0], xs[4], xs[8]), (0.0, 1.0, 2.0));
    }
}
