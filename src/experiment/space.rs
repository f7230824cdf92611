//! The parameter space of an experiment: the values fixed in `params` and the axes of
//! `matrix`, each key given once, the method and every required parameter given somewhere.
//!
//! `matrix` is a map of axes (one cartesian product) or a list of such maps, the blocks: the
//! runs are the union of the blocks' products. Blocks let one experiment hold studies of
//! different shapes (a few profiles at one resolution beside a refinement study) without
//! running their whole product.

use std::collections::HashMap;

use crate::benchmarks::{BenchmarkInfo, ParamDefault};
use crate::methods::{self, INTEGRATOR_KEY, SHAPE_KEY, TRANSFER_KEY};
use crate::params::ParamValue;

use super::document::Sections;
use super::error::{ConfigError, Pos};
use super::values::{method_names, normalize, settable_kind, ValueKind, METHOD_KEY};
use super::yaml::{child_field, item_field, Entry, Node, NodeKind};

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

/// One cartesian product of axes.
pub(crate) struct Block {
    /// In the order of the first block's axes (file order there).
    pub axes: Vec<Axis>,
    /// Where the block is written, for errors about the runs it makes.
    pub pos: Pos,
}

pub(crate) struct ParamSpace {
    pub fixed: Vec<(String, Written)>,
    /// At least one; all with the same axes. Without a matrix, one block without axes.
    pub blocks: Vec<Block>,
    /// Where the matrix is (the document start without one), for errors about its size.
    pub matrix_pos: Pos,
}

impl ParamSpace {
    pub fn read(sections: &Sections, info: &BenchmarkInfo) -> Result<Self, ConfigError> {
        let fixed = match sections.get("params") {
            Some(params) => read_params(params, info)?,
            None => Vec::new(),
        };
        let matrix_pos = sections.key_pos("matrix");
        let blocks = match sections.get("matrix") {
            Some(matrix) => read_matrix(matrix, info, &fixed)?,
            None => vec![Block {
                axes: Vec::new(),
                pos: matrix_pos,
            }],
        };
        let space = ParamSpace {
            fixed,
            blocks,
            matrix_pos,
        };
        space.require_given(info, sections.key_pos("params"))?;
        Ok(space)
    }

    /// The axes (keys and kinds; their values are the first block's).
    /// Every axis of the matrix: the first block's, then the method parameters that only
    /// later blocks list, in order of first appearance.
    pub fn axes(&self) -> Vec<&Axis> {
        let mut axes: Vec<&Axis> = Vec::new();
        for axis in self.blocks.iter().flat_map(|b| &b.axes) {
            if !axes.iter().any(|a| a.key == axis.key) {
                axes.push(axis);
            }
        }
        axes
    }

    /// Every value axis `key` takes in any block, in order of first appearance.
    pub fn axis_values(&self, key: &str) -> Vec<&ParamValue> {
        let mut values: Vec<&ParamValue> = Vec::new();
        let axes = self.blocks.iter().flat_map(|b| &b.axes);
        for written in axes.filter(|a| a.key == key).flat_map(|a| &a.values) {
            if !values.contains(&&written.value) {
                values.push(&written.value);
            }
        }
        values
    }

    fn is_given(&self, key: &str) -> bool {
        self.fixed.iter().any(|(k, _)| k == key) || self.axes().iter().any(|a| a.key == key)
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
        // A simulation that names all three parts of its method needs no preset.
        let composed = info.kind.steps()
            && [SHAPE_KEY, TRANSFER_KEY, INTEGRATOR_KEY]
                .iter()
                .all(|key| self.is_given(key));
        if !self.is_given(METHOD_KEY) && !composed {
            let valid = method_names(info.kind);
            return Err(missing(METHOD_KEY).with_valid(valid));
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
        self.axes().into_iter().filter(|a| a.key != CELLS_KEY)
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

/// A map of axes, or a non-empty list of them with the same keys.
fn read_matrix(
    section: &Entry,
    info: &BenchmarkInfo,
    fixed: &[(String, Written)],
) -> Result<Vec<Block>, ConfigError> {
    let node = section.value;
    let NodeKind::List(items) = &node.kind else {
        return Ok(vec![read_block(node, "matrix", info, fixed)?]);
    };
    if items.is_empty() {
        return Err(node.expected(
            "matrix",
            "a map of axes or a non-empty list of such maps (blocks)",
        ));
    }
    let mut blocks = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let mut block = read_block(item, &item_field("matrix", i), info, fixed)?;
        if let Some(first) = blocks.first() {
            let composable = info.kind.steps();
            align(&mut block, first, &item_field("matrix", i), composable)?;
        }
        blocks.push(block);
    }
    Ok(blocks)
}

/// Puts `block`'s axes in the order of `first`'s (axes `first` lacks last), which must have
/// the same keys apart from the method and its parameters: every run then has a value for
/// every axis but those that apply to some methods only (`gamma` for LME), which a block of
/// other methods leaves out, and, where methods are `composable` from their parts
/// (simulations), the method, which a block that names the parts instead leaves out.
fn align(
    block: &mut Block,
    first: &Block,
    field: &str,
    composable: bool,
) -> Result<(), ConfigError> {
    let keys = |b: &Block| {
        let mut keys: Vec<String> = b
            .axes
            .iter()
            .map(|a| a.key.clone())
            .filter(|key| {
                let method_part = composable && key == METHOD_KEY;
                !method_part && !methods::METHOD_PARAMS.iter().any(|p| p.key == key)
            })
            .collect();
        keys.sort();
        keys
    };
    if keys(block) != keys(first) {
        return Err(ConfigError::at(
            block.pos,
            field,
            format!(
                "every block of the matrix lists the same axes, apart from {} ({}); this one \
                 has [{}], the first has [{}]",
                if composable {
                    "the method and its parameters"
                } else {
                    "the method parameters"
                },
                method_param_keys().join(", "),
                keys(block).join(", "),
                keys(first).join(", ")
            ),
        ));
    }
    block.axes.sort_by_key(|a| {
        first
            .axes
            .iter()
            .position(|f| f.key == a.key)
            .unwrap_or(usize::MAX)
    });
    Ok(())
}

fn method_param_keys() -> Vec<&'static str> {
    methods::METHOD_PARAMS.iter().map(|p| p.key).collect()
}

fn read_block(
    node: &Node,
    field: &str,
    info: &BenchmarkInfo,
    fixed: &[(String, Written)],
) -> Result<Block, ConfigError> {
    let entries = node.entries(field)?;
    let axes = entries
        .iter()
        .map(|e| {
            let kind = settable_kind(info, e, field)?;
            let field = child_field(field, e.key);
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
        .collect::<Result<_, _>>()?;
    Ok(Block {
        axes,
        pos: node.pos,
    })
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
