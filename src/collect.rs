//! Gathers what a report needs from a results directory: the experiment (from its copy
//! beside the runs) and the summary of every run file the experiment expands to, with the
//! final fields along the bar and the errors against the reference run when it names one.

mod compare;

use std::path::Path;

use crate::experiment::{self, Experiment};
use crate::experiment::{FigureKind, TableKind};
use crate::output::{read_probes, read_profile, read_summary, run_path, RunSummary};
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
            if wants_profiles(&experiment) {
                run.profile = read_profile(&path)?;
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
