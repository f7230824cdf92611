//! `mpmlab slurm`: a study as a Slurm job array, one array task per shard, each task
//! `mpmlab run --shard $SLURM_ARRAY_TASK_ID/N` into the same results directory. Slurm
//! schedules; mpmlab only writes the script, submits it with `sbatch` and, with `--wait`,
//! waits through `sbatch --wait`, which exits with the largest exit code of the array's tasks
//! (1 for a task ended by a signal) and needs no accounting database.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::fs;
use std::io::{self, BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};

use crate::experiment::Experiment;
use crate::runner::{check_distinct_names, results_dir, write_experiment_copy, EXPERIMENT_COPY};
use crate::shard::Plan;

/// What `mpmlab slurm` was asked for.
#[derive(Clone, Debug)]
pub struct Options {
    /// Parent directory of the results, as given (made absolute for the script).
    pub out: PathBuf,
    /// Number of shards; `None`: `DEFAULT_SHARDS`, or the number of runs if fewer.
    pub shards: Option<usize>,
    pub partition: Option<String>,
    pub time: Option<String>,
    pub cpus_per_task: usize,
    /// Threads inside each run (`run --threads`).
    pub threads: usize,
    pub force: bool,
    /// Wait for the array to end and check that every run has its file.
    pub wait: bool,
    /// Print the script, write and submit nothing.
    pub dry_run: bool,
    /// Options for sbatch's command line.
    pub sbatch_args: Vec<String>,
}

/// Shards (array tasks) when `--shards` is not given.
pub const DEFAULT_SHARDS: usize = 8;

/// `mpmlab slurm`: plans the shards of `experiments`, writes the experiment copies and the
/// array script, submits it and, with `wait`, checks the outcome. The job id goes to stdout,
/// everything else to stderr.
pub fn submit_study(experiments: &[Experiment], options: Options) -> Result<(), String> {
    check_distinct_names(experiments)?;
    let runs: usize = experiments.iter().map(|e| e.runs.len()).sum();
    let shards = match options.shards {
        Some(0) => return Err("--shards must be at least 1".into()),
        Some(n) => n,
        None => DEFAULT_SHARDS.min(runs).max(1),
    };
    if options.threads > options.cpus_per_task {
        return Err(format!(
            "--threads {} exceeds --cpus-per-task {}: a task's runs would have fewer cores than \
             threads; give --cpus-per-task at least {}",
            options.threads, options.cpus_per_task, options.threads
        ));
    }
    let plan = Plan::new(experiments, shards);
    let out =
        std::path::absolute(&options.out).map_err(|e| format!("{}: {e}", options.out.display()))?;
    let exe = std::env::current_exe()
        .and_then(|p| p.canonicalize())
        .map_err(|e| format!("cannot locate the mpmlab binary: {e}"))?;
    let mut notes = vec![format!(
        "{runs} runs of {} experiment(s); shards by estimated cost (particle-steps):",
        experiments.len()
    )];
    notes.extend(plan.describe().into_iter().map(|line| format!("  {line}")));
    let job = ArrayJob {
        exe,
        // The tasks read the copies written at submission, so editing an experiment file
        // while the array waits in the queue does not change what its tasks run.
        files: experiments
            .iter()
            .map(|e| results_dir(&out, e).join(EXPERIMENT_COPY))
            .collect(),
        out,
        shards,
        job_name: match experiments {
            [one] => format!("mpmlab-{}", one.name),
            many => format!("mpmlab-{}-experiments", many.len()),
        },
        partition: options.partition,
        time: options.time,
        cpus_per_task: options.cpus_per_task,
        threads: options.threads,
        force: options.force,
        notes,
    };
    let script = job.script();
    let args = sbatch_args(&job.script_path(), &options.sbatch_args, options.wait);
    if options.dry_run {
        print!("{script}");
        let command: Vec<String> = args.iter().map(|a| shell_quote(a)).collect();
        eprintln!(
            "dry run: submitting would write {} and the experiment copies it reads, then run: \
             sbatch {}",
            job.script_path().display(),
            command.join(" ")
        );
        return Ok(());
    }

    let sbatch = find_sbatch()?;
    for experiment in experiments {
        let dir = results_dir(&job.out, experiment);
        fs::create_dir_all(&dir)
            .and_then(|()| write_experiment_copy(&dir, experiment))
            .map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    fs::create_dir_all(job.slurm_dir())
        .and_then(|()| fs::write(job.script_path(), &script))
        .map_err(|e| format!("{}: {e}", job.script_path().display()))?;
    eprintln!(
        "{shards} shards of {runs} runs, longest / mean shard by estimated cost {:.3}; script {}",
        plan.imbalance(),
        job.script_path().display()
    );
    let submitted = submit(&sbatch, &args, options.wait, |job_id| {
        println!("{job_id}");
        eprintln!(
            "submitted array job {job_id}; task logs: {}",
            job.log_path(job_id, "*").display()
        );
    })?;
    match submitted.status {
        Some(status) => check_outcome(experiments, &plan, &job, &submitted.job_id, status),
        None => Ok(()),
    }
}

/// After `sbatch --wait`: the failed tasks (from `scontrol`, when it still knows them) and
/// the runs without a file, by shard; an error when there is either.
fn check_outcome(
    experiments: &[Experiment],
    plan: &Plan,
    job: &ArrayJob,
    job_id: &str,
    status: ExitStatus,
) -> Result<(), String> {
    let shards = plan.count();
    let missing = plan.missing(experiments, &job.out);
    for (shard, name, run_id) in &missing {
        eprintln!("missing run: {name}/{run_id} (shard {shard}/{shards})");
    }
    // The shards to look at: those with runs missing, and the tasks that did not complete.
    let mut bad: BTreeSet<usize> = missing.iter().map(|m| m.0).collect();
    let states = (!status.success() || !bad.is_empty())
        .then(|| task_states(job_id))
        .flatten();
    for task in states.iter().flatten() {
        if task.state != "COMPLETED" || task.exit_code != "0:0" {
            eprintln!(
                "shard {}/{shards}: {} (exit code {})",
                task.task, task.state, task.exit_code
            );
            bad.insert(task.task);
        }
    }
    for shard in bad {
        let log = job.log_path(job_id, &shard.to_string());
        if log.exists() {
            eprintln!("  log of shard {shard}/{shards}: {}", log.display());
        } else {
            eprintln!("  shard {shard}/{shards} left no log: its task did not start");
        }
    }
    let mut problems = Vec::new();
    if !status.success() {
        problems.push(format!("a task failed (sbatch --wait: {status})"));
        if states.is_none() {
            eprintln!("  task logs: {}", job.log_path(job_id, "*").display());
        }
    }
    let runs = plan.loads.iter().map(|l| l.runs).sum::<usize>();
    if !missing.is_empty() {
        problems.push(format!("{} of {runs} runs are missing", missing.len()));
    }
    if problems.is_empty() {
        eprintln!("array job {job_id} ended: all {runs} runs present");
        Ok(())
    } else {
        Err(format!("array job {job_id}: {}", problems.join("; ")))
    }
}

/// Everything the array script says.
#[derive(Clone, Debug)]
pub struct ArrayJob {
    /// Absolute path of the mpmlab binary the tasks run.
    pub exe: PathBuf,
    /// Absolute parent directory of the results (`run --out`).
    pub out: PathBuf,
    /// Absolute paths of the experiment files the tasks read.
    pub files: Vec<PathBuf>,
    pub shards: usize,
    pub job_name: String,
    pub partition: Option<String>,
    /// `sbatch --time` of each task, e.g. `02:00:00`.
    pub time: Option<String>,
    pub cpus_per_task: usize,
    /// Threads inside each run; a task runs its CPUs divided by this many runs at a time.
    pub threads: usize,
    /// Pass `--force` to `run`: rerun runs whose file exists.
    pub force: bool,
    /// Comment lines (the shard plan), written after the directives.
    pub notes: Vec<String>,
}

impl ArrayJob {
    /// Where the script is written and the tasks' logs go: `<out>/slurm/`.
    pub fn slurm_dir(&self) -> PathBuf {
        self.out.join("slurm")
    }

    pub fn script_path(&self) -> PathBuf {
        self.slurm_dir().join(format!("{}.sbatch", self.job_name))
    }

    /// The log of array task `task` (a number, or `*` for a pattern) of job `job_id`, as the
    /// script's `--output` names it.
    pub fn log_path(&self, job_id: &str, task: &str) -> PathBuf {
        self.slurm_dir()
            .join(format!("{}-{job_id}_{task}.out", self.job_name))
    }

    /// The sbatch array script: `#SBATCH` directives, the plan as comments, and one command.
    pub fn script(&self) -> String {
        let n = self.shards;
        let mut s = String::from("#!/bin/bash\n");
        let mut directive = |option: &str, value: &str| {
            // sbatch reads a directive's value up to the first blank unless it is quoted.
            let value = if value.contains(char::is_whitespace) {
                format!("\"{value}\"")
            } else {
                value.to_string()
            };
            let _ = writeln!(s, "#SBATCH --{option}={value}");
        };
        directive("job-name", &self.job_name);
        directive("array", &format!("1-{n}"));
        directive("cpus-per-task", &self.cpus_per_task.to_string());
        if let Some(partition) = &self.partition {
            directive("partition", partition);
        }
        if let Some(time) = &self.time {
            directive("time", time);
        }
        let log = self.slurm_dir().join("%x-%A_%a.out");
        directive("output", &log.to_string_lossy());
        s.push_str(&format!(
            "#\n# Written by `mpmlab slurm`. Array task K runs shard K of {n} of the runs of the\n\
             # files below (`mpmlab run --shard K/{n}`) into {}/<name>/runs/, beside the\n\
             # runs of the other shards; a task run again skips the runs already there.\n",
            self.out.display()
        ));
        for note in &self.notes {
            let _ = writeln!(s, "# {note}");
        }
        s.push_str("set -eu\n");
        let cpus = format!("${{SLURM_CPUS_PER_TASK:-{}}}", self.cpus_per_task);
        // sbatch options given after `--` may change the CPUs, so the task divides what it got.
        let jobs = match self.threads {
            1 => format!("--jobs \"{cpus}\""),
            t => format!("--jobs \"$(( {cpus} / {t} > 0 ? {cpus} / {t} : 1 ))\" --threads {t}"),
        };
        let _ = write!(
            s,
            "exec {} run --shard \"${{SLURM_ARRAY_TASK_ID}}/{n}\" --out {} {jobs}{}",
            shell_quote(&self.exe.to_string_lossy()),
            shell_quote(&self.out.to_string_lossy()),
            if self.force { " --force" } else { "" },
        );
        for file in &self.files {
            let _ = write!(s, " \\\n  {}", shell_quote(&file.to_string_lossy()));
        }
        s.push('\n');
        s
    }
}

/// `sbatch`'s arguments for submitting `script`: options given on the command line override
/// the script's `#SBATCH` directives, so `extra` can change any of them.
pub fn sbatch_args(script: &Path, extra: &[String], wait: bool) -> Vec<String> {
    let mut args = vec!["--parsable".to_string()];
    if wait {
        args.push("--wait".to_string());
    }
    args.extend(extra.iter().cloned());
    args.push(script.to_string_lossy().into_owned());
    args
}

const NO_SBATCH: &str = "sbatch not found on PATH: `mpmlab slurm` submits through Slurm's \
    sbatch, so run it where Slurm's client commands are installed (a login node), or add \
    --dry-run to only print the script";

/// Fails with a clear message when `sbatch` is not on PATH, before anything is written.
pub fn find_sbatch() -> Result<PathBuf, String> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|dir| dir.join("sbatch"))
        .find(|candidate| candidate.is_file())
        .ok_or_else(|| NO_SBATCH.to_string())
}

/// A submitted array: its job id, and with `wait` how `sbatch --wait` ended.
pub struct Submitted {
    pub job_id: String,
    pub status: Option<ExitStatus>,
}

/// Runs `sbatch` (the path `find_sbatch` found) with `args` (from `sbatch_args`), calls `on_submit` with the job id as soon
/// as sbatch prints it, and with `wait` returns when sbatch does, i.e. when the array ends.
pub fn submit(
    sbatch: &Path,
    args: &[String],
    wait: bool,
    on_submit: impl FnOnce(&str),
) -> Result<Submitted, String> {
    let mut child = Command::new(sbatch)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            io::ErrorKind::NotFound => NO_SBATCH.to_string(),
            _ => format!("cannot run sbatch: {e}"),
        })?;
    let mut line = String::new();
    if let Some(stdout) = child.stdout.take() {
        BufReader::new(stdout)
            .read_line(&mut line)
            .map_err(|e| format!("reading sbatch's output: {e}"))?;
    }
    // --parsable prints `jobid` or `jobid;cluster`.
    let job_id = line.trim().split(';').next().unwrap_or("").to_string();
    if job_id.is_empty() || !job_id.bytes().all(|b| b.is_ascii_digit()) {
        let status = child.wait().map_err(|e| format!("sbatch: {e}"))?;
        return Err(format!(
            "sbatch did not submit the array ({status}){}",
            if line.trim().is_empty() {
                String::new()
            } else {
                format!(": it printed '{}'", line.trim())
            }
        ));
    }
    on_submit(&job_id);
    let status = child.wait().map_err(|e| format!("sbatch: {e}"))?;
    if !wait && !status.success() {
        return Err(format!("sbatch {status} after submitting job {job_id}"));
    }
    Ok(Submitted {
        job_id,
        status: wait.then_some(status),
    })
}

/// One array task as `scontrol show job` lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TaskState {
    pub task: usize,
    /// COMPLETED, FAILED, CANCELLED, TIMEOUT, ...
    pub state: String,
    /// `code:signal`.
    pub exit_code: String,
}

/// The state of each task of array job `job_id`, from `scontrol -o show job`, while the
/// controller still holds the records (`MinJobAge` after the end; no accounting needed).
/// `None` when scontrol cannot tell.
pub fn task_states(job_id: &str) -> Option<Vec<TaskState>> {
    let output = Command::new("scontrol")
        .args(["-o", "show", "job", job_id])
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .ok()?;
    if !output.status.success() {
        return None;
    }
    Some(parse_task_states(&String::from_utf8_lossy(&output.stdout)))
}

/// Parses `scontrol -o show job` output: one line per job, `Key=value` words.
pub fn parse_task_states(text: &str) -> Vec<TaskState> {
    let mut tasks: Vec<TaskState> = text
        .lines()
        .filter_map(|line| {
            let field = |key: &str| {
                line.split_whitespace()
                    .find_map(|word| word.strip_prefix(key)?.strip_prefix('='))
            };
            Some(TaskState {
                task: field("ArrayTaskId")?.parse().ok()?,
                state: field("JobState")?.to_string(),
                exit_code: field("ExitCode").unwrap_or("?").to_string(),
            })
        })
        .collect();
    tasks.sort_by_key(|t| t.task);
    tasks
}

/// `s` as one word for bash: unchanged when it is made of safe characters, otherwise in
/// single quotes.
pub fn shell_quote(s: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "/._-+,:=@%".contains(c);
    if !s.is_empty() && s.chars().all(safe) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_task_states() {
        let text = "JobId=5 ArrayJobId=4 ArrayTaskId=2 JobName=x UserId=root(0) \
                    JobState=FAILED Reason=NonZeroExitCode Dependency=(null) ExitCode=1:0\n\
                    JobId=4 ArrayJobId=4 ArrayTaskId=3 JobState=COMPLETED ExitCode=0:0\n\
                    JobId=6 ArrayJobId=4 ArrayTaskId=1 JobState=COMPLETED ExitCode=0:0\n";
        let tasks = parse_task_states(text);
        assert_eq!(tasks.len(), 3);
        assert_eq!(tasks[0].task, 1);
        assert_eq!(
            tasks[1],
            TaskState {
                task: 2,
                state: "FAILED".into(),
                exit_code: "1:0".into()
            }
        );
    }

    #[test]
    fn quotes_for_bash() {
        assert_eq!(shell_quote("/a/b-c_1.yaml"), "/a/b-c_1.yaml");
        assert_eq!(shell_quote("/my dir/x"), "'/my dir/x'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
        assert_eq!(shell_quote(""), "''");
    }
}
