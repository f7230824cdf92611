//! `expect` entries: bounds on convergence rates and final errors, and on measured stability
//! limits, for `report --check`.

use crate::output::Measures;

use super::error::ConfigError;
use super::measures::{error_field, norm};
use super::select::{selection, Selection};
use super::space::ParamSpace;
use super::stability::sweep;
use super::values::{finite, positive};
use super::yaml::{child_field, find, read_list, require, Entry, Node};
use super::{Expectation, LimitBound};

const KEYS: [&str; 9] = [
    "field",
    "norm",
    "rate_min",
    "rate_max",
    "error_min",
    "error_max",
    "sweep",
    "limit_min",
    "limit_max",
];
const BOUNDS: [&str; 4] = ["rate_min", "rate_max", "error_min", "error_max"];
/// The keys of a stability-limit entry; the others belong to rate and error entries.
const LIMIT_KEYS: [&str; 3] = ["sweep", "limit_min", "limit_max"];
/// What the stability criterion reads (`report::stability`).
const LIMIT_FIELD: &str = "velocity";
const LIMIT_NORM: &str = "l2";

pub(crate) fn read(
    section: Option<&Entry>,
    space: &ParamSpace,
    measures: Measures,
) -> Result<Vec<Expectation>, ConfigError> {
    read_list(section, |node, field| {
        read_entry(node, field, space, measures)
    })
}

fn read_entry(
    node: &Node,
    parent: &str,
    space: &ParamSpace,
    measures: Measures,
) -> Result<Expectation, ConfigError> {
    let entries = node.entries(parent)?;
    let select = selection(&entries, parent, space, &KEYS)?;
    let is_limit = find(&entries, "sweep").is_some();
    if let Some(e) = entries
        .iter()
        .find(|e| KEYS.contains(&e.key) && LIMIT_KEYS.contains(&e.key) != is_limit)
    {
        let message = if is_limit {
            format!(
                "'{}' does not apply to a stability-limit expectation (one with 'sweep')",
                e.key
            )
        } else {
            format!(
                "'{}' needs 'sweep', the axis the stability limit is measured along",
                e.key
            )
        };
        return Err(ConfigError::at(
            e.key_pos,
            child_field(parent, e.key),
            message,
        ));
    }
    if is_limit {
        return read_limit(node, parent, &entries, space, select);
    }
    let field_entry =
        require(&entries, "field", node.pos, parent).map_err(|e| e.with_valid(measures.fields))?;
    let field = error_field(field_entry.value, &child_field(parent, "field"), measures)?;
    let bound = |key: &str, read: fn(&Node, &str) -> Result<f64, ConfigError>| {
        find(&entries, key)
            .map(|e| read(e.value, &child_field(parent, key)))
            .transpose()
    };
    let rate_min = bound("rate_min", finite)?;
    let rate_max = bound("rate_max", finite)?;
    let error_min = bound("error_min", positive)?;
    let error_max = bound("error_max", positive)?;
    if [rate_min, rate_max, error_min, error_max]
        .iter()
        .all(Option::is_none)
    {
        return Err(
            ConfigError::at(node.pos, parent, "an expectation needs at least one bound")
                .with_valid(BOUNDS),
        );
    }
    if let (Some(min), Some(max)) = (rate_min, rate_max) {
        ordered(&entries, node, parent, "rate", min, max)?;
    }
    if let (Some(min), Some(max)) = (error_min, error_max) {
        ordered(&entries, node, parent, "error", min, max)?;
    }
    Ok(Expectation {
        select,
        field,
        norm: norm(&entries, parent, measures)?,
        rate_min,
        rate_max,
        error_min,
        error_max,
        limit: None,
        line: node.pos.line,
    })
}

/// `{sweep: cfl, limit_min: a, limit_max: b}` and selectors.
fn read_limit(
    node: &Node,
    parent: &str,
    entries: &[Entry],
    space: &ParamSpace,
    select: Selection,
) -> Result<Expectation, ConfigError> {
    let sweep = sweep(entries, node, parent, space, &select)?;
    let bound = |key: &str| {
        let entry = require(entries, key, node.pos, parent)?;
        finite(entry.value, &child_field(parent, key))
    };
    let (min, max) = (bound("limit_min")?, bound("limit_max")?);
    ordered(entries, node, parent, "limit", min, max)?;
    Ok(Expectation {
        select,
        field: LIMIT_FIELD.to_string(),
        norm: LIMIT_NORM.to_string(),
        rate_min: None,
        rate_max: None,
        error_min: None,
        error_max: None,
        limit: Some(LimitBound { sweep, min, max }),
        line: node.pos.line,
    })
}

/// `<what>_min` must not exceed `<what>_max`; the error points at the latter.
fn ordered(
    entries: &[Entry],
    node: &Node,
    parent: &str,
    what: &str,
    min: f64,
    max: f64,
) -> Result<(), ConfigError> {
    if min <= max {
        return Ok(());
    }
    let key = format!("{what}_max");
    let at = find(entries, &key).map_or(node.pos, |e| e.value.pos);
    Err(ConfigError::at(
        at,
        child_field(parent, &key),
        format!("{key} {max} is below {what}_min {min}; no {what} can pass"),
    ))
}
