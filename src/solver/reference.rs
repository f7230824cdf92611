//! A run of a reference method (`ulfem`): the same sampling, errors and run record as an MPM
//! run, with one point per element in place of the particles.

use nalgebra::SVector;

use super::recorder::{GridSample, Recorder};
use super::{base_record, stepped_record, Stepped};
use crate::benchmarks::{AnyProblem, Problem};
use crate::experiment::ResolvedRun;
use crate::output::{MethodParts, RunRecord};
use crate::reference::UlFem;

/// Runs `run`, whose method is a reference solver (its resolution has checked that it solves the
/// run's benchmark), on its `problem`.
pub(super) fn solve(
    run: &ResolvedRun,
    problem: AnyProblem,
    file: Option<&hdf5::File>,
) -> RunRecord {
    match problem {
        AnyProblem::D1(problem) => ulfem(run, problem.as_ref(), file),
        AnyProblem::D2(_) => base_record(run, format!("{} is 1D only", run.spec.method)),
    }
}

fn ulfem(run: &ResolvedRun, problem: &dyn Problem<1>, file: Option<&hdf5::File>) -> RunRecord {
    let dt = problem.dt();
    let planned = problem.steps();
    let every = run.spec.output_every;
    let mut fem = UlFem::new(problem);
    let mut recorder = Recorder::new();
    if let Some(file) = file {
        recorder.stream_to(file, fem.elements(), planned, every);
    }
    let mut velocity = vec![SVector::zeros(); fem.elements()];
    let mut outcome = Ok(());
    let mut steps = planned;
    for s in 0..=planned {
        fem.accelerate();
        if s == 0 || s == planned || (every > 0 && s % every == 0) {
            let half = if s == 0 { 0.0 } else { 0.5 * dt };
            let points = fem.points(half, &mut velocity);
            let t = s as f64 * dt;
            // Its nodes move with the material: no grid velocity to compare.
            let grid = GridSample {
                mass: fem.nodal_mass(),
                velocity: &[],
                time: t,
            };
            recorder.sample(s, t, points, &velocity, grid, problem);
        }
        if s == planned {
            break;
        }
        fem.kick(if s == 0 { 0.5 * dt } else { dt });
        if let Err(reason) = fem.drift(dt) {
            outcome = Err((s + 1, reason));
            steps = s;
            break;
        }
    }
    let h = problem.domain().upper[0] - problem.domain().lower[0];
    let mut record = stepped_record(
        run,
        Stepped {
            parts: MethodParts {
                shape: "linear finite element".into(),
                transfer: "none".into(),
                integrator: "central difference".into(),
            },
            h: h / fem.elements() as f64,
            dt,
            planned,
            steps,
            outcome,
            particles: fem.into_points(),
            recorder,
            diagnostics: Default::default(),
        },
    );
    // One point per element, whatever `ppc` says.
    record.ppc = 1;
    record
}
