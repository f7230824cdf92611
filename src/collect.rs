//! Gathers what a report needs from a results directory: the experiment (from its copy
//! beside the runs) and the summary of every run file the experiment expands to, with the
//! final fields along the bar and the errors against the reference run when it names one, and
//! the last particle state of each 2D run for field maps.

mod compare;

use std::path::Path;

use crate::benchmarks::BenchmarkKind;
use crate::experiment::{self, Experiment};
use crate::experiment::{FigureKind, TableKind};
use crate::output::{
    read_final_state, read_probes, read_summary, run_path, ParticleState, RunSummary,
};
use crate::runner::EXPERIMENT_COPY;

pub struct Collected {
    pub experiment: Experiment,
    pub runs: Vec<RunSummary>,
    /// Run ids of the matrix that have no file yet.
    pub missing: Vec<String>,
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
    for spec in &experiment.runs {
        let path = run_path(dir, &spec.run_id);
        if path.exists() {
            let mut run = read_summary(&path)?;
            let state = if wants_profiles(&experiment) || draws_particle_maps(&experiment) {
                read_final_state(&path)?
            } else {
                None
            };
            if wants_profiles(&experiment) {
                run.profile = state.as_ref().map(ParticleState::along_x);
            }
            if draws_particle_maps(&experiment) {
                run.final_state = state.filter(|s| s.dim == 2);
            }
            if reads_probes(&experiment) {
                run.probes = read_probes(&path)?;
            }
            runs.push(run);
        } else {
            missing.push(spec.run_id.clone());
        }
    }
    if let Some(select) = &experiment.reference {
        compare::attach_reference_errors(select, &mut runs);
    }
    Ok(Collected {
        experiment,
        runs,
        missing,
    })
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
