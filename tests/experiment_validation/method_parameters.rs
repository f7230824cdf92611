//! Experiment files: method parameters: blocks that leave them out, gamma, the integrator, the
//! quadrature settings.

use super::*;

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
    let mpm = exp.runs.iter().find(|r| r.spec.method == "mpm").unwrap();
    assert!(
        !mpm.spec.params.contains_key("gamma"),
        "{:?}",
        mpm.spec.params
    );
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
        "apart from the method and its parameters",
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
