//! Reports over a results directory: summary.csv, rates.csv, figures and report.md, and
//! the `--check` of an experiment's expectations.
//!
//! Runs that differ only in the refinement axis (`cells`) form a group; each group's final
//! errors are fitted against h as a power law per field and norm.

mod check;
pub mod claims;
mod colour_map;
pub mod figures;
mod fit;
mod format;
mod group;
pub mod index;
mod map_plot;
mod markdown;
mod plot;
mod pointwise;
mod probe_table;
mod ranking;
pub mod stability;
mod style;
mod table;
mod tables;
mod units;

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

pub use check::{check, CheckFailure};

use crate::experiment::Experiment;
use crate::output::{remove_dead_temps, write_all_atomically, RunSummary, UnreadableRun};
use crate::params::Params;

/// The fitted convergence rate of one (group, field, norm): `log10(error) = intercept +
/// rate * log10(h)`.
#[derive(Clone, Debug, PartialEq)]
pub struct RateRow {
    pub experiment: String,
    /// `key=value` pairs of `group_axes`, sorted by key; empty when cells is the only axis.
    pub group: String,
    /// The run axes minus the refinement axis.
    pub group_axes: Params,
    pub field: String,
    pub norm: String,
    pub rate: f64,
    pub intercept: f64,
    /// Coefficient of determination of the fit in log-log space.
    pub r2: f64,
    /// Number of runs in the fit.
    pub n: usize,
    pub h_min: f64,
    pub h_max: f64,
    /// The slope between each pair of successive points from the coarsest h to the finest:
    /// where the fit hides a bend or a floor.
    pub segments: Vec<f64>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// Written figures, relative to the report directory.
    pub figures: Vec<PathBuf>,
}

/// Writes summary.csv, timings.csv, rates.csv, figures/*.png (plots, then field maps) with
/// their data figures/*.csv, and report.md into `dir`; report.md lists the `unreadable` run
/// files, and gets a "Checks" section when `check` is given.
///
/// Every file is computed before any is written, then all are written under temporary names
/// and renamed into place (`output::write_all_atomically`): an error on the way, a full disk
/// included, leaves the previous report as it was. The figures of an earlier report that
/// this one no longer draws are removed last.
pub fn write_report(
    dir: &Path,
    experiment: &Experiment,
    runs: &[RunSummary],
    unreadable: &[UnreadableRun],
    rates: &[RateRow],
    check: Option<&[CheckFailure]>,
) -> io::Result<Report> {
    let figures = figures::plan(experiment, runs).map_err(io::Error::other)?;
    let maps = figures::plan_maps(experiment, runs, &figures).map_err(io::Error::other)?;
    let tables = pointwise::tables(experiment, runs).map_err(io::Error::other)?;
    let figure_dir = dir.join("figures");
    fs::create_dir_all(&figure_dir)?;
    remove_dead_temps(dir)?;
    remove_dead_temps(&figure_dir)?;
    let mut outputs: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    for figure in &figures {
        let png = dir.join(&figure.file);
        outputs.push((png.clone(), plot::render(&png, figure)?));
        outputs.push((png.with_extension("csv"), tables::figure_csv(figure).into()));
    }
    for map in &maps {
        let png = dir.join(&map.file);
        outputs.push((png.clone(), map_plot::render(&png, map)?));
        outputs.push((png.with_extension("csv"), tables::map_csv(map).into()));
    }
    let claims = claims::evaluate(experiment, rates, runs);
    let contents = markdown::Contents {
        tables: &tables,
        figures: &figures,
        maps: &maps,
        claims: &claims,
        unreadable,
    };
    let md = markdown::report_md(experiment, runs, rates, &contents, check);
    outputs.extend([
        (
            dir.join("summary.csv"),
            tables::summary_csv(experiment, runs).into(),
        ),
        (dir.join("timings.csv"), tables::timings_csv(runs).into()),
        (dir.join("rates.csv"), tables::rates_csv(rates).into()),
        (dir.join("report.md"), md.into()),
    ]);
    if let Some(costs) = ranking::costs_md(experiment, runs) {
        outputs.push((dir.join("costs.md"), costs.into()));
    }
    write_all_atomically(&outputs)?;
    let files: Vec<PathBuf> = figures
        .iter()
        .map(|f| f.file.clone())
        .chain(maps.iter().map(|m| m.file.clone()))
        .collect();
    remove_stale_figures(&figure_dir, &files)?;
    Ok(Report { figures: files })
}

/// PNGs and their data left by an earlier report whose figure this report no longer draws
/// would otherwise be committed beside the current ones.
fn remove_stale_figures(figure_dir: &Path, files: &[PathBuf]) -> io::Result<()> {
    for entry in fs::read_dir(figure_dir)? {
        let path = entry?.path();
        let ours = path.extension().is_some_and(|e| e == "png" || e == "csv");
        let current = files
            .iter()
            .any(|f| path.with_extension("png").ends_with(f));
        if ours && !current {
            fs::remove_file(&path)?;
        }
    }
    Ok(())
}

/// Fits every (group, field, norm) with at least two finished runs of positive, finite
/// error that is not round-off (`group::fit_points`), sorted by group, then field and norm in
/// the order of the experiment's measures.
pub fn fit_rates(experiment: &Experiment, runs: &[RunSummary]) -> Vec<RateRow> {
    let measures = experiment.measures();
    let mut rows = Vec::new();
    for g in group::group_runs(runs, &[group::REFINEMENT_AXIS]) {
        for &field in measures.fields {
            for &norm in measures.norms {
                let points = group::fit_points(&g.runs, field, norm);
                let Some(line) = fit::fit_loglog(&points) else {
                    continue;
                };
                let (h_min, h_max) = fit::min_max(points.iter().map(|p| p.0));
                let segments = fit::segment_slopes(&points);
                rows.push(RateRow {
                    experiment: experiment.name.clone(),
                    group: g.label.clone(),
                    group_axes: g.axes.clone(),
                    field: field.to_string(),
                    norm: norm.to_string(),
                    rate: line.slope,
                    intercept: line.intercept,
                    r2: line.r2,
                    n: points.len(),
                    h_min,
                    h_max,
                    segments,
                });
            }
        }
    }
    rows
}
