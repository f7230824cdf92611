//! The tables that experiments ask for: u - u^h at the nodes in Gong's format (Tables
//! 4.1-4.2), the <p_i, p_i> of the orthogonal basis (Tran Figs 1-3), the errors of the
//! element-wise fits (Wobbes sec 2.1), measured stability limits (`stability`), and every
//! run's final error in one field and norm. They go into report.md; the numbers come from the
//! run files unchanged.

use super::format::general;
use super::group::{group_runs, label, ordered_runs, scoped_label, selects, title_suffix};
use super::probe_table;
use super::ranking;
use super::stability;
use super::table::{per_run_rows, Table};
use crate::experiment::{Experiment, TableKind, TableSpec};
use crate::output::{ElementRecord, ReconstructionRecord, RunStatus, RunSummary};

/// Every table the experiment's `tables` entries ask for, in their order; an error names a
/// probe no selected run records.
pub fn tables(experiment: &Experiment, runs: &[RunSummary]) -> Result<Vec<Table>, String> {
    let mut tables = Vec::new();
    for spec in &experiment.tables {
        let selected = runs.iter().filter(|run| selects(&spec.select, &run.axes));
        match spec.kind {
            TableKind::NodalErrors => tables.extend(nodal_errors(experiment, selected, spec)),
            TableKind::BasisNorms => tables.extend(basis_norms(selected)),
            TableKind::Stability => tables.extend(stability::tables(selected, spec)),
            TableKind::ElementFits => tables.extend(element_fits(experiment, selected)),
            TableKind::Errors => tables.extend(final_errors(experiment, selected, spec)),
            TableKind::Ranking => tables.extend(ranking::by_error(experiment, selected, spec)),
            TableKind::Probes => tables.extend(probe_table::table(experiment, selected, spec)?),
            TableKind::Conservation => tables.extend(conservation(experiment, selected, spec)),
        }
    }
    Ok(tables)
}

/// One table per group of the axes other than `columns`; a column per run of the group, in
/// the order of the experiment's runs, a row per node, numbered from 1 as in the thesis.
fn nodal_errors<'a>(
    experiment: &Experiment,
    runs: impl Iterator<Item = &'a RunSummary>,
    spec: &TableSpec,
) -> Vec<Table> {
    let column_axis = spec.columns.as_deref().unwrap_or_default();
    let order = |run: &RunSummary| {
        experiment
            .runs
            .iter()
            .position(|r| r.spec.run_id == run.run_id)
    };
    group_runs(runs, &[column_axis])
        .into_iter()
        .filter_map(|group| {
            let mut columns: Vec<(&RunSummary, &ReconstructionRecord)> = group
                .runs
                .iter()
                .filter_map(|run| Some((*run, run.unstepped.reconstruction()?)))
                .collect();
            columns.sort_by_key(|(run, _)| order(run));
            let nodes = columns.iter().map(|(_, r)| r.error.len()).max()?;
            let mut header = vec!["i".to_string()];
            header.extend(columns.iter().map(|(_, r)| format!("{} - u^h", r.formula)));
            let rows =
                (0..nodes)
                    .map(|i| {
                        let mut row = vec![(i + 1).to_string()];
                        row.extend(columns.iter().map(|(_, r)| {
                            r.error.get(i).map_or_else(String::new, |&e| decimals(e))
                        }));
                        row
                    })
                    .collect();
            Some(Table {
                title: format!(
                    "u(x_i) - u^h(x_i) at the nodes{}",
                    title_suffix(&scoped_label(&group.axes, &spec.select))
                ),
                note: "Four decimals as in Gong's Tables 4.1-4.2; an error below 1e-12 (rounding) \
                       is printed as 0, a node without data in reach as NaN."
                    .into(),
                header,
                rows,
            })
        })
        .collect()
}

/// One row per run: the points, <p_i, p_i> of each polynomial and how many are kept.
fn basis_norms<'a>(runs: impl Iterator<Item = &'a RunSummary>) -> Option<Table> {
    let rows: Vec<(&RunSummary, &ReconstructionRecord)> = runs
        .filter_map(|run| {
            let record = run.unstepped.reconstruction()?;
            record.basis.as_ref().map(|_| (run, record))
        })
        .collect();
    let terms = rows
        .iter()
        .filter_map(|(_, r)| r.basis.as_ref().map(|b| b.terms))
        .max()?;
    let mut header = vec!["run".to_string(), "points x_p".to_string()];
    header.extend((1..=terms).map(|i| format!("<p{i},p{i}>")));
    header.push("kept".into());
    let rows = rows
        .into_iter()
        .filter_map(|(run, r)| {
            let basis = r.basis.as_ref()?;
            let points: Vec<String> = r.data_x.iter().map(|&x| general(x, 4)).collect();
            let mut row = vec![label(&run.axes), points.join(", ")];
            row.extend(
                (0..terms).map(|i| match (basis.norms.get(i), basis.kept.get(i)) {
                    (Some(&norm), Some(0)) => format!("{} (dropped)", general(norm, 3)),
                    (Some(&norm), _) => general(norm, 4),
                    _ => String::new(),
                }),
            );
            let kept = basis.kept.iter().filter(|&&k| k != 0).count();
            row.push(format!("{kept} of {}", basis.terms));
            Some(row)
        })
        .collect();
    Some(Table {
        title: "Weighted orthogonal polynomials (Tran eq 16)".into(),
        note: "<p_i,p_i> = sum_p w(x_p - centre) p_i(x_p)^2; a polynomial is dropped (eq 17) when \
               this is at most 1e-10 of the weighted norm of its monomial, i.e. zero up to rounding."
            .into(),
        header,
        rows,
    })
}

/// One row per element-wise run in the order of the experiment: its axes, the RMS error and
/// the integrals at the Gauss points, and how many elements fell below the requested degree.
fn element_fits<'a>(
    experiment: &Experiment,
    runs: impl Iterator<Item = &'a RunSummary>,
) -> Option<Table> {
    let order = |run: &RunSummary| {
        experiment
            .runs
            .iter()
            .position(|r| r.spec.run_id == run.run_id)
    };
    let mut rows: Vec<(&RunSummary, &ElementRecord)> = runs
        .filter_map(|run| Some((run, run.unstepped.elements()?)))
        .collect();
    if rows.is_empty() {
        return None;
    }
    rows.sort_by_key(|(run, _)| order(run));
    let header = [
        "run",
        "u",
        "a_1",
        "Gauss points",
        "RMS error",
        "integral of u^h",
        "exact integral",
        "relative integral error",
        "elements below the degree",
    ]
    .map(String::from)
    .to_vec();
    let rows = rows
        .into_iter()
        .map(|(run, r)| {
            let elements = r.element_degree.len();
            let points = r.gauss.pow(r.dim as u32);
            vec![
                label(&run.axes),
                r.formula.clone(),
                r.conservation.clone(),
                format!("{points} per element"),
                general(r.rms, 5),
                general(r.integral, 10),
                general(r.exact_integral, 10),
                general(r.integral_error, 5),
                format!("{} of {elements} (degree {})", r.degraded, r.degree),
            ]
        })
        .collect();
    Some(Table {
        title: "Element-wise Taylor least squares (Wobbes sec 2.1)".into(),
        note: "RMS = sqrt(mean of (u - u^h)^2 over the Gauss points of every element); the \
               integral of u^h is the Gauss sum over the elements, its error relative to the exact \
               integral of u. a_1 fixed is the exact element mean (eq 5), fitted is least squares. \
               An element below the degree had data that could not support every Taylor \
               function of it, and its fit dropped the whole degree."
            .into(),
        header,
        rows,
    })
}

/// One row per run: its final error in the spec's field and norm (empty for a run that stopped
/// before its final time), then for each probe of that field with a reference the wiggle
/// measures of its history: the total variation against the reference's and the overshoot
/// past the reference's range.
fn final_errors<'a>(
    experiment: &Experiment,
    runs: impl Iterator<Item = &'a RunSummary>,
    spec: &TableSpec,
) -> Option<Table> {
    let (field, norm) = spec.measure.as_ref()?;
    let runs = ordered_runs(runs);
    if runs.is_empty() {
        return None;
    }
    let probes = compared_probes(&runs, field);
    let mut columns = vec![format!("{norm} {field} error")];
    for (name, unit) in &probes {
        columns.push(format!("{name}: TV / exact TV"));
        columns.push(format!("{name}: overshoot ({unit})"));
    }
    let (header, rows) = per_run_rows(experiment, &runs, columns, |run| {
        let finished = run.status == RunStatus::Ok;
        let shown = |value: Option<f64>| {
            value
                .filter(|_| finished)
                .map_or_else(String::new, |e| general(e, 4))
        };
        let error = run.final_norms.get(&(field.clone(), norm.clone()));
        let mut cells = vec![shown(error.copied())];
        for (name, _) in &probes {
            let wiggles = run.probe(name).map(|p| p.wiggles());
            cells.push(shown(
                wiggles.map(|w| w.total_variation / w.reference_total_variation),
            ));
            cells.push(shown(wiggles.map(|w| w.overshoot)));
        }
        cells
    });
    Some(Table {
        title: format!(
            "Final {norm} {field} error{}",
            title_suffix(&label(&spec.select))
        ),
        note: format!(
            "The {norm} norm of the {field} error over the particles at the final time (rms: \
             sqrt(sum_p e_p^2 / N_p), Molinos eq 40; l2: sqrt(sum_p V_p e_p^2)); NaN where the \
             benchmark has no exact solution, empty for a run that did not finish.{}",
            if probes.is_empty() {
                ""
            } else {
                " For each probe of the field, the total variation of its history, \
                 sum_k |v_(k+1) - v_k| over every step, divided by the exact history's (1: no \
                 ringing; below 1: damped), and the overshoot, how far the history goes past \
                 the exact range (`/probes/<name>` attributes)."
            }
        ),
        header,
        rows,
    })
}

/// One row per run: the largest relative mass and momentum errors of its mappings (Wobbes
/// Table 3), from `/conservation`.
fn conservation<'a>(
    experiment: &Experiment,
    runs: impl Iterator<Item = &'a RunSummary>,
    spec: &TableSpec,
) -> Option<Table> {
    let runs = ordered_runs(runs);
    if runs.is_empty() {
        return None;
    }
    let columns = ["mass error", "momentum error"].map(String::from);
    let (header, rows) = per_run_rows(experiment, &runs, columns, |run| {
        vec![
            general(run.max_mass_error, 4),
            general(run.max_momentum_error, 4),
        ]
    });
    Some(Table {
        title: format!(
            "Largest relative mass and momentum errors{}",
            title_suffix(&label(&spec.select))
        ),
        note: "Over every particle-to-grid mapping of the run (each step's transfer and MUSL's \
               velocity remap), the largest |sum_i m_i - sum_p M_p| / sum_p M_p and \
               |sum_i p_i - sum_p M_p v_p| / sum_p M_p |v_p| (`/conservation` attributes \
               `max_mass_error`, `max_momentum_error`; Wobbes et al. Table 3); NaN for a run \
               that never mapped."
            .to_string(),
        header,
        rows,
    })
}

/// The probes of `field` that have a reference, by name and unit, in the order of the first
/// run that records each.
fn compared_probes(runs: &[&RunSummary], field: &str) -> Vec<(String, &'static str)> {
    let mut probes: Vec<(String, &'static str)> = Vec::new();
    for probe in runs.iter().flat_map(|run| &run.probes) {
        let compared = probe.quantity == field && probe.reference_kind == "exact";
        if compared && !probes.iter().any(|(name, _)| name == &probe.name) {
            probes.push((probe.name.clone(), probe.unit()));
        }
    }
    probes
}

/// Four decimals; rounding-level values as 0.
fn decimals(e: f64) -> String {
    if e.abs() < 1e-12 {
        "0".into()
    } else {
        format!("{e:.4}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_decimals_with_rounding_as_zero() {
        assert_eq!(decimals(-0.068_749_9), "-0.0687");
        assert_eq!(decimals(0.130_625), "0.1306");
        assert_eq!(decimals(3e-17), "0");
        assert_eq!(decimals(f64::NAN), "NaN");
    }
}
