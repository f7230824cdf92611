//! Inputs that once stopped a matrix, ran with a time step no check approved, or were taken
//! silently, kept in tests/inputs/robustness/ (or generated here when they are large): each
//! is refused where the file is read, at its file, line, column and field, with the bound it
//! breaks in the message. Long list values expand into run ids of bounded length, and a closed
//! standard output ends the program quietly.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use mpmlab::benchmarks::{self, AnyProblem, MAX_POINTS, MAX_STEPS};
use mpmlab::experiment::{
    self, ConfigError, Experiment, ResolvedRun, MAX_LIST_VALUES, MAX_NAME_LEN, MAX_RUN_ID_LEN,
    MAX_SAMPLES,
};
use mpmlab::output::{open_run_file, read_summary, run_path, RunStatus};
use mpmlab::params::ParamValue;
use mpmlab::runner::{results_dir, run_experiment, RunOptions, REFUSED};
use mpmlab::shape::MAX_STENCIL_NODES;
use mpmlab::solver::Job;

const DIR: &str = "tests/inputs/robustness";

fn path(name: &str) -> PathBuf {
    Path::new(DIR).join(name)
}

fn load(name: &str) -> Result<Experiment, ConfigError> {
    experiment::load(&path(name))
}

/// The error of loading `name`, checked to be at `line`:`column` in `field` of that file and
/// to say each of `said`.
fn refused(name: &str, line: usize, column: usize, field: &str, said: &[&str]) -> ConfigError {
    let e = match load(name) {
        Ok(_) => panic!("{name} was accepted"),
        Err(e) => e,
    };
    let shown = e.to_string();
    assert_eq!(e.file, path(name), "{shown}");
    assert_eq!(
        (e.line, e.column, e.field.as_str()),
        (line, column, field),
        "{shown}"
    );
    for part in said {
        assert!(e.message.contains(part), "'{part}' not in: {shown}");
    }
    e
}

fn max_steps() -> String {
    format!("more than max_steps = {MAX_STEPS}")
}

#[test]
fn a_name_longer_than_a_directory_name_is_refused() {
    refused(
        "name_too_long.yaml",
        3,
        7,
        "name",
        &["a name of 300 bytes", &format!("at most {MAX_NAME_LEN}")],
    );
}

#[test]
fn a_tiny_dt_is_refused_at_its_step_count() {
    refused(
        "dt_tiny.yaml",
        6,
        16,
        "matrix.dt[1]",
        &["dt = 1.0000e-300 s takes 2.0000e298 steps", &max_steps()],
    );
}

#[test]
fn a_huge_t_end_is_refused_at_its_step_count() {
    refused(
        "t_end_huge.yaml",
        5,
        17,
        "params.t_end",
        &["t_end = 1e300 s", "takes 2.0000e303 steps", &max_steps()],
    );
}

/// rho0 sets the wave speed and so the Courant-limited step: a tiny one is refused at rho0,
/// with the step it makes, instead of running with a step the check never saw.
#[test]
fn a_tiny_rho0_is_refused_at_its_step_count() {
    refused(
        "rho0_tiny.yaml",
        7,
        10,
        "matrix.rho0[0]",
        &[
            "c = sqrt(E/rho0) = 3.1623e153 m/s) = 1.5811e-155 s takes 1.2649e153 steps",
            &max_steps(),
        ],
    );
    refused(
        "rho0_overflow.yaml",
        4,
        41,
        "params.rho0",
        &["= 0.0 s is no time step"],
    );
}

/// `max_steps` raises the bound; without it the same run is refused at t_end.
#[test]
fn max_steps_raises_the_bound() {
    let runs = load("max_steps_raised.yaml").unwrap().runs;
    assert_eq!(
        runs[0].spec.params["max_steps"],
        ParamValue::Int(30_000_000)
    );
    let text = std::fs::read_to_string(path("max_steps_raised.yaml")).unwrap();
    let without = text.replace(",\n         max_steps: 30000000", "");
    assert_ne!(without, text);
    let e = experiment::parse(&without, Path::new("x.yaml")).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (4, "params.t_end"), "{e}");
    assert!(e.message.contains("takes 2.0000e7 steps"), "{e}");
}

/// Every simulation run of the committed experiments steps with the time step its check
/// approves: the problem's dt and step count are those of the benchmark's `time_step`, and
/// the resolved run carries that step count.
#[test]
fn runs_take_the_time_step_their_check_approves() {
    let mut compared = 0;
    for entry in std::fs::read_dir("experiments").unwrap() {
        let experiment = experiment::load(&entry.unwrap().path()).unwrap();
        let info = benchmarks::CATALOG.find(&experiment.benchmark).unwrap();
        let Some(time_step) = info.time_step else {
            continue;
        };
        for run in &experiment.runs {
            let step = time_step(&run.spec.params).unwrap();
            let (dt, steps) = match run.benchmark.problem(&run.spec.params).unwrap() {
                AnyProblem::D1(p) => (p.dt(), p.steps()),
                AnyProblem::D2(p) => (p.dt(), p.steps()),
            };
            assert_eq!((dt, steps), (step.dt, step.steps), "{}", run.spec.run_id);
            assert_eq!(run.steps, Some(steps), "{}", run.spec.run_id);
            compared += 1;
        }
    }
    assert!(compared > 500, "{compared} runs compared");
}

#[test]
fn a_tiny_lme_gamma_is_refused_at_its_stencil() {
    refused(
        "lme_gamma_tiny.yaml",
        7,
        16,
        "matrix.gamma[1]",
        &[
            "gamma = 1e-9 with tolerance = 1e-6",
            "a stencil of 2.3508e5 nodes per point in 1D",
            &format!("at most {MAX_STENCIL_NODES} are supported, which needs gamma > 5.2702e-5"),
        ],
    );
}

#[test]
fn particle_node_and_point_counts_are_bounded() {
    let at_most = format!("at most {MAX_POINTS} are supported");
    refused(
        "cells_huge.yaml",
        5,
        17,
        "params.cells",
        &["makes 40000000000 particles", &at_most],
    );
    refused(
        "extra_cells_huge.yaml",
        4,
        36,
        "params.extra_cells",
        &["makes 200000041 grid nodes", &at_most],
    );
    refused(
        "shape_lattice_huge.yaml",
        4,
        41,
        "params.cells",
        &["makes 10000200001 evaluation points", &at_most],
    );
    refused(
        "gauss_points_huge.yaml",
        5,
        24,
        "params.gauss_points",
        &["gauss_points = 1000: at most 32 Gauss points per cell and axis"],
    );
}

#[test]
fn history_samples_are_bounded() {
    refused(
        "every_one_huge_steps.yaml",
        5,
        17,
        "output.every",
        &[
            "every = 1 stores 200001 samples of the 200000 steps",
            &format!("at most {MAX_SAMPLES} are stored: use every >= 3"),
        ],
    );
}

/// Whether `id` and the longest name of its files (the temporary one of a run file) fit.
fn fits(id: &str) -> bool {
    let temporary = format!(".{id}.h5.tmp-{}", u32::MAX);
    id.len() <= MAX_RUN_ID_LEN && temporary.len() <= 255
}

/// A list axis too long to write out enters the run id by its length; a short one keeps its
/// id (that of the committed ci_recon_basis run).
#[test]
fn long_list_values_give_bounded_run_ids() {
    let runs = load("long_points_list.yaml").unwrap().runs;
    assert_eq!(
        runs[0].spec.run_id,
        "imls_quadratic-points-0.5_0.0_0.5-26e231655be8"
    );
    assert!(
        runs[1]
            .spec
            .run_id
            .starts_with("imls_quadratic-pointslist40-"),
        "{}",
        runs[1].spec.run_id
    );
    assert!(runs.iter().all(|r| fits(&r.spec.run_id)));
    assert_eq!(runs[1].spec.params["points"].as_list().unwrap().len(), 40);
}

/// `points` as a matrix axis of one list of `n` values in [-1, 1].
fn points_axis(n: usize) -> String {
    let points: Vec<String> = (0..n)
        .map(|i| format!("{:?}", -1.0 + 2.0 * i as f64 / (n - 1) as f64))
        .collect();
    format!(
        "name: many_points\nbenchmark: recon1d_basis\n\
         params: {{method: imls_quadratic, function: x_plus_1, cells: 2}}\n\
         matrix:\n  points: [[{}]]\n",
        points.join(", ")
    )
}

/// ... and is written: its configuration (over 64 KiB of YAML) and its list are datasets,
/// which an attribute of at most 64 KiB could not hold, and read back whole.
#[test]
fn a_list_of_twenty_thousand_values_expands_with_a_bounded_id_and_is_written() {
    let text = points_axis(20_000);
    let experiment = experiment::parse(&text, Path::new("many_points.yaml")).unwrap();
    let run = &experiment.runs[0];
    let id = &run.spec.run_id;
    assert!(id.starts_with("imls_quadratic-pointslist20000-"), "{id}");
    assert!(fits(id), "{id}");
    assert_eq!(run.spec.params["points"].as_list().unwrap().len(), 20_000);
    assert!(
        run.spec.config_yaml.len() > 1 << 16,
        "{}",
        run.spec.config_yaml.len()
    );

    let out = tempfile::tempdir().unwrap();
    let options = RunOptions {
        out: out.path().to_path_buf(),
        jobs: 1,
        threads: 1,
        force: false,
        memory: None,
    };
    let outcome = run_experiment(&experiment, &options).unwrap();
    assert_eq!(
        (outcome.written, outcome.failed.len()),
        (1, 0),
        "{outcome:?}"
    );
    let dir = results_dir(out.path(), &experiment);
    let file = open_run_file(&run_path(&dir, id)).unwrap();
    let summary = read_summary(&file).unwrap();
    assert_eq!(summary.axes["points"], run.spec.params["points"]);
    let stored: hdf5::types::VarLenUnicode =
        file.dataset("config_yaml").unwrap().read_scalar().unwrap();
    assert_eq!(stored.as_str(), run.spec.config_yaml);
}

#[test]
fn lists_are_bounded() {
    let text = points_axis(MAX_LIST_VALUES + 1);
    let e = experiment::parse(&text, Path::new("many_points.yaml")).unwrap_err();
    assert_eq!(
        (e.line, e.column, e.field.as_str()),
        (5, 12, "matrix.points[0]"),
        "{e}"
    );
    assert!(
        e.message.contains(&format!(
            "holds {} numbers; at most {MAX_LIST_VALUES}",
            MAX_LIST_VALUES + 1
        )),
        "{e}"
    );
}

#[test]
fn yaml_tags_are_refused_where_written() {
    refused(
        "yaml_tag.yaml",
        5,
        17,
        "cells",
        &["the YAML tag '!!int' is not accepted"],
    );
}

#[test]
fn invalid_utf8_is_located() {
    refused(
        "invalid_utf8.yaml",
        3,
        26,
        "description",
        &["the byte 0xb2 is not UTF-8 text"],
    );
}

/// Errors of the YAML reader are told in the file's terms, not the library's.
#[test]
fn reader_errors_are_in_plain_words() {
    let e = refused(
        "yaml_two_documents.yaml",
        5,
        1,
        "name",
        &["a file holds one YAML document; found a second at line 5"],
    );
    assert!(!e.message.contains("from_str"), "{e}");
    // 250,001 nodes: the map, its key and the list, and the list's values.
    let values = vec!["1"; 249_998].join(", ");
    let e = experiment::parse(&format!("points: [{values}]\n"), Path::new("x.yaml")).unwrap_err();
    assert!(
        e.message
            .contains("the file has more than 250000 YAML nodes (values, lists and maps)"),
        "{e}"
    );
    assert!(!e.message.contains("budget"), "{e}");
}

/// `mpmlab list-benchmarks | head -1`: the reader has gone before the first line is written.
/// The program ends quietly, by the default action of SIGPIPE (as other Unix tools do) or
/// with success, not with a panic.
#[cfg(unix)]
#[test]
fn a_closed_standard_output_ends_the_program_quietly() {
    use std::os::unix::process::ExitStatusExt;

    for args in [
        &["list-benchmarks"][..],
        &["list-methods"],
        &["expand", "experiments/gong_mpm_1d.yaml"],
    ] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let output = Command::new(env!("CARGO_BIN_EXE_mpmlab"))
            .args(args)
            .stdout(writer)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let status = output.status;
        assert!(
            status.success() || status.signal() == Some(libc::SIGPIPE),
            "{args:?}: {status}"
        );
        assert!(
            output.stderr.is_empty(),
            "{args:?}: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

/// A run estimated above the memory the runs may use is recorded as failed, with its estimate
/// and the limit, and the rest of the matrix completes; a rerun under a larger limit computes
/// it.
#[test]
fn a_run_that_cannot_fit_is_refused_and_computed_by_a_rerun_that_has_room() {
    let yaml = "name: memory\nbenchmark: vibrating_bar\nparams: {method: mpm, ppc: 4}\n\
                matrix:\n  cells: [4, 400]\n";
    let experiment = experiment::parse(yaml, Path::new("memory.yaml")).unwrap();
    let [small, large] = [&experiment.runs[0], &experiment.runs[1]];
    let need = |run| Job::new(run).estimated_bytes();
    let (need_small, need_large) = (need(small), need(large));
    assert!(need_small < need_large, "{need_small} {need_large}");
    let out = tempfile::tempdir().unwrap();
    let mut options = RunOptions {
        out: out.path().to_path_buf(),
        jobs: 2,
        threads: 1,
        force: false,
        memory: Some(((need_small + need_large) / 2.0) as u64),
    };
    let outcome = run_experiment(&experiment, &options).unwrap();
    assert_eq!(
        (outcome.written, outcome.failed.len()),
        (2, 1),
        "{outcome:?}"
    );
    let failure = &outcome.failed[0];
    assert!(
        failure.starts_with(&format!("{}: {REFUSED}", large.spec.run_id)),
        "{failure}"
    );
    assert!(
        failure.contains("it needs an estimated") && failure.contains("of --memory"),
        "{failure}"
    );
    let dir = results_dir(out.path(), &experiment);
    let summary = |run: &ResolvedRun| {
        read_summary(&open_run_file(&run_path(&dir, &run.spec.run_id)).unwrap()).unwrap()
    };
    assert_eq!(summary(large).status, RunStatus::Failed);
    assert_eq!(summary(small).status, RunStatus::Ok);

    options.memory = Some((2.0 * need_large) as u64);
    let rerun = run_experiment(&experiment, &options).unwrap();
    assert_eq!(
        (rerun.written, rerun.skipped, rerun.failed.len()),
        (1, 1, 0),
        "{rerun:?}"
    );
    assert_eq!(summary(large).status, RunStatus::Ok);
}
