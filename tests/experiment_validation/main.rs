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

mod expansion;
mod expectations_and_figures;
mod histories;
mod method_parameters;
mod no_panic;
mod reconstruction;
mod unknown_names;
mod values;
