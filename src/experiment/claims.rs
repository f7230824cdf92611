//! `paper_claims` entries: a number a paper states (a convergence rate or a final error),
//! which runs measure it, and how close ours must come to count as reproduced. The report
//! prints paper against ours and `mpmlab index` gathers every experiment's claims.

use crate::output::Measures;

use super::error::ConfigError;
use super::measures::{error_field, norm};
use super::select::selection;
use super::space::ParamSpace;
use super::values::{finite, positive};
use super::yaml::{child_field, find, read_list, require, Entry, Node};
use super::{ClaimedValue, FigureSpec, PaperClaim};

const KEYS: [&str; 9] = [
    "item",
    "claim",
    "figure",
    "field",
    "norm",
    "rate",
    "error",
    "tolerance",
    "differs",
];
/// One of these states the paper's number.
const VALUES: [&str; 2] = ["rate", "error"];

pub(crate) fn read(
    section: Option<&Entry>,
    space: &ParamSpace,
    measures: Measures,
    figures: &[FigureSpec],
) -> Result<Vec<PaperClaim>, ConfigError> {
    read_list(section, |node, parent| {
        read_entry(node, parent, space, measures, figures)
    })
}

fn read_entry(
    node: &Node,
    parent: &str,
    space: &ParamSpace,
    measures: Measures,
    figures: &[FigureSpec],
) -> Result<PaperClaim, ConfigError> {
    let entries = node.entries(parent)?;
    let select = selection(&entries, parent, space, &KEYS)?;
    let text = |key: &str| -> Result<String, ConfigError> {
        let e = require(&entries, key, node.pos, parent)?;
        let field = child_field(parent, key);
        let text = e.value.as_text(&field)?.trim();
        if text.is_empty() {
            return Err(e.value.expected(&field, "non-empty text"));
        }
        Ok(text.to_string())
    };
    let field_entry =
        require(&entries, "field", node.pos, parent).map_err(|e| e.with_valid(measures.fields))?;
    let field = error_field(field_entry.value, &child_field(parent, "field"), measures)?;
    let value = claimed_value(&entries, node, parent)?;
    let tolerance = require(&entries, "tolerance", node.pos, parent)?;
    let tolerance = positive(tolerance.value, &child_field(parent, "tolerance"))?;
    let figure = find(&entries, "figure")
        .map(|e| figure_name(e, parent, figures))
        .transpose()?;
    let differs = find(&entries, "differs")
        .map(|_| text("differs"))
        .transpose()?;
    Ok(PaperClaim {
        item: text("item")?,
        claim: text("claim")?,
        figure,
        select,
        field,
        norm: norm(&entries, parent, measures)?,
        value,
        tolerance,
        differs,
        line: node.pos.line,
    })
}

/// Exactly one of `rate` and `error`.
fn claimed_value(
    entries: &[Entry],
    node: &Node,
    parent: &str,
) -> Result<ClaimedValue, ConfigError> {
    let given: Vec<&Entry> = entries.iter().filter(|e| VALUES.contains(&e.key)).collect();
    match given.as_slice() {
        [e] if e.key == "rate" => Ok(ClaimedValue::Rate(finite(
            e.value,
            &child_field(parent, "rate"),
        )?)),
        [e] => Ok(ClaimedValue::Error(positive(
            e.value,
            &child_field(parent, "error"),
        )?)),
        [] => Err(ConfigError::at(
            node.pos,
            parent,
            "a claim needs the paper's number: a rate or an error",
        )
        .with_valid(VALUES)),
        [_, second, ..] => Err(ConfigError::at(
            second.key_pos,
            child_field(parent, second.key),
            "a claim states one number: a rate or an error, not both",
        )),
    }
}

/// The `name` of one of the experiment's figures.
fn figure_name(e: &Entry, parent: &str, figures: &[FigureSpec]) -> Result<String, ConfigError> {
    let field = child_field(parent, "figure");
    let name = e.value.as_text(&field)?;
    let names = figures.iter().filter_map(|f| f.name.as_deref());
    if names.clone().any(|n| n == name) {
        return Ok(name.to_string());
    }
    Err(ConfigError::at(
        e.value.pos,
        field,
        format!("no figure of this experiment is named '{name}'"),
    )
    .with_valid(names))
}
