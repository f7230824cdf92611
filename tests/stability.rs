//! The stability sweep end to end: runs of the original MPM on either side of the limit for
//! one particle per cell (0.7084 on 32 cells with fixed ends, docs/NOTES.md) are told apart
//! by the criterion of `report::stability`, with a wide margin on both sides of its
//! threshold, and `report --check` holds limit expectations against them.

use mpmlab::collect::collect;
use mpmlab::experiment;
use mpmlab::linear_stability::projected_bound_fixed_ends;
use mpmlab::output::RunStatus;
use mpmlab::report::{self, stability};
use mpmlab::runner::{results_dir, run_experiment, RunOptions};

const MATRIX: &str = "\
name: stability
benchmark: mms1d_gong
params: {method: mpm, nu: 0.0, cells: 32, ppc: 1, t_end: 0.2, courant_limit: 2.0}
matrix:
  G: [1.0e-4]
  cfl: [0.69, 0.74]
output: {every: 20}
expect:
  - {sweep: cfl, limit_min: 0.69, limit_max: 0.74}
  - {sweep: cfl, limit_min: 0.7, limit_max: 0.8}
  - {sweep: cfl, limit_min: 0.6, limit_max: 0.7}
figures:
  - {kind: stability, x: G, sweep: cfl}
  - {kind: growth, sweep: cfl}
";

#[test]
fn runs_either_side_of_the_limit_are_told_apart() {
    let bound = projected_bound_fixed_ends(1, 32);
    assert!(0.69 < bound && bound < 0.74, "{bound}");

    let tmp = tempfile::tempdir().unwrap();
    let yaml = tmp.path().join("stability.yaml");
    std::fs::write(&yaml, MATRIX).unwrap();
    let exp = experiment::load(&yaml).unwrap();
    let options = RunOptions {
        out: tmp.path().to_path_buf(),
        jobs: 2,
        threads: 1,
        force: false,
        memory: None,
    };
    run_experiment(&exp, &options).unwrap();
    let collected = collect(&results_dir(tmp.path(), &exp)).unwrap();

    let limits = stability::limits(&collected.runs, "cfl");
    assert_eq!(limits.len(), 1);
    let limit = &limits[0];
    let stable = limit.last_stable().expect("a stable run");
    let unstable = limit.first_unstable().expect("an unstable run");
    assert_eq!((stable.value, unstable.value), (0.69, 0.74));
    assert_eq!(stable.run.status, RunStatus::Ok);
    // The threshold (error = solution) sits far from both: the stable run's error stays a
    // few per cent of the solution, the unstable one grows past it by orders of magnitude.
    assert!(stable.peak < 0.1, "{}", stable.peak);
    assert!(unstable.peak > 10.0, "{}", unstable.peak);
    assert_eq!(limit.stable_above().count(), 0);

    let rates = report::fit_rates(&collected.experiment, &collected.runs);
    let failures = report::check(&collected.experiment, &rates, &collected.runs);
    let messages: Vec<String> = failures.iter().map(ToString::to_string).collect();
    assert_eq!(messages.len(), 2, "{messages:?}");
    assert!(
        messages[0].starts_with("line 10: G=0.0001: last stable cfl 0.69 < limit_min 0.7"),
        "{messages:?}"
    );
    assert!(
        messages[1].starts_with("line 11: G=0.0001: first unstable cfl 0.74 > limit_max 0.7"),
        "{messages:?}"
    );

    let dir = results_dir(tmp.path(), &exp);
    let written = report::write_report(
        &dir,
        &collected.experiment,
        &collected.runs,
        &collected.unreadable,
        &rates,
        Some(&failures),
    )
    .unwrap();
    assert_eq!(
        written.figures,
        [
            "figures/stability_stability_all.png",
            "figures/stability_growth_G_0.0001.png",
        ]
        .map(std::path::PathBuf::from)
    );
    for figure in &written.figures {
        let png = std::fs::read(dir.join(figure)).unwrap();
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
    }
}
