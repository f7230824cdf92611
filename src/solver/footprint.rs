//! What a run will hold in memory, estimated from its parameters before it starts, so that the
//! runner can refuse a run that cannot fit and hold back runs that would not fit beside those
//! running. The terms are the arrays that scale with the run: the particle state and stencils,
//! one sample of the history (kept until it is streamed, and in the stream's buffers), the
//! grid, the transfer's evaluation points and their least-squares neighbourhoods, and the
//! banded consistent mass matrix; a fixed allowance covers the HDF5 library and the stream's
//! chunk buffers. The history itself is on disk (`output::HistoryStream`), so the estimate
//! does not grow with the number of samples.

use super::{Job, Work};
use crate::benchmarks::{AnyProblem, Problem};
use crate::grid::Grid;
use crate::methods::Method;
use crate::reconstruct::{MassMatrix, NodalVelocity, Recipe, TransferKind};
use crate::shape::{LinearHat, LocalMaxEnt, ParticleDomains, Shape, ShapeKind};

/// The HDF5 library, its chunk caches, and the stream's chunk buffers (about 1 MiB per
/// growing dataset).
const FIXED_BYTES: f64 = 48.0 * 1024.0 * 1024.0;
/// Bytes per point of an unstepped run (reconstructions, shape functions): its position,
/// value, fit and errors.
const UNSTEPPED_BYTES_PER_POINT: f64 = 512.0;

/// The estimated peak memory of `job` in bytes.
pub(super) fn estimated_bytes(job: &Job) -> f64 {
    let run = job.run;
    let (cells, ppc) = (run.cells.max(1) as f64, run.ppc.max(1) as f64);
    let body_particles = (cells * ppc).powi(run.dim() as i32);
    FIXED_BYTES
        + match &job.work {
            Ok(Work::Mpm(method, AnyProblem::D1(p))) => {
                simulation_bytes(p.as_ref(), method, body_particles, ppc)
            }
            Ok(Work::Mpm(method, AnyProblem::D2(p))) => {
                simulation_bytes(p.as_ref(), method, body_particles, ppc)
            }
            Ok(_) => body_particles * UNSTEPPED_BYTES_PER_POINT,
            Err(_) => 0.0,
        }
}

/// The arrays of a simulation of `particles` particles, `ppc` per cell and axis.
fn simulation_bytes<const D: usize>(
    problem: &dyn Problem<D>,
    method: &Method,
    particles: f64,
    ppc: f64,
) -> f64 {
    let d = D as f64;
    let grid = Grid::with_dofs(&problem.domain(), method.shape.dofs());
    let cells = grid.cells as f64;
    let nodes = grid.num_nodes() as f64;
    let stencil = stencil_nodes::<D>(method.shape) as f64;
    let stencil_bytes = |points: f64| points * stencil * (4.0 + 8.0 + 8.0 * d);
    // x0, x, v, F, stress, J, mass, volumes; body force, synchronised velocity, cell; the
    // predictor-corrector's acceleration and prediction; a particle domain's corners.
    let state = 8.0 * (6.0 * d + 2.0 * d * d + 5.0 + 2.0 * d)
        + match method.shape {
            ShapeKind::Domain(_) => 2.0 * 8.0 * d * 2f64.powi(D as i32),
            _ => 0.0,
        };
    // Positions, velocities, stress, density, volume and four error fields, twice.
    let sample = 2.0 * 8.0 * (2.0 * d + d * d + 6.0);
    let per_node = 8.0 * (7.0 * d + 3.0);
    let gauss_points = |per_axis: usize| (cells * per_axis as f64).powi(D as i32);
    let neighbours =
        |recipe: &Recipe| (ppc * (2.0 * recipe.kernel.radius_cells().ceil() + 1.0)).powi(D as i32);
    let fit_bytes = |points: f64, recipe: &Recipe| points * (24.0 * neighbours(recipe) + 512.0);
    let span = stencil.powf(1.0 / d);
    let banded = (d + 1.0) * nodes * (span * (cells + 2.0).powi(D as i32 - 1) + 1.0) * 8.0;
    let transfer = match &method.transfer {
        TransferKind::Shepard => 0.0,
        TransferKind::FittedVelocity(recipe) => fit_bytes(nodes, recipe),
        TransferKind::ConsistentMass => banded,
        TransferKind::Quadrature(recipe) => {
            let points = gauss_points(recipe.gauss_points);
            let velocity = match &recipe.velocity {
                NodalVelocity::Fit(fit) => fit_bytes(nodes, fit),
                NodalVelocity::Shepard => 0.0,
            };
            velocity + fit_bytes(points, &recipe.fields) + stencil_bytes(points) + 96.0 * points
        }
        TransferKind::Taylor(recipe) => {
            let points = gauss_points(recipe.gauss_points);
            let mass = match recipe.mass {
                MassMatrix::Consistent => banded,
                MassMatrix::Lumped => 0.0,
            };
            mass + stencil_bytes(points) + 256.0 * points + 1024.0 * cells.powi(D as i32)
        }
    };
    // The dual-domain integrals (int S_j and 3^D averages per node) and the nodal tensors
    // of its factored gradients.
    let dual = match method.shape {
        ShapeKind::DualDomain(_) => 8.0 * (3f64.powi(D as i32) * d + 1.0 + 2.0 * d * d),
        _ => 0.0,
    };
    particles * (state + sample) + stencil_bytes(particles) + nodes * (per_node + dual) + transfer
}

/// The nodes each particle's stencil holds for the method's basis.
pub fn stencil_nodes<const D: usize>(shape: ShapeKind) -> usize {
    match shape {
        // The dual-domain basis holds the hat's entries; its gradients are nodal averages.
        ShapeKind::Linear | ShapeKind::DualDomain(_) => Shape::<D>::nodes_per_point(&LinearHat),
        ShapeKind::Domain(_) => ParticleDomains::<D>::nodes_per_point(),
        ShapeKind::BSpline(degree) => degree.shape::<D>().nodes_per_point(),
        ShapeKind::LocalMaxEnt(settings) => {
            LocalMaxEnt::<D>::with_tolerance(settings.gamma, settings.tolerance)
                .map_or(1, |lme| lme.nodes_per_point())
        }
    }
}
