//! Basis functions on the background grid and the per-particle tables of their values.

mod block;
mod bspline;
mod domain;
mod dual_domain;
mod kind;
mod linear;
mod lme;
mod stencils;

use nalgebra::SVector;

use crate::grid::Grid;

pub use bspline::{BSpline, SplineDegree};
pub use domain::{DomainShape, ParticleDomains};
pub use dual_domain::{DualDomain, DualIntegrals};
pub use kind::{LmeSettings, ShapeKind, LME_UNSET, SHAPES, SHAPE_NAMES};
pub use linear::LinearHat;
pub use lme::{
    LmeFailure, LmeParamError, LocalMaxEnt, DEFAULT_TOLERANCE, MAX_ITERATIONS, MAX_STENCIL_NODES,
    RESIDUAL_TOLERANCE,
};
pub use stencils::{EntryGradients, NodeGradients, Stencils, VelocityGradient};

/// A family of grid basis functions N_i(x).
pub trait Shape<const D: usize>: Sync {
    /// How many nodes one point's stencil lists (entries beyond the true support carry
    /// zero weight and gradient).
    fn nodes_per_point(&self) -> usize;

    /// How many of a stencil's entries can carry nonzero values, where fewer than
    /// `nodes_per_point` do (the dual-domain basis: the hat's 2^D of 4^D nodes); sums of
    /// values then run over those entries alone (`Stencils::for_values`).
    fn value_nodes_per_point(&self) -> usize {
        self.nodes_per_point()
    }

    /// Fills the nodes, values N_i(x) and gradients grad N_i(x) of the stencil of `x`.
    /// Returns false when `x` is outside the grid.
    fn eval(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> bool;
}
