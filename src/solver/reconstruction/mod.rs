//! One run of a reconstruction benchmark: place the data, fit the method's local least
//! squares at the grid nodes, and record u - u^h there; for `recon1d_basis` also the weighted
//! orthogonal basis. The element-wise benchmark fits each element instead (`elements`). No
//! time stepping.

mod basis;
mod elements;

use nalgebra::SVector;

use super::base_record;
use crate::benchmarks::scattered::{ElementProblem, ScatteredData};
use crate::benchmarks::BenchmarkKind;
use crate::experiment::ResolvedRun;
use crate::grid::Grid;
use crate::output::{ElementRecord, ReconstructionRecord, RunRecord, RunStatus, Unstepped};
use crate::params::Params;
use crate::reconstruct::{Kernel, Lattice, Recipe, Reconstructor, Solver};
use crate::reconstruction_methods::{Fit, ReconstructionMethod};
use crate::run_spec::RunSpec;

/// Samples of u on the interval for plots: smooth enough for sin(pi x) at any scale.
const CURVE_SAMPLES: usize = 401;

/// Runs one configuration of `method`, nodal or element-wise by the benchmark's kind.
pub(super) fn evaluate(run: &ResolvedRun, method: &'static ReconstructionMethod) -> RunRecord {
    if run.benchmark.kind == BenchmarkKind::Elementwise {
        evaluate_elements(run, method)
    } else {
        evaluate_nodes(run, method)
    }
}

/// A nodal reconstruction. A run whose method cannot be fitted (a singular MLS moment matrix)
/// is `failed`, with the evaluation point in `message` and the data still recorded.
fn evaluate_nodes(run: &ResolvedRun, method: &'static ReconstructionMethod) -> RunRecord {
    let mut record = base_record(run, String::new());
    let (data, solver) = match prepare(&run.spec, method) {
        Ok(prepared) => prepared,
        Err(message) => {
            record.message = message;
            record.unstepped = Unstepped::Reconstruction(ReconstructionRecord {
                l2: f64::NAN,
                max: f64::NAN,
                ..Default::default()
            });
            return record;
        }
    };
    let grid = Grid::new(&data.domain);
    record.h = grid.h;
    let mut out = describe(&data, method, solver);
    match fit_nodes(&data, method, solver, &grid, &mut out) {
        Ok(()) => record.status = RunStatus::Ok,
        Err(message) => record.message = message,
    }
    out.basis = data
        .basis_centre
        .map(|centre| basis::record(&data, method.degree, grid.h, centre, &out.curve_x));
    record.unstepped = Unstepped::Reconstruction(out);
    record
}

fn prepare(
    spec: &RunSpec,
    method: &ReconstructionMethod,
) -> Result<(ScatteredData, Solver), String> {
    let Fit::Local(solver) = method.fit else {
        return Err(format!(
            "'{}' fits element by element; a nodal benchmark needs a local method",
            method.name
        ));
    };
    let data =
        ScatteredData::from_params(&spec.benchmark, &spec.params).map_err(|e| e.to_string())?;
    Ok((data, solver))
}

/// An element-wise reconstruction: every element fitted on its own, errors at Gauss points.
/// A run that cannot start is `failed` with the reason in `message`.
fn evaluate_elements(run: &ResolvedRun, method: &ReconstructionMethod) -> RunRecord {
    let mut record = base_record(run, String::new());
    match fit_elements(&run.spec.params, method) {
        Ok((h, out)) => {
            record.status = RunStatus::Ok;
            record.dim = out.dim;
            record.h = h;
            record.unstepped = Unstepped::Elements(out);
        }
        Err(message) => {
            record.message = message;
            record.unstepped = Unstepped::Elements(ElementRecord {
                rms: f64::NAN,
                integral: f64::NAN,
                exact_integral: f64::NAN,
                integral_error: f64::NAN,
                ..Default::default()
            });
        }
    }
    record
}

/// Every element's fit of the data `params` describe by `method`, with the element size.
fn fit_elements(
    params: &Params,
    method: &ReconstructionMethod,
) -> Result<(f64, ElementRecord), String> {
    let Fit::Taylor(conservation) = method.fit else {
        return Err(format!(
            "'{}' is a local fit; the element-wise benchmark needs a tls method",
            method.name
        ));
    };
    let problem = ElementProblem::from_params(params).map_err(|e| e.to_string())?;
    let degree = method.degree.value();
    Ok(match problem {
        ElementProblem::Line(data) => {
            (data.h(), elements::reconstruct(&data, degree, conservation))
        }
        ElementProblem::Surface(data) => {
            (data.h(), elements::reconstruct(&data, degree, conservation))
        }
    })
}

/// The record before the fit: the method, the data and the exact values; the fit's outputs
/// are NaN until `fit_nodes` fills them.
fn describe(
    data: &ScatteredData,
    method: &ReconstructionMethod,
    solver: Solver,
) -> ReconstructionRecord {
    let u = |xs: &[f64]| {
        xs.iter()
            .map(|&x| data.function.eval(x))
            .collect::<Vec<f64>>()
    };
    let (lower, upper) = (data.domain.lower[0], data.domain.upper[0]);
    let nodes = data.domain.cells + 1;
    let x: Vec<f64> = (0..nodes)
        .map(|i| lower + (upper - lower) * i as f64 / data.domain.cells as f64)
        .collect();
    let curve_x: Vec<f64> = (0..CURVE_SAMPLES)
        .map(|k| lower + (upper - lower) * k as f64 / (CURVE_SAMPLES - 1) as f64)
        .collect();
    ReconstructionRecord {
        formula: data.function.formula().to_string(),
        weight: data.weight.name().to_string(),
        scale: data.scale,
        degree: method.degree.value() as i64,
        solver: solver.to_string(),
        exact: u(&x),
        reconstructed: vec![f64::NAN; nodes],
        error: vec![f64::NAN; nodes],
        x,
        data_u: u(&data.points),
        data_x: data.points.clone(),
        curve_u: u(&curve_x),
        curve_x,
        l2: f64::NAN,
        max: f64::NAN,
        fits: 0,
        rank_deficient: 0,
        uncovered: 0,
        basis: None,
    }
}

/// u^h at the nodes, u - u^h and its norms. Nodes without data in reach keep NaN, and so
/// do the norms: nothing is left out silently.
fn fit_nodes(
    data: &ScatteredData,
    method: &ReconstructionMethod,
    solver: Solver,
    grid: &Grid<1>,
    out: &mut ReconstructionRecord,
) -> Result<(), String> {
    let recipe = Recipe {
        kernel: Kernel {
            weight: data.weight,
            scale: data.scale,
        },
        degree: method.degree,
        solver,
    };
    let mut reconstructor = Reconstructor::new(recipe, Lattice::nodes(grid));
    let positions: Vec<SVector<f64, 1>> = data.points.iter().map(|&x| [x].into()).collect();
    let stats = reconstructor.fit(&positions).map_err(|e| e.to_string())?;
    reconstructor.apply(&out.data_u, &mut out.reconstructed);
    for e in 0..out.x.len() {
        if !reconstructor.covered(e) {
            out.reconstructed[e] = f64::NAN;
            out.uncovered += 1;
        }
        out.error[e] = out.exact[e] - out.reconstructed[e];
    }
    out.fits = stats.fits as i64;
    out.rank_deficient = stats.rank_deficient as i64;
    out.l2 = out.error.iter().map(|e| grid.h * e * e).sum::<f64>().sqrt();
    out.max = out.error.iter().map(|e| e.abs()).fold(0.0, nan_max);
    Ok(())
}

/// The larger of two numbers, NaN if either is (`f64::max` would drop the NaN).
pub(super) fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
