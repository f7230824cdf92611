//! The crate's layers: no module of `src/` imports from a module above it, as the layer table
//! of `docs/ARCHITECTURE.md` orders them, and inside each module no two of its parts import
//! each other round a cycle. Test-only code (`#[cfg(test)]` items and the files of
//! `#[cfg(test)] mod` declarations) is left out: a test may build what it checks from above.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

const ARCHITECTURE: &str = "docs/ARCHITECTURE.md";
const LAYERS_HEADING: &str = "## Layers";

/// One source file: its module path below the crate root and its code without test items.
struct Source {
    path: PathBuf,
    module: Vec<String>,
    code: String,
}

/// The layer table: each top-level module with its row, 0 for the top row.
fn layer_table() -> BTreeMap<String, usize> {
    let text = fs::read_to_string(ARCHITECTURE).expect("docs/ARCHITECTURE.md");
    let section = text
        .split(LAYERS_HEADING)
        .nth(1)
        .unwrap_or_else(|| panic!("{ARCHITECTURE} has no `{LAYERS_HEADING}` section"));
    let mut layers = BTreeMap::new();
    let rows = section
        .lines()
        .skip_while(|line| !line.starts_with('|'))
        .take_while(|line| line.starts_with('|'))
        .skip(2);
    for (row, line) in rows.enumerate() {
        let cells: Vec<&str> = line.split('|').collect();
        let modules = cells.get(2).expect("a row `| layer | modules | ... |`");
        for name in modules.split(',') {
            let name = name.trim().trim_matches('`');
            assert!(
                layers.insert(name.to_string(), row).is_none(),
                "{ARCHITECTURE}: `{name}` is in two layers"
            );
        }
    }
    assert!(
        !layers.is_empty(),
        "{ARCHITECTURE}: the layer table is empty"
    );
    layers
}

/// The code with comments and `#[cfg(test)]` items removed, and the names of the modules it
/// declares under `#[cfg(test)]`.
fn without_tests(code: &str) -> (String, Vec<String>) {
    let lines: Vec<&str> = code
        .lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect();
    let mut kept = String::new();
    let mut test_modules = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim() != "#[cfg(test)]" {
            kept.push_str(lines[i]);
            kept.push('\n');
            i += 1;
            continue;
        }
        let mut j = i + 1;
        while j < lines.len() && lines[j].trim().starts_with("#[") {
            j += 1;
        }
        let item = lines.get(j).map_or("", |line| line.trim());
        if item.ends_with(';') {
            if let Some(name) = item
                .strip_prefix("mod ")
                .or_else(|| item.strip_prefix("pub mod "))
            {
                test_modules.push(name.trim_end_matches(';').to_string());
            }
            i = j + 1;
            continue;
        }
        // A block item: up to the brace that closes its first one.
        let mut depth = 0i64;
        let mut opened = false;
        while j < lines.len() {
            depth += lines[j].matches('{').count() as i64 - lines[j].matches('}').count() as i64;
            opened |= lines[j].contains('{');
            j += 1;
            if opened && depth <= 0 {
                break;
            }
        }
        i = j;
    }
    (kept, test_modules)
}

/// Every non-test source file of the library.
fn sources() -> Vec<Source> {
    let mut out = Vec::new();
    collect(Path::new("src"), &[], &BTreeSet::new(), &mut out);
    out
}

/// The files of the module in `dir`, leaving out the test modules that `x.rs` (for a folder
/// `x/` beside it) declares, `tests_declared`, and those its own `mod.rs` declares.
fn collect(
    dir: &Path,
    module: &[String],
    tests_declared: &BTreeSet<String>,
    out: &mut Vec<Source>,
) {
    let mut entries: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.expect("a directory entry").path())
        .collect();
    entries.sort();
    // The directory's own file first, for the test modules it declares.
    let own = if module.is_empty() {
        dir.join("lib.rs")
    } else {
        dir.join("mod.rs")
    };
    let mut test_only = tests_declared.clone();
    if own.exists() {
        let (code, tests) = without_tests(&fs::read_to_string(&own).expect("source"));
        test_only.extend(tests);
        if !module.is_empty() {
            out.push(Source {
                path: own.clone(),
                module: module.to_vec(),
                code,
            });
        }
    }
    for path in entries {
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        if path == own || test_only.contains(stem) || (module.is_empty() && stem == "main") {
            continue;
        }
        let mut child = module.to_vec();
        child.push(stem.to_string());
        if path.is_dir() {
            let beside = path.with_extension("rs");
            let declared = if beside.exists() {
                let code = fs::read_to_string(&beside).expect("source");
                without_tests(&code).1.into_iter().collect()
            } else {
                BTreeSet::new()
            };
            collect(&path, &child, &declared, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let (code, _) = without_tests(&fs::read_to_string(&path).expect("source"));
            out.push(Source {
                path,
                module: child,
                code,
            });
        }
    }
}

/// The identifiers that follow `prefix` in `code`: `prefix::name` and each first name of a
/// `prefix::{a::b, c}` list.
fn names_after(code: &str, prefix: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut names = Vec::new();
    for (at, _) in code.match_indices(prefix) {
        let before = code[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        let rest = &code[at + prefix.len()..];
        if let Some(list) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut item_start = true;
            for (k, c) in list.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => item_start = true,
                    c if item_start && !c.is_whitespace() => {
                        names.push(ident(&list[k..]));
                        item_start = false;
                    }
                    _ => {}
                }
            }
        } else {
            names.push(ident(rest));
        }
    }
    names
}

#[test]
fn no_module_imports_from_a_layer_above_it() {
    let layers = layer_table();
    let sources = sources();
    let modules: BTreeSet<&str> = sources.iter().map(|s| s.module[0].as_str()).collect();
    for module in &modules {
        assert!(
            layers.contains_key(*module),
            "module `{module}` is missing from the layer table of {ARCHITECTURE}"
        );
    }
    for name in layers.keys() {
        assert!(
            modules.contains(name.as_str()),
            "{ARCHITECTURE} lists `{name}`, which is not a module of src/"
        );
    }
    let mut upward = Vec::new();
    for source in &sources {
        let own = &source.module[0];
        for target in names_after(&source.code, "crate::") {
            if &target == own || !layers.contains_key(&target) {
                continue;
            }
            if layers[&target] <= layers[own] {
                upward.push(format!(
                    "{} (`{own}`, layer {}) uses `crate::{target}` (layer {})",
                    source.path.display(),
                    layers[own] + 1,
                    layers[&target] + 1
                ));
            }
        }
    }
    upward.sort();
    upward.dedup();
    assert!(
        upward.is_empty(),
        "imports from the same layer or one above (layers numbered from the top of \
         {ARCHITECTURE}'s table):\n{}",
        upward.join("\n")
    );
}

#[test]
fn no_module_has_parts_that_import_each_other_in_a_cycle() {
    let sources = sources();
    // Per top-level module, the edges between its parts (its files and folders).
    let mut parts: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    for source in sources.iter().filter(|s| s.module.len() >= 2) {
        parts
            .entry(&source.module[0])
            .or_default()
            .insert(&source.module[1]);
    }
    let mut edges: BTreeMap<(&str, &str), BTreeSet<&str>> = BTreeMap::new();
    for source in sources.iter().filter(|s| s.module.len() >= 2) {
        let (top, part) = (source.module[0].as_str(), source.module[1].as_str());
        let siblings = &parts[top];
        let mut named = names_after(&source.code, &format!("crate::{top}::"));
        // `super` of a part's own file is the module; of a file inside a part, the part.
        let is_part_file = source.module.len() == 2
            || (source.module.len() == 3 && source.path.ends_with("mod.rs"));
        let up = if is_part_file {
            "super::"
        } else {
            "super::super::"
        };
        if source.module.len() <= 3 {
            named.extend(names_after(&source.code, up));
        }
        for name in named {
            if name != part {
                if let Some(sibling) = siblings.get(name.as_str()) {
                    edges.entry((top, part)).or_default().insert(sibling);
                }
            }
        }
    }
    // A depth-first search from every part; a part met again on the current path closes a
    // cycle.
    fn visit<'a>(
        node: (&'a str, &'a str),
        edges: &BTreeMap<(&'a str, &'a str), BTreeSet<&'a str>>,
        path: &mut Vec<&'a str>,
        done: &mut BTreeSet<(&'a str, &'a str)>,
        cycles: &mut Vec<String>,
    ) {
        if let Some(at) = path.iter().position(|p| *p == node.1) {
            let mut cycle: Vec<&str> = path[at..].to_vec();
            cycle.push(node.1);
            cycles.push(format!("{}: {}", node.0, cycle.join(" -> ")));
            return;
        }
        if !done.insert(node) {
            return;
        }
        path.push(node.1);
        for next in edges.get(&node).into_iter().flatten() {
            visit((node.0, next), edges, path, done, cycles);
        }
        path.pop();
    }
    let mut cycles = Vec::new();
    let mut done = BTreeSet::new();
    for &node in edges.keys() {
        visit(node, &edges, &mut Vec::new(), &mut done, &mut cycles);
    }
    assert!(
        cycles.is_empty(),
        "parts of a module that import each other round a cycle:\n{}",
        cycles.join("\n")
    );
}

#[test]
fn the_checks_see_the_imports() {
    let code = "use crate::grid::{Domain, Grid};\nuse super::{stream::X, probes};\n\
                let x = crate::gauss::rule(3);\n";
    assert_eq!(names_after(code, "crate::"), ["grid", "gauss"]);
    assert_eq!(names_after(code, "super::"), ["stream", "probes"]);
    let (kept, tests) = without_tests(
        "use crate::a::B;\n#[cfg(test)]\nmod tests;\n#[cfg(test)]\nmod inline {\n    \
         use crate::c::D;\n}\n// crate::e\nfn f() {}\n",
    );
    assert_eq!(tests, ["tests"]);
    assert_eq!(names_after(&kept, "crate::"), ["a"]);
}
