//! Reconstruction benchmarks: a known function sampled at scattered points on an interval and
//! reconstructed at the nodes of a uniform grid, with no time stepping.
//!
//! * `recon1d_nodes`: equally spaced or seeded random points, a fixed number per cell
//!   (Gong sec 4.3.1, Tables 4.1-4.2; sec 5.2, Figs 5.1-5.4).
//! * `recon1d_basis`: points given in the experiment file; besides the reconstruction, the
//!   weighted orthogonal polynomials of eq 16 at a centre are recorded (Tran Figs 1-3).
//! * `recon_tls`: points placed element by element in 1D or 2D, each element reconstructed
//!   on its own (Wobbes et al. 2018, Figs 1-2; `elements`).

mod elements;
mod functions;
mod points;

pub use elements::{ElementData, ElementProblem, INFO as INFO_ELEMENTS, MAX_GAUSS_POINTS};
pub use functions::{ElementFunction, ExactField, SurfaceFunction, TestFunction};
pub use points::{place, Spacing};

use points::check_ppc;

use super::limits::{check_count, check_lattice};
use super::{BenchmarkInfo, BenchmarkKind, Build, ParamDefault, ParamKind, ParamSpec};
use crate::grid::Domain;
use crate::params::{get_f64, get_list, get_str, get_usize, ParamError, Params};
use crate::reconstruct::{Weight, MAX_NODE_SUPPORT_CELLS};

const FUNCTION: ParamSpec = ParamSpec {
    key: "function",
    kind: ParamKind::Choice(&TestFunction::NAMES),
    default: ParamDefault::Required,
    unit: "1",
    doc: "the sampled function u(x)",
};

const CELLS: ParamSpec = ParamSpec {
    key: "cells",
    kind: ParamKind::PositiveInt,
    default: ParamDefault::Required,
    unit: "1",
    doc: "grid cells on [lower, upper]; u^h is evaluated at the cells + 1 nodes",
};

const fn bound(key: &'static str, default: f64, doc: &'static str) -> ParamSpec {
    ParamSpec {
        key,
        kind: ParamKind::Real,
        default: ParamDefault::Float(default),
        unit: "1",
        doc,
    }
}

const fn weight(default: &'static str) -> ParamSpec {
    ParamSpec {
        key: "weight",
        kind: ParamKind::Choice(&Weight::NAMES),
        default: ParamDefault::Text(default),
        unit: "1",
        doc: "weight function w of the local least squares (B-spline of order 1, 2 or 3)",
    }
}

const fn scale(default: f64) -> ParamSpec {
    ParamSpec {
        key: "scale",
        kind: ParamKind::PositiveReal,
        default: ParamDefault::Float(default),
        unit: "1",
        doc: "support length in cells: w(|x - x_p| / (scale h))",
    }
}

const NODE_PARAMS: &[ParamSpec] = &[
    FUNCTION,
    ParamSpec {
        key: "spacing",
        kind: ParamKind::Choice(&Spacing::NAMES),
        default: ParamDefault::Text("equal"),
        unit: "1",
        doc: "equal: cell-centred sub-intervals; random: uniform in each cell",
    },
    ParamSpec {
        key: "seed",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(1),
        unit: "1",
        doc: "seed of the random points (spacing random)",
    },
    bound("lower", 0.0, "left end of the interval"),
    bound("upper", 1.0, "right end of the interval"),
    CELLS,
    ParamSpec {
        key: "ppc",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Required,
        unit: "1",
        doc: "data points per cell",
    },
    weight("hat"),
    scale(1.0),
];

const BASIS_PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "points",
        kind: ParamKind::RealList,
        default: ParamDefault::Required,
        unit: "1",
        doc: "coordinates of the data points, inside [lower, upper]",
    },
    FUNCTION,
    bound("lower", -1.0, "left end of the interval"),
    bound("upper", 1.0, "right end of the interval"),
    CELLS,
    bound(
        "centre",
        0.0,
        "where the orthogonal basis is built (the weight's centre)",
    ),
    weight("quadratic"),
    scale(2.0),
];

pub const INFO_NODES: BenchmarkInfo = BenchmarkInfo {
    name: "recon1d_nodes",
    kind: BenchmarkKind::Reconstruction,
    build: Build::Points { dim: 1 },
    source: "Gong 2015, sec 4.3.1 and 5.2",
    description: "u sampled at equal or random points per cell, reconstructed at the grid nodes",
    params: NODE_PARAMS,
    check: check_nodes,
    time_step: None,
};

pub const INFO_BASIS: BenchmarkInfo = BenchmarkInfo {
    name: "recon1d_basis",
    kind: BenchmarkKind::OrthogonalBasis,
    build: Build::Points { dim: 1 },
    source: "Tran et al. 2019, eq 16, Figs 1-3",
    description: "weighted orthogonal polynomials of given points, and u reconstructed from them",
    params: BASIS_PARAMS,
    check: check_basis,
    time_step: None,
};

/// One reconstruction problem, resolved from validated parameters.
#[derive(Clone, Debug)]
pub struct ScatteredData {
    pub domain: Domain<1>,
    pub function: TestFunction,
    /// Data points, ascending for the generated sets, as given otherwise.
    pub points: Vec<f64>,
    pub weight: Weight,
    pub scale: f64,
    /// Where the orthogonal basis is recorded (`recon1d_basis` only).
    pub basis_centre: Option<f64>,
}

impl ScatteredData {
    pub fn from_params(benchmark: &str, params: &Params) -> Result<Self, ParamError> {
        let (lower, upper) = interval(params)?;
        let cells = get_usize(params, "cells")?;
        let h = (upper - lower) / cells as f64;
        let (points, basis_centre) = match super::CATALOG.find(benchmark).map(|b| b.kind) {
            Some(BenchmarkKind::OrthogonalBasis) => (
                get_list(params, "points")?.to_vec(),
                Some(get_f64(params, "centre")?),
            ),
            Some(BenchmarkKind::Reconstruction) => {
                let spacing = choice(params, "spacing", Spacing::from_name)?;
                let seed = get_usize(params, "seed")? as u64;
                let ppc = get_usize(params, "ppc")?;
                (place(spacing, lower, h, cells, ppc, seed), None)
            }
            _ => {
                return Err(ParamError::new(
                    "benchmark",
                    format!("'{benchmark}' is not a nodal reconstruction benchmark"),
                ))
            }
        };
        Ok(ScatteredData {
            domain: Domain {
                lower: [lower].into(),
                upper: [upper].into(),
                cells,
            },
            function: choice(params, "function", TestFunction::from_name)?,
            points,
            weight: choice(params, "weight", Weight::from_name)?,
            scale: get_f64(params, "scale")?,
            basis_centre,
        })
    }
}

fn choice<T>(params: &Params, key: &str, parse: fn(&str) -> Option<T>) -> Result<T, ParamError> {
    let name = get_str(params, key)?;
    parse(name).ok_or_else(|| ParamError::new(key, format!("unknown {key} '{name}'")))
}

fn interval(params: &Params) -> Result<(f64, f64), ParamError> {
    let (lower, upper) = (get_f64(params, "lower")?, get_f64(params, "upper")?);
    if lower < upper {
        Ok((lower, upper))
    } else {
        Err(ParamError::new(
            "upper",
            format!("upper = {upper} must exceed lower = {lower}"),
        ))
    }
}

/// The size of the run, as `check_support`, and a placement has the points it needs per cell.
fn check_nodes(params: &Params) -> Result<(), ParamError> {
    check_lattice(params, 1, "data points")?;
    check_support(params)?;
    let spacing = choice(params, "spacing", Spacing::from_name)?;
    check_ppc(spacing, get_usize(params, "ppc")?)
}

/// The interval is not empty and the weight's support fits the reconstruction's node table.
fn check_support(params: &Params) -> Result<(), ParamError> {
    interval(params)?;
    let weight = choice(params, "weight", Weight::from_name)?;
    let scale = get_f64(params, "scale")?;
    let radius = weight.radius() * scale;
    if radius > MAX_NODE_SUPPORT_CELLS {
        return Err(ParamError::new(
            "scale",
            format!(
                "the {weight} weight with scale {scale} reaches {radius} cells; at most \
                 {MAX_NODE_SUPPORT_CELLS} are supported"
            ),
        ));
    }
    Ok(())
}

/// The grid's size, as `check_support`, and the points and the centre lie in the interval.
fn check_basis(params: &Params) -> Result<(), ParamError> {
    let cells = get_usize(params, "cells")?;
    check_count(
        cells.checked_add(1),
        "grid nodes",
        &format!("cells + 1 with cells = {cells}"),
        "cells",
    )?;
    check_support(params)?;
    let (lower, upper) = interval(params)?;
    let inside = |x: f64| (lower..=upper).contains(&x);
    if let Some(x) = get_list(params, "points")?.iter().find(|&&x| !inside(x)) {
        return Err(ParamError::new(
            "points",
            format!("the point {x} lies outside [lower, upper] = [{lower}, {upper}]"),
        ));
    }
    let centre = get_f64(params, "centre")?;
    if !inside(centre) {
        return Err(ParamError::new(
            "centre",
            format!("centre = {centre} lies outside [lower, upper] = [{lower}, {upper}]"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamValue;

    fn params(pairs: &[(&str, ParamValue)]) -> Params {
        pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect()
    }

    fn basis_params(points: Vec<f64>) -> Params {
        params(&[
            ("points", ParamValue::List(points)),
            ("function", ParamValue::Str("x".into())),
            ("lower", ParamValue::Float(-1.0)),
            ("upper", ParamValue::Float(1.0)),
            ("cells", ParamValue::Int(2)),
            ("centre", ParamValue::Float(0.0)),
            ("weight", ParamValue::Str("quadratic".into())),
            ("scale", ParamValue::Float(2.0)),
        ])
    }

    #[test]
    fn checks_name_the_offending_parameter() {
        let mut p = basis_params(vec![-0.5, 1.5]);
        assert_eq!(check_basis(&p).unwrap_err().key, "points");
        p.insert("points".into(), ParamValue::List(vec![0.5]));
        assert!(check_basis(&p).is_ok());
        p.insert("scale".into(), ParamValue::Float(11.0));
        let e = check_basis(&p).unwrap_err();
        assert_eq!(e.key, "scale");
        assert!(e.message.contains("16.5 cells"), "{e}");
        p.insert("upper".into(), ParamValue::Float(-1.0));
        assert_eq!(check_basis(&p).unwrap_err().key, "upper");
    }

    #[test]
    fn builds_the_given_or_generated_points() {
        let data =
            ScatteredData::from_params("recon1d_basis", &basis_params(vec![0.2, -0.4])).unwrap();
        assert_eq!(data.points, [0.2, -0.4]);
        assert_eq!(data.basis_centre, Some(0.0));
        assert_eq!(data.weight, Weight::QuadraticSpline);
        let nodes = params(&[
            ("function", ParamValue::Str("x2".into())),
            ("spacing", ParamValue::Str("equal".into())),
            ("seed", ParamValue::Int(1)),
            ("lower", ParamValue::Float(-1.0)),
            ("upper", ParamValue::Float(1.0)),
            ("cells", ParamValue::Int(10)),
            ("ppc", ParamValue::Int(4)),
            ("weight", ParamValue::Str("hat".into())),
            ("scale", ParamValue::Float(1.0)),
        ]);
        let data = ScatteredData::from_params("recon1d_nodes", &nodes).unwrap();
        assert_eq!((data.points.len(), data.basis_centre), (40, None));
        assert_eq!(data.function, TestFunction::X2);
        assert!(ScatteredData::from_params("mms1d_gong", &nodes).is_err());
    }
}
