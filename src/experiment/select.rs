//! Selecting runs by matrix-axis values, shared by `expect`, `figures` and `tables` entries:
//! every entry of their maps that is not one of their own keys names a group axis and a value.

use crate::params::Params;

use super::error::ConfigError;
use super::space::ParamSpace;
use super::values::normalize;
use super::yaml::{child_field, Entry, Node};

/// The entries of a map other than `keys`, as axis values that runs must have.
pub(crate) fn selection(
    entries: &[Entry],
    parent: &str,
    space: &ParamSpace,
    keys: &[&str],
) -> Result<Params, ConfigError> {
    let mut select = Params::new();
    for e in entries.iter().filter(|e| !keys.contains(&e.key)) {
        let field = child_field(parent, e.key);
        let unknown = format!("unknown key '{}'", e.key);
        let axis = space.group_axis(e.key, e.key_pos, &field, unknown, keys)?;
        let value = normalize(axis.kind, e.value, &field)?;
        let values = space.axis_values(e.key);
        if !values.contains(&&value) {
            return Err(ConfigError::at(
                e.value.pos,
                field,
                format!("no run has {} = {value}", e.key),
            )
            .with_valid(values));
        }
        select.insert(e.key.to_string(), value);
    }
    Ok(select)
}

/// A group axis named by the text of `node` (a figure's `by`, a table's `columns`).
pub(crate) fn axis_key(
    node: &Node,
    field: &str,
    space: &ParamSpace,
) -> Result<String, ConfigError> {
    let key = node
        .as_text(field)
        .map_err(|e| e.with_valid(space.group_axis_names()))?;
    let unknown = format!("'{key}' is not a matrix axis");
    let axis = space.group_axis(key, node.pos, field, unknown, &[])?;
    Ok(axis.key.clone())
}
