//! Mutation fuzzing of the experiment front end and of `run` on tiny problems.
//!
//! Every committed experiment and reduced matrix is a seed; a mutant applies one to three
//! random edits to a seed (a value replaced by an extreme or malformed one, a line deleted,
//! duplicated, re-indented or taken from another seed, a key misspelt, bytes that are not
//! UTF-8, a truncation) and is written to a file and loaded. A mutant is a finding when
//! * loading it panics;
//! * its error does not name the file, a line and column inside it and a field, or speaks in
//!   the YAML library's words instead of the project's;
//! * it is accepted, small enough to run (at most `RUN_COST` particle-steps in all), and
//!   running it panics, returns an error, leaves a run without its file, or records a run
//!   that failed on an internal error (a panic).
//!
//! `fixed_seed_mutants` replays a fixed set of mutants on every `cargo test`;
//! `replay_findings` loads every input once found and kept in `tests/inputs/fuzz/`;
//! `fuzz_open_ended` (ignored; `make fuzz`) mutates for `MPMLAB_FUZZ_SECONDS` seconds from
//! `MPMLAB_FUZZ_SEED` and writes each finding to `target/fuzz/findings/`.

use std::fs;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use mpmlab::experiment::{self, Experiment};
use mpmlab::output::{open_run_file, read_summary, run_path, RunStatus};
use mpmlab::rng::Lcg;
use mpmlab::runner::{estimated_cost, results_dir};

/// Particle-steps of all runs of an accepted mutant, at most, for it to be run.
const RUN_COST: u64 = 400_000;
/// Runs of an accepted mutant, at most, for it to be run.
const RUN_COUNT: usize = 6;

/// Seconds a mutant may take to load, and to run when it is small, at most.
const LOAD_SECONDS: f64 = 5.0;
const RUN_SECONDS: f64 = 30.0;

/// Words of the YAML library's messages that must not reach a user.
const LIBRARY_WORDS: [&str; 6] = [
    "budget breached",
    "from_str",
    "Nodes {",
    "saphyr",
    "serde",
    "Error {",
];

/// Values a mutation writes in place of a scalar: extremes, non-numbers, wrong types,
/// YAML structure where a scalar was, tags, anchors and unbalanced quotes or brackets.
const VALUES: [&str; 44] = [
    "0",
    "-1",
    "1",
    "2",
    "-0.0",
    "0.5",
    "1.0e-300",
    "1.0e300",
    "1e-9",
    "1e9",
    "4294967297",
    "18446744073709551616",
    "-9223372036854775808",
    ".nan",
    ".inf",
    "-.inf",
    "~",
    "null",
    "true",
    "no",
    "\"\"",
    "\"x\"",
    "[]",
    "{}",
    "[1, 2, 3]",
    "[0.5, 1.0e300]",
    "[8, 8]",
    "!foo 1",
    "!!str 3",
    "&a 1",
    "*a",
    "{a: 1}",
    "'",
    "\"",
    "[",
    "{",
    "- 1",
    "mpm",
    "cpdi2",
    "lme",
    "é",
    "\t1",
    "1 # comment",
    "0x10",
];

struct Seed {
    name: String,
    text: String,
}

/// The committed experiments and reduced matrices.
fn seeds() -> Vec<Seed> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut seeds = Vec::new();
    for dir in ["experiments", "tests/matrices"] {
        let mut paths: Vec<PathBuf> = fs::read_dir(root.join(dir))
            .unwrap()
            .map(|entry| entry.unwrap().path())
            .filter(|path| path.extension().is_some_and(|e| e == "yaml"))
            .collect();
        paths.sort();
        for path in paths {
            seeds.push(Seed {
                name: path.file_stem().unwrap().to_string_lossy().into_owned(),
                text: fs::read_to_string(&path).unwrap(),
            });
        }
    }
    assert!(seeds.len() > 10, "the seeds are the committed experiments");
    seeds
}

/// Random edits of seed texts.
struct Mutator {
    rng: Lcg,
    /// Every key written in any seed, for misspellings that are real keys elsewhere.
    keys: Vec<String>,
}

impl Mutator {
    fn new(seed: u64, seeds: &[Seed]) -> Self {
        let mut keys: Vec<String> = seeds
            .iter()
            .flat_map(|s| s.text.lines())
            .filter_map(|line| {
                let key = line
                    .trim_start()
                    .trim_start_matches("- ")
                    .split(':')
                    .next()?;
                let key = key.trim();
                (!key.is_empty() && key.chars().all(|c| c.is_alphanumeric() || c == '_'))
                    .then(|| key.to_string())
            })
            .collect();
        keys.sort();
        keys.dedup();
        Mutator {
            rng: Lcg::new(seed),
            keys,
        }
    }

    fn below(&mut self, n: usize) -> usize {
        ((self.rng.unit() * n as f64) as usize).min(n.saturating_sub(1))
    }

    fn pick<'a>(&mut self, items: &'a [&'a str]) -> &'a str {
        items[self.below(items.len())]
    }

    /// One to three edits of `seeds[k]`, as bytes (a mutant need not be UTF-8).
    fn mutant(&mut self, seeds: &[Seed], k: usize) -> (Vec<u8>, Vec<String>) {
        let mut lines: Vec<String> = seeds[k].text.lines().map(str::to_string).collect();
        let mut edits = Vec::new();
        let mut bytes_edit = None;
        for _ in 0..1 + self.below(3) {
            if lines.is_empty() {
                break;
            }
            let i = self.below(lines.len());
            let edit = match self.below(11) {
                0..=3 => {
                    let value = self.value();
                    let line = &mut lines[i];
                    match line.find(": ").or_else(|| line.find("- ")) {
                        Some(at) => line.replace_range(at + 2.., &value),
                        None => line.push_str(&format!(": {value}")),
                    }
                    format!("line {}: value {}", i + 1, abbreviate(&value))
                }
                4 => {
                    let line = scale_numbers(&lines[i], self.below(5));
                    lines[i] = line;
                    format!("line {}: numbers scaled", i + 1)
                }
                5 => {
                    lines.remove(i);
                    format!("line {} deleted", i + 1)
                }
                6 => {
                    let line = lines[i].clone();
                    lines.insert(i, line);
                    format!("line {} duplicated", i + 1)
                }
                7 => {
                    let indent = self.pick(&["", "  ", "    ", "\t", " "]);
                    lines[i] = format!("{indent}{}", lines[i].trim_start());
                    format!("line {} re-indented", i + 1)
                }
                8 => {
                    let j = self.below(self.keys.len());
                    let key = self.keys[j].clone();
                    let line = &mut lines[i];
                    if let Some(colon) = line.find(':') {
                        let start = line.len() - line.trim_start().len();
                        let start = if line[start..].starts_with("- ") {
                            start + 2
                        } else {
                            start
                        };
                        if start < colon {
                            line.replace_range(start..colon, &key);
                        }
                    }
                    format!("line {}: key {key}", i + 1)
                }
                9 => {
                    let other = &seeds[self.below(seeds.len())].text;
                    let other: Vec<&str> = other.lines().collect();
                    let line = other[self.below(other.len())].to_string();
                    lines.insert(i, line);
                    format!("line {} from another seed", i + 1)
                }
                _ => {
                    bytes_edit = Some(self.below(2));
                    "bytes".to_string()
                }
            };
            edits.push(edit);
        }
        let mut bytes = (lines.join("\n") + "\n").into_bytes();
        match bytes_edit {
            Some(0) => {
                let at = self.below(bytes.len());
                let junk: &[u8] =
                    [&[0xffu8][..], &[0xc3, 0x28], &[0], &[0xe2, 0x82]][self.below(4)];
                bytes.splice(at..at, junk.iter().copied());
                edits.push(format!("byte {at}: not UTF-8 or NUL"));
            }
            Some(_) => {
                let at = self.below(bytes.len());
                bytes.truncate(at);
                edits.push(format!("truncated at byte {at}"));
            }
            None => {}
        }
        (bytes, edits)
    }

    /// A replacement value: from `VALUES`, or a long list or text.
    fn value(&mut self) -> String {
        match self.below(12) {
            0 => {
                let n = [40, 2_000, 30_000][self.below(3)];
                let items: Vec<String> = (0..n).map(|i| format!("{}", 0.5 + i as f64)).collect();
                format!("[{}]", items.join(", "))
            }
            1 => "a".repeat([300, 70_000][self.below(2)]),
            _ => VALUES[self.below(VALUES.len())].to_string(),
        }
    }
}

/// `line` with every number multiplied by a power of ten, negated or zeroed.
fn scale_numbers(line: &str, how: usize) -> String {
    let factor = ["1e-12", "1e12", "-1", "0", "1e300"][how];
    let mut out = String::new();
    let mut number = String::new();
    let flush = |number: &mut String, out: &mut String| {
        if !number.is_empty() {
            let value: f64 = number.parse().unwrap_or(0.0);
            let factor: f64 = factor.parse().unwrap();
            out.push_str(&format!("{:e}", value * factor));
            number.clear();
        }
    };
    for c in line.chars() {
        if c.is_ascii_digit() || (c == '.' && !number.is_empty()) {
            number.push(c);
        } else {
            flush(&mut number, &mut out);
            out.push(c);
        }
    }
    flush(&mut number, &mut out);
    out
}

fn abbreviate(text: &str) -> String {
    if text.len() > 40 {
        format!("{}... ({} bytes)", &text[..20], text.len())
    } else {
        text.to_string()
    }
}

/// What a mutant did.
#[derive(Debug, PartialEq)]
enum Outcome {
    Refused,
    Accepted,
    Ran,
}

/// Loads `bytes` from `dir/<name>.yaml` and, if accepted and small, runs it into `dir/out`;
/// `Err` describes a finding.
fn check(dir: &Path, name: &str, bytes: &[u8]) -> Result<Outcome, String> {
    // One mutant at a time: tens of thousands of files left in one directory slow it down.
    let dir = &dir.join("mutant");
    let _ = fs::remove_dir_all(dir);
    fs::create_dir_all(dir).unwrap();
    let path = dir.join(format!("{name}.yaml"));
    fs::write(&path, bytes).unwrap();
    let lines = bytes.split(|&b| b == b'\n').count();
    let started = Instant::now();
    let loaded = catch_unwind(AssertUnwindSafe(|| experiment::load(&path)))
        .map_err(|panic| format!("load panicked: {}", panic_text(&panic)))?;
    let seconds = started.elapsed().as_secs_f64();
    if seconds > LOAD_SECONDS {
        return Err(format!("loading took {seconds:.1} s"));
    }
    let experiment = match loaded {
        Err(error) => {
            let text = error.to_string();
            if let Err(invalid) = std::str::from_utf8(bytes) {
                let line = 1 + bytes[..invalid.valid_up_to()]
                    .iter()
                    .filter(|&&b| b == b'\n')
                    .count();
                if error.line != line {
                    return Err(format!("invalid UTF-8 on line {line}, reported: {text}"));
                }
            }
            if error.file != path || !text.starts_with(&path.display().to_string()) {
                return Err(format!("error does not name the file: {text}"));
            }
            if error.line == 0 || error.line > lines || error.column == 0 {
                return Err(format!("position outside the file ({lines} lines): {text}"));
            }
            if error.field.is_empty() || error.message.is_empty() {
                return Err(format!("error without field or message: {text}"));
            }
            if let Some(word) = LIBRARY_WORDS.iter().find(|w| text.contains(*w)) {
                return Err(format!("library wording '{word}': {text}"));
            }
            return Ok(Outcome::Refused);
        }
        Ok(experiment) => experiment,
    };
    let cost: u64 = experiment.runs.iter().map(estimated_cost).sum();
    if experiment.runs.len() > RUN_COUNT || cost > RUN_COST {
        return Ok(Outcome::Accepted);
    }
    run_mutant(&experiment, &dir.join("out"))?;
    Ok(Outcome::Ran)
}

/// Runs an accepted mutant with the `mpmlab` binary, so that an abort is a finding and not
/// the end of the fuzzing; the command must exit 0 within `RUN_SECONDS` and every run must
/// end with a readable file that records no internal error.
fn run_mutant(experiment: &Experiment, out: &Path) -> Result<(), String> {
    let _ = fs::remove_dir_all(out);
    // A file, not a pipe: a pipe nobody reads until the end blocks a talkative child.
    let log = out.with_extension("log");
    let mut child = Command::new(env!("CARGO_BIN_EXE_mpmlab"))
        .arg("run")
        .arg("--out")
        .arg(out)
        .args(["--jobs", "1"])
        .arg(&experiment.source_path)
        .stdout(Stdio::null())
        .stderr(fs::File::create(&log).map_err(|e| e.to_string())?)
        .spawn()
        .map_err(|e| format!("cannot start mpmlab: {e}"))?;
    let started = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            break status;
        }
        if started.elapsed().as_secs_f64() > RUN_SECONDS {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("run took more than {RUN_SECONDS} s"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr = fs::read_to_string(&log).unwrap_or_default();
    if !status.success() {
        let tail: String = stderr.lines().rev().take(3).collect::<Vec<_>>().join(" | ");
        return Err(format!("run ended with {status}: {tail}"));
    }
    let dir = results_dir(out, experiment);
    for run in &experiment.runs {
        let path = run_path(&dir, &run.spec.run_id);
        let summary = open_run_file(&path)
            .and_then(|file| read_summary(&file))
            .map_err(|e| format!("run {} has no readable file: {e}", run.spec.run_id))?;
        if summary.status == RunStatus::Failed && summary.message.contains("panicked") {
            return Err(format!(
                "run {} failed internally: {}",
                run.spec.run_id, summary.message
            ));
        }
    }
    Ok(())
}

fn panic_text(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "(no message)".to_string())
}

#[derive(Default)]
struct Tally {
    mutants: usize,
    refused: usize,
    accepted: usize,
    ran: usize,
    /// Each finding: the mutant (its name and edits), and what was wrong.
    findings: Vec<(String, String)>,
    /// The longest check, in seconds, and its mutant.
    slowest: (f64, String),
}

/// Mutants from `seed` until `count` are made or `time` is up; findings are written to
/// `keep` when given.
fn fuzz(seed: u64, count: usize, time: Duration, keep: Option<&Path>) -> Tally {
    let seeds = seeds();
    let mut mutator = Mutator::new(seed, &seeds);
    let dir = tempfile::tempdir().unwrap();
    let started = Instant::now();
    let mut tally = Tally::default();
    // A panic is a finding, reported once with its mutant, not printed for every one.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    while tally.mutants < count && started.elapsed() < time {
        let k = tally.mutants % seeds.len();
        let (bytes, edits) = mutator.mutant(&seeds, k);
        let name = format!("{}_{}", seeds[k].name, tally.mutants);
        tally.mutants += 1;
        let one = Instant::now();
        let checked = catch_unwind(AssertUnwindSafe(|| check(dir.path(), &name, &bytes)))
            .unwrap_or_else(|panic| Err(format!("panicked: {}", panic_text(&panic))));
        let seconds = one.elapsed().as_secs_f64();
        if seconds > tally.slowest.0 {
            tally.slowest = (seconds, name.clone());
        }
        match checked {
            Ok(Outcome::Refused) => tally.refused += 1,
            Ok(Outcome::Accepted) => tally.accepted += 1,
            Ok(Outcome::Ran) => tally.ran += 1,
            Err(finding) => {
                let mutant = format!("{name} ({})", edits.join("; "));
                if let Some(keep) = keep {
                    fs::create_dir_all(keep).unwrap();
                    fs::write(keep.join(format!("{name}.yaml")), &bytes).unwrap();
                    fs::write(
                        keep.join(format!("{name}.txt")),
                        format!("{mutant}: {finding}"),
                    )
                    .unwrap();
                }
                tally.findings.push((mutant, finding));
            }
        }
    }
    std::panic::set_hook(hook);
    tally
}

/// The tally, and the findings by class (the words before their first colon or number)
/// with the first example of each.
fn report(tally: &Tally, seconds: f64) -> String {
    let mut text = format!(
        "{} mutants in {seconds:.0} s: {} refused, {} accepted, {} also run; {} findings; \
         slowest {} in {:.1} s",
        tally.mutants,
        tally.refused,
        tally.accepted,
        tally.ran,
        tally.findings.len(),
        tally.slowest.1,
        tally.slowest.0
    );
    let mut classes: Vec<(String, usize, &String)> = Vec::new();
    for (mutant, finding) in &tally.findings {
        let class: String = finding
            .split(':')
            .next()
            .unwrap_or_default()
            .chars()
            .map(|c| if c.is_ascii_digit() { 'N' } else { c })
            .collect();
        match classes.iter_mut().find(|(c, _, _)| *c == class) {
            Some((_, count, _)) => *count += 1,
            None => classes.push((class, 1, mutant)),
        }
    }
    for (class, count, mutant) in classes {
        let example = tally.findings.iter().find(|(m, _)| m == mutant).unwrap();
        let example: String = format!("{}: {}", example.0, example.1)
            .chars()
            .take(600)
            .collect();
        text.push_str(&format!("\n  {count} x {class}\n    e.g. {example}"));
    }
    text
}

/// The same mutants on every run of the tests: each class of input the fuzzer has ever
/// found wrong recurs among them.
#[test]
fn fixed_seed_mutants() {
    let started = Instant::now();
    let tally = fuzz(20, 600, Duration::MAX, None);
    let text = report(&tally, started.elapsed().as_secs_f64());
    println!("{text}");
    assert!(tally.findings.is_empty(), "{text}");
    assert!(
        tally.refused > 0 && tally.accepted + tally.ran > 0,
        "{text}"
    );
}

/// Inputs the fuzzer found wrong once, kept as they were found.
#[test]
fn replay_findings() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/inputs/fuzz");
    let dir = tempfile::tempdir().unwrap();
    let mut inputs: Vec<PathBuf> = fs::read_dir(&root)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "yaml"))
        .collect();
    inputs.sort();
    assert!(!inputs.is_empty(), "no inputs in {}", root.display());
    let findings: Vec<String> = inputs
        .iter()
        .filter_map(|input| {
            let name = input.file_stem().unwrap().to_string_lossy();
            check(dir.path(), &name, &fs::read(input).unwrap())
                .err()
                .map(|finding| format!("{}: {finding}", input.display()))
        })
        .collect();
    assert!(findings.is_empty(), "{}", findings.join("\n"));
}

/// `make fuzz`: mutants for `MPMLAB_FUZZ_SECONDS` (default 300) from `MPMLAB_FUZZ_SEED`
/// (default: the clock), findings kept in `target/fuzz/findings/`.
#[test]
#[ignore = "open-ended; run by make fuzz"]
fn fuzz_open_ended() {
    let seconds: u64 = std::env::var("MPMLAB_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    let seed: u64 = std::env::var("MPMLAB_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(1, |d| d.as_secs())
        });
    let keep = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/fuzz/findings");
    let started = Instant::now();
    let tally = fuzz(seed, usize::MAX, Duration::from_secs(seconds), Some(&keep));
    let text = report(&tally, started.elapsed().as_secs_f64());
    println!("seed {seed}: {text}");
    assert!(
        tally.findings.is_empty(),
        "seed {seed}: {text}\n(inputs in {})",
        keep.display()
    );
}
