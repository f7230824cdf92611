//! The particle-to-grid transfer of a run, chosen from the method's parts.

use nalgebra::SVector;

use crate::integrate::Divergence;
use crate::methods::TransferKind;
use crate::particles::Particles;
use crate::reconstruct::{
    particles_to_grid, remap_velocity, FitStats, GridState, Lattice, QuadratureTransfer,
    Reconstructor,
};
use crate::shape::{Grid, Stencils};

pub enum Transfer<const D: usize> {
    Shepard,
    Quadrature(Box<QuadratureTransfer<D>>),
    /// The Shepard transfer with the nodal velocity replaced by this fit at the nodes.
    FittedVelocity(Box<Reconstructor<D>>),
}

impl<const D: usize> Transfer<D> {
    pub fn new(kind: &TransferKind, grid: &Grid<D>) -> Self {
        match kind {
            TransferKind::Shepard => Transfer::Shepard,
            TransferKind::Quadrature(recipe) => {
                Transfer::Quadrature(Box::new(QuadratureTransfer::new(recipe, grid)))
            }
            TransferKind::FittedVelocity(recipe) => Transfer::FittedVelocity(Box::new(
                Reconstructor::new(*recipe, Lattice::nodes(grid)),
            )),
        }
    }

    /// Nodal mass, velocity and force from the particles; the fit counters of the step.
    pub fn map_to_grid(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        body_force: &[SVector<f64, D>],
        grid: &mut GridState<D>,
    ) -> Result<FitStats, Divergence> {
        match self {
            Transfer::Shepard => {
                particles_to_grid(stencils, particles, body_force, grid);
                Ok(FitStats::default())
            }
            Transfer::Quadrature(q) => q
                .map_to_grid(particles, body_force, grid)
                .map_err(|e| Divergence::Reconstruction(e.to_string())),
            Transfer::FittedVelocity(fit) => {
                particles_to_grid(stencils, particles, body_force, grid);
                let stats = fit
                    .fit(&particles.x)
                    .map_err(|e| Divergence::Reconstruction(e.to_string()))?;
                fit.apply(&particles.v, &mut grid.velocity);
                Ok(stats)
            }
        }
    }

    /// The nodal velocity rebuilt from the particle velocities `v` with this step's
    /// weights (MUSL's v_i^L): mass-weighted for Shepard, the velocity fit otherwise.
    pub fn remap_velocity(
        &self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        grid: &GridState<D>,
        out: &mut [SVector<f64, D>],
    ) {
        match self {
            Transfer::Shepard => remap_velocity(stencils, particles, grid, out),
            Transfer::Quadrature(q) => q.remap_velocity(&particles.v, out),
            Transfer::FittedVelocity(fit) => fit.apply(&particles.v, out),
        }
    }
}
