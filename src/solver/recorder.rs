use nalgebra::SVector;

use crate::benchmarks::{ProbeQuantity, Problem};
use crate::output::{Conservation, Errors, History, ProbeRecord, REFERENCE_KINDS};
use crate::particles::Particles;

/// Appends sampled particle states, their errors against the exact solution and the mass
/// totals, and every step the values at the problem's probes.
pub struct Recorder {
    pub history: History,
    pub errors: Errors,
    pub conservation: Conservation,
    pub probes: Vec<ProbeRecord>,
    /// What each of `probes` records.
    quantities: Vec<ProbeQuantity>,
}

impl Recorder {
    pub fn new() -> Self {
        Recorder {
            history: History::default(),
            errors: Errors::default(),
            conservation: Conservation::default(),
            probes: Vec::new(),
            quantities: Vec::new(),
        }
    }

    /// Resolves the problem's probes to the particles nearest them (once, after seeding).
    /// The reference is `exact` where the problem has an exact solution, `static` where it
    /// gives another one for probes only, else `none`.
    pub fn attach_probes<const D: usize>(
        &mut self,
        problem: &dyn Problem<D>,
        x0: &[SVector<f64, D>],
    ) {
        for probe in problem.probes() {
            let Some(p) = probe.nearest(x0) else {
                continue;
            };
            let [exact, other, none] = REFERENCE_KINDS;
            let reference_kind = if problem.exact(&x0[p], 0.0).is_some() {
                exact
            } else if problem.probe_reference(&x0[p], 0.0).is_some() {
                other
            } else {
                none
            };
            self.probes.push(ProbeRecord {
                name: probe.name.to_string(),
                particle: p as i64,
                x0: x0[p].iter().copied().collect(),
                quantity: probe.quantity.name().to_string(),
                component: probe
                    .quantity
                    .component()
                    .iter()
                    .map(|&k| k as i64)
                    .collect(),
                reference_kind: reference_kind.to_string(),
                ..ProbeRecord::default()
            });
            self.quantities.push(probe.quantity);
        }
    }

    /// Appends each probe's value at step `step`, time `t`, with `velocity(p)` particle p's
    /// velocity synchronised to `t`, and the problem's reference value there (NaN if none).
    pub fn record_probes<const D: usize>(
        &mut self,
        step: usize,
        t: f64,
        particles: &Particles<D>,
        velocity: impl Fn(usize) -> SVector<f64, D>,
        problem: &dyn Problem<D>,
    ) {
        for (probe, quantity) in self.probes.iter_mut().zip(&self.quantities) {
            let p = probe.particle as usize;
            let displacement = particles.x[p] - particles.x0[p];
            let value = quantity.of(&displacement, &velocity(p), &particles.stress[p]);
            let reference = problem
                .probe_reference(&particles.x0[p], t)
                .map_or(f64::NAN, |r| {
                    quantity.of(&r.displacement, &r.velocity, &r.stress)
                });
            probe.time.push(t);
            probe.step.push(step as i64);
            probe.value.push(value);
            probe.reference.push(reference);
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
        particle_mass: &[f64],
        particle_velocity: &[SVector<f64, D>],
        grid_mass: f64,
        grid_momentum: &SVector<f64, D>,
    ) {
        let mut mass = 0.0;
        let mut momentum = SVector::<f64, D>::zeros();
        let mut scale = 0.0;
        for (m, v) in particle_mass.iter().zip(particle_velocity) {
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
