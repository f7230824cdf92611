//! `recon_tls`: a function of one or two variables sampled at points placed element by element
//! on a uniform grid of [lower, upper]^D and reconstructed on each element on its own (Taylor
//! least squares, Wobbes et al. 2018 sec 2.1, Figs 1-2). The function decides the dimension.

use nalgebra::SVector;

use super::functions::{ElementFunction, SurfaceFunction, TestFunction};
use super::points::{cell_fractions, check_ppc, Spacing};
use super::ParamSpec;
use super::{choice, interval, BenchmarkInfo, Domain, ParamDefault, ParamKind};
use super::{BenchmarkKind, Build};
use crate::benchmarks::limits::{check_count, largest, per_axis_total, power};
use crate::grid::lattice_coords;
use crate::params::{get_usize, ParamError, Params};
use crate::rng::Lcg;

/// More Gauss points per axis than this would only cost time: 32 integrate polynomials of
/// degree 63 exactly.
pub const MAX_GAUSS_POINTS: usize = 32;

const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        key: "function",
        kind: ParamKind::Choice(&ElementFunction::NAMES),
        default: ParamDefault::Required,
        unit: "1",
        doc: "the sampled function u; 1D (x) or 2D (x, y), which sets the dimension",
    },
    super::bound(
        "lower",
        0.0,
        "lower end of the interval, or of the square [lower, upper]^2",
    ),
    super::bound("upper", 1.0, "upper end of the interval, or of the square"),
    ParamSpec {
        key: "cells",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Required,
        unit: "1",
        doc: "elements per axis on [lower, upper]",
    },
    ParamSpec {
        key: "spacing",
        kind: ParamKind::Choice(&Spacing::NAMES),
        default: ParamDefault::Text("equal"),
        unit: "1",
        doc: "equal: cell-centred sub-intervals; interior: j/(n+1) of the element; random: \
              uniform; mixed (1D): Wobbes Fig 1's elements (edges, shared edge, equal, random)",
    },
    ParamSpec {
        key: "ppc",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Required,
        unit: "1",
        doc: "data points per element along x",
    },
    ParamSpec {
        key: "ppc_y",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(1),
        unit: "1",
        doc: "data points per element along y (2D functions; must stay 1 in 1D)",
    },
    ParamSpec {
        key: "seed",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(1),
        unit: "1",
        doc: "seed of the random points (spacing random or mixed)",
    },
    ParamSpec {
        key: "gauss",
        kind: ParamKind::PositiveInt,
        default: ParamDefault::Int(2),
        unit: "1",
        doc: "Gauss-Legendre points per element and axis where the errors are measured",
    },
];

pub const INFO: BenchmarkInfo = BenchmarkInfo {
    name: "recon_tls",
    kind: BenchmarkKind::Elementwise,
    // Runs take the dimension of their function; this is the largest.
    build: Build::Points { dim: 2 },
    source: "Wobbes et al. 2018, sec 2.1, Figs 1-2",
    description: "u sampled element by element (1D or 2D), reconstructed on each element, \
                  RMS and integral errors at Gauss points",
    params: PARAMS,
    check,
    time_step: None,
};

/// One element-wise reconstruction problem in `D` dimensions, resolved from parameters.
#[derive(Clone, Debug)]
pub struct ElementData<const D: usize, F> {
    /// [lower, upper]^D in `cells` elements per axis, numbered with x fastest.
    pub domain: Domain<D>,
    pub function: F,
    /// The data points of each element. A point on an edge belongs to the element it was
    /// placed for: Wobbes Fig 1 puts one at x = pi for the first element and one for the second.
    pub points: Vec<Vec<SVector<f64, D>>>,
    /// Gauss points per element and axis.
    pub gauss: usize,
}

/// The problem in the dimension of its function.
#[derive(Clone, Debug)]
pub enum ElementProblem {
    Line(ElementData<1, TestFunction>),
    Surface(ElementData<2, SurfaceFunction>),
}

impl ElementProblem {
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        check(params)?;
        let (lower, upper) = interval(params)?;
        let cells = get_usize(params, "cells")?;
        let layout = Layout::read(params)?;
        let gauss = get_usize(params, "gauss")?;
        Ok(
            match choice(params, "function", ElementFunction::from_name)? {
                ElementFunction::Line(function) => ElementProblem::Line(ElementData::new(
                    lower, upper, cells, function, &layout, gauss,
                )),
                ElementFunction::Surface(function) => ElementProblem::Surface(ElementData::new(
                    lower, upper, cells, function, &layout, gauss,
                )),
            },
        )
    }
}

impl<const D: usize, F> ElementData<D, F> {
    /// The edge length of the (square) elements.
    pub fn h(&self) -> f64 {
        element_size(&self.domain)
    }

    fn new(
        lower: f64,
        upper: f64,
        cells: usize,
        function: F,
        layout: &Layout,
        gauss: usize,
    ) -> Self {
        let domain = Domain {
            lower: SVector::repeat(lower),
            upper: SVector::repeat(upper),
            cells,
        };
        ElementData {
            points: layout.place(&domain),
            domain,
            function,
            gauss,
        }
    }
}

fn element_size<const D: usize>(domain: &Domain<D>) -> f64 {
    (domain.upper[0] - domain.lower[0]) / domain.cells as f64
}

/// Where the data go in each element.
struct Layout {
    spacing: Spacing,
    /// Points per element along each axis.
    per_axis: [usize; 2],
    seed: u64,
}

impl Layout {
    fn read(params: &Params) -> Result<Self, ParamError> {
        Ok(Layout {
            spacing: choice(params, "spacing", Spacing::from_name)?,
            per_axis: [get_usize(params, "ppc")?, get_usize(params, "ppc_y")?],
            seed: get_usize(params, "seed")? as u64,
        })
    }

    /// The points of every element, elements numbered with x fastest. Equal and interior
    /// spacings are tensor products of the 1D placements; random points are drawn x then y,
    /// point by point, element by element, from one generator.
    fn place<const D: usize>(&self, domain: &Domain<D>) -> Vec<Vec<SVector<f64, D>>> {
        let mut rng = Lcg::new(self.seed);
        let h = element_size(domain);
        let per_axis: [usize; D] = std::array::from_fn(|k| self.per_axis[k]);
        let elements = domain.cells.pow(D as u32);
        (0..elements)
            .map(|e| {
                let cell = lattice_coords(e, &[domain.cells; D]);
                let at = |k: usize, f: f64| domain.lower[k] + (cell[k] as f64 + f) * h;
                if D == 2 && self.spacing == Spacing::Random {
                    let n = per_axis.iter().product();
                    return (0..n)
                        .map(|_| {
                            let f: [f64; D] = std::array::from_fn(|_| rng.unit());
                            SVector::from_fn(|k, _| at(k, f[k]))
                        })
                        .collect();
                }
                let fractions: Vec<Vec<f64>> = (0..D)
                    .map(|k| cell_fractions(self.spacing, cell[k], per_axis[k], &mut rng))
                    .collect();
                let count = per_axis.iter().product();
                (0..count)
                    .map(|p| {
                        let j = lattice_coords(p, &per_axis);
                        SVector::from_fn(|k, _| at(k, fractions[k][j[k]]))
                    })
                    .collect()
            })
            .collect()
    }
}

/// The interval, the layout's needs (two points for the edges of `mixed`, which is 1D only;
/// `ppc_y` only for 2D functions), and a bounded number of Gauss points.
fn check(params: &Params) -> Result<(), ParamError> {
    interval(params)?;
    let function = choice(params, "function", ElementFunction::from_name)?;
    let layout = Layout::read(params)?;
    let dim = function.dim();
    if dim == 1 && layout.per_axis[1] != 1 {
        return Err(ParamError::new(
            "ppc_y",
            format!(
                "ppc_y = {} applies to 2D functions only; {} is a function of x",
                layout.per_axis[1],
                function.name()
            ),
        ));
    }
    if layout.spacing == Spacing::Mixed && dim != 1 {
        return Err(ParamError::new(
            "spacing",
            "spacing mixed (Wobbes Fig 1) is defined in 1D only; valid in 2D: equal, interior, \
             random",
        ));
    }
    check_ppc(layout.spacing, layout.per_axis[0])?;
    let gauss = get_usize(params, "gauss")?;
    if gauss > MAX_GAUSS_POINTS {
        return Err(ParamError::new(
            "gauss",
            format!("gauss = {gauss}: at most {MAX_GAUSS_POINTS} Gauss points per axis"),
        ));
    }
    let cells = get_usize(params, "cells")?;
    let [ppc, ppc_y] = layout.per_axis;
    let elements = per_axis_total(cells, dim);
    let p = power(dim);
    check_count(
        elements.and_then(|n| n.checked_mul(ppc)?.checked_mul(ppc_y)),
        "data points",
        &format!("cells{p} ppc ppc_y with cells = {cells}, ppc = {ppc} and ppc_y = {ppc_y}"),
        largest(&[("cells", cells), ("ppc", ppc), ("ppc_y", ppc_y)]),
    )?;
    check_count(
        cells
            .checked_mul(gauss)
            .and_then(|n| per_axis_total(n, dim)),
        "Gauss points",
        &format!("(cells gauss){p} with cells = {cells} and gauss = {gauss}"),
        largest(&[("cells", cells), ("gauss", gauss)]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamValue;

    fn params(function: &str, spacing: &str, ppc: i64, ppc_y: i64) -> Params {
        [
            ("function", ParamValue::Str(function.into())),
            ("lower", ParamValue::Float(0.0)),
            ("upper", ParamValue::Float(4.0)),
            ("cells", ParamValue::Int(4)),
            ("spacing", ParamValue::Str(spacing.into())),
            ("ppc", ParamValue::Int(ppc)),
            ("ppc_y", ParamValue::Int(ppc_y)),
            ("seed", ParamValue::Int(3)),
            ("gauss", ParamValue::Int(2)),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }

    #[test]
    fn mixed_places_edge_points_for_the_first_two_elements() {
        let ElementProblem::Line(data) =
            ElementProblem::from_params(&params("sin_plus_2", "mixed", 3, 1)).unwrap()
        else {
            panic!("a function of x is 1D");
        };
        let x: Vec<Vec<f64>> = data
            .points
            .iter()
            .map(|p| p.iter().map(|x| x[0]).collect())
            .collect();
        assert_eq!(x.len(), 4);
        assert_eq!((x[0][0], x[0][2]), (0.0, 1.0));
        assert!(x[0][1] > 0.0 && x[0][1] < 1.0);
        assert_eq!(x[1][0], 1.0);
        assert!(x[1][1..].iter().all(|&p| p > 1.0 && p < 2.0));
        assert_eq!(x[2], [2.0 + 1.0 / 6.0, 2.5, 2.0 + 5.0 / 6.0]);
        assert!(x[3].iter().all(|&p| p > 3.0 && p < 4.0));
    }

    #[test]
    fn interior_points_form_the_wobbes_pattern_in_2d() {
        let ElementProblem::Surface(data) =
            ElementProblem::from_params(&params("sin_x_cos_y", "interior", 2, 3)).unwrap()
        else {
            panic!("a function of x and y is 2D");
        };
        assert_eq!(data.points.len(), 16);
        // Element 5 is (1, 1): x in {1 + 1/3, 1 + 2/3}, y in {1.25, 1.5, 1.75}, x fastest.
        let p = &data.points[5];
        assert_eq!(p.len(), 6);
        assert!((p[0] - SVector::from([1.0 + 1.0 / 3.0, 1.25])).norm() < 1e-15);
        assert!((p[1] - SVector::from([1.0 + 2.0 / 3.0, 1.25])).norm() < 1e-15);
        assert!((p[5] - SVector::from([1.0 + 2.0 / 3.0, 1.75])).norm() < 1e-15);
    }

    #[test]
    fn checks_name_the_offending_parameter() {
        assert_eq!(
            check(&params("sin_plus_2", "equal", 3, 2)).unwrap_err().key,
            "ppc_y"
        );
        assert_eq!(
            check(&params("sin_x_cos_y", "mixed", 3, 3))
                .unwrap_err()
                .key,
            "spacing"
        );
        assert_eq!(check(&params("x2", "mixed", 1, 1)).unwrap_err().key, "ppc");
        let mut p = params("x2", "random", 3, 1);
        p.insert("gauss".into(), ParamValue::Int(33));
        assert_eq!(check(&p).unwrap_err().key, "gauss");
        assert!(check(&params("x2_plus_xy", "random", 2, 2)).is_ok());
    }
}
