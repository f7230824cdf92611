//! Fields along the bar at the final time (Wobbes Fig 4): one line per run against the
//! current position x, the experiment's reference run as grey markers.

use super::{default_stem, Figure, Scale, Series};
use crate::experiment::{Experiment, FigureSpec, Selection};
use crate::output::{ParticleState, RunStatus, RunSummary};
use crate::report::group::{label, ordered_runs, selects};
use crate::report::units::quantity;

/// At most this many reference markers are drawn (every k-th point of the reference).
const MAX_MARKERS: usize = 80;

/// One figure per field of `spec` over the `selected` runs that finished; `all` holds the
/// reference run, which need not be selected.
pub(super) fn figures(
    experiment: &Experiment,
    all: &[RunSummary],
    selected: &[&RunSummary],
    spec: &FigureSpec,
) -> Vec<Figure> {
    let reference_axes = experiment.reference.as_ref().map(Selection::from);
    let is_reference = |run: &RunSummary| {
        reference_axes
            .as_ref()
            .is_some_and(|select| selects(select, &run.axes))
    };
    let reference = all
        .iter()
        .find(|run| is_reference(run) && run.status == RunStatus::Ok);
    let lines: Vec<&RunSummary> = ordered_runs(all)
        .into_iter()
        .filter(|run| selected.iter().any(|s| s.run_id == run.run_id))
        .filter(|run| run.status == RunStatus::Ok && !is_reference(run))
        .collect();
    let mut figures = Vec::new();
    for field in &spec.fields {
        let mut series: Vec<Series> = lines
            .iter()
            .filter_map(|run| {
                let points = along(run.profile.as_ref()?, field);
                Some(Series::line(differing(&lines, run), points))
            })
            .collect();
        if let Some(run) = reference {
            if let Some(profile) = &run.profile {
                let points = along(profile, field);
                // A fine reference would draw a solid band of markers.
                let stride = points.len().div_ceil(MAX_MARKERS);
                let mut s = Series::markers(
                    format!("reference: {}", label(&run.axes)),
                    super::Marker::Circle,
                    points.into_iter().step_by(stride).collect(),
                );
                s.neutral = true;
                series.push(s);
            }
        }
        if series.is_empty() {
            continue;
        }
        let what = format!("{field}_along_bar_{}", label(&spec.select));
        figures.push(Figure {
            file: default_stem(&what),
            title: format!("{}: {field} at the final time", experiment.name),
            variant: vec![("field".into(), field.clone())],
            x_label: "x, current position (m)".into(),
            y_label: quantity(field),
            scale: Scale::Linear,
            series,
            notes: Vec::new(),
            drawn_by: None,
        });
    }
    figures
}

/// A line's label: the axis values that tell its run from the figure's other lines (all of
/// them for a figure of one line).
fn differing(lines: &[&RunSummary], run: &RunSummary) -> String {
    let varies = |axis: &String| {
        lines
            .iter()
            .any(|other| other.axes.get(axis) != run.axes.get(axis))
    };
    let pairs: Vec<_> = run.axes.iter().filter(|(axis, _)| varies(axis)).collect();
    if pairs.is_empty() {
        label(&run.axes)
    } else {
        label(pairs)
    }
}

/// (x_p, f_p) in order of x.
fn along(profile: &ParticleState, field: &str) -> Vec<(f64, f64)> {
    let mut points: Vec<(f64, f64)> = profile
        .x
        .iter()
        .copied()
        .zip(profile.field(field))
        .collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points
}
