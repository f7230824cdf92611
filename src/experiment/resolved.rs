//! A run as expansion resolves it: its `RunSpec` beside the catalogue entries its names stand
//! for and the sizes its parameters set, typed once, so that no later stage looks a name up or
//! reads a parameter back by its key.

use std::fmt;

use crate::benchmarks::{self, BenchmarkInfo, BenchmarkKind};
use crate::methods::{self, Method};
use crate::params::{get_f64, get_usize, ParamError, Params};
use crate::reconstruction_methods::{self, ReconstructionMethod};
use crate::reference::{self, ReferenceMethod};
use crate::run_spec::RunSpec;
use crate::shape_methods::{self, ShapeMethod};

use super::values::METHOD_KEY;

/// One run of an experiment, resolved: what the runner schedules and the solver computes.
#[derive(Clone)]
pub struct ResolvedRun {
    pub spec: RunSpec,
    pub benchmark: &'static BenchmarkInfo,
    pub method: RunMethod,
    /// Cells and points per cell along each axis; 0 where the benchmark has no such parameter.
    pub cells: usize,
    pub ppc: usize,
    /// The final time; NaN for a benchmark that does not step.
    pub t_end: f64,
    /// The time steps to `t_end`, as the benchmark's time step sets them; `None` for a
    /// benchmark that does not step.
    pub steps: Option<usize>,
}

/// What computes a run, by the kind of its benchmark.
#[derive(Clone, Copy)]
pub enum RunMethod {
    /// An MPM method, its parts and settings resolved for the run's parameters and dimension.
    Mpm(Method),
    /// A reference solver of a simulation benchmark.
    Reference(&'static ReferenceMethod),
    /// The fit of a reconstruction benchmark.
    Reconstruction(&'static ReconstructionMethod),
    /// The grid basis of the shape-function benchmark.
    Basis(&'static ShapeMethod),
}

impl ResolvedRun {
    /// `spec` with what its names stand for, the sizes read from its parameters; `steps` is
    /// what its benchmark's time step gave.
    pub(super) fn new(
        spec: RunSpec,
        benchmark: &'static BenchmarkInfo,
        method: RunMethod,
        steps: Option<usize>,
    ) -> Self {
        let int = |key: &str| get_usize(&spec.params, key).unwrap_or(0);
        ResolvedRun {
            cells: int("cells"),
            ppc: int("ppc"),
            t_end: get_f64(&spec.params, "t_end").unwrap_or(f64::NAN),
            steps,
            method,
            benchmark,
            spec,
        }
    }

    /// Resolves a `RunSpec` written by hand rather than expanded from a file: its benchmark
    /// looked up, its method resolved and its time step taken, each failure named by its
    /// parameter. The benchmark's own checks are not run.
    pub fn resolve(spec: RunSpec) -> Result<Self, ParamError> {
        let benchmark = benchmarks::CATALOG
            .get(&spec.benchmark)
            .map_err(|e| ParamError::new("benchmark", e))?;
        let method = RunMethod::resolve(&spec.method, benchmark, &spec.params)?;
        let steps = match benchmark.time_step {
            Some(time_step) => Some(time_step(&spec.params)?.steps),
            None => None,
        };
        Ok(Self::new(spec, benchmark, method, steps))
    }

    pub fn dim(&self) -> usize {
        self.benchmark.dim()
    }
}

impl RunMethod {
    /// The method `name` of a run of `benchmark` with `params`, looked up in the catalogue of
    /// the benchmark's kind: a reference solver only for a benchmark it solves, an MPM preset
    /// resolved with the run's method parameters.
    pub(super) fn resolve(
        name: &str,
        benchmark: &BenchmarkInfo,
        params: &Params,
    ) -> Result<Self, ParamError> {
        let unknown = |e: String| ParamError::new(METHOD_KEY, e);
        Ok(match benchmark.kind {
            BenchmarkKind::Simulation => match reference::METHODS.find(name) {
                Some(solver) => match reference::unsupported(name, benchmark.name) {
                    Some(reason) => return Err(ParamError::new(METHOD_KEY, reason)),
                    None => RunMethod::Reference(solver),
                },
                None => {
                    let preset = methods::PRESETS.get(name).map_err(unknown)?;
                    RunMethod::Mpm(methods::resolve(preset, params, benchmark.dim())?)
                }
            },
            BenchmarkKind::ShapeFunctions => {
                RunMethod::Basis(shape_methods::METHODS.get(name).map_err(unknown)?)
            }
            BenchmarkKind::Reconstruction
            | BenchmarkKind::OrthogonalBasis
            | BenchmarkKind::Elementwise => RunMethod::Reconstruction(
                reconstruction_methods::METHODS.get(name).map_err(unknown)?,
            ),
        })
    }
}

impl fmt::Debug for ResolvedRun {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ResolvedRun")
            .field("spec", &self.spec)
            .field("benchmark", &self.benchmark.name)
            .field("method", &self.method)
            .finish_non_exhaustive()
    }
}

impl fmt::Debug for RunMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunMethod::Mpm(method) => f.debug_tuple("Mpm").field(method).finish(),
            RunMethod::Reference(m) => f.debug_tuple("Reference").field(&m.name).finish(),
            RunMethod::Reconstruction(m) => f.debug_tuple("Reconstruction").field(&m.name).finish(),
            RunMethod::Basis(m) => f.debug_tuple("Basis").field(&m.name).finish(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::thesis_params;
    use crate::params::Params;

    fn spec(benchmark: &str, method: &str) -> RunSpec {
        RunSpec {
            experiment: "t".into(),
            run_id: "t".into(),
            benchmark: benchmark.into(),
            method: method.into(),
            params: thesis_params(1e-4, 8, 2),
            axes: Params::new(),
            output_every: 0,
            config_yaml: String::new(),
        }
    }

    /// A hand-built spec gets its method, sizes and step count, or an error that names the
    /// parameter: an unknown benchmark, or a reference solver on a benchmark it does not solve.
    #[test]
    fn a_hand_built_spec_is_resolved_or_refused_by_name() {
        let run = ResolvedRun::resolve(spec("mms1d_gong", "mpm")).unwrap();
        assert!(matches!(run.method, RunMethod::Mpm(_)));
        assert_eq!(
            (run.cells, run.ppc, run.steps, run.dim()),
            (8, 2, Some(40), 1)
        );
        assert_eq!(run.t_end, 0.02);
        let refused =
            |benchmark, method| ResolvedRun::resolve(spec(benchmark, method)).unwrap_err();
        assert_eq!(refused("mms1d_gong", "ulfem").key, "method");
        assert_eq!(refused("no_such_benchmark", "mpm").key, "benchmark");
        assert_eq!(refused("mms1d_gong", "no_such_method").key, "method");
    }
}
