//! Experiment files: unknown names: methods, benchmarks, sections and parameters, each error
//! listing the valid ones.

use super::*;

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
