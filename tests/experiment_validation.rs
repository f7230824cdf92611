//! Experiment files: every bad input gives one located error (file, line, column, field, and
//! the valid choices where there are any), a valid file expands into stable run ids, and no
//! input at all makes the parser panic.

use std::collections::HashSet;
use std::path::Path;

use mpmlab::experiment::{self, ConfigError, Experiment, FieldMapSpec, FigureKind, MAX_RUNS};
use mpmlab::params::ParamValue;

const FILE: &str = "exp.yaml";

const VALID: &str = "\
name: gong_mpm_1d
benchmark: mms1d_gong
params: {E: 1.0e7, nu: 0.3, rho0: 1000.0, t_end: 0.02, cfl: 0.4, ppc: 2, method: mpm}
matrix:
  G: [1.0e-4, 0.1]
  cells: [8, 16, 32, 64, 128]
output: {every: 10}
expect:
  - {G: 1.0e-4, field: velocity, norm: l2, rate_min: 1.8}
  - {G: 0.1, field: stress, rate_max: 1.0}
figures:
  - {kind: convergence, fields: [stress, density, velocity, displacement], by: G}
";

fn parse(text: &str) -> Result<Experiment, ConfigError> {
    experiment::parse(text, Path::new(FILE))
}

fn error(text: &str) -> ConfigError {
    match parse(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e,
    }
}

/// The valid file with its first `from` replaced by `to`.
fn edited(from: &str, to: &str) -> String {
    let text = VALID.replacen(from, to, 1);
    assert_ne!(text, VALID, "'{from}' is not in the valid file");
    text
}

/// Checks where the error is, what it names and that it mentions `message`; `valid` must all
/// be among the listed choices (and show in the one-line display).
fn check(e: &ConfigError, line: usize, column: usize, field: &str, message: &str, valid: &[&str]) {
    let shown = e.to_string();
    assert_eq!(
        (e.line, e.column, e.field.as_str()),
        (line, column, field),
        "{shown}"
    );
    assert!(e.message.contains(message), "'{message}' not in: {shown}");
    assert!(
        shown.starts_with(&format!("{FILE}:{line}:{column}: field '{field}': ")),
        "{shown}"
    );
    for choice in valid {
        assert!(
            e.valid.iter().any(|v| v == choice),
            "{choice} not listed: {shown}"
        );
    }
    if !valid.is_empty() {
        assert!(
            shown.ends_with(&format!("(valid: {})", e.valid.join(", "))),
            "{shown}"
        );
    }
}

#[test]
fn unknown_method_lists_the_presets() {
    let e = error(&edited("method: mpm", "method: flip"));
    check(
        &e,
        3,
        82,
        "params.method",
        "unknown method 'flip'",
        &["mpm"],
    );
    let text = edited("ppc: 2, method: mpm}", "ppc: 2}")
        .replace("matrix:\n", "matrix:\n  method: [mpm, flip]\n");
    let e = error(&text);
    check(&e, 5, 17, "matrix.method[1]", "unknown method", &["mpm"]);
}

#[test]
fn missing_method_lists_the_presets() {
    let e = error(&edited(", method: mpm}", "}"));
    check(&e, 3, 1, "params.method", "required", &["mpm"]);
}

#[test]
fn unknown_benchmark_lists_the_catalogue() {
    let e = error(&edited("benchmark: mms1d_gong", "benchmark: mms3d"));
    check(
        &e,
        2,
        12,
        "benchmark",
        "unknown benchmark 'mms3d'",
        &["mms1d_gong", "mms2d_gong"],
    );
}

#[test]
fn unknown_top_level_key_lists_the_sections() {
    let e = error(&edited("output:", "outputs:"));
    let sections = [
        "name",
        "benchmark",
        "params",
        "matrix",
        "output",
        "expect",
        "figures",
    ];
    check(&e, 7, 1, "outputs", "unknown key 'outputs'", &sections);
}

#[test]
fn unknown_parameter_lists_the_benchmark_parameters() {
    let e = error(&edited("nu: 0.3", "poisson: 0.3"));
    check(
        &e,
        3,
        20,
        "params.poisson",
        "unknown parameter 'poisson'",
        &["nu", "cfl", "method"],
    );
    let e = error(&edited("  G: [", "  g: ["));
    check(
        &e,
        5,
        3,
        "matrix.g",
        "unknown parameter 'g'",
        &["G", "cells"],
    );
}

#[test]
fn wrong_types_name_the_expected_type() {
    let e = error(&edited("E: 1.0e7", "E: stiff"));
    check(
        &e,
        3,
        13,
        "params.E",
        "expected a finite number > 0, found the text 'stiff'",
        &[],
    );
    let e = error(&edited("ppc: 2", "ppc: '2'"));
    check(&e, 3, 71, "params.ppc", "expected an integer", &[]);
    let e = error(&edited("G: [1.0e-4, 0.1]", "G: 0.1"));
    check(
        &e,
        5,
        6,
        "matrix.G",
        "expected a list, found the number 0.1",
        &[],
    );
    let e = error(&edited("params: {", "params: [{").replace("method: mpm}", "method: mpm}]"));
    check(&e, 3, 9, "params", "expected a map, found a list", &[]);
    let e = error(&edited("t_end: 0.02", "t_end: .inf"));
    check(&e, 3, 50, "params.t_end", "expected a finite number", &[]);
}

#[test]
fn cells_and_ppc_must_be_positive_integers() {
    for (bad, found) in [("0", "0"), ("-16", "-16"), ("16.0", "16.0"), ("8.5", "8.5")] {
        let e = error(&edited("cells: [8, 16,", &format!("cells: [8, {bad},")));
        check(
            &e,
            6,
            14,
            "matrix.cells[1]",
            "expected an integer >= 1",
            &[],
        );
        assert!(e.message.contains(found), "{e}");
    }
    for bad in ["0", "-1", "2.0"] {
        let e = error(&edited("ppc: 2", &format!("ppc: {bad}")));
        check(&e, 3, 71, "params.ppc", "expected an integer >= 1", &[]);
    }
}

#[test]
fn matrix_values_in_block_lists_are_located() {
    let e = error(&edited(
        "  cells: [8, 16, 32, 64, 128]",
        "  cells:\n    - 8\n    - 0",
    ));
    check(&e, 8, 7, "matrix.cells[1]", "expected an integer >= 1", &[]);
}

#[test]
fn unstable_cfl_is_reported_at_its_value_with_the_run() {
    let e = error(&edited("cfl: 0.4", "cfl: 0.95"));
    check(&e, 3, 61, "params.cfl", "unstable", &[]);
    assert!(e.message.contains("G=0.0001, cells=8"), "{e}");
    let text = edited("cfl: 0.4, ", "").replace("  cells:", "  cfl: [0.4, 0.95]\n  cells:");
    let e = error(&text);
    check(&e, 6, 14, "matrix.cfl[1]", "unstable", &[]);
    assert!(e.message.contains("cfl=0.95"), "{e}");
}

/// A small matrix of Tran's bar, for its own parameter checks.
const TRAN: &str = "\
name: tran
benchmark: mms1d_tran
params: {method: mpm, ppc: 3, A: 0.001, dt: 1.0e-5}
matrix:
  cells: [8, 16, 32]
";

#[test]
fn tran_amplitude_that_inverts_the_bar_is_named() {
    let e = error(&TRAN.replace("A: 0.001", "A: 0.2"));
    check(&e, 3, 34, "params.A", "|2 pi A / L| = 1.2566 >= 1", &[]);
    // The default A = 0.1 on a bar of half a metre: reported at the benchmark.
    let e = error(&TRAN.replace("A: 0.001", "L: 0.5"));
    check(
        &e,
        2,
        12,
        "params.A",
        "the default A = 0.1 of mms1d_tran",
        &[],
    );
}

#[test]
fn tran_unstable_time_step_is_reported_with_the_run() {
    let e = error(&TRAN.replace("dt: 1.0e-5", "dt: 5.0e-4"));
    check(&e, 3, 45, "params.dt", "unstable", &[]);
    assert!(e.message.contains("cells=32"), "{e}");
    assert!(e.message.contains("Courant number"), "{e}");
}

#[test]
fn missing_required_parameter_is_named() {
    let e = error(&edited("ppc: 2, ", ""));
    check(&e, 3, 1, "params.ppc", "'ppc' is required", &[]);
    let text = "name: x\nbenchmark: mms1d_gong\nmatrix: {method: [mpm], G: [0.1], cells: [8]}\n";
    check(&error(text), 1, 1, "params.ppc", "'ppc' is required", &[]);
}

#[test]
fn a_key_in_params_and_matrix_is_rejected() {
    let e = error(&edited("cfl: 0.4", "cfl: 0.4, G: 0.1"));
    check(&e, 5, 3, "matrix.G", "also set in params (line 3)", &[]);
}

#[test]
fn expect_selector_must_be_a_value_of_its_axis() {
    let e = error(&edited("{G: 0.1, field", "{G: 0.2, field"));
    check(
        &e,
        10,
        9,
        "expect[1].G",
        "no run has G = 0.2",
        &["0.0001", "0.1"],
    );
    let e = error(&edited("{G: 0.1, field", "{cells: 8, field"));
    check(
        &e,
        10,
        6,
        "expect[1].cells",
        "refinement axis",
        &["field", "rate_min", "G"],
    );
    let e = error(&edited("{G: 0.1, field", "{E: 1.0e7, field"));
    check(&e, 10, 6, "expect[1].E", "unknown key 'E'", &["field", "G"]);
}

#[test]
fn selectors_may_list_values_each_checked_where_written() {
    let exp = parse(&edited("{G: 0.1, field", "{G: [0.1, 1.0e-4], field")).unwrap();
    let g = exp.expect[1].select.get("G").unwrap();
    assert_eq!(
        g.values(),
        [ParamValue::Float(0.1), ParamValue::Float(1e-4)]
    );
    let e = error(&edited("{G: 0.1, field", "{G: [0.1, 0.2], field"));
    check(
        &e,
        10,
        15,
        "expect[1].G[1]",
        "no run has G = 0.2",
        &["0.0001", "0.1"],
    );
    let e = error(&edited("{G: 0.1, field", "{G: [], field"));
    check(
        &e,
        10,
        9,
        "expect[1].G",
        "an empty list selects no run",
        &["0.0001", "0.1"],
    );
    let e = error(&edited("{G: 0.1, field", "{G: [0.1, 1.0e-1], field"));
    check(
        &e,
        10,
        15,
        "expect[1].G[1]",
        "0.1 is listed twice (first as expect[1].G[0])",
        &[],
    );
}

#[test]
fn expect_entries_need_a_field_and_a_bound() {
    let e = error(&edited("field: stress, ", ""));
    check(
        &e,
        10,
        5,
        "expect[1].field",
        "missing",
        &["stress", "velocity"],
    );
    let e = error(&edited("field: stress", "field: strain"));
    check(
        &e,
        10,
        21,
        "expect[1].field",
        "unknown field 'strain'",
        &["stress"],
    );
    let e = error(&edited(", rate_max: 1.0}", "}"));
    check(
        &e,
        10,
        5,
        "expect[1]",
        "at least one bound",
        &["rate_min", "error_max"],
    );
    let e = error(&edited("norm: l2", "norm: max"));
    check(
        &e,
        9,
        40,
        "expect[0].norm",
        "unknown norm 'max'",
        &["l2", "rms"],
    );
    let e = error(&edited("rate_min: 1.8", "rate_min: fast"));
    check(
        &e,
        9,
        54,
        "expect[0].rate_min",
        "expected a finite number",
        &[],
    );
}

#[test]
fn figure_by_must_be_a_matrix_axis() {
    let e = error(&edited("by: G", "by: E"));
    check(
        &e,
        12,
        80,
        "figures[0].by",
        "'E' is not a matrix axis",
        &["G"],
    );
    let e = error(&edited("by: G", "by: cells"));
    check(&e, 12, 80, "figures[0].by", "refinement axis", &["G"]);
    let e = error(&edited("kind: convergence", "kind: histogram"));
    check(
        &e,
        12,
        12,
        "figures[0].kind",
        "unknown figure kind",
        &["convergence"],
    );
    let e = error(&edited("fields: [stress,", "fields: [strain,"));
    check(
        &e,
        12,
        34,
        "figures[0].fields[0]",
        "unknown field",
        &["stress"],
    );
    let e = error(&edited(", by: G}", ", colour: red}"));
    check(
        &e,
        12,
        76,
        "figures[0].colour",
        "unknown key",
        &["kind", "fields", "norm", "by"],
    );
}

/// `name`, `title` and `paper` are checked where written; two figures cannot share a name.
#[test]
fn figure_names_and_titles_are_checked() {
    let named = edited(
        ", by: G}",
        ", by: G, name: fig4_7, paper: \"Gong 2015, Fig 4.7\"}",
    );
    let exp = parse(&named).unwrap();
    assert_eq!(exp.figures[0].name.as_deref(), Some("fig4_7"));
    assert_eq!(exp.figures[0].paper.as_deref(), Some("Gong 2015, Fig 4.7"));
    assert_eq!(exp.figures[0].title, None);
    let e = error(&edited(", by: G}", ", by: G, name: fig 4.7}"));
    check(&e, 12, 89, "figures[0].name", "a file stem", &[]);
    let e = error(&edited(", by: G}", ", by: G, name: a/b}"));
    check(&e, 12, 89, "figures[0].name", "letters, digits", &[]);
    let e = error(&edited(", by: G}", ", by: G, title: \"  \"}"));
    check(&e, 12, 90, "figures[0].title", "non-empty text", &[]);
    let twice = edited(
        ", by: G}",
        ", by: G, name: f}\n  - {kind: convergence, fields: [stress], name: f}",
    );
    let e = error(&twice);
    check(
        &e,
        13,
        49,
        "figures[1].name",
        "another figure is named 'f'",
        &[],
    );
}

#[test]
fn output_interval_must_be_positive() {
    for bad in ["0", "-5"] {
        let e = error(&edited("every: 10", &format!("every: {bad}")));
        check(&e, 7, 17, "output.every", "omit 'every'", &[]);
    }
    let e = error(&edited("every: 10", "every: 2.5"));
    check(&e, 7, 17, "output.every", "expected an integer", &[]);
    let e = error(&edited("every: 10", "evry: 10"));
    check(&e, 7, 10, "output.evry", "unknown key", &["every"]);
}

#[test]
fn names_must_be_directory_names() {
    let e = error(&edited("name: gong_mpm_1d", "name: gong/mpm 1d"));
    check(&e, 1, 7, "name", "directory name", &[]);
    let e = error(&edited("name: gong_mpm_1d\n", ""));
    check(&e, 1, 1, "name", "missing required key 'name'", &[]);
}

#[test]
fn axes_need_distinct_values() {
    let e = error(&edited("G: [1.0e-4, 0.1]", "G: [0.1, 1.0e-1]"));
    check(
        &e,
        5,
        12,
        "matrix.G[1]",
        "repeats the value of matrix.G[0]",
        &[],
    );
    let e = error(&edited("G: [1.0e-4, 0.1]", "G: []"));
    check(&e, 5, 6, "matrix.G", "at least one value", &[]);
}

#[test]
fn absurd_matrices_are_refused() {
    let values: Vec<String> = (1..=400).map(|i| i.to_string()).collect();
    let axis = format!("[{}]", values.join(", "));
    let text = format!(
        "name: big\nbenchmark: mms1d_gong\nparams: {{G: 0.1, method: mpm}}\n\
         matrix:\n  ppc: {axis}\n  cells: {axis}\n"
    );
    let e = error(&text);
    check(
        &e,
        4,
        1,
        "matrix",
        &format!("more than {MAX_RUNS} runs"),
        &[],
    );
    assert!(e.message.contains("400 x 400"), "{e}");
}

#[test]
fn yaml_syntax_errors_are_located() {
    let e = error(&edited("cells: [8, 16, 32, 64, 128]", "cells: [8, 16}"));
    check(&e, 6, 10, "cells", "invalid YAML: mismatched bracket", &[]);
    let e = error(&edited(
        "output: {every: 10}",
        "output: {every: 10, every: 20}",
    ));
    check(&e, 7, 21, "every", "duplicate key 'every'", &[]);
    let e = error(&edited(
        "name: gong_mpm_1d",
        "name: gong_mpm_1d\nname: again",
    ));
    check(&e, 2, 1, "name", "duplicate key 'name'", &[]);
}

#[test]
fn unreadable_files_are_config_errors() {
    let path = Path::new("/nonexistent/experiment.yaml");
    let e = experiment::load(path).unwrap_err();
    assert_eq!((e.file.as_path(), e.line, e.column), (path, 1, 1));
    assert!(
        e.to_string()
            .starts_with("/nonexistent/experiment.yaml:1:1: field "),
        "{e}"
    );

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gong.yaml");
    std::fs::write(&path, VALID).unwrap();
    let exp = experiment::load(&path).unwrap();
    assert_eq!(
        (exp.source_path.as_path(), exp.source_text.as_str()),
        (path.as_path(), VALID)
    );
}

#[test]
fn valid_file_expands_in_order_with_stable_ids() {
    let exp = parse(VALID).unwrap();
    assert_eq!(exp.name, "gong_mpm_1d");
    assert_eq!(exp.benchmark, "mms1d_gong");
    assert_eq!(exp.axes, ["G", "cells"]);
    assert_eq!(exp.output.every, 10);
    assert_eq!(exp.runs.len(), 10);
    let order: Vec<(String, String)> = exp
        .runs
        .iter()
        .map(|r| (r.axes["G"].to_string(), r.axes["cells"].to_string()))
        .collect();
    let expected: Vec<(String, String)> = ["0.0001", "0.1"]
        .iter()
        .flat_map(|g| ["8", "16", "32", "64", "128"].map(|c| (g.to_string(), c.to_string())))
        .collect();
    assert_eq!(order, expected, "last axis varies fastest");

    let run = &exp.runs[0];
    assert_eq!((run.method.as_str(), run.output_every), ("mpm", 10));
    assert_eq!(run.params["G"], ParamValue::Float(1e-4));
    assert_eq!(run.params["cells"], ParamValue::Int(8));
    assert!(!run.params.contains_key("method"));
    assert!(run
        .config_yaml
        .starts_with("experiment: gong_mpm_1d\nbenchmark: mms1d_gong\n"));
    let (prefix, hash) = run.run_id.rsplit_once('-').unwrap();
    assert_eq!(prefix, "mpm-G0.0001-cells8");
    assert!(
        hash.len() == 12 && hash.chars().all(|c| c.is_ascii_hexdigit()),
        "{hash}"
    );
    let unique: HashSet<&str> = exp.runs.iter().map(|r| r.run_id.as_str()).collect();
    assert_eq!(unique.len(), exp.runs.len());

    assert_eq!(exp.expect.len(), 2);
    let g = exp.expect[0].select.get("G").unwrap();
    assert_eq!(g.values(), [ParamValue::Float(1e-4)]);
    assert_eq!((exp.expect[0].line, exp.expect[0].rate_min), (9, Some(1.8)));
    assert_eq!(
        (exp.expect[1].norm.as_str(), exp.expect[1].rate_max),
        ("l2", Some(1.0))
    );
    assert_eq!(exp.figures[0].kind, FigureKind::Convergence);
    assert_eq!(exp.figures[0].fields[0], "stress");
    assert_eq!(exp.figures[0].by, ["G"]);
}

#[test]
fn defaults_fill_what_the_file_leaves_out() {
    let text = "name: x\nbenchmark: mms2d_gong\nparams: {G: 0.1, ppc: 2, cells: 4}\n\
                matrix: {method: [mpm]}\nfigures: [{kind: convergence}]\n";
    let exp = parse(text).unwrap();
    let run = &exp.runs[0];
    for (key, value) in [
        ("E", 1e7),
        ("nu", 0.3),
        ("rho0", 1e3),
        ("t_end", 0.02),
        ("cfl", 0.4),
    ] {
        assert_eq!(run.params[key], ParamValue::Float(value), "{key}");
    }
    assert_eq!(exp.output.every, 0);
    assert_eq!(run.axes["method"], ParamValue::Str("mpm".into()));
    assert_eq!(run.run_id.matches("mpm").count(), 1, "{}", run.run_id);
    assert_eq!(
        exp.figures[0].fields,
        [
            "displacement",
            "velocity",
            "stress",
            "density",
            "grid_velocity"
        ]
    );
    assert_eq!(
        (exp.figures[0].norm.as_str(), exp.figures[0].by.is_empty()),
        ("l2", true)
    );
}

/// Only a benchmark that knows the exact velocity at the nodes has the field `grid_velocity`;
/// elsewhere it is an unknown field, with the particle fields listed.
#[test]
fn grid_velocity_is_a_field_of_the_manufactured_solutions_only() {
    let text = |benchmark: &str, params: &str| {
        format!(
            "name: x\nbenchmark: {benchmark}\nparams: {{method: mpm, cells: 4, {params}}}\n\
             expect:\n  - {{field: grid_velocity, rate_min: 1.0}}\n"
        )
    };
    for (benchmark, params) in [
        ("mms1d_gong", "G: 0.1, ppc: 2"),
        ("mms2d_gong", "G: 0.1, ppc: 2"),
        ("mms1d_tran", "ppc: 3"),
    ] {
        let exp = parse(&text(benchmark, params)).unwrap();
        assert_eq!(exp.expect[0].field, "grid_velocity", "{benchmark}");
    }
    let e = error(&text("vibrating_bar", "ppc: 2"));
    check(
        &e,
        5,
        13,
        "expect[0].field",
        "unknown field",
        &["displacement", "velocity", "stress", "density"],
    );
    assert!(!e.valid.iter().any(|v| v == "grid_velocity"), "{e}");
    let defaults = parse(
        "name: x\nbenchmark: dyka_bar\nparams: {method: mpm}\nfigures: [{kind: convergence}]\n",
    )
    .unwrap();
    assert_eq!(defaults.figures[0].fields.len(), 4);
}

fn ids(text: &str) -> Vec<String> {
    parse(text)
        .unwrap()
        .runs
        .into_iter()
        .map(|r| r.run_id)
        .collect()
}

#[test]
fn run_ids_follow_the_resolved_configuration_only() {
    let base = ids(VALID);
    assert_eq!(ids(VALID), base, "stable across parses");
    assert_eq!(
        ids(&edited("name: gong_mpm_1d", "name: renamed")),
        base,
        "name is not hashed"
    );
    assert_eq!(
        ids(&edited("E: 1.0e7", "E: 10000000")),
        base,
        "1e7 and 10000000 are one value"
    );
    assert_eq!(ids(&edited("figures:\n", "figures: \n")), base);
    let changed = ids(&edited("cfl: 0.4", "cfl: 0.3"));
    assert!(base.iter().zip(&changed).all(|(a, b)| a != b));
    let changed = ids(&edited("every: 10", "every: 5"));
    assert!(base.iter().zip(&changed).all(|(a, b)| a != b));
}

#[test]
fn runs_describe_themselves() {
    let exp = parse(VALID).unwrap();
    let run = &exp.runs[5];
    assert_eq!(
        run.describe(),
        format!("{}  mms1d_gong mpm G=0.1 cells=8", run.run_id)
    );
    let json = run.to_json();
    assert_eq!(json["run_id"], run.run_id.as_str());
    assert_eq!(json["params"]["cells"], 8);
    assert_eq!(json["axes"]["G"], 0.1);
    assert_eq!(json["output_every"], 10);
}

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

const RECONSTRUCTION: &str = "\
name: recon
benchmark: recon1d_nodes
params: {lower: 0.0, upper: 1.0, ppc: 4, seed: 5, function: sin_pi}
matrix:
  - {method: [mls_linear], spacing: [random], cells: [5]}
  - {method: [shepard, mls_linear], spacing: [equal, random], cells: [10, 20, 40]}
expect:
  - {method: shepard, spacing: equal, field: u, norm: l2, rate_min: 1.4}
figures:
  - {kind: reconstruction, method: mls_linear}
  - {kind: convergence, by: spacing}
tables:
  - {kind: nodal_errors, columns: spacing}
";

const BASIS: &str = "\
name: basis
benchmark: recon1d_basis
params: {method: imls_quadratic, function: x_plus_1, cells: 2}
matrix:
  points: [[-0.5, 0.0, 0.5], [-0.6, 0.4]]
figures:
  - {kind: basis}
tables:
  - {kind: basis_norms}
";

const ELEMENTS: &str = "\
name: tls
benchmark: recon_tls
params: {function: sin_x_cos_y, lower: 0.0, upper: 5.0, spacing: interior, ppc: 2, ppc_y: 3}
matrix:
  method: [tls_fixed, tls_fitted]
  cells: [5, 10]
expect:
  - {method: tls_fixed, field: u, norm: rms, error_min: 6.0e-3, error_max: 7.0e-3}
figures:
  - {kind: reconstruction, method: tls_fixed}
tables:
  - {kind: element_fits}
";

fn edited_in(valid: &str, from: &str, to: &str) -> String {
    let text = valid.replacen(from, to, 1);
    assert_ne!(text, valid, "'{from}' is not in the file");
    text
}

#[test]
fn matrix_blocks_expand_in_order_without_repeats() {
    let exp = parse(RECONSTRUCTION).unwrap();
    assert_eq!(exp.axes, ["method", "spacing", "cells"]);
    assert_eq!(exp.runs.len(), 1 + 2 * 2 * 3);
    assert!(exp.runs[0]
        .run_id
        .starts_with("mls_linear-spacingrandom-cells5-"));
    assert!(exp.runs[1]
        .run_id
        .starts_with("shepard-spacingequal-cells10-"));
    assert_eq!(exp.runs[0].params["weight"], ParamValue::Str("hat".into()));
    assert_eq!(exp.figures[0].kind, FigureKind::Reconstruction);
    let basis = parse(BASIS).unwrap();
    assert_eq!(
        basis.runs[1].params["points"],
        ParamValue::List(vec![-0.6, 0.4])
    );
    assert!(basis.runs[1]
        .run_id
        .starts_with("imls_quadratic-points-0.6_0.4-"));
}

#[test]
fn a_block_that_makes_a_run_twice_is_refused() {
    let e = error(&edited_in(RECONSTRUCTION, "cells: [5]", "cells: [10]"));
    check(
        &e,
        6,
        5,
        "matrix",
        "block 2 makes the run mls_linear-spacingrandom-cells10-",
        &[],
    );
    assert!(e.message.ends_with("again (block 1 made it first)"), "{e}");
}

#[test]
fn blocks_need_the_same_axes() {
    let e = error(&edited_in(
        RECONSTRUCTION,
        "spacing: [random], cells: [5]}",
        "cells: [5]}",
    ));
    check(
        &e,
        6,
        5,
        "matrix[1]",
        "this one has [cells, method, spacing], the first has [cells, method]",
        &[],
    );
    let e = error(&edited_in(RECONSTRUCTION, "matrix:\n  - {method: [mls_linear], spacing: [random], cells: [5]}\n  - {method: [shepard, mls_linear], spacing: [equal, random], cells: [10, 20, 40]}", "matrix: []"));
    check(&e, 4, 9, "matrix", "non-empty list of such maps", &[]);
}

#[test]
fn reconstruction_choices_list_the_valid_values() {
    let e = error(&edited_in(
        RECONSTRUCTION,
        "function: sin_pi",
        "function: cos_pi",
    ));
    check(
        &e,
        3,
        61,
        "params.function",
        "unknown value 'cos_pi'",
        &["one", "x2", "sin_pi", "const_1_5"],
    );
    let e = error(&edited_in(
        RECONSTRUCTION,
        "spacing: [random]",
        "spacing: [jitter]",
    ));
    check(
        &e,
        5,
        38,
        "matrix[0].spacing[0]",
        "unknown value 'jitter'",
        &["equal", "random"],
    );
    let e = error(&edited_in(
        RECONSTRUCTION,
        "method: [mls_linear]",
        "method: [mpm]",
    ));
    check(
        &e,
        5,
        15,
        "matrix[0].method[0]",
        "unknown method 'mpm'",
        &["shepard", "imls_quadratic"],
    );
    let e = error(&edited_in(RECONSTRUCTION, "seed: 5", "seed: 0"));
    check(&e, 3, 48, "params.seed", "expected an integer >= 1", &[]);
}

#[test]
fn benchmark_checks_point_at_the_offending_value() {
    let e = error(&edited_in(BASIS, "[-0.6, 0.4]", "[-0.6, 1.4]"));
    check(
        &e,
        5,
        30,
        "matrix.points[1]",
        "the point 1.4 lies outside [lower, upper] = [-1, 1]",
        &[],
    );
    let e = error(&edited_in(BASIS, "cells: 2}", "cells: 2, scale: 11.0}"));
    check(
        &e,
        3,
        71,
        "params.scale",
        "reaches 16.5 cells; at most 15 are supported",
        &[],
    );
    let e = error(&edited_in(BASIS, "[-0.6, 0.4]]", "-0.6]"));
    check(
        &e,
        5,
        30,
        "matrix.points[1]",
        "expected a non-empty list of finite numbers, found the number -0.6",
        &[],
    );
    let e = error(&edited_in(BASIS, "[-0.6, 0.4]", "[-0.6, .nan]"));
    check(
        &e,
        5,
        37,
        "matrix.points[1][1]",
        "expected a finite number",
        &[],
    );
}

#[test]
fn figures_and_tables_must_suit_the_benchmark() {
    let e = error(&edited_in(
        RECONSTRUCTION,
        "{kind: reconstruction, method: mls_linear}",
        "{kind: basis}",
    ));
    check(
        &e,
        10,
        12,
        "figures[0].kind",
        "a basis figure needs data that nodal reconstruction benchmarks do not record",
        &["convergence", "reconstruction"],
    );
    assert!(!e.valid.contains(&"basis".to_string()));
    let e = error(&edited_in(
        RECONSTRUCTION,
        "kind: reconstruction, method: mls_linear",
        "kind: reconstruction, by: spacing",
    ));
    check(
        &e,
        10,
        28,
        "figures[0].by",
        "applies to convergence, shape_functions, history and field_map figures only",
        &[],
    );
    let e = error(&edited_in(
        RECONSTRUCTION,
        "{kind: nodal_errors, columns: spacing}",
        "{kind: nodal_errors}",
    ));
    check(
        &e,
        13,
        5,
        "tables[0].columns",
        "needs 'columns'",
        &["method", "spacing"],
    );
    let e = error(&edited_in(
        RECONSTRUCTION,
        "{kind: nodal_errors, columns: spacing}",
        "{kind: basis_norms}",
    ));
    check(
        &e,
        13,
        12,
        "tables[0].kind",
        "a basis_norms table needs data",
        &[],
    );
    let e = error(&edited(
        "figures:\n  - {kind: convergence",
        "tables: [{kind: nodal_errors, columns: G}]\nfigures:\n  - {kind: convergence",
    ));
    check(
        &e,
        11,
        17,
        "tables[0].kind",
        "a nodal_errors table needs data that simulation benchmarks do not record",
        &[],
    );
    let e = error(&edited_in(RECONSTRUCTION, "field: u", "field: velocity"));
    check(
        &e,
        8,
        46,
        "expect[0].field",
        "unknown field 'velocity'",
        &["u"],
    );
    let e = error(&edited_in(RECONSTRUCTION, "norm: l2", "norm: rms"));
    check(
        &e,
        8,
        55,
        "expect[0].norm",
        "unknown norm 'rms'",
        &["l2", "max"],
    );
}

const STABILITY: &str = "\
name: stab
benchmark: mms1d_gong
params: {method: mpm, nu: 0.0, G: 1.0e-4, cells: 16, courant_limit: 2.0}
matrix:
  ppc: [1, 2]
  cfl: [0.6, 0.8]
expect:
  - {ppc: 1, sweep: cfl, limit_min: 0.6, limit_max: 0.8}
figures:
  - {kind: stability, x: ppc, sweep: cfl}
  - {kind: growth, sweep: cfl}
tables:
  - {kind: stability, x: ppc, sweep: cfl}
";

#[test]
fn stability_studies_read_their_axes() {
    let exp = parse(STABILITY).unwrap();
    assert_eq!(exp.runs.len(), 4);
    let limit = exp.expect[0].limit.as_ref().unwrap();
    assert_eq!(
        (limit.sweep.as_str(), limit.min, limit.max),
        ("cfl", 0.6, 0.8)
    );
    assert_eq!(exp.expect[0].field, "velocity");
    assert_eq!(exp.figures[0].kind, FigureKind::Stability);
    let axes = exp.figures[0].stability.as_ref().unwrap();
    assert_eq!(
        (axes.sweep.as_str(), axes.x.as_deref()),
        ("cfl", Some("ppc"))
    );
    assert_eq!(exp.figures[1].stability.as_ref().unwrap().x, None);
    assert!(exp.tables[0].stability.is_some());
    // Without courant_limit a sweep past Courant number 1 is refused at the value.
    let text = edited_in(STABILITY, ", courant_limit: 2.0", "").replace("0.8]", "1.2]");
    let e = error(&text);
    check(&e, 6, 14, "matrix.cfl[1]", "raise courant_limit", &[]);
    assert!(e.message.contains("Use cfl <= 1.0000"), "{e}");
}

/// One bad edit of a valid file and where its error must point: (base file, from, to, line,
/// column, field, part of the message, valid choices listed).
type Case = (
    &'static str,
    &'static str,
    &'static str,
    usize,
    usize,
    &'static str,
    &'static str,
    &'static [&'static str],
);

#[test]
fn stability_keys_are_located_with_their_choices() {
    let growth = "{kind: growth, sweep: cfl}";
    let table = "tables:\n  - {kind: stability, x: ppc, sweep: cfl}";
    #[rustfmt::skip]
    let cases: [Case; 12] = [
        (STABILITY, "x: ppc, sweep: cfl}\n  - {kind: growth", "x: cfl, sweep: cfl}\n  - {kind: growth", 10, 26, "figures[0].x", "already the swept axis", &["ppc"]),
        (STABILITY, growth, "{kind: growth}", 11, 5, "figures[1].sweep", "missing required key 'sweep'", &["ppc", "cfl"]),
        (STABILITY, growth, "{kind: growth, sweep: G}", 11, 27, "figures[1].sweep", "'G' is not a matrix axis", &["ppc", "cfl"]),
        (STABILITY, growth, "{kind: growth, x: ppc, sweep: cfl}", 11, 20, "figures[1].x", "'x' applies to stability figures only", &[]),
        (STABILITY, growth, "{kind: convergence, sweep: cfl}", 11, 25, "figures[1].sweep", "applies to stability and growth figures only", &[]),
        (STABILITY, growth, "{kind: growth, sweep: cfl, cfl: 0.6}", 11, 27, "figures[1].sweep", "also selects runs", &[]),
        (STABILITY, table, "tables:\n  - {kind: stability, x: ppc, sweep: cfl, columns: ppc}", 13, 43, "tables[0].columns", "applies to nodal_errors tables only", &[]),
        (STABILITY, "limit_max: 0.8", "limit_max: 0.5", 8, 53, "expect[0].limit_max", "below limit_min 0.6", &[]),
        (STABILITY, ", limit_max: 0.8", "", 8, 5, "expect[0].limit_max", "missing required key", &[]),
        (STABILITY, "sweep: cfl, limit_min", "sweep: cfl, field: stress, limit_min", 8, 26, "expect[0].field", "does not apply to a stability-limit expectation", &[]),
        (STABILITY, "sweep: cfl, limit_min", "field: velocity, rate_min: 1.0, limit_min", 8, 46, "expect[0].limit_min", "needs 'sweep'", &[]),
        (RECONSTRUCTION, "{kind: reconstruction, method: mls_linear}", "{kind: stability, x: cells, sweep: spacing}", 10, 12, "figures[0].kind", "a stability figure needs data that nodal reconstruction benchmarks do not record", &[]),
    ];
    for (base, from, to, line, column, field, message, valid) in cases {
        let e = error(&edited_in(base, from, to));
        check(&e, line, column, field, message, valid);
    }
}

/// The element-wise benchmark takes the tls methods, its own norms and table, and its checks
/// name the parameter at fault; error bounds must be ordered.
#[test]
fn element_wise_experiments_are_checked() {
    let exp = parse(ELEMENTS).unwrap();
    assert_eq!(exp.runs.len(), 4);
    let e = error(&edited_in(
        ELEMENTS,
        "[tls_fixed, tls_fitted]",
        "[mls_linear]",
    ));
    check(
        &e,
        5,
        12,
        "matrix.method[0]",
        "unknown method 'mls_linear'",
        &["tls_fixed", "tls_fitted"],
    );
    let e = error(&edited_in(ELEMENTS, "spacing: interior", "spacing: mixed"));
    assert_eq!(e.field, "params.spacing", "{e}");
    assert!(e.message.contains("defined in 1D only"), "{e}");
    let e = error(&edited_in(
        ELEMENTS,
        "function: sin_x_cos_y",
        "function: x2",
    ));
    assert_eq!(e.field, "params.ppc_y", "{e}");
    let e = error(&edited_in(ELEMENTS, "norm: rms", "norm: l2"));
    check(
        &e,
        8,
        41,
        "expect[0].norm",
        "unknown norm 'l2'",
        &["rms", "integral"],
    );
    let e = error(&edited_in(
        ELEMENTS,
        "error_max: 7.0e-3",
        "error_max: 5.0e-3",
    ));
    assert_eq!(e.field, "expect[0].error_max", "{e}");
    assert!(e.message.contains("is below error_min"), "{e}");
    let e = error(&edited_in(
        ELEMENTS,
        "kind: element_fits",
        "kind: nodal_errors",
    ));
    assert_eq!(e.field, "tables[0].kind", "{e}");
    assert!(e.valid.contains(&"element_fits".to_string()), "{e}");
}

/// The original MPM beside LME on Gong's problem: blocks that differ in a method parameter.
const LME: &str = "\
name: lme
benchmark: mms1d_gong
params: {E: 1.0e7, nu: 0.3, rho0: 1000.0, t_end: 0.02, cfl: 0.4, ppc: 2, G: 1.0e-4}
matrix:
  - {method: [mpm], integrator: [leapfrog, predictor_corrector], cells: [8, 16]}
  - {method: [lme], gamma: [0.8, 3.0], integrator: [predictor_corrector], cells: [8, 16]}
";

#[test]
fn method_parameters_are_axes_that_blocks_may_leave_out() {
    let exp = parse(LME).unwrap();
    assert_eq!(exp.runs.len(), 8);
    assert_eq!(exp.axes, ["method", "integrator", "cells", "gamma"]);
    let mpm = exp.runs.iter().find(|r| r.method == "mpm").unwrap();
    assert!(!mpm.params.contains_key("gamma"), "{:?}", mpm.params);
    // Other axes must still agree between blocks.
    let e = error(&LME.replace(
        "integrator: [predictor_corrector], cells",
        "courant_limit: [1.0], cells",
    ));
    check(
        &e,
        6,
        5,
        "matrix[1]",
        "apart from the method parameters",
        &[],
    );
}

#[test]
fn lme_needs_a_valid_gamma_and_other_methods_refuse_it() {
    let e = error(&LME.replace("gamma: [0.8, 3.0], ", ""));
    check(
        &e,
        6,
        15,
        "matrix[1].method[0]",
        "method lme needs gamma",
        &[],
    );
    let e = error(&LME.replace(
        "{method: [mpm], integrator",
        "{method: [mpm], gamma: [1.0], integrator",
    ));
    check(
        &e,
        5,
        29,
        "matrix[0].gamma[0]",
        "gamma applies to LME methods only (lme)",
        &[],
    );
    let e = error(&LME.replace("gamma: [0.8, 3.0]", "gamma: [0.8, 30.0]"));
    check(&e, 6, 34, "matrix[1].gamma[1]", "cut-off radius", &[]);
    assert!(e.message.contains("method=lme"), "{e}");
    let e = error(&LME.replace("gamma: [0.8, 3.0]", "gamma: [0.8, -3.0]"));
    check(
        &e,
        6,
        34,
        "matrix[1].gamma[1]",
        "expected a finite number > 0",
        &[],
    );
}

#[test]
fn integrator_must_be_known_and_fit_the_transfer() {
    let e = error(&LME.replace("integrator: [leapfrog,", "integrator: [rk4,"));
    check(
        &e,
        5,
        34,
        "matrix[0].integrator[0]",
        "rk4",
        &[
            "leapfrog",
            "musl",
            "usl",
            "euler",
            "euler_corrected",
            "predictor_corrector",
        ],
    );
    // The TLS transfers keep their own integrator.
    let e = error(&LME.replace("{method: [mpm],", "{method: [mpm_tls],"));
    check(
        &e,
        5,
        38,
        "matrix[0].integrator[0]",
        "maps with taylor",
        &[],
    );
    assert!(
        e.message
            .contains("leapfrog runs with the methods mpm, mpm_musl, impm,"),
        "{e}"
    );
    assert!(!e.message.contains(", mpm_tls"), "{e}");
    // A quadrature transfer runs any integrator but the predictor-corrector, which maps its
    // predictor with the Shepard transfer.
    let text = LME.replace("{method: [mpm],", "{method: [imls],");
    let e = error(&text);
    check(
        &e,
        5,
        45,
        "matrix[0].integrator[1]",
        "cannot run predictor_corrector",
        &[],
    );
    assert!(
        e.message
            .contains("runs with the methods mpm, mpm_musl, ugimp,"),
        "{e}"
    );
    assert!(!e.message.contains("mpm_musl, impm"), "{e}");
    parse(&text.replace(
        "integrator: [leapfrog, predictor_corrector]",
        "integrator: [leapfrog, usl]",
    ))
    .unwrap();
}

#[test]
fn quadrature_parameters_apply_to_quadrature_transfers_only() {
    let text = "\
name: exp
benchmark: mms1d_tran
params: {ppc: 3, dt: 1.0e-5, t_end: 0.02}
matrix:
  - {method: [imls], gauss_points: [1, 2], body_force_fit: [separate, product], cells: [8]}
  - {method: [mpm], cells: [8]}
";
    assert_eq!(parse(text).unwrap().runs.len(), 5);
    let e = error(&text.replace(
        "{method: [mpm], cells",
        "{method: [mpm], gauss_points: [1], cells",
    ));
    check(
        &e,
        6,
        36,
        "matrix[1].gauss_points[0]",
        "quadrature transfers only (impm, impm_fields_only, imls,",
        &[],
    );
    let e = error(&text.replace("gauss_points: [1, 2]", "gauss_points: [0, 2]"));
    check(&e, 5, 37, "matrix[0].gauss_points[0]", "integer >= 1", &[]);
    let e = error(&text.replace("[separate, product]", "[separate, sum]"));
    check(
        &e,
        5,
        71,
        "matrix[0].body_force_fit[1]",
        "sum",
        &["separate", "product"],
    );
}

const MOLINOS: &str = "\
name: molinos
benchmark: andersen_block
params: {t_end: 1.0}
matrix:
  - {method: [mpm], placement: [gauss]}
  - {method: [ugimp], placement: [centres]}
figures:
  - {kind: history, probe: top_displacement, by: method}
tables:
  - {kind: errors, field: velocity, norm: rms}
";

#[test]
fn history_figures_and_errors_tables_are_read() {
    let exp = parse(MOLINOS).unwrap();
    assert_eq!(exp.figures[0].kind, FigureKind::History);
    assert_eq!(exp.figures[0].probe.as_deref(), Some("top_displacement"));
    assert_eq!(
        exp.tables[0].measure,
        Some(("velocity".to_string(), "rms".to_string()))
    );
    assert_eq!(exp.runs.len(), 2);
}

#[test]
fn a_history_figure_needs_a_probe() {
    let text = MOLINOS.replace("probe: top_displacement, ", "");
    check(
        &error(&text),
        8,
        5,
        "figures[0].probe",
        "needs 'probe'",
        &[],
    );
}

#[test]
fn an_errors_table_needs_a_known_field() {
    let text = MOLINOS.replace("field: velocity, ", "");
    check(
        &error(&text),
        10,
        5,
        "tables[0].field",
        "needs 'field'",
        &["velocity", "stress"],
    );
    let text = MOLINOS.replace("field: velocity", "field: speed");
    check(
        &error(&text),
        10,
        27,
        "tables[0].field",
        "speed",
        &["velocity"],
    );
}

#[test]
fn probes_tables_are_read_with_their_window() {
    let text = MOLINOS.replace(
        "  - {kind: errors, field: velocity, norm: rms}",
        "  - {kind: probes, probe: top_displacement, after: 10.0, tolerance: 0.05}",
    );
    let exp = parse(&text).unwrap();
    let window = exp.tables[0].probe.as_ref().unwrap();
    assert_eq!(window.name, "top_displacement");
    assert_eq!((window.after, window.tolerance), (10.0, 0.05));
    let text = MOLINOS.replace(
        "  - {kind: errors, field: velocity, norm: rms}",
        "  - {kind: probes, probe: top_displacement, tolerance: 0.05}",
    );
    assert_eq!(
        parse(&text).unwrap().tables[0]
            .probe
            .as_ref()
            .unwrap()
            .after,
        0.0
    );
}

#[test]
fn a_probes_table_needs_a_probe_and_a_positive_tolerance() {
    let table =
        |entry: &str| MOLINOS.replace("  - {kind: errors, field: velocity, norm: rms}", entry);
    let text = table("  - {kind: probes, tolerance: 0.05}");
    check(
        &error(&text),
        10,
        5,
        "tables[0].probe",
        "needs 'probe'",
        &[],
    );
    let text = table("  - {kind: probes, probe: top_displacement}");
    check(
        &error(&text),
        10,
        5,
        "tables[0].tolerance",
        "needs 'tolerance'",
        &[],
    );
    let text = table("  - {kind: probes, probe: top_displacement, tolerance: -1.0}");
    check(&error(&text), 10, 56, "tables[0].tolerance", "> 0", &[]);
    let text =
        table("  - {kind: probes, probe: top_displacement, tolerance: 1.0, field: velocity}");
    let e = error(&text);
    assert_eq!(e.field, "tables[0].field", "{e}");
}

#[test]
fn gauss_placement_is_refused_with_particle_domains() {
    let text = MOLINOS.replace("placement: [centres]", "placement: [gauss]");
    check(
        &error(&text),
        6,
        35,
        "matrix[1].placement[0]",
        "ugimp takes the seed lattice's sub-cells as particle domains",
        &[],
    );
}

/// MOLINOS with a field map after its history figure (line 9).
fn with_map(entry: &str) -> String {
    edited_in(
        MOLINOS,
        "by: method}\n",
        &format!("by: method}}\n  - {entry}\n"),
    )
}

/// Line 9's column of `text` in `yaml`, 1-based.
fn column_in_line_9(yaml: &str, text: &str) -> usize {
    yaml.lines().nth(8).unwrap().find(text).unwrap() + 1
}

#[test]
fn field_maps_are_read_with_their_field_and_axes() {
    let text = with_map(
        "{kind: field_map, field: stress_yy, by: [method, placement], title: \"Molinos, Fig 11\"}",
    );
    let exp = parse(&text).unwrap();
    let map = &exp.figures[1];
    assert_eq!(map.kind, FigureKind::FieldMap);
    assert_eq!(map.by, ["method", "placement"]);
    assert_eq!(
        map.map,
        Some(FieldMapSpec {
            field: "stress_yy".into(),
        })
    );
    assert_eq!(map.title.as_deref(), Some("Molinos, Fig 11"));
    assert_eq!(exp.figures[0].map, None);
    let untitled = parse(&with_map("{kind: field_map, field: density}")).unwrap();
    assert_eq!(untitled.figures[1].title, None);
}

#[test]
fn a_field_map_needs_a_field_its_runs_record() {
    let text = with_map("{kind: field_map, field: stress_zz}");
    check(
        &error(&text),
        9,
        column_in_line_9(&text, "stress_zz"),
        "figures[1].field",
        "unknown map field 'stress_zz'",
        &["stress_yy", "displacement_y", "velocity_x", "density"],
    );
    let text = with_map("{kind: field_map, by: method}");
    check(
        &error(&text),
        9,
        5,
        "figures[1].field",
        "a field_map figure needs 'field'",
        &["stress_xx", "stress_yy", "stress_xy"],
    );
    // The fields are those of the benchmark's kind: an element-wise fit has no stress.
    let text = edited_in(
        ELEMENTS,
        "{kind: reconstruction, method: tls_fixed}",
        "{kind: field_map, field: stress_yy}",
    );
    let e = error(&text);
    assert_eq!(e.field, "figures[0].field", "{e}");
    assert_eq!(e.valid, ["reconstructed", "error"], "{e}");
    let text = edited_in(
        ELEMENTS,
        "{kind: reconstruction, method: tls_fixed}",
        "{kind: field_map, field: error, by: [method]}",
    );
    assert!(parse(&text).is_ok());
}

#[test]
fn field_maps_suit_2d_kinds_and_keep_their_keys() {
    // Nodal reconstructions are 1D: nothing to map.
    let e = error(&edited_in(
        RECONSTRUCTION,
        "{kind: reconstruction, method: mls_linear}",
        "{kind: field_map, field: u}",
    ));
    assert_eq!(e.field, "figures[0].kind", "{e}");
    assert!(
        e.message
            .contains("a field_map figure needs data that nodal reconstruction benchmarks"),
        "{e}"
    );
    assert!(!e.valid.contains(&"field_map".to_string()), "{e}");
    // `field` belongs to field maps.
    let text = edited_in(MOLINOS, "by: method}", "by: method, field: density}");
    check(
        &error(&text),
        8,
        text.lines().nth(7).unwrap().find("field").unwrap() + 1,
        "figures[0].field",
        "'field' applies to field_map figures only",
        &[],
    );
    let e = error(&with_map("{kind: field_map, field: density, norm: l2}"));
    assert_eq!(e.field, "figures[1].norm", "{e}");
    assert!(
        e.message.contains("applies to convergence figures only"),
        "{e}"
    );
}
