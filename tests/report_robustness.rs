//! `mpmlab report` and `mpmlab index` over damaged results directories: a report that fails
//! leaves the previous one whole, and run files that cannot be read are listed with the reason
//! while the others are reported. Written to hold as root too, which ignores file permissions:
//! the failures come from directories where files must go.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use mpmlab::collect::collect;
use mpmlab::experiment::{self, Experiment};
use mpmlab::output::{run_path, temp_path, SCHEMA_VERSION};
use mpmlab::report;
use mpmlab::runner::results_dir;

const EXE: &str = env!("CARGO_BIN_EXE_mpmlab");

fn input(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/inputs/robustness")
        .join(name)
}

fn mpmlab(args: &[&str]) -> Output {
    Command::new(EXE).args(args).output().unwrap()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// `broken_runs.yaml` run into `out`: the experiment and its results directory.
fn computed(out: &Path) -> (Experiment, PathBuf) {
    let file = input("broken_runs.yaml");
    let run = mpmlab(&[
        "run",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let experiment = experiment::load(&file).unwrap();
    let dir = results_dir(out, &experiment);
    (experiment, dir)
}

/// The run file of the run with `cells` cells.
fn run_file(experiment: &Experiment, dir: &Path, cells: i64) -> PathBuf {
    let run = experiment
        .runs
        .iter()
        .find(|r| {
            r.spec
                .params
                .get("cells")
                .is_some_and(|v| v.to_string() == cells.to_string())
        })
        .unwrap();
    run_path(dir, &run.spec.run_id)
}

/// Every file of a results directory but its run files, with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                if path != dir.join("runs") {
                    pending.push(path);
                }
            } else {
                files.insert(path.clone(), fs::read(&path).unwrap());
            }
        }
    }
    files
}

/// Temporary files anywhere in `dir`.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path
                .file_name()
                .unwrap()
                .to_string_lossy()
                .contains(".tmp-")
            {
                found.push(path.clone());
            }
            if path.is_dir() {
                pending.push(path);
            }
        }
    }
    found
}

#[test]
fn a_report_that_fails_leaves_the_previous_report_whole() {
    let out = tempfile::tempdir().unwrap();
    let (experiment, dir) = computed(out.path());
    // The previous report covers one run fewer, so that a new one would differ from it.
    let aside = out.path().join("aside.h5");
    let last = run_file(&experiment, &dir, 22);
    fs::rename(&last, &aside).unwrap();
    let previous = mpmlab(&["report", dir.to_str().unwrap()]);
    assert!(previous.status.success(), "{}", stderr(&previous));
    fs::rename(&aside, &last).unwrap();

    // A figure's data file replaced by a directory: the new report cannot go in.
    let figure_csv = fs::read_dir(dir.join("figures"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "csv"))
        .unwrap();
    fs::remove_file(&figure_csv).unwrap();
    fs::create_dir(&figure_csv).unwrap();
    let before = snapshot(&dir);
    let failed = mpmlab(&["report", dir.to_str().unwrap()]);
    assert!(!failed.status.success());
    let message = stderr(&failed);
    assert!(
        message.contains(&format!("{} is a directory", figure_csv.display())),
        "{message}"
    );
    assert_eq!(snapshot(&dir), before);
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
    fs::remove_dir(&figure_csv).unwrap();

    // A write that fails after every figure is written (the temporary name of report.md, the
    // last file, taken by a directory): the figures already written under temporary names go,
    // and nothing is renamed.
    let before = snapshot(&dir);
    let blocker = temp_path(&dir.join("report.md"));
    fs::create_dir(&blocker).unwrap();
    let collected = collect(&dir).unwrap();
    let rates = report::fit_rates(&collected.experiment, &collected.runs);
    let write = |dir: &Path| {
        report::write_report(
            dir,
            &collected.experiment,
            &collected.runs,
            &collected.unreadable,
            &rates,
            None,
        )
    };
    assert!(write(&dir).is_err());
    assert_eq!(snapshot(&dir), before);
    assert_eq!(temporaries(&dir), vec![blocker.clone()]);
    fs::remove_dir(&blocker).unwrap();

    write(&dir).unwrap();
    let summary = fs::read_to_string(dir.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 1 + experiment.runs.len());
    assert_eq!(temporaries(&dir), Vec::<PathBuf>::new());
}

/// Rewrites an HDF5 file in place.
fn edit(path: &Path, change: impl FnOnce(&hdf5::File) -> hdf5::Result<()>) {
    let file = hdf5::File::open_rw(path).unwrap();
    change(&file).unwrap();
}

#[test]
fn unreadable_run_files_are_listed_with_the_reason_and_the_others_reported() {
    let out = tempfile::tempdir().unwrap();
    let (experiment, dir) = computed(out.path());
    let file = |cells| run_file(&experiment, &dir, cells);
    let name = |cells| {
        let path: PathBuf = file(cells);
        format!("runs/{}", path.file_name().unwrap().to_string_lossy())
    };

    let whole = fs::read(file(4)).unwrap();
    fs::write(file(4), &whole[..whole.len() / 2]).unwrap();
    fs::write(file(6), "run: not really\n").unwrap();
    fs::write(dir.join("runs/x.h5"), "a text file named like a run\n").unwrap();
    edit(&file(8), |f| f.unlink("history/v"));
    edit(&file(10), |f| {
        f.unlink("errors/norms/l2_velocity")?;
        f.new_dataset::<f64>()
            .shape((2, 3))
            .create("errors/norms/l2_velocity")
            .map(drop)
    });
    edit(&file(12), |f| {
        f.delete_attr("schema_version")?;
        f.new_attr::<i64>()
            .shape(())
            .create("schema_version")?
            .write_scalar(&1)
    });
    fs::copy(file(16), file(14)).unwrap();
    drop(hdf5::File::create(file(18)).unwrap());

    let expected = [
        (
            name(4),
            format!("truncated: {} of {} bytes", whole.len() / 2, whole.len()),
        ),
        (name(6), "not an HDF5 file".to_string()),
        (name(8), "lacks /history/v".to_string()),
        (
            name(10),
            "dataset /errors/norms/l2_velocity has 2 dimensions, 1 expected".to_string(),
        ),
        (
            name(12),
            format!(
                "written with layout version 1, this mpmlab reads version {SCHEMA_VERSION} \
                 (rerun it with --force)"
            ),
        ),
        (
            name(14),
            format!(
                "holds run {}, not {}",
                &name(16)[5..name(16).len() - 3],
                &name(14)[5..name(14).len() - 3]
            ),
        ),
        (name(18), "lacks the attribute 'schema_version'".to_string()),
        ("runs/x.h5".to_string(), "not an HDF5 file".to_string()),
    ];

    let plain = mpmlab(&["report", dir.to_str().unwrap()]);
    assert!(plain.status.success(), "{}", stderr(&plain));
    let checked = mpmlab(&["report", dir.to_str().unwrap(), "--check"]);
    assert!(!checked.status.success());
    let message = stderr(&checked);
    // Only the project's words: no HDF5 error stack, no HDF5 function names.
    assert!(!message.contains("H5"), "{message}");
    assert!(message.contains("8 run file(s) unreadable: "), "{message}");
    let md = fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("## Unreadable run files"), "{md}");
    for (file, reason) in &expected {
        assert!(
            message.contains(&format!(
                "unreadable run file: {}: {reason}\n",
                dir.join(file).display()
            )),
            "{file}: {message}"
        );
        assert!(
            md.contains(&format!("| `{file}` | {reason} |")),
            "{file}: {md}"
        );
    }
    // The readable runs are reported, and fitted.
    let summary = fs::read_to_string(dir.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 1 + 3, "{summary}");
    for cells in [16, 20, 22] {
        assert!(
            summary.contains(&name(cells)[5..name(cells).len() - 3]),
            "{summary}"
        );
    }
    let rates = fs::read_to_string(dir.join("rates.csv")).unwrap();
    assert!(
        rates.lines().any(|l| l.contains(",velocity,l2,")),
        "{rates}"
    );
}

#[test]
fn the_index_is_not_stopped_by_one_broken_results_directory() {
    let out = tempfile::tempdir().unwrap();
    let (experiment, dir) = computed(out.path());
    fs::write(run_file(&experiment, &dir, 4), "damaged\n").unwrap();
    let broken = out.path().join("broken");
    fs::create_dir(&broken).unwrap();
    fs::write(
        broken.join("experiment.yaml"),
        "name: broken\nbenchmark: nothing_of_that_name\n",
    )
    .unwrap();

    let index = mpmlab(&["index", out.path().to_str().unwrap()]);
    assert!(!index.status.success());
    let message = stderr(&index);
    assert!(
        message.contains("1 results directory left out of the index"),
        "{message}"
    );
    let md = fs::read_to_string(out.path().join("README.md")).unwrap();
    assert!(
        md.contains("- [broken_runs](broken_runs/report.md): 10 runs; 1 unreadable run file(s)"),
        "{md}"
    );
    assert!(md.contains("## Unreadable results directories"), "{md}");
    assert!(md.contains("- `broken`: "), "{md}");
    assert!(md.contains("nothing_of_that_name"), "{md}");
}
