//! Leapfrog with half-step velocities and the particle update of Gong sec 4.4 (and of IMPM,
//! sec 5.4). Between steps the particles carry v^{s-1/2}; the first step is a half kick
//! (v^{1/2} = v^0 + a^0 dt/2, as Gong suggests after eq 4.24). The same update serves USL
//! (whole kicks from the start) and forward Euler (whole kicks, moved with the start-of-step
//! velocity).

use nalgebra::{SMatrix, SVector};

use super::deform::deform_particle;
use crate::divergence::Divergence;
use crate::grid::GridState;
use crate::material::Material;
use crate::parallel;
use crate::particles::{ParticleChunk, Particles};
use crate::shape::{EntryGradients, NodeGradients, Stencils, VelocityGradient};

/// Step 3 of Gong sec 4.4, one pass per particle with N and grad N taken at x_p^s:
/// v_p += kick sum_i N_ip a_i, x_p += dt sum_i N_ip v_i^{s+1/2},
/// F_p = (I + dt sum_i v_i^{s+1/2} (x) grad N_ip) F_p, then J and the stress.
/// Eq 4.28 prints grad N_i(x_p^{s+1}); Gong's implementation notes (sec 5.4) use the element
/// found at the start of the step, i.e. x_p^s, which is what is done here (docs/NOTES.md).
///
/// The particles move with the nodal velocity `drift`: the updated one `grid.velocity_new`
/// (leapfrog, USL) or the start-of-step one `grid.velocity` (forward Euler, Molinos et al.
/// eq 22); F always follows `grid.velocity_new`. Chunks of particles run in parallel
/// (`parallel::map_chunks`); the error is that of the first particle that failed.
pub fn update_particles<const D: usize>(
    stencils: &Stencils<D>,
    particles: &mut Particles<D>,
    grid: &GridState<D>,
    drift: &[SVector<f64, D>],
    kick: f64,
    dt: f64,
    material: &Material,
) -> Result<(), Divergence> {
    let step = Step {
        grid,
        drift,
        kick,
        dt,
    };
    match stencils.dual_domain() {
        Some(dual) => {
            let gradients = NodeGradients(dual.velocity_gradients(&grid.velocity_new));
            update_with(stencils, particles, &step, &gradients, material)
        }
        None => {
            let gradients = EntryGradients(&grid.velocity_new);
            update_with(stencils, particles, &step, &gradients, material)
        }
    }
}

/// The nodal fields and step lengths of `update_particles`.
struct Step<'a, const D: usize> {
    grid: &'a GridState<D>,
    drift: &'a [SVector<f64, D>],
    kick: f64,
    dt: f64,
}

fn update_with<const D: usize>(
    stencils: &Stencils<D>,
    particles: &mut Particles<D>,
    step: &Step<D>,
    gradients: &impl VelocityGradient<D>,
    material: &Material,
) -> Result<(), Divergence> {
    let update = |mut chunk: ParticleChunk<D>| {
        for q in 0..chunk.x.len() {
            let mut a = SVector::<f64, D>::zeros();
            let mut v = SVector::<f64, D>::zeros();
            let mut grad_v = SMatrix::<f64, D, D>::zeros();
            for (i, w, g) in stencils.of(chunk.start + q) {
                a += step.grid.force[i] * w;
                v += step.drift[i] * w;
                grad_v += gradients.term(i, w, g);
            }
            chunk.v[q] += a * step.kick;
            chunk.x[q] += v * step.dt;
            let finite = a.iter().all(|c| c.is_finite());
            deform_particle(&mut chunk, q, &grad_v, step.dt, finite, material)?;
        }
        Ok(())
    };
    parallel::map_chunks(particles.chunks_mut(), update)
        .into_iter()
        .collect()
}

/// Particle velocities at the integer time level s: v_p^s = v_p^{s-1/2} + half sum_i N_ip a_i
/// (half = dt/2, or 0 at s = 0 where the particles still carry v^0). Used for output only;
/// the stepping state is untouched.
pub fn synchronized_velocity<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    grid: &GridState<D>,
    half: f64,
    out: &mut [SVector<f64, D>],
) {
    for (p, out) in out.iter_mut().enumerate() {
        *out = synchronized_velocity_of(stencils, particles, grid, half, p);
    }
}

/// `synchronized_velocity` of particle `p` alone.
pub fn synchronized_velocity_of<const D: usize>(
    stencils: &Stencils<D>,
    particles: &Particles<D>,
    grid: &GridState<D>,
    half: f64,
    p: usize,
) -> SVector<f64, D> {
    let a: SVector<f64, D> = stencils
        .for_values()
        .of(p)
        .map(|(i, w, _)| grid.force[i] * w)
        .sum();
    particles.v[p] + a * half
}
