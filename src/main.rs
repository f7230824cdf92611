use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use serde_json::{json, Value};

use mpmlab::catalog::Parts;
use mpmlab::collect::{collect, Collected};
use mpmlab::experiment::Experiment;
use mpmlab::output::{remove_dead_temps, write_atomically};
use mpmlab::runner::{
    check_copy, check_distinct_names, parse_size, results_dir, run_experiment, RunOptions,
    EXPERIMENT_COPY,
};
use mpmlab::shard::{Plan, Shard};
use mpmlab::slurm;
use mpmlab::{
    benchmarks, experiment, integrate, methods, reconstruct, reconstruction_methods, reference,
    report, shape, shape_methods,
};

/// mpmlab: run Material Point Method experiment matrices and report their convergence.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the runs an experiment file expands to, one per line.
    Expand {
        file: PathBuf,
        /// One JSON object per line instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Run every configuration of one or more experiment files.
    Run {
        /// Experiment files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Parent directory of the results; each experiment writes to OUT/<name>/.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Parallel runs (default: one per core, or one per THREADS cores).
        #[arg(long, default_value_t = 0)]
        jobs: usize,
        /// Threads inside each run (default 1); the runs in progress use JOBS x THREADS in all;
        /// results are bit for bit the same for any count. Worth it for a few large runs of
        /// mpm (and other Shepard-transfer methods), which parallelise their particle loops.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        threads: u32,
        /// Rerun runs whose file already exists.
        #[arg(long)]
        force: bool,
        /// Memory the runs in progress may use together, e.g. 48G or 512M (default: the
        /// memory available when the matrix starts). A run estimated above it is recorded as
        /// failed; the others wait until it has room for them.
        #[arg(long, value_name = "SIZE", value_parser = parse_size)]
        memory: Option<u64>,
        /// Run only shard K of N (1 <= K <= N) of the runs of all the files together. Every
        /// shard computes the same split, so N machines can run one shard each into the same
        /// OUT.
        #[arg(long, value_name = "K/N")]
        shard: Option<Shard>,
    },
    /// Run the files' runs as a Slurm job array, one task per shard (`run --shard K/N`).
    ///
    /// Writes the array script to OUT/slurm/<job name>.sbatch and the experiment copies the
    /// tasks read to OUT/<name>/experiment.yaml, submits the script with sbatch and prints the
    /// job id. Options after `--` go to sbatch (e.g. -- --account=proj --qos=long) and
    /// override the script's directives.
    Slurm {
        /// Experiment files; their runs together are split into the shards.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Parent directory of the results, on a file system every node sees.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Number of shards, one array task each (default: 8, or the number of runs if fewer).
        #[arg(long)]
        shards: Option<usize>,
        /// sbatch --partition.
        #[arg(long)]
        partition: Option<String>,
        /// sbatch --time of each task, e.g. 02:00:00.
        #[arg(long, value_name = "HH:MM:SS")]
        time: Option<String>,
        /// sbatch --cpus-per-task; each task runs this many runs at a time, or this many divided
        /// by THREADS.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        cpus_per_task: u32,
        /// Threads inside each run of a task (`run --threads`), at most CPUS_PER_TASK.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        threads: u32,
        /// Rerun runs whose file already exists.
        #[arg(long)]
        force: bool,
        /// Wait until the array ends; exit non-zero if a task failed or a run is missing.
        #[arg(long, conflicts_with = "dry_run")]
        wait: bool,
        /// Print the script and each shard's runs and estimated cost; submit nothing.
        #[arg(long)]
        dry_run: bool,
        /// Further sbatch options, after `--`.
        #[arg(last = true, value_name = "SBATCH_OPTION")]
        sbatch_args: Vec<String>,
    },
    /// Write summary.csv, rates.csv, figures and report.md for a results directory.
    Report {
        dir: PathBuf,
        /// Evaluate the experiment's `expect` entries; exit non-zero if any fails.
        #[arg(long)]
        check: bool,
    },
    /// Write <dir>/README.md, the reproduction index: every paper claim of the results
    /// directories under <dir> beside ours, with verdicts and the figures of each paper item.
    Index { dir: PathBuf },
    /// List the method presets and what they are composed of, and the reconstruction methods.
    ListMethods {
        /// Print them as JSON: presets with their parts' names, the parts, the method
        /// parameters, the reference solvers, reconstruction methods and grid bases.
        #[arg(long)]
        json: bool,
    },
    /// List the benchmarks and their parameters.
    ListBenchmarks {
        /// Print them as JSON: each benchmark's name, kind, dimension and parameters.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    end_quietly_on_closed_pipe();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Expand { file, json } => expand(&file, json),
        Command::Run {
            files,
            out,
            jobs,
            threads,
            force,
            memory,
            shard,
        } => run(
            &files,
            RunOptions {
                out,
                jobs,
                threads: threads as usize,
                force,
                memory,
            },
            shard,
        ),
        Command::Slurm {
            files,
            out,
            shards,
            partition,
            time,
            cpus_per_task,
            threads,
            force,
            wait,
            dry_run,
            sbatch_args,
        } => load_all(&files).and_then(|experiments| {
            slurm::submit_study(
                &experiments,
                slurm::Options {
                    out,
                    shards,
                    partition,
                    time,
                    cpus_per_task: cpus_per_task as usize,
                    threads: threads as usize,
                    force,
                    wait,
                    dry_run,
                    sbatch_args,
                },
            )
        }),
        Command::Report { dir, check } => report_dir(&dir, check),
        Command::Index { dir } => index(&dir),
        Command::ListMethods { json } => list(json, methods_json, list_methods),
        Command::ListBenchmarks { json } => list(json, benchmarks_json, list_benchmarks),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// A reader that closes its end of the pipe (`mpmlab list-benchmarks | head -1`) ends the
/// process quietly, as it ends other Unix tools, instead of making `println!` panic on the
/// failed write: Rust's runtime ignores SIGPIPE, and this restores its default action.
fn end_quietly_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first in main, before any other thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn expand(file: &Path, json: bool) -> Result<(), String> {
    let experiment = experiment::load(file).map_err(|e| e.to_string())?;
    for run in &experiment.runs {
        if json {
            println!("{}", run.spec.to_json());
        } else {
            println!("{}", run.spec.describe());
        }
    }
    Ok(())
}

/// Reads and validates every file before running any, so a typo in the last file does not
/// surface after hours of work.
fn load_all(files: &[PathBuf]) -> Result<Vec<Experiment>, String> {
    files
        .iter()
        .map(|f| experiment::load(f).map_err(|e| e.to_string()))
        .collect()
}

fn run(files: &[PathBuf], options: RunOptions, shard: Option<Shard>) -> Result<(), String> {
    let mut experiments = load_all(files)?;
    check_distinct_names(&experiments)?;
    for experiment in &experiments {
        check_copy(&results_dir(&options.out, experiment), experiment)?;
    }
    if let Some(shard) = shard {
        let plan = Plan::new(&experiments, shard.count);
        let load = plan.loads[shard.index - 1];
        let total: usize = plan.loads.iter().map(|l| l.runs).sum();
        eprintln!(
            "shard {shard}: {} of {total} runs, estimated cost {:.3e} particle-steps",
            load.runs, load.cost as f64
        );
        experiments = experiments
            .iter()
            .map(|e| plan.select(e, shard.index))
            .collect();
    }
    // An experiment that cannot be written does not stop the others (a shard on a cluster
    // does as much as it can); the command fails at the end.
    let mut errors = Vec::new();
    for experiment in &experiments {
        let dir = results_dir(&options.out, experiment);
        let outcome = match run_experiment(experiment, &options) {
            Ok(outcome) => outcome,
            Err(e) => {
                eprintln!("error: {}: {e}", dir.display());
                errors.push(experiment.name.clone());
                continue;
            }
        };
        let elsewhere = match outcome.elsewhere {
            0 => String::new(),
            n => format!(", {n} computed by another process"),
        };
        eprintln!(
            "{}: {} runs written, {} already present{elsewhere}, {} diverged, {} failed -> {}",
            experiment.name,
            outcome.written,
            outcome.skipped,
            outcome.diverged.len(),
            outcome.failed.len(),
            dir.display()
        );
        for line in outcome.diverged.iter().chain(&outcome.failed) {
            eprintln!("  {line}");
        }
        if !outcome.unwritten.is_empty() {
            eprintln!(
                "{}: {} runs could not be written:",
                experiment.name,
                outcome.unwritten.len()
            );
            for line in &outcome.unwritten {
                eprintln!("  {line}");
            }
            errors.push(experiment.name.clone());
        }
    }
    match errors.as_slice() {
        [] => Ok(()),
        [one] => Err(format!("{one} could not be run completely")),
        many => Err(format!(
            "{} experiments could not be run completely: {}",
            many.len(),
            many.join(", ")
        )),
    }
}

fn report_dir(dir: &Path, check: bool) -> Result<(), String> {
    let collected = collect(dir)?;
    for run_id in &collected.missing {
        eprintln!("missing run: {run_id}");
    }
    if !collected.missing.is_empty() {
        eprintln!(
            "{} of {} runs missing (listed above); the report covers the other {}",
            collected.missing.len(),
            collected.experiment.runs.len(),
            collected.runs.len()
        );
    }
    for file in &collected.unreadable {
        eprintln!(
            "unreadable run file: {}: {}",
            dir.join(&file.file).display(),
            file.reason
        );
    }
    if !collected.unreadable.is_empty() {
        eprintln!(
            "{} run file(s) unreadable (listed above); the report leaves them out",
            collected.unreadable.len()
        );
    }
    let rates = report::fit_rates(&collected.experiment, &collected.runs);
    // The expectations are evaluated and written into report.md either way, so the report is
    // the same file with or without --check; --check only makes a failure the exit status.
    let failures = report::check(&collected.experiment, &rates, &collected.runs);
    report::write_report(
        dir,
        &collected.experiment,
        &collected.runs,
        &collected.unreadable,
        &rates,
        Some(&failures),
    )
    .map_err(|e| format!("{}: {e}", dir.display()))?;
    eprintln!("report written to {}", dir.join("report.md").display());
    if !check {
        return Ok(());
    }
    let mut problems = Vec::new();
    if !failures.is_empty() {
        for failure in &failures {
            eprintln!("check failed: {}", failure.message);
        }
        problems.push(format!("{} expectation(s) not met", failures.len()));
    }
    if !collected.unreadable.is_empty() {
        let files: Vec<String> = collected
            .unreadable
            .iter()
            .map(|f| dir.join(&f.file).display().to_string())
            .collect();
        problems.push(format!(
            "{} run file(s) unreadable: {}",
            files.len(),
            files.join(", ")
        ));
    }
    if !collected.missing.is_empty() {
        problems.push(format!(
            "{} run(s) of the matrix are missing",
            collected.missing.len()
        ));
    }
    if !problems.is_empty() {
        return Err(problems.join("; "));
    }
    eprintln!("all expectations met");
    Ok(())
}

/// The index over every results directory under `root` (those with an experiment copy). A
/// directory that cannot be read or reported is listed in the index with the reason, and
/// fails the command once the index of the others is written.
fn index(root: &Path) -> Result<(), String> {
    let read = std::fs::read_dir(root).map_err(|e| format!("{}: {e}", root.display()))?;
    let mut dirs: Vec<String> = read
        .filter_map(|entry| entry.ok())
        .filter(|entry| entry.path().join(EXPERIMENT_COPY).exists())
        .map(|entry| entry.file_name().to_string_lossy().into_owned())
        .collect();
    dirs.sort();
    let collected: Vec<(String, Result<Collected, String>)> = dirs
        .into_iter()
        .map(|dir| {
            let collected = collect(&root.join(&dir));
            (dir, collected)
        })
        .collect();
    let mut indexed = Vec::new();
    let mut unreadable = Vec::new();
    for (dir, collected) in &collected {
        let entry = collected.as_ref().map_err(Clone::clone).and_then(|c| {
            index_entry(dir, c).map_err(|e| format!("{}: {e}", root.join(dir).display()))
        });
        match entry {
            Ok(entry) => indexed.push(entry),
            Err(reason) => {
                eprintln!("error: {reason}");
                unreadable.push(report::index::Unreadable { dir, reason });
            }
        }
    }
    remove_dead_temps(root).map_err(|e| format!("{}: {e}", root.display()))?;
    let path = root.join("README.md");
    let md = report::index::index_md(&indexed, &unreadable);
    write_atomically(&path, |tmp| std::fs::write(tmp, &md))
        .map_err(|e| format!("{}: {e}", path.display()))?;
    eprintln!("index written to {}", path.display());
    match unreadable.len() {
        0 => Ok(()),
        n => Err(format!(
            "{n} results director{} left out of the index (listed above)",
            if n == 1 { "y" } else { "ies" }
        )),
    }
}

/// What the index shows of one results directory: its claims and the figures its report
/// draws.
fn index_entry<'a>(dir: &'a str, c: &'a Collected) -> Result<report::index::Indexed<'a>, String> {
    let rates = report::fit_rates(&c.experiment, &c.runs);
    let figures = report::figures::plan(&c.experiment, &c.runs)?;
    let maps = report::figures::plan_maps(&c.experiment, &c.runs, &figures)?;
    Ok(report::index::Indexed {
        dir,
        experiment: &c.experiment,
        claims: report::claims::evaluate(&c.experiment, &rates, &c.runs),
        figures,
        maps,
        unreadable_runs: c.unreadable.len(),
    })
}

/// A parameter's spec as JSON: its key, kind (with the choices of a `Choice`), default, unit
/// and documentation.
fn param_json(p: &benchmarks::ParamSpec) -> Value {
    let (kind, choices) = match p.kind {
        benchmarks::ParamKind::Real => ("real", None),
        benchmarks::ParamKind::PositiveReal => ("positive_real", None),
        benchmarks::ParamKind::PositiveInt => ("positive_int", None),
        benchmarks::ParamKind::Choice(names) => ("choice", Some(names)),
        benchmarks::ParamKind::RealList => ("real_list", None),
    };
    let default = match p.default {
        benchmarks::ParamDefault::Required => Value::Null,
        benchmarks::ParamDefault::Int(i) => json!(i),
        benchmarks::ParamDefault::Float(x) => json!(x),
        benchmarks::ParamDefault::Text(s) | benchmarks::ParamDefault::Implicit(s) => json!(s),
    };
    json!({
        "key": p.key,
        "kind": kind,
        "choices": choices,
        "required": p.default == benchmarks::ParamDefault::Required,
        "default": default,
        "unit": p.unit,
        "doc": p.doc,
    })
}

fn parts_json<T>(parts: &Parts<T>) -> Value {
    parts
        .entries
        .iter()
        .map(|e| json!({"name": e.name, "description": e.description}))
        .collect()
}

/// The shape parts, each with the degree of its DOF lattice: cells + `dof_degree` DOFs per
/// axis at the Greville abscissae of that degree (1: the grid nodes).
fn shapes_json() -> Value {
    let mut shapes = parts_json(&shape::SHAPES);
    for (json, entry) in shapes
        .as_array_mut()
        .into_iter()
        .flatten()
        .zip(shape::SHAPES.entries)
    {
        json["dof_degree"] = json!(entry.value.dofs().degree());
    }
    shapes
}

/// Everything `list_methods` prints, for tools.
fn methods_json() -> Value {
    let presets: Vec<Value> = methods::PRESETS
        .entries
        .iter()
        .map(|p| {
            let m = &p.method;
            json!({
                "name": p.name,
                "shape": m.shape.name(),
                "transfer": reconstruct::TRANSFERS.name_of(&m.transfer),
                "integrator": m.integrator.name(),
                "source": p.source,
                "description": p.description,
            })
        })
        .collect();
    let named = |name: &str, source: &str, description: &str| json!({"name": name, "source": source, "description": description});
    json!({
        "presets": presets,
        "parts": {
            "shape": shapes_json(),
            "transfer": parts_json(&reconstruct::TRANSFERS),
            "integrator": parts_json(&integrate::INTEGRATORS),
        },
        "method_params": methods::METHOD_PARAMS.iter().map(param_json).collect::<Vec<_>>(),
        "reference": reference::METHODS.entries
            .iter()
            .map(|m| {
                let mut v = named(m.name, m.source, m.description);
                v["benchmarks"] = json!(m.benchmarks);
                v
            })
            .collect::<Vec<_>>(),
        "reconstruction": reconstruction_methods::METHODS.entries
            .iter()
            .map(|m| named(m.name, m.source, m.description))
            .collect::<Vec<_>>(),
        "shape_functions": shape_methods::METHODS.entries
            .iter()
            .map(|m| named(m.name, m.source, m.description))
            .collect::<Vec<_>>(),
    })
}

/// Every benchmark with its kind, dimension and parameters, for tools.
fn benchmarks_json() -> Value {
    benchmarks::CATALOG
        .entries
        .iter()
        .map(|b| {
            json!({
                "name": b.name,
                "kind": b.kind.to_string(),
                "dim": b.dim(),
                "source": b.source,
                "description": b.description,
                "params": b.params.iter().map(param_json).collect::<Vec<_>>(),
            })
        })
        .collect()
}

/// A listing as JSON for tools, or as text.
fn list(json: bool, as_json: fn() -> Value, as_text: fn()) -> Result<(), String> {
    if json {
        let text = serde_json::to_string_pretty(&as_json()).map_err(|e| e.to_string())?;
        println!("{text}");
    } else {
        as_text();
    }
    Ok(())
}

fn print_parts<T>(parts: &Parts<T>) {
    println!("{}s:", parts.kind);
    for part in parts.entries {
        println!("  {:<20} {}", part.name, part.description);
    }
}

fn list_methods() {
    println!("Simulation methods (benchmarks of kind simulation):");
    for preset in methods::PRESETS.entries {
        println!(
            "{:<15} {}  [{}]",
            preset.name, preset.description, preset.source
        );
        println!("{:<15} {}", "", preset.method);
    }
    println!(
        "\nThe parts of a method (the shape, transfer and integrator parameters; a run that sets \
         all three needs no preset):"
    );
    print_parts(&shape::SHAPES);
    print_parts(&reconstruct::TRANSFERS);
    print_parts(&integrate::INTEGRATORS);
    println!("\nMethod parameters (in params or as matrix axes of any simulation):");
    for p in methods::METHOD_PARAMS {
        print_param(p);
    }
    println!("\nReference solvers (simulation benchmarks they name):");
    for m in reference::METHODS.entries {
        println!("{:<15} {}  [{}]", m.name, m.description, m.source);
        println!("{:<15} benchmarks: {}", "", m.benchmarks.join(", "));
    }
    println!(
        "\nReconstruction methods (reconstruction benchmarks; the weight of a local fit is a \
         parameter, tls_* serve recon_tls):"
    );
    for m in reconstruction_methods::METHODS.entries {
        println!("{:<15} {}  [{}]", m.name, m.description, m.source);
        println!("{:<15} degree={} fit={}", "", m.degree.value(), m.fit);
    }
    println!("\nGrid bases (shape_functions; gamma and tolerance are parameters of lme):");
    for m in shape_methods::METHODS.entries {
        println!("{:<15} {}  [{}]", m.name, m.description, m.source);
    }
}

fn list_benchmarks() {
    for b in benchmarks::CATALOG.entries {
        let kind = b.kind;
        // Runs that build no problem take the dimension of their parameters, up to `dim`.
        let dims = match b.build {
            benchmarks::Build::Points { dim } if dim > 1 => format!("1D or {dim}D"),
            _ => format!("{}D", b.dim()),
        };
        println!(
            "{} ({dims}, {kind}) - {} [{}]",
            b.name, b.description, b.source
        );
        for p in b.params {
            print_param(p);
        }
    }
}

/// One parameter: key, default, unit, meaning and the choices it takes.
fn print_param(p: &benchmarks::ParamSpec) {
    let default = match p.default {
        benchmarks::ParamDefault::Required => "required".to_string(),
        benchmarks::ParamDefault::Int(i) => format!("default {i}"),
        benchmarks::ParamDefault::Float(x) => format!("default {x:?}"),
        benchmarks::ParamDefault::Text(s) | benchmarks::ParamDefault::Implicit(s) => {
            format!("default {s}")
        }
    };
    let choices = match p.kind {
        benchmarks::ParamKind::Choice(names) => format!(" (one of: {})", names.join(", ")),
        _ => String::new(),
    };
    println!(
        "  {:<8} {:<17} [{}] {}{choices}",
        p.key, default, p.unit, p.doc
    );
}
