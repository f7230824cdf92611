//! Runs an expanded experiment: every run in parallel across a rayon pool, each written
//! to its own file. Numbers do not depend on the pool size: each run is sequential.

use std::fs;
use std::io::{self, IsTerminal};
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::benchmarks::AnyProblem;
use crate::experiment::{Experiment, RunSpec};
use crate::output::{describe_if_missing, run_path, write_run, RunStatus};
use crate::params::get_usize;
use crate::solver::simulate;

/// Name of the copy of the experiment file kept beside the runs.
pub const EXPERIMENT_COPY: &str = "experiment.yaml";

pub struct RunOptions {
    /// Parent directory; the experiment writes into `<out>/<name>/`.
    pub out: PathBuf,
    /// Worker threads (0 = one per core).
    pub jobs: usize,
    /// Rerun runs whose file already exists.
    pub force: bool,
}

#[derive(Debug, Default)]
pub struct MatrixOutcome {
    pub written: usize,
    pub skipped: usize,
    /// `run_id: message` of each run that did not finish normally.
    pub diverged: Vec<String>,
    pub failed: Vec<String>,
}

/// The directory an experiment's results go to.
pub fn results_dir(out: &Path, experiment: &Experiment) -> PathBuf {
    out.join(&experiment.name)
}

pub fn run_experiment(experiment: &Experiment, options: &RunOptions) -> io::Result<MatrixOutcome> {
    let dir = results_dir(&options.out, experiment);
    fs::create_dir_all(dir.join("runs"))?;
    write_experiment_copy(&dir, &experiment.source_text)?;

    let (todo, done): (Vec<&RunSpec>, Vec<&RunSpec>) = experiment
        .runs
        .iter()
        .partition(|run| options.force || !run_path(&dir, &run.run_id).exists());
    // A skipped run still gets the XDMF description it lacks.
    for run in &done {
        describe_if_missing(&run_path(&dir, &run.run_id))?;
    }
    let mut todo = todo;
    // Longest first, so the pool does not end waiting on one large run.
    todo.sort_by_cached_key(|run| std::cmp::Reverse(estimated_cost(run)));

    let progress = progress_bar(&experiment.name, todo.len());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs)
        .build()
        .map_err(io::Error::other)?;
    let results: Vec<io::Result<(String, RunStatus, String)>> = pool.install(|| {
        todo.par_iter()
            .map(|run| {
                let record = simulate(run);
                write_run(&dir, &record)?;
                progress.inc(1);
                Ok((run.run_id.clone(), record.status, record.message))
            })
            .collect()
    });
    progress.finish_and_clear();

    let mut outcome = MatrixOutcome {
        skipped: done.len(),
        ..Default::default()
    };
    for result in results {
        let (run_id, status, message) = result?;
        outcome.written += 1;
        match status {
            RunStatus::Ok => {}
            RunStatus::Diverged => outcome.diverged.push(format!("{run_id}: {message}")),
            RunStatus::Failed => outcome.failed.push(format!("{run_id}: {message}")),
        }
    }
    outcome.diverged.sort();
    outcome.failed.sort();
    Ok(outcome)
}

/// A run's cost in particle-steps: its particles (`cells * ppc` per axis) times the time
/// steps its problem takes to the final time. A reconstruction benchmark takes no steps and
/// costs its points. The runner starts the costliest runs first and `shard` balances shards
/// by this, across experiments, so it is computed from the validated parameters alone and is
/// the same on every machine.
pub fn estimated_cost(run: &RunSpec) -> u64 {
    let dim = crate::benchmarks::info(&run.benchmark).map_or(1, |b| b.dim) as u32;
    let cells = get_usize(&run.params, "cells").unwrap_or(1) as u64;
    let ppc = get_usize(&run.params, "ppc").unwrap_or(1) as u64;
    let particles = cells.saturating_mul(ppc).saturating_pow(dim);
    // Building a problem only reads its parameters (dt, step count); it has no particles yet.
    let steps = match crate::benchmarks::build(&run.benchmark, &run.params) {
        Ok(AnyProblem::D1(problem)) => problem.steps(),
        Ok(AnyProblem::D2(problem)) => problem.steps(),
        Err(_) => 1,
    };
    particles.saturating_mul(steps.max(1) as u64)
}

/// Shards of one study, on several hosts, all write the same copy: an identical copy is left
/// alone, and a new one is written under a temporary name unique to this host, process and
/// moment (`write_atomically` names it by process id only, which processes on different hosts
/// can share) and renamed into place, so a reader never sees a partial copy.
pub fn write_experiment_copy(dir: &Path, text: &str) -> io::Result<()> {
    let path = dir.join(EXPERIMENT_COPY);
    if fs::read_to_string(&path).is_ok_and(|old| old == text) {
        return Ok(());
    }
    let host = fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_default();
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    let tmp = dir.join(format!(
        ".{EXPERIMENT_COPY}.tmp-{}-{}-{nanos}",
        host.trim(),
        std::process::id()
    ));
    let written = fs::write(&tmp, text).and_then(|()| fs::rename(&tmp, &path));
    if written.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    written
}

/// A bar on a terminal; nothing when stderr is piped or redirected.
fn progress_bar(name: &str, len: usize) -> ProgressBar {
    if !io::stderr().is_terminal() {
        return ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::hidden());
    }
    let bar = ProgressBar::new(len as u64);
    let style = ProgressStyle::with_template(
        "{prefix} [{bar:40}] {pos}/{len} runs {elapsed_precise} eta {eta}",
    )
    .unwrap_or_else(|_| ProgressStyle::default_bar())
    .progress_chars("=> ");
    bar.set_style(style);
    bar.set_prefix(name.to_string());
    bar
}
