//! `expect` entries: bounds on convergence rates and final errors, for `report --check`.

use crate::output::Measures;

use super::error::ConfigError;
use super::measures::{error_field, norm};
use super::select::selection;
use super::space::ParamSpace;
use super::values::{finite, positive};
use super::yaml::{child_field, find, read_list, require, Entry, Node};
use super::Expectation;

const KEYS: [&str; 5] = ["field", "norm", "rate_min", "rate_max", "error_max"];
const BOUNDS: [&str; 3] = ["rate_min", "rate_max", "error_max"];

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
    let error_max = bound("error_max", positive)?;
    if rate_min.is_none() && rate_max.is_none() && error_max.is_none() {
        return Err(
            ConfigError::at(node.pos, parent, "an expectation needs at least one bound")
                .with_valid(BOUNDS),
        );
    }
    if let (Some(min), Some(max)) = (rate_min, rate_max) {
        if min > max {
            let at = find(&entries, "rate_max").map_or(node.pos, |e| e.value.pos);
            return Err(ConfigError::at(
                at,
                child_field(parent, "rate_max"),
                format!("rate_max {max} is below rate_min {min}; no rate can pass"),
            ));
        }
    }
    Ok(Expectation {
        select,
        field,
        norm: norm(&entries, parent, measures)?,
        rate_min,
        rate_max,
        error_max,
        line: node.pos.line,
    })
}
