//! Runs an expanded experiment: every run in parallel across a rayon pool, each written
//! to its own file, each run's loops over `threads` threads of its own. Numbers depend on
//! neither count: the in-run loops give the sequential results bit for bit (`parallel`). Processes
//! that run one experiment into one results directory at the same time share its runs
//! (`runner/locks.rs`).

mod locks;
mod memory;

use std::fs;
use std::io::{self, IsTerminal};
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::experiment::Experiment;
use crate::experiment::ResolvedRun;
use crate::output::{
    compute_run, describe_if_missing, read_message, remove_dead_temps, run_path, write_atomically,
    write_run, RunRecord, RunStatus,
};
use crate::parallel::with_threads;
use crate::solver::{base_record, Job};

pub use memory::{parse_size, MemoryBudget, REFUSED};

/// Name of the copy of the experiment file kept beside the runs.
pub const EXPERIMENT_COPY: &str = "experiment.yaml";

pub struct RunOptions {
    /// Parent directory; the experiment writes into `<out>/<name>/`.
    pub out: PathBuf,
    /// Runs at a time (0 = one per core, or per `threads` cores).
    pub jobs: usize,
    /// Threads inside each run (1 = sequential), an execution setting like `jobs`: it is not
    /// a parameter, so it changes neither run ids nor results.
    pub threads: usize,
    /// Rerun runs whose file already exists.
    pub force: bool,
    /// Bytes the runs in progress may use together (default: the memory available).
    pub memory: Option<u64>,
}

#[derive(Debug, Default)]
pub struct MatrixOutcome {
    pub written: usize,
    pub skipped: usize,
    /// Runs another process computed into the same directory while this one ran.
    pub elsewhere: usize,
    /// `run_id: message` of each run that did not finish normally.
    pub diverged: Vec<String>,
    pub failed: Vec<String>,
    /// `run_id: error` of each run of which no file could be written, not even of its failure.
    pub unwritten: Vec<String>,
}

/// The directory an experiment's results go to.
pub fn results_dir(out: &Path, experiment: &Experiment) -> PathBuf {
    out.join(&experiment.name)
}

pub fn run_experiment(experiment: &Experiment, options: &RunOptions) -> io::Result<MatrixOutcome> {
    let dir = results_dir(&options.out, experiment);
    fs::create_dir_all(dir.join("runs"))?;
    write_experiment_copy(&dir, experiment)?;
    remove_dead_temps(&dir)?;
    locks::remove_leftovers(&dir)?;
    let mut outcome = MatrixOutcome::default();
    let mut runs: Vec<&ResolvedRun> = experiment.runs.iter().collect();
    let budget = MemoryBudget::new(options.memory);
    // Runs another process held but ended without writing come back for another pass.
    while !runs.is_empty() {
        runs = run_pass(
            &dir,
            &experiment.name,
            &runs,
            options,
            &budget,
            &mut outcome,
        )?;
    }
    outcome.diverged.sort();
    outcome.failed.sort();
    outcome.unwritten.sort();
    Ok(outcome)
}

/// Computes the runs of `runs` that have no file (every one with `force`), or whose file says
/// they were refused for memory, and whose lock this process takes, each once `budget` has
/// room for it, then waits for those another process holds; returns the runs of these that
/// their holder did not write.
fn run_pass<'a>(
    dir: &Path,
    name: &str,
    runs: &[&'a ResolvedRun],
    options: &RunOptions,
    budget: &MemoryBudget,
    outcome: &mut MatrixOutcome,
) -> io::Result<Vec<&'a ResolvedRun>> {
    let (todo, done): (Vec<&ResolvedRun>, Vec<&ResolvedRun>) = runs
        .iter()
        .partition(|run| needs_run(dir, &run.spec.run_id, options.force));
    // A skipped run still gets the XDMF description it lacks.
    for run in &done {
        describe_if_missing(&run_path(dir, &run.spec.run_id))?;
    }
    let mut todo = todo;
    // Longest first, so the pool does not end waiting on one large run.
    todo.sort_by_cached_key(|run| std::cmp::Reverse(estimated_cost(run)));

    let progress = progress_bar(name, todo.len());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(parallel_runs(options))
        .build()
        .map_err(io::Error::other)?;
    let claims = locks::Claims::new(dir, options.force);
    let results: Vec<(&ResolvedRun, io::Result<(RunStatus, String)>)> = pool.install(|| {
        todo.par_iter()
            .filter(|run| claims.take(run))
            .map(|&run| {
                let job = Job::new(run);
                let bytes = job.estimated_bytes();
                let result = match budget.refusal(bytes) {
                    Some(message) => record_failure(dir, run, message),
                    None => {
                        let _hold = budget.hold(bytes);
                        let compute = |file: &hdf5::File| job.compute(Some(file));
                        with_threads(options.threads, || execute(dir, run, compute)).unwrap_or_else(
                            |e| {
                                let message = format!("its threads could not be started: {e}");
                                record_failure(dir, run, message)
                            },
                        )
                    }
                };
                if result.is_ok() {
                    claims.release(&run.spec.run_id);
                }
                progress.inc(1);
                (run, result)
            })
            .collect()
    });
    progress.finish_and_clear();

    outcome.skipped += done.len();
    for (run, result) in results {
        let run_id = &run.spec.run_id;
        match result {
            Ok((status, message)) => {
                outcome.written += 1;
                match status {
                    RunStatus::Ok => {}
                    RunStatus::Diverged => outcome.diverged.push(format!("{run_id}: {message}")),
                    RunStatus::Failed => outcome.failed.push(format!("{run_id}: {message}")),
                }
            }
            Err(e) => outcome.unwritten.push(format!("{run_id}: {e}")),
        }
    }
    let waited = claims.wait_for_others(name)?;
    outcome.elsewhere += waited.elsewhere;
    Ok(waited.orphans)
}

/// Runs at a time: `jobs`, or by default as many as fill the cores with `threads` each
/// (rayon's default of one per core when runs are sequential).
fn parallel_runs(options: &RunOptions) -> usize {
    match (options.jobs, options.threads) {
        (0, 0 | 1) => 0,
        (0, threads) => {
            std::thread::available_parallelism().map_or(1, |cores| (cores.get() / threads).max(1))
        }
        (jobs, _) => jobs,
    }
}

/// Whether the run is to be computed: it has no file, or its file records that it was refused
/// for memory (`REFUSED`), or `force` says to compute it again.
fn needs_run(dir: &Path, run_id: &str, force: bool) -> bool {
    let path = run_path(dir, run_id);
    force || !path.exists() || read_message(&path).is_some_and(|m| m.starts_with(REFUSED))
}

/// Computes one run into its file and returns its status and message. A panic is caught and
/// recorded as the run's failure, as is an error writing its file (in a file of the failed
/// run, if that can be written), so neither stops the other runs; the error is returned when
/// not even that file could be written.
fn execute(
    dir: &Path,
    run: &ResolvedRun,
    compute: impl FnOnce(&hdf5::File) -> RunRecord,
) -> io::Result<(RunStatus, String)> {
    let computed = panic::catch_unwind(AssertUnwindSafe(|| {
        compute_run(dir, &run.spec.run_id, compute)
    }));
    let message = match computed {
        Ok(Ok(record)) => return Ok((record.status, record.message)),
        Ok(Err(e)) => format!("its file could not be written: {e}"),
        Err(payload) => format!("stopped by an internal error: {}", panic_text(&*payload)),
    };
    record_failure(dir, run, message)
}

/// Writes the file of a run that failed with `message` before or while it ran.
fn record_failure(
    dir: &Path,
    run: &ResolvedRun,
    message: String,
) -> io::Result<(RunStatus, String)> {
    match write_run(dir, &base_record(run, message.clone())) {
        Ok(_) => Ok((RunStatus::Failed, message)),
        Err(e) => Err(io::Error::other(format!(
            "{message}; nor could the failure be recorded: {e}"
        ))),
    }
}

/// What a panic said.
fn panic_text(payload: &(dyn std::any::Any + Send)) -> &str {
    payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("a panic without a message")
}

/// A run's cost in particle-steps: its particles (`cells * ppc` per axis) times the time
/// steps to the final time. A reconstruction benchmark takes no steps and costs its points.
/// The runner starts the costliest runs first and `shard` balances shards by this, across
/// experiments, so it is computed from the validated parameters alone and is the same on
/// every machine.
pub fn estimated_cost(run: &ResolvedRun) -> u64 {
    let (cells, ppc) = (run.cells.max(1) as u64, run.ppc.max(1) as u64);
    let particles = cells.saturating_mul(ppc).saturating_pow(run.dim() as u32);
    particles.saturating_mul(run.steps.unwrap_or(1).max(1) as u64)
}

/// Experiments run or submitted together must differ in `name`, since each writes to
/// `OUT/<name>/`.
pub fn check_distinct_names(experiments: &[Experiment]) -> Result<(), String> {
    for (i, a) in experiments.iter().enumerate() {
        if let Some(b) = experiments[..i].iter().find(|b| b.name == a.name) {
            return Err(format!(
                "{} and {} both name the experiment '{}' (results go to OUT/<name>/)",
                b.source_path.display(),
                a.source_path.display(),
                a.name
            ));
        }
    }
    Ok(())
}

/// Where a results directory records the experiment file its copy was last written from (its
/// canonical path). It lives in `runs/`, which is not committed and which `make reproduce`
/// does not compare, since the path is this machine's.
const COPY_SOURCE: &str = ".experiment-source";

/// Whether `experiment` may write its copy into `dir`. The same text may come from anywhere
/// (the shards of a study, a task reading the copy itself), and new text from the file the copy
/// was last written from (an edited experiment file, rerun); new text from another file of the
/// same `name` is refused, naming both, as it would orphan the runs of the first. A directory
/// without a record (written before records were kept) takes any file.
pub fn check_copy(dir: &Path, experiment: &Experiment) -> Result<(), String> {
    let copy = dir.join(EXPERIMENT_COPY);
    let Ok(text) = fs::read_to_string(&copy) else {
        return Ok(());
    };
    let Ok(recorded) = fs::read_to_string(dir.join("runs").join(COPY_SOURCE)) else {
        return Ok(());
    };
    let recorded = PathBuf::from(recorded.trim_end());
    let source = canonical(&experiment.source_path);
    if text == experiment.source_text || source == recorded || source == canonical(&copy) {
        return Ok(());
    }
    Err(format!(
        "{}: the experiment '{}' already in {} comes from {}, and its text differs; one --out \
         holds one experiment of a name, so give one of them another `name` or use another \
         --out (if {} was renamed to {}, remove {})",
        experiment.source_path.display(),
        experiment.name,
        copy.display(),
        recorded.display(),
        recorded.display(),
        source.display(),
        dir.join("runs").join(COPY_SOURCE).display()
    ))
}

/// The absolute path of a file with symbolic links resolved, or as absolute as it gets.
fn canonical(path: &Path) -> PathBuf {
    fs::canonicalize(path)
        .or_else(|_| std::path::absolute(path))
        .unwrap_or_else(|_| path.to_path_buf())
}

/// Writes the copy of the experiment file beside its runs (`check_copy` first), and records
/// the file it came from unless that is the copy itself (an identical copy keeps the record it
/// has). Shards of one study, on several
/// hosts, all write the same copy: an identical copy is left alone, and a new one is written
/// under a temporary name unique to host and process and renamed into place, so a reader never
/// sees a partial copy.
pub fn write_experiment_copy(dir: &Path, experiment: &Experiment) -> io::Result<()> {
    let path = dir.join(EXPERIMENT_COPY);
    let record = dir.join("runs").join(COPY_SOURCE);
    let text = &experiment.source_text;
    if !fs::read_to_string(&path).is_ok_and(|old| old == *text) {
        check_copy(dir, experiment).map_err(io::Error::other)?;
        write_atomically(&path, |tmp| fs::write(tmp, text))?;
    } else if record.exists() {
        return Ok(());
    }
    let source = canonical(&experiment.source_path);
    if source == canonical(&path) {
        return Ok(());
    }
    let line = format!("{}\n", source.display());
    write_atomically(&record, |tmp| fs::write(tmp, &line))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::{open_run_file, read_summary};

    /// Two runs of a small bar.
    fn runs() -> Vec<ResolvedRun> {
        let yaml = "name: t\nbenchmark: vibrating_bar\nparams: {method: mpm}\n\
                    matrix:\n  cells: [4, 5]\n";
        crate::experiment::parse(yaml, Path::new("t.yaml"))
            .unwrap()
            .runs
    }

    fn status(dir: &Path, run: &ResolvedRun) -> (RunStatus, String) {
        let file = open_run_file(&run_path(dir, &run.spec.run_id)).unwrap();
        let summary = read_summary(&file).unwrap();
        (summary.status, summary.message)
    }

    /// A run that panics half way through its file is recorded as failed, with the panic's
    /// words, in a whole file of its own; the next run is computed as usual.
    #[test]
    fn a_panicking_run_is_recorded_as_failed_and_the_next_goes_on() {
        let dir = tempfile::tempdir().unwrap();
        let runs = runs();
        let panicking = |file: &hdf5::File| -> RunRecord {
            file.create_group("history").unwrap();
            panic!("boom")
        };
        let (status_of_first, message) = execute(dir.path(), &runs[0], panicking).unwrap();
        assert_eq!(status_of_first, RunStatus::Failed);
        assert_eq!(message, "stopped by an internal error: boom");
        assert_eq!(status(dir.path(), &runs[0]), (RunStatus::Failed, message));
        let compute = |file: &hdf5::File| Job::new(&runs[1]).compute(Some(file));
        let (second, _) = execute(dir.path(), &runs[1], compute).unwrap();
        assert_eq!(second, RunStatus::Ok);
        assert_eq!(status(dir.path(), &runs[1]).0, RunStatus::Ok);
        let leftovers: Vec<_> = fs::read_dir(dir.path().join("runs"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|name| name.to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }
}
