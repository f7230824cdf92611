//! One run of an experiment, fully resolved: what `experiment` expands a file into and every
//! later stage (runner, solver, output) is handed.

use crate::params::Params;

/// Everything one run needs, fully resolved.
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
