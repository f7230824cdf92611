//! `mpmlab run` again over an existing results directory: it removes what killed processes
//! left, refuses a second experiment of the same name, and shares the work with another
//! `run` on the same --out.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use mpmlab::experiment;
use mpmlab::output::{host_tag, run_path, this_host};
use mpmlab::runner::results_dir;

const EXE: &str = env!("CARGO_BIN_EXE_mpmlab");

/// No process has an id above the kernel's largest pid_max (2^22).
const DEAD_PID: u32 = 1 << 23;

fn input(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/inputs/robustness")
        .join(name)
}

fn run(files: &[&Path], out: &Path) -> Output {
    let mut command = Command::new(EXE);
    command.arg("run").args(files).arg("--out").arg(out);
    command.output().unwrap()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn a_rerun_removes_what_dead_processes_left_and_nothing_else() {
    let out = tempfile::tempdir().unwrap();
    let file = input("same_name.yaml");
    let first = run(&[&file], out.path());
    assert!(first.status.success(), "{}", stderr(&first));
    let exp = experiment::load(&file).unwrap();
    let dir = results_dir(out.path(), &exp);
    let id = &exp.runs[0].spec.run_id;
    let me = std::process::id();
    let (host, tag) = (this_host(), host_tag());
    let dead = [
        format!("runs/.{id}.h5.tmp-{DEAD_PID}@{tag}"),
        // As earlier versions named them: removed as nobody holds the run's lock.
        format!("runs/.{id}.xdmf.tmp-{DEAD_PID}"),
        format!("runs/.{id}.lock"),
        format!(".experiment.yaml.tmp-{DEAD_PID}@{tag}"),
        format!(".experiment.yaml.tmp-{host}-{DEAD_PID}-1"),
        format!(".summary.csv.tmp-{DEAD_PID}@{tag}"),
    ];
    // `run` looks only where it writes; `report` in figures/ too.
    let report_temps = [format!(
        "figures/.same_name_all_l2.png.tmp-{DEAD_PID}@{tag}"
    )];
    let alive = [
        // This test's own process is alive; another host's processes cannot be looked at.
        format!("runs/.{id}.h5.tmp-{me}@{tag}"),
        format!("runs/.{id}.h5.tmp-{DEAD_PID}@0badc0de"),
        format!(".experiment.yaml.tmp-{host}.elsewhere-{DEAD_PID}-1"),
    ];
    fs::create_dir_all(dir.join("figures")).unwrap();
    for name in dead.iter().chain(&report_temps).chain(&alive) {
        fs::write(dir.join(name), "left behind").unwrap();
    }

    let again = run(&[&file], out.path());
    assert!(again.status.success(), "{}", stderr(&again));
    for name in &dead {
        assert!(!dir.join(name).exists(), "{name} is still there");
    }
    for name in report_temps.iter().chain(&alive) {
        assert!(dir.join(name).exists(), "{name} was removed");
    }
    let report = Command::new(EXE).arg("report").arg(&dir).output().unwrap();
    assert!(report.status.success(), "{}", stderr(&report));
    for name in &report_temps {
        assert!(!dir.join(name).exists(), "{name} is still there");
    }
    for name in &alive {
        assert!(dir.join(name).exists(), "{name} was removed");
    }
}

#[test]
fn another_experiment_of_the_same_name_is_refused_and_an_edited_one_is_not() {
    let out = tempfile::tempdir().unwrap();
    let sources = tempfile::tempdir().unwrap();
    let mine = sources.path().join("same_name.yaml");
    fs::copy(input("same_name.yaml"), &mine).unwrap();
    let other = input("same_name_other.yaml");
    let first = run(&[&mine], out.path());
    assert!(first.status.success(), "{}", stderr(&first));
    let dir = out.path().join("same_name");
    let copy = fs::read_to_string(dir.join("experiment.yaml")).unwrap();

    let refused = run(&[&other], out.path());
    assert!(!refused.status.success());
    let message = stderr(&refused);
    let canonical = fs::canonicalize(&mine).unwrap();
    for named in [
        other.display().to_string(),
        dir.join("experiment.yaml").display().to_string(),
        canonical.display().to_string(),
    ] {
        assert!(message.contains(&named), "{named} not in: {message}");
    }
    assert_eq!(
        fs::read_to_string(dir.join("experiment.yaml")).unwrap(),
        copy
    );

    // The same text from another place, and the copy itself (what a Slurm task runs), are the
    // same experiment.
    let twin = sources.path().join("twin.yaml");
    fs::copy(&mine, &twin).unwrap();
    for same in [twin, dir.join("experiment.yaml")] {
        let rerun = run(&[&same], out.path());
        assert!(rerun.status.success(), "{}", stderr(&rerun));
    }

    // Editing the file and running it again is the ordinary workflow.
    fs::write(&mine, copy.replace("cells: [4, 8]", "cells: [4, 8, 16]")).unwrap();
    let edited = run(&[&mine], out.path());
    assert!(edited.status.success(), "{}", stderr(&edited));
    assert!(stderr(&edited).contains("1 runs written, 2 already present"));
    assert_ne!(
        fs::read_to_string(dir.join("experiment.yaml")).unwrap(),
        copy
    );

    // Two files of one name in one command: refused before anything runs.
    let fresh = tempfile::tempdir().unwrap();
    let both = run(&[&input("same_name.yaml"), &other], fresh.path());
    assert!(!both.status.success());
    assert!(stderr(&both).contains("both name the experiment 'same_name'"));
    assert_eq!(fs::read_dir(fresh.path()).unwrap().count(), 0);
}

/// `<written> runs written, <present> already present[, <elsewhere> computed by another
/// process]` of a `run`'s summary line.
fn counts(output: &Output) -> [usize; 3] {
    let text = stderr(output);
    let line = text
        .lines()
        .find(|l| l.contains(" runs written, "))
        .unwrap_or_else(|| panic!("no summary in: {text}"));
    let number = |after: &str| -> usize {
        if !line.contains(after) {
            return 0;
        }
        line.split(after)
            .next()
            .and_then(|head| head.rsplit([' ', ',']).next())
            .and_then(|n| n.parse().ok())
            .unwrap_or(0)
    };
    [
        number(" runs written"),
        number(" already present"),
        number(" computed by another process"),
    ]
}

#[test]
fn two_runs_on_one_out_compute_each_run_once() {
    let out = tempfile::tempdir().unwrap();
    let file = input("shared_out.yaml");
    let exp = experiment::load(&file).unwrap();
    let start = || {
        Command::new(EXE)
            .arg("run")
            .arg(&file)
            .arg("--out")
            .arg(out.path())
            .args(["--jobs", "1"])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (start(), start());
    let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
    assert!(a.status.success(), "{}", stderr(&a));
    assert!(b.status.success(), "{}", stderr(&b));
    let (a, b) = (counts(&a), counts(&b));
    let runs = exp.runs.len();
    assert_eq!(a[0] + b[0], runs, "written: {a:?} and {b:?}");
    assert_eq!(a.iter().sum::<usize>(), runs, "{a:?}");
    assert_eq!(b.iter().sum::<usize>(), runs, "{b:?}");
    let dir = results_dir(out.path(), &exp);
    for run in &exp.runs {
        assert!(
            run_path(&dir, &run.spec.run_id).exists(),
            "{}",
            run.spec.run_id
        );
    }
    let left: Vec<String> = fs::read_dir(dir.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".lock") || n.contains(".tmp-"))
        .collect();
    assert_eq!(left, Vec::<String>::new());
}
