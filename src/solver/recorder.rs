use nalgebra::SVector;

use crate::benchmarks::{ProbeQuantity, Problem};
use crate::experiment::sample_count;
use crate::grid::Grid;
use crate::output::{
    Conservation, Errors, GridHistory, History, HistoryStream, ProbeRecord, StreamShape,
    REFERENCE_KINDS,
};
use crate::particles::Particles;

/// Appends sampled particle states and grid velocities, their errors against the exact
/// solution and the mass totals, and every step the values at the problem's probes. With a
/// stream (`stream_to`) the arrays that grow with the samples and steps go to the run file as
/// they are recorded, and only the per-sample totals and norms stay in memory.
pub struct Recorder<const D: usize> {
    pub history: History,
    pub grid: GridHistory,
    pub errors: Errors,
    pub conservation: Conservation,
    pub probes: Vec<ProbeRecord>,
    /// What each of `probes` records.
    quantities: Vec<ProbeQuantity>,
    /// Where the DOFs of the grid sit (none until `attach_grid`).
    dofs: Vec<SVector<f64, D>>,
    /// The run file's stream, or why writing to it failed (after which what is recorded is
    /// dropped, so memory stays bounded, and the run's file is not written).
    pub stream: Option<Result<HistoryStream, String>>,
}

/// What a sample records of the grid: the total nodal mass the transfer of the step
/// assembled, and the nodal velocity compared with the exact one at `time`, the time it
/// belongs to.
pub struct GridSample<'a, const D: usize> {
    pub mass: f64,
    pub velocity: &'a [SVector<f64, D>],
    pub time: f64,
}

impl<const D: usize> Recorder<D> {
    pub fn new() -> Self {
        Recorder {
            history: History::default(),
            grid: GridHistory::default(),
            errors: Errors::default(),
            conservation: Conservation::default(),
            probes: Vec::new(),
            quantities: Vec::new(),
            dofs: Vec::new(),
            stream: None,
        }
    }

    /// Streams the growing arrays of `particles` particles into `file` from now on (once,
    /// after `attach_grid` and `attach_probes`, before the first record), for a run of
    /// `steps` steps sampled every `every`.
    pub fn stream_to(&mut self, file: &hdf5::File, particles: usize, steps: usize, every: usize) {
        let shape = StreamShape {
            dim: D,
            particles,
            dofs: self.dofs.len(),
            samples: sample_count(steps, every),
            steps,
        };
        self.stream =
            Some(HistoryStream::create(file, shape, &self.probes).map_err(|e| e.to_string()));
    }

    /// Moves the last sample's per-particle and per-DOF arrays to the stream, if there is one.
    fn drain_sample(&mut self) {
        let Some(stream) = &mut self.stream else {
            return;
        };
        if let Ok(open) = stream {
            if let Err(e) = open.append_samples(1, &self.history, &self.grid, &self.errors) {
                *stream = Err(e.to_string());
            }
        }
        let h = &mut self.history;
        for values in [&mut h.x, &mut h.v, &mut h.stress, &mut h.density] {
            values.clear();
        }
        self.grid.v.clear();
        let e = &mut self.errors;
        for values in [&mut e.volume, &mut e.grid_velocity.pointwise]
            .into_iter()
            .chain(&mut e.pointwise)
        {
            values.clear();
        }
    }

    /// Moves the probes' last step to the stream, if there is one.
    fn drain_probes(&mut self) {
        let Some(stream) = &mut self.stream else {
            return;
        };
        if let Ok(open) = stream {
            if let Err(e) = open.append_probes(&self.probes) {
                *stream = Err(e.to_string());
            }
        }
        for probe in &mut self.probes {
            probe.time.clear();
            probe.step.clear();
            probe.value.clear();
            probe.reference.clear();
        }
    }

    /// The DOFs whose velocity every sample compares with the exact one (once, before
    /// stepping), and their quadrature weights: the trapezoidal rule over the DOF positions
    /// along each axis, so that the weights of the hat's nodes are h^D inside and half as much
    /// per face a node lies on (the integrals of the hats), and sum to the grid's volume.
    pub fn attach_grid(&mut self, grid: &Grid<D>) {
        let n = grid.nodes_per_dim();
        let axis_weights: [Vec<f64>; D] = std::array::from_fn(|axis| {
            let at = |i: usize| grid.dof_coordinate(axis, i);
            (0..n)
                .map(|i| 0.5 * (at((i + 1).min(n - 1)) - at(i.saturating_sub(1))))
                .collect()
        });
        self.dofs = (0..grid.num_nodes())
            .map(|i| grid.node_position(i))
            .collect();
        self.grid.x = self.dofs.iter().flat_map(|x| x.iter().copied()).collect();
        self.grid.weight = (0..grid.num_nodes())
            .map(|i| {
                let ijk = grid.node_coords(i);
                (0..D).map(|k| axis_weights[k][ijk[k]]).product()
            })
            .collect();
    }

    /// Resolves the problem's probes to the particles nearest them (once, after seeding).
    /// The reference is `exact` where the problem has an exact solution, `static` where it
    /// gives another one for probes only, else `none`.
    pub fn attach_probes(&mut self, problem: &dyn Problem<D>, x0: &[SVector<f64, D>]) {
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
    pub fn record_probes(
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
        self.drain_probes();
    }

    /// Records the state at step `step`, time `t`, with `velocity` synchronised to `t`, and
    /// what `grid` gives of the grid (its velocity one per attached DOF, or none for a run
    /// without a grid).
    pub fn sample(
        &mut self,
        step: usize,
        t: f64,
        particles: &Particles<D>,
        velocity: &[SVector<f64, D>],
        grid: GridSample<D>,
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
        self.sample_grid(t, &grid, problem);
        // Summed in particle order, so the total is the same on every run.
        let particle_mass = particles.mass.iter().sum();
        self.conservation.particle_mass.push(particle_mass);
        self.conservation.grid_mass.push(grid.mass);
        self.drain_sample();
    }

    /// The grid velocity of the step sampled at time `t` and its error at each DOF x_a: the
    /// grid moves with the material during the step (Gong sec 4.3.4) and is reset after it, so
    /// DOF a carries the velocity of the material point at x_a at `t`, X_a = X(x_a, t) from
    /// the problem's inverse motion, at the time the velocity belongs to, t_g = `grid.time`:
    /// e_a = |v_a - V(X_a, t_g)|.
    fn sample_grid(&mut self, t: f64, grid: &GridSample<D>, problem: &dyn Problem<D>) {
        debug_assert_eq!(grid.velocity.len(), self.dofs.len());
        self.grid.time.push(grid.time);
        let e = &mut self.errors.grid_velocity;
        let (mut sum_w, mut sum_n, mut known) = (0.0, 0.0, 0usize);
        for ((x, v), w) in self.dofs.iter().zip(grid.velocity).zip(&self.grid.weight) {
            self.grid.v.extend(v.iter());
            let exact = problem
                .material_point(x, t)
                .and_then(|x0| problem.exact(&x0, grid.time));
            let Some(exact) = exact else {
                e.pointwise.push(f64::NAN);
                continue;
            };
            let value = (v - exact.velocity).norm();
            e.pointwise.push(value);
            sum_w += w * value * value;
            sum_n += value * value;
            known += 1;
        }
        let (l2, rms) = if known == 0 {
            (f64::NAN, f64::NAN)
        } else {
            (sum_w.sqrt(), (sum_n / known as f64).sqrt())
        };
        e.l2.push(l2);
        e.rms.push(rms);
    }

    /// Compares the totals a mapping gave the grid with the particles' totals it started
    /// from and keeps the largest relative errors of the run.
    pub fn track_mapping(
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

    fn sample_errors(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{gong_mms, thesis_params, SineMms};
    use crate::shape::SplineDegree;

    /// Sampled at t = 3.7 ms, when the material has moved by up to 3.3 % of the box, with a
    /// grid velocity that belongs to 4.2 ms.
    const T: f64 = 0.0037;
    const T_GRID: f64 = 0.0042;

    /// Gong's 2D problem on 4 cells with a recorder attached to its grid.
    fn setup() -> (SineMms<2>, Grid<2>, Recorder<2>) {
        let problem = gong_mms::<2>(&thesis_params(0.05, 4, 2)).unwrap();
        let grid = Grid::new(&problem.domain());
        let mut recorder = Recorder::new();
        recorder.attach_grid(&grid);
        (problem, grid, recorder)
    }

    /// At every DOF, the exact velocity at time `t_v` of the material point at the DOF at `t_x`.
    fn exact_nodal(
        problem: &SineMms<2>,
        grid: &Grid<2>,
        t_x: f64,
        t_v: f64,
    ) -> Vec<SVector<f64, 2>> {
        (0..grid.num_nodes())
            .map(|i| {
                let x0 = problem.material_point(&grid.node_position(i), t_x).unwrap();
                problem.exact(&x0, t_v).unwrap().velocity
            })
            .collect()
    }

    /// A sample at `T` with the grid velocity `v` belonging to `T_GRID`.
    fn sample(recorder: &mut Recorder<2>, problem: &SineMms<2>, v: &[SVector<f64, 2>]) {
        let grid = Grid::new(&problem.domain());
        let particles = problem.seed_particles(&grid);
        let velocity = particles.v.clone();
        let sample = GridSample {
            mass: 0.0,
            velocity: v,
            time: T_GRID,
        };
        recorder.sample(0, T, &particles, &velocity, sample, problem);
    }

    /// Hats integrate to h^2 inside, h^2/2 on an edge and h^2/4 at a corner; the B-spline's
    /// Greville abscissae 0, h/2, 3h/2, ... get h/4, 3h/4, h, ... per axis. Both sum to the
    /// volume of the grid.
    #[test]
    fn grid_weights_are_the_trapezoidal_rule_over_the_dofs() {
        let (_, grid, recorder) = setup();
        let h2 = grid.h * grid.h;
        let w = &recorder.grid.weight;
        assert_eq!(w.len(), 25);
        assert_eq!((w[0], w[1], w[6]), (0.25 * h2, 0.5 * h2, h2));
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let bar = gong_mms::<1>(&thesis_params(0.05, 4, 2)).unwrap();
        let spline = Grid::<1>::with_dofs(&bar.domain(), SplineDegree::Quadratic.dofs());
        let mut recorder = Recorder::<1>::new();
        recorder.attach_grid(&spline);
        let h = spline.h;
        assert_eq!(
            recorder.grid.weight,
            vec![0.25 * h, 0.75 * h, h, h, 0.75 * h, 0.25 * h]
        );
    }

    /// The exact velocity at `T_GRID` of the material points at the DOFs at `T` has no error,
    /// while the exact velocity at the DOFs at `T_GRID` (the material moved on) has; a uniform
    /// perturbation delta of one component has l2 error delta sqrt(area) = delta and rms delta;
    /// a perturbation at one corner DOF alone has l2 error delta sqrt(h^2/4) and rms
    /// delta / sqrt(25).
    #[test]
    fn grid_velocity_error_of_known_nodal_fields() {
        let (problem, grid, mut recorder) = setup();
        let exact = exact_nodal(&problem, &grid, T, T_GRID);
        sample(&mut recorder, &problem, &exact);
        let delta = 1e-3;
        let shifted: Vec<_> = exact
            .iter()
            .map(|v| v + SVector::<f64, 2>::new(0.0, delta))
            .collect();
        sample(&mut recorder, &problem, &shifted);
        let mut corner = exact.clone();
        corner[24][0] += delta;
        sample(&mut recorder, &problem, &corner);
        sample(
            &mut recorder,
            &problem,
            &exact_nodal(&problem, &grid, T_GRID, T_GRID),
        );
        let e = &recorder.errors.grid_velocity;
        assert_eq!((e.l2[0], e.rms[0]), (0.0, 0.0));
        assert!(e.pointwise[..25].iter().all(|&value| value == 0.0));
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b;
        assert!(close(e.l2[1], delta) && close(e.rms[1], delta), "{e:?}");
        assert!(close(e.l2[2], delta * 0.5 * grid.h), "{}", e.l2[2]);
        assert!(close(e.rms[2], delta / 5.0), "{}", e.rms[2]);
        assert!(e.l2[3] > 1e-3, "{}", e.l2[3]);
        assert_eq!(recorder.grid.time, vec![T_GRID; 4]);
        assert_eq!(recorder.grid.v.len(), 4 * 25 * 2);
    }

    /// Without the inverse motion every pointwise error of the grid velocity and its norms are
    /// NaN, while the small-strain bar's exact solution still gives the particle errors.
    #[test]
    fn grid_velocity_error_is_nan_without_an_exact_velocity_on_the_grid() {
        let problem = crate::benchmarks::vibrating_bar(&vibrating_bar_params()).unwrap();
        let grid = Grid::new(&problem.domain());
        let mut recorder = Recorder::<1>::new();
        recorder.attach_grid(&grid);
        let particles = problem.seed_particles(&grid);
        let nodal = vec![SVector::zeros(); grid.num_nodes()];
        let sample = GridSample {
            mass: 0.0,
            velocity: &nodal,
            time: 0.0,
        };
        recorder.sample(0, 0.0, &particles, &particles.v.clone(), sample, &problem);
        let e = &recorder.errors.grid_velocity;
        assert!(e.pointwise.iter().all(|v| v.is_nan()) && e.l2[0].is_nan() && e.rms[0].is_nan());
        assert!(recorder.errors.l2[1][0].is_finite());
    }

    fn vibrating_bar_params() -> crate::params::Params {
        let info = crate::benchmarks::CATALOG.find("vibrating_bar").unwrap();
        let mut params = crate::benchmarks::default_params(info.params);
        params.insert("cells".into(), crate::params::ParamValue::Int(4));
        params
    }
}
