//! The parameter space of an experiment: the values fixed in `params` and the axes of
//! `matrix`, each key given once, the method and every required parameter given somewhere.

use std::collections::HashMap;

use crate::benchmarks::{BenchmarkInfo, ParamDefault};
use crate::methods;
use crate::params::ParamValue;

use super::document::Sections;
use super::error::{ConfigError, Pos};
use super::values::{normalize, settable_kind, ValueKind, METHOD_KEY};
use super::yaml::{child_field, item_field, Entry, Node};

/// The axis along which rates are fitted; it never selects or groups runs.
const CELLS_KEY: &str = "cells";

/// A value as written in the file, kept with its place so that problems found later (the
/// benchmark's own checks) can point back at it.
#[derive(Debug)]
pub(crate) struct Written {
    pub value: ParamValue,
    pub pos: Pos,
    pub field: String,
}

pub(crate) struct Axis {
    pub key: String,
    pub kind: ValueKind,
    pub values: Vec<Written>,
}

pub(crate) struct ParamSpace {
    pub fixed: Vec<(String, Written)>,
    /// In file order.
    pub axes: Vec<Axis>,
    /// Where the matrix is (the document start without one), for errors about its size.
    pub matrix_pos: Pos,
}

impl ParamSpace {
    pub fn read(sections: &Sections, info: &BenchmarkInfo) -> Result<Self, ConfigError> {
        let fixed = match sections.get("params") {
            Some(params) => read_params(params, info)?,
            None => Vec::new(),
        };
        let axes = match sections.get("matrix") {
            Some(matrix) => read_matrix(matrix, info, &fixed)?,
            None => Vec::new(),
        };
        let space = ParamSpace {
            fixed,
            axes,
            matrix_pos: sections.key_pos("matrix"),
        };
        space.require_given(info, sections.key_pos("params"))?;
        Ok(space)
    }

    fn is_given(&self, key: &str) -> bool {
        self.fixed.iter().any(|(k, _)| k == key) || self.axes.iter().any(|a| a.key == key)
    }

    /// The method and every parameter without a default must be in `params` or `matrix`.
    fn require_given(&self, info: &BenchmarkInfo, params_pos: Pos) -> Result<(), ConfigError> {
        let missing = |key: &str| {
            ConfigError::at(
                params_pos,
                child_field("params", key),
                format!(
                    "'{key}' is required by {}: set it in params or make it a matrix axis",
                    info.name
                ),
            )
        };
        if !self.is_given(METHOD_KEY) {
            return Err(missing(METHOD_KEY).with_valid(methods::preset_names()));
        }
        match info
            .params
            .iter()
            .find(|p| p.default == ParamDefault::Required && !self.is_given(p.key))
        {
            Some(p) => Err(missing(p.key)),
            None => Ok(()),
        }
    }

    /// The axes that split runs into convergence groups: all but `cells`.
    pub fn group_axes(&self) -> impl Iterator<Item = &Axis> {
        self.axes.iter().filter(|a| a.key != CELLS_KEY)
    }

    /// The group axis named `key`. Otherwise an error at `pos` saying `unknown` (or why
    /// `cells` cannot group) and listing `also_valid` and the group axes.
    pub fn group_axis(
        &self,
        key: &str,
        pos: Pos,
        field: &str,
        unknown: String,
        also_valid: &[&str],
    ) -> Result<&Axis, ConfigError> {
        self.group_axes().find(|a| a.key == key).ok_or_else(|| {
            let message = if key == CELLS_KEY {
                "'cells' is the refinement axis that rates are fitted over; it cannot select or \
                 group runs"
                    .to_string()
            } else {
                unknown
            };
            let valid = also_valid.iter().copied().chain(self.group_axis_names());
            ConfigError::at(pos, field, message).with_valid(valid)
        })
    }

    pub fn group_axis_names(&self) -> Vec<&str> {
        self.group_axes().map(|a| a.key.as_str()).collect()
    }
}

fn read_params(
    section: &Entry,
    info: &BenchmarkInfo,
) -> Result<Vec<(String, Written)>, ConfigError> {
    let entries = section.value.entries("params")?;
    entries
        .iter()
        .map(|e| {
            let kind = settable_kind(info, e, "params")?;
            let written = read_value(kind, e.value, child_field("params", e.key))?;
            Ok((e.key.to_string(), written))
        })
        .collect()
}

fn read_matrix(
    section: &Entry,
    info: &BenchmarkInfo,
    fixed: &[(String, Written)],
) -> Result<Vec<Axis>, ConfigError> {
    let entries = section.value.entries("matrix")?;
    entries
        .iter()
        .map(|e| {
            let kind = settable_kind(info, e, "matrix")?;
            let field = child_field("matrix", e.key);
            if let Some((_, fixed)) = fixed.iter().find(|(k, _)| k == e.key) {
                return Err(ConfigError::at(
                    e.key_pos,
                    field,
                    format!(
                        "'{}' is also set in params (line {}); give it in one place only",
                        e.key, fixed.pos.line
                    ),
                ));
            }
            read_axis(kind, e, &field)
        })
        .collect()
}

fn read_axis(kind: ValueKind, entry: &Entry, field: &str) -> Result<Axis, ConfigError> {
    let items = entry.value.as_list(field)?;
    if items.is_empty() {
        return Err(ConfigError::at(
            entry.value.pos,
            field,
            "an axis needs at least one value",
        ));
    }
    let mut values: Vec<Written> = Vec::with_capacity(items.len());
    // Two equal values would be two runs with one id. Canonical text identifies a value.
    let mut seen: HashMap<String, usize> = HashMap::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let written = read_value(kind, item, item_field(field, i))?;
        if let Some(earlier) = seen.insert(written.value.to_string(), i) {
            return Err(ConfigError::at(
                written.pos,
                written.field,
                format!(
                    "{} repeats the value of {} in this axis",
                    written.value,
                    item_field(field, earlier)
                ),
            ));
        }
        values.push(written);
    }
    Ok(Axis {
        key: entry.key.to_string(),
        kind,
        values,
    })
}

fn read_value(kind: ValueKind, node: &Node, field: String) -> Result<Written, ConfigError> {
    Ok(Written {
        value: normalize(kind, node, &field)?,
        pos: node.pos,
        field,
    })
}
