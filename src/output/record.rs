use super::{
    ElementRecord, HistoryStream, ProbeRecord, ReconstructionRecord, RunStatus, ShapeFunctionRecord,
};
use crate::methods::Method;
use crate::run_spec::RunSpec;

/// Everything written to one run file, as flat row-major arrays so that the layout does
/// not depend on the dimension at compile time.
#[derive(Debug)]
pub struct RunRecord {
    pub spec: RunSpec,
    pub parts: MethodParts,
    pub dim: usize,
    pub cells: usize,
    pub ppc: usize,
    pub h: f64,
    pub dt: f64,
    pub t_end: f64,
    /// Steps actually taken (fewer than planned when the run diverged).
    pub steps: usize,
    pub status: RunStatus,
    pub message: String,
    pub wall_seconds: f64,
    /// The median wall time of one step of the time loop; NaN for runs without one.
    pub step_seconds: f64,
    pub particles: ParticleTable,
    pub history: History,
    pub grid: GridHistory,
    pub errors: Errors,
    pub conservation: Conservation,
    pub diagnostics: Diagnostics,
    /// `/probes`: every-step records at single particles (none for reference solvers).
    pub probes: Vec<ProbeRecord>,
    /// What a run of a benchmark that does not step records in place of particles and a
    /// history.
    pub unstepped: Unstepped,
    /// The arrays of `history`, `grid`, `errors` and `probes` that grow with the samples and
    /// steps, when the run wrote them to its file as it went (those vectors then hold none),
    /// or why writing them failed.
    pub stream: Option<Result<HistoryStream, String>>,
}

/// The record of an unstepped run by its benchmark's kind; `None` for a stepped run, whose
/// record is its particles and history.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Unstepped {
    #[default]
    None,
    /// `/reconstruction`: a nodal reconstruction.
    Reconstruction(ReconstructionRecord),
    /// `/elements`: the element-wise reconstruction.
    Elements(ElementRecord),
    /// `/shape_functions`: a grid basis evaluated on a lattice.
    ShapeFunctions(ShapeFunctionRecord),
}

impl Unstepped {
    pub fn reconstruction(&self) -> Option<&ReconstructionRecord> {
        match self {
            Unstepped::Reconstruction(record) => Some(record),
            _ => None,
        }
    }

    pub fn elements(&self) -> Option<&ElementRecord> {
        match self {
            Unstepped::Elements(record) => Some(record),
            _ => None,
        }
    }

    pub fn shape_functions(&self) -> Option<&ShapeFunctionRecord> {
        match self {
            Unstepped::ShapeFunctions(record) => Some(record),
            _ => None,
        }
    }
}

/// The root attributes `shape`, `transfer` and `integrator`: what the run's method is made of.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MethodParts {
    pub shape: String,
    pub transfer: String,
    pub integrator: String,
}

impl From<Method> for MethodParts {
    fn from(method: Method) -> Self {
        MethodParts {
            shape: method.shape.to_string(),
            transfer: method.transfer.to_string(),
            integrator: method.integrator.to_string(),
        }
    }
}

/// `/particles`: reference positions (Np x D), masses and initial volumes.
#[derive(Clone, Debug, Default)]
pub struct ParticleTable {
    pub x0: Vec<f64>,
    pub mass: Vec<f64>,
    pub volume0: Vec<f64>,
}

impl ParticleTable {
    pub fn len(&self) -> usize {
        self.mass.len()
    }

    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }
}

/// `/history`: sampled particle states, Nt samples.
#[derive(Clone, Debug, Default)]
pub struct History {
    pub time: Vec<f64>,
    pub step: Vec<i64>,
    /// Nt x Np x D.
    pub x: Vec<f64>,
    /// Nt x Np x D, velocities synchronised to the sample time.
    pub v: Vec<f64>,
    /// Nt x Np x D x D, Cauchy stress.
    pub stress: Vec<f64>,
    /// Nt x Np.
    pub density: Vec<f64>,
}

/// `/grid`: the DOFs of the grid's basis and their velocity at the history samples, which
/// `/errors/grid_velocity` compares with the exact velocity.
#[derive(Clone, Debug, Default)]
pub struct GridHistory {
    /// Nn x D positions of the DOFs.
    pub x: Vec<f64>,
    /// Nn quadrature weights of the grid-velocity norm: the trapezoidal rule over the DOFs.
    pub weight: Vec<f64>,
    /// Nt: the time each sample's grid velocity belongs to.
    pub time: Vec<f64>,
    /// Nt x Nn x D.
    pub v: Vec<f64>,
}

/// `/errors`: pointwise error magnitudes and their norms at the history samples.
#[derive(Clone, Debug, Default)]
pub struct Errors {
    /// Nt x Np current particle volumes, the quadrature weights of the l2 norm.
    pub volume: Vec<f64>,
    /// Per field of `ERROR_FIELDS`: Nt x Np magnitudes |e_p|.
    pub pointwise: [Vec<f64>; 4],
    /// Per field: Nt values of sqrt(sum_p V_p |e_p|^2).
    pub l2: [Vec<f64>; 4],
    /// Per field: Nt values of sqrt(sum_p |e_p|^2 / Np).
    pub rms: [Vec<f64>; 4],
    /// `GRID_VELOCITY` at the DOFs, with the weights of `/grid/weight`.
    pub grid_velocity: GridErrors,
}

/// The grid-velocity error: Nt x Nn magnitudes |e_a| (NaN at a DOF where the exact velocity
/// is unknown) and Nt values of each norm over the DOFs where it is known (NaN when at none):
/// sqrt(sum_a w_a |e_a|^2) and sqrt(sum_a |e_a|^2 / Na).
#[derive(Clone, Debug, Default)]
pub struct GridErrors {
    pub pointwise: Vec<f64>,
    pub l2: Vec<f64>,
    pub rms: Vec<f64>,
}

/// `/conservation`: mass totals at the history samples (the times are `/history/time`).
/// Methods that reconstruct density at quadrature points do not carry the particle mass to
/// the grid exactly; these totals show by how much.
#[derive(Clone, Debug)]
pub struct Conservation {
    /// Nt sums of the particle masses.
    pub particle_mass: Vec<f64>,
    /// Nt sums of the lumped nodal masses assembled at the sampled step.
    pub grid_mass: Vec<f64>,
    /// Over every mapping of the run (each step's particle-to-grid transfer and, for MUSL, the
    /// velocity remap): max |sum_i m_i - sum_p M_p| / sum_p M_p ...
    pub max_mass_error: f64,
    /// ... and max |sum_i p_i - sum_p M_p v_p| / sum_p M_p |v_p|, the momentum the DOFs received
    /// against the particles' (absolute when every particle is at rest). NaN for runs that
    /// did not map.
    pub max_momentum_error: f64,
}

impl Default for Conservation {
    fn default() -> Self {
        Conservation {
            particle_mass: Vec::new(),
            grid_mass: Vec::new(),
            max_mass_error: f64::NAN,
            max_momentum_error: f64::NAN,
        }
    }
}

/// `/diagnostics`: how the local least-squares fits of a run went.
#[derive(Clone, Copy, Debug, Default)]
pub struct Diagnostics {
    /// Local least-squares fits made during the run.
    pub reconstructions: usize,
    /// Fits whose moment matrix lost rank.
    pub rank_deficient: usize,
    /// Particle moves from one grid cell to another, summed over the steps.
    pub grid_crossings: usize,
    /// LME evaluations whose Newton iteration stopped short (`shape::LmeFailure`): each still
    /// fills its stencil from the last iterate, which is why the count is kept.
    pub lme_failures: usize,
}
