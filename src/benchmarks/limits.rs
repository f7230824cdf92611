//! Bounds on the work and memory a run asks for, checked by the benchmarks where their
//! parameters are read: the number of time steps (overridable with `max_steps`), and the
//! number of particles, data or evaluation points and grid nodes.

use super::{ParamDefault, ParamKind, ParamSpec};
use crate::params::{get_f64, get_usize, ParamError, ParamValue, Params};

/// The key that raises the bound on a run's time steps.
pub const MAX_STEPS_KEY: &str = "max_steps";

/// Time steps a run may take without `max_steps`: 350 times the longest committed study
/// (28,868), and about a day of work for a 1D run of a thousand particles.
pub const MAX_STEPS: usize = 10_000_000;

/// Most particles (or data points, or evaluation points) and grid nodes a run may have. The
/// solver numbers both with 32-bit indices (up to 4.3e9), and past 1e8 a run's particle
/// state alone takes tens of GB: a slip in the file, not a plan.
pub const MAX_POINTS: usize = 100_000_000;

/// Parameters of any simulation that bound its work rather than describe it. Like the method
/// parameters they enter a run only when written, so the runs that do not set them keep
/// their ids.
pub const LIMIT_PARAMS: &[ParamSpec] = &[ParamSpec {
    key: MAX_STEPS_KEY,
    kind: ParamKind::PositiveInt,
    default: ParamDefault::Int(MAX_STEPS as i64),
    unit: "1",
    doc: "most time steps t_end / dt a run may take; raise it for a longer run",
}];

/// The time step a run takes and the number of steps to t_end. A benchmark's check and its
/// problem both take it from one function of the parameters, so that a run steps with the dt
/// its check approved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeStep {
    pub dt: f64,
    pub steps: usize,
}

/// The number of steps of at most `dt_max` that reach `t_end`: the ratio is rounded first, so
/// that t_end/dt_max = 40.000000000000004 does not add a step (dt_max is then kept to 1e-9).
/// Not finite when dt_max is not a positive time.
fn step_count(dt_max: f64, t_end: f64) -> f64 {
    let ratio = t_end / dt_max;
    let nearest = ratio.round();
    let steps = if (ratio - nearest).abs() <= 1e-9 * nearest {
        nearest
    } else {
        ratio.ceil()
    };
    // max would turn NaN into 1.
    if steps.is_nan() {
        steps
    } else {
        steps.max(1.0)
    }
}

/// How a benchmark derives its largest stable step, for the messages of `fit`: the formula as
/// text, and the exponent of the step count in each parameter that sets it.
struct StepSource<'a> {
    formula: String,
    specs: &'a [ParamSpec],
    powers: &'a [(&'static str, f64)],
}

/// The largest step not above `dt_max` that divides t_end into whole steps. Refused when
/// dt_max is not a positive finite time or the steps are more than `max_steps`; the error is
/// placed at the parameter that raises the step count most above its default.
fn fit(params: &Params, dt_max: f64, source: &StepSource) -> Result<TimeStep, ParamError> {
    let t_end = get_f64(params, "t_end")?;
    let limit = match params.get(MAX_STEPS_KEY) {
        Some(_) => get_usize(params, MAX_STEPS_KEY)?,
        None => MAX_STEPS,
    };
    let steps = step_count(dt_max, t_end);
    let culprit = || culprit(params, source.specs, source.powers);
    if !steps.is_finite() {
        return Err(ParamError::new(
            culprit(),
            format!(
                "{} = {dt_max:?} s is no time step; it must be a positive finite time",
                source.formula
            ),
        ));
    }
    if steps > limit as f64 {
        return Err(ParamError::new(
            culprit(),
            format!(
                "t_end = {t_end:?} s in steps of {} = {dt_max:.4e} s takes {steps:.4e} steps, \
                 more than {MAX_STEPS_KEY} = {limit}; shorten t_end or lengthen the step, or \
                 raise {MAX_STEPS_KEY} to run it",
                source.formula
            ),
        ));
    }
    // 1 <= steps <= limit, so the cast is exact and dt is positive and finite.
    let steps = steps as usize;
    Ok(TimeStep {
        dt: t_end / steps as f64,
        steps,
    })
}

/// The parameter among `powers` (and `max_steps`) whose value raises the step count most
/// above its default, the first listed on a tie: the likeliest slip when there are too many
/// steps. A parameter without a default counts as at its default.
fn culprit(params: &Params, specs: &[ParamSpec], powers: &[(&'static str, f64)]) -> &'static str {
    let growth = |&(key, power): &(&'static str, f64)| {
        let default = specs
            .iter()
            .chain(LIMIT_PARAMS)
            .find(|s| s.key == key)
            .and_then(|s| match s.default {
                ParamDefault::Int(i) => Some(i as f64),
                ParamDefault::Float(x) => Some(x),
                ParamDefault::Required | ParamDefault::Text(_) | ParamDefault::Implicit(_) => None,
            });
        match (params.get(key).and_then(ParamValue::as_f64), default) {
            (Some(value), Some(default)) => (value / default).powf(power),
            _ => 1.0,
        }
    };
    let max_steps = [(MAX_STEPS_KEY, -1.0)];
    // `max_by` keeps the last of equal elements; reversed, that is the first listed.
    powers
        .iter()
        .chain(&max_steps)
        .rev()
        .max_by(|a, b| growth(a).total_cmp(&growth(b)))
        .map_or(MAX_STEPS_KEY, |&(key, _)| key)
}

/// The step of a benchmark that is given `dt`, fitted to t_end.
pub(crate) fn given_time_step(
    params: &Params,
    specs: &[ParamSpec],
) -> Result<TimeStep, ParamError> {
    let source = StepSource {
        formula: "dt".into(),
        specs,
        powers: &[("t_end", 1.0), ("dt", -1.0)],
    };
    fit(params, get_f64(params, "dt")?, &source)
}

/// The step of a benchmark that is given a Courant number: dt = cfl h / c with
/// h = length / cells and c = sqrt(E / rho0), fitted to t_end.
pub(crate) fn courant_time_step(
    params: &Params,
    specs: &[ParamSpec],
    length: f64,
) -> Result<TimeStep, ParamError> {
    let c = (get_f64(params, "E")? / get_f64(params, "rho0")?).sqrt();
    let h = length / get_usize(params, "cells")? as f64;
    let source = StepSource {
        formula: format!("cfl h / c (h = {h:?} m, c = sqrt(E/rho0) = {c:.4e} m/s)"),
        specs,
        powers: &[
            ("t_end", 1.0),
            ("cfl", -1.0),
            ("rho0", -0.5),
            ("E", 0.5),
            ("cells", 1.0),
        ],
    };
    fit(params, get_f64(params, "cfl")? * h / c, &source)
}

/// `n^dim`; None past usize.
pub(crate) fn per_axis_total(n: usize, dim: usize) -> Option<usize> {
    u32::try_from(dim).ok().and_then(|d| n.checked_pow(d))
}

/// `^dim` for a power written after a count per axis; nothing in 1D.
pub(crate) fn power(dim: usize) -> String {
    if dim == 1 {
        String::new()
    } else {
        format!("^{dim}")
    }
}

/// The key of the largest of `factors`, the first on a tie: where an error about their product
/// is placed.
pub(crate) fn largest(factors: &[(&'static str, usize)]) -> &'static str {
    factors
        .iter()
        .rev()
        .max_by_key(|(_, n)| *n)
        .map_or("cells", |(key, _)| key)
}

/// Refuses `count` of `what` (None: more than usize holds) above `MAX_POINTS`, placed at
/// `key`; `counted` says how the count arises.
pub(crate) fn check_count(
    count: Option<usize>,
    what: &str,
    counted: &str,
    key: &str,
) -> Result<(), ParamError> {
    match count {
        Some(n) if n <= MAX_POINTS => Ok(()),
        _ => {
            let count =
                count.map_or_else(|| format!("more than {}", usize::MAX), |n| n.to_string());
            Err(ParamError::new(
                key,
                format!("{counted} makes {count} {what}; at most {MAX_POINTS} are supported"),
            ))
        }
    }
}

/// The points of a lattice in `dim` dimensions (`cells ppc` per axis: particles, or data
/// points) and the grid's nodes (`cells + extra_cells + 1` per axis) are at most
/// `MAX_POINTS` each; an error is placed at the larger factor.
pub(crate) fn check_lattice(params: &Params, dim: usize, points: &str) -> Result<(), ParamError> {
    let cells = get_usize(params, "cells")?;
    let ppc = get_usize(params, "ppc")?;
    let extra = match params.get("extra_cells") {
        Some(_) => get_usize(params, "extra_cells")?,
        None => 0,
    };
    let p = power(dim);
    check_count(
        cells.checked_mul(ppc).and_then(|n| per_axis_total(n, dim)),
        points,
        &format!("(cells ppc){p} with cells = {cells} and ppc = {ppc}"),
        largest(&[("cells", cells), ("ppc", ppc)]),
    )?;
    check_count(
        cells
            .checked_add(extra)
            .and_then(|n| n.checked_add(1))
            .and_then(|n| per_axis_total(n, dim)),
        "grid nodes",
        &format!("(cells + extra_cells + 1){p} with cells = {cells} and extra_cells = {extra}"),
        largest(&[("cells", cells), ("extra_cells", extra)]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPECS: &[ParamSpec] = &[
        ParamSpec {
            key: "dt",
            kind: ParamKind::PositiveReal,
            default: ParamDefault::Float(1e-5),
            unit: "s",
            doc: "",
        },
        ParamSpec {
            key: "t_end",
            kind: ParamKind::PositiveReal,
            default: ParamDefault::Float(0.02),
            unit: "s",
            doc: "",
        },
    ];

    fn params(pairs: &[(&str, ParamValue)]) -> Params {
        pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect()
    }

    fn given(dt: f64, t_end: f64) -> Result<TimeStep, ParamError> {
        let p = params(&[
            ("dt", ParamValue::Float(dt)),
            ("t_end", ParamValue::Float(t_end)),
        ]);
        given_time_step(&p, SPECS)
    }

    #[test]
    fn time_step_is_kept_when_it_divides_t_end() {
        assert_eq!(given(1e-5, 0.02).unwrap().steps, 2000);
        assert_eq!(
            given(5e-4, 0.02).unwrap(),
            TimeStep {
                dt: 5e-4,
                steps: 40
            }
        );
    }

    #[test]
    fn time_step_is_shortened_to_hit_t_end() {
        let step = given(3e-3, 0.02).unwrap();
        assert_eq!(step.steps, 7);
        assert!((step.dt * 7.0 - 0.02).abs() < 1e-18);
        // A step longer than t_end is one step of t_end.
        assert_eq!(given(1.0, 0.02).unwrap(), TimeStep { dt: 0.02, steps: 1 });
    }

    #[test]
    fn too_many_steps_are_refused_at_the_parameter_that_makes_them() {
        let e = given(1e-300, 0.02).unwrap_err();
        assert_eq!(e.key, "dt");
        assert!(e.message.contains("2.0000e298 steps"), "{e}");
        assert!(e.message.contains("max_steps = 10000000"), "{e}");
        let e = given(1e-5, 1e300).unwrap_err();
        assert_eq!(e.key, "t_end");
        // At the bound exactly: accepted; one step more: refused.
        assert_eq!(given(1e-5, 100.0).unwrap().steps, MAX_STEPS);
        assert!(given(1e-5, 100.00001).is_err());
    }

    #[test]
    fn max_steps_moves_the_bound() {
        let mut p = params(&[
            ("dt", ParamValue::Float(1e-5)),
            ("t_end", ParamValue::Float(0.02)),
            (MAX_STEPS_KEY, ParamValue::Int(1000)),
        ]);
        let e = given_time_step(&p, SPECS).unwrap_err();
        assert_eq!(e.key, MAX_STEPS_KEY);
        assert!(e.message.contains("max_steps = 1000;"), "{e}");
        p.insert(MAX_STEPS_KEY.into(), ParamValue::Int(2000));
        assert_eq!(given_time_step(&p, SPECS).unwrap().steps, 2000);
    }

    #[test]
    fn a_step_that_is_no_time_is_refused() {
        // E / rho0 overflows: c is infinite and dt = cfl h / c is zero.
        let p = params(&[
            ("E", ParamValue::Float(1e308)),
            ("rho0", ParamValue::Float(1e-300)),
            ("cfl", ParamValue::Float(0.4)),
            ("cells", ParamValue::Int(8)),
            ("t_end", ParamValue::Float(0.02)),
        ]);
        let e = courant_time_step(&p, &[], 1.0).unwrap_err();
        assert!(e.message.contains("is no time step"), "{e}");
    }

    #[test]
    fn lattices_are_bounded_at_their_larger_factor() {
        let lattice = |cells: i64, ppc: i64, extra: i64| {
            params(&[
                ("cells", ParamValue::Int(cells)),
                ("ppc", ParamValue::Int(ppc)),
                ("extra_cells", ParamValue::Int(extra)),
            ])
        };
        assert!(check_lattice(&lattice(5000, 2, 1), 2, "particles").is_ok());
        let e = check_lattice(&lattice(10_000, 2, 1), 2, "particles").unwrap_err();
        assert_eq!(e.key, "cells");
        assert!(
            e.message
                .contains("makes 400000000 particles; at most 100000000"),
            "{e}"
        );
        let e = check_lattice(&lattice(8, i64::MAX, 1), 2, "particles").unwrap_err();
        assert_eq!(e.key, "ppc");
        assert!(e.message.contains("makes more than"), "{e}");
        let e = check_lattice(&lattice(8, 1, 100_000_000), 1, "particles").unwrap_err();
        assert_eq!(e.key, "extra_cells");
        assert!(e.message.contains("grid nodes"), "{e}");
    }
}
