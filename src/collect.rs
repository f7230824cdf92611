//! Gathers what a report needs from a results directory: the experiment (from its copy
//! beside the runs) and the summary of every run file the experiment expands to.

use std::path::Path;

use crate::experiment::{self, Experiment};
use crate::output::{read_summary, run_path, RunSummary};
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
            runs.push(read_summary(&path)?);
        } else {
            missing.push(spec.run_id.clone());
        }
    }
    Ok(Collected {
        experiment,
        runs,
        missing,
    })
}
