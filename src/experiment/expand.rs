//! Matrix expansion: the cartesian product of each block's axes (last axis fastest), blocks in
//! file order, each run resolved against the benchmark's defaults, checked by the benchmark
//! and given its id.

use std::collections::HashMap;

use crate::benchmarks::{self, PLACEMENT_KEY};
use crate::methods;
use crate::params::{ParamError, ParamValue, Params};
use crate::reference;

use super::document::Benchmark;
use super::error::{ConfigError, Pos};
use super::resolved::{ResolvedRun, RunMethod};
use super::run_id::{config_body, config_yaml, run_id};
use super::space::{Block, ParamSpace, Written};
use super::values::{method_names, METHOD_KEY};
use super::yaml::child_field;
use crate::run_spec::RunSpec;

/// The placement at the Gauss points, which the particle-domain methods cannot take.
const GAUSS_PLACEMENT: &str = "gauss";

/// More runs than this is taken to be a mistake in the matrix, not a plan.
pub const MAX_RUNS: usize = 100_000;

/// Most history samples a run may store (t = 0, every `output.every`-th step and the final
/// time): a thousand times the most a committed study stores (104).
pub const MAX_SAMPLES: usize = 100_000;

/// How the runs' histories are sampled: `output.every` and where it is written.
pub(crate) struct Sampling {
    pub every: usize,
    pub pos: Pos,
}

pub(crate) fn expand(
    experiment: &str,
    benchmark: &Benchmark,
    space: &ParamSpace,
    sampling: &Sampling,
) -> Result<Vec<ResolvedRun>, ConfigError> {
    run_count(space)?;
    let defaults = benchmarks::default_params(benchmark.info.params);
    let mut runs: Vec<ResolvedRun> = Vec::new();
    // Run id -> its block, to refuse a run that two blocks both make.
    let mut made_by: HashMap<String, usize> = HashMap::new();
    for (b, block) in space.blocks.iter().enumerate() {
        for index in 0..block_size(block) {
            let chosen = choose(space, block, index);
            let run = resolve(experiment, benchmark, &defaults, &chosen, sampling)?;
            if let Some(earlier) = made_by.insert(run.spec.run_id.clone(), b) {
                return Err(ConfigError::at(
                    block.pos,
                    "matrix",
                    format!(
                        "block {} makes the run {} again (block {} made it first)",
                        b + 1,
                        run.spec.run_id,
                        earlier + 1
                    ),
                ));
            }
            runs.push(run);
        }
    }
    Ok(runs)
}

/// Runs of one block, saturating: `run_count` rejects the sums that overflow.
fn block_size(block: &Block) -> usize {
    block
        .axes
        .iter()
        .try_fold(1usize, |n, axis| n.checked_mul(axis.values.len()))
        .unwrap_or(usize::MAX)
}

fn run_count(space: &ParamSpace) -> Result<usize, ConfigError> {
    space
        .blocks
        .iter()
        .try_fold(0usize, |n, block| n.checked_add(block_size(block)))
        .filter(|&n| n <= MAX_RUNS)
        .ok_or_else(|| {
            let sizes: Vec<String> = space
                .blocks
                .iter()
                .map(|block| {
                    let axes: Vec<String> = block
                        .axes
                        .iter()
                        .map(|a| a.values.len().to_string())
                        .collect();
                    axes.join(" x ")
                })
                .collect();
            ConfigError::at(
                space.matrix_pos,
                "matrix",
                format!(
                    "the matrix ({} values per axis) expands to more than {MAX_RUNS} runs",
                    sizes.join(" + ")
                ),
            )
        })
}

/// A value a run takes from the file.
struct Chosen<'a> {
    key: &'a str,
    written: &'a Written,
    /// From a matrix axis rather than from params.
    is_axis: bool,
}

/// The values of run number `index` of `block`: the fixed ones, then one per axis in order.
fn choose<'a>(space: &'a ParamSpace, block: &'a Block, index: usize) -> Vec<Chosen<'a>> {
    let mut from_axes = Vec::with_capacity(block.axes.len());
    let mut rest = index;
    for axis in block.axes.iter().rev() {
        from_axes.push(Chosen {
            key: &axis.key,
            written: &axis.values[rest % axis.values.len()],
            is_axis: true,
        });
        rest /= axis.values.len();
    }
    from_axes.reverse();
    let fixed = space.fixed.iter().map(|(key, written)| Chosen {
        key,
        written,
        is_axis: false,
    });
    fixed.chain(from_axes).collect()
}

/// Builds one run from its chosen values and the defaults.
fn resolve(
    experiment: &str,
    benchmark: &Benchmark,
    defaults: &Params,
    chosen: &[Chosen],
    sampling: &Sampling,
) -> Result<ResolvedRun, ConfigError> {
    let mut params = defaults.clone();
    // Without a preset, the method is the one the run's parts compose (`require_given`
    // checked that a simulation without one names them all).
    let mut method = methods::COMPOSED.to_string();
    let mut axes = Params::new();
    let mut id_axes = Vec::new();
    for c in chosen {
        let value = &c.written.value;
        if c.key == METHOD_KEY {
            method = value.to_string();
        } else {
            params.insert(c.key.to_string(), value.clone());
            if c.is_axis {
                id_axes.push((c.key, value));
            }
        }
        if c.is_axis {
            axes.insert(c.key.to_string(), value.clone());
        }
    }
    if let Some(reason) = reference::unsupported(&method, benchmark.info.name) {
        let error = ParamError::new(METHOD_KEY, reason);
        let valid = method_names(benchmark.info.kind)
            .into_iter()
            .filter(|m| reference::unsupported(m, benchmark.info.name).is_none());
        return Err(check_error(error, benchmark, &params, chosen).with_valid(valid));
    }
    (benchmark.info.check)(&params).map_err(|e| check_error(e, benchmark, &params, chosen))?;
    if benchmark.info.kind.steps() {
        refuse_reference_params(&method, &params)
            .map_err(|e| check_error(e, benchmark, &params, chosen))?;
    }
    let run_method = RunMethod::resolve(&method, benchmark.info, &params)
        .map_err(|e| check_error(e, benchmark, &params, chosen))?;
    if let Some(error) = placement_conflict(&method, &run_method, &params) {
        return Err(check_error(error, benchmark, &params, chosen));
    }
    let mut steps = None;
    if let Some(time_step) = benchmark.info.time_step {
        let step = time_step(&params).map_err(|e| check_error(e, benchmark, &params, chosen))?;
        check_samples(step.steps, sampling, chosen)?;
        steps = Some(step.steps);
    }
    let output_every = sampling.every;
    let body = config_body(benchmark.info.name, &method, output_every, &params);
    let spec = RunSpec {
        experiment: experiment.to_string(),
        run_id: run_id(&method, &id_axes, &body),
        benchmark: benchmark.info.name.to_string(),
        method,
        params,
        axes,
        output_every,
        config_yaml: config_yaml(experiment, &body),
    };
    Ok(ResolvedRun::new(spec, benchmark.info, run_method, steps))
}

/// Reference solvers take none of the method parameters (`gamma`, `integrator`, ...), which
/// `methods::resolve` checks for the MPM methods.
fn refuse_reference_params(method: &str, params: &Params) -> Result<(), ParamError> {
    match methods::METHOD_PARAMS
        .iter()
        .find(|spec| params.contains_key(spec.key))
    {
        Some(spec) if reference::METHODS.find(method).is_some() => Err(ParamError::new(
            spec.key,
            format!(
                "{} applies to MPM methods, not to the reference solver {method}",
                spec.key
            ),
        )),
        _ => Ok(()),
    }
}

/// The particle-domain methods (GIMP, CPDI) take the sub-cells of the seed lattice as the
/// particles' domains, which only sub-cell centres sit in the middle of.
fn placement_conflict(method: &str, resolved: &RunMethod, params: &Params) -> Option<ParamError> {
    let gauss = params.get(PLACEMENT_KEY) == Some(&ParamValue::Str(GAUSS_PLACEMENT.into()));
    let domains = matches!(resolved, RunMethod::Mpm(m) if m.shape.reads_seed_domains());
    (gauss && domains).then(|| {
        ParamError::new(
            PLACEMENT_KEY,
            format!(
                "{method} takes the seed lattice's sub-cells as particle domains, which the \
                 Gauss points do not sit at the centres of; use placement: centres"
            ),
        )
    })
}

/// The history samples of a run of `steps` steps: t = 0, every `every`-th step and the final
/// time (every = 0: the first and last states only).
pub fn sample_count(steps: usize, every: usize) -> usize {
    if steps == 0 {
        return 1;
    }
    let between = match every {
        0 => 0,
        every => steps / every - usize::from(steps.is_multiple_of(every)),
    };
    2 + between
}

/// A run samples its history at t = 0, every `every`-th step and the final time (every = 0:
/// the first and last states only); at most `MAX_SAMPLES` times.
fn check_samples(steps: usize, sampling: &Sampling, chosen: &[Chosen]) -> Result<(), ConfigError> {
    let every = sampling.every;
    let samples = sample_count(steps, every);
    if every == 0 || samples <= MAX_SAMPLES {
        return Ok(());
    }
    Err(ConfigError::at(
        sampling.pos,
        "output.every",
        format!(
            "every = {every} stores {samples} samples of the {steps} steps of a run (t = 0, \
             every {every} steps and t_end); at most {MAX_SAMPLES} are stored: use every >= \
             {}{}",
            steps.div_ceil(MAX_SAMPLES - 2),
            in_run(chosen)
        ),
    ))
}

/// " (in the run with k=v, ...)" over the axis values of a run; nothing without axes.
fn in_run(chosen: &[Chosen]) -> String {
    let run: Vec<String> = chosen
        .iter()
        .filter(|c| c.is_axis)
        .map(|c| format!("{}={}", c.key, c.written.value))
        .collect();
    if run.is_empty() {
        String::new()
    } else {
        format!(" (in the run with {})", run.join(", "))
    }
}

/// Places a failed benchmark check at the value it names: the matrix element or params entry
/// it came from, or the benchmark key for a default; and says which run it was.
fn check_error(
    error: ParamError,
    benchmark: &Benchmark,
    params: &Params,
    chosen: &[Chosen],
) -> ConfigError {
    let in_run = in_run(chosen);
    match chosen.iter().find(|c| c.key == error.key) {
        Some(Chosen { written, .. }) => ConfigError::at(
            written.pos,
            written.field.as_str(),
            format!("{}{in_run}", error.message),
        ),
        None => {
            let default = params
                .get(&error.key)
                .map_or_else(String::new, |v| format!(" = {v}"));
            ConfigError::at(
                benchmark.pos,
                child_field("params", &error.key),
                format!(
                    "the default {}{default} of {}: {}{in_run}",
                    error.key, benchmark.info.name, error.message
                ),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::{
        BenchmarkInfo, BenchmarkKind, Build, ParamDefault, ParamKind, ParamSpec,
    };
    use crate::experiment::space::{Axis, Block};
    use crate::experiment::values::ValueKind;
    use crate::params::ParamValue;

    /// The samples the step loop takes (s = 0, s = steps, and s % every == 0), counted.
    #[test]
    fn sample_count_counts_what_the_step_loop_samples() {
        for steps in 0..40 {
            for every in 0..12 {
                let taken = (0..=steps)
                    .filter(|&s| s == 0 || s == steps || (every > 0 && s % every == 0))
                    .count();
                assert_eq!(sample_count(steps, every), taken, "{steps} {every}");
            }
        }
    }

    /// A benchmark whose check rejects its own default, which no real benchmark does.
    const TOY: BenchmarkInfo = BenchmarkInfo {
        name: "toy",
        kind: BenchmarkKind::Simulation,
        build: Build::Line(|_| Err(ParamError::new("x", "the toy has no problem"))),
        source: "",
        description: "",
        params: &[
            ParamSpec {
                key: "k",
                kind: ParamKind::PositiveInt,
                default: ParamDefault::Int(3),
                unit: "1",
                doc: "",
            },
            ParamSpec {
                key: "x",
                kind: ParamKind::Real,
                default: ParamDefault::Required,
                unit: "1",
                doc: "",
            },
        ],
        check: reject_three,
        time_step: None,
    };

    fn reject_three(params: &Params) -> Result<(), ParamError> {
        match params.get("k") {
            Some(ParamValue::Int(3)) => Err(ParamError::new("k", "3 is not allowed")),
            _ => Ok(()),
        }
    }

    fn written(value: ParamValue, line: usize, field: &str) -> Written {
        Written {
            value,
            pos: Pos { line, column: 5 },
            field: field.to_string(),
        }
    }

    fn sampling(every: usize) -> Sampling {
        Sampling {
            every,
            pos: Pos::START,
        }
    }

    fn toy_space() -> ParamSpace {
        let xs = [1.0, 2.0].map(ParamValue::Float);
        ParamSpace {
            fixed: vec![(
                METHOD_KEY.to_string(),
                written(ParamValue::Str("mpm".into()), 3, "params.method"),
            )],
            blocks: vec![Block {
                axes: vec![Axis {
                    key: "x".into(),
                    kind: ValueKind::Param(ParamKind::Real),
                    values: xs
                        .into_iter()
                        .enumerate()
                        .map(|(i, v)| written(v, 5, &format!("matrix.x[{i}]")))
                        .collect(),
                }],
                pos: Pos { line: 5, column: 3 },
            }],
            matrix_pos: Pos { line: 4, column: 1 },
        }
    }

    #[test]
    fn a_rejected_default_points_at_the_benchmark() {
        let benchmark = Benchmark {
            info: &TOY,
            pos: Pos {
                line: 2,
                column: 12,
            },
        };
        let e = expand("toy_exp", &benchmark, &toy_space(), &sampling(0)).unwrap_err();
        assert_eq!((e.line, e.column, e.field.as_str()), (2, 12, "params.k"));
        assert!(e.message.contains("the default k = 3 of toy"), "{e}");
        assert!(e.message.ends_with("(in the run with x=1.0)"), "{e}");
    }

    #[test]
    fn runs_take_defaults_and_axis_values() {
        let benchmark = Benchmark {
            info: &TOY,
            pos: Pos::START,
        };
        let mut space = toy_space();
        space
            .fixed
            .push(("k".into(), written(ParamValue::Int(4), 3, "params.k")));
        let runs = expand("toy_exp", &benchmark, &space, &sampling(7)).unwrap();
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[1].spec.params["x"], ParamValue::Float(2.0));
        assert_eq!(runs[1].spec.params["k"], ParamValue::Int(4));
        assert_eq!(runs[1].spec.output_every, 7);
        assert!(
            runs[1].spec.run_id.starts_with("mpm-x2.0-"),
            "{}",
            runs[1].spec.run_id
        );
    }
}
