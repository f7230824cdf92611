//! A selection that lists several values of an axis, end to end: a small vibrating-bar matrix
//! of three methods is run, and a figure, an expectation and a table that select two of them
//! by a list draw, check and list those two only (each method with and without TLS in one
//! figure, as Wobbes et al. 2018 Fig 3).

use std::path::Path;

use mpmlab::collect::collect;
use mpmlab::experiment;
use mpmlab::report::{self, figures};
use mpmlab::runner::{results_dir, run_experiment, RunOptions};

const MATRIX: &str = "\
name: multi_select
benchmark: vibrating_bar
params: {exact: small_strain, ppc: 4}
matrix:
  method: [mpm, mpm_musl, mpm_tls]
  cells: [5, 10]
figures:
  - {kind: convergence, fields: [displacement], norm: rms, by: method, method: [mpm_musl, mpm_tls]}
expect:
  - {method: [mpm_musl, mpm_tls], field: displacement, norm: rms, rate_min: 1.5}
tables:
  - {kind: errors, field: displacement, norm: rms, method: [mpm_tls, mpm_musl]}
";

#[test]
fn a_figure_of_two_listed_methods_draws_those_two() {
    let out = tempfile::tempdir().unwrap();
    let exp = experiment::parse(MATRIX, Path::new("multi_select.yaml")).unwrap();
    let options = RunOptions {
        out: out.path().to_path_buf(),
        jobs: 2,
        threads: 1,
        force: false,
        memory: None,
    };
    let outcome = run_experiment(&exp, &options).unwrap();
    assert!(outcome.failed.is_empty() && outcome.diverged.is_empty());
    let dir = results_dir(out.path(), &exp);
    let collected = collect(&dir).unwrap();
    let (exp, runs) = (&collected.experiment, &collected.runs);
    assert_eq!(runs.len(), 6);

    let planned = figures::plan(exp, runs).unwrap();
    assert_eq!(planned.len(), 1);
    let figure = &planned[0];
    assert_eq!(
        figure.title,
        "multi_select: displacement (rms norm): method=mpm_musl|mpm_tls"
    );
    let labels: Vec<&str> = figure.series.iter().map(|s| s.label.as_str()).collect();
    assert_eq!(labels.len(), 2, "{labels:?}");
    assert!(
        labels[0].starts_with("displacement, method=mpm_musl (rate "),
        "{labels:?}"
    );
    assert!(
        labels[1].starts_with("displacement, method=mpm_tls (rate "),
        "{labels:?}"
    );
    assert!(figure.series.iter().all(|s| s.markers.len() == 2));

    let rates = report::fit_rates(exp, runs);
    let failures = report::check(exp, &rates, runs);
    assert!(failures.is_empty(), "{failures:?}");
    let written = report::write_report(&dir, exp, runs, &[], &rates, Some(&failures)).unwrap();
    let file = Path::new("figures/multi_select_method_mpm_musl+mpm_tls_displacement_rms.png");
    assert_eq!(written.figures, [file]);
    let png = std::fs::read(dir.join(file)).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));

    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let check = "- **pass** line 10: method=mpm_musl|mpm_tls displacement rms: rate >= 1.5";
    assert!(md.contains(check), "missing {check:?} in\n{md}");
    // The table lists the two methods' runs, its title the values in the order written.
    let heading = "### Final rms displacement error: method=mpm_tls|mpm_musl\n";
    let table = &md[md.find(heading).expect(heading)..];
    let table = &table[..table.find("\n## ").unwrap()];
    let methods: Vec<&str> = table
        .lines()
        .filter_map(|line| line.strip_prefix("| ")?.split(" | ").next())
        .filter(|cell| cell.starts_with("mpm"))
        .collect();
    assert_eq!(
        methods,
        ["mpm_musl", "mpm_musl", "mpm_tls", "mpm_tls"],
        "{table}"
    );
}
