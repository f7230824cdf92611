//! Convergence figures: error against h on log-log axes, one curve per field (and value of
//! `by`): the measured errors as markers joined by a solid line, the fitted power law dashed
//! over the h it was fitted to, and a note for every run that did not finish.

use super::{default_stem, Figure, Marker, Scale, Series};
use crate::benchmarks::BenchmarkKind;
use crate::experiment::{Experiment, FigureSpec};
use crate::output::{RunStatus, RunSummary};
use crate::report::fit::{fit_loglog, min_max};
use crate::report::format::{general, rate};
use crate::report::group::{
    fit_points, group_runs, label, label_or_all, scoped_pairs, title_suffix, usable_points,
    REFINEMENT_AXIS,
};
use crate::report::units::{cell_size_label, error_unit};

/// What a reader needs to read the dashed lines.
const FIT_NOTE: &str = "dashed: least-squares power law over the runs it was fitted to";

/// One figure per combination of the axes other than the refinement axis and `by`.
pub(super) fn figures(
    experiment: &Experiment,
    runs: &[&RunSummary],
    spec: &FigureSpec,
) -> Vec<Figure> {
    let mut drop = vec![REFINEMENT_AXIS];
    drop.extend(spec.by.iter().map(String::as_str));
    let dim = runs.first().map_or(1, |run| run.dim);
    group_runs(runs.iter().copied(), &drop)
        .into_iter()
        .filter_map(|group| {
            let series = curves(&group.runs, spec, dim);
            if series.is_empty() {
                return None;
            }
            let variant = scoped_pairs(&group.axes, &spec.select);
            let scope = label(variant.iter().map(|(k, v)| (k, v)));
            let title = format!(
                "{}: {} ({} norm){}",
                experiment.name,
                spec.fields.join(", "),
                spec.norm,
                title_suffix(&scope)
            );
            let mut notes = Vec::new();
            if series.iter().any(|s| !s.fit.is_empty()) {
                notes.push(FIT_NOTE.to_string());
            }
            notes.extend(unfinished(&group.runs, spec));
            Some(Figure {
                file: default_stem(&file_stem(&label_or_all(&scope), spec)),
                title,
                variant,
                x_label: cell_size_label(experiment.kind == BenchmarkKind::Simulation),
                y_label: y_label(spec, dim),
                scale: Scale::LogLog,
                series,
                notes,
                drawn_by: None,
            })
        })
        .collect()
}

/// The quantity and unit on the error axis: one field's, or the norm's with the units in
/// the legend when the fields differ.
fn y_label(spec: &FigureSpec, dim: usize) -> String {
    match spec.fields.as_slice() {
        [field] => format!(
            "{field} error, {} norm ({})",
            spec.norm,
            error_unit(field, &spec.norm, dim)
        ),
        _ => format!("{} error (units in the legend)", spec.norm),
    }
}

/// One curve per combination of the `by` axes (if any) and field, in that order: the runs as
/// markers on a solid line in order of h, and the fit dashed between the coarsest and finest
/// h it was fitted to; empty curves are dropped. The label names the `by` axes a run sets,
/// the unit when the figure shows several fields, and the fitted rate.
fn curves(runs: &[&RunSummary], spec: &FigureSpec, dim: usize) -> Vec<Series> {
    let mut curves = Vec::new();
    // Within one figure only `by` is left to vary besides the refinement axis.
    for sub in group_runs(runs.iter().copied(), &[REFINEMENT_AXIS]) {
        let by = by_label(&sub.axes, spec);
        for field in &spec.fields {
            let mut points = usable_points(&sub.runs, field, &spec.norm);
            if points.is_empty() {
                continue;
            }
            points.sort_by(|a, b| b.0.total_cmp(&a.0));
            // Round-off errors are drawn but not fitted (`fit_points`).
            let fitted = fit_points(&sub.runs, field, &spec.norm);
            let fit = fit_loglog(&fitted);
            let slope = fit.map_or(String::new(), |f| format!(" (rate {})", rate(f.slope)));
            let unit = match spec.fields.len() {
                1 => String::new(),
                _ => format!(" ({})", error_unit(field, &spec.norm, dim)),
            };
            let line = fit.map_or_else(Vec::new, |f| {
                let (h_lo, h_hi) = min_max(fitted.iter().map(|p| p.0));
                vec![(h_hi, f.eval(h_hi)), (h_lo, f.eval(h_lo))]
            });
            curves.push(Series {
                label: format!("{field}{unit}{by}{slope}"),
                line: points.clone(),
                markers: points,
                marker: Marker::DATA[curves.len() % Marker::DATA.len()],
                fit: line,
                dashed: false,
                neutral: false,
            });
        }
    }
    curves
}

/// `, method=mpm` for the `by` axes a group of runs sets.
fn by_label(axes: &crate::params::Params, spec: &FigureSpec) -> String {
    spec.by
        .iter()
        .filter_map(|axis| axes.get(axis).map(|value| format!(", {axis}={value}")))
        .collect()
}

/// A note per run of the figure that did not finish, with its message (where it stopped and
/// why), since it has no final error to draw.
fn unfinished(runs: &[&RunSummary], spec: &FigureSpec) -> Vec<String> {
    runs.iter()
        .filter(|run| run.status != RunStatus::Ok)
        .map(|run| {
            let by = by_label(&run.axes, spec);
            let by = by.trim_start_matches(", ");
            let which = if by.is_empty() {
                String::new()
            } else {
                format!("{by}, ")
            };
            format!(
                "not drawn: {which}h = {}, {}: {}",
                general(run.h, 4),
                run.status.as_str(),
                run.message
            )
        })
        .collect()
}

/// `<group>_<norm>`, with the field before the norm when the figure draws only one, so that
/// one figure per field of a group gets a name that says which.
fn file_stem(which: &str, spec: &FigureSpec) -> String {
    match spec.fields.as_slice() {
        [field] => format!("{which}_{field}_{}", spec.norm),
        _ => format!("{which}_{}", spec.norm),
    }
}
