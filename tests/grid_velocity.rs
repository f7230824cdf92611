//! The grid-velocity error of a run compares the velocity at DOF x_a with the exact velocity
//! of the material point at x_a at the sampled step's time (the grid moves with the material
//! during the step), at the time the velocity belongs to. Either time taken wrongly adds an
//! O(dt) error, far more than the scheme's O(h^2) one.

use std::path::Path;

use mpmlab::benchmarks::{AnyProblem, Problem};
use mpmlab::experiment;
use mpmlab::output::{RunRecord, RunStatus};
use mpmlab::run_spec::RunSpec;
use mpmlab::solver::simulate;

/// Quarter of a period (t = T/4 = 5 ms), small deformation, 32 cells; the leapfrog (`mpm`,
/// `impm`, `cpdi2`), MUSL read as stepped and as centred, and the predictor-corrector (`lme`).
const MATRIX: &str = "\
name: grid_velocity_time
benchmark: mms1d_gong
params: {E: 1.0e7, nu: 0.3, rho0: 1000.0, t_end: 0.005, cfl: 0.4, G: 1.0e-4, ppc: 2, cells: 32}
matrix:
  - {method: [mpm, impm, cpdi2, mpm_musl]}
  - {method: [mpm_musl], sampled_velocity: [centred]}
  - {method: [lme], gamma: [1.5]}
";

/// sqrt(sum_a w_a |v_a - V(X(x_a, t_x), t_v)|^2) of the last sampled grid velocity against
/// the exact velocity at time `t_v` of the material points at the DOFs at time `t_x`.
fn error_at(record: &RunRecord, problem: &dyn Problem<1>, t_x: f64, t_v: f64) -> f64 {
    let grid = &record.grid;
    let n = grid.weight.len();
    let last = &grid.v[grid.v.len() - n..];
    let sum: f64 = (0..n)
        .map(|a| {
            let x = nalgebra::SVector::<f64, 1>::repeat(grid.x[a]);
            let x0 = problem.material_point(&x, t_x).unwrap();
            let e = last[a] - problem.exact(&x0, t_v).unwrap().velocity[0];
            grid.weight[a] * e * e
        })
        .sum();
    sum.sqrt()
}

fn label(spec: &RunSpec) -> String {
    match spec.params.get("sampled_velocity") {
        Some(v) => format!("{} ({})", spec.method, v.as_str().unwrap_or("")),
        None => spec.method.clone(),
    }
}

/// At a quarter period the exact velocity changes fastest (it passes through zero), so a
/// velocity read half a step off its time is off by dt/2 a.
#[test]
fn the_grid_velocity_is_compared_at_the_time_it_belongs_to() {
    let exp = experiment::parse(MATRIX, Path::new("grid_velocity_time.yaml")).unwrap();
    assert_eq!(exp.runs.len(), 6);
    for run in &exp.runs {
        let spec = &run.spec;
        let name = label(spec);
        let record = simulate(run);
        assert_eq!(record.status, RunStatus::Ok, "{name}: {}", record.message);
        let AnyProblem::D1(problem) = run.benchmark.problem(&spec.params).unwrap() else {
            unreachable!("mms1d_gong is 1D")
        };
        let t = *record.history.time.last().unwrap();
        let t_grid = *record.grid.time.last().unwrap();
        let stored = *record.errors.grid_velocity.l2.last().unwrap();
        let lag = (t_grid - t) / record.dt;
        let stepped = spec.method == "mpm_musl" && !spec.params.contains_key("sampled_velocity");
        let expected_lag = if stepped { 1.0 } else { 0.5 };
        assert!((lag - expected_lag).abs() < 1e-9, "{name}: lag {lag} dt");
        let recomputed = error_at(&record, problem.as_ref(), t, t_grid);
        assert!(
            (recomputed - stored).abs() <= 1e-12 * stored,
            "{name}: stored {stored:e}, recomputed {recomputed:e}"
        );
        // The half-step velocities are off by dt/2 a against the exact velocity at t; the
        // stepped reading's v^{s+1} is itself half a step from the time it is read at.
        let at_sample_time = error_at(&record, problem.as_ref(), t, t);
        if stepped {
            assert!(
                stored > at_sample_time,
                "{name}: {stored:e}, {at_sample_time:e}"
            );
        } else {
            assert!(
                stored < 0.25 * at_sample_time,
                "{name}: {stored:e} at its time, {at_sample_time:e} at the sample time"
            );
        }
    }
}

/// At large deformation (G = 0.1, one period, 256 cells) the material has moved by up to
/// dt/2 |v| = 2.5e-4 (h/16) between the step's time and the velocity's: the velocity of the material point
/// at the DOF at the step's time converges at second order, the exact velocity at the DOF at the
/// velocity's time (the material point that has arrived there since) differs from it by
/// dt/2 |v dv/dx| = O(h), which at this mesh is twice IMPM's error.
#[test]
fn the_grid_velocity_is_that_of_the_material_at_the_dof_at_the_step() {
    let text = MATRIX
        .replace("t_end: 0.005", "t_end: 0.02")
        .replace("G: 1.0e-4", "G: 0.1")
        .replace("cells: 32", "cells: 256");
    let exp = experiment::parse(&text, Path::new("grid_velocity_time.yaml")).unwrap();
    let run = exp.runs.iter().find(|r| r.spec.method == "impm").unwrap();
    let spec = &run.spec;
    let record = simulate(run);
    assert_eq!(record.status, RunStatus::Ok, "{}", record.message);
    let AnyProblem::D1(problem) = run.benchmark.problem(&spec.params).unwrap() else {
        unreachable!("mms1d_gong is 1D")
    };
    let t = *record.history.time.last().unwrap();
    let t_grid = *record.grid.time.last().unwrap();
    let stored = *record.errors.grid_velocity.l2.last().unwrap();
    let recomputed = error_at(&record, problem.as_ref(), t, t_grid);
    assert!(
        (recomputed - stored).abs() <= 1e-12 * stored,
        "{stored:e}, {recomputed:e}"
    );
    let arrived = error_at(&record, problem.as_ref(), t_grid, t_grid);
    assert!(
        stored < 0.5 * arrived,
        "{stored:e} for the material at the DOFs at the step, {arrived:e} at the velocity's time"
    );
}
