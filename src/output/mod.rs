//! The HDF5 layout of one run. Every dataset and attribute name lives here; the README's
//! "HDF5 layout" section documents the same contract.

use std::collections::BTreeMap;

use crate::benchmarks::{self, BenchmarkInfo, BenchmarkKind};
use crate::params::Params;

/// Bumped whenever a name or shape below changes meaning.
pub const SCHEMA_VERSION: i64 = 3;

/// The root dataset holding the run's resolved configuration as YAML text.
pub const CONFIG_YAML: &str = "config_yaml";

/// The error fields at the particles, in the order they are written.
pub const ERROR_FIELDS: [&str; 4] = ["displacement", "velocity", "stress", "density"];
/// The error of the grid velocity at the grid's DOFs against the exact velocity there.
pub const GRID_VELOCITY: &str = "grid_velocity";
/// The fields of a simulation whose benchmark knows the exact velocity on the grid
/// (`benchmarks::exact_on_grid`).
pub const ERROR_FIELDS_WITH_GRID: [&str; 5] = [
    ERROR_FIELDS[0],
    ERROR_FIELDS[1],
    ERROR_FIELDS[2],
    ERROR_FIELDS[3],
    GRID_VELOCITY,
];
/// The error norms: `l2 = sqrt(sum_p V_p |e_p|^2)`, `rms = sqrt(sum_p |e_p|^2 / Np)` (for the
/// grid velocity the sums run over the DOFs, with their quadrature weights).
pub const NORMS: [&str; 2] = ["l2", "rms"];
/// The norms with the relative l2 error against an experiment's reference run (computed by
/// `collect`, never stored in a run file): ||f - f_ref|| / ||f_ref|| with the l2 norm above.
pub const NORMS_WITH_REFERENCE: [&str; 3] = ["l2", "rms", REFERENCE_NORM];
pub const REFERENCE_NORM: &str = "reference";

/// A reconstruction run's error field, u - u^h at the evaluation points.
pub const RECONSTRUCTION_FIELDS: [&str; 1] = ["u"];
/// Its norms: `l2 = sqrt(sum_e h e_e^2)` (Gong sec 5.2), `max = max_e |e_e|`.
pub const RECONSTRUCTION_NORMS: [&str; 2] = ["l2", "max"];
/// The norms of an element-wise reconstruction, u - u^h at the Gauss points (Wobbes sec 2.1):
/// `rms = sqrt(sum_g e_g^2 / Ng)` and `integral`, the relative error of the Gauss integral of
/// u^h against the exact integral of u.
pub const ELEMENT_NORMS: [&str; 2] = ["rms", "integral"];

/// The consistency errors of a shape-function run at each point, over the whole basis:
/// `partition` |sum N_a - 1|, `moment` |sum N_a x_a - x| / h, `gradient` h |sum grad N_a|,
/// `gradient_moment` |sum grad N_a (x) x_a - I| (Frobenius).
pub const SHAPE_FIELDS: [&str; 4] = ["partition", "moment", "gradient", "gradient_moment"];
/// Their norm: the largest over the evaluation points.
pub const SHAPE_NORMS: [&str; 1] = ["max"];

/// The fields a `field_map` figure draws over the plane of a 2D run, by kind of run. A
/// simulation's are components of the particle state at the last sample (`displacement` is
/// x - X); an element-wise reconstruction's are u^h and u - u^h at its map samples
/// (`/elements/map_*`); a shape-function run's are N_a and the components of grad N_a of its
/// centre node.
pub const PARTICLE_MAP_FIELDS: [&str; 8] = [
    "displacement_x",
    "displacement_y",
    "velocity_x",
    "velocity_y",
    "stress_xx",
    "stress_yy",
    "stress_xy",
    "density",
];
pub const ELEMENT_MAP_FIELDS: [&str; 2] = ["reconstructed", "error"];
pub const SHAPE_MAP_FIELDS: [&str; 3] = ["value", "gradient_x", "gradient_y"];

/// The map fields of a kind of run; none for the nodal reconstructions, which are 1D.
pub fn map_fields(kind: BenchmarkKind) -> &'static [&'static str] {
    match kind {
        BenchmarkKind::Simulation => &PARTICLE_MAP_FIELDS,
        BenchmarkKind::Elementwise => &ELEMENT_MAP_FIELDS,
        BenchmarkKind::ShapeFunctions => &SHAPE_MAP_FIELDS,
        BenchmarkKind::Reconstruction | BenchmarkKind::OrthogonalBasis => &[],
    }
}

/// The unit of a particle or grid field's values.
pub(super) fn field_unit(field: &str) -> &'static str {
    match field {
        "displacement" => "m",
        "velocity" | GRID_VELOCITY => "m/s",
        "stress" => "Pa",
        _ => "kg/m^D",
    }
}

/// The error fields a kind of run reports, each in each of the norms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measures {
    pub fields: &'static [&'static str],
    pub norms: &'static [&'static str],
}

impl Measures {
    pub fn of(kind: BenchmarkKind) -> Measures {
        match kind {
            BenchmarkKind::Simulation => Measures {
                fields: &ERROR_FIELDS,
                norms: &NORMS,
            },
            BenchmarkKind::Reconstruction | BenchmarkKind::OrthogonalBasis => Measures {
                fields: &RECONSTRUCTION_FIELDS,
                norms: &RECONSTRUCTION_NORMS,
            },
            BenchmarkKind::Elementwise => Measures {
                fields: &RECONSTRUCTION_FIELDS,
                norms: &ELEMENT_NORMS,
            },
            BenchmarkKind::ShapeFunctions => Measures {
                fields: &SHAPE_FIELDS,
                norms: &SHAPE_NORMS,
            },
        }
    }

    /// The measures of a benchmark's runs: its kind's, with the grid velocity for simulations
    /// that know the exact velocity on the grid.
    pub fn of_benchmark(info: &BenchmarkInfo) -> Measures {
        let measures = Measures::of(info.kind);
        if measures.fields == ERROR_FIELDS && benchmarks::exact_on_grid(info) {
            Measures {
                fields: &ERROR_FIELDS_WITH_GRID,
                ..measures
            }
        } else {
            measures
        }
    }

    /// With the `reference` norm when `compared` (simulations only).
    pub fn with_reference(self, compared: bool) -> Measures {
        if compared && self.norms == NORMS {
            Measures {
                norms: &NORMS_WITH_REFERENCE,
                ..self
            }
        } else {
            self
        }
    }
}

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
    /// The median wall time of one step (NaN without a time loop, or from a file that lacks it).
    pub step_seconds: f64,
    /// The run's value of each matrix axis (from the `/matrix` group).
    pub axes: Params,
    /// Final error norms keyed by (field, norm), e.g. ("velocity", "l2").
    pub final_norms: BTreeMap<(String, String), f64>,
    /// The `/reconstruction`, `/elements` or `/shape_functions` group of an unstepped run,
    /// which its figures and tables show.
    pub unstepped: Unstepped,
    /// The l2 velocity error at every sample of a simulation run that took any.
    pub velocity_history: Option<VelocityHistory>,
    /// The `/conservation` attributes (largest relative mass and momentum errors of the run's
    /// mappings); NaN for a run that has none.
    pub max_mass_error: f64,
    pub max_momentum_error: f64,
    /// The state along x at the last sample of a simulation run (`ParticleState::along_x`),
    /// when the report compares runs with a reference run or draws fields along the bar
    /// (`collect` fills it).
    pub profile: Option<ParticleState>,
    /// The `/probes` of a simulation run, when the report draws their histories (`collect`
    /// fills it); empty otherwise.
    pub probes: Vec<ProbeRecord>,
    /// The last sample of a 2D simulation run, when the report draws field maps (`collect`
    /// fills it).
    pub final_state: Option<ParticleState>,
}

impl RunSummary {
    /// The run's probe `name`, when `collect` read the probes and the run records it.
    pub fn probe(&self, name: &str) -> Option<&ProbeRecord> {
        self.probes.iter().find(|p| p.name == name)
    }
}

/// The last sample of a simulation run, one row per particle (per element for a reference
/// solver), from `/particles`, `/history` and `/errors/volume`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleState {
    pub dim: usize,
    /// The sample's time: t_end, or where a diverged run stopped.
    pub time: f64,
    /// Np x D: reference and current positions, velocities.
    pub x0: Vec<f64>,
    pub x: Vec<f64>,
    pub velocity: Vec<f64>,
    /// Np x D x D, Cauchy stress.
    pub stress: Vec<f64>,
    pub density: Vec<f64>,
    /// Current volumes (areas in 2D), the quadrature weights of the l2 norm.
    pub volume: Vec<f64>,
}

impl ParticleState {
    pub fn len(&self) -> usize {
        self.density.len()
    }

    pub fn is_empty(&self) -> bool {
        self.density.is_empty()
    }
}

impl ParticleState {
    /// The state along x: the first component of every vector and tensor, as a 1D state (the
    /// whole state of a 1D run).
    pub fn along_x(&self) -> ParticleState {
        let d = self.dim;
        let first = |values: &[f64], per: usize| values.iter().step_by(per).copied().collect();
        ParticleState {
            dim: 1,
            time: self.time,
            x0: first(&self.x0, d),
            x: first(&self.x, d),
            velocity: first(&self.velocity, d),
            stress: first(&self.stress, d * d),
            density: self.density.clone(),
            volume: self.volume.clone(),
        }
    }

    /// The values of an error field along x (`displacement` is x - X) of a 1D state.
    pub fn field(&self, field: &str) -> Vec<f64> {
        match field {
            "displacement" => self.x.iter().zip(&self.x0).map(|(x, x0)| x - x0).collect(),
            "velocity" => self.velocity.clone(),
            "stress" => self.stress.clone(),
            _ => self.density.clone(),
        }
    }
}

/// The l2 velocity error over a run beside the size of the solution, which is what a
/// stability study needs to tell a run whose error grew (`report`'s stability kinds).
#[derive(Clone, Debug, PartialEq)]
pub struct VelocityHistory {
    /// `/errors/time`.
    pub time: Vec<f64>,
    /// `/errors/norms/l2_velocity`.
    pub l2_error: Vec<f64>,
    /// sqrt(sum_p V_p |v_p|^2) of the first sample (t = 0), where the particles carry the
    /// exact initial velocity.
    pub initial_l2: f64,
}

mod atomic;
mod elements;
mod h5;
mod probes;
mod reader;
mod reconstruction;
mod record;
mod shape_functions;
mod stream;
mod writer;
mod xdmf;

pub use atomic::{
    compute_run, describe_if_missing, host_tag, remove_dead_temps, run_path, temp_path, this_host,
    write_all_atomically, write_atomically, write_run, TempHost, TempWriter,
};
pub use elements::ElementRecord;
pub use probes::{ProbeRecord, Wiggles, REFERENCE_KINDS};
pub use reader::{
    open_hdf5, open_run_file, read_final_state, read_message, read_probes, read_summary,
    UnreadableRun,
};
pub use reconstruction::{BasisRecord, ReconstructionRecord};
pub use record::{
    Conservation, Diagnostics, Errors, GridErrors, GridHistory, History, MethodParts,
    ParticleTable, RunRecord, Unstepped,
};
pub use shape_functions::ShapeFunctionRecord;
pub use stream::{HistoryStream, StreamShape};
pub use writer::{write_hdf5, write_record};
pub use xdmf::xdmf_path;
use xdmf::{write_xdmf, HistoryLayout};
