//! Leapfrog with half-step velocities and the particle update of Gong sec 4.4.
//! Between steps the particles carry v^{s-1/2}; the first step is a half kick
//! (v^{1/2} = v^0 + a^0 dt/2, as Gong suggests after eq 4.24).

use nalgebra::{SMatrix, SVector};

use super::Divergence;
use crate::material::{det, NeoHookean};
use crate::particles::Particles;
use crate::reconstruct::GridState;
use crate::shape::Stencils;

/// Nodes below this fraction of a particle mass are treated as empty: the hat's gradient
/// does not vanish where its value does, so a node touched only at N ~ 0 would otherwise
/// get an unbounded acceleration.
const EMPTY_NODE_MASS: f64 = 1e-12;

/// A velocity component held at zero: (node, axis).
pub type FixedDof = (u32, u8);

/// Step 2 of Gong sec 4.4: v_i^{s-1/2} = (mv)_i / m_i, a_i = f_i / m_i, then
/// v_i^{s+1/2} = v_i^{s-1/2} + kick a_i, with fixed components held at zero. Afterwards
/// `momentum` holds v_i^{s-1/2} and `force` holds a_i.
pub fn solve_grid<const D: usize>(
    grid: &mut GridState<D>,
    fixed: &[FixedDof],
    kick: f64,
    particle_mass: f64,
) {
    let empty = EMPTY_NODE_MASS * particle_mass;
    for i in 0..grid.mass.len() {
        let m = grid.mass[i];
        if m > empty {
            grid.momentum[i] /= m;
            grid.force[i] /= m;
        } else {
            grid.momentum[i] = SVector::zeros();
            grid.force[i] = SVector::zeros();
        }
    }
    for &(i, k) in fixed {
        grid.momentum[i as usize][k as usize] = 0.0;
        grid.force[i as usize][k as usize] = 0.0;
    }
    for i in 0..grid.mass.len() {
        grid.velocity[i] = grid.momentum[i] + grid.force[i] * kick;
    }
}

/// Step 3 of Gong sec 4.4, one pass per particle with N and grad N taken at x_p^s:
/// v_p += kick sum_i N_ip a_i, x_p += dt sum_i N_ip v_i^{s+1/2},
/// F_p = (I + dt sum_i v_i^{s+1/2} (x) grad N_ip) F_p, then J and the stress.
/// Eq 4.28 prints grad N_i(x_p^{s+1}); Gong's implementation notes (sec 5.4) use the element
/// found at the start of the step, i.e. x_p^s, which is what is done here (docs/NOTES.md).
pub fn update_particles<const D: usize>(
    stencils: &Stencils<D>,
    particles: &mut Particles<D>,
    grid: &GridState<D>,
    kick: f64,
    dt: f64,
    material: &NeoHookean,
) -> Result<(), Divergence> {
    for p in 0..particles.len() {
        let mut a = SVector::<f64, D>::zeros();
        let mut v = SVector::<f64, D>::zeros();
        let mut grad_v = SMatrix::<f64, D, D>::zeros();
        for (i, w, g) in stencils.of(p) {
            let vi = grid.velocity[i];
            a += grid.force[i] * w;
            v += vi * w;
            grad_v += vi * g.transpose();
        }
        particles.v[p] += a * kick;
        particles.x[p] += v * dt;
        let f = (SMatrix::<f64, D, D>::identity() + grad_v * dt) * particles.f[p];
        let j = det(&f);
        if !(j.is_finite() && a.iter().all(|c| c.is_finite())) {
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
        particles.stress[p] = material.cauchy(&f, j);
    }
    Ok(())
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
        let a: SVector<f64, D> = stencils.of(p).map(|(i, w, _)| grid.force[i] * w).sum();
        *out = particles.v[p] + a * half;
    }
}
