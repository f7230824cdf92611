//! The modified update-stress-last scheme of Tran et al. eqs 31-40: velocities at whole
//! steps, the particles moved with the new nodal velocity, then the nodal velocity rebuilt
//! from the updated particle velocities (v_i^L, eq 36) and used for the velocity gradient.
//! N and grad N are taken at x_p^t throughout the step: the grid moves with the material
//! until it is reset at the end (Tran: "at that moment, the grid configuration is reset").
//! The deformation with v_i^L is `deform::deform_particles` (eqs 37-40).

use nalgebra::SVector;

use crate::divergence::Divergence;
use crate::grid::GridState;
use crate::particles::Particles;
use crate::shape::Stencils;

/// Eqs 34-35: v_p += dt sum_i N_ip a_i, x_p += dt sum_i N_ip v_i with the nodal velocity
/// `drift`: v_i^{t+1} (`grid.velocity_new`, MUSL), the start-of-step v_i^t (`grid.velocity`,
/// Molinos et al. eq 23) or the predictor-corrector's v_i + dt/2 a_i. `acceleration`, when
/// given, receives every a_p = sum_i N_ip a_i.
pub fn move_particles<const D: usize>(
    stencils: &Stencils<D>,
    particles: &mut Particles<D>,
    grid: &GridState<D>,
    drift: &[SVector<f64, D>],
    dt: f64,
    mut acceleration: Option<&mut [SVector<f64, D>]>,
) -> Result<(), Divergence> {
    for p in 0..particles.len() {
        let mut a = SVector::<f64, D>::zeros();
        let mut v = SVector::<f64, D>::zeros();
        for (i, w, _) in stencils.for_values().of(p) {
            a += grid.force[i] * w;
            v += drift[i] * w;
        }
        if !a.iter().chain(v.iter()).all(|c| c.is_finite()) {
            return Err(Divergence::NonFinite {
                particle: p,
                what: "velocity",
            });
        }
        if let Some(out) = acceleration.as_deref_mut() {
            out[p] = a;
        }
        particles.v[p] += a * dt;
        particles.x[p] += v * dt;
    }
    Ok(())
}
