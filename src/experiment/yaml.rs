//! The YAML text as a tree of nodes that remember where they were written. Validation walks
//! this tree instead of deserializing into structs, so that every error can name its exact
//! position and field and list the valid choices.

use std::fmt;

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_saphyr::budget::BudgetBreach;
use serde_saphyr::options::NonFiniteFloatPolicy;
use serde_saphyr::{Budget, Location, MessageFormatter, Spanned, Tagged, UserMessageFormatter};

use super::error::{ConfigError, Pos, DOCUMENT_FIELD, FILE_FIELD};

#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Node {
    pub kind: NodeKind,
    pub pos: Pos,
    /// An explicit YAML tag (`!foo`, `!!str`), which `parse_tree` refuses: a tag would change
    /// how a value is read in ways no experiment needs.
    tag: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum NodeKind {
    Null,
    Bool(bool),
    /// Wide enough for every integer YAML gives us (up to u64::MAX) without wrapping.
    Int(i128),
    /// Possibly non-finite: `.nan`, `.inf` and `1e999` are rejected by validation, where the
    /// field they belong to is known.
    Float(f64),
    Text(String),
    List(Vec<Node>),
    /// Entries in file order.
    Map(Vec<(Node, Node)>),
}

/// One `key: value` entry of a map whose keys are text.
pub(crate) struct Entry<'a> {
    pub key: &'a str,
    pub key_pos: Pos,
    pub value: &'a Node,
}

/// The text of a file, which must be UTF-8; an error points at the first byte that is not.
pub(crate) fn decode(bytes: &[u8]) -> Result<&str, ConfigError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let valid = &bytes[..e.valid_up_to()];
        // The valid prefix decodes, by definition.
        let before = std::str::from_utf8(valid).unwrap_or_default();
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let pos = Pos {
            line: before.matches('\n').count() + 1,
            column: before[line_start..].chars().count() + 1,
        };
        let field = key_on_line(before, pos.line).unwrap_or(FILE_FIELD);
        ConfigError::at(
            pos,
            field,
            format!(
                "the byte 0x{:02x} is not UTF-8 text; experiment files are UTF-8",
                bytes[e.valid_up_to()]
            ),
        )
    })
}

/// Parses a whole file. Syntax errors carry the parser's position; their field is a guess.
pub(crate) fn parse_tree(text: &str) -> Result<Node, ConfigError> {
    let budget = Budget::default();
    let options = serde_saphyr::options! {
        // YAML 1.2 booleans, so that `n`, `no` or `on` stay text.
        strict_booleans: true,
        non_finite_float_policy: NonFiniteFloatPolicy::PassThrough,
        with_snippet: false,
        budget: Some(budget.clone()),
    };
    let root: Node = serde_saphyr::from_str_with_options(text, options)
        .map_err(|e| syntax_error(&e, text, &budget))?;
    let Some((tag, node_pos)) = root.first_tag() else {
        return Ok(root);
    };
    let (pos, tag) = written_tag(text, node_pos).unwrap_or((node_pos, tag));
    // A tagged key is guessed with its tag in front.
    let field = key_on_line(text, pos.line).map(|key| key.strip_prefix(tag).unwrap_or(key));
    Err(ConfigError::at(
        pos,
        field.map_or(DOCUMENT_FIELD, str::trim_start),
        format!("the YAML tag '{tag}' is not accepted; write the value without it"),
    ))
}

/// Where the tag of the node at `node` is written, and how: the token before the node's
/// content, past blanks, line ends, comments and an anchor (`&name`). `None` when it is not
/// found there (the parser names the node's content, after its tag).
fn written_tag(text: &str, node: Pos) -> Option<(Pos, &str)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut line = node.line.checked_sub(1)?;
    let source = lines.get(line)?;
    let end = source
        .char_indices()
        .nth(node.column - 1)
        .map_or(source.len(), |(i, _)| i);
    let mut before = &source[..end];
    loop {
        let trimmed = before.trim_end();
        if trimmed.is_empty() {
            // The content starts a line: the tag ends an earlier one, before any comment.
            line = line.checked_sub(1)?;
            let earlier = lines[line];
            before = match earlier.find(" #") {
                Some(i) => &earlier[..i],
                None if earlier.trim_start().starts_with('#') => "",
                None => earlier,
            };
            continue;
        }
        let start = trimmed.rfind(char::is_whitespace).map_or(0, |i| i + 1);
        // A flow collection's opening or separator may touch the token: `[!tag 1]`.
        let token = trimmed[start..].trim_start_matches(['[', '{', ',']);
        let token_start = trimmed.len() - token.len();
        if token.starts_with('&') {
            before = &trimmed[..token_start];
        } else if token.starts_with('!') {
            let column = trimmed[..token_start].chars().count() + 1;
            return Some((
                Pos {
                    line: line + 1,
                    column,
                },
                token,
            ));
        } else {
            return None;
        }
    }
}

fn syntax_error(err: &serde_saphyr::Error, text: &str, budget: &Budget) -> ConfigError {
    let err = err.without_snippet();
    let pos = err.location().map_or(Pos::START, position);
    let message = match err {
        serde_saphyr::Error::DuplicateMappingKey { key: Some(key), .. } => {
            return ConfigError::at(pos, key.as_str(), format!("duplicate key '{key}'"));
        }
        serde_saphyr::Error::MultipleDocuments { .. } => format!(
            "a file holds one YAML document; found a second at line {}",
            pos.line
        ),
        serde_saphyr::Error::Budget { breach, .. } => too_large(breach, budget),
        serde_saphyr::Error::AliasReplayCounterOverflow { .. }
        | serde_saphyr::Error::AliasReplayLimitExceeded { .. }
        | serde_saphyr::Error::AliasExpansionLimitExceeded { .. }
        | serde_saphyr::Error::AliasReplayStackDepthExceeded { .. } => {
            "its aliases (*name) expand to more values than a file may hold".to_string()
        }
        serde_saphyr::Error::UnknownAnchor { .. } => {
            "an alias (*name) names no anchor (&name) defined before it".to_string()
        }
        // The parser's own description of the syntax, in YAML's terms.
        _ => UserMessageFormatter.format_message(err).into_owned(),
    };
    let message: String = message
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    let field = key_on_line(text, pos.line).unwrap_or(DOCUMENT_FIELD);
    ConfigError::at(pos, field, format!("invalid YAML: {message}"))
}

/// What a breach of the reader's limits means, with the limit.
fn too_large(breach: &BudgetBreach, budget: &Budget) -> String {
    match breach {
        BudgetBreach::Nodes { .. } => format!(
            "the file has more than {} YAML nodes (values, lists and maps); at most that many \
             are read",
            budget.max_nodes
        ),
        BudgetBreach::Events { .. } => format!(
            "the file has more than {} YAML events (nodes and the ends of lists and maps)",
            budget.max_events
        ),
        BudgetBreach::Depth { .. } => format!(
            "lists and maps are nested more than {} deep",
            budget.max_depth
        ),
        BudgetBreach::Aliases { .. } => {
            format!(
                "the file has more than {} aliases (*name)",
                budget.max_aliases
            )
        }
        BudgetBreach::Anchors { .. } => {
            format!(
                "the file has more than {} anchors (&name)",
                budget.max_anchors
            )
        }
        BudgetBreach::AliasAnchorRatio { aliases, anchors } => format!(
            "{aliases} aliases (*name) for {anchors} anchors (&name); at most {} per anchor",
            budget.alias_anchor_ratio_multiplier
        ),
        BudgetBreach::Documents { .. } => format!(
            "the file has more than {} YAML documents; it should hold one",
            budget.max_documents
        ),
        BudgetBreach::ScalarBytes { .. } => format!(
            "the values hold more than {} bytes of text",
            budget.max_total_scalar_bytes
        ),
        BudgetBreach::MergeKeys { .. } => {
            format!(
                "the file has more than {} merge keys (<<)",
                budget.max_merge_keys
            )
        }
        BudgetBreach::SequenceUnbalanced => "a list or map ends that was never opened".to_string(),
        _ => "the file is too large or too complex to read".to_string(),
    }
}

/// The parser's 1-based location; an unknown one (0) becomes the start of the file, so that
/// every error has a real position.
fn position(location: Location) -> Pos {
    match (
        usize::try_from(location.line()),
        usize::try_from(location.column()),
    ) {
        (Ok(line @ 1..), Ok(column @ 1..)) => Pos { line, column },
        _ => Pos::START,
    }
}

/// The key written on a line (`  - key: value` gives `key`), the best available name for the
/// field of a syntax error.
fn key_on_line(text: &str, line: usize) -> Option<&str> {
    let source_line = text.lines().nth(line.checked_sub(1)?)?;
    let (key, _) = source_line.split_once(':')?;
    let key = key.trim_start_matches(|c: char| c.is_whitespace() || "-?{[,".contains(c));
    let key = key.trim_end();
    (!key.is_empty()).then_some(key)
}

impl Node {
    /// The first explicit tag in the tree, in file order, and where it is.
    fn first_tag(&self) -> Option<(&str, Pos)> {
        if let Some(tag) = &self.tag {
            return Some((tag, self.pos));
        }
        match &self.kind {
            NodeKind::List(items) => items.iter().find_map(Node::first_tag),
            NodeKind::Map(pairs) => pairs
                .iter()
                .find_map(|(key, value)| key.first_tag().or_else(|| value.first_tag())),
            _ => None,
        }
    }

    /// What the node holds, for "expected X, found Y" messages.
    fn describe(&self) -> String {
        match &self.kind {
            NodeKind::Null => "nothing".into(),
            NodeKind::Bool(b) => format!("the boolean {b}"),
            NodeKind::Int(i) => format!("the integer {i}"),
            NodeKind::Float(x) => format!("the number {x:?}"),
            NodeKind::Text(s) => format!("the text '{s}'"),
            NodeKind::List(_) => "a list".into(),
            NodeKind::Map(_) => "a map".into(),
        }
    }

    /// "expected WHAT, found THIS" at this node.
    pub fn expected(&self, field: &str, what: &str) -> ConfigError {
        ConfigError::at(
            self.pos,
            field,
            format!("expected {what}, found {}", self.describe()),
        )
    }

    pub fn as_text(&self, field: &str) -> Result<&str, ConfigError> {
        match &self.kind {
            NodeKind::Text(s) => Ok(s),
            _ => Err(self.expected(field, "text")),
        }
    }

    pub fn as_list(&self, field: &str) -> Result<&[Node], ConfigError> {
        match &self.kind {
            NodeKind::List(items) => Ok(items),
            _ => Err(self.expected(field, "a list")),
        }
    }

    /// The entries of a map whose keys must all be text.
    pub fn entries(&self, field: &str) -> Result<Vec<Entry<'_>>, ConfigError> {
        let NodeKind::Map(pairs) = &self.kind else {
            return Err(self.expected(field, "a map"));
        };
        pairs
            .iter()
            .map(|(key, value)| match &key.kind {
                NodeKind::Text(name) => Ok(Entry {
                    key: name,
                    key_pos: key.pos,
                    value,
                }),
                _ => Err(key.expected(field, "a text key")),
            })
            .collect()
    }
}

/// Path of a map entry below `parent` (the top level has the empty path).
pub(crate) fn child_field(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// Path of a list element below `parent`.
pub(crate) fn item_field(parent: &str, index: usize) -> String {
    format!("{parent}[{index}]")
}

/// The items of an optional top-level list section, each read by `read_item` with its path.
pub(crate) fn read_list<T>(
    section: Option<&Entry>,
    read_item: impl Fn(&Node, &str) -> Result<T, ConfigError>,
) -> Result<Vec<T>, ConfigError> {
    let Some(section) = section else {
        return Ok(Vec::new());
    };
    let items = section.value.as_list(section.key)?;
    items
        .iter()
        .enumerate()
        .map(|(i, node)| read_item(node, &item_field(section.key, i)))
        .collect()
}

/// Rejects the first entry whose key is not one of `valid`.
pub(crate) fn reject_unknown_keys(
    entries: &[Entry],
    valid: &[&str],
    parent: &str,
) -> Result<(), ConfigError> {
    match entries.iter().find(|e| !valid.contains(&e.key)) {
        Some(e) => Err(ConfigError::at(
            e.key_pos,
            child_field(parent, e.key),
            format!("unknown key '{}'", e.key),
        )
        .with_valid(valid)),
        None => Ok(()),
    }
}

pub(crate) fn find<'e, 'a>(entries: &'e [Entry<'a>], key: &str) -> Option<&'e Entry<'a>> {
    entries.iter().find(|e| e.key == key)
}

/// The entry `key` of the map at `map_pos`, which must be present.
pub(crate) fn require<'e, 'a>(
    entries: &'e [Entry<'a>],
    key: &str,
    map_pos: Pos,
    parent: &str,
) -> Result<&'e Entry<'a>, ConfigError> {
    find(entries, key).ok_or_else(|| {
        ConfigError::at(
            map_pos,
            child_field(parent, key),
            format!("missing required key '{key}'"),
        )
    })
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let spanned = Spanned::<Tagged<NodeKind>>::deserialize(deserializer)?;
        let Tagged(kind, tag) = spanned.value;
        Ok(Node {
            kind,
            pos: position(spanned.referenced),
            tag,
        })
    }
}

impl<'de> Deserialize<'de> for NodeKind {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(NodeVisitor)
    }
}

struct NodeVisitor;

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = NodeKind;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any YAML value")
    }

    fn visit_unit<E: de::Error>(self) -> Result<NodeKind, E> {
        Ok(NodeKind::Null)
    }

    fn visit_none<E: de::Error>(self) -> Result<NodeKind, E> {
        Ok(NodeKind::Null)
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<NodeKind, E> {
        Ok(NodeKind::Bool(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<NodeKind, E> {
        Ok(NodeKind::Int(v.into()))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<NodeKind, E> {
        Ok(NodeKind::Int(v.into()))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<NodeKind, E> {
        Ok(NodeKind::Float(v))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<NodeKind, E> {
        Ok(NodeKind::Text(v.to_string()))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<NodeKind, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element::<Node>()? {
            items.push(item);
        }
        Ok(NodeKind::List(items))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<NodeKind, A::Error> {
        let mut pairs = Vec::new();
        while let Some(key) = map.next_key::<Node>()? {
            pairs.push((key, map.next_value::<Node>()?));
        }
        Ok(NodeKind::Map(pairs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pos(line: usize, column: usize) -> Pos {
        Pos { line, column }
    }

    #[test]
    fn nodes_keep_positions_and_scalar_types() {
        let tree = parse_tree("a: 1\nb: [2.5, x, no, ~]\n").unwrap();
        let entries = tree.entries("").unwrap();
        assert_eq!(entries[0].key, "a");
        assert_eq!(entries[0].value.kind, NodeKind::Int(1));
        assert_eq!(entries[1].key_pos, pos(2, 1));
        let items = entries[1].value.as_list("b").unwrap();
        let kinds: Vec<_> = items.iter().map(|n| n.kind.clone()).collect();
        assert_eq!(
            kinds,
            [
                NodeKind::Float(2.5),
                NodeKind::Text("x".into()),
                NodeKind::Text("no".into()),
                NodeKind::Null
            ]
        );
        assert_eq!(items[1].pos, pos(2, 10));
    }

    #[test]
    fn syntax_errors_are_located() {
        let e = parse_tree("a: 1\nb: [1, 2\n").unwrap_err();
        assert_eq!((e.line, e.column, e.field.as_str()), (2, 4, "b"));
        assert!(e.message.starts_with("invalid YAML"), "{e}");
        let e = parse_tree("a: 1\nouter: {b: 1, b: 2}\n").unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (2, "b"));
        assert!(e.message.contains("duplicate key 'b'"), "{e}");
    }

    #[test]
    fn non_text_keys_are_rejected() {
        let tree = parse_tree("1: x\n").unwrap();
        let e = tree.entries("params").err().unwrap();
        assert_eq!((e.field.as_str(), e.line, e.column), ("params", 1, 1));
    }

    #[test]
    fn key_guess_skips_list_and_flow_markers() {
        assert_eq!(key_on_line("x: 1\n  - {key: v", 2), Some("key"));
        assert_eq!(key_on_line("no colon here", 1), None);
        assert_eq!(key_on_line("a: 1", 0), None);
    }
}
