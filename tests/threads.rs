//! A run's results do not depend on its thread count: the same runs with 1 and 3 threads of
//! their own give bit for bit the same record, and the same as outside any pool. The 2D runs
//! have 4096 particles, four chunks of the per-particle loops, and their grids are cut into
//! three blocks of nodes; they cover the leapfrog (`mpm`), MUSL and the predictor-corrector,
//! the dual-domain gradient's node passes (`ddmpm` with MUSL and the leapfrog), and a run
//! that diverges.

use std::path::Path;

use mpmlab::experiment;
use mpmlab::output::{RunRecord, RunStatus};
use mpmlab::parallel::with_threads;
use mpmlab::solver::simulate;

const MATRIX: &str = "\
name: threads
benchmark: mms2d_gong
params: {ppc: 4, cells: 16, G: 1.0e-2, courant_limit: 10.0}
matrix:
  - {method: [mpm, mpm_musl], cfl: [0.2], t_end: [0.004]}
  - {method: [mpm], integrator: [predictor_corrector], cfl: [0.2], t_end: [0.004]}
  - {method: [mpm], cfl: [3.0], t_end: [0.5]}
  - {method: [ddmpm], integrator: [musl, leapfrog], cfl: [0.2], t_end: [0.004]}
output: {every: 10}
";

/// The record with its wall and step times cleared, as text: `Debug` prints every float so that it
/// reads back to the same bits, so equal texts are bitwise-equal records.
fn record_text(mut record: RunRecord) -> String {
    record.wall_seconds = 0.0;
    record.step_seconds = 0.0;
    format!("{record:?}")
}

#[test]
fn results_are_bitwise_the_same_for_any_thread_count() {
    let exp = experiment::parse(MATRIX, Path::new("threads.yaml")).unwrap();
    let mut diverged = 0;
    for spec in &exp.runs {
        let sequential = simulate(spec);
        diverged += usize::from(sequential.status == RunStatus::Diverged);
        assert_ne!(
            sequential.status,
            RunStatus::Failed,
            "{}",
            sequential.message
        );
        assert!(sequential.history.x.len() > 4096, "{}", spec.spec.run_id);
        let expected = record_text(sequential);
        for threads in [1, 3] {
            let record = with_threads(threads, || simulate(spec)).unwrap();
            assert!(
                record_text(record) == expected,
                "{} with {threads} threads differs from the sequential run",
                spec.spec.run_id
            );
        }
    }
    assert_eq!(diverged, 1, "the run at cfl 3 is to diverge");
}
