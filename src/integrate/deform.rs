//! The deformation update shared by the integrators: F, J and the stress of a particle.

use nalgebra::{SMatrix, SVector};

use super::Divergence;
use crate::material::{det, Material};
use crate::particles::Particles;
use crate::shape::Stencils;

/// F_p = (I + dt grad v_p) F_p, J_p = det F_p, V_p = J_p V_p^0 and the stress (from F, or
/// advanced with grad v for a rate material), after checking that the new state is finite
/// and not inverted. `accel_finite` reports the acceleration gathered in
/// the same pass, so that a non-finite grid is caught at the first particle that sees it.
// Always inlined: it sits in the innermost particle loops, and a call there costs a fifth
// of the 2D step.
#[inline(always)]
pub(super) fn deform_particle<const D: usize>(
    particles: &mut Particles<D>,
    p: usize,
    grad_v: &SMatrix<f64, D, D>,
    dt: f64,
    accel_finite: bool,
    material: &Material,
) -> Result<(), Divergence> {
    let f = (SMatrix::<f64, D, D>::identity() + grad_v * dt) * particles.f[p];
    let j = det(&f);
    if !(j.is_finite() && accel_finite) {
        return Err(Divergence::NonFinite {
            particle: p,
            what: "state",
        });
    }
    if j <= 0.0 {
        return Err(Divergence::Jacobian { particle: p, j });
    }
    particles.f[p] = f;
    particles.j[p] = j;
    particles.volume[p] = j * particles.volume0[p];
    particles.stress[p] = material.stress(&particles.stress[p], &f, j, grad_v, dt);
    Ok(())
}

/// grad v_p = sum_i v_i (x) grad N_ip from the nodal velocity `velocity`, then F, J and the
/// stress of every particle: MUSL's eqs 37-40 of Tran et al. with v_i^L (eq 37 prints N), and
/// the predictor-corrector's steps 4-5 with v~_i.
pub fn deform_particles<const D: usize>(
    stencils: &Stencils<D>,
    particles: &mut Particles<D>,
    velocity: &[SVector<f64, D>],
    dt: f64,
    material: &Material,
) -> Result<(), Divergence> {
    for p in 0..particles.len() {
        let grad_v: SMatrix<f64, D, D> = stencils
            .of(p)
            .map(|(i, _, g)| velocity[i] * g.transpose())
            .sum();
        deform_particle(particles, p, &grad_v, dt, true, material)?;
    }
    Ok(())
}
