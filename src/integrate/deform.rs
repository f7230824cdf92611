//! The deformation update shared by the integrators: F, J and the stress of a particle.

use nalgebra::{SMatrix, SVector};

use crate::divergence::Divergence;
use crate::material::{det, Material};
use crate::parallel;
use crate::particles::{ParticleChunk, Particles};
use crate::shape::{EntryGradients, NodeGradients, Stencils, VelocityGradient};

/// F_p = (I + dt grad v_p) F_p, J_p = det F_p, V_p = J_p V_p^0 and the stress (from F, or
/// advanced with grad v for a rate material), after checking that the new state is finite
/// and not inverted. `accel_finite` reports the acceleration gathered in
/// the same pass, so that a non-finite grid is caught at the first particle that sees it.
// Always inlined: it sits in the innermost particle loops, and a call there costs a fifth
// of the 2D step.
#[inline(always)]
pub(super) fn deform_particle<const D: usize>(
    chunk: &mut ParticleChunk<D>,
    q: usize,
    grad_v: &SMatrix<f64, D, D>,
    dt: f64,
    accel_finite: bool,
    material: &Material,
) -> Result<(), Divergence> {
    let particle = chunk.start + q;
    let f = (SMatrix::<f64, D, D>::identity() + grad_v * dt) * chunk.f[q];
    let j = det(&f);
    if !(j.is_finite() && accel_finite) {
        return Err(Divergence::NonFinite {
            particle,
            what: "state",
        });
    }
    if j <= 0.0 {
        return Err(Divergence::Jacobian { particle, j });
    }
    chunk.f[q] = f;
    chunk.j[q] = j;
    chunk.volume[q] = j * chunk.volume0[q];
    chunk.stress[q] = material.stress(&chunk.stress[q], &f, j, grad_v, dt);
    Ok(())
}

/// grad v_p = sum_i v_i (x) grad N_ip from the nodal velocity `velocity` (in factored form for
/// the dual-domain basis), then F, J and the stress of every particle: MUSL's eqs 37-40 of
/// Tran et al. with v_i^L (eq 37 prints N), and the predictor-corrector's steps 4-5 with
/// v~_i. Chunks of particles run in parallel (`parallel::map_chunks`); the error is that of
/// the first particle that failed.
pub fn deform_particles<const D: usize>(
    stencils: &Stencils<D>,
    particles: &mut Particles<D>,
    velocity: &[SVector<f64, D>],
    dt: f64,
    material: &Material,
) -> Result<(), Divergence> {
    match stencils.dual_domain() {
        Some(dual) => {
            let gradients = NodeGradients(dual.velocity_gradients(velocity));
            deform_with(stencils, particles, &gradients, dt, material)
        }
        None => deform_with(stencils, particles, &EntryGradients(velocity), dt, material),
    }
}

fn deform_with<const D: usize>(
    stencils: &Stencils<D>,
    particles: &mut Particles<D>,
    gradients: &impl VelocityGradient<D>,
    dt: f64,
    material: &Material,
) -> Result<(), Divergence> {
    let deform = |mut chunk: ParticleChunk<D>| {
        for q in 0..chunk.f.len() {
            let grad_v: SMatrix<f64, D, D> = stencils
                .of(chunk.start + q)
                .map(|(i, w, g)| gradients.term(i, w, g))
                .sum();
            deform_particle(&mut chunk, q, &grad_v, dt, true, material)?;
        }
        Ok(())
    };
    parallel::map_chunks(particles.chunks_mut(), deform)
        .into_iter()
        .collect()
}
