//! Probe histories (Molinos Figs 5-13): a probe's value against time, one line per run, with
//! the benchmark's reference in grey, once per problem. A diverged run's line stops where it did,
//! marked with a cross.

use super::{default_stem, Figure, Marker, Scale, Series};
use crate::experiment::{Experiment, FigureSpec};
use crate::output::{ProbeRecord, RunStatus, RunSummary};
use crate::params::Params;
use crate::report::format::general;
use crate::report::group::{
    group_runs, label, label_or_all, recorded_probes, scoped_pairs, title_suffix,
};

/// Names of the components of vectors and tensors, by index.
const AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

/// Time buckets a history line keeps its envelope of: about one per pixel column of the axes.
const BUCKETS: usize = 600;

/// One figure per group of the axes other than `by`, a line per run of the group. An error
/// names the probe when no selected run records it, with the probes they do record.
pub(super) fn figures(
    experiment: &Experiment,
    runs: &[&RunSummary],
    spec: &FigureSpec,
) -> Result<Vec<Figure>, String> {
    let Some(name) = spec.probe.as_deref() else {
        return Ok(Vec::new());
    };
    if runs.iter().all(|run| run.probe(name).is_none()) {
        return Err(format!(
            "history figure: no selected run of {} records the probe '{name}'; the runs record: \
             {}",
            experiment.name,
            recorded_probes(runs.iter().copied())
        ));
    }
    let drop: Vec<&str> = spec.by.iter().map(String::as_str).collect();
    let mut figures = Vec::new();
    for group in group_runs(runs.iter().copied(), &drop) {
        let probes: Vec<(&RunSummary, &ProbeRecord)> = group
            .runs
            .iter()
            .filter_map(|run| Some((*run, run.probe(name)?)))
            .filter(|(_, probe)| !probe.time.is_empty())
            .collect();
        let Some((_, first)) = probes.first() else {
            continue;
        };
        let mut series: Vec<Series> = probes.iter().map(|(run, p)| line(run, p, &drop)).collect();
        let axes_and_probes: Vec<(&Params, &ProbeRecord)> = probes
            .iter()
            .map(|(run, probe)| (&run.axes, *probe))
            .collect();
        series.extend(references(&axes_and_probes, &drop));
        let variant = scoped_pairs(&group.axes, &spec.select);
        let scope = label(variant.iter().map(|(k, v)| (k, v)));
        let which = format!("{name}_{}", label_or_all(&scope));
        figures.push(Figure {
            file: default_stem(&which),
            title: format!("{}: {name}{}", experiment.name, title_suffix(&scope)),
            variant,
            x_label: "t, time (s)".into(),
            y_label: quantity_label(first),
            scale: Scale::Linear,
            series,
            notes: Vec::new(),
            drawn_by: None,
        });
    }
    Ok(figures)
}

/// The run's values over time, labelled with its values of the `by` axes (all its axes when
/// there are none); a diverged run ends in a cross at its last recorded value.
fn line(run: &RunSummary, probe: &ProbeRecord, by: &[&str]) -> Series {
    let points: Vec<(f64, f64)> = probe
        .time
        .iter()
        .copied()
        .zip(probe.value.iter().copied())
        .collect();
    let points = envelope(points, BUCKETS);
    let axes = if by.is_empty() {
        run.axes.clone()
    } else {
        run.axes
            .iter()
            .filter(|(k, _)| by.contains(&k.as_str()))
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect()
    };
    let mut series = Series::line(label(&axes), points);
    if run.status == RunStatus::Diverged {
        if let Some(&last) = series.line.last() {
            series.label = format!("{} (diverged at t = {})", series.label, general(last.0, 4));
            series.markers = vec![last];
            series.marker = Marker::Cross;
        }
    }
    series
}

/// Two runs' references are drawn as one when their final values agree to this fraction of
/// the larger: the same reference seen from particles a little apart, not another problem.
const SAME_REFERENCE: f64 = 0.01;

/// The runs' references in grey, labelled by their kind: once for runs whose references agree
/// (`SAME_REFERENCE`), and where a `by` axis changes the problem (the load, say) once per
/// reference, each labelled with the values of the `by` axes of the first run that has it.
fn references(probes: &[(&Params, &ProbeRecord)], by: &[&str]) -> Vec<Series> {
    let last = |p: &ProbeRecord| p.reference.iter().rev().copied().find(|r| r.is_finite());
    let mut distinct: Vec<(&Params, &ProbeRecord)> = Vec::new();
    for &(axes, probe) in probes {
        let Some(value) = last(probe) else {
            continue;
        };
        let same = |other: &ProbeRecord| {
            last(other)
                .is_some_and(|o| (o - value).abs() <= SAME_REFERENCE * o.abs().max(value.abs()))
        };
        if !distinct.iter().any(|(_, other)| same(other)) {
            distinct.push((axes, probe));
        }
    }
    let several = distinct.len() > 1;
    distinct
        .into_iter()
        .map(|(axes, probe)| {
            let points = probe
                .time
                .iter()
                .copied()
                .zip(probe.reference.iter().copied());
            let name = if several {
                let axes: Vec<(&String, &_)> = axes
                    .iter()
                    .filter(|(k, _)| by.contains(&k.as_str()))
                    .collect();
                format!("{}, {}", probe.reference_kind, label(axes))
            } else {
                probe.reference_kind.clone()
            };
            let mut series = Series::line(
                name,
                envelope(points.filter(|(_, r)| r.is_finite()).collect(), BUCKETS),
            );
            series.neutral = true;
            series
        })
        .collect()
}

/// A line of many points as the axes can show it: split into `buckets` runs of consecutive
/// points, each keeps its first, lowest, highest and last point in time order, so the drawn
/// line covers the same range in every pixel column (and the figure's data file stays small).
/// A line of at most 4 points per bucket is kept whole; the last point is always kept.
fn envelope(points: Vec<(f64, f64)>, buckets: usize) -> Vec<(f64, f64)> {
    if points.len() <= 4 * buckets {
        return points;
    }
    let size = points.len().div_ceil(buckets);
    let mut kept = Vec::with_capacity(4 * buckets);
    for chunk in points.chunks(size) {
        let by_y = |a: &&(f64, f64), b: &&(f64, f64)| a.1.total_cmp(&b.1);
        let (low, high) = (
            chunk.iter().min_by(by_y).expect("chunks are not empty"),
            chunk.iter().max_by(by_y).expect("chunks are not empty"),
        );
        let mut four = [chunk[0], *low, *high, chunk[chunk.len() - 1]];
        four.sort_by(|a, b| a.0.total_cmp(&b.0));
        for p in four {
            if kept.last() != Some(&p) {
                kept.push(p);
            }
        }
    }
    kept
}

/// E.g. `velocity x (m/s)`, `stress yy (Pa)`.
fn quantity_label(probe: &ProbeRecord) -> String {
    let component: String = probe
        .component
        .iter()
        .map(|&k| AXIS_NAMES.get(k as usize).copied().unwrap_or("?"))
        .collect();
    format!("{} {component} ({})", probe.quantity, probe.unit())
}

#[cfg(test)]
mod tests {
    use super::{envelope, references};
    use crate::output::ProbeRecord;
    use crate::params::{ParamValue, Params};

    /// References that agree to 1 % are drawn once, unlabelled; others once each, labelled with
    /// the `by` axes of the first run that has it.
    #[test]
    fn each_reference_is_drawn_once_and_named_when_there_are_several() {
        let probe = |last: f64| ProbeRecord {
            reference_kind: "static".into(),
            time: vec![0.0, 1.0],
            reference: vec![0.0, last],
            ..Default::default()
        };
        let axes = |g: f64| Params::from([("g".to_string(), ParamValue::Float(g))]);
        let (a, b, c) = (axes(9.81), axes(9.81), axes(4.0));
        let (pa, pb, pc) = (probe(-0.59), probe(-0.5905), probe(-0.24));
        let names = |pairs: &[(&Params, &ProbeRecord)]| -> Vec<String> {
            references(pairs, &["g"])
                .into_iter()
                .map(|s| s.label)
                .collect()
        };
        assert_eq!(names(&[(&a, &pa), (&b, &pb)]), ["static"]);
        assert_eq!(
            names(&[(&a, &pa), (&b, &pb), (&c, &pc)]),
            ["static, g=9.81", "static, g=4.0"]
        );
    }

    /// A short line is kept whole; a long one keeps each bucket's extremes and both ends.
    #[test]
    fn the_envelope_keeps_ends_and_extremes() {
        let short: Vec<(f64, f64)> = (0..8).map(|i| (i as f64, (i % 3) as f64)).collect();
        assert_eq!(envelope(short.clone(), 2), short);
        let long: Vec<(f64, f64)> = (0..1000)
            .map(|i| (i as f64, ((i as f64) * 0.37).sin()))
            .collect();
        let kept = envelope(long.clone(), 10);
        assert!(kept.len() <= 40, "{} points", kept.len());
        assert_eq!(kept.first(), long.first());
        assert_eq!(kept.last(), long.last());
        assert!(kept.windows(2).all(|w| w[0].0 < w[1].0));
        for chunk in long.chunks(100) {
            let high = chunk.iter().map(|p| p.1).fold(f64::MIN, f64::max);
            let low = chunk.iter().map(|p| p.1).fold(f64::MAX, f64::min);
            assert!(kept.iter().any(|p| p.1 == high) && kept.iter().any(|p| p.1 == low));
        }
    }
}
