//! The one error type of experiment files: where (file, line, column, field) and what.

use std::fmt;
use std::path::{Path, PathBuf};

/// Field names for problems with the document as a whole (empty, not a map) and with
/// reading the file at all.
pub(crate) const DOCUMENT_FIELD: &str = "(document)";
pub(crate) const FILE_FIELD: &str = "(file)";

/// A problem in an experiment file, located precisely enough to jump to it.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigError {
    pub file: PathBuf,
    /// 1-based line and column of the offending key or value.
    pub line: usize,
    pub column: usize,
    /// Dotted path of the offending entry: `params.cfl`, `matrix.cells[2]`, `expect[1].rate_min`.
    pub field: String,
    pub message: String,
    /// The accepted choices, when the value had to be one of a known set.
    pub valid: Vec<String>,
}

impl ConfigError {
    /// An error at a position; the file is attached once, by `parse`.
    pub(crate) fn at(pos: Pos, field: impl Into<String>, message: impl Into<String>) -> Self {
        ConfigError {
            file: PathBuf::new(),
            line: pos.line,
            column: pos.column,
            field: field.into(),
            message: message.into(),
            valid: Vec::new(),
        }
    }

    pub(crate) fn with_valid<S: ToString>(mut self, valid: impl IntoIterator<Item = S>) -> Self {
        self.valid = valid.into_iter().map(|s| s.to_string()).collect();
        self
    }

    pub(crate) fn in_file(mut self, path: &Path) -> Self {
        self.file = path.to_path_buf();
        self
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: field '{}': {}",
            self.file.display(),
            self.line,
            self.column,
            self.field,
            self.message
        )?;
        if !self.valid.is_empty() {
            write!(f, " (valid: {})", self.valid.join(", "))?;
        }
        Ok(())
    }
}

impl std::error::Error for ConfigError {}

/// A 1-based position in the source text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Pos {
    pub line: usize,
    pub column: usize,
}

impl Pos {
    /// The start of the file, for problems that have no better place.
    pub(crate) const START: Pos = Pos { line: 1, column: 1 };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_file_position_field_and_choices() {
        let e = ConfigError::at(
            Pos { line: 3, column: 7 },
            "params.method",
            "unknown method 'x'",
        )
        .with_valid(["mpm", "gimp"])
        .in_file(Path::new("exp.yaml"));
        assert_eq!(
            e.to_string(),
            "exp.yaml:3:7: field 'params.method': unknown method 'x' (valid: mpm, gimp)"
        );
        let e = ConfigError::at(Pos::START, "name", "missing").in_file(Path::new("a.yaml"));
        assert_eq!(e.to_string(), "a.yaml:1:1: field 'name': missing");
    }
}
