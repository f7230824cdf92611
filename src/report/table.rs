//! A table of report.md: its heading, a note on how to read it, the header and the rows; and
//! the rows of a table with one row per run.

use super::group::axis_values;
use crate::experiment::Experiment;
use crate::output::RunSummary;

/// A table with a heading and a note on how to read it.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    pub title: String,
    pub note: String,
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

/// The header and rows of a table with one row per run, in the order of the run tables: the
/// run's axis values and status, then `columns`, filled by `cells`.
pub(super) fn per_run_rows(
    experiment: &Experiment,
    runs: &[&RunSummary],
    columns: impl IntoIterator<Item = String>,
    cells: impl Fn(&RunSummary) -> Vec<String>,
) -> (Vec<String>, Vec<Vec<String>>) {
    let mut header = experiment.axes.clone();
    header.push("status".to_string());
    header.extend(columns);
    let rows = runs
        .iter()
        .map(|run| {
            let mut row: Vec<String> = axis_values(experiment, run).collect();
            row.push(run.status.as_str().to_string());
            row.extend(cells(run));
            row
        })
        .collect();
    (header, rows)
}
