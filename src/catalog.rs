//! A catalogue of named things (method presets, benchmarks, and the parts a method is made
//! of): found by name, listed, and named in the error for an unknown one.

/// What a catalogue entry is called in experiment files.
pub trait Named {
    fn name(&self) -> &'static str;
}

/// One entry of a catalogue of parts: what experiment files call it, what it is, and a line
/// that says so.
#[derive(Debug)]
pub struct Entry<T: 'static> {
    pub name: &'static str,
    pub value: T,
    pub description: &'static str,
}

impl<T> Named for Entry<T> {
    fn name(&self) -> &'static str {
        self.name
    }
}

/// The entries of one kind of thing, in the order listings show them.
#[derive(Debug)]
pub struct Catalog<T: 'static> {
    /// What an entry is, in the singular ("shape function"), for messages.
    pub kind: &'static str,
    pub entries: &'static [T],
}

/// A catalogue of parts, each entry a value with its name and description.
pub type Parts<T> = Catalog<Entry<T>>;

impl<T: Named> Catalog<T> {
    pub fn find(&self, name: &str) -> Option<&'static T> {
        self.entries.iter().find(|e| e.name() == name)
    }

    pub fn names(&self) -> Vec<&'static str> {
        self.entries.iter().map(|e| e.name()).collect()
    }

    /// The entry `name`, or an error that lists the valid names.
    pub fn get(&self, name: &str) -> Result<&'static T, String> {
        self.find(name).ok_or_else(|| {
            format!(
                "unknown {} '{name}'; valid: {}",
                self.kind,
                self.names().join(", ")
            )
        })
    }
}

impl<T: PartialEq> Parts<T> {
    /// The name of the first entry whose value is `value`.
    pub fn name_of(&self, value: &T) -> Option<&'static str> {
        self.entries
            .iter()
            .find(|e| &e.value == value)
            .map(|e| e.name)
    }
}

/// The entries' names as an array, for the choices of a parameter: `N` must be
/// `entries.len()`.
pub const fn names_of<T, const N: usize>(entries: &[Entry<T>]) -> [&'static str; N] {
    assert!(entries.len() == N, "N is the number of entries");
    let mut names = [""; N];
    let mut i = 0;
    while i < N {
        names[i] = entries[i].name;
        i += 1;
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    const DIGITS: Parts<u8> = Catalog {
        kind: "digit",
        entries: &[
            Entry {
                name: "one",
                value: 1,
                description: "the first",
            },
            Entry {
                name: "two",
                value: 2,
                description: "the second",
            },
        ],
    };

    #[test]
    fn entries_are_found_by_name_and_value() {
        assert_eq!(DIGITS.find("two").map(|e| e.value), Some(2));
        assert_eq!(DIGITS.name_of(&1), Some("one"));
        assert_eq!(DIGITS.names(), ["one", "two"]);
        assert_eq!(names_of::<u8, 2>(DIGITS.entries), ["one", "two"]);
        assert_eq!(
            DIGITS.get("three").unwrap_err(),
            "unknown digit 'three'; valid: one, two"
        );
    }
}
