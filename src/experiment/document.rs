//! The top level of an experiment file: which sections exist, the experiment name, the
//! benchmark and the output settings.

use crate::benchmarks::{self, BenchmarkInfo};

use super::error::{ConfigError, Pos, DOCUMENT_FIELD};
use super::values::{pick, positive_int};
use super::yaml::{find, reject_unknown_keys, require, Entry, Node, NodeKind};
use super::OutputSpec;

const TOP_LEVEL_KEYS: [&str; 11] = [
    "name",
    "description",
    "benchmark",
    "params",
    "matrix",
    "output",
    "expect",
    "figures",
    "tables",
    "reference",
    "paper_claims",
];

/// The top-level entries, all of known keys.
pub(crate) struct Sections<'a> {
    entries: Vec<Entry<'a>>,
    /// Where the document starts, for "missing key" errors.
    pos: Pos,
}

impl<'a> Sections<'a> {
    pub fn read(root: &'a Node) -> Result<Self, ConfigError> {
        if root.kind == NodeKind::Null {
            return Err(ConfigError::at(
                root.pos,
                DOCUMENT_FIELD,
                "the file is empty; expected a map of experiment settings",
            )
            .with_valid(TOP_LEVEL_KEYS));
        }
        let entries = root
            .entries(DOCUMENT_FIELD)
            .map_err(|e| e.with_valid(TOP_LEVEL_KEYS))?;
        reject_unknown_keys(&entries, &TOP_LEVEL_KEYS, "")?;
        Ok(Sections {
            entries,
            pos: root.pos,
        })
    }

    pub fn get(&self, key: &str) -> Option<&Entry<'a>> {
        find(&self.entries, key)
    }

    fn require(&self, key: &str) -> Result<&Entry<'a>, ConfigError> {
        require(&self.entries, key, self.pos, "")
    }

    /// Where the entry `key` is, or the document start without one.
    pub fn key_pos(&self, key: &str) -> Pos {
        self.get(key).map_or(self.pos, |e| e.key_pos)
    }
}

/// The experiment name; it becomes a directory name, hence the restricted alphabet.
/// The longest experiment `name`, in bytes: it names the results directory, whose name a
/// file system limits (to 255 bytes on most).
pub const MAX_NAME_LEN: usize = 100;

pub(crate) fn name(sections: &Sections) -> Result<String, ConfigError> {
    let node = sections.require("name")?.value;
    let name = node.as_text("name")?;
    if name.len() > MAX_NAME_LEN {
        return Err(ConfigError::at(
            node.pos,
            "name",
            format!(
                "a name of {} bytes cannot be a directory name; at most {MAX_NAME_LEN}",
                name.len()
            ),
        ));
    }
    let allowed = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
    if name.is_empty() || !name.chars().all(allowed) {
        return Err(ConfigError::at(
            node.pos,
            "name",
            format!("'{name}' cannot be a directory name; use letters, digits, '_' and '-' only"),
        ));
    }
    Ok(name.to_string())
}

/// The optional `description`: text the report prints under its title.
pub(crate) fn description(sections: &Sections) -> Result<String, ConfigError> {
    match sections.get("description") {
        Some(entry) => Ok(entry.value.as_text("description")?.trim().to_string()),
        None => Ok(String::new()),
    }
}

/// The chosen benchmark and where it is named (the origin of every default value).
pub(crate) struct Benchmark {
    pub info: &'static BenchmarkInfo,
    pub pos: Pos,
}

pub(crate) fn benchmark(sections: &Sections) -> Result<Benchmark, ConfigError> {
    let node = sections.require("benchmark")?.value;
    let info = pick(
        node,
        "benchmark",
        "benchmark",
        benchmarks::CATALOG.entries,
        |b| b.name,
    )?;
    Ok(Benchmark {
        info,
        pos: node.pos,
    })
}

/// `output: {every: N}`; without it only the first and last states are stored (`every = 0`).
/// Also where `every` is written (the document start without it), for errors about the
/// samples it makes.
pub(crate) fn output(sections: &Sections) -> Result<(OutputSpec, Pos), ConfigError> {
    let unsampled = (OutputSpec { every: 0 }, sections.pos);
    let Some(section) = sections.get("output") else {
        return Ok(unsampled);
    };
    let entries = section.value.entries("output")?;
    reject_unknown_keys(&entries, &["every"], "output")?;
    let Some(every) = find(&entries, "every") else {
        return Ok(unsampled);
    };
    let field = "output.every";
    let node = every.value;
    if let NodeKind::Int(i) = node.kind {
        if i < 1 {
            return Err(ConfigError::at(
                node.pos,
                field,
                format!(
                    "every = {i} is not a sampling interval; omit 'every' to store only the \
                     first and last states"
                ),
            ));
        }
    }
    let every = positive_int(node, field)?;
    let every = usize::try_from(every)
        .map_err(|_| node.expected(field, "an interval that fits in this machine's usize"))?;
    Ok((OutputSpec { every }, node.pos))
}
