//! report.md: everything a reader needs on one page. Wall-clock times are left out so that
//! rerunning an identical experiment leaves the committed report unchanged.

use std::fmt::Write;

use super::check::{describe, CheckFailure};
use super::claims::{claim_figures, Outcome, COLUMNS};
use super::figures::{FieldMap, Figure};
use super::format::{general, rate};
use super::group::{self, label, ordered_runs, RELATIVE_ROUND_OFF};
use super::table::Table;
use super::RateRow;
use crate::benchmarks::BenchmarkKind;
use crate::experiment::Experiment;
use crate::output::{RunStatus, RunSummary, UnreadableRun, REFERENCE_NORM, SHAPE_FIELDS};

/// What the report computed besides the rates: its tables, figures, field maps and the
/// papers' claims against ours; and the run files it could not read.
pub struct Contents<'a> {
    pub tables: &'a [Table],
    pub figures: &'a [Figure],
    pub maps: &'a [FieldMap],
    pub claims: &'a [Outcome<'a>],
    pub unreadable: &'a [UnreadableRun],
}

pub fn report_md(
    experiment: &Experiment,
    runs: &[RunSummary],
    rates: &[RateRow],
    contents: &Contents,
    check: Option<&[CheckFailure]>,
) -> String {
    let Contents {
        tables,
        figures,
        maps,
        claims,
        unreadable,
    } = *contents;
    let runs = ordered_runs(runs);
    let mut md = format!("# {}\n\n", experiment.name);
    if !experiment.description.is_empty() {
        let _ = writeln!(md, "{}\n", experiment.description);
    }
    overview(&mut md, experiment, &runs);
    runs_table(&mut md, experiment, &runs);
    reference_table(&mut md, experiment, &runs);
    if experiment.kind == BenchmarkKind::ShapeFunctions {
        consistency_table(&mut md, experiment, &runs);
    } else {
        rates_table(&mut md, rates);
    }
    unfinished(&mut md, experiment, &runs);
    unreadable_files(&mut md, unreadable);
    claims_table(&mut md, claims, figures);
    if !tables.is_empty() {
        md.push_str("## Tables\n\n");
        for t in tables {
            let _ = writeln!(md, "### {}\n\n{}\n", t.title, t.note);
            table(&mut md, &t.header, t.rows.iter().cloned());
        }
    }
    if !figures.is_empty() || !maps.is_empty() {
        md.push_str("## Figures\n\n");
        let captions = figures.iter().map(|f| (f.title.clone(), &f.file));
        for (caption, file) in captions.chain(maps.iter().map(|m| (m.caption(), &m.file))) {
            let link = file.to_string_lossy().replace('\\', "/");
            let _ = writeln!(md, "![{caption}]({link})\n");
        }
    }
    if let Some(failures) = check {
        checks(&mut md, experiment, failures);
    }
    md
}

fn overview(md: &mut String, experiment: &Experiment, runs: &[&RunSummary]) {
    let _ = writeln!(md, "- Benchmark: `{}`", experiment.benchmark);
    for axis in &experiment.axes {
        let mut values: Vec<String> = Vec::new();
        for value in runs.iter().filter_map(|r| r.axes.get(axis)) {
            let text = value.to_string();
            if !values.contains(&text) {
                values.push(text);
            }
        }
        let _ = writeln!(md, "- Axis `{axis}`: {}", values.join(", "));
    }
    let count = |status| runs.iter().filter(|r| r.status == status).count();
    let _ = writeln!(
        md,
        "- Runs: {} ({} ok, {} diverged, {} failed)\n",
        runs.len(),
        count(RunStatus::Ok),
        count(RunStatus::Diverged),
        count(RunStatus::Failed)
    );
}

fn runs_table(md: &mut String, experiment: &Experiment, runs: &[&RunSummary]) {
    md.push_str("## Runs\n\n");
    // Reconstruction runs take no time steps.
    let stepped = experiment.kind.steps();
    let mut header = vec!["run".to_string()];
    header.extend(experiment.axes.iter().cloned());
    header.extend(["h", "status"].map(String::from));
    if stepped {
        header.push("steps".into());
    }
    let rows = runs.iter().map(|run| {
        let mut row = vec![format!("`{}`", run.run_id)];
        row.extend(group::axis_values(experiment, run));
        row.extend([h_text(run.h), run.status.as_str().to_string()]);
        if stepped {
            row.push(run.steps.to_string());
        }
        row
    });
    table(md, &header, rows);
}

/// The relative l2 errors against the reference run (`collect::compare`), one row per run.
fn reference_table(md: &mut String, experiment: &Experiment, runs: &[&RunSummary]) {
    let Some(select) = &experiment.reference else {
        return;
    };
    md.push_str(
        "## Errors against the reference run

",
    );
    let _ = writeln!(
        md,
        "Relative l2 error at the final time against the run with {}: \
         sqrt(sum_p V_p (f_p - f_ref(X_p))^2) / sqrt(sum_p V_p f_ref(X_p)^2) over the run's \
         particles, with the reference field interpolated in the reference coordinate X \
         piecewise linearly through the reference's points (element centroids for ULFEM) and \
         extended linearly past the first and last; the displacement is x - X. The same \
         numbers are the `reference_<field>` columns of summary.csv and the norm `reference` \
         of rates.csv.\n",
        label(select)
    );
    let fields = ["displacement", "velocity", "stress"];
    let mut header = vec!["run".to_string()];
    header.extend(experiment.axes.iter().cloned());
    header.push("h".into());
    header.extend(fields.map(String::from));
    let rows = runs.iter().map(|run| {
        let mut row = vec![format!("`{}`", run.run_id)];
        row.extend(group::axis_values(experiment, run));
        row.push(h_text(run.h));
        row.extend(fields.map(|field| {
            let key = (field.to_string(), REFERENCE_NORM.to_string());
            run.final_norms
                .get(&key)
                .map_or_else(String::new, |&e| general(e, 4))
        }));
        row
    });
    table(md, &header, rows);
}

/// The largest consistency errors of each shape-function run over its points, and how LME's
/// Newton iterations went.
fn consistency_table(md: &mut String, experiment: &Experiment, runs: &[&RunSummary]) {
    md.push_str(
        "## Consistency of the bases

",
    );
    md.push_str(
        "Largest over the evaluation points, the sums over every node of each point's \
         stencil: partition |sum N_a - 1|, moment |sum N_a x_a - x| / h, gradient \
         h |sum grad N_a|, gradient_moment |sum grad N_a (x) x_a - I| (Frobenius); then the \
         LME points where Newton stopped short and the most Newton steps at any point.\n\n",
    );
    let mut header = vec!["run".to_string()];
    header.extend(experiment.axes.iter().cloned());
    header.extend(SHAPE_FIELDS.map(String::from));
    header.extend(["Newton failures", "most Newton steps"].map(String::from));
    let rows = runs.iter().filter_map(|run| {
        let record = run.unstepped.shape_functions()?;
        let mut row = vec![format!("`{}`", run.run_id)];
        row.extend(group::axis_values(experiment, run));
        row.extend(record.max_errors.map(|e| general(e, 3)));
        row.extend([record.failures, record.max_newton_steps].map(|n| n.to_string()));
        Some(row)
    });
    table(md, &header, rows);
}

fn rates_table(md: &mut String, rates: &[RateRow]) {
    md.push_str("## Convergence rates\n\n");
    if rates.is_empty() {
        md.push_str(
            "No rate could be fitted: no group has two finished runs with a positive error.\n\n",
        );
        return;
    }
    let _ = writeln!(
        md,
        "Least-squares slope of log10(final error) against log10(h), over the runs that finished; \
         relative errors (norms `integral` and `reference`) at or below {RELATIVE_ROUND_OFF:e} \
         are round-off and left out of the fit. The segments are the slopes between successive \
         runs from the coarsest h to the finest.\n"
    );
    let header = [
        "group", "field", "norm", "rate", "r2", "points", "h range", "segments",
    ]
    .map(String::from);
    let rows = rates.iter().map(|r| {
        vec![
            if r.group.is_empty() {
                "(all)".to_string()
            } else {
                r.group.clone()
            },
            r.field.clone(),
            r.norm.clone(),
            rate(r.rate),
            format!("{:.3}", r.r2),
            r.n.to_string(),
            format!("{} to {}", h_text(r.h_min), h_text(r.h_max)),
            r.segments
                .iter()
                .map(|&s| rate(s))
                .collect::<Vec<_>>()
                .join(", "),
        ]
    });
    table(md, &header, rows);
}

/// The run files the report could not read, so that it is plain which runs its tables,
/// rates and figures lack.
fn unreadable_files(md: &mut String, files: &[UnreadableRun]) {
    if files.is_empty() {
        return;
    }
    md.push_str(
        "## Unreadable run files\n\nThese files in `runs/` could not be read; the tables, rates \
         and figures leave them out, and `mpmlab report --check` fails while they are there. \
         Remove them and `mpmlab run` computes the runs whose file is missing.\n\n",
    );
    let rows = files.iter().map(|f| {
        let name = f.file.to_string_lossy().replace('\\', "/");
        vec![format!("`{name}`"), f.reason.clone()]
    });
    table(md, &["file".into(), "reason".into()], rows);
}

/// Diverged and failed runs are left out of fits and convergence figures; this says which
/// and why.
fn unfinished(md: &mut String, experiment: &Experiment, runs: &[&RunSummary]) {
    let bad: Vec<&&RunSummary> = runs.iter().filter(|r| r.status != RunStatus::Ok).collect();
    if bad.is_empty() {
        return;
    }
    let studies_stability = experiment.figures.iter().any(|f| f.stability.is_some())
        || experiment.tables.iter().any(|t| t.stability.is_some());
    md.push_str(if studies_stability {
        "## Diverged and failed runs\n\nThese runs are left out of the rates and convergence \
         figures; the stability figures and tables count a diverged run as unstable.\n\n"
    } else {
        "## Diverged and failed runs\n\nThese runs are left out of the rates and figures.\n\n"
    });
    let header = ["run", "axes", "status", "message"].map(String::from);
    let rows = bad.iter().map(|run| {
        vec![
            format!("`{}`", run.run_id),
            label(&run.axes),
            run.status.as_str().to_string(),
            run.message.clone(),
        ]
    });
    table(md, &header, rows);
}

/// The papers' numbers beside ours (`paper_claims`), each with its figures.
fn claims_table(md: &mut String, claims: &[Outcome], figures: &[Figure]) {
    if claims.is_empty() {
        return;
    }
    md.push_str(
        "## Paper claims\n\nEach number the papers state, beside what the runs measure for it: \
         reproduced when every measured value is within the tolerance (absolute for a rate, \
         relative for an error); otherwise the difference and where docs/NOTES.md isolates it.\n\n",
    );
    let rows = claims.iter().map(|o| {
        let links: Vec<String> = claim_figures(o, figures)
            .map(|f| {
                let link = f.file.to_string_lossy().replace('\\', "/");
                let stem = f.file.file_stem().unwrap_or_default().to_string_lossy();
                format!("[{stem}]({link})")
            })
            .collect();
        o.cells(links.join(", "))
    });
    table(md, &COLUMNS.map(String::from), rows);
}

fn checks(md: &mut String, experiment: &Experiment, failures: &[CheckFailure]) {
    md.push_str("## Checks\n\n");
    if experiment.expect.is_empty() {
        md.push_str("The experiment states no expectations.\n\n");
        return;
    }
    for e in &experiment.expect {
        let mine: Vec<&CheckFailure> = failures.iter().filter(|f| f.line == e.line).collect();
        let verdict = if mine.is_empty() { "pass" } else { "FAIL" };
        let _ = writeln!(md, "- **{verdict}** line {}: {}", e.line, describe(e));
        for failure in mine {
            let _ = writeln!(md, "  - {}", failure.message);
        }
    }
    md.push('\n');
}

pub(super) fn table(md: &mut String, header: &[String], rows: impl Iterator<Item = Vec<String>>) {
    let line = |cells: &[String]| {
        let cells: Vec<String> = cells.iter().map(|c| cell(c)).collect();
        format!("| {} |\n", cells.join(" | "))
    };
    md.push_str(&line(header));
    md.push_str(&line(&vec!["---".to_string(); header.len()]));
    for row in rows {
        md.push_str(&line(&row));
    }
    md.push('\n');
}

/// Cell sizes are often 1/2^k: six digits show 1/64 = 0.015625 exactly.
fn h_text(h: f64) -> String {
    general(h, 6)
}

/// Table cells cannot hold pipes or line breaks.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}
