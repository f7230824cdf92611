use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use mpmlab::collect::collect;
use mpmlab::runner::{results_dir, run_experiment, RunOptions};
use mpmlab::{
    benchmarks, experiment, methods, reconstruction_methods, reference, report, shape_methods,
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
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Parent directory of the results; each experiment writes to OUT/<name>/.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Parallel runs (default: one per core).
        #[arg(long, default_value_t = 0)]
        jobs: usize,
        /// Rerun runs whose file already exists.
        #[arg(long)]
        force: bool,
    },
    /// Write summary.csv, rates.csv, figures and report.md for a results directory.
    Report {
        dir: PathBuf,
        /// Evaluate the experiment's `expect` entries; exit non-zero if any fails.
        #[arg(long)]
        check: bool,
    },
    /// List the method presets and what they are composed of, and the reconstruction methods.
    ListMethods,
    /// List the benchmarks and their parameters.
    ListBenchmarks,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Expand { file, json } => expand(&file, json),
        Command::Run {
            files,
            out,
            jobs,
            force,
        } => run(&files, RunOptions { out, jobs, force }),
        Command::Report { dir, check } => report_dir(&dir, check),
        Command::ListMethods => {
            list_methods();
            Ok(())
        }
        Command::ListBenchmarks => {
            list_benchmarks();
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn expand(file: &Path, json: bool) -> Result<(), String> {
    let experiment = experiment::load(file).map_err(|e| e.to_string())?;
    for run in &experiment.runs {
        if json {
            println!("{}", run.to_json());
        } else {
            println!("{}", run.describe());
        }
    }
    Ok(())
}

fn run(files: &[PathBuf], options: RunOptions) -> Result<(), String> {
    // Validate every file before running any, so a typo in the last file does not
    // surface after hours of work.
    let experiments = files
        .iter()
        .map(|f| experiment::load(f).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    for experiment in &experiments {
        let dir = results_dir(&options.out, experiment);
        let outcome =
            run_experiment(experiment, &options).map_err(|e| format!("{}: {e}", dir.display()))?;
        eprintln!(
            "{}: {} runs written, {} already present, {} diverged, {} failed -> {}",
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
    }
    Ok(())
}

fn report_dir(dir: &Path, check: bool) -> Result<(), String> {
    let collected = collect(dir)?;
    for run_id in &collected.missing {
        eprintln!("missing run: {run_id}");
    }
    let rates = report::fit_rates(&collected.experiment, &collected.runs);
    let failures = check.then(|| report::check(&collected.experiment, &rates, &collected.runs));
    report::write_report(
        dir,
        &collected.experiment,
        &collected.runs,
        &rates,
        failures.as_deref(),
    )
    .map_err(|e| format!("{}: {e}", dir.display()))?;
    eprintln!("report written to {}", dir.join("report.md").display());
    match failures {
        Some(failures) if !failures.is_empty() => {
            for failure in &failures {
                eprintln!("check failed: {}", failure.message);
            }
            Err(format!("{} expectation(s) not met", failures.len()))
        }
        Some(_) if !collected.missing.is_empty() => Err(format!(
            "{} run(s) of the matrix are missing",
            collected.missing.len()
        )),
        Some(_) => {
            eprintln!("all expectations met");
            Ok(())
        }
        None => Ok(()),
    }
}

fn list_methods() {
    println!("Simulation methods (benchmarks of kind simulation):");
    for preset in methods::presets() {
        println!(
            "{:<15} {}  [{}]",
            preset.name, preset.description, preset.source
        );
        println!("{:<15} {}", "", preset.method);
    }
    println!("\nReference solvers (simulation benchmarks they name):");
    for m in reference::methods() {
        println!("{:<15} {}  [{}]", m.name, m.description, m.source);
        println!("{:<15} benchmarks: {}", "", m.benchmarks.join(", "));
    }
    println!(
        "\nReconstruction methods (reconstruction benchmarks; the weight of a local fit is a \
         parameter, tls_* serve recon_tls):"
    );
    for m in reconstruction_methods::methods() {
        println!("{:<15} {}  [{}]", m.name, m.description, m.source);
        println!("{:<15} degree={} fit={}", "", m.degree.value(), m.fit);
    }
    println!("\nGrid bases (shape_functions; gamma and tolerance are parameters of lme):");
    for m in shape_methods::methods() {
        println!("{:<15} {}  [{}]", m.name, m.description, m.source);
    }
}

fn list_benchmarks() {
    for b in benchmarks::catalog() {
        let kind = benchmarks::kind(b);
        // The element-wise benchmark runs in its function's dimension, shape_functions in its
        // `dim`.
        let varies = [
            benchmarks::BenchmarkKind::Elementwise,
            benchmarks::BenchmarkKind::ShapeFunctions,
        ];
        let dims = if varies.contains(&kind) {
            format!("1D or {}D", b.dim)
        } else {
            format!("{}D", b.dim)
        };
        println!(
            "{} ({dims}, {kind}) - {} [{}]",
            b.name, b.description, b.source
        );
        for p in b.params {
            let default = match p.default {
                benchmarks::ParamDefault::Required => "required".to_string(),
                benchmarks::ParamDefault::Int(i) => format!("default {i}"),
                benchmarks::ParamDefault::Float(x) => format!("default {x:?}"),
                benchmarks::ParamDefault::Text(s) => format!("default {s}"),
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
    }
}
