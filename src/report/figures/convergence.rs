//! Convergence figures: error against h on log-log axes, one curve per field (and value of
//! `by`), each with its fitted power law.

use super::{Figure, Marker, Names, Scale, Series};
use crate::experiment::{Experiment, FigureSpec};
use crate::output::RunSummary;
use crate::report::fit::{fit_loglog, min_max};
use crate::report::format::rate;
use crate::report::group::{
    fit_points, group_runs, label_or_all, scoped_label, title_suffix, usable_points,
    REFINEMENT_AXIS,
};

/// One figure per combination of the axes other than the refinement axis and `by`.
pub(super) fn figures(
    experiment: &Experiment,
    runs: &[&RunSummary],
    spec: &FigureSpec,
    names: &mut Names,
) -> Vec<Figure> {
    let mut drop = vec![REFINEMENT_AXIS];
    drop.extend(spec.by.iter().map(String::as_str));
    group_runs(runs.iter().copied(), &drop)
        .into_iter()
        .filter_map(|group| {
            let series = curves(&group.runs, spec);
            if series.is_empty() {
                return None;
            }
            let scope = scoped_label(&group.axes, &spec.select);
            let which = label_or_all(&scope);
            let title = format!(
                "{}: {} ({} norm){}",
                experiment.name,
                spec.fields.join(", "),
                spec.norm,
                title_suffix(&scope)
            );
            Some(Figure {
                file: names.file(experiment, &file_stem(&which, spec)),
                title,
                x_label: "h (cell size)".into(),
                y_label: format!("{} error", spec.norm),
                scale: Scale::LogLog,
                series,
            })
        })
        .collect()
}

/// One curve per combination of the `by` axes (if any) and field, in that order: the runs as
/// markers and the fit dashed between the coarsest and finest h; empty curves are dropped.
/// The label names the `by` axes a run sets.
fn curves(runs: &[&RunSummary], spec: &FigureSpec) -> Vec<Series> {
    let mut curves = Vec::new();
    // Within one figure only `by` is left to vary besides the refinement axis.
    for sub in group_runs(runs.iter().copied(), &[REFINEMENT_AXIS]) {
        let by: String = spec
            .by
            .iter()
            .filter_map(|axis| sub.axes.get(axis).map(|value| format!(", {axis}={value}")))
            .collect();
        for field in &spec.fields {
            let points = usable_points(&sub.runs, field, &spec.norm);
            if points.is_empty() {
                continue;
            }
            // Round-off errors are drawn but not fitted (`fit_points`).
            let fitted = fit_points(&sub.runs, field, &spec.norm);
            let fit = fit_loglog(&fitted);
            let slope = fit.map_or(String::new(), |f| format!(" (rate {})", rate(f.slope)));
            let line = fit.map_or_else(Vec::new, |f| {
                let (h_lo, h_hi) = min_max(fitted.iter().map(|p| p.0));
                vec![(h_lo, f.eval(h_lo)), (h_hi, f.eval(h_hi))]
            });
            curves.push(Series {
                label: format!("{field}{by}{slope}"),
                markers: points,
                marker: Marker::DATA[curves.len() % Marker::DATA.len()],
                line,
                dashed: true,
                neutral: false,
            });
        }
    }
    curves
}

/// `<group>_<norm>`, with the field before the norm when the figure draws only one, so that
/// one figure per field of a group gets a name that says which.
fn file_stem(which: &str, spec: &FigureSpec) -> String {
    match spec.fields.as_slice() {
        [field] => format!("{which}_{field}_{}", spec.norm),
        _ => format!("{which}_{}", spec.norm),
    }
}
