//! Which runs belong together, in which order, and which of their errors can be fitted.

use std::cmp::Ordering;

use crate::experiment::Experiment;
use crate::output::{RunStatus, RunSummary};
use crate::params::{ParamValue, Params};

/// The matrix axis that refines the grid: runs differing only in it form one convergence
/// study.
pub const REFINEMENT_AXIS: &str = "cells";

/// Runs sharing the same values of every axis except the dropped ones.
#[derive(Debug)]
pub struct Group<'a> {
    pub axes: Params,
    pub label: String,
    /// Coarsest grid first.
    pub runs: Vec<&'a RunSummary>,
}

/// Splits `runs` by their axes minus `drop`. Groups are ordered by axis values (numbers
/// numerically), so the order does not depend on the order runs were read in.
pub fn group_runs<'a>(
    runs: impl IntoIterator<Item = &'a RunSummary>,
    drop: &[&str],
) -> Vec<Group<'a>> {
    let mut groups: Vec<Group<'a>> = Vec::new();
    for run in runs {
        let axes = without(&run.axes, drop);
        match groups.iter_mut().find(|g| g.axes == axes) {
            Some(group) => group.runs.push(run),
            None => groups.push(Group {
                label: label(&axes),
                axes,
                runs: vec![run],
            }),
        }
    }
    groups.sort_by(|a, b| cmp_params(&a.axes, &b.axes));
    for group in &mut groups {
        group
            .runs
            .sort_by(|a, b| b.h.total_cmp(&a.h).then_with(|| a.run_id.cmp(&b.run_id)));
    }
    groups
}

/// Every run, grouped and coarsest first within a group: the order of the run tables.
pub fn ordered_runs<'a>(runs: impl IntoIterator<Item = &'a RunSummary>) -> Vec<&'a RunSummary> {
    group_runs(runs, &[REFINEMENT_AXIS])
        .into_iter()
        .flat_map(|g| g.runs)
        .collect()
}

fn without(axes: &Params, drop: &[&str]) -> Params {
    axes.iter()
        .filter(|(k, _)| !drop.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect()
}

/// `key=value` pairs sorted by key, space separated; empty when there are none.
/// The run's value of each of the experiment's axes, in file order (empty if absent).
pub fn axis_values<'a>(
    experiment: &'a Experiment,
    run: &'a RunSummary,
) -> impl Iterator<Item = String> + 'a {
    experiment.axes.iter().map(|axis| {
        run.axes
            .get(axis)
            .map(ToString::to_string)
            .unwrap_or_default()
    })
}

pub fn label(axes: &Params) -> String {
    axes.iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A group's label for titles and file names, `all` for a group without axes.
pub fn label_or_all(label: &str) -> String {
    if label.is_empty() {
        "all".into()
    } else {
        label.to_string()
    }
}

/// `: <label>` to end a title with the group, empty for a group without axes.
pub fn title_suffix(label: &str) -> String {
    if label.is_empty() {
        String::new()
    } else {
        format!(": {label}")
    }
}

/// Whether `axes` holds every key of `select` with the same value.
pub fn selects(select: &Params, axes: &Params) -> bool {
    select
        .iter()
        .all(|(k, v)| axes.get(k).is_some_and(|a| same_value(a, v)))
}

/// `G: 1` in a selector should match an axis written `G: 1.0`, so numbers compare by value.
fn same_value(a: &ParamValue, b: &ParamValue) -> bool {
    match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

fn cmp_params(a: &Params, b: &Params) -> Ordering {
    a.iter()
        .zip(b)
        .map(|((ka, va), (kb, vb))| ka.cmp(kb).then_with(|| cmp_value(va, vb)))
        .find(|o| o.is_ne())
        .unwrap_or_else(|| a.len().cmp(&b.len()))
}

/// Numbers before strings; numbers by value, strings lexically, lists of numbers element by
/// element.
fn cmp_value(a: &ParamValue, b: &ParamValue) -> Ordering {
    match (a.as_f64(), b.as_f64(), a.as_str(), b.as_str()) {
        (Some(x), Some(y), _, _) => x.total_cmp(&y),
        (Some(_), None, _, _) => Ordering::Less,
        (None, Some(_), _, _) => Ordering::Greater,
        (_, _, Some(x), Some(y)) => x.cmp(y),
        _ => match (a.as_list(), b.as_list()) {
            (Some(x), Some(y)) => x
                .iter()
                .zip(y)
                .map(|(p, q)| p.total_cmp(q))
                .find(|o| o.is_ne())
                .unwrap_or_else(|| x.len().cmp(&y.len())),
            _ => Ordering::Equal,
        },
    }
}

/// (h, final error) of every run that can enter a log-log fit, in the runs' order: the run
/// finished and both numbers are finite and positive.
pub fn usable_points(runs: &[&RunSummary], field: &str, norm: &str) -> Vec<(f64, f64)> {
    let key = (field.to_string(), norm.to_string());
    let positive = |x: f64| x.is_finite() && x > 0.0;
    runs.iter()
        .filter(|run| run.status == RunStatus::Ok)
        .filter_map(|run| Some((run.h, *run.final_norms.get(&key)?)))
        .filter(|&(h, error)| positive(h) && positive(error))
        .collect()
}

/// A file-name-safe version of `text`: runs of characters outside `[A-Za-z0-9.-]` become one
/// `_`, none at the ends (`points=[-0.6, 0.4]` gives `points_-0.6_0.4`).
pub fn slug(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_ascii_alphanumeric() || matches!(c, '.' | '-') {
            out.push(c);
        } else if !out.is_empty() && !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_end_matches('_').to_string()
}

/// The names of the probes `runs` record, sorted, for a message about a missing one; `none`
/// when they record none.
pub fn recorded_probes<'a>(runs: impl IntoIterator<Item = &'a RunSummary>) -> String {
    let mut names: Vec<&str> = runs
        .into_iter()
        .flat_map(|run| run.probes.iter().map(|p| p.name.as_str()))
        .collect();
    names.sort_unstable();
    names.dedup();
    if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(key: &str, value: ParamValue) -> Params {
        Params::from([(key.to_string(), value)])
    }

    #[test]
    fn numbers_order_by_value_and_before_strings() {
        let mut values = [
            one("G", ParamValue::Str("b".into())),
            one("G", ParamValue::Float(10.0)),
            one("G", ParamValue::Int(2)),
            one("G", ParamValue::Float(1.5)),
        ];
        values.sort_by(cmp_params);
        let labels: Vec<String> = values.iter().map(label).collect();
        assert_eq!(labels, ["G=1.5", "G=2", "G=10.0", "G=b"]);
        let mut lists = [
            one("x", ParamValue::List(vec![0.6, 0.75])),
            one("x", ParamValue::List(vec![-0.6, 0.4, 1.0])),
            one("x", ParamValue::List(vec![-0.6, 0.4])),
        ];
        lists.sort_by(cmp_params);
        let labels: Vec<String> = lists.iter().map(label).collect();
        assert_eq!(
            labels,
            ["x=[-0.6, 0.4]", "x=[-0.6, 0.4, 1.0]", "x=[0.6, 0.75]"]
        );
    }

    #[test]
    fn selectors_compare_numbers_by_value() {
        let axes = Params::from([
            ("G".to_string(), ParamValue::Float(1.0)),
            ("method".to_string(), ParamValue::Str("mpm".into())),
        ]);
        assert!(selects(&one("G", ParamValue::Int(1)), &axes));
        assert!(selects(&Params::new(), &axes));
        assert!(!selects(
            &one("method", ParamValue::Str("usl".into())),
            &axes
        ));
        assert!(!selects(&one("ppc", ParamValue::Int(2)), &axes));
    }

    #[test]
    fn slug_replaces_unsafe_characters() {
        assert_eq!(slug("G=0.1 method=mpm"), "G_0.1_method_mpm");
        assert_eq!(slug("a/b,c-d_e"), "a_b_c-d_e");
        assert_eq!(slug("points=[-0.6, 0.4]"), "points_-0.6_0.4");
    }
}
