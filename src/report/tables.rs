//! summary.csv, timings.csv, rates.csv and each figure's data, written by hand: the quoting
//! rules are all we need of CSV.

use std::borrow::Cow;

use super::figures::{FieldMap, Figure};
use super::format::exact;
use super::group::{self, ordered_runs};
use super::RateRow;
use crate::experiment::Experiment;
use crate::output::{Measures, RunStatus, RunSummary};

const RATE_COLUMNS: [&str; 10] = [
    "experiment",
    "group",
    "field",
    "norm",
    "rate",
    "intercept",
    "r2",
    "n",
    "h_min",
    "h_max",
];

/// One run per row, grouped and coarsest first: identity, matrix values, status, time steps
/// (for simulations), every final error norm, then the message (last, as it is the field
/// most likely to need quoting).
pub fn summary_csv(experiment: &Experiment, runs: &[RunSummary]) -> String {
    let stepped = experiment.kind.steps();
    let measures = experiment.measures();
    let mut header: Vec<String> = vec!["run_id".into()];
    header.extend(experiment.axes.iter().cloned());
    header.extend(["h", "status"].map(String::from));
    if stepped {
        // A matrix axis `dt` holds the requested step; the run's own (shortened to hit
        // t_end) then gets a name of its own, so that no two columns share one.
        let taken = experiment.axes.iter().any(|a| a == "dt");
        header.extend(["steps", if taken { "dt_used" } else { "dt" }].map(String::from));
    }
    header.extend(norm_columns(measures).map(|(field, norm)| format!("{norm}_{field}")));
    header.push("message".into());

    let rows = ordered_runs(runs).into_iter().map(|run| {
        let mut row = vec![run.run_id.clone()];
        row.extend(group::axis_values(experiment, run));
        row.extend([exact(run.h), run.status.as_str().to_string()]);
        if stepped {
            row.extend([run.steps.to_string(), exact(run.dt)]);
        }
        // A run that stopped early has no final errors: its last sample may be t = 0.
        let finished = run.status == RunStatus::Ok;
        row.extend(norm_columns(measures).map(|(field, norm)| {
            run.final_norms
                .get(&(field.to_string(), norm.to_string()))
                .filter(|_| finished)
                .map(|&e| exact(e))
                .unwrap_or_default()
        }));
        row.push(run.message.clone());
        row
    });
    csv(&header, rows)
}

/// How long each run took, in the order of summary.csv: kept apart from it because it
/// changes with every rerun and machine, while summary.csv reproduces byte for byte.
pub fn timings_csv(runs: &[RunSummary]) -> String {
    let header = ["run_id", "status", "steps", "wall_seconds"].map(String::from);
    let rows = ordered_runs(runs).into_iter().map(|run| {
        vec![
            run.run_id.clone(),
            run.status.as_str().to_string(),
            run.steps.to_string(),
            exact(run.wall_seconds),
        ]
    });
    csv(&header, rows)
}

/// A figure's series exactly as plotted, one row per point: `series` (the legend label),
/// `role` (`marker` for a measured point, `line` for a point of the drawn line, a fit or a
/// curve), x and y, written beside the PNG so that the figure can be redrawn elsewhere.
pub fn figure_csv(figure: &Figure) -> String {
    let header = [
        "series".to_string(),
        "role".to_string(),
        figure.x_label.clone(),
        figure.y_label.clone(),
    ];
    let rows = figure.series.iter().flat_map(|s| {
        let points = |role: &'static str, points: &[(f64, f64)]| {
            points
                .iter()
                .map(|&(x, y)| vec![s.label.clone(), role.to_string(), exact(x), exact(y)])
                .collect::<Vec<_>>()
        };
        let mut rows = points("marker", &s.markers);
        rows.extend(points("line", &s.line));
        rows.extend(points("fit", &s.fit));
        rows
    });
    csv(&header, rows)
}

/// A field map's cells and markers exactly as drawn, one row per point: `panel` (its label),
/// `role` (`cell` for a filled rectangle, `marker` for a point drawn over them, which has no
/// size or value), the centre x and y, the rectangle's width and height (in the units of x
/// and y) and the value its colour shows.
pub fn map_csv(map: &FieldMap) -> String {
    let header = [
        "panel".to_string(),
        "role".to_string(),
        map.x_label.clone(),
        map.y_label.clone(),
        "width".to_string(),
        "height".to_string(),
        map.value_label.clone(),
    ];
    let rows = map.panels.iter().flat_map(|panel| {
        let cells = panel.cells.iter().map(|c| {
            vec![
                panel.label.clone(),
                "cell".to_string(),
                exact(c.x),
                exact(c.y),
                exact(c.width),
                exact(c.height),
                exact(c.value),
            ]
        });
        let markers = panel.markers.iter().map(|&(x, y)| {
            let mut row = vec![
                panel.label.clone(),
                "marker".to_string(),
                exact(x),
                exact(y),
            ];
            row.extend([String::new(), String::new(), String::new()]);
            row
        });
        cells.chain(markers).collect::<Vec<_>>()
    });
    csv(&header, rows)
}

pub fn rates_csv(rates: &[RateRow]) -> String {
    let rows = rates.iter().map(|r| {
        vec![
            r.experiment.clone(),
            r.group.clone(),
            r.field.clone(),
            r.norm.clone(),
            exact(r.rate),
            exact(r.intercept),
            exact(r.r2),
            r.n.to_string(),
            exact(r.h_min),
            exact(r.h_max),
        ]
    });
    csv(&RATE_COLUMNS.map(String::from), rows)
}

/// (field, norm) pairs, norm-major: all l2 columns, then all rms (or max) columns.
fn norm_columns(measures: Measures) -> impl Iterator<Item = (&'static str, &'static str)> {
    measures
        .norms
        .iter()
        .flat_map(move |&norm| measures.fields.iter().map(move |&field| (field, norm)))
}

fn csv(header: &[String], rows: impl IntoIterator<Item = Vec<String>>) -> String {
    let mut out = String::new();
    for row in std::iter::once(header.to_vec()).chain(rows) {
        let fields: Vec<Cow<str>> = row.iter().map(|f| quote(f)).collect();
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// RFC 4180: a field holding a comma, quote or line break is quoted, inner quotes doubled.
fn quote(field: &str) -> Cow<'_, str> {
    if field.contains([',', '"', '\n', '\r']) {
        Cow::Owned(format!("\"{}\"", field.replace('"', "\"\"")))
    } else {
        Cow::Borrowed(field)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_only_when_needed() {
        assert_eq!(quote("plain"), "plain");
        assert_eq!(quote("a,b"), "\"a,b\"");
        assert_eq!(quote("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(quote("two\nlines"), "\"two\nlines\"");
    }

    #[test]
    fn rows_join_quoted_fields() {
        let header = ["a".to_string(), "b".to_string()];
        let text = csv(&header, [vec!["1".to_string(), "x, y".to_string()]]);
        assert_eq!(text, "a,b\n1,\"x, y\"\n");
    }
}
