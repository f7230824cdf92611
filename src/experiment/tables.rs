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
use super::yaml::{child_field, find, Entry};
use super::{TableKind, TableSpec};

const KINDS: Kinds<TableKind> = Kinds {
    what: "table",
    kinds: &[
        ("nodal_errors", TableKind::NodalErrors),
        ("basis_norms", TableKind::BasisNorms),
        ("stability", TableKind::Stability),
        ("element_fits", TableKind::ElementFits),
        ("errors", TableKind::Errors),
    ],
    keys: &["kind", "columns", "x", "sweep", "field", "norm"],
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
        TableKind::Errors => {
            let field = match find(&entries, "field") {
                Some(e) => error_field(e.value, &child_field(parent, "field"), measures)?,
                None => {
                    return Err(ConfigError::at(
                        node.pos,
                        child_field(parent, "field"),
                        "an errors table needs 'field': the error it lists",
                    )
                    .with_valid(measures.fields))
                }
            };
            Some((field, norm(&entries, parent, measures)?))
        }
        _ => None,
    };
    Ok(TableSpec {
        kind: kind.clone(),
        columns,
        select,
        stability,
        measure,
    })
}

/// The keys a table of `kind` takes besides `kind` and selectors.
fn takes(kind: &TableKind) -> &'static [&'static str] {
    match kind {
        TableKind::NodalErrors => &["columns"],
        TableKind::BasisNorms | TableKind::ElementFits => &[],
        TableKind::Stability => &["x", "sweep"],
        TableKind::Errors => &["field", "norm"],
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
        TableKind::Errors => true,
    }
}
