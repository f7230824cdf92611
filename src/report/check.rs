//! `report --check`: holds the fitted rates, final errors and measured stability limits
//! against the experiment's `expect` entries.

use std::fmt;

use super::claims::{self, Outcome, Verdict};
use super::format::{exact, general};
use super::group::{label, ordered_runs, selects};
use super::stability::{group_name, limits};
use super::RateRow;
use crate::experiment::{Expectation, Experiment, LimitBound};
use crate::output::{RunStatus, RunSummary};

/// One unmet expectation. `message` names the group, field, norm, value and bound; the
/// `Display` form prefixes the expectation's line.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckFailure {
    pub line: usize,
    pub message: String,
}

impl fmt::Display for CheckFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Evaluates every `expect` entry and every paper claim; an empty vector means all passed.
/// A claim fails when ours leaves its tolerance without a `differs` note, when the note says
/// it differs but ours is within, and when no run measures it.
///
/// Rate bounds apply to every fitted rate whose group matches the selector, and fail when
/// none does. `error_min` and `error_max` apply to every run whose axes match the selector
/// (the refinement axis included): each must have finished with a final error within them.
/// A limit bound applies to every group of the other axes along its swept axis.
pub fn check(experiment: &Experiment, rates: &[RateRow], runs: &[RunSummary]) -> Vec<CheckFailure> {
    experiment
        .expect
        .iter()
        .flat_map(|e| {
            let mut messages = check_rates(e, rates);
            messages.extend(check_errors(e, runs));
            messages.extend(check_limit(e, runs));
            messages.into_iter().map(|message| CheckFailure {
                line: e.line,
                message,
            })
        })
        .chain(claim_failures(&claims::evaluate(experiment, rates, runs)))
        .collect()
}

/// A one-line statement of what `e` requires, e.g. `method=mpm velocity l2: rate >= 1.8`.
pub fn describe(e: &Expectation) -> String {
    if let Some(LimitBound { sweep, min, max }) = &e.limit {
        let at = label(&e.select);
        let at = if at.is_empty() { at } else { format!("{at} ") };
        return format!(
            "{at}stability limit along {sweep}: last stable >= {}, first unstable <= {}",
            exact(*min),
            exact(*max)
        );
    }
    let bounds: Vec<String> = [
        e.rate_min.map(|v| format!("rate >= {}", exact(v))),
        e.rate_max.map(|v| format!("rate <= {}", exact(v))),
        e.error_min.map(|v| format!("error >= {}", exact(v))),
        e.error_max.map(|v| format!("error <= {}", exact(v))),
    ]
    .into_iter()
    .flatten()
    .collect();
    format!("{}: {}", subject(&label(&e.select), e), bounds.join(", "))
}

fn check_rates(e: &Expectation, rates: &[RateRow]) -> Vec<String> {
    if e.rate_min.is_none() && e.rate_max.is_none() {
        return Vec::new();
    }
    let rows: Vec<&RateRow> = rates
        .iter()
        .filter(|r| r.field == e.field && r.norm == e.norm && selects(&e.select, &r.group_axes))
        .collect();
    if rows.is_empty() {
        return vec![format!(
            "no fitted rate for {}",
            subject(&label(&e.select), e)
        )];
    }
    let mut messages = Vec::new();
    for row in rows {
        let at = subject(&row.group, e);
        if let Some(min) = e.rate_min.filter(|&min| row.rate < min) {
            messages.push(format!(
                "{at}: rate {} < rate_min {}",
                beside(row.rate, min),
                exact(min)
            ));
        }
        if let Some(max) = e.rate_max.filter(|&max| row.rate > max) {
            messages.push(format!(
                "{at}: rate {} > rate_max {}",
                beside(row.rate, max),
                exact(max)
            ));
        }
    }
    messages
}

fn check_errors(e: &Expectation, runs: &[RunSummary]) -> Vec<String> {
    if e.error_min.is_none() && e.error_max.is_none() {
        return Vec::new();
    }
    let matching: Vec<&RunSummary> = ordered_runs(runs)
        .into_iter()
        .filter(|run| selects(&e.select, &run.axes))
        .collect();
    if matching.is_empty() {
        return vec![format!("no run for {}", subject(&label(&e.select), e))];
    }
    matching
        .into_iter()
        .filter_map(|run| {
            let at = subject(&label(&run.axes), e);
            let error = run.final_norms.get(&(e.field.clone(), e.norm.clone()));
            match (run.status, error) {
                (RunStatus::Ok, Some(&error)) => error_outside(error, e.error_min, e.error_max)
                    .map(|bound| format!("{at}: error {bound} (run {})", run.run_id)),
                (RunStatus::Ok, None) => Some(format!("{at}: no final error (run {})", run.run_id)),
                (status, _) => Some(format!(
                    "{at}: run {} {}: {}",
                    run.run_id,
                    status.as_str(),
                    run.message
                )),
            }
        })
        .collect()
}

/// `value > error_max ...` or `value < error_min ...` when the error breaks a bound (NaN
/// breaks both), else `None`.
fn error_outside(error: f64, min: Option<f64>, max: Option<f64>) -> Option<String> {
    if let Some(max) = max.filter(|&max| error > max || error.is_nan()) {
        return Some(format!("{} > error_max {}", beside(error, max), exact(max)));
    }
    let min = min.filter(|&min| error < min || error.is_nan())?;
    Some(format!("{} < error_min {}", beside(error, min), exact(min)))
}

/// In every group of the selected runs, the last stable value of the swept axis must be at
/// least `min` and the first unstable one at most `max`.
fn check_limit(e: &Expectation, runs: &[RunSummary]) -> Vec<String> {
    let Some(LimitBound { sweep, min, max }) = &e.limit else {
        return Vec::new();
    };
    let selected = runs.iter().filter(|run| selects(&e.select, &run.axes));
    let groups = limits(selected, sweep);
    if groups.is_empty() {
        return vec![format!("no run for {}", describe(e))];
    }
    let mut messages = Vec::new();
    for limit in &groups {
        let at = group_name(&limit.axes);
        match limit.last_stable() {
            None => messages.push(format!("{at}: no stable run along {sweep}")),
            Some(p) if p.value < *min => messages.push(format!(
                "{at}: last stable {sweep} {} < limit_min {} (run {})",
                beside(p.value, *min),
                exact(*min),
                p.run.run_id
            )),
            Some(_) => {}
        }
        match limit.first_unstable() {
            None => messages.push(format!("{at}: no unstable run along {sweep}")),
            Some(p) if p.value > *max => messages.push(format!(
                "{at}: first unstable {sweep} {} > limit_max {} (run {})",
                beside(p.value, *max),
                exact(*max),
                p.run.run_id
            )),
            Some(_) => {}
        }
    }
    messages
}

/// `<group> <field> <norm>`, or just `<field> <norm>` when the group has no axes.
fn subject(group: &str, e: &Expectation) -> String {
    let what = format!("{} {}", e.field, e.norm);
    if group.is_empty() {
        what
    } else {
        format!("{group} {what}")
    }
}

/// `value` with just enough digits to show on which side of `bound` it lies, so that a
/// failure never reads `rate 1.80 < rate_min 1.8`.
fn beside(value: f64, bound: f64) -> String {
    (3..=17)
        .map(|sig| general(value, sig))
        .find(|text| {
            text.parse::<f64>()
                .is_ok_and(|shown| shown.partial_cmp(&bound) == value.partial_cmp(&bound))
        })
        .unwrap_or_else(|| exact(value))
}

/// A claim `--check` cannot let pass: unexplained, stale or unmeasured.
fn claim_failures(outcomes: &[Outcome]) -> Vec<CheckFailure> {
    outcomes
        .iter()
        .filter(|o| !matches!(o.verdict, Verdict::Reproduced | Verdict::Differs))
        .map(|o| CheckFailure {
            line: o.claim.line,
            message: format!(
                "paper claim {} ({}): paper {}, ours {}: {}",
                o.claim.item,
                o.claim.claim,
                o.paper_text(),
                if o.ours.is_empty() {
                    "none".into()
                } else {
                    o.ours_text()
                },
                o.verdict.as_str()
            ),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_outside_either_bound() {
        assert_eq!(error_outside(6.17e-3, Some(6.165e-3), Some(6.175e-3)), None);
        assert_eq!(
            error_outside(6.2e-3, Some(6.165e-3), Some(6.175e-3)).unwrap(),
            "0.0062 > error_max 0.006175"
        );
        assert_eq!(
            error_outside(6.1e-3, Some(6.165e-3), None).unwrap(),
            "0.0061 < error_min 0.006165"
        );
        assert!(error_outside(f64::NAN, Some(1.0), None).is_some());
        assert!(error_outside(f64::NAN, None, Some(1.0)).is_some());
    }

    #[test]
    fn values_near_a_bound_get_more_digits() {
        assert_eq!(beside(0.31234, 1.8), "0.312");
        assert_eq!(beside(1.79996, 1.8), "1.79996");
        assert_eq!(beside(2.2e-3, 1e-3), "0.0022");
        assert_eq!(beside(f64::NAN, 1e-3), "NaN");
    }
}
