//! Particle-to-grid transfers: what each method reconstructs on the grid from particle data,
//! and the local least-squares reconstructions (Shepard, MLS, IMLS, element-wise Taylor least
//! squares) they are built from.

mod banded;
mod basis;
mod conjugate_gradients;
mod consistent_mass;
mod diagonals;
mod kernel;
mod kind;
mod lattice;
mod least_squares;
mod line_sums;
mod mass_matrix;
mod quadrature;
mod shepard;
mod solve;
mod taylor;
mod taylor_transfer;
#[cfg(test)]
mod tests;

pub use basis::{monomials, Degree, MAX_TERMS};
pub use consistent_mass::ConsistentMassTransfer;
pub use kernel::{Kernel, Weight};
pub use kind::{
    TransferKind, IMLS, IMLS_CPLS, IMLS_EQ27, IMPM, IMPM_FIELDS, IMPM_VELOCITY, TLS, TLS_LUMPED,
    TRANSFERS, TRANSFER_NAMES,
};
pub use lattice::Lattice;
pub use least_squares::{
    FitStats, Recipe, Reconstructor, SingularMoments, Solver, VelocityFit, MAX_NODE_SUPPORT_CELLS,
};
pub use mass_matrix::{MassMatrix, MassSolver};
pub use quadrature::{
    BodyForceFit, NodalVelocity, QuadratureRecipe, QuadratureTransfer, BODY_FORCE_FITS,
    BODY_FORCE_FIT_NAMES,
};
pub use shepard::{map_velocity, mass_and_forces, nodal_forces, particles_to_grid, remap_velocity};
pub use solve::{moment_matrix, Moments, OrthogonalBasis, RANK_TOLERANCE};
pub use taylor::{taylor_terms, Conservation, TaylorCell, TaylorFit, MAX_TAYLOR_TERMS};
pub use taylor_transfer::{TaylorRecipe, TaylorTransfer};
