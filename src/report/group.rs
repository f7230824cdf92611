//! Which runs belong together, in which order, and which of their errors can be fitted.

use std::cmp::Ordering;
use std::collections::BTreeMap;
use std::fmt::Display;

use crate::experiment::{Experiment, Selection};
use crate::output::{RunStatus, RunSummary, REFERENCE_NORM};
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

/// `key=value` pairs, space separated, in their order (by key for axes and selections; a
/// selection's values read `a|b`); empty when there are none.
pub fn label<K: Display, V: Display>(pairs: impl IntoIterator<Item = (K, V)>) -> String {
    pairs
        .into_iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The label of a group of runs that `select` chose: the group's axis values, and for an axis
/// that varies within the group (one the grouping dropped, a figure's `by`) the values
/// `select` lists when it lists several, so that figures of two such selections tell
/// themselves apart (`G=0.1 method=mpm_musl|mpm_tls`). A one-value selection adds nothing.
pub fn scoped_label(group: &Params, select: &Selection) -> String {
    label(scoped_pairs(group, select))
}

/// The (axis, value) pairs of `scoped_label`, sorted by axis.
pub fn scoped_pairs(group: &Params, select: &Selection) -> Vec<(String, String)> {
    let mut pairs: BTreeMap<String, String> = group
        .iter()
        .map(|(k, v)| (k.clone(), v.to_string()))
        .collect();
    for (axis, allowed) in select {
        if allowed.values().len() > 1 {
            pairs
                .entry(axis.clone())
                .or_insert_with(|| allowed.to_string());
        }
    }
    pairs.into_iter().collect()
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

/// Whether `axes` holds every axis of `select` with one of the values it allows.
pub fn selects(select: &Selection, axes: &Params) -> bool {
    select.iter().all(|(k, allowed)| {
        axes.get(k)
            .is_some_and(|a| allowed.values().iter().any(|v| same_value(a, v)))
    })
}

/// `G: 1` in a selector should match an axis written `G: 1.0`, so numbers compare by value.
fn same_value(a: &ParamValue, b: &ParamValue) -> bool {
    match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

/// Axis values in order: by key, then value (`cmp_value`).
pub fn cmp_params(a: &Params, b: &Params) -> Ordering {
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

/// Relative errors at or below this are round-off: about 4500 times the machine epsilon.
pub const RELATIVE_ROUND_OFF: f64 = 1e-12;

/// The points a convergence rate is fitted to: `usable_points` without the errors of a
/// relative norm (`integral`, `reference`) that are round-off, whose slope would be noise.
pub fn fit_points(runs: &[&RunSummary], field: &str, norm: &str) -> Vec<(f64, f64)> {
    let relative = matches!(norm, "integral" | REFERENCE_NORM);
    usable_points(runs, field, norm)
        .into_iter()
        .filter(|&(_, error)| !(relative && error <= RELATIVE_ROUND_OFF))
        .collect()
}

/// A file-name-safe version of `text`: the `|` between the values of a selection becomes `+`,
/// other runs of characters outside `[A-Za-z0-9.-]` one `_`, none at the ends
/// (`points=[-0.6, 0.4]` gives `points_-0.6_0.4`, `method=mpm|usl` `method_mpm+usl`).
pub fn slug(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_ascii_alphanumeric() || matches!(c, '.' | '-') {
            out.push(c);
        } else if c == '|' {
            out.truncate(out.trim_end_matches('_').len());
            out.push('+');
        } else if !out.is_empty() && !out.ends_with(['_', '+']) {
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

    fn text(s: &str) -> ParamValue {
        ParamValue::Str(s.into())
    }

    /// A selection of `key` with these values.
    fn any_of(key: &str, values: Vec<ParamValue>) -> Selection {
        Selection::from_iter([(key.to_string(), values.into())])
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
        let select = |params: Params| selects(&Selection::from(&params), &axes);
        assert!(select(one("G", ParamValue::Int(1))));
        assert!(select(Params::new()));
        assert!(!select(one("method", text("usl"))));
        assert!(!select(one("ppc", ParamValue::Int(2))));
    }

    #[test]
    fn a_list_selects_runs_with_any_of_its_values() {
        let run = |method: &str, g: f64| {
            Params::from([
                ("G".to_string(), ParamValue::Float(g)),
                ("method".to_string(), text(method)),
            ])
        };
        let tls = any_of("method", vec![text("mpm_musl"), text("mpm_tls")]);
        assert!(selects(&tls, &run("mpm_musl", 0.1)));
        assert!(selects(&tls, &run("mpm_tls", 0.1)));
        assert!(!selects(&tls, &run("mpm", 0.1)));
        // Numbers still compare by value, and every axis named must match.
        let both = Selection::from_iter([
            (
                "G".to_string(),
                vec![ParamValue::Int(1), ParamValue::Float(0.1)].into(),
            ),
            ("method".to_string(), vec![text("mpm_tls")].into()),
        ]);
        assert!(selects(&both, &run("mpm_tls", 1.0)));
        assert!(!selects(&both, &run("mpm_musl", 1.0)));
        assert!(!selects(&both, &one("G", ParamValue::Float(0.1))));
        let none = any_of("method", Vec::new());
        assert!(
            !selects(&none, &run("mpm", 0.1)),
            "an empty list selects nothing"
        );
    }

    #[test]
    fn selection_labels_join_listed_values() {
        let single = Params::from([
            ("G".to_string(), ParamValue::Float(0.1)),
            ("method".to_string(), text("mpm")),
        ]);
        // One value per axis reads exactly as the axes themselves.
        assert_eq!(label(&Selection::from(&single)), label(&single));
        assert_eq!(label(&single), "G=0.1 method=mpm");
        let tls = any_of("method", vec![text("mpm_musl"), text("mpm_tls")]);
        assert_eq!(label(&tls), "method=mpm_musl|mpm_tls");
        assert_eq!(slug(&label(&tls)), "method_mpm_musl+mpm_tls");
        let points = any_of(
            "points",
            vec![
                ParamValue::List(vec![-0.6, 0.4]),
                ParamValue::List(vec![0.5]),
            ],
        );
        assert_eq!(label(&points), "points=[-0.6, 0.4]|[0.5]");
        assert_eq!(slug(&label(&points)), "points_-0.6_0.4+0.5");
    }

    #[test]
    fn scoped_labels_add_listed_values_of_axes_within_the_group() {
        let group = one("G", ParamValue::Float(0.1));
        let tls = any_of("method", vec![text("mpm_musl"), text("mpm_tls")]);
        assert_eq!(scoped_label(&group, &tls), "G=0.1 method=mpm_musl|mpm_tls");
        assert_eq!(
            scoped_label(&Params::new(), &tls),
            "method=mpm_musl|mpm_tls"
        );
        // A one-value selection, or one of an axis the group fixes, changes nothing.
        let mpm = any_of("method", vec![text("mpm")]);
        assert_eq!(scoped_label(&group, &mpm), "G=0.1");
        let gs = any_of("G", vec![ParamValue::Float(0.1), ParamValue::Float(1.0)]);
        assert_eq!(scoped_label(&group, &gs), "G=0.1");
    }

    #[test]
    fn slug_replaces_unsafe_characters() {
        assert_eq!(slug("G=0.1 method=mpm"), "G_0.1_method_mpm");
        assert_eq!(slug("a/b,c-d_e"), "a_b_c-d_e");
        assert_eq!(slug("points=[-0.6, 0.4]"), "points_-0.6_0.4");
        assert_eq!(slug("method=a|b|c G=1"), "method_a+b+c_G_1");
    }
}
