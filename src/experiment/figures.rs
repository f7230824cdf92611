//! `figures` entries: which plots the report draws.

use std::cell::RefCell;

use crate::benchmarks::BenchmarkKind;
use crate::output::{map_fields, Measures};

use super::error::ConfigError;
use super::kinds::{Item, Kinds};
use super::measures::{error_field, norm};
use super::select::axis_key;
use super::space::ParamSpace;
use super::stability;
use super::values::choice;
use super::yaml::{child_field, find, item_field, Entry, Node, NodeKind};
use super::{FieldMapSpec, FigureKind, FigureSpec};

/// What a profile figure shows without `fields` (Wobbes Fig 4).
const PROFILE_FIELD: &str = "stress";

const KINDS: Kinds<FigureKind> = Kinds {
    what: "figure",
    kinds: &[
        ("convergence", FigureKind::Convergence),
        ("reconstruction", FigureKind::Reconstruction),
        ("basis", FigureKind::Basis),
        ("stability", FigureKind::Stability),
        ("growth", FigureKind::Growth),
        ("profile", FigureKind::Profile),
        ("shape_functions", FigureKind::ShapeFunctions),
        ("history", FigureKind::History),
        ("field_map", FigureKind::FieldMap),
    ],
    keys: &[
        "kind", "fields", "norm", "by", "x", "sweep", "probe", "field",
    ],
    common: &["name", "title", "paper"],
    takes,
    suits: draws_for,
};

pub(crate) fn read(
    section: Option<&Entry>,
    space: &ParamSpace,
    benchmark: BenchmarkKind,
    measures: Measures,
) -> Result<Vec<FigureSpec>, ConfigError> {
    // Two figures of one name would overwrite each other's file.
    let names = RefCell::new(Vec::new());
    KINDS.read_list(section, space, benchmark, |item| {
        figure(item, space, benchmark, measures, &names)
    })
}

/// The longest `name`: with a variant and `.png` it stays well inside a file name.
const NAME_MAX: usize = 60;

/// A figure's `name`: its file stem, so letters, digits, `.`, `-` and `_` only.
fn figure_name(node: &Node, field: &str) -> Result<String, ConfigError> {
    let name = node.as_text(field)?;
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_');
    if name.is_empty() || name.len() > NAME_MAX || !name.chars().all(allowed) {
        return Err(node.expected(
            field,
            &format!("a file stem of 1 to {NAME_MAX} letters, digits, '.', '-' or '_'"),
        ));
    }
    Ok(name.to_string())
}

/// Text that says something: `title` and `paper`.
fn text(node: &Node, field: &str) -> Result<String, ConfigError> {
    let text = node.as_text(field)?.trim();
    if text.is_empty() {
        return Err(node.expected(field, "non-empty text"));
    }
    Ok(text.to_string())
}

fn figure(
    item: Item<FigureKind>,
    space: &ParamSpace,
    benchmark: BenchmarkKind,
    measures: Measures,
    names: &RefCell<Vec<String>>,
) -> Result<FigureSpec, ConfigError> {
    let Item {
        node,
        parent,
        entries,
        kind,
        select,
    } = item;
    let stability = match kind {
        FigureKind::Stability | FigureKind::Growth => {
            let with_x = *kind == FigureKind::Stability;
            let axes = stability::axes(&entries, node, parent, space, &select, with_x)?;
            Some(axes)
        }
        _ => None,
    };
    let fields = match (find(&entries, "fields"), kind) {
        (Some(e), _) => fields(e.value, &child_field(parent, "fields"), measures)?,
        (None, FigureKind::Profile) => vec![PROFILE_FIELD.to_string()],
        (None, _) => measures.fields.iter().map(|f| f.to_string()).collect(),
    };
    let by = match find(&entries, "by") {
        Some(e) => by_axes(e.value, &child_field(parent, "by"), space, kind)?,
        None => Vec::new(),
    };
    let probe = match (find(&entries, "probe"), kind) {
        (Some(e), _) => Some(e.value.as_text(&child_field(parent, "probe"))?.to_string()),
        (None, FigureKind::History) => {
            return Err(ConfigError::at(
                node.pos,
                child_field(parent, "probe"),
                "a history figure needs 'probe': the name of a probe its runs record",
            ))
        }
        (None, _) => None,
    };
    let given = |key: &str, read: fn(&Node, &str) -> Result<String, ConfigError>| {
        find(&entries, key)
            .map(|e| Ok((read(e.value, &child_field(parent, key))?, e.value.pos)))
            .transpose()
    };
    let name = given("name", figure_name)?;
    if let Some((name, pos)) = &name {
        let mut names = names.borrow_mut();
        if names.contains(name) {
            return Err(ConfigError::at(
                *pos,
                child_field(parent, "name"),
                format!("another figure is named '{name}' already; each needs its own"),
            ));
        }
        names.push(name.clone());
    }
    let text_of = |key| Ok::<_, ConfigError>(given(key, text)?.map(|(t, _)| t));
    let map = match kind {
        FigureKind::FieldMap => Some(field_map(&entries, node, parent, benchmark)?),
        _ => None,
    };
    Ok(FigureSpec {
        name: name.map(|(name, _)| name),
        title: text_of("title")?,
        paper: text_of("paper")?,
        kind: kind.clone(),
        fields,
        norm: norm(&entries, parent, measures)?,
        by,
        select,
        stability,
        probe,
        map,
    })
}

/// The required `field` of a field map, one its benchmark's runs can draw.
fn field_map(
    entries: &[Entry],
    node: &Node,
    parent: &str,
    benchmark: BenchmarkKind,
) -> Result<FieldMapSpec, ConfigError> {
    let valid = map_fields(benchmark);
    match find(entries, "field") {
        Some(e) => Ok(FieldMapSpec {
            field: choice(e.value, &child_field(parent, "field"), "map field", valid)?,
        }),
        None => Err(ConfigError::at(
            node.pos,
            child_field(parent, "field"),
            "a field_map figure needs 'field': the field it draws",
        )
        .with_valid(valid)),
    }
}

/// The axis of `by`, or for a history, convergence or field_map figure also a list of axes.
fn by_axes(
    node: &Node,
    field: &str,
    space: &ParamSpace,
    kind: &FigureKind,
) -> Result<Vec<String>, ConfigError> {
    let NodeKind::List(items) = &node.kind else {
        return Ok(vec![axis_key(node, field, space)?]);
    };
    if !matches!(
        kind,
        FigureKind::History | FigureKind::Convergence | FigureKind::FieldMap
    ) {
        return Err(node.expected(
            field,
            "one matrix axis (a list applies to history, convergence and field_map figures)",
        ));
    }
    if items.is_empty() {
        return Err(node.expected(field, "a matrix axis or a non-empty list of them"));
    }
    items
        .iter()
        .enumerate()
        .map(|(i, item)| axis_key(item, &item_field(field, i), space))
        .collect()
}

/// The keys a figure of `kind` takes besides `kind` and selectors.
fn takes(kind: &FigureKind) -> &'static [&'static str] {
    match kind {
        FigureKind::Convergence => &["fields", "norm", "by"],
        FigureKind::Reconstruction | FigureKind::Basis => &[],
        FigureKind::Stability => &["x", "sweep"],
        FigureKind::Growth => &["sweep"],
        FigureKind::Profile => &["fields"],
        FigureKind::ShapeFunctions => &["by"],
        FigureKind::History => &["probe", "by"],
        FigureKind::FieldMap => &["field", "by"],
    }
}

/// Whether runs of `benchmark` hold what a figure of `kind` shows.
fn draws_for(kind: &FigureKind, benchmark: BenchmarkKind) -> bool {
    match kind {
        // A shape-function run has no grid to refine.
        FigureKind::Convergence => benchmark != BenchmarkKind::ShapeFunctions,
        FigureKind::ShapeFunctions => benchmark == BenchmarkKind::ShapeFunctions,
        FigureKind::Reconstruction => benchmark.is_reconstruction(),
        FigureKind::Basis => benchmark == BenchmarkKind::OrthogonalBasis,
        FigureKind::Stability | FigureKind::Growth | FigureKind::Profile | FigureKind::History => {
            benchmark == BenchmarkKind::Simulation
        }
        FigureKind::FieldMap => !map_fields(benchmark).is_empty(),
    }
}

fn fields(node: &Node, field: &str, measures: Measures) -> Result<Vec<String>, ConfigError> {
    let items = node.as_list(field)?;
    if items.is_empty() {
        return Err(ConfigError::at(
            node.pos,
            field,
            "list at least one field, or omit 'fields' for all",
        )
        .with_valid(measures.fields));
    }
    let mut fields: Vec<String> = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let item_field = item_field(field, i);
        let name = error_field(item, &item_field, measures)?;
        if fields.contains(&name) {
            return Err(ConfigError::at(
                item.pos,
                item_field,
                format!("'{name}' is listed twice"),
            ));
        }
        fields.push(name);
    }
    Ok(fields)
}
