use nalgebra::SVector;

use crate::benchmarks::Problem;
use crate::output::{Conservation, Errors, History};
use crate::particles::Particles;

/// Appends sampled particle states, their errors against the exact solution and the mass
/// totals.
pub struct Recorder {
    pub history: History,
    pub errors: Errors,
    pub conservation: Conservation,
}

impl Recorder {
    pub fn new() -> Self {
        Recorder {
            history: History::default(),
            errors: Errors::default(),
            conservation: Conservation::default(),
        }
    }

    /// Records the state at step `step`, time `t`, with `velocity` synchronised to `t`, and
    /// `grid_mass`, the total nodal mass the transfer of that step assembled.
    pub fn sample<const D: usize>(
        &mut self,
        step: usize,
        t: f64,
        particles: &Particles<D>,
        velocity: &[SVector<f64, D>],
        grid_mass: f64,
        problem: &dyn Problem<D>,
    ) {
        let h = &mut self.history;
        h.time.push(t);
        h.step.push(step as i64);
        let rho0 = problem.rho0();
        for p in 0..particles.len() {
            h.x.extend(particles.x[p].iter());
            h.v.extend(velocity[p].iter());
            // Row-major D x D (nalgebra stores columns; the transpose's columns are rows).
            h.stress.extend(particles.stress[p].transpose().iter());
            h.density.push(rho0 / particles.j[p]);
        }
        self.sample_errors(t, particles, velocity, problem);
        // Summed in particle order, so the total is the same on every run.
        let particle_mass = particles.mass.iter().sum();
        self.conservation.particle_mass.push(particle_mass);
        self.conservation.grid_mass.push(grid_mass);
    }

    /// Compares the totals a mapping gave the grid with the particles' totals it started
    /// from and keeps the largest relative errors of the run.
    pub fn track_mapping<const D: usize>(
        &mut self,
        particles: &Particles<D>,
        grid_mass: f64,
        grid_momentum: &SVector<f64, D>,
    ) {
        let mut mass = 0.0;
        let mut momentum = SVector::<f64, D>::zeros();
        let mut scale = 0.0;
        for (m, v) in particles.mass.iter().zip(&particles.v) {
            mass += m;
            momentum += v * *m;
            scale += m * v.norm();
        }
        let mass_error = (grid_mass - mass).abs() / mass;
        let momentum_error =
            (grid_momentum - momentum).norm() / if scale > 0.0 { scale } else { 1.0 };
        let c = &mut self.conservation;
        c.max_mass_error = nan_max(c.max_mass_error, mass_error);
        c.max_momentum_error = nan_max(c.max_momentum_error, momentum_error);
    }

    fn sample_errors<const D: usize>(
        &mut self,
        t: f64,
        particles: &Particles<D>,
        velocity: &[SVector<f64, D>],
        problem: &dyn Problem<D>,
    ) {
        let e = &mut self.errors;
        let rho0 = problem.rho0();
        let mut sum_v = [0.0; 4];
        let mut sum_n = [0.0; 4];
        for p in 0..particles.len() {
            let volume = particles.volume(p);
            // Without an exact solution the errors are NaN, so every array keeps its
            // (Nt, Np) shape.
            let pointwise = problem
                .exact(&particles.x0[p], t)
                .map_or([f64::NAN; 4], |exact| {
                    [
                        (particles.x[p] - particles.x0[p] - exact.displacement).norm(),
                        (velocity[p] - exact.velocity).norm(),
                        (particles.stress[p] - exact.stress).norm(),
                        (rho0 / particles.j[p] - exact.density).abs(),
                    ]
                });
            e.volume.push(volume);
            for (f, &value) in pointwise.iter().enumerate() {
                e.pointwise[f].push(value);
                sum_v[f] += volume * value * value;
                sum_n[f] += value * value;
            }
        }
        let n = particles.len() as f64;
        for f in 0..4 {
            e.l2[f].push(sum_v[f].sqrt());
            e.rms[f].push((sum_n[f] / n).sqrt());
        }
    }
}

/// The larger of the two; `current` is NaN until something was tracked, and a NaN `value`
/// is kept rather than hidden.
fn nan_max(current: f64, value: f64) -> f64 {
    if value <= current {
        current
    } else {
        value
    }
}
