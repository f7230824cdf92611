//! A run computed into its file, its history streamed there as it is sampled, gives the same
//! file as the run kept in memory and written whole: every dataset, shape and attribute, bit
//! for bit (but the wall time), and not much larger than its numbers. Checked on runs of every
//! kind of the reduced matrices, and on histories of many samples, which span several chunks of
//! the streamed datasets.

use std::path::Path;

use hdf5::types::{TypeDescriptor, VarLenUnicode};
use hdf5::{Attribute, Dataset, Group};

use mpmlab::experiment;

use mpmlab::experiment::ResolvedRun;
use mpmlab::output::{compute_run, run_path, write_hdf5};
use mpmlab::solver::{simulate, Job};

/// A value of a dataset or attribute, comparable bit for bit.
#[derive(Debug, PartialEq)]
enum Stored {
    Floats(Vec<usize>, Vec<u64>),
    Ints(Vec<usize>, Vec<i64>),
    Text(String),
}

fn floats(shape: Vec<usize>, values: Vec<f64>) -> Stored {
    Stored::Floats(shape, values.iter().map(|v| v.to_bits()).collect())
}

fn read_dataset(ds: &Dataset) -> Stored {
    match ds.dtype().unwrap().to_descriptor().unwrap() {
        TypeDescriptor::Float(_) => floats(ds.shape(), ds.read_raw::<f64>().unwrap()),
        TypeDescriptor::Integer(_) => Stored::Ints(ds.shape(), ds.read_raw::<i64>().unwrap()),
        _ => Stored::Text(ds.read_scalar::<VarLenUnicode>().unwrap().to_string()),
    }
}

fn read_attr(attr: &Attribute) -> Stored {
    match attr.dtype().unwrap().to_descriptor().unwrap() {
        TypeDescriptor::Float(_) => floats(attr.shape(), attr.read_raw::<f64>().unwrap()),
        TypeDescriptor::Integer(_) => Stored::Ints(attr.shape(), attr.read_raw::<i64>().unwrap()),
        _ => Stored::Text(attr.read_scalar::<VarLenUnicode>().unwrap().to_string()),
    }
}

/// Every dataset and attribute below `group`, by path, in name order.
fn contents(group: &Group, prefix: &str, out: &mut Vec<(String, Stored)>) {
    let mut names = group.attr_names().unwrap();
    names.sort();
    for name in names {
        if name != "wall_seconds" && name != "step_seconds" {
            let attr = group.attr(&name).unwrap();
            out.push((format!("{prefix}@{name}"), read_attr(&attr)));
        }
    }
    let mut members = group.member_names().unwrap();
    members.sort();
    for name in members {
        let path = format!("{prefix}/{name}");
        if let Ok(ds) = group.dataset(&name) {
            let mut attrs = ds.attr_names().unwrap();
            attrs.sort();
            for attr in attrs {
                out.push((
                    format!("{path}@{attr}"),
                    read_attr(&ds.attr(&attr).unwrap()),
                ));
            }
            out.push((path, read_dataset(&ds)));
        } else {
            contents(&group.group(&name).unwrap(), &path, out);
        }
    }
}

fn file_contents(path: &Path) -> Vec<(String, Stored)> {
    let file = hdf5::File::open(path).unwrap();
    let mut out = Vec::new();
    contents(&file, "", &mut out);
    out
}

/// Writes `spec` both ways and compares the two files; returns the number of values compared.
fn check(run: &ResolvedRun) -> usize {
    let spec = &run.spec;
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole.h5");
    write_hdf5(&whole, &simulate(run)).unwrap();
    let streamed = compute_run(dir.path(), &spec.run_id, |file| {
        Job::new(run).compute(Some(file))
    })
    .unwrap();
    assert!(streamed.history.x.is_empty() || streamed.history.time.is_empty());
    let a = file_contents(&whole);
    let b = file_contents(&run_path(dir.path(), &spec.run_id));
    let names = |c: &[(String, Stored)]| c.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b), "{}", spec.run_id);
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{}: {name} differs", spec.run_id);
    }
    // Chunks fit the planned samples: a file is not much larger than its numbers.
    let numbers: usize = b
        .iter()
        .map(|(_, stored)| match stored {
            Stored::Floats(_, values) => 8 * values.len(),
            Stored::Ints(_, values) => 8 * values.len(),
            Stored::Text(text) => text.len(),
        })
        .sum();
    let size = std::fs::metadata(run_path(dir.path(), &spec.run_id))
        .unwrap()
        .len() as usize;
    assert!(
        size <= 2 * numbers + (1 << 20),
        "{}: {size} bytes for {numbers}",
        spec.run_id
    );
    a.len()
}

/// The first and the last run of each reduced matrix: simulations of every integrator, basis
/// and transfer family, with probes (Molinos' bar and block), the reference solver (no grid),
/// and the unstepped kinds, which do not stream.
#[test]
fn streamed_files_equal_files_written_whole() {
    let mut checked = 0;
    for entry in std::fs::read_dir("tests/matrices").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "yaml") {
            continue;
        }
        let runs = experiment::load(&path).unwrap().runs;
        for spec in [runs.first().unwrap(), runs.last().unwrap()] {
            checked += check(spec);
        }
    }
    assert!(checked > 1000, "{checked}");
}

/// A history of every step (4,000 samples of 120 particles in 1D: the particle arrays span
/// three chunks, the 2D ones of 36 particles a sample more than one) and a probe of every
/// step.
#[test]
fn histories_of_many_samples_span_chunks_and_equal_the_whole() {
    let yaml = "name: many_samples\nbenchmark: vibrating_bar\n\
                params: {cells: 10, ppc: 12, t_end: 4.0e-4, method: mpm}\n\
                output: {every: 1}\n";
    let runs = experiment::parse(yaml, Path::new("many_samples.yaml"))
        .unwrap()
        .runs;
    let record = simulate(&runs[0]);
    assert!(
        record.history.time.len() > 3 * (1 << 17) / 120,
        "{}",
        record.history.time.len()
    );
    check(&runs[0]);
    let molinos = experiment::load(Path::new("tests/matrices/ci_molinos.yaml"))
        .unwrap()
        .runs;
    let mut spec = molinos[0].clone();
    spec.spec.output_every = 1;
    check(&spec);
}
