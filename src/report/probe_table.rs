//! The probes table: how one probe's history settles against its reference after a time, one
//! row per run (Molinos Figs 10-11: which runs stay stable, and when the others leave). The
//! numbers come from `/probes/<name>` unchanged.

use super::format::general;
use super::group::{label, ordered_runs, recorded_probes, title_suffix};
use super::table::{per_run_rows, Table};
use crate::experiment::{Experiment, ProbeWindow, TableSpec};
use crate::output::{ProbeRecord, RunSummary};

/// The table of `spec.probe` over the selected runs; an error when none of them records it.
pub fn table<'a>(
    experiment: &Experiment,
    runs: impl Iterator<Item = &'a RunSummary>,
    spec: &TableSpec,
) -> Result<Option<Table>, String> {
    let Some(window) = &spec.probe else {
        return Ok(None);
    };
    let runs = ordered_runs(runs);
    if runs.is_empty() {
        return Ok(None);
    }
    let Some(unit) = runs
        .iter()
        .find_map(|run| run.probe(&window.name))
        .map(|p| p.unit())
    else {
        return Err(format!(
            "probes table: no selected run of {} records the probe '{}'; the runs record: {}",
            experiment.name,
            window.name,
            recorded_probes(runs.iter().copied())
        ));
    };
    let columns = [
        "mean",
        "sd",
        "reference at the end",
        "largest |value - reference|",
    ]
    .map(|c| format!("{c} ({unit})"))
    .into_iter()
    .chain(["leaves at (s)".to_string()]);
    let (header, rows) = per_run_rows(experiment, &runs, columns, |run| {
        match run.probe(&window.name).and_then(|p| Settled::of(p, window)) {
            Some(s) => {
                let mut cells: Vec<String> = [s.mean, s.sd, s.reference, s.largest_deviation]
                    .map(|x| general(x, 4))
                    .into();
                cells.push(
                    s.leaves_at
                        .map_or_else(|| "never".to_string(), |t| general(t, 4)),
                );
                cells
            }
            None => vec![String::new(); 5],
        }
    });
    Ok(Some(Table {
        title: format!(
            "Probe {} after t = {}{}",
            window.name,
            general(window.after, 4),
            title_suffix(&label(&spec.select))
        ),
        note: format!(
            "Over the recorded steps with t >= {after} s: the mean and standard deviation of the \
             probe's value, its reference at the last of them, the largest distance from the \
             reference, and the first time the value is farther than {tolerance} {unit} from \
             it (`never`: it stays within). A diverged run is judged up to where it stopped; \
             empty where it recorded nothing after t = {after} s.",
            after = general(window.after, 4),
            tolerance = general(window.tolerance, 4),
        ),
        header,
        rows,
    }))
}

/// A probe's history over t >= after.
struct Settled {
    mean: f64,
    sd: f64,
    reference: f64,
    largest_deviation: f64,
    leaves_at: Option<f64>,
}

impl Settled {
    fn of(probe: &ProbeRecord, window: &ProbeWindow) -> Option<Self> {
        let points: Vec<(f64, f64, f64)> = probe
            .time
            .iter()
            .zip(&probe.value)
            .zip(&probe.reference)
            .filter(|((t, _), _)| **t >= window.after)
            .map(|((&t, &v), &r)| (t, v, r))
            .collect();
        let &(_, _, reference) = points.last()?;
        let n = points.len() as f64;
        let mean = points.iter().map(|p| p.1).sum::<f64>() / n;
        let variance = points.iter().map(|p| (p.1 - mean).powi(2)).sum::<f64>() / n;
        let deviation = |p: &(f64, f64, f64)| (p.1 - p.2).abs();
        Some(Settled {
            mean,
            sd: variance.sqrt(),
            reference,
            largest_deviation: points.iter().map(deviation).fold(0.0, f64::max),
            leaves_at: points
                .iter()
                .find(|p| deviation(p) > window.tolerance)
                .map(|p| p.0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settles_and_leaves() {
        let probe = ProbeRecord {
            time: vec![0.0, 1.0, 2.0, 3.0, 4.0],
            value: vec![5.0, 1.0, 1.2, 0.8, 2.0],
            reference: vec![0.0, 1.0, 1.0, 1.0, 1.0],
            ..Default::default()
        };
        let window = ProbeWindow {
            name: String::new(),
            after: 1.0,
            tolerance: 0.5,
        };
        let s = Settled::of(&probe, &window).unwrap();
        assert!((s.mean - 1.25).abs() < 1e-15);
        let sd = ((0.0625 + 0.0025 + 0.2025 + 0.5625) / 4.0f64).sqrt();
        assert!((s.sd - sd).abs() < 1e-15);
        assert_eq!(s.reference, 1.0);
        assert!((s.largest_deviation - 1.0).abs() < 1e-15);
        assert_eq!(s.leaves_at, Some(4.0));
        let never = ProbeWindow {
            tolerance: 2.0,
            ..window.clone()
        };
        assert_eq!(Settled::of(&probe, &never).unwrap().leaves_at, None);
        let late = ProbeWindow {
            after: 10.0,
            ..window
        };
        assert!(Settled::of(&probe, &late).is_none());
    }
}
