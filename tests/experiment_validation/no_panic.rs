//! Experiment files: no input at all makes the parser panic, and every error is located.

use super::*;

/// A small deterministic generator, so that a failure can be replayed.
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Whole documents that are odd in one way each.
const ODD_DOCUMENTS: &[&str] = &[
    "",
    "\n\n",
    "---\n",
    "~",
    "- a\n- b\n",
    "[1, 2]",
    "42",
    "just text",
    "\u{feff}name: x\n",
    "name:\n\tx\n",
    "\tname: x\n",
    "name: x\r\nbenchmark: mms1d_gong\r\n",
    "name: x\nname: y\n",
    "? [a, b]\n: c\n",
    "name: &a x\nbenchmark: *a\n",
    "name: *missing\n",
    "a: &a [*a]\n",
    "--- a\n--- b\n",
    "%YAML 9.9\n---\nname: x\n",
    "name: !!binary aGVsbG8=\n",
    "name: !custom x\nbenchmark: !!int mms\n",
    "name: \"\\q\"\n",
    "name: 'unterminated\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 1e999, ppc: 99999999999999999999999, method: mpm, cells: .nan}\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: -.inf, ppc: -9223372036854775808, method: mpm, cells: 18446744073709551615}\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 0.1, ppc: 1, method: mpm, cells: 9223372036854775807}\n",
    "name: ünïcødé\nbenchmark: mms1d_gong\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 0.1, ppc: 1, método: mpm}\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 0.1, ppc: 1, method: 🦀, cells: 8}\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {<<: {G: 0.1, ppc: 1}, method: mpm, cells: 8}\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 0.1, ppc: 1, method: mpm, cells: 8}\nmatrix: {}\nexpect: []\nfigures: []\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 0.1, ppc: 1, method: mpm, cells: 8}\nexpect: [1, [], {}, {field: velocity, rate_min: 1, method: mpm}]\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 0.1, ppc: 1, method: mpm, cells: 8}\nfigures: [{kind: convergence, fields: []}]\n",
    "name: x\nbenchmark: mms1d_gong\nparams: {G: 0.1, ppc: 1, method: mpm, cells: 8}\noutput: {every: 99999999999999999999}\n",
    "name: x\nbenchmark: mms1d_gong\nparams:\nmatrix:\noutput:\nexpect:\nfigures:\n",
];

/// Values dropped in place of the valid file's scalars: every wrong type and edge case.
const ODD_VALUES: &[&str] = &[
    "~",
    "true",
    "0",
    "-1",
    "8.0",
    "1e999",
    ".nan",
    "99999999999999999999",
    "[]",
    "{a: 1}",
    "'8'",
    "ünï",
    "\"\\u0000\"",
    "cells",
];

/// Characters that matter to YAML, spliced in at random.
const ODD_CHARS: &[&str] = &[
    ":", "{", "}", "[", "]", ",", "-", "#", "&a", "*a", "!", "|", ">", "'", "\"", "%", "@", "\t",
    "\n", " ", "?", "é", "\u{0}", "\r", "9", ".",
];

fn assert_no_panic_and_located(text: &str) {
    let result = std::panic::catch_unwind(|| parse(text));
    let Ok(result) = result else {
        panic!("parser panicked on {text:?}");
    };
    if let Err(e) = result {
        assert!(
            e.line >= 1 && e.column >= 1,
            "unlocated error {e} for {text:?}"
        );
        assert!(
            !e.field.is_empty() && !e.message.is_empty(),
            "{e} for {text:?}"
        );
        assert!(!e.to_string().contains('\n'), "multi-line error {e:?}");
    }
}

#[test]
fn odd_documents_never_panic_and_errors_are_located() {
    for text in ODD_DOCUMENTS {
        assert_no_panic_and_located(text);
    }
}

#[test]
fn every_scalar_replaced_by_odd_values_never_panics() {
    for valid in [VALID, RECONSTRUCTION] {
        let starts = valid.char_indices().filter(|&(i, c)| {
            let prev = valid[..i].chars().last();
            c.is_alphanumeric() && matches!(prev, Some(' ' | '[' | '{'))
        });
        for (start, _) in starts {
            let end = valid[start..]
                .find([',', '}', ']', '\n'])
                .map_or(valid.len(), |n| start + n);
            for value in ODD_VALUES {
                let text = format!("{}{value}{}", &valid[..start], &valid[end..]);
                assert_no_panic_and_located(&text);
            }
        }
    }
}

#[test]
fn random_splices_cuts_and_swaps_never_panic() {
    let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
    for round in 0..1200 {
        let valid = if round % 2 == 0 {
            VALID
        } else {
            RECONSTRUCTION
        };
        let mut text: Vec<char> = valid.chars().collect();
        for _ in 0..1 + rng.below(3) {
            let at = rng.below(text.len() + 1);
            match rng.below(3) {
                0 => {
                    let odd = ODD_CHARS[rng.below(ODD_CHARS.len())];
                    text.splice(at..at, odd.chars());
                }
                1 => {
                    let to = (at + rng.below(8)).min(text.len());
                    text.drain(at..to);
                }
                _ => {
                    let joined: String = text.iter().collect();
                    let mut lines: Vec<&str> = joined.lines().collect();
                    let n = lines.len().max(1);
                    let (a, b) = (rng.below(n), rng.below(n));
                    if b < lines.len() {
                        lines.swap(a.min(b), b);
                    }
                    text = lines.join("\n").chars().collect();
                }
            }
        }
        assert_no_panic_and_located(&text.iter().collect::<String>());
    }
}

// ---------------------------------------------------------------------------------------------
// Reconstruction benchmarks: choices, point lists, matrix blocks, figure and table kinds.
