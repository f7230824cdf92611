//! Benchmark problems: domain, material, initial and boundary conditions, body force and the
//! exact solution. A benchmark knows nothing of how a method maps data. The reconstruction
//! benchmarks (`scattered`) have no time stepping: a known function sampled at points; nor has
//! `shape_functions`, a grid basis evaluated at points.

mod andersen_block;
mod dyka_bar;
pub(crate) mod limits;
mod mms_gong;
mod mms_tran;
pub mod scattered;
pub mod shape_functions;
mod sine_mms;
mod vibrating_bar;

use nalgebra::{SMatrix, SVector};

use crate::catalog::{Catalog, Named};
use crate::grid::{Domain, Grid};
use crate::material::Material;
use crate::params::{get_str, ParamError, ParamValue, Params};
use crate::particles::{Body, Particles, Placement};

pub use limits::{TimeStep, LIMIT_PARAMS, MAX_POINTS, MAX_STEPS, MAX_STEPS_KEY};
pub use mms_gong::{gong_mms, thesis_params};
pub use sine_mms::SineMms;
pub use vibrating_bar::{vibrating_bar, VibratingBar};

/// The kind of value a parameter takes; checked by the experiment layer before a run starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamKind {
    /// Any finite real number.
    Real,
    /// A finite real number > 0.
    PositiveReal,
    /// An integer >= 1.
    PositiveInt,
    /// One of the listed names.
    Choice(&'static [&'static str]),
    /// A non-empty list of finite real numbers.
    RealList,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamDefault {
    Required,
    Int(i64),
    Float(f64),
    Text(&'static str),
    /// The choice a run takes when its file does not set the parameter, left out of the
    /// run's parameters (and so of its id and configuration) unless set: a parameter added to
    /// a benchmark this way keeps every existing run's id.
    Implicit(&'static str),
}

pub struct ParamSpec {
    pub key: &'static str,
    pub kind: ParamKind,
    pub default: ParamDefault,
    pub unit: &'static str,
    pub doc: &'static str,
}

/// The parameters of `specs` that have a default, at their defaults.
pub fn default_params(specs: &[ParamSpec]) -> Params {
    specs
        .iter()
        .filter_map(|spec| {
            let value = match spec.default {
                ParamDefault::Required | ParamDefault::Implicit(_) => return None,
                ParamDefault::Int(i) => ParamValue::Int(i),
                ParamDefault::Float(x) => ParamValue::Float(x),
                ParamDefault::Text(s) => ParamValue::Str(s.to_string()),
            };
            Some((spec.key.to_string(), value))
        })
        .collect()
}

/// The seeding parameter of the benchmarks that offer a choice of particle placement, and its
/// values: the Gauss points of each cell, or the sub-cell centres.
pub const PLACEMENT_KEY: &str = "placement";
pub const PLACEMENTS: &[&str] = &["gauss", "centres"];

/// The placement a run's `placement` names; `absent` where it names none.
fn placement(params: &Params, absent: Placement) -> Result<Placement, ParamError> {
    if !params.contains_key(PLACEMENT_KEY) {
        return Ok(absent);
    }
    Ok(match get_str(params, PLACEMENT_KEY)? {
        "gauss" => Placement::Gauss,
        _ => Placement::SubCellCentres,
    })
}

/// Catalogue entry of a benchmark: what `list-benchmarks` prints and what validation uses.
pub struct BenchmarkInfo {
    pub name: &'static str,
    /// What its runs do, which decides what they record.
    pub kind: BenchmarkKind,
    /// What a run builds, which fixes its dimension.
    pub build: Build,
    pub source: &'static str,
    pub description: &'static str,
    pub params: &'static [ParamSpec],
    /// Checks that need several parameters at once (stability, physical admissibility).
    /// Called with every parameter present and of the right kind.
    pub check: fn(&Params) -> Result<(), ParamError>,
    /// The time step of a run, which its check approves and its problem takes; `None` for a
    /// benchmark that does not step in time.
    pub time_step: Option<TimeStepFn>,
}

/// A simulation's problem in `D` dimensions from validated parameters.
pub type ProblemFn<const D: usize> = fn(&Params) -> Result<Box<dyn Problem<D>>, ParamError>;

/// What a benchmark builds for a run: a simulation its problem, in 1D or 2D; the other kinds
/// nothing, evaluating data or a basis at points in up to `dim` dimensions (each run takes
/// the dimension of its own parameters).
#[derive(Clone, Copy)]
pub enum Build {
    Line(ProblemFn<1>),
    Plane(ProblemFn<2>),
    Points { dim: usize },
}

impl BenchmarkInfo {
    /// The spatial dimension; for benchmarks whose runs choose theirs, the largest.
    pub fn dim(&self) -> usize {
        match self.build {
            Build::Line(_) => 1,
            Build::Plane(_) => 2,
            Build::Points { dim } => dim,
        }
    }

    /// The problem of a simulation run from validated parameters.
    pub fn problem(&self, params: &Params) -> Result<AnyProblem, ParamError> {
        match self.build {
            Build::Line(build) => build(params).map(AnyProblem::D1),
            Build::Plane(build) => build(params).map(AnyProblem::D2),
            Build::Points { .. } => Err(ParamError::new(
                "benchmark",
                format!(
                    "{} is not a simulation: its runs build no problem",
                    self.name
                ),
            )),
        }
    }
}

/// How a simulation benchmark's runs step (`BenchmarkInfo::time_step`).
pub type TimeStepFn = fn(&Params) -> Result<TimeStep, ParamError>;

pub const CATALOG: Catalog<BenchmarkInfo> = Catalog {
    kind: "benchmark",
    entries: &[
        mms_gong::INFO_1D,
        mms_gong::INFO_2D,
        mms_tran::INFO,
        vibrating_bar::INFO,
        dyka_bar::INFO,
        andersen_block::INFO,
        scattered::INFO_NODES,
        scattered::INFO_BASIS,
        scattered::INFO_ELEMENTS,
        shape_functions::INFO,
    ],
};

/// What a run of a benchmark computes, and so which methods, measures and figures apply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchmarkKind {
    /// A `Problem` stepped in time by an MPM method; errors at the particles.
    Simulation,
    /// Sampled data reconstructed at grid nodes by a reconstruction method; no time stepping.
    Reconstruction,
    /// A reconstruction that also records the weighted orthogonal basis of its points.
    OrthogonalBasis,
    /// Sampled data reconstructed element by element (Taylor least squares); errors at
    /// Gauss points.
    Elementwise,
    /// A grid basis and its gradient evaluated at points, with its consistency errors; no
    /// data and no time stepping.
    ShapeFunctions,
}

impl BenchmarkKind {
    /// Whether a run reconstructs sampled data (nodal, orthogonal-basis or element-wise).
    pub fn is_reconstruction(self) -> bool {
        matches!(
            self,
            BenchmarkKind::Reconstruction
                | BenchmarkKind::OrthogonalBasis
                | BenchmarkKind::Elementwise
        )
    }

    /// Whether a run steps in time (only simulations do).
    pub fn steps(self) -> bool {
        self == BenchmarkKind::Simulation
    }
}

impl std::fmt::Display for BenchmarkKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BenchmarkKind::Simulation => "simulation",
            BenchmarkKind::Reconstruction => "nodal reconstruction",
            BenchmarkKind::OrthogonalBasis => "orthogonal-basis reconstruction",
            BenchmarkKind::Elementwise => "element-wise reconstruction",
            BenchmarkKind::ShapeFunctions => "shape-function evaluation",
        })
    }
}

/// The benchmarks whose `Problem::material_point` inverts the exact motion, so that their
/// runs also measure the grid velocity against the exact one: the manufactured solutions.
const EXACT_ON_GRID: [&str; 3] = [
    mms_gong::INFO_1D.name,
    mms_gong::INFO_2D.name,
    mms_tran::INFO.name,
];

/// Whether runs of the benchmark know the exact velocity at the grid's nodes.
pub fn exact_on_grid(info: &BenchmarkInfo) -> bool {
    EXACT_ON_GRID.contains(&info.name)
}

impl Named for BenchmarkInfo {
    fn name(&self) -> &'static str {
        self.name
    }
}

/// Exact state of the material point that started at `X`, in the current configuration.
pub struct ExactState<const D: usize> {
    pub displacement: SVector<f64, D>,
    pub velocity: SVector<f64, D>,
    /// Cauchy stress.
    pub stress: SMatrix<f64, D, D>,
    pub density: f64,
}

/// What a probe records at its particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProbeQuantity {
    Displacement(usize),
    Velocity(usize),
    Stress(usize, usize),
}

impl ProbeQuantity {
    /// The quantity's name in the run file (`/probes/<name>` attribute `quantity`).
    pub fn name(self) -> &'static str {
        match self {
            ProbeQuantity::Displacement(_) => "displacement",
            ProbeQuantity::Velocity(_) => "velocity",
            ProbeQuantity::Stress(..) => "stress",
        }
    }

    /// The component: one index for a vector, row and column for the stress.
    pub fn component(self) -> Vec<usize> {
        match self {
            ProbeQuantity::Displacement(k) | ProbeQuantity::Velocity(k) => vec![k],
            ProbeQuantity::Stress(i, j) => vec![i, j],
        }
    }

    /// The quantity's value in a state: displacement, velocity and Cauchy stress.
    pub fn of<const D: usize>(
        self,
        displacement: &SVector<f64, D>,
        velocity: &SVector<f64, D>,
        stress: &SMatrix<f64, D, D>,
    ) -> f64 {
        match self {
            ProbeQuantity::Displacement(k) => displacement[k],
            ProbeQuantity::Velocity(k) => velocity[k],
            ProbeQuantity::Stress(i, j) => stress[(i, j)],
        }
    }
}

/// A quantity recorded at one particle every step (Molinos et al. Figs 5-13): the particle whose
/// reference position is nearest `at` (ties: the lowest index).
#[derive(Clone, Debug, PartialEq)]
pub struct Probe<const D: usize> {
    pub name: &'static str,
    pub at: SVector<f64, D>,
    pub quantity: ProbeQuantity,
}

/// Squared distances closer than this (relative) are a tie: equidistant particles differ by
/// rounding only.
const TIE_TOLERANCE: f64 = 1e-9;

impl<const D: usize> Probe<D> {
    /// The index of the particle nearest `at` among the reference positions `x0`; `None` when
    /// there are none.
    pub fn nearest(&self, x0: &[SVector<f64, D>]) -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for (p, x) in x0.iter().enumerate() {
            let d = (x - self.at).norm_squared();
            // Nearer by more than rounding only, so a tie keeps the lower index.
            if best.is_none_or(|(_, b)| d < b * (1.0 - TIE_TOLERANCE)) {
                best = Some((p, d));
            }
        }
        best.map(|(p, _)| p)
    }
}

/// The `cfl` parameter of an explicit benchmark, refused above 1.
fn courant_number(params: &Params) -> Result<f64, ParamError> {
    let cfl = crate::params::get_f64(params, "cfl")?;
    if cfl > 1.0 {
        return Err(ParamError::new(
            "cfl",
            format!("cfl = {cfl} > 1 makes the explicit scheme unstable; use cfl <= 1"),
        ));
    }
    Ok(cfl)
}

/// Which velocity components are held at zero on the faces of the domain box
/// (`[axis][0]` the lower face, `[axis][1]` the upper face, the component normal to it).
pub type FixedFaces<const D: usize> = [[bool; 2]; D];

/// A problem in `D` dimensions as the solver sees it.
pub trait Problem<const D: usize>: Send + Sync {
    fn domain(&self) -> Domain<D>;
    /// Body (material region) as a box inside the domain, filled with `ppc^D` points per cell.
    fn body(&self) -> (SVector<f64, D>, SVector<f64, D>);
    fn ppc(&self) -> usize;
    fn rho0(&self) -> f64;
    fn material(&self) -> Material;
    fn dt(&self) -> f64;
    fn steps(&self) -> usize;
    fn fixed_faces(&self) -> FixedFaces<D>;
    fn initial_velocity(&self, x0: &SVector<f64, D>) -> SVector<f64, D>;
    /// Body force per unit mass at every particle at time `t`, written into `out`.
    /// Called once per step, so implementations precompute what does not depend on time.
    fn body_force(&mut self, t: f64, out: &mut [SVector<f64, D>]);
    /// Prepare `body_force` for these reference positions (called once before stepping).
    fn attach_particles(&mut self, x0: &[SVector<f64, D>]);
    fn exact(&self, x0: &SVector<f64, D>, t: f64) -> Option<ExactState<D>>;
    /// The reference position X of the material point at `x` at time `t`: the inverse of the
    /// exact motion, through which the exact velocity is known at a grid node. `None` where
    /// the benchmark does not invert its motion (only the manufactured solutions do, as
    /// `exact_on_grid` lists) or `x` is outside the body.
    fn material_point(&self, _x: &SVector<f64, D>, _t: f64) -> Option<SVector<f64, D>> {
        None
    }
    /// Where the particles are seeded inside each cell.
    fn placement(&self) -> Placement {
        Placement::SubCellCentres
    }
    /// The particles of the body at rest in their initial state, on `grid`.
    fn seed_particles(&self, grid: &Grid<D>) -> Particles<D> {
        let (lower, upper) = self.body();
        let body = Body {
            lower,
            upper,
            ppc: self.ppc(),
            placement: self.placement(),
            rho0: self.rho0(),
        };
        Particles::seed(&body, grid, |x| self.initial_velocity(x))
    }
    fn probes(&self) -> Vec<Probe<D>> {
        Vec::new()
    }
    /// The solution a probe is drawn against: the exact one where there is one; a benchmark without one
    /// may give another reference (the quasi-static solution of the Andersen block).
    fn probe_reference(&self, x0: &SVector<f64, D>, t: f64) -> Option<ExactState<D>> {
        self.exact(x0, t)
    }
}

/// A problem of either supported dimension.
pub enum AnyProblem {
    D1(Box<dyn Problem<1>>),
    D2(Box<dyn Problem<2>>),
}

/// Boxes a benchmark's problem for `Build`.
fn boxed<P: Problem<D> + 'static, const D: usize>(
    problem: Result<P, ParamError>,
) -> Result<Box<dyn Problem<D>>, ParamError> {
    Ok(Box::new(problem?))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A benchmark's catalogue defaults with its required parameters filled in.
    fn runnable_params(info: &BenchmarkInfo) -> Params {
        let mut params = default_params(info.params);
        for spec in info.params {
            if spec.default == ParamDefault::Required {
                let value = match spec.kind {
                    ParamKind::PositiveInt => ParamValue::Int(4),
                    _ => ParamValue::Float(0.01),
                };
                params.insert(spec.key.to_string(), value);
            }
        }
        params
    }

    /// A simulation builds a problem and every other kind builds none, so a benchmark's kind
    /// and its constructor cannot disagree.
    #[test]
    fn simulations_and_only_simulations_build_a_problem() {
        for info in CATALOG.entries {
            let builds = matches!(info.build, Build::Line(_) | Build::Plane(_));
            assert_eq!(builds, info.kind.steps(), "{}", info.name);
            if builds {
                let problem = info.problem(&runnable_params(info));
                assert!(problem.is_ok(), "{}", info.name);
            } else {
                assert!(info.problem(&Params::new()).is_err(), "{}", info.name);
            }
        }
        let dims: Vec<usize> = CATALOG.entries.iter().map(BenchmarkInfo::dim).collect();
        assert_eq!(dims, [1, 2, 1, 1, 1, 2, 1, 1, 2, 2]);
    }

    /// `exact_on_grid` lists exactly the simulation benchmarks whose problem inverts its
    /// motion at a point of the body (its lower corner and a point inside).
    #[test]
    fn exact_on_grid_lists_the_problems_that_invert_their_motion() {
        let mut listed = 0;
        for info in CATALOG
            .entries
            .iter()
            .filter(|i| i.kind == BenchmarkKind::Simulation)
        {
            let params = runnable_params(info);
            let problem = info
                .problem(&params)
                .unwrap_or_else(|e| panic!("{}: {e}", info.name));
            let inverts = match problem {
                AnyProblem::D1(p) => {
                    let (lo, hi) = p.body();
                    p.material_point(&lo, 1e-3).is_some()
                        && p.material_point(&(0.3 * lo + 0.7 * hi), 1e-3).is_some()
                }
                AnyProblem::D2(p) => {
                    let (lo, hi) = p.body();
                    p.material_point(&lo, 1e-3).is_some()
                        && p.material_point(&(0.3 * lo + 0.7 * hi), 1e-3).is_some()
                }
            };
            assert_eq!(inverts, exact_on_grid(info), "{}", info.name);
            listed += usize::from(inverts);
        }
        assert_eq!(listed, EXACT_ON_GRID.len());
    }
}
