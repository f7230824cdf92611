//! Experiment files: expectations, figures and output settings.

use super::*;

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
