//! Experiment files: what a valid file expands into: names, axes, limits, syntax errors,
//! defaults, stable run ids.

use super::*;

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
        .map(|r| {
            (
                r.spec.axes["G"].to_string(),
                r.spec.axes["cells"].to_string(),
            )
        })
        .collect();
    let expected: Vec<(String, String)> = ["0.0001", "0.1"]
        .iter()
        .flat_map(|g| ["8", "16", "32", "64", "128"].map(|c| (g.to_string(), c.to_string())))
        .collect();
    assert_eq!(order, expected, "last axis varies fastest");

    let run = &exp.runs[0];
    assert_eq!(
        (run.spec.method.as_str(), run.spec.output_every),
        ("mpm", 10)
    );
    assert_eq!(run.spec.params["G"], ParamValue::Float(1e-4));
    assert_eq!(run.spec.params["cells"], ParamValue::Int(8));
    assert!(!run.spec.params.contains_key("method"));
    assert!(run
        .spec
        .config_yaml
        .starts_with("experiment: gong_mpm_1d\nbenchmark: mms1d_gong\n"));
    let (prefix, hash) = run.spec.run_id.rsplit_once('-').unwrap();
    assert_eq!(prefix, "mpm-G0.0001-cells8");
    assert!(
        hash.len() == 12 && hash.chars().all(|c| c.is_ascii_hexdigit()),
        "{hash}"
    );
    let unique: HashSet<&str> = exp.runs.iter().map(|r| r.spec.run_id.as_str()).collect();
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
        assert_eq!(run.spec.params[key], ParamValue::Float(value), "{key}");
    }
    assert_eq!(exp.output.every, 0);
    assert_eq!(run.spec.axes["method"], ParamValue::Str("mpm".into()));
    assert_eq!(
        run.spec.run_id.matches("mpm").count(),
        1,
        "{}",
        run.spec.run_id
    );
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
        .map(|r| r.spec.run_id)
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
        run.spec.describe(),
        format!("{}  mms1d_gong mpm G=0.1 cells=8", run.spec.run_id)
    );
    let json = run.spec.to_json();
    assert_eq!(json["run_id"], run.spec.run_id.as_str());
    assert_eq!(json["params"]["cells"], 8);
    assert_eq!(json["axes"]["G"], 0.1);
    assert_eq!(json["output_every"], 10);
}
