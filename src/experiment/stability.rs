//! The keys of stability studies, shared by `figures`, `tables` and `expect`: `sweep`, the
//! axis along which runs are taken towards instability, and `x`, the axis whose values a
//! stability figure puts on its abscissa and a stability table in its rows.

use super::error::{ConfigError, Pos};
use super::select::{axis_key, Selection};
use super::space::ParamSpace;
use super::yaml::{child_field, require, Entry, Node};
use super::StabilityAxes;

/// `sweep` and, when `with_x`, `x` of the map `node` at `parent`: required, two different
/// numeric group axes.
pub(crate) fn axes(
    entries: &[Entry],
    node: &Node,
    parent: &str,
    space: &ParamSpace,
    select: &Selection,
    with_x: bool,
) -> Result<StabilityAxes, ConfigError> {
    let sweep = sweep(entries, node, parent, space, select)?;
    if !with_x {
        return Ok(StabilityAxes { sweep, x: None });
    }
    let (x, pos) = numeric_axis(entries, "x", node, parent, space)?;
    if x == sweep {
        return Err(ConfigError::at(
            pos,
            child_field(parent, "x"),
            format!("'{x}' is already the swept axis; x needs another axis"),
        )
        .with_valid(numeric_axes(space).filter(|a| *a != sweep)));
    }
    Ok(StabilityAxes { sweep, x: Some(x) })
}

/// The required `sweep` of the map `node` at `parent`: a numeric group axis that does not also
/// select runs (a limit needs every value of it).
pub(crate) fn sweep(
    entries: &[Entry],
    node: &Node,
    parent: &str,
    space: &ParamSpace,
    select: &Selection,
) -> Result<String, ConfigError> {
    let (sweep, pos) = numeric_axis(entries, "sweep", node, parent, space)?;
    if select.get(&sweep).is_some() {
        return Err(ConfigError::at(
            pos,
            child_field(parent, "sweep"),
            format!(
                "'{sweep}' also selects runs in this entry; the limit along it needs all its \
                 values, so drop the selector"
            ),
        ));
    }
    Ok(sweep)
}

/// The group axis named by the required entry `key`, with where it is written; its values
/// must all be numbers.
fn numeric_axis(
    entries: &[Entry],
    key: &str,
    node: &Node,
    parent: &str,
    space: &ParamSpace,
) -> Result<(String, Pos), ConfigError> {
    let field = child_field(parent, key);
    let entry =
        require(entries, key, node.pos, parent).map_err(|e| e.with_valid(numeric_axes(space)))?;
    let axis = axis_key(entry.value, &field, space)?;
    let values = space.axis_values(&axis);
    if let Some(value) = values.iter().find(|v| v.as_f64().is_none()) {
        return Err(ConfigError::at(
            entry.value.pos,
            field,
            format!("'{axis}' takes the value {value}; {key} needs an axis of numbers"),
        )
        .with_valid(numeric_axes(space)));
    }
    Ok((axis, entry.value.pos))
}

/// The group axes whose values are all numbers.
fn numeric_axes(space: &ParamSpace) -> impl Iterator<Item = &str> {
    space
        .group_axis_names()
        .into_iter()
        .filter(|key| space.axis_values(key).iter().all(|v| v.as_f64().is_some()))
}
