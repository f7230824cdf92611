//! The error fields and norms an experiment can ask the report about.

use crate::output::{ERROR_FIELDS, NORMS};

use super::error::ConfigError;
use super::values::choice;
use super::yaml::{child_field, find, Entry, Node};

const DEFAULT_NORM: &str = "l2";

pub(crate) fn error_field(node: &Node, field: &str) -> Result<String, ConfigError> {
    choice(node, field, "field", &ERROR_FIELDS)
}

/// The optional `norm` entry of a map at `parent`, `l2` when absent.
pub(crate) fn norm(entries: &[Entry], parent: &str) -> Result<String, ConfigError> {
    match find(entries, "norm") {
        Some(e) => choice(e.value, &child_field(parent, "norm"), "norm", &NORMS),
        None => Ok(DEFAULT_NORM.to_string()),
    }
}
