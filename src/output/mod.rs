//! The HDF5 layout of one run. Every dataset and attribute name lives here; the README's
//! "HDF5 layout" section documents the same contract.

use std::collections::BTreeMap;

use crate::params::Params;

/// Bumped whenever a name or shape below changes meaning.
pub const SCHEMA_VERSION: i64 = 2;

/// The error fields, in the order they are written.
pub const ERROR_FIELDS: [&str; 4] = ["displacement", "velocity", "stress", "density"];
/// The error norms: `l2 = sqrt(sum_p V_p |e_p|^2)`, `rms = sqrt(sum_p |e_p|^2 / Np)`.
pub const NORMS: [&str; 2] = ["l2", "rms"];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunStatus {
    Ok,
    Diverged,
    Failed,
}

impl RunStatus {
    pub fn as_str(self) -> &'static str {
        match self {
            RunStatus::Ok => "ok",
            RunStatus::Diverged => "diverged",
            RunStatus::Failed => "failed",
        }
    }

    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "ok" => Some(RunStatus::Ok),
            "diverged" => Some(RunStatus::Diverged),
            "failed" => Some(RunStatus::Failed),
            _ => None,
        }
    }
}

/// What the report needs from one run file: its identity, matrix values, status and the
/// final error norms.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSummary {
    pub run_id: String,
    pub experiment: String,
    pub benchmark: String,
    pub method: String,
    pub dim: usize,
    pub cells: usize,
    pub ppc: usize,
    /// Cell size of the background grid.
    pub h: f64,
    pub dt: f64,
    pub steps: usize,
    pub status: RunStatus,
    pub message: String,
    pub wall_seconds: f64,
    /// The run's value of each matrix axis (from the `/matrix` group).
    pub axes: Params,
    /// Final error norms keyed by (field, norm), e.g. ("velocity", "l2").
    pub final_norms: BTreeMap<(String, String), f64>,
}

mod atomic;
mod reader;
mod record;
mod writer;

pub use atomic::{run_path, write_atomically, write_run};
pub use reader::read_summary;
pub use record::{Conservation, Diagnostics, Errors, History, ParticleTable, RunRecord};
pub use writer::write_hdf5;
