//! The runs of an experiment ranked, for comparisons of whole methods such as the component
//! matrix (every valid shape x transfer x integrator): by their final error in one field and
//! norm into report.md, and by the time their steps take into costs.md, which like timings.csv
//! changes with every rerun and machine and so stays out of the committed results.

use std::cmp::Ordering;
use std::collections::HashMap;
use std::fmt::Write;

use super::format::general;
use super::group::{label, ordered_runs, selects, title_suffix};
use super::markdown;
use super::table::{per_run_rows, Table};
use crate::experiment::{Experiment, TableKind, TableSpec};
use crate::output::{RunStatus, RunSummary};

/// The final error a run is ranked by, when it finished with one.
fn ranked_error(run: &RunSummary, field: &str, norm: &str) -> Option<f64> {
    let error = run
        .final_norms
        .get(&(field.to_string(), norm.to_string()))?;
    (run.status == RunStatus::Ok && error.is_finite()).then_some(*error)
}

/// `runs` ordered by `key` ascending, the runs without one after them in the experiment's
/// order, with each run's rank (none for those without a key).
fn rank<'a>(
    runs: &[&'a RunSummary],
    key: impl Fn(&RunSummary) -> Option<f64>,
) -> Vec<(Option<usize>, &'a RunSummary)> {
    let mut keyed: Vec<(f64, &RunSummary)> = runs
        .iter()
        .filter_map(|run| Some((key(run)?, *run)))
        .collect();
    // A stable sort: equal keys keep the experiment's order.
    keyed.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(Ordering::Equal));
    let unranked = runs.iter().filter(|run| key(run).is_none());
    keyed
        .into_iter()
        .enumerate()
        .map(|(i, (_, run))| (Some(i + 1), run))
        .chain(unranked.map(|run| (None, *run)))
        .collect()
}

fn rank_text(rank: Option<usize>) -> String {
    rank.map_or_else(|| "-".to_string(), |r| r.to_string())
}

/// The table of a `ranking` entry: its runs from the smallest final error to the largest,
/// each with its error over the smallest; runs that did not finish come last, unranked.
pub fn by_error<'a>(
    experiment: &Experiment,
    runs: impl Iterator<Item = &'a RunSummary>,
    spec: &TableSpec,
) -> Option<Table> {
    let (field, norm) = spec.measure.as_ref()?;
    let runs = ordered_runs(runs);
    let ranked = rank(&runs, |run| ranked_error(run, field, norm));
    let best = ranked
        .first()
        .and_then(|(_, run)| ranked_error(run, field, norm));
    let in_order: Vec<&RunSummary> = ranked.iter().map(|(_, run)| *run).collect();
    let columns = [format!("{norm} {field} error"), "/ smallest".to_string()];
    let (mut header, rows) = per_run_rows(experiment, &in_order, columns, |run| {
        let error = ranked_error(run, field, norm);
        vec![
            error.map_or_else(String::new, |e| general(e, 4)),
            error
                .zip(best)
                .map_or_else(String::new, |(e, b)| general(e / b, 3)),
        ]
    });
    header.insert(0, "rank".to_string());
    let rows = ranked
        .iter()
        .zip(rows)
        .map(|((r, _), mut row)| {
            row.insert(0, rank_text(*r));
            row
        })
        .collect();
    let finished = ranked.iter().filter(|(r, _)| r.is_some()).count();
    Some(Table {
        title: format!(
            "Ranking by final {norm} {field} error{}",
            title_suffix(&label(&spec.select))
        ),
        note: format!(
            "The {} runs that finished, from the smallest {norm} {field} error over the \
             particles at the final time to the largest, then the {} that did not (status), \
             unranked. The ranking by cost, from the measured step times, is in costs.md beside \
             this report: it changes with every rerun, so it is not part of the committed \
             results.",
            finished,
            ranked.len() - finished
        ),
        header,
        rows,
    })
}

/// The time a run's steps take: the median step times the steps, so that neither the set-up
/// nor a step slowed by writing a sample or by another process counts.
fn stepping_seconds(run: &RunSummary) -> f64 {
    run.step_seconds * run.steps as f64
}

/// costs.md: for each `ranking` entry, its finished runs from the shortest stepping time to
/// the longest, then those that stopped early or do not step, with the time over the shortest,
/// the whole wall time and the run's rank by error. `None` when the experiment ranks nothing.
pub fn costs_md(experiment: &Experiment, runs: &[RunSummary]) -> Option<String> {
    let specs: Vec<&TableSpec> = experiment
        .tables
        .iter()
        .filter(|t| t.kind == TableKind::Ranking)
        .collect();
    if specs.is_empty() {
        return None;
    }
    let mut md = format!(
        "# {}: ranking by cost\n\nThe time each run's steps took as `mpmlab run` measured it: \
         the median wall time of a step (`step_seconds` in its file) times its steps, which \
         leaves out the set-up and the occasional slow step (a sample written, another \
         process); `wall s` is the whole run (`wall_seconds`). Runs that share the machine \
         (`--jobs`) slow each other, so compare factors, not percent. Rewritten by every \
         `mpmlab report`; not committed.\n\n",
        experiment.name
    );
    for spec in specs {
        let Some((field, norm)) = spec.measure.as_ref() else {
            continue;
        };
        let selected = ordered_runs(runs.iter().filter(|run| selects(&spec.select, &run.axes)));
        let error_rank: HashMap<&str, Option<usize>> =
            rank(&selected, |run| ranked_error(run, field, norm))
                .into_iter()
                .map(|(rank, run)| (run.run_id.as_str(), rank))
                .collect();
        let by_time = rank(&selected, |run| {
            let seconds = stepping_seconds(run);
            (run.status == RunStatus::Ok && seconds.is_finite()).then_some(seconds)
        });
        let fastest = by_time
            .first()
            .map(|(_, run)| stepping_seconds(run))
            .filter(|s| s.is_finite());
        let in_order: Vec<&RunSummary> = by_time.iter().map(|(_, run)| *run).collect();
        let columns = [
            "steps s".to_string(),
            "/ shortest".to_string(),
            "wall s".to_string(),
            format!("rank by {norm} {field} error"),
        ];
        let (mut header, rows) = per_run_rows(experiment, &in_order, columns, |run| {
            let error_rank = error_rank.get(run.run_id.as_str()).copied().flatten();
            let seconds = stepping_seconds(run);
            vec![
                general(seconds, 3),
                fastest.map_or_else(String::new, |f| general(seconds / f, 3)),
                general(run.wall_seconds, 3),
                rank_text(error_rank),
            ]
        });
        header.insert(0, "rank".to_string());
        let _ = writeln!(
            md,
            "## Ranking by stepping time{}\n",
            title_suffix(&label(&spec.select))
        );
        let rows = by_time.iter().zip(rows).map(|((r, _), mut row)| {
            row.insert(0, rank_text(*r));
            row
        });
        markdown::table(&mut md, &header, rows);
    }
    Some(md)
}
