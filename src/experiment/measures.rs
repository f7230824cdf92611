//! The error fields and norms an experiment can ask the report about: those of its
//! benchmark's kind.

use crate::output::Measures;

use super::error::ConfigError;
use super::values::choice;
use super::yaml::{child_field, find, Entry, Node};

const DEFAULT_NORM: &str = "l2";

pub(crate) fn error_field(
    node: &Node,
    field: &str,
    measures: Measures,
) -> Result<String, ConfigError> {
    choice(node, field, "field", measures.fields)
}

/// The optional `norm` entry of a map at `parent`, `l2` when absent.
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
        None => Ok(DEFAULT_NORM.to_string()),
    }
}
