//! One run of an experiment as its file states it, defaults filled in: the names and values
//! a run record carries into its HDF5 file. `experiment::ResolvedRun` holds it beside what
//! the names stand for.

use crate::params::Params;

/// One run's benchmark, method, parameters and identity.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSpec {
    pub experiment: String,
    /// Human-readable and stable: `<method>-<axis values>-<hash>`; the hash covers the
    /// canonical resolved configuration, so the same YAML always gives the same ids.
    pub run_id: String,
    pub benchmark: String,
    pub method: String,
    /// Every benchmark parameter, defaults filled in (method excluded).
    pub params: Params,
    /// This run's value of each matrix axis (method included when it is an axis).
    pub axes: Params,
    pub output_every: usize,
    /// The canonical resolved configuration as YAML, stored in each HDF5 file.
    pub config_yaml: String,
}
