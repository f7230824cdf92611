//! What `figures` and `tables` items share: a required `kind`, one of a list and one whose
//! data the benchmark's runs record, their own keys, and axis values selecting runs.

use super::error::ConfigError;
use super::select::{selection, Selection};
use super::space::ParamSpace;
use super::values::pick;
use super::yaml::{child_field, read_list, require, Entry, Node};
use crate::benchmarks::BenchmarkKind;

/// Named kinds of a `what` (figure, table), the keys its items take besides axis values, which
/// of them each kind takes, and which benchmarks record what each kind shows.
pub(crate) struct Kinds<K: 'static> {
    pub what: &'static str,
    pub kinds: &'static [(&'static str, K)],
    /// `kind` and every key of `takes` of any kind.
    pub keys: &'static [&'static str],
    /// Keys every kind takes (a figure's `name`, `title`, `paper`).
    pub common: &'static [&'static str],
    pub takes: fn(&K) -> &'static [&'static str],
    pub suits: fn(&K, BenchmarkKind) -> bool,
}

/// One item of the list, read as far as all kinds go.
pub(crate) struct Item<'a, K: 'static> {
    pub node: &'a Node,
    /// Its path, e.g. `figures[2]`.
    pub parent: &'a str,
    pub entries: Vec<Entry<'a>>,
    pub kind: &'static K,
    pub select: Selection,
}

impl<K> Kinds<K> {
    /// The items of an optional list section, each finished by `read`.
    pub fn read_list<T>(
        &self,
        section: Option<&Entry>,
        space: &ParamSpace,
        benchmark: BenchmarkKind,
        read: impl Fn(Item<K>) -> Result<T, ConfigError>,
    ) -> Result<Vec<T>, ConfigError> {
        read_list(section, |node, parent| {
            let entries = node.entries(parent)?;
            let own: Vec<&str> = self.keys.iter().chain(self.common).copied().collect();
            let select = selection(&entries, parent, space, &own)?;
            let kind = self.kind(&entries, node, parent, benchmark)?;
            self.reject_others_keys(&entries, kind, parent)?;
            read(Item {
                node,
                parent,
                entries,
                kind,
                select,
            })
        })
    }

    /// An error at the first key that another kind takes but `kind` does not.
    fn reject_others_keys(
        &self,
        entries: &[Entry],
        kind: &K,
        parent: &str,
    ) -> Result<(), ConfigError> {
        let own = (self.takes)(kind);
        let foreign = entries
            .iter()
            .find(|e| e.key != "kind" && self.keys.contains(&e.key) && !own.contains(&e.key));
        let Some(e) = foreign else {
            return Ok(());
        };
        let takers: Vec<&str> = self
            .kinds
            .iter()
            .filter(|(_, k)| (self.takes)(k).contains(&e.key))
            .map(|(name, _)| *name)
            .collect();
        Err(ConfigError::at(
            e.key_pos,
            child_field(parent, e.key),
            format!(
                "'{}' applies to {} {}s only",
                e.key,
                enumeration(&takers),
                self.what
            ),
        ))
    }

    /// The kind named by the required `kind` entry of the map `node` at `parent`.
    fn kind(
        &self,
        entries: &[Entry],
        node: &Node,
        parent: &str,
        benchmark: BenchmarkKind,
    ) -> Result<&'static K, ConfigError> {
        let names = self.kinds.iter().map(|(name, _)| *name);
        let entry = require(entries, "kind", node.pos, parent).map_err(|e| e.with_valid(names))?;
        let field = child_field(parent, "kind");
        let what = format!("{} kind", self.what);
        let (name, kind) = pick(entry.value, &field, &what, self.kinds, |(name, _)| name)?;
        if (self.suits)(kind, benchmark) {
            return Ok(kind);
        }
        let suitable = self
            .kinds
            .iter()
            .filter(|(_, k)| (self.suits)(k, benchmark));
        Err(ConfigError::at(
            entry.value.pos,
            field,
            format!(
                "a {name} {} needs data that {benchmark} benchmarks do not record",
                self.what
            ),
        )
        .with_valid(suitable.map(|(name, _)| name)))
    }
}

/// "a", "a and b", "a, b and c".
fn enumeration(items: &[&str]) -> String {
    match items.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => items.join(""),
    }
}
