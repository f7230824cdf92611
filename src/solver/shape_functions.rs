//! One run of the shape-function benchmark: the method's grid basis evaluated on a lattice of
//! points, N_a and grad N_a of the centre node and its neighbours along x recorded, and the
//! consistency of the whole basis measured at every point. No time stepping.

use nalgebra::{SMatrix, SVector};

use super::base_record;
use super::reconstruction::nan_max;
use crate::benchmarks::shape_functions::ShapeProblem;
use crate::experiment::ResolvedRun;
use crate::grid::{lattice_coords, Dofs, Grid};
use crate::output::{RunRecord, RunStatus, ShapeFunctionRecord, Unstepped};
use crate::shape::{LinearHat, LmeFailure, LocalMaxEnt, Shape, SplineDegree};
use crate::shape_methods::{Basis, ShapeMethod};

/// Neighbours of the centre node recorded on each side along x.
const NEIGHBOURS: usize = 2;

/// Runs one configuration. A run whose basis cannot be built is `failed` with the reason in
/// `message`; so is a run where Newton stopped short at some LME point, with the numbers of
/// every point still recorded.
pub(super) fn evaluate(run: &ResolvedRun, method: &ShapeMethod) -> RunRecord {
    let mut record = base_record(run, String::new());
    let evaluated = ShapeProblem::from_params(&run.spec.params)
        .map_err(|e| e.to_string())
        .and_then(|problem| {
            record.dim = problem.dim;
            record.h = 1.0;
            match problem.dim {
                1 => tabulate::<1>(&problem, method.basis),
                _ => tabulate::<2>(&problem, method.basis),
            }
        });
    match evaluated {
        Ok(out) if out.failures > 0 => {
            record.message = format!(
                "Newton stopped short of |r| < 1e-12 h at {} of {} points",
                out.failures,
                out.point_count()
            );
            record.unstepped = Unstepped::ShapeFunctions(out);
        }
        Ok(out) => {
            record.status = RunStatus::Ok;
            record.unstepped = Unstepped::ShapeFunctions(out);
        }
        Err(message) => {
            record.message = message;
            record.unstepped = Unstepped::ShapeFunctions(ShapeFunctionRecord {
                gamma: f64::NAN,
                tolerance: f64::NAN,
                radius: f64::NAN,
                max_errors: [f64::NAN; 4],
                ..Default::default()
            });
        }
    }
    record
}

/// A basis of the catalogue in `D` dimensions.
enum Evaluator<const D: usize> {
    Lme(LocalMaxEnt<D>),
    Hat,
    BSpline(SplineDegree),
}

impl<const D: usize> Evaluator<D> {
    fn new(basis: Basis, problem: &ShapeProblem) -> Result<Self, String> {
        Ok(match basis {
            Basis::Lme => Evaluator::Lme(problem.lme().map_err(|e| e.to_string())?),
            Basis::Linear => Evaluator::Hat,
            Basis::BSpline(degree) => Evaluator::BSpline(degree),
        })
    }

    fn dofs(&self) -> Dofs {
        match self {
            Evaluator::BSpline(degree) => degree.dofs(),
            _ => Dofs::Nodes,
        }
    }

    fn shape(&self) -> &dyn Shape<D> {
        match self {
            Evaluator::Lme(lme) => lme,
            Evaluator::Hat => &LinearHat,
            Evaluator::BSpline(degree) => degree.shape(),
        }
    }

    /// Fills the stencil of `x`: Newton's steps (none for the polynomial bases), or why LME's
    /// stopped short (the stencil then holds its last iterate).
    fn eval(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> Result<usize, LmeFailure> {
        match self {
            Evaluator::Lme(lme) => lme.evaluate(grid, x, node, weight, grad),
            other if other.shape().eval(grid, x, node, weight, grad) => Ok(0),
            _ => Err(LmeFailure::Outside),
        }
    }
}

/// The record of `basis` on the problem's lattice.
fn tabulate<const D: usize>(
    problem: &ShapeProblem,
    basis: Basis,
) -> Result<ShapeFunctionRecord, String> {
    let evaluator = Evaluator::<D>::new(basis, problem)?;
    let grid = Grid::with_dofs(&problem.domain::<D>(), evaluator.dofs());
    let recorded = recorded_nodes(&grid);
    let centre = recorded.len() / 2;
    let coordinates = problem.axis_coordinates();
    let per_axis = [coordinates.len(); D];
    let points = coordinates.len().pow(D as u32);
    let lme = match &evaluator {
        Evaluator::Lme(lme) => Some(lme),
        _ => None,
    };
    let mut out = ShapeFunctionRecord {
        basis: basis.to_string(),
        dim: D,
        gamma: lme.map_or(f64::NAN, |_| problem.gamma),
        tolerance: lme.map_or(f64::NAN, |_| problem.tolerance),
        radius: lme.map_or(f64::NAN, |lme| lme.radius()),
        nodes: recorded.iter().map(|&a| a as i64).collect(),
        centre: centre as i64,
        node_x: recorded
            .iter()
            .flat_map(|&a| grid.node_position(a).iter().copied().collect::<Vec<_>>())
            .collect(),
        ..Default::default()
    };
    let n = evaluator.shape().nodes_per_point();
    let (mut node, mut weight, mut grad) = (vec![0; n], vec![0.0; n], vec![SVector::zeros(); n]);
    for p in 0..points {
        let ijk = lattice_coords(p, &per_axis);
        let x = SVector::<f64, D>::from_fn(|k, _| coordinates[ijk[k]]);
        match evaluator.eval(&grid, &x, &mut node, &mut weight, &mut grad) {
            Ok(steps) => out.max_newton_steps = out.max_newton_steps.max(steps as i64),
            Err(LmeFailure::Outside) => return Err(format!("{x:?} is outside the grid")),
            Err(_) => out.failures += 1,
        }
        out.x.extend(x.iter());
        for &a in &recorded {
            let entry = node.iter().position(|&b| b as usize == a);
            out.value.push(entry.map_or(0.0, |e| weight[e]));
            let g = entry.map_or(SVector::zeros(), |e| grad[e]);
            out.gradient.extend(g.iter());
        }
        let errors = consistency(&grid, &x, &node, &weight, &grad);
        for (list, error) in out.errors.iter_mut().zip(errors) {
            list.push(error);
        }
    }
    out.max_errors = out
        .errors
        .each_ref()
        .map(|e| e.iter().copied().fold(0.0, nan_max));
    Ok(out)
}

/// The DOF nearest the middle of the grid (the first on a tie) and up to `NEIGHBOURS` on each
/// side of it along x, ascending.
fn recorded_nodes<const D: usize>(grid: &Grid<D>) -> Vec<usize> {
    let middle = grid.cells as f64 * grid.h / 2.0;
    let n = grid.nodes_per_dim();
    let distance = |i: usize| (grid.dof_coordinate(0, i) - grid.lower[0] - middle).abs();
    let c = (0..n).fold(0, |best, i| {
        if distance(i) < distance(best) {
            i
        } else {
            best
        }
    });
    let along_x = c.saturating_sub(NEIGHBOURS)..(c + NEIGHBOURS + 1).min(n);
    along_x.map(|i| grid.node_index([c; D]) - c + i).collect()
}

/// |sum N_a - 1|, |sum N_a x_a - x| / h, h |sum grad N_a| and |sum grad N_a (x) x_a - I|_F
/// over one point's stencil.
fn consistency<const D: usize>(
    grid: &Grid<D>,
    x: &SVector<f64, D>,
    node: &[u32],
    weight: &[f64],
    grad: &[SVector<f64, D>],
) -> [f64; 4] {
    let mut sum = 0.0;
    let mut moment = SVector::<f64, D>::zeros();
    let mut gradient = SVector::<f64, D>::zeros();
    let mut gradient_moment = SMatrix::<f64, D, D>::zeros();
    for ((&a, &w), g) in node.iter().zip(weight).zip(grad) {
        let xa = grid.node_position(a as usize);
        sum += w;
        moment += xa * w;
        gradient += g;
        gradient_moment += g * xa.transpose();
    }
    [
        (sum - 1.0).abs(),
        (moment - x).norm() / grid.h,
        gradient.norm() * grid.h,
        (gradient_moment - SMatrix::identity()).norm(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::Domain;

    #[test]
    fn records_the_centre_node_and_its_neighbours_along_x() {
        let domain = Domain::<2> {
            lower: SVector::zeros(),
            upper: SVector::repeat(6.0),
            cells: 6,
        };
        let grid = Grid::new(&domain);
        // Node (3, 3) of a 7 x 7 lattice is 24.
        assert_eq!(recorded_nodes(&grid), [22, 23, 24, 25, 26]);
        let spline = Grid::with_dofs(&domain, SplineDegree::Quadratic.dofs());
        // DOF (3, 3) of 8 x 8 sits at (2.5, 2.5), the first of the two nearest the middle.
        assert_eq!(recorded_nodes(&spline), [25, 26, 27, 28, 29]);
        let small = Grid::<1>::new(&Domain {
            lower: SVector::zeros(),
            upper: SVector::repeat(2.0),
            cells: 2,
        });
        assert_eq!(recorded_nodes(&small), [0, 1, 2]);
    }

    #[test]
    fn the_hat_is_consistent_to_round_off() {
        let problem = ShapeProblem {
            dim: 2,
            cells: 4,
            gamma: 0.8,
            tolerance: 1e-6,
            points: 3,
        };
        let out = tabulate::<2>(&problem, Basis::Linear).unwrap();
        assert_eq!(out.point_count(), 13 * 13);
        assert!(out.max_errors.iter().all(|&e| e < 1e-14), "{out:?}");
        // N of the centre node (2, 2) at (2, 2) is one, at (2 + 1/3, 2) two thirds.
        let at = |p: usize| out.value[p * out.node_count() + out.centre as usize];
        let row = 6 * 13;
        assert_eq!((at(row + 6), at(row + 9)), (1.0, 0.0));
        assert!((at(row + 7) - 2.0 / 3.0).abs() < 1e-15);
    }
}
