//! Figures of stability sweeps: the measured limit against `x` beside the predicted bounds,
//! and the error histories of the two runs that bracket the limit.

use super::{default_stem, Figure, Marker, Scale, Series};
use crate::experiment::{Experiment, FigureSpec, StabilityAxes};
use crate::output::RunSummary;
use crate::report::format::general;
use crate::report::group::{group_runs, label, label_or_all, scoped_pairs};
use crate::report::stability::{
    group_name, limits, outcome, particles_per_cell, predicted, Verdict, PPC_AXIS, THRESHOLD,
};

/// One figure per group of the axes other than `x` and `sweep`: the last stable and the
/// first unstable value of `sweep` at each value of `x` as markers, and when `x` is the
/// particles per cell the predicted bounds as lines over 1 to the largest value drawn.
pub(super) fn limit_figures(
    experiment: &Experiment,
    runs: &[&RunSummary],
    spec: &FigureSpec,
) -> Vec<Figure> {
    let Some(StabilityAxes { sweep, x: Some(x) }) = &spec.stability else {
        return Vec::new();
    };
    group_runs(runs.iter().copied(), &[x, sweep])
        .into_iter()
        .filter_map(|group| {
            let mut stable = Vec::new();
            let mut unstable = Vec::new();
            for limit in limits(group.runs.iter().copied(), sweep) {
                let Some(at) = limit.axes.get(x).and_then(|v| v.as_f64()) else {
                    continue;
                };
                stable.extend(limit.last_stable().map(|p| (at, p.value)));
                unstable.extend(limit.first_unstable().map(|p| (at, p.value)));
            }
            if stable.is_empty() && unstable.is_empty() {
                return None;
            }
            // The lines first, so that the markers are drawn over them.
            let mut series = if x == PPC_AXIS {
                bound_lines(&group.runs, x)
            } else {
                Vec::new()
            };
            series.extend([
                Series::markers(format!("last stable {sweep}"), Marker::Circle, stable),
                Series::markers(format!("first unstable {sweep}"), Marker::Square, unstable),
            ]);
            let variant = scoped_pairs(&group.axes, &spec.select);
            let name = label_or_all(&label(variant.iter().map(|(k, v)| (k, v))));
            Some(Figure {
                file: default_stem(&format!("stability_{name}")),
                variant,
                title: format!(
                    "{}: stability limit along {sweep} ({name})",
                    experiment.name
                ),
                x_label: format!("{x} (dimensionless)"),
                y_label: format!("{sweep} (Courant number, dimensionless)"),
                scale: Scale::Linear,
                series,
                notes: Vec::new(),
                drawn_by: None,
            })
        })
        .collect()
}

/// The predicted bounds at 1, 2, ... up to the largest particles per cell of `runs`.
fn bound_lines(runs: &[&RunSummary], x: &str) -> Vec<Series> {
    let largest = runs
        .iter()
        .filter_map(|run| particles_per_cell(run.axes.get(x)?))
        .max()
        .unwrap_or(1);
    let rows: Vec<_> = (1..=largest).map(|n| (n, predicted(n))).collect();
    (0..3)
        .map(|k| {
            let name = rows[0].1[k].0;
            let points = rows.iter().map(|(n, b)| (*n as f64, b[k].1)).collect();
            let mut line = Series::line(name.to_string(), points);
            // The printed bound is a flat line that markers may sit on.
            line.dashed = k == 0;
            line
        })
        .collect()
}

/// One figure per group of the axes other than `sweep`: the l2 velocity error over the
/// velocity at t = 0 against time for the last stable and the first unstable run, on a log
/// scale, with the threshold of the criterion.
pub(super) fn growth_figures(
    experiment: &Experiment,
    runs: &[&RunSummary],
    spec: &FigureSpec,
) -> Vec<Figure> {
    let Some(StabilityAxes { sweep, .. }) = &spec.stability else {
        return Vec::new();
    };
    limits(runs.iter().copied(), sweep)
        .into_iter()
        .filter_map(|limit| {
            let mut series: Vec<Series> = limit
                .bracket()
                .filter_map(|point| {
                    let history = point.run.velocity_history.as_ref()?;
                    let ratios: Vec<(f64, f64)> = history
                        .time
                        .iter()
                        .zip(&history.l2_error)
                        .map(|(&t, &e)| (t, e / history.initial_l2))
                        .filter(|&(_, r)| r.is_finite() && r > 0.0)
                        .collect();
                    let verdict = match point.verdict {
                        Verdict::Stable => "stable",
                        Verdict::Unstable => "unstable",
                    };
                    let label = format!(
                        "{sweep}={}: {verdict}, {}",
                        general(point.value, 6),
                        outcome(point)
                    );
                    let mut s = Series::markers(label, Marker::Circle, ratios.clone());
                    s.line = ratios;
                    Some(s)
                })
                .collect();
            let t_end = series
                .iter()
                .flat_map(|s| s.line.iter().map(|p| p.0))
                .fold(0.0, f64::max);
            if series.is_empty() || t_end <= 0.0 {
                return None;
            }
            let mut threshold = Series::line(
                format!("threshold: error = {THRESHOLD} x solution"),
                vec![(0.0, THRESHOLD), (t_end, THRESHOLD)],
            );
            threshold.dashed = true;
            series.push(threshold);
            let name = group_name(&limit.axes);
            Some(Figure {
                file: default_stem(&format!("growth_{name}")),
                title: format!("{}: error growth at the limit ({name})", experiment.name),
                variant: limit
                    .axes
                    .iter()
                    .map(|(k, v)| (k.clone(), v.to_string()))
                    .collect(),
                x_label: "t, time (s)".into(),
                y_label: "l2 velocity error / l2 velocity at t = 0 (-)".into(),
                scale: Scale::LogY,
                series,
                notes: Vec::new(),
                drawn_by: None,
            })
        })
        .collect()
}
