//! The particle-to-grid transfer of a run, chosen from the method's parts.

use nalgebra::SVector;

use crate::divergence::Divergence;
use crate::grid::{FixedDof, Grid, GridState};
use crate::integrate;
use crate::particles::Particles;
use crate::reconstruct::TransferKind;
use crate::reconstruct::{
    mass_and_forces, particles_to_grid, remap_velocity, ConsistentMassTransfer, FitStats,
    QuadratureTransfer, TaylorTransfer, VelocityFit,
};
use crate::shape::{Shape, Stencils};

pub enum Transfer<const D: usize> {
    Shepard,
    Quadrature(Box<QuadratureTransfer<D>>),
    /// The Shepard transfer with the nodal velocity replaced by this fit at the nodes.
    FittedVelocity(Box<VelocityFit<D>>),
    /// The Shepard sums solved with the consistent mass matrix.
    ConsistentMass(Box<ConsistentMassTransfer<D>>),
    /// Taylor least squares per element with its own mass matrix.
    Taylor(Box<TaylorTransfer<D>>),
}

impl<const D: usize> Transfer<D> {
    /// `basis` is the run's grid basis, for transfers that evaluate it at quadrature points
    /// of their own; `remaps` whether the integrator rebuilds the nodal velocity after the
    /// particles move (`remap_velocity`).
    pub fn new(
        kind: &TransferKind,
        grid: &Grid<D>,
        basis: &dyn Shape<D>,
        fixed: &[FixedDof],
        remaps: bool,
    ) -> Self {
        match kind {
            TransferKind::Shepard => Transfer::Shepard,
            TransferKind::ConsistentMass => Transfer::ConsistentMass(Box::new(
                ConsistentMassTransfer::new(grid.nodes_per_dim(), fixed),
            )),
            TransferKind::Quadrature(recipe) => {
                Transfer::Quadrature(Box::new(QuadratureTransfer::new(recipe, grid, remaps)))
            }
            TransferKind::FittedVelocity(recipe) => {
                Transfer::FittedVelocity(Box::new(VelocityFit::new(*recipe, grid, remaps)))
            }
            TransferKind::Taylor(recipe) => {
                Transfer::Taylor(Box::new(TaylorTransfer::new(*recipe, grid, basis, fixed)))
            }
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
                .map_to_grid(stencils, particles, body_force, grid)
                .map_err(|e| Divergence::Reconstruction(e.to_string())),
            Transfer::FittedVelocity(fit) => {
                mass_and_forces(stencils, particles, body_force, grid);
                let stats = fit
                    .map(&particles.x, &particles.v, &mut grid.velocity)
                    .map_err(|e| Divergence::Reconstruction(e.to_string()))?;
                Ok(stats)
            }
            Transfer::ConsistentMass(cm) => cm
                .map_to_grid(stencils, particles, body_force, grid)
                .map(|()| FitStats::default()),
            Transfer::Taylor(tls) => tls.map_to_grid(stencils, particles, body_force, grid),
        }
    }

    /// Follows a basis that changes with the material (the dual-domain gradient) at the
    /// transfer's own quadrature points.
    pub fn refresh_basis(&mut self, basis: &dyn Shape<D>) {
        if let Transfer::Taylor(tls) = self {
            tls.refresh_basis(basis);
        }
    }

    /// The grid solve (a = M^-1 f, v_new = v + kick a) with the transfer's mass matrix.
    pub fn solve_grid(
        &mut self,
        grid: &mut GridState<D>,
        fixed: &[FixedDof],
        kick: f64,
    ) -> Result<(), Divergence> {
        match self {
            Transfer::Taylor(tls) => tls.solve_grid(grid, kick),
            Transfer::ConsistentMass(cm) => cm.solve_grid(grid, kick),
            _ => {
                integrate::solve_grid(grid, fixed, kick);
                Ok(())
            }
        }
    }

    /// Total momentum the DOFs received from the last mapping (`grid` after `map_to_grid`,
    /// or the remapped velocity `velocity`): sum_i p_i, before boundary conditions where the
    /// transfer assembles p; sum_i m_i v_i otherwise.
    pub fn received_momentum(&self, mass: &[f64], velocity: &[SVector<f64, D>]) -> SVector<f64, D> {
        match self {
            Transfer::Taylor(tls) => tls.momentum_total(),
            Transfer::ConsistentMass(cm) => cm.momentum_total(),
            _ => mass.iter().zip(velocity).map(|(&m, v)| v * m).sum(),
        }
    }

    /// The nodal velocity rebuilt from the particle velocities `v` with this step's
    /// weights (MUSL's v_i^L): mass-weighted for Shepard (and a quadrature transfer with the
    /// Shepard velocity), the velocity fit otherwise.
    pub fn remap_velocity(
        &mut self,
        stencils: &Stencils<D>,
        particles: &Particles<D>,
        grid: &GridState<D>,
        out: &mut [SVector<f64, D>],
    ) -> Result<(), Divergence> {
        match self {
            Transfer::Shepard => {
                remap_velocity(stencils, particles, &grid.mass, grid.empty_mass, out)
            }
            Transfer::Quadrature(q) => q.remap_velocity(stencils, particles, grid.empty_mass, out),
            Transfer::FittedVelocity(fit) => fit.remap(&particles.v, out),
            Transfer::ConsistentMass(cm) => {
                return cm.remap_velocity(stencils, particles, grid, out)
            }
            Transfer::Taylor(tls) => return tls.remap_velocity(particles, grid, out),
        }
        Ok(())
    }
}
