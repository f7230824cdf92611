//! Selecting runs by matrix-axis values, shared by `expect`, `figures` and `tables` entries:
//! every entry of their maps that is not one of their own keys names a group axis and the
//! value, or a list of the values, that runs must have.

use std::collections::{btree_map, BTreeMap};
use std::fmt;

use crate::benchmarks::ParamKind;
use crate::params::{ParamValue, Params};

use super::error::ConfigError;
use super::space::{Axis, ParamSpace};
use super::values::{normalize, ValueKind};
use super::yaml::{child_field, item_field, Entry, Node, NodeKind};

/// Runs chosen by their axis values: a run is selected when its value of every axis named is
/// one of the values allowed for it. Empty selects every run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selection(BTreeMap<String, Allowed>);

/// The values of one axis that a selection allows, in the order written. Read from a file
/// they are never empty and never repeat.
#[derive(Clone, Debug, PartialEq)]
pub struct Allowed(Vec<ParamValue>);

impl Selection {
    pub fn get(&self, axis: &str) -> Option<&Allowed> {
        self.0.get(axis)
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Axes by name, each with its allowed values.
    pub fn iter(&self) -> btree_map::Iter<'_, String, Allowed> {
        self.0.iter()
    }
}

/// Each axis with its one value (a run's axes, the reference run).
impl From<&Params> for Selection {
    fn from(values: &Params) -> Self {
        values
            .iter()
            .map(|(k, v)| (k.clone(), Allowed::from(v.clone())))
            .collect()
    }
}

impl FromIterator<(String, Allowed)> for Selection {
    fn from_iter<I: IntoIterator<Item = (String, Allowed)>>(iter: I) -> Self {
        Selection(iter.into_iter().collect())
    }
}

impl<'a> IntoIterator for &'a Selection {
    type Item = (&'a String, &'a Allowed);
    type IntoIter = btree_map::Iter<'a, String, Allowed>;

    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

impl Allowed {
    pub fn values(&self) -> &[ParamValue] {
        &self.0
    }
}

impl From<ParamValue> for Allowed {
    fn from(value: ParamValue) -> Self {
        Allowed(vec![value])
    }
}

impl From<Vec<ParamValue>> for Allowed {
    fn from(values: Vec<ParamValue>) -> Self {
        Allowed(values)
    }
}

/// The values joined by `|`: one value prints as itself, so a label of a one-value selection
/// reads as before lists were allowed.
impl fmt::Display for Allowed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, value) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str("|")?;
            }
            write!(f, "{value}")?;
        }
        Ok(())
    }
}

/// The entries of a map other than `keys`, as the axis values that runs must have.
pub(crate) fn selection(
    entries: &[Entry],
    parent: &str,
    space: &ParamSpace,
    keys: &[&str],
) -> Result<Selection, ConfigError> {
    let mut select = Selection::default();
    for e in entries.iter().filter(|e| !keys.contains(&e.key)) {
        let field = child_field(parent, e.key);
        let unknown = format!("unknown key '{}'", e.key);
        let axis = space.group_axis(e.key, e.key_pos, &field, unknown, keys)?;
        let allowed = match listed(axis.kind, e.value) {
            Some(items) => several(axis, items, e.value, &field, space)?,
            None => vec![one(axis, e.value, &field, space)?],
        };
        select.0.insert(e.key.to_string(), Allowed(allowed));
    }
    Ok(select)
}

/// The items of `node` when it lists several values of an axis of `kind`: any list, except
/// for an axis whose values are lists themselves, where a list that holds lists.
pub(crate) fn listed(kind: ValueKind, node: &Node) -> Option<&[Node]> {
    let NodeKind::List(items) = &node.kind else {
        return None;
    };
    let lists_of = |item: &Node| matches!(item.kind, NodeKind::List(_));
    if kind == ValueKind::Param(ParamKind::RealList) && !items.iter().any(lists_of) {
        return None;
    }
    Some(items)
}

/// A non-empty list of distinct values of `axis`, each one that some run has.
fn several(
    axis: &Axis,
    items: &[Node],
    node: &Node,
    field: &str,
    space: &ParamSpace,
) -> Result<Vec<ParamValue>, ConfigError> {
    if items.is_empty() {
        return Err(ConfigError::at(
            node.pos,
            field,
            format!(
                "an empty list selects no run; list at least one value of '{}'",
                axis.key
            ),
        )
        .with_valid(space.axis_values(&axis.key)));
    }
    let mut values: Vec<ParamValue> = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let at = item_field(field, i);
        let value = one(axis, item, &at, space)?;
        if let Some(earlier) = values.iter().position(|v| *v == value) {
            return Err(ConfigError::at(
                item.pos,
                at,
                format!(
                    "{value} is listed twice (first as {})",
                    item_field(field, earlier)
                ),
            ));
        }
        values.push(value);
    }
    Ok(values)
}

/// A value of `axis` that some run has.
fn one(
    axis: &Axis,
    node: &Node,
    field: &str,
    space: &ParamSpace,
) -> Result<ParamValue, ConfigError> {
    let value = normalize(axis.kind, node, field)?;
    let values = space.axis_values(&axis.key);
    if !values.contains(&&value) {
        return Err(ConfigError::at(
            node.pos,
            field,
            format!("no run has {} = {value}", axis.key),
        )
        .with_valid(values));
    }
    Ok(value)
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::experiment::{parse, ConfigError, Experiment};

    const BAR: &str = "\
name: sel
benchmark: vibrating_bar
params: {exact: small_strain, ppc: 2}
matrix:
  method: [mpm_musl, mpm_tls, mpm]
  cells: [5, 10]
figures:
  - {kind: convergence, by: method, method: [mpm_musl, mpm_tls]}
";

    fn read(text: &str) -> Result<Experiment, ConfigError> {
        parse(text, Path::new("sel.yaml"))
    }

    /// BAR with its figure's selection replaced by `select`.
    fn with_figure_selection(select: &str) -> Result<Experiment, ConfigError> {
        read(&BAR.replace("method: [mpm_musl, mpm_tls]}", &format!("{select}}}")))
    }

    fn methods(allowed: Option<&Allowed>) -> Vec<String> {
        allowed
            .unwrap()
            .values()
            .iter()
            .map(ToString::to_string)
            .collect()
    }

    #[test]
    fn a_list_selects_several_values_in_every_kind_of_entry() {
        let text = format!(
            "{BAR}expect:\n  - {{method: [mpm, mpm_musl], field: stress, rate_min: 0.9}}\n\
             tables:\n  - {{kind: errors, field: stress, method: [mpm_tls, mpm]}}\n"
        );
        let exp = read(&text).unwrap();
        let figure = &exp.figures[0].select;
        assert_eq!(methods(figure.get("method")), ["mpm_musl", "mpm_tls"]);
        assert_eq!(
            methods(exp.expect[0].select.get("method")),
            ["mpm", "mpm_musl"]
        );
        assert_eq!(
            methods(exp.tables[0].select.get("method")),
            ["mpm_tls", "mpm"]
        );
        let one = with_figure_selection("method: mpm").unwrap();
        assert_eq!(methods(one.figures[0].select.get("method")), ["mpm"]);
        let listed_once = with_figure_selection("method: [mpm]").unwrap();
        assert_eq!(listed_once.figures[0].select, one.figures[0].select);
    }

    #[test]
    fn each_listed_value_is_checked_where_it_is_written() {
        let e = with_figure_selection("method: [mpm_musl, bsmpm]").unwrap_err();
        assert_eq!(
            e.to_string(),
            "sel.yaml:8:56: field 'figures[0].method[1]': no run has method = bsmpm \
             (valid: mpm_musl, mpm_tls, mpm)"
        );
        let e = with_figure_selection("method: [mpm_musl, flip]").unwrap_err();
        assert_eq!((e.line, e.column), (8, 56));
        assert!(e.message.contains("unknown method 'flip'"), "{e}");
        assert!(e.valid.contains(&"bsmpm_tls".to_string()), "{e}");
    }

    #[test]
    fn empty_lists_and_repeats_are_refused() {
        let e = with_figure_selection("method: []").unwrap_err();
        assert_eq!(
            e.to_string(),
            "sel.yaml:8:45: field 'figures[0].method': an empty list selects no run; list at \
             least one value of 'method' (valid: mpm_musl, mpm_tls, mpm)"
        );
        let e = with_figure_selection("method: [mpm_tls, mpm, mpm_tls]").unwrap_err();
        assert_eq!(
            e.to_string(),
            "sel.yaml:8:60: field 'figures[0].method[2]': mpm_tls is listed twice (first as \
             figures[0].method[0])"
        );
        let e = with_figure_selection("cells: [5, 10]").unwrap_err();
        assert!(e.message.contains("refinement axis"), "{e}");
    }

    #[test]
    fn values_that_are_lists_are_told_apart_from_lists_of_values() {
        let text = "\
name: sel
benchmark: recon1d_basis
params: {method: imls_quadratic, function: x_plus_1, lower: -1.0, upper: 1.0, cells: 2}
matrix:
  points: [[0.6, 0.75, 0.9], [-0.6, 0.4], [0.0, 0.5]]
figures:
  - {kind: basis, points: SELECT}
";
        let points = |select: &str| {
            let exp = read(&text.replace("SELECT", select))?;
            Ok::<_, ConfigError>(methods(exp.figures[0].select.get("points")))
        };
        assert_eq!(points("[-0.6, 0.4]").unwrap(), ["[-0.6, 0.4]"]);
        assert_eq!(
            points("[[-0.6, 0.4], [0.0, 0.5]]").unwrap(),
            ["[-0.6, 0.4]", "[0.0, 0.5]"]
        );
        let e = points("[[-0.6, 0.4], 0.5]").unwrap_err();
        assert_eq!(e.field, "figures[0].points[1]");
        assert!(e.message.contains("non-empty list"), "{e}");
        let e = points("[[-0.6, 0.4], [-0.6, 0.4]]").unwrap_err();
        assert!(e.message.contains("listed twice"), "{e}");
    }
}
