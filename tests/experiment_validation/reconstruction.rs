//! Experiment files: reconstruction benchmarks: choices, point lists, matrix blocks, figure and
//! table kinds; stability studies; the element-wise benchmark.

use super::*;

#[test]
fn matrix_blocks_expand_in_order_without_repeats() {
    let exp = parse(RECONSTRUCTION).unwrap();
    assert_eq!(exp.axes, ["method", "spacing", "cells"]);
    assert_eq!(exp.runs.len(), 1 + 2 * 2 * 3);
    assert!(exp.runs[0]
        .spec
        .run_id
        .starts_with("mls_linear-spacingrandom-cells5-"));
    assert!(exp.runs[1]
        .spec
        .run_id
        .starts_with("shepard-spacingequal-cells10-"));
    assert_eq!(
        exp.runs[0].spec.params["weight"],
        ParamValue::Str("hat".into())
    );
    assert_eq!(exp.figures[0].kind, FigureKind::Reconstruction);
    let basis = parse(BASIS).unwrap();
    assert_eq!(
        basis.runs[1].spec.params["points"],
        ParamValue::List(vec![-0.6, 0.4])
    );
    assert!(basis.runs[1]
        .spec
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
