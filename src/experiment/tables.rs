//! `tables` entries: the tables that report.md prints beside the rates: pointwise values of
//! the reconstruction benchmarks (the counterparts of Gong's Tables 4.1-4.2 and of the
//! <p_i, p_i> of Tran's Figs 1-3), the errors of element-wise fits (Wobbes sec 2.1),
//! measured stability limits, and every run's final error in one field and norm.

use crate::benchmarks::BenchmarkKind;
use crate::output::Measures;

use super::error::ConfigError;
use super::kinds::{Item, Kinds};
use super::measures::{error_field, norm};
use super::select::axis_key;
use super::space::ParamSpace;
use super::stability;
use super::values::{finite, positive};
use super::yaml::{child_field, find, Entry, Node};
use super::{ProbeWindow, TableKind, TableSpec};

const KINDS: Kinds<TableKind> = Kinds {
    what: "table",
    kinds: &[
        ("nodal_errors", TableKind::NodalErrors),
        ("basis_norms", TableKind::BasisNorms),
        ("stability", TableKind::Stability),
        ("element_fits", TableKind::ElementFits),
        ("errors", TableKind::Errors),
        ("ranking", TableKind::Ranking),
        ("probes", TableKind::Probes),
        ("conservation", TableKind::Conservation),
    ],
    keys: &[
        "kind",
        "columns",
        "x",
        "sweep",
        "field",
        "norm",
        "probe",
        "after",
        "tolerance",
    ],
    common: &[],
    takes,
    suits: lists_for,
};

pub(crate) fn read(
    section: Option<&Entry>,
    space: &ParamSpace,
    benchmark: BenchmarkKind,
    measures: Measures,
) -> Result<Vec<TableSpec>, ConfigError> {
    KINDS.read_list(section, space, benchmark, |item| {
        table(item, space, measures)
    })
}

fn table(
    item: Item<TableKind>,
    space: &ParamSpace,
    measures: Measures,
) -> Result<TableSpec, ConfigError> {
    let Item {
        node,
        parent,
        entries,
        kind,
        select,
    } = item;
    let columns = match (kind, find(&entries, "columns")) {
        (TableKind::NodalErrors, Some(e)) => {
            Some(axis_key(e.value, &child_field(parent, "columns"), space)?)
        }
        (TableKind::NodalErrors, None) => {
            return Err(ConfigError::at(
                node.pos,
                child_field(parent, "columns"),
                "a nodal_errors table needs 'columns': the axis whose runs become its columns",
            )
            .with_valid(space.group_axis_names()))
        }
        _ => None,
    };
    let stability = match kind {
        TableKind::Stability => Some(stability::axes(
            &entries, node, parent, space, &select, true,
        )?),
        _ => None,
    };
    let measure = match kind {
        TableKind::Errors | TableKind::Ranking => {
            let field = match find(&entries, "field") {
                Some(e) => error_field(e.value, &child_field(parent, "field"), measures)?,
                None => {
                    return Err(ConfigError::at(
                        node.pos,
                        child_field(parent, "field"),
                        format!(
                            "{} table needs 'field': the error it lists",
                            if *kind == TableKind::Ranking {
                                "a ranking"
                            } else {
                                "an errors"
                            }
                        ),
                    )
                    .with_valid(measures.fields))
                }
            };
            Some((field, norm(&entries, parent, measures)?))
        }
        _ => None,
    };
    let probe = match kind {
        TableKind::Probes => Some(probe_window(&entries, node, parent)?),
        _ => None,
    };
    Ok(TableSpec {
        kind: kind.clone(),
        columns,
        select,
        stability,
        measure,
        probe,
    })
}

/// `probe` and `tolerance` (> 0) are required; `after` is a finite time, 0 when left out.
fn probe_window(entries: &[Entry], node: &Node, parent: &str) -> Result<ProbeWindow, ConfigError> {
    let required = |key: &str, what: &str| {
        find(entries, key).ok_or_else(|| {
            ConfigError::at(
                node.pos,
                child_field(parent, key),
                format!("a probes table needs '{key}': {what}"),
            )
        })
    };
    let name = required("probe", "the name of a probe its runs record")?;
    let tolerance = required(
        "tolerance",
        "how far from its reference the probe may go before the run counts as having left it",
    )?;
    let after = match find(entries, "after") {
        Some(e) => finite(e.value, &child_field(parent, "after"))?,
        None => 0.0,
    };
    Ok(ProbeWindow {
        name: name
            .value
            .as_text(&child_field(parent, "probe"))?
            .to_string(),
        after,
        tolerance: positive(tolerance.value, &child_field(parent, "tolerance"))?,
    })
}

/// The keys a table of `kind` takes besides `kind` and selectors.
fn takes(kind: &TableKind) -> &'static [&'static str] {
    match kind {
        TableKind::NodalErrors => &["columns"],
        TableKind::BasisNorms | TableKind::ElementFits | TableKind::Conservation => &[],
        TableKind::Stability => &["x", "sweep"],
        TableKind::Errors | TableKind::Ranking => &["field", "norm"],
        TableKind::Probes => &["probe", "after", "tolerance"],
    }
}

/// Whether runs of `benchmark` hold what a table of `kind` lists.
fn lists_for(kind: &TableKind, benchmark: BenchmarkKind) -> bool {
    match kind {
        TableKind::NodalErrors => matches!(
            benchmark,
            BenchmarkKind::Reconstruction | BenchmarkKind::OrthogonalBasis
        ),
        TableKind::BasisNorms => benchmark == BenchmarkKind::OrthogonalBasis,
        TableKind::Stability => benchmark == BenchmarkKind::Simulation,
        TableKind::ElementFits => benchmark == BenchmarkKind::Elementwise,
        TableKind::Errors | TableKind::Ranking => true,
        TableKind::Probes | TableKind::Conservation => benchmark == BenchmarkKind::Simulation,
    }
}
