//! The shard split (`mpmlab run --shard K/N`) and the Slurm array script (`mpmlab slurm
//! --dry-run`), without Slurm: the split is deterministic, covers every run exactly once,
//! is balanced by the estimated cost, and shards run one by one into one directory give the
//! files a single run gives. `make test-slurm` runs the same against a real cluster.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use mpmlab::experiment::{self, Experiment};
use mpmlab::output::run_path;
use mpmlab::runner::{estimated_cost, results_dir};
use mpmlab::shard::{Plan, Shard};

const EXE: &str = env!("CARGO_BIN_EXE_mpmlab");

fn load_dir(dir: &str) -> Vec<Experiment> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no {dir}/*.yaml");
    files
        .iter()
        .map(|f| experiment::load(f).unwrap_or_else(|e| panic!("{e}")))
        .collect()
}

fn keys(experiments: &[Experiment]) -> BTreeSet<(String, String)> {
    experiments
        .iter()
        .flat_map(|e| {
            e.runs
                .iter()
                .map(|r| (e.name.clone(), r.spec.run_id.clone()))
        })
        .collect()
}

fn mpmlab(args: &[&str]) -> Output {
    Command::new(EXE).args(args).output().unwrap()
}

#[test]
fn split_of_the_full_matrix_is_deterministic_disjoint_complete_and_balanced() {
    let experiments = load_dir("experiments");
    let all = keys(&experiments);
    let n = 8;
    let plan = Plan::new(&experiments, n);

    // Same input, same split; the order of the files does not matter.
    let mut reversed = experiments.clone();
    reversed.reverse();
    let again = Plan::new(&reversed, n);
    for (name, run_id) in &all {
        let k = plan.shard_of(name, run_id).unwrap();
        assert!((1..=n).contains(&k));
        assert_eq!(again.shard_of(name, run_id), Some(k), "{name}/{run_id}");
    }
    assert_eq!(plan.loads, again.loads);

    // The shards' selections are disjoint and together hold every run once.
    let mut union = BTreeSet::new();
    let mut count = 0;
    for k in 1..=n {
        let part: Vec<Experiment> = experiments.iter().map(|e| plan.select(e, k)).collect();
        let runs = keys(&part);
        assert_eq!(runs.len(), plan.loads[k - 1].runs);
        let cost: u64 = part
            .iter()
            .flat_map(|e| e.runs.iter().map(estimated_cost))
            .sum();
        assert_eq!(cost, plan.loads[k - 1].cost);
        count += runs.len();
        union.extend(runs);
        // A selection keeps the whole experiment file, so every shard writes the same copy.
        for (whole, shard) in experiments.iter().zip(&part) {
            assert_eq!(whole.source_text, shard.source_text);
        }
    }
    assert_eq!(count, all.len(), "a run is in two shards");
    assert_eq!(union, all);

    // Greedy largest-first: no shard exceeds the mean by more than the costliest run, and
    // the costliest shard is within 4/3 of the best possible (Graham's bound for LPT), which
    // is at least the mean and at least the costliest run.
    let costs: Vec<u64> = experiments
        .iter()
        .flat_map(|e| e.runs.iter().map(estimated_cost))
        .collect();
    let total: u64 = costs.iter().sum();
    let mean = total as f64 / n as f64;
    let largest = *costs.iter().max().unwrap() as f64;
    let max = plan.loads.iter().map(|l| l.cost).max().unwrap() as f64;
    let describe = plan.describe();
    assert!(max <= mean + largest, "{describe:?}");
    assert!(max <= 4.0 / 3.0 * mean.max(largest), "{describe:?}");
    assert_eq!(plan.loads.iter().map(|l| l.cost).sum::<u64>(), total);
}

#[test]
fn equal_costs_go_round_robin_in_run_id_order() {
    let yaml = "name: ties\nbenchmark: mms1d_gong\nparams: {method: mpm, ppc: 2, cells: 8}\n\
                matrix:\n  G: [0.01, 0.02, 0.03, 0.04, 0.05]\n";
    let exp = experiment::parse(yaml, Path::new("ties.yaml")).unwrap();
    let cost = estimated_cost(&exp.runs[0]);
    assert!(exp.runs.iter().all(|r| estimated_cost(r) == cost));
    let plan = Plan::new(std::slice::from_ref(&exp), 3);
    let mut ids: Vec<&str> = exp.runs.iter().map(|r| r.spec.run_id.as_str()).collect();
    ids.sort();
    let shards: Vec<usize> = ids
        .iter()
        .map(|id| plan.shard_of("ties", id).unwrap())
        .collect();
    // Largest first, ties by run id, each to the least-loaded shard, ties to the lowest.
    assert_eq!(shards, [1, 2, 3, 1, 2]);
}

#[test]
fn more_shards_than_runs_leaves_shards_empty() {
    let experiments = load_dir("tests/matrices");
    let runs = keys(&experiments).len();
    let plan = Plan::new(&experiments, runs + 3);
    assert_eq!(plan.loads.iter().filter(|l| l.runs == 0).count(), 3);
    assert!(plan.loads.iter().all(|l| l.runs <= 1));
    let one = Plan::new(&experiments, 1);
    assert_eq!(one.loads[0].runs, runs);
    assert_eq!(one.imbalance(), 1.0);
}

#[test]
fn estimated_cost_counts_particles_times_steps() {
    let yaml = "name: cost\nbenchmark: mms1d_gong\nparams: {method: mpm, ppc: 2, G: 0.05}\n\
                matrix:\n  cells: [8, 16]\n";
    let exp = experiment::parse(yaml, Path::new("cost.yaml")).unwrap();
    let [coarse, fine] = [&exp.runs[0], &exp.runs[1]].map(estimated_cost);
    // Twice the cells: twice the particles and, at a fixed CFL number, twice the steps.
    assert_eq!(fine, 4 * coarse);
    assert_eq!(coarse % 16, 0, "16 particles times the step count");
}

const SHARD_A: &str = "\
name: shard_a
benchmark: mms1d_gong
params: {method: mpm, ppc: 2, G: 0.05}
matrix:
  cells: [8, 16, 32]
output: {every: 8}
";

const SHARD_B: &str = "\
name: shard_b
benchmark: recon1d_nodes
params: {method: mls_linear, function: sin_pi, spacing: random, ppc: 4}
matrix:
  cells: [10, 20, 40, 80]
";

fn files_in(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

#[test]
fn shards_run_one_by_one_give_the_single_run_files() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("shard_a.yaml");
    let b = tmp.path().join("shard_b.yaml");
    std::fs::write(&a, SHARD_A).unwrap();
    std::fs::write(&b, SHARD_B).unwrap();
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let single = tmp.path().join("single");
    let sharded = tmp.path().join("sharded");
    let out = mpmlab(&["run", "--out", single.to_str().unwrap(), a, b]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let experiments = [a, b].map(|f| experiment::load(Path::new(f)).unwrap());
    let plan = Plan::new(&experiments, 3);
    for k in 1..=3 {
        let shard = format!("{k}/3");
        let out = mpmlab(&[
            "run",
            "--shard",
            &shard,
            "--out",
            sharded.to_str().unwrap(),
            a,
            b,
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        let load = plan.loads[k - 1];
        assert!(
            stderr.contains(&format!("shard {shard}: {} of 7 runs", load.runs)),
            "{stderr}"
        );
    }
    for experiment in &experiments {
        let (one, merged) = (
            results_dir(&single, experiment),
            results_dir(&sharded, experiment),
        );
        assert_eq!(files_in(&one.join("runs")), files_in(&merged.join("runs")));
        assert_eq!(
            std::fs::read(one.join("experiment.yaml")).unwrap(),
            std::fs::read(merged.join("experiment.yaml")).unwrap()
        );
        for run in &experiment.runs {
            assert!(run_path(&merged, &run.spec.run_id).exists());
        }
    }

    // A shard run again finds its runs complete.
    let out = mpmlab(&[
        "run",
        "--shard",
        "2/3",
        "--out",
        sharded.to_str().unwrap(),
        a,
        b,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains(" 1 runs written") && stderr.contains(" 0 runs written"));
}

#[test]
fn dry_run_prints_the_array_script_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = tmp.path().join("shard_a.yaml");
    std::fs::write(&yaml, SHARD_A).unwrap();
    let yaml_b = tmp.path().join("shard_b.yaml");
    std::fs::write(&yaml_b, SHARD_B).unwrap();
    let out_dir = tmp.path().join("out");
    let out = mpmlab(&[
        "slurm",
        yaml.to_str().unwrap(),
        yaml_b.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--shards",
        "3",
        "--partition",
        "short",
        "--time",
        "01:30:00",
        "--cpus-per-task",
        "4",
        "--dry-run",
        "--",
        "--account=proj",
        "--qos",
        "long",
    ]);
    let script = String::from_utf8(out.stdout).unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!out_dir.exists(), "--dry-run wrote {}", out_dir.display());

    let lines: Vec<&str> = script.lines().collect();
    assert_eq!(lines[0], "#!/bin/bash");
    let out_abs = out_dir.to_str().unwrap();
    for directive in [
        "#SBATCH --job-name=mpmlab-2-experiments".to_string(),
        "#SBATCH --array=1-3".to_string(),
        "#SBATCH --cpus-per-task=4".to_string(),
        "#SBATCH --partition=short".to_string(),
        "#SBATCH --time=01:30:00".to_string(),
        format!("#SBATCH --output={out_abs}/slurm/%x-%A_%a.out"),
    ] {
        assert!(lines.contains(&directive.as_str()), "{directive}\n{script}");
    }
    // The directives come before the first command, which sbatch requires.
    let first_command = lines
        .iter()
        .position(|l| !l.starts_with('#') && !l.is_empty())
        .unwrap();
    assert!(lines[..first_command]
        .iter()
        .all(|l| !l.starts_with("#SBATCH") || l.starts_with("#SBATCH --")));
    assert!(lines[first_command..]
        .iter()
        .all(|l| !l.starts_with("#SBATCH")));

    // Each task runs its shard of both files with the absolute binary, into the absolute
    // results directory, reading the experiment copies written at submission.
    let exe = std::fs::canonicalize(EXE).unwrap();
    let command = script[script.find("exec ").unwrap()..].replace(" \\\n  ", " ");
    assert_eq!(
        command.trim_end(),
        format!(
            "exec {} run --shard \"${{SLURM_ARRAY_TASK_ID}}/3\" --out {out_abs} --jobs \
             \"${{SLURM_CPUS_PER_TASK:-4}}\" {out_abs}/shard_a/experiment.yaml \
             {out_abs}/shard_b/experiment.yaml",
            exe.display()
        )
    );

    // The plan: each shard's runs and estimated cost, as `run --shard` splits them.
    let experiments = [&yaml, &yaml_b].map(|f| experiment::load(f).unwrap());
    let plan = Plan::new(&experiments, 3);
    for line in plan.describe() {
        assert!(
            script.contains(&format!("#   {line}\n")),
            "{line}\n{script}"
        );
    }
    assert!(script.contains("shard 1/3: "));

    // The options after `--` go to sbatch's command line, before the script.
    assert!(
        stderr.contains(&format!(
            "sbatch --parsable --account=proj --qos long {out_abs}/slurm/mpmlab-2-experiments.sbatch"
        )),
        "{stderr}"
    );
}

/// `--threads T` gives each run of a task T threads and the task its CPUs divided by T runs
/// at a time, at least one; more threads than CPUs per task is refused before anything is written.
#[test]
fn slurm_threads_divide_each_tasks_cpus() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = tmp.path().join("shard_a.yaml");
    std::fs::write(&yaml, SHARD_A).unwrap();
    let out_dir = tmp.path().join("out");
    let slurm = |cpus: &str, threads: &str| {
        mpmlab(&[
            "slurm",
            yaml.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--cpus-per-task",
            cpus,
            "--threads",
            threads,
            "--dry-run",
        ])
    };
    let out = slurm("4", "2");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let script = String::from_utf8(out.stdout).unwrap();
    let jobs =
        "--jobs \"$(( ${SLURM_CPUS_PER_TASK:-4} / 2 > 0 ? ${SLURM_CPUS_PER_TASK:-4} / 2 : 1 ))\" \
                --threads 2";
    assert!(script.contains(jobs), "{script}");
    // What bash makes of the --jobs argument for the CPUs a task may get.
    for (cpus, jobs) in [("", "2"), ("6", "3"), ("1", "1")] {
        let expr =
            "echo $(( ${SLURM_CPUS_PER_TASK:-4} / 2 > 0 ? ${SLURM_CPUS_PER_TASK:-4} / 2 : 1 ))";
        let mut bash = std::process::Command::new("bash");
        bash.args(["-c", expr]);
        if !cpus.is_empty() {
            bash.env("SLURM_CPUS_PER_TASK", cpus);
        }
        let printed = bash.output().unwrap().stdout;
        assert_eq!(String::from_utf8_lossy(&printed).trim(), jobs, "{cpus:?}");
    }

    let out = slurm("2", "3");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--threads 3 exceeds --cpus-per-task 2"),
        "{stderr}"
    );
    assert!(!out_dir.exists());
}

#[test]
fn slurm_without_sbatch_says_so_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = tmp.path().join("shard_a.yaml");
    std::fs::write(&yaml, SHARD_A).unwrap();
    let out_dir = tmp.path().join("out");
    let out = Command::new(EXE)
        .args(["slurm", yaml.to_str().unwrap(), "--out"])
        .arg(&out_dir)
        .env("PATH", tmp.path())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("sbatch not found on PATH"), "{stderr}");
    assert!(!out_dir.exists());
}

#[test]
fn shard_arguments_are_checked() {
    let out = mpmlab(&["run", "--shard", "4/3", "experiments/gong_mpm_1d.yaml"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("1 <= K <= N"));
    assert_eq!(
        "3/3".parse::<Shard>().unwrap(),
        Shard { index: 3, count: 3 }
    );
}
