//! `figures` entries: which plots the report draws.

use crate::output::ERROR_FIELDS;

use super::error::ConfigError;
use super::measures::{error_field, norm};
use super::space::ParamSpace;
use super::values::pick;
use super::yaml::{
    child_field, find, item_field, read_list, reject_unknown_keys, require, Entry, Node,
};
use super::{FigureKind, FigureSpec};

const KEYS: [&str; 4] = ["kind", "fields", "norm", "by"];
const KINDS: [(&str, FigureKind); 1] = [("convergence", FigureKind::Convergence)];

pub(crate) fn read(
    section: Option<&Entry>,
    space: &ParamSpace,
) -> Result<Vec<FigureSpec>, ConfigError> {
    read_list(section, |node, field| read_entry(node, field, space))
}

fn read_entry(node: &Node, parent: &str, space: &ParamSpace) -> Result<FigureSpec, ConfigError> {
    let entries = node.entries(parent)?;
    reject_unknown_keys(&entries, &KEYS, parent)?;
    let kind_entry = require(&entries, "kind", node.pos, parent)
        .map_err(|e| e.with_valid(KINDS.iter().map(|(name, _)| name)))?;
    let (_, kind) = pick(
        kind_entry.value,
        &child_field(parent, "kind"),
        "figure kind",
        &KINDS,
        |(name, _)| name,
    )?;
    let fields = match find(&entries, "fields") {
        Some(e) => fields(e.value, &child_field(parent, "fields"))?,
        None => ERROR_FIELDS.iter().map(|f| f.to_string()).collect(),
    };
    let by = match find(&entries, "by") {
        Some(e) => Some(by(e.value, &child_field(parent, "by"), space)?),
        None => None,
    };
    Ok(FigureSpec {
        kind: kind.clone(),
        fields,
        norm: norm(&entries, parent)?,
        by,
    })
}

fn fields(node: &Node, field: &str) -> Result<Vec<String>, ConfigError> {
    let items = node.as_list(field)?;
    if items.is_empty() {
        return Err(ConfigError::at(
            node.pos,
            field,
            "list at least one field, or omit 'fields' for all",
        )
        .with_valid(ERROR_FIELDS));
    }
    let mut fields: Vec<String> = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let item_field = item_field(field, i);
        let name = error_field(item, &item_field)?;
        if fields.contains(&name) {
            return Err(ConfigError::at(
                item.pos,
                item_field,
                format!("'{name}' is listed twice"),
            ));
        }
        fields.push(name);
    }
    Ok(fields)
}

/// The axis whose values become the curves of one figure.
fn by(node: &Node, field: &str, space: &ParamSpace) -> Result<String, ConfigError> {
    let key = node
        .as_text(field)
        .map_err(|e| e.with_valid(space.group_axis_names()))?;
    let unknown = format!("'{key}' is not a matrix axis");
    let axis = space.group_axis(key, node.pos, field, unknown, &[])?;
    Ok(axis.key.clone())
}
