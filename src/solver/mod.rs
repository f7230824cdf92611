//! One run: build the problem, seed particles, step, sample, and return the record. Runs of
//! reconstruction benchmarks, which do not step, go to `reconstruction`, and those of the
//! shape-function benchmark to `shape_functions`.

mod footprint;
mod reconstruction;
mod recorder;
mod reference;
mod shape_functions;
mod transfer;

use std::time::Instant;

use nalgebra::SVector;

use crate::benchmarks::{AnyProblem, Problem};
use crate::divergence::Divergence;
use crate::experiment::{ResolvedRun, RunMethod};
use crate::grid::{FixedDof, Grid, GridState};
use crate::integrate::predictor_corrector::PredictorCorrector;
use crate::integrate::{self, leapfrog, musl, IntegratorKind};
use crate::methods::{self, Method};
use crate::output::{Diagnostics, MethodParts, ParticleTable, RunRecord, RunStatus, Unstepped};
use crate::parallel;
use crate::particles::Particles;
use crate::reconstruct::{nodal_forces, FitStats};
use crate::reconstruction_methods::ReconstructionMethod;
use crate::shape::ShapeKind;
use crate::shape::{
    DualDomain, LinearHat, LocalMaxEnt, ParticleDomains, Shape, SplineDegree, Stencils,
};
use crate::shape_methods::ShapeMethod;

use recorder::{GridSample, Recorder};
use transfer::Transfer;

/// Runs one configuration, keeping its whole history in the record. Never panics on bad
/// numbers: a run that cannot start is `failed`, a run that blows up is `diverged`, each with
/// the reason in `message`.
pub fn simulate(run: &ResolvedRun) -> RunRecord {
    Job::new(run).compute(None)
}

/// A run ready to compute: what its method works on, built once, so that the runner can weigh
/// its memory (`estimated_bytes`) before it starts.
pub struct Job<'a> {
    run: &'a ResolvedRun,
    /// What the run computes, or why it cannot start.
    work: Result<Work, String>,
}

/// The problem of a stepped run with what steps it; the method of a run that does not step.
enum Work {
    Mpm(Method, AnyProblem),
    Reference(AnyProblem),
    Reconstruction(&'static ReconstructionMethod),
    Basis(&'static ShapeMethod),
}

impl<'a> Job<'a> {
    /// Builds the problem of a stepped run; the problem seeds no particles until it runs.
    pub fn new(run: &'a ResolvedRun) -> Self {
        let problem = || {
            run.benchmark
                .problem(&run.spec.params)
                .map_err(|e| e.to_string())
        };
        let work = match run.method {
            RunMethod::Mpm(method) => problem().map(|p| Work::Mpm(method, p)),
            RunMethod::Reference(_) => problem().map(Work::Reference),
            RunMethod::Reconstruction(method) => Ok(Work::Reconstruction(method)),
            RunMethod::Basis(method) => Ok(Work::Basis(method)),
        };
        Job { run, work }
    }

    /// The run's estimated peak memory in bytes (`footprint`).
    pub fn estimated_bytes(&self) -> f64 {
        footprint::estimated_bytes(self)
    }

    /// Computes the run; with a `file`, the history of a stepped run is streamed into it as it
    /// is sampled (the record's `stream`), so that its memory does not grow with the samples,
    /// and `write_record` completes the file.
    pub fn compute(self, file: Option<&hdf5::File>) -> RunRecord {
        let started = Instant::now();
        let run = self.run;
        let mut record = match self.work {
            Ok(Work::Mpm(method, AnyProblem::D1(problem))) => {
                Run::new(run, method, problem, file).execute()
            }
            Ok(Work::Mpm(method, AnyProblem::D2(problem))) => {
                Run::new(run, method, problem, file).execute()
            }
            Ok(Work::Reference(problem)) => reference::solve(run, problem, file),
            Ok(Work::Reconstruction(method)) => reconstruction::evaluate(run, method),
            Ok(Work::Basis(method)) => shape_functions::evaluate(run, method),
            Err(message) => base_record(run, message),
        };
        record.wall_seconds = started.elapsed().as_secs_f64();
        record
    }
}

/// The grid basis of a run as the particles see it.
enum Basis<const D: usize> {
    /// The hat evaluated at x_p.
    Hat,
    /// The hat averaged over each particle's domain.
    Domains(ParticleDomains<D>),
    /// The B-spline of a degree evaluated at x_p.
    BSpline(SplineDegree),
    /// The hat with the dual-domain gradient, from the integrals over this step's material,
    /// which the stencils hold (`Stencils::attach_dual_domain`).
    DualDomain,
    /// Local maximum-entropy functions evaluated at x_p.
    LocalMaxEnt(LocalMaxEnt<D>),
}

/// The particle-to-grid mappings of a step: the transfer at its start, MUSL's remap of the
/// updated particle velocities, or the predictor-corrector's mapping of v_p + dt/2 a_p.
#[derive(Clone, Copy)]
enum Mapping {
    Step,
    Remap,
    Predictor,
}

impl<const D: usize> Basis<D> {
    /// The basis as a function of position on the grid, for transfers that evaluate it at
    /// points of their own. Particle domains have none; their grid basis is the hat.
    fn shape<'a>(&'a self, stencils: &'a Stencils<D>) -> &'a dyn Shape<D> {
        match self {
            Basis::Hat | Basis::Domains(_) => &LinearHat,
            Basis::BSpline(degree) => degree.shape(),
            Basis::DualDomain => stencils
                .dual_domain()
                .expect("the dual-domain integrals are attached with the basis"),
            Basis::LocalMaxEnt(lme) => lme,
        }
    }
}

/// The state of one run in progress.
struct Run<'a, const D: usize> {
    resolved: &'a ResolvedRun,
    method: Method,
    problem: Box<dyn Problem<D>>,
    basis: Basis<D>,
    grid: Grid<D>,
    particles: Particles<D>,
    stencils: Stencils<D>,
    transfer: Transfer<D>,
    nodes: GridState<D>,
    fixed: Vec<FixedDof>,
    body_force: Vec<SVector<f64, D>>,
    /// Nodal velocity rebuilt after the particles moved (MUSL and eqs 23-24 only).
    remapped: Vec<SVector<f64, D>>,
    /// The particle accelerations and scratch of the predictor-corrector (left empty by the
    /// other integrators).
    predictor: PredictorCorrector<D>,
    fits: FitStats,
    /// The flat index of every particle's cell, after the last move.
    cells: Vec<usize>,
    grid_crossings: usize,
    recorder: Recorder<D>,
    /// The wall time of each completed step, for `RunRecord::step_seconds`.
    step_seconds: Vec<f64>,
}

impl<'a, const D: usize> Run<'a, D> {
    fn new(
        resolved: &'a ResolvedRun,
        method: Method,
        mut problem: Box<dyn Problem<D>>,
        file: Option<&hdf5::File>,
    ) -> Self {
        let grid = Grid::with_dofs(&problem.domain(), method.shape.dofs());
        let particles = problem.seed_particles(&grid);
        problem.attach_particles(&particles.x0);
        let fixed = fixed_dofs(&grid, &problem.fixed_faces());
        let mut recorder = Recorder::new();
        recorder.attach_probes(problem.as_ref(), &particles.x0);
        recorder.attach_grid(&grid);
        if let Some(file) = file {
            recorder.stream_to(
                file,
                particles.len(),
                problem.steps(),
                resolved.spec.output_every,
            );
        }
        let n = particles.len();
        let particle_mass = particles.mass.iter().cloned().fold(0.0, f64::max);
        let per_point = match method.shape {
            ShapeKind::Domain(_) => ParticleDomains::<D>::narrow_nodes_per_point(),
            shape => footprint::stencil_nodes::<D>(shape),
        };
        let mut stencils = Stencils::new(per_point, n);
        let basis = match method.shape {
            ShapeKind::Linear => Basis::Hat,
            ShapeKind::Domain(shape) => Basis::Domains(ParticleDomains::new(shape, &particles)),
            ShapeKind::BSpline(degree) => Basis::BSpline(degree),
            ShapeKind::DualDomain(integrals) => {
                stencils.attach_dual_domain(DualDomain::new(&grid, integrals));
                Basis::DualDomain
            }
            ShapeKind::LocalMaxEnt(settings) => {
                // `methods::resolve` has checked gamma and the cut-off for this dimension.
                let lme = LocalMaxEnt::with_tolerance(settings.gamma, settings.tolerance)
                    .expect("LME parameters are validated before a run starts");
                Basis::LocalMaxEnt(lme)
            }
        };
        Run {
            resolved,
            method,
            transfer: Transfer::new(
                &method.transfer,
                &grid,
                basis.shape(&stencils),
                &fixed,
                method.integrator.remaps_velocity(),
            ),
            stencils,
            basis,
            nodes: GridState::new(grid.num_nodes(), particle_mass),
            remapped: vec![SVector::zeros(); grid.num_nodes()],
            predictor: PredictorCorrector::default(),
            grid,
            particles,
            fixed,
            body_force: vec![SVector::zeros(); n],
            fits: FitStats::default(),
            cells: Vec::new(),
            grid_crossings: 0,
            recorder,
            step_seconds: Vec::new(),
            problem,
        }
    }

    fn execute(mut self) -> RunRecord {
        let (steps, outcome) = self.step_all();
        let mut record = stepped_record(
            self.resolved,
            Stepped {
                parts: self.method.into(),
                h: self.grid.h,
                dt: self.problem.dt(),
                planned: self.problem.steps(),
                steps,
                outcome,
                particles: self.particles,
                recorder: self.recorder,
                diagnostics: Diagnostics {
                    reconstructions: self.fits.fits,
                    rank_deficient: self.fits.rank_deficient,
                    grid_crossings: self.grid_crossings,
                    lme_failures: match &self.basis {
                        Basis::LocalMaxEnt(lme) => lme.failures(),
                        _ => 0,
                    },
                },
            },
        );
        record.step_seconds = median(&mut self.step_seconds);
        // The file counts them; the message makes them visible in summary.csv and report.md.
        let failures = record.diagnostics.lme_failures;
        if failures > 0 {
            let note = format!(
                "{failures} LME evaluations stopped short of the Newton tolerance \
                 (/diagnostics lme_failures)"
            );
            if !record.message.is_empty() {
                record.message.push_str("; ");
            }
            record.message.push_str(&note);
        }
        record
    }

    /// Steps to the final time; returns the steps completed and, on divergence, the step
    /// that failed and why.
    fn step_all(&mut self) -> (usize, Result<(), (usize, Divergence)>) {
        let dt = self.problem.dt();
        let steps = self.problem.steps();
        let every = self.resolved.spec.output_every;
        let mut synced = vec![SVector::zeros(); self.particles.len()];
        if let Err(reason) = self
            .locate_particles()
            .and_then(|()| self.update_stencils())
        {
            return (0, Err((0, reason)));
        }
        for s in 0..=steps {
            let started = Instant::now();
            let t = s as f64 * dt;
            self.problem.body_force(t, &mut self.body_force);
            // Staggered velocities start with a half kick from v^0 to v^{1/2}.
            let half_kick = s == 0 && self.method.integrator.staggers_velocity();
            let kick = if half_kick { 0.5 * dt } else { dt };
            if self.method.integrator == IntegratorKind::PredictorCorrector {
                // The predictor-corrector solves its grid after the stress update.
                self.predictor
                    .predict(&self.stencils, &self.particles, dt, &mut self.nodes);
                self.track_mapping(Mapping::Predictor);
                integrate::apply_fixed(&mut self.nodes.velocity, &self.fixed);
            } else {
                match self.transfer.map_to_grid(
                    &self.stencils,
                    &self.particles,
                    &self.body_force,
                    &mut self.nodes,
                ) {
                    Ok(stats) => self.fits += stats,
                    Err(reason) => return (s, Err((s, reason))),
                }
                self.track_mapping(Mapping::Step);
                if let Err(reason) = self.transfer.solve_grid(&mut self.nodes, &self.fixed, kick) {
                    return (s, Err((s, reason)));
                }
            }
            self.record_probes(s, t, synchronising_half(s, dt));
            if s == 0 || s == steps || (every > 0 && s % every == 0) {
                let velocity = if self.method.synchronises_samples() {
                    let half = synchronising_half(s, dt);
                    leapfrog::synchronized_velocity(
                        &self.stencils,
                        &self.particles,
                        &self.nodes,
                        half,
                        &mut synced,
                    );
                    &synced
                } else {
                    &self.particles.v
                };
                let (grid_velocity, grid_time) =
                    sampled_grid_velocity(&self.method, &self.nodes, t, dt);
                let grid = GridSample {
                    // In node order, so the total is the same on every run.
                    mass: self.nodes.mass.iter().sum(),
                    velocity: grid_velocity,
                    time: grid_time,
                };
                self.recorder
                    .sample(s, t, &self.particles, velocity, grid, self.problem.as_ref());
            }
            if s == steps {
                break;
            }
            if let Err(reason) = self
                .update_particles(kick, dt)
                .and_then(|()| self.locate_particles())
                .and_then(|()| self.update_stencils())
            {
                return (s, Err((s + 1, reason)));
            }
            self.step_seconds.push(started.elapsed().as_secs_f64());
        }
        (steps, Ok(()))
    }

    /// The probes' values at step `s`, time `t`; `half` as in `synchronising_half`. A
    /// synchronised sample synchronises the velocity of the probed particles only.
    fn record_probes(&mut self, s: usize, t: f64, half: f64) {
        let synchronised = self.method.synchronises_samples();
        let (stencils, particles, nodes) = (&self.stencils, &self.particles, &self.nodes);
        let velocity = |p: usize| {
            if synchronised {
                leapfrog::synchronized_velocity_of(stencils, particles, nodes, half, p)
            } else {
                particles.v[p]
            }
        };
        self.recorder
            .record_probes(s, t, particles, velocity, self.problem.as_ref());
    }

    /// The cell of every particle; after the first call, counts the particles that changed
    /// cell since the last (Wobbes et al. sec 5 count these grid crossings to explain MPM's
    /// error).
    fn locate_particles(&mut self) -> Result<(), Divergence> {
        let first = self.cells.is_empty();
        self.cells.resize(self.particles.len(), usize::MAX);
        let grid = &self.grid;
        let chunks = self
            .cells
            .chunks_mut(parallel::CHUNK)
            .zip(self.particles.x.chunks(parallel::CHUNK))
            .enumerate();
        // Each chunk's crossings up to its first particle off the grid, if any; the count
        // stops at the first such particle of all, as a sequential pass would.
        let locate = |(c, (cells, x)): (usize, (&mut [usize], &[SVector<f64, D>]))| {
            let mut crossings = 0;
            for (q, (cell, x)) in cells.iter_mut().zip(x).enumerate() {
                let Some((found, _)) = grid.locate(x) else {
                    let particle = c * parallel::CHUNK + q;
                    return (crossings, Some(Divergence::LeftGrid { particle }));
                };
                let found = grid.cell_index(found);
                if found != *cell {
                    *cell = found;
                    crossings += usize::from(!first);
                }
            }
            (crossings, None)
        };
        for (crossings, left) in parallel::map_chunks(chunks, locate) {
            self.grid_crossings += crossings;
            if let Some(reason) = left {
                return Err(reason);
            }
        }
        Ok(())
    }

    /// Records how far the totals the last mapping gave the DOFs are from the particles'.
    fn track_mapping(&mut self, mapping: Mapping) {
        let (velocity, sent) = match mapping {
            Mapping::Step => (&self.nodes.velocity, self.particles.v.as_slice()),
            Mapping::Remap => (&self.remapped, self.particles.v.as_slice()),
            Mapping::Predictor => (&self.nodes.velocity, self.predictor.predicted()),
        };
        let grid_mass = self.nodes.mass.iter().sum();
        let momentum = self.transfer.received_momentum(&self.nodes.mass, velocity);
        self.recorder
            .track_mapping(&self.particles.mass, sent, grid_mass, &momentum);
    }

    /// The shape functions of every particle at its current position and domain.
    fn update_stencils(&mut self) -> Result<(), Divergence> {
        match &mut self.basis {
            Basis::Hat => self
                .stencils
                .update(&LinearHat, &self.grid, &self.particles.x)
                .map_err(|particle| Divergence::LeftGrid { particle }),
            Basis::Domains(domains) => {
                domains.fill(&self.grid, &mut self.particles, &mut self.stencils)?;
                Ok(())
            }
            Basis::BSpline(degree) => self
                .stencils
                .update(degree.shape(), &self.grid, &self.particles.x)
                .map_err(|particle| Divergence::LeftGrid { particle }),
            Basis::DualDomain => {
                let dual = self
                    .stencils
                    .update_dual_domain(
                        &self.grid,
                        &self.particles.x,
                        &self.particles.volume,
                        &self.cells,
                    )
                    .map_err(|particle| Divergence::LeftGrid { particle })?;
                self.transfer.refresh_basis(dual);
                Ok(())
            }
            Basis::LocalMaxEnt(lme) => lme
                .update_particles(&mut self.stencils, &self.grid, &self.particles.x)
                .map_err(|particle| Divergence::LeftGrid { particle }),
        }
    }

    /// Step 3 of the method's integrator, after the grid solve.
    fn update_particles(&mut self, kick: f64, dt: f64) -> Result<(), Divergence> {
        let material = self.problem.material();
        let drift = match self.method.integrator {
            IntegratorKind::PredictorCorrector => return self.correct_and_move(dt),
            IntegratorKind::Euler | IntegratorKind::EulerCorrected => &self.nodes.velocity,
            IntegratorKind::Leapfrog | IntegratorKind::Musl | IntegratorKind::Usl => {
                &self.nodes.velocity_new
            }
        };
        if let Basis::Domains(domains) = &mut self.basis {
            domains.advance_corners(&self.grid, drift, dt)?;
        }
        if !self.method.integrator.remaps_velocity() {
            return leapfrog::update_particles(
                &self.stencils,
                &mut self.particles,
                &self.nodes,
                drift,
                kick,
                dt,
                &material,
            );
        }
        musl::move_particles(
            &self.stencils,
            &mut self.particles,
            &self.nodes,
            drift,
            dt,
            None,
        )?;
        self.transfer.remap_velocity(
            &self.stencils,
            &self.particles,
            &self.nodes,
            &mut self.remapped,
        )?;
        self.track_mapping(Mapping::Remap);
        integrate::apply_fixed(&mut self.remapped, &self.fixed);
        integrate::deform_particles(
            &self.stencils,
            &mut self.particles,
            &self.remapped,
            dt,
            &material,
        )
    }

    /// Steps 2-5 of `integrate::predictor_corrector` after its predictor, at the
    /// start-of-step positions: the stress from v~, the forces, the corrector, the move.
    fn correct_and_move(&mut self, dt: f64) -> Result<(), Divergence> {
        let material = self.problem.material();
        let (stencils, particles, nodes) = (&self.stencils, &mut self.particles, &mut self.nodes);
        integrate::deform_particles(stencils, particles, &nodes.velocity, dt, &material)?;
        nodal_forces(stencils, particles, &self.body_force, &mut nodes.force);
        let drift = self.predictor.correct(nodes, &self.fixed, dt);
        if let Basis::Domains(domains) = &mut self.basis {
            domains.advance_corners(&self.grid, drift, dt)?;
        }
        self.predictor
            .move_particles(stencils, particles, nodes, dt)
    }
}

/// The nodal velocity a sample at time `t` compares with the exact one, and the time it
/// belongs to: the grid solve's updated velocity, v_i^{s+1/2} at t + dt/2 where the velocities
/// are half-step ones (the leapfrog, and MUSL or USL read as centred), v_i^{s+1} at t + dt for
/// whole-step ones. The predictor-corrector solves its grid after the sample; its nodal
/// velocity then is the predictor v_i^s + dt/2 a_i, the half-step velocity of the
/// central-difference form of its Newmark scheme, at t + dt/2.
fn sampled_grid_velocity<'a, const D: usize>(
    method: &Method,
    nodes: &'a GridState<D>,
    t: f64,
    dt: f64,
) -> (&'a [SVector<f64, D>], f64) {
    if method.integrator == IntegratorKind::PredictorCorrector {
        (&nodes.velocity, t + 0.5 * dt)
    } else if method.synchronises_samples() {
        (&nodes.velocity_new, t + 0.5 * dt)
    } else {
        (&nodes.velocity_new, t + dt)
    }
}

/// What a synchronised sample adds to the half-step velocity at step `s`: a^s dt / 2, or
/// nothing at s = 0 where the particles still carry v^0.
fn synchronising_half(s: usize, dt: f64) -> f64 {
    if s == 0 {
        0.0
    } else {
        0.5 * dt
    }
}

/// The end of a stepped run (MPM or a reference solver), whatever method made it.
/// The median of `times` (NaN for none): a step's cost, which the samples written to the file
/// and the other processes of the machine disturb only now and then.
fn median(times: &mut [f64]) -> f64 {
    if times.is_empty() {
        return f64::NAN;
    }
    times.sort_by(f64::total_cmp);
    let mid = times.len() / 2;
    if times.len() % 2 == 1 {
        times[mid]
    } else {
        0.5 * (times[mid - 1] + times[mid])
    }
}

struct Stepped<const D: usize> {
    parts: MethodParts,
    h: f64,
    dt: f64,
    planned: usize,
    /// Steps completed.
    steps: usize,
    /// On divergence, the step that failed and why.
    outcome: Result<(), (usize, Divergence)>,
    particles: Particles<D>,
    recorder: Recorder<D>,
    diagnostics: Diagnostics,
}

fn stepped_record<const D: usize>(resolved: &ResolvedRun, run: Stepped<D>) -> RunRecord {
    let (status, message) = match run.outcome {
        Ok(()) => (RunStatus::Ok, String::new()),
        Err((step, reason)) => (
            RunStatus::Diverged,
            format!("step {step} (t = {:e}): {reason}", step as f64 * run.dt),
        ),
    };
    let mut record = base_record(resolved, message);
    record.parts = run.parts;
    record.dim = D;
    record.h = run.h;
    record.dt = run.dt;
    record.t_end = run.dt * run.planned as f64;
    record.steps = run.steps;
    record.status = status;
    record.particles = ParticleTable {
        x0: run
            .particles
            .x0
            .iter()
            .flat_map(|x| x.iter().copied())
            .collect(),
        mass: run.particles.mass,
        volume0: run.particles.volume0,
    };
    record.history = run.recorder.history;
    record.grid = run.recorder.grid;
    record.errors = run.recorder.errors;
    record.conservation = run.recorder.conservation;
    record.probes = run.recorder.probes;
    record.stream = run.recorder.stream;
    record.diagnostics = run.diagnostics;
    record
}

/// The velocity components held at zero: the normal component of the DOFs on each fixed
/// face. Every basis interpolates at the faces (the hat at its nodes, the clamped B-spline at
/// its end DOFs: on a face only the DOFs there are nonzero, and they sum to one), so this
/// holds the normal velocity of the whole face at zero.
fn fixed_dofs<const D: usize>(grid: &Grid<D>, faces: &[[bool; 2]; D]) -> Vec<FixedDof> {
    let last = grid.nodes_per_dim() - 1;
    let mut fixed = Vec::new();
    for i in 0..grid.num_nodes() {
        let ijk = grid.node_coords(i);
        for k in 0..D {
            let on_lower = faces[k][0] && ijk[k] == 0;
            let on_upper = faces[k][1] && ijk[k] == last;
            if on_lower || on_upper {
                fixed.push((i as u32, k as u8));
            }
        }
    }
    fixed
}

/// A record with the run's identity and status `failed` with `message`: the whole record of a
/// run that failed before it computed anything; a run that starts fills in the rest.
pub fn base_record(run: &ResolvedRun, message: String) -> RunRecord {
    // A run that is not MPM records the parts of the first preset until it fills in its own.
    let method = match run.method {
        RunMethod::Mpm(method) => method,
        _ => methods::PRESETS.entries[0].method,
    };
    RunRecord {
        spec: run.spec.clone(),
        parts: method.into(),
        dim: run.dim(),
        cells: run.cells,
        ppc: run.ppc,
        h: f64::NAN,
        dt: f64::NAN,
        t_end: run.t_end,
        steps: 0,
        status: RunStatus::Failed,
        message,
        wall_seconds: 0.0,
        step_seconds: f64::NAN,
        particles: ParticleTable::default(),
        history: Default::default(),
        grid: Default::default(),
        errors: Default::default(),
        conservation: Default::default(),
        diagnostics: Default::default(),
        probes: Vec::new(),
        unstepped: Unstepped::None,
        stream: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;
    use std::path::Path;

    /// The run of `resolved`, a 1D MPM run, ready to step.
    fn one_dimensional_run(resolved: &ResolvedRun) -> Run<'_, 1> {
        match Job::new(resolved).work.unwrap() {
            Work::Mpm(method, AnyProblem::D1(problem)) => Run::new(resolved, method, problem, None),
            _ => unreachable!("a 1D MPM run"),
        }
    }

    /// Steps 1-2 of a step at time `t`: locate, the stencils, the body force, the mapping and
    /// the grid solve with a whole kick dt.
    fn grid_step(run: &mut Run<1>, t: f64, dt: f64) {
        run.locate_particles().unwrap();
        run.update_stencils().unwrap();
        run.problem.body_force(t, &mut run.body_force);
        run.transfer
            .map_to_grid(
                &run.stencils,
                &run.particles,
                &run.body_force,
                &mut run.nodes,
            )
            .unwrap();
        run.transfer
            .solve_grid(&mut run.nodes, &run.fixed, dt)
            .unwrap();
    }

    /// The second step of `mpm` on Tran's bar with `integrator`, taken piece by piece: the
    /// particles' F after it, and I + dt sum_i v_i (x) grad N_ip with the nodal velocity the
    /// grid solve produced and the start-of-step stencils.
    fn second_step(integrator: &str) -> (Vec<SMatrix<f64, 1, 1>>, Vec<SMatrix<f64, 1, 1>>) {
        let text = format!(
            "name: t\nbenchmark: mms1d_tran\nparams: {{method: mpm, integrator: {integrator}, \
             cells: 4, ppc: 2, dt: 1.0e-4, t_end: 0.02}}\n"
        );
        let exp = crate::experiment::parse(&text, Path::new("t.yaml")).unwrap();
        let mut run = one_dimensional_run(&exp.runs[0]);
        let dt = run.problem.dt();
        let grid_solve = |run: &mut Run<1>, s: usize| grid_step(run, s as f64 * dt, dt);
        // At t = 0 the stress and the body force vanish, so every integrator agrees; the
        // second step is compared.
        grid_solve(&mut run, 0);
        run.update_particles(dt, dt).unwrap();
        grid_solve(&mut run, 1);
        let expected = (0..run.particles.len())
            .map(|p| {
                let grad_v: SMatrix<f64, 1, 1> = run
                    .stencils
                    .of(p)
                    .map(|(i, _, g)| run.nodes.velocity_new[i] * g.transpose())
                    .sum();
                (SMatrix::identity() + grad_v * dt) * run.particles.f[p]
            })
            .collect();
        run.update_particles(dt, dt).unwrap();
        (run.particles.f.clone(), expected)
    }

    /// USL deforms with the nodal velocity of the grid solve of the same step (the CPLS
    /// code's `nvelo_si = nmomentum_si / nmass_si` before `Update_Stress`); MUSL with the
    /// velocity rebuilt from the moved particles, which differs.
    #[test]
    fn usl_deforms_with_the_updated_grid_velocity() {
        let (f, expected) = second_step("usl");
        for (a, b) in f.iter().zip(&expected) {
            assert!((a - b).norm() < 1e-15, "{a} against {b}");
        }
        let (f, expected) = second_step("musl");
        let largest = f
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(largest > 1e-9, "MUSL matched USL to {largest:e}");
    }

    /// A body in uniform translation (no stress, no fixed DOFs) keeps its velocity and moves
    /// by v t under every MUSL composition: the mapping, the remap and the solve with either
    /// mass matrix reproduce a constant, so MUSL adds no velocity error of its own.
    #[test]
    fn musl_translates_a_uniform_velocity_exactly() {
        let musl = [
            "mpm_musl",
            "mpm_tls",
            "bsmpm",
            "bsmpm_consistent",
            "bsmpm_tls",
            "ddmpm",
            "ddmpm_tls",
        ];
        let v = 0.3;
        for name in musl {
            let text = format!(
                "name: t\nbenchmark: vibrating_bar\nparams: {{method: {name}, cells: 5, ppc: 3, \
                 dt: 1.0e-4, t_end: 1.0e-2}}\n"
            );
            let exp = crate::experiment::parse(&text, Path::new("t.yaml")).unwrap();
            let mut run = one_dimensional_run(&exp.runs[0]);
            let method = run.method;
            // The grid [0, 1] with the body shrunk to its middle, free at both ends.
            run.fixed.clear();
            run.transfer = Transfer::new(
                &method.transfer,
                &run.grid,
                run.basis.shape(&run.stencils),
                &[],
                method.integrator.remaps_velocity(),
            );
            for p in 0..run.particles.len() {
                let x = 0.3 + 0.4 * run.particles.x[p][0];
                run.particles.x[p][0] = x;
                run.particles.x0[p][0] = x;
                run.particles.v[p][0] = v;
            }
            let dt = run.problem.dt();
            for s in 0..40 {
                grid_step(&mut run, s as f64 * dt, dt);
                run.update_particles(dt, dt).unwrap();
                let t = (s + 1) as f64 * dt;
                for p in 0..run.particles.len() {
                    let (vp, xp) = (run.particles.v[p][0], run.particles.x[p][0]);
                    assert!(
                        (vp - v).abs() < 1e-14,
                        "{name}: step {s}, particle {p}: v {vp} against {v}"
                    );
                    let moved = xp - run.particles.x0[p][0];
                    assert!(
                        (moved - v * t).abs() < 1e-14,
                        "{name}: step {s}, particle {p}: moved {moved} against {}",
                        v * t
                    );
                }
            }
        }
    }
}
