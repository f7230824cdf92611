//! Which figures a report draws and what goes into each; drawing is `plot`'s job.

use std::collections::BTreeSet;
use std::path::PathBuf;

use super::fit::{fit_loglog, LineFit};
use super::format::rate;
use super::group::{group_runs, slug, usable_points, REFINEMENT_AXIS};
use crate::experiment::{Experiment, FigureKind, FigureSpec};
use crate::output::{RunSummary, ERROR_FIELDS, NORMS};

#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    pub label: String,
    /// (h, error), coarsest first.
    pub points: Vec<(f64, f64)>,
    pub fit: Option<LineFit>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Relative to the report directory.
    pub file: PathBuf,
    pub title: String,
    pub y_label: String,
    pub curves: Vec<Curve>,
}

/// Every figure of the report: the experiment's own, or one convergence figure per group
/// with all fields in the first norm when it asks for none. Figures without a single
/// usable point are left out.
pub fn plan(experiment: &Experiment, runs: &[RunSummary]) -> Vec<Figure> {
    let default = [FigureSpec {
        kind: FigureKind::Convergence,
        fields: ERROR_FIELDS.map(String::from).to_vec(),
        norm: NORMS[0].to_string(),
        by: None,
    }];
    let specs = if experiment.figures.is_empty() {
        &default[..]
    } else {
        &experiment.figures
    };
    let mut names = BTreeSet::new();
    let mut figures = Vec::new();
    for spec in specs {
        match spec.kind {
            FigureKind::Convergence => {
                figures.extend(convergence(experiment, runs, spec, &mut names))
            }
        }
    }
    figures
}

/// One figure per combination of the axes other than the refinement axis and `by`.
fn convergence(
    experiment: &Experiment,
    runs: &[RunSummary],
    spec: &FigureSpec,
    names: &mut BTreeSet<String>,
) -> Vec<Figure> {
    let drop: Vec<&str> = [Some(REFINEMENT_AXIS), spec.by.as_deref()]
        .into_iter()
        .flatten()
        .collect();
    group_runs(runs, &drop)
        .into_iter()
        .filter_map(|group| {
            let curves = curves(&group.runs, spec);
            if curves.is_empty() {
                return None;
            }
            let which = if group.label.is_empty() {
                "all".to_string()
            } else {
                slug(&group.label)
            };
            let stem = format!("{}_{which}_{}", slug(&experiment.name), slug(&spec.norm));
            let title = if group.label.is_empty() {
                experiment.name.clone()
            } else {
                format!("{}: {}", experiment.name, group.label)
            };
            Some(Figure {
                file: PathBuf::from("figures").join(unique(names, stem) + ".png"),
                title,
                y_label: format!("{} error", spec.norm),
                curves,
            })
        })
        .collect()
}

/// One curve per value of `by` (if any) and field, in that order; empty curves are dropped.
fn curves(runs: &[&RunSummary], spec: &FigureSpec) -> Vec<Curve> {
    let mut curves = Vec::new();
    // Within one figure only `by` is left to vary besides the refinement axis.
    for sub in group_runs(runs.iter().copied(), &[REFINEMENT_AXIS]) {
        let by = spec
            .by
            .as_ref()
            .and_then(|axis| sub.axes.get(axis).map(|value| format!(", {axis}={value}")))
            .unwrap_or_default();
        for field in &spec.fields {
            let points = usable_points(&sub.runs, field, &spec.norm);
            if points.is_empty() {
                continue;
            }
            let fit = fit_loglog(&points);
            let slope = fit.map_or(String::new(), |f| format!(" (rate {})", rate(f.slope)));
            curves.push(Curve {
                label: format!("{field}{by}{slope}"),
                points,
                fit,
            });
        }
    }
    curves
}

/// Two figure specs may land on the same file name; later ones get a numeric suffix.
fn unique(names: &mut BTreeSet<String>, stem: String) -> String {
    let mut name = stem.clone();
    let mut k = 2;
    while !names.insert(name.clone()) {
        name = format!("{stem}_{k}");
        k += 1;
    }
    name
}
