//! The error fields and norms an experiment can ask the report about: those of its
//! benchmark's kind.

use crate::output::Measures;

use super::error::ConfigError;
use super::values::choice;
use super::yaml::{child_field, find, Entry, Node};

pub(crate) fn error_field(
    node: &Node,
    field: &str,
    measures: Measures,
) -> Result<String, ConfigError> {
    choice(node, field, "field", measures.fields)
}

/// The optional `norm` entry of a map at `parent`; when absent the kind's first norm (`l2`
/// for simulations and nodal reconstructions, `rms` for element-wise ones).
pub(crate) fn norm(
    entries: &[Entry],
    parent: &str,
    measures: Measures,
) -> Result<String, ConfigError> {
    match find(entries, "norm") {
        Some(e) => choice(
            e.value,
            &child_field(parent, "norm"),
            "norm",
            measures.norms,
        ),
        None => Ok(measures.norms[0].to_string()),
    }
}
