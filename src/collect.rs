//! Gathers what a report needs from a results directory: the experiment (from its copy
//! beside the runs) and the summary of every run file the experiment expands to, with the
//! final fields along the bar and the errors against the reference run when it names one, and
//! the last particle state of each 2D run for field maps. Each run file is read on its own: one
//! that cannot be read is listed with the reason and left out, and the others are reported.

mod compare;

use std::collections::BTreeSet;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use crate::benchmarks::BenchmarkKind;
use crate::experiment::{self, Experiment, FigureKind, TableKind};
use crate::output::{
    open_hdf5, open_run_file, read_final_state, read_probes, read_summary, run_path, ParticleState,
    RunSummary, UnreadableRun,
};
use crate::run_spec::RunSpec;
use crate::runner::EXPERIMENT_COPY;

pub struct Collected {
    pub experiment: Experiment,
    pub runs: Vec<RunSummary>,
    /// Run ids of the matrix that have no file yet.
    pub missing: Vec<String>,
    /// Files in `runs/` that cannot be read: a run's file of the matrix that is not a complete
    /// run file of this experiment, or any other `*.h5` that is not an HDF5 file at all. In
    /// the order of the matrix, then by name.
    pub unreadable: Vec<UnreadableRun>,
}

pub fn collect(dir: &Path) -> Result<Collected, String> {
    let copy = dir.join(EXPERIMENT_COPY);
    if !copy.exists() {
        return Err(format!(
            "{}: not a results directory (no {EXPERIMENT_COPY}); run `mpmlab run` first",
            dir.display()
        ));
    }
    let experiment = experiment::load(&copy).map_err(|e| e.to_string())?;
    let mut runs = Vec::new();
    let mut missing = Vec::new();
    let mut unreadable = Vec::new();
    for spec in experiment.runs.iter().map(|run| &run.spec) {
        let path = run_path(dir, &spec.run_id);
        if !path.exists() {
            missing.push(spec.run_id.clone());
            continue;
        }
        match read_run(&path, &experiment, spec) {
            Ok(run) => runs.push(run),
            Err(reason) => unreadable.push(UnreadableRun {
                file: in_runs(&path),
                reason,
            }),
        }
    }
    unreadable.extend(foreign_files(dir, &experiment)?);
    if let Some(select) = &experiment.reference {
        compare::attach_reference_errors(select, &mut runs);
    }
    Ok(Collected {
        experiment,
        runs,
        missing,
        unreadable,
    })
}

/// The summary of the run file at `path`, with what the experiment's report draws from it;
/// an error in plain words when it is not a whole run file of `spec`.
fn read_run(path: &Path, experiment: &Experiment, spec: &RunSpec) -> Result<RunSummary, String> {
    let file = open_run_file(path)?;
    let mut run = read_summary(&file)?;
    if run.experiment != experiment.name {
        return Err(format!(
            "belongs to experiment '{}', not '{}'",
            run.experiment, experiment.name
        ));
    }
    if run.run_id != spec.run_id {
        return Err(format!("holds run {}, not {}", run.run_id, spec.run_id));
    }
    let state = if wants_profiles(experiment) || draws_particle_maps(experiment) {
        read_final_state(&file)?
    } else {
        None
    };
    if wants_profiles(experiment) {
        run.profile = state.as_ref().map(ParticleState::along_x);
    }
    if draws_particle_maps(experiment) {
        run.final_state = state.filter(|s| s.dim == 2);
    }
    if reads_probes(experiment) {
        run.probes = read_probes(&file)?;
    }
    Ok(run)
}

/// The `*.h5` files in `runs/` that no run of the matrix names and that HDF5 cannot open (a
/// truncated copy, a file of another kind). Run files of runs the experiment no longer has
/// are left alone, as the report leaves them out.
fn foreign_files(dir: &Path, experiment: &Experiment) -> Result<Vec<UnreadableRun>, String> {
    let runs = dir.join("runs");
    let entries = match fs::read_dir(&runs) {
        Ok(entries) => entries,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("{}: {e}", runs.display())),
    };
    let matrix: BTreeSet<&str> = experiment
        .runs
        .iter()
        .map(|r| r.spec.run_id.as_str())
        .collect();
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| {
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            let stem = name.strip_suffix(".h5").unwrap_or_default();
            name.ends_with(".h5")
                && !name.starts_with('.')
                && !matrix.contains(stem)
                && path.is_file()
        })
        .collect();
    paths.sort();
    Ok(paths
        .into_iter()
        .filter_map(|path| {
            let reason = open_hdf5(&path).err()?;
            Some(UnreadableRun {
                file: in_runs(&path),
                reason,
            })
        })
        .collect())
}

/// A run file's path as the report names it: `runs/<name>`.
fn in_runs(path: &Path) -> PathBuf {
    Path::new("runs").join(path.file_name().unwrap_or_default())
}

/// Whether the report compares runs with a reference run or draws fields along the bar.
fn wants_profiles(experiment: &Experiment) -> bool {
    experiment.reference.is_some()
        || experiment
            .figures
            .iter()
            .any(|f| f.kind == FigureKind::Profile)
}

/// Whether the report draws field maps of the particles of a simulation.
fn draws_particle_maps(experiment: &Experiment) -> bool {
    experiment.kind == BenchmarkKind::Simulation
        && experiment
            .figures
            .iter()
            .any(|f| f.kind == FigureKind::FieldMap)
}

/// Whether the report needs the `/probes` of every run: to draw their histories, for the
/// wiggle measures of its errors tables, or for its probes tables.
fn reads_probes(experiment: &Experiment) -> bool {
    experiment
        .figures
        .iter()
        .any(|f| f.kind == FigureKind::History)
        || experiment
            .tables
            .iter()
            .any(|t| matches!(t.kind, TableKind::Errors | TableKind::Probes))
}
