//! The report stage end to end on synthetic runs: rates, checks and the files written.

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;

use mpmlab::benchmarks::BenchmarkKind;
use mpmlab::experiment::{
    ClaimedValue, Expectation, Experiment, FieldMapSpec, FigureKind, FigureSpec, OutputSpec,
    PaperClaim, ProbeWindow, Selection, TableKind, TableSpec,
};
use mpmlab::output::{
    ParticleState, ProbeRecord, RunStatus, RunSummary, Unstepped, ERROR_FIELDS, NORMS,
};
use mpmlab::params::{ParamValue, Params};
use mpmlab::report::claims::{self, Verdict};
use mpmlab::report::{check, figures, fit_rates, index, write_report, CheckFailure};

/// Axis values written as in YAML: integers, floats or strings.
fn params(pairs: &[(&str, &str)]) -> Params {
    pairs
        .iter()
        .map(|&(k, v)| {
            let value = v
                .parse::<i64>()
                .map(ParamValue::Int)
                .or_else(|_| v.parse::<f64>().map(ParamValue::Float))
                .unwrap_or_else(|_| ParamValue::Str(v.to_string()));
            (k.to_string(), value)
        })
        .collect()
}

/// A finished run whose errors follow `C h^p` with `C = G * field_scale * norm_scale`:
/// p = 2 everywhere except stress with `usl` (p = 1).
fn run(g: &str, method: &str, cells: usize) -> RunSummary {
    let h = 1.0 / cells as f64;
    let c: f64 = g.parse().unwrap();
    let mut final_norms = BTreeMap::new();
    for field in ERROR_FIELDS {
        let p = if field == "stress" && method == "usl" {
            1
        } else {
            2
        };
        for norm in NORMS {
            let error = c * scale(field, norm) * h.powi(p);
            final_norms.insert((field.to_string(), norm.to_string()), error);
        }
    }
    RunSummary {
        run_id: format!("{method}-G{g}-c{cells}"),
        experiment: "gong_conv".into(),
        benchmark: "mms_gong".into(),
        method: method.into(),
        dim: 2,
        cells,
        ppc: 2,
        h,
        dt: 1e-3 * h,
        steps: 100 * cells,
        status: RunStatus::Ok,
        message: String::new(),
        wall_seconds: 0.01 * cells as f64,
        step_seconds: 1e-4 * cells as f64,
        axes: params(&[("G", g), ("method", method), ("cells", &cells.to_string())]),
        final_norms,
        unstepped: Unstepped::None,
        velocity_history: None,
        max_mass_error: f64::NAN,
        max_momentum_error: f64::NAN,
        profile: None,
        probes: Vec::new(),
        final_state: None,
    }
}

fn scale(field: &str, norm: &str) -> f64 {
    let field_scale = match field {
        "displacement" => 0.2,
        "velocity" => 1.0,
        "stress" => 5.0,
        _ => 0.6,
    };
    field_scale * if norm == "rms" { 0.5 } else { 1.0 }
}

/// G x method x cells, with the finest `usl` run at G=0.05 diverged.
fn runs() -> Vec<RunSummary> {
    let mut runs = Vec::new();
    for g in ["0.1", "0.05"] {
        for method in ["mpm", "usl"] {
            for cells in [8, 16, 32, 64] {
                runs.push(run(g, method, cells));
            }
        }
    }
    let bad = runs
        .iter_mut()
        .find(|r| r.run_id == "usl-G0.05-c64")
        .unwrap();
    bad.status = RunStatus::Diverged;
    bad.message = "NaN in stress at step 120, \"J < 0\"".into();
    for error in bad.final_norms.values_mut() {
        *error = f64::NAN;
    }
    runs
}

fn experiment(expect: Vec<Expectation>, figures: Vec<FigureSpec>) -> Experiment {
    Experiment {
        name: "gong_conv".into(),
        description: String::new(),
        source_path: "experiments/gong_conv.yaml".into(),
        source_text: String::new(),
        benchmark: "mms_gong".into(),
        kind: BenchmarkKind::Simulation,
        axes: ["G", "method", "cells"].map(String::from).to_vec(),
        output: OutputSpec { every: 10 },
        expect,
        figures,
        tables: Vec::new(),
        paper_claims: Vec::new(),
        reference: None,
        runs: Vec::new(),
    }
}

fn expect(line: usize, select: &[(&str, &str)], field: &str) -> Expectation {
    Expectation {
        select: Selection::from(&params(select)),
        field: field.into(),
        norm: "l2".into(),
        rate_min: None,
        rate_max: None,
        error_min: None,
        error_max: None,
        limit: None,
        line,
    }
}

fn messages(failures: &[CheckFailure]) -> Vec<String> {
    failures.iter().map(ToString::to_string).collect()
}

#[test]
fn rates_are_fitted_per_group_in_order() {
    let rates = fit_rates(&experiment(vec![], vec![]), &runs());
    assert_eq!(rates.len(), 4 * ERROR_FIELDS.len() * NORMS.len());
    let groups: Vec<&str> = rates.iter().map(|r| r.group.as_str()).collect();
    assert_eq!(groups[0], "G=0.05 method=mpm");
    assert_eq!(groups[8], "G=0.05 method=usl");
    assert_eq!(groups[16], "G=0.1 method=mpm");
    assert_eq!(groups[31], "G=0.1 method=usl");
    let order: Vec<(&str, &str)> = rates[..8]
        .iter()
        .map(|r| (r.field.as_str(), r.norm.as_str()))
        .collect();
    assert_eq!(
        order[..3],
        [
            ("displacement", "l2"),
            ("displacement", "rms"),
            ("velocity", "l2")
        ]
    );

    for r in &rates {
        let expected = if r.field == "stress" && r.group.ends_with("usl") {
            1.0
        } else {
            2.0
        };
        assert!((r.rate - expected).abs() < 1e-10, "{r:?}");
        assert!((r.r2 - 1.0).abs() < 1e-12, "{r:?}");
        let c = r.group_axes["G"].as_f64().unwrap() * scale(&r.field, &r.norm);
        assert!((r.intercept - c.log10()).abs() < 1e-10, "{r:?}");
    }
    // The diverged finest run is left out of its group's fits.
    let usl = rates
        .iter()
        .find(|r| r.group == "G=0.05 method=usl")
        .unwrap();
    assert_eq!((usl.n, usl.h_min, usl.h_max), (3, 1.0 / 32.0, 0.125));
    let mpm = &rates[0];
    assert_eq!((mpm.n, mpm.h_min), (4, 1.0 / 64.0));
}

#[test]
fn checks_pass_and_fail_as_stated() {
    let runs = runs();
    let mut ok = expect(10, &[("method", "mpm")], "velocity");
    ok.rate_min = Some(1.8);
    ok.rate_max = Some(2.2);
    let mut slow = expect(12, &[("method", "usl"), ("G", "0.1")], "stress");
    slow.rate_min = Some(1.8);
    let mut missing = expect(14, &[("method", "mls")], "velocity");
    missing.rate_min = Some(1.0);
    let mut fast = expect(16, &[], "density");
    fast.rate_max = Some(1.5);
    let exp = experiment(vec![ok, slow, missing, fast], vec![]);
    let rates = fit_rates(&exp, &runs);

    let failures = messages(&check(&exp, &rates, &runs));
    assert_eq!(
        failures,
        [
            "line 12: G=0.1 method=usl stress l2: rate 1 < rate_min 1.8",
            "line 14: no fitted rate for method=mls velocity l2",
            "line 16: G=0.05 method=mpm density l2: rate 2 > rate_max 1.5",
            "line 16: G=0.05 method=usl density l2: rate 2 > rate_max 1.5",
            "line 16: G=0.1 method=mpm density l2: rate 2 > rate_max 1.5",
            "line 16: G=0.1 method=usl density l2: rate 2 > rate_max 1.5",
        ]
    );
    let exp = experiment(exp.expect[..1].to_vec(), vec![]);
    assert!(check(&exp, &rates, &runs).is_empty());
}

#[test]
fn error_bounds_cover_every_matching_run() {
    let runs = runs();
    // 0.1 h^2 <= 2e-3 holds from cells = 8 on; 0.05 h^2 everywhere.
    let mut loose = expect(20, &[("method", "mpm")], "velocity");
    loose.error_max = Some(2e-3);
    let mut tight = expect(21, &[("G", "0.1"), ("method", "mpm")], "velocity");
    tight.error_max = Some(1e-4);
    let mut diverged = expect(
        22,
        &[("G", "0.05"), ("method", "usl"), ("cells", "64")],
        "velocity",
    );
    diverged.error_max = Some(1.0);
    let exp = experiment(vec![loose, tight, diverged], vec![]);
    let rates = fit_rates(&exp, &runs);

    let failures = messages(&check(&exp, &rates, &runs));
    assert_eq!(
        failures,
        [
            "line 21: G=0.1 cells=8 method=mpm velocity l2: error 0.00156 > error_max 0.0001 (run mpm-G0.1-c8)",
            "line 21: G=0.1 cells=16 method=mpm velocity l2: error 3.91e-4 > error_max 0.0001 (run mpm-G0.1-c16)",
            "line 22: G=0.05 cells=64 method=usl velocity l2: run usl-G0.05-c64 diverged: NaN in stress at step 120, \"J < 0\"",
        ]
    );
}

#[test]
fn report_files_are_written_and_deterministic() {
    let runs = runs();
    let mut ok = expect(10, &[("method", "mpm")], "velocity");
    ok.rate_min = Some(1.8);
    let mut slow = expect(12, &[("method", "usl")], "stress");
    slow.rate_min = Some(1.8);
    let exp = experiment(vec![ok, slow], vec![]);
    let rates = fit_rates(&exp, &runs);
    let failures = check(&exp, &rates, &runs);

    let dirs = [tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap()];
    let reports: Vec<_> = dirs
        .iter()
        .map(|d| write_report(d.path(), &exp, &runs, &[], &rates, Some(&failures)).unwrap())
        .collect();
    let report = &reports[0];
    assert_eq!(
        report.figures,
        [
            "figures/gong_conv_G_0.05_method_mpm_l2.png",
            "figures/gong_conv_G_0.05_method_usl_l2.png",
            "figures/gong_conv_G_0.1_method_mpm_l2.png",
            "figures/gong_conv_G_0.1_method_usl_l2.png",
        ]
        .map(std::path::PathBuf::from)
    );
    let dir = dirs[0].path();
    for figure in &report.figures {
        let png = fs::read(dir.join(figure)).unwrap();
        assert!(png.len() > 1000);
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
        assert_eq!(png, fs::read(dirs[1].path().join(figure)).unwrap());
        // The data beside it: every plotted point, markers first, then the line through
        // them and the fit's ends.
        let data = read(dir, &figure.with_extension("csv").to_string_lossy());
        let rows: Vec<&str> = data.lines().collect();
        assert_eq!(
            rows[0],
            "series,role,\"h, cell size (m)\",l2 error (units in the legend)"
        );
        let count = |role: &str| rows.iter().filter(|r| r.contains(role)).count();
        let markers = count(",marker,");
        assert!(markers >= 2 && count(",line,") == markers, "{data}");
        assert!(count(",fit,") >= 2, "{data}");
    }
    let csv = read(dir, "figures/gong_conv_G_0.05_method_mpm_l2.csv");
    let coarse = runs
        .iter()
        .find(|r| r.run_id == "mpm-G0.05-c8")
        .expect("the fixture has mpm at G = 0.05 on 8 cells");
    let velocity = coarse.final_norms[&("velocity".to_string(), "l2".to_string())];
    let point = format!(",marker,0.125,{velocity:?}");
    assert!(
        csv.lines()
            .any(|r| r.starts_with("velocity (m/s·m)") && r.ends_with(&point)),
        "{csv}"
    );
    for name in ["summary.csv", "rates.csv", "report.md"] {
        assert_eq!(read(dir, name), read(dirs[1].path(), name), "{name}");
    }

    let summary = read(dir, "summary.csv");
    let lines: Vec<&str> = summary.lines().collect();
    assert_eq!(
        lines[0],
        "run_id,G,method,cells,h,status,steps,dt,\
         l2_displacement,l2_velocity,l2_stress,l2_density,\
         rms_displacement,rms_velocity,rms_stress,rms_density,message"
    );
    assert_eq!(lines.len(), 1 + runs.len());
    assert!(
        lines[1].starts_with("mpm-G0.05-c8,0.05,mpm,8,0.125,ok,800,"),
        "{}",
        lines[1]
    );
    assert!(
        lines[8].ends_with(
            ",diverged,6400,1.5625e-5,,,,,,,,,\"NaN in stress at step 120, \"\"J < 0\"\"\""
        ),
        "{}",
        lines[8]
    );

    let timings = read(dir, "timings.csv");
    let rows: Vec<&str> = timings.lines().collect();
    assert_eq!(rows[0], "run_id,status,steps,wall_seconds");
    assert_eq!(rows.len(), 1 + runs.len());
    assert!(rows[1].starts_with("mpm-G0.05-c8,ok,800,"), "{}", rows[1]);

    let rates_csv = read(dir, "rates.csv");
    let mut rows = rates_csv.lines();
    assert_eq!(
        rows.next(),
        Some("experiment,group,field,norm,rate,intercept,r2,n,h_min,h_max")
    );
    assert!(rows
        .next()
        .unwrap()
        .starts_with("gong_conv,G=0.05 method=mpm,displacement,l2,"));
    assert_eq!(rows.count(), rates.len() - 1);

    let md = read(dir, "report.md");
    for needle in [
        "# gong_conv\n",
        "- Benchmark: `mms_gong`",
        "- Axis `G`: 0.05, 0.1",
        "- Runs: 16 (15 ok, 1 diverged, 0 failed)",
        "| `usl-G0.05-c64` | 0.05 | usl | 64 | 0.015625 | diverged | 6400 |",
        "| G=0.1 method=usl | stress | l2 | 1.00 | 1.000 | 4 | 0.015625 to 0.125 |",
        "## Diverged and failed runs",
        "NaN in stress at step 120, \"J < 0\"",
        "![gong_conv: displacement, velocity, stress, density (l2 norm): G=0.1 method=mpm](figures/gong_conv_G_0.1_method_mpm_l2.png)",
        "- **pass** line 10: method=mpm velocity l2: rate >= 1.8",
        "- **FAIL** line 12: method=usl stress l2: rate >= 1.8",
        "  - G=0.1 method=usl stress l2: rate 1 < rate_min 1.8",
    ] {
        assert!(md.contains(needle), "missing {needle:?} in\n{md}");
    }
    assert!(!md.contains("wall"));
}

#[test]
fn figure_specs_split_by_the_remaining_axes() {
    let figure = FigureSpec {
        by: vec!["G".into()],
        ..FigureSpec::new(
            FigureKind::Convergence,
            vec!["velocity".into(), "stress".into()],
            "rms",
        )
    };
    let exp = experiment(vec![], vec![figure.clone(), figure]);
    let (dir, names) = figure_names(&exp);
    assert_eq!(
        names,
        [
            "figures/gong_conv_method_mpm_rms.png",
            "figures/gong_conv_method_usl_rms.png",
            "figures/gong_conv_method_mpm_rms_2.png",
            "figures/gong_conv_method_usl_rms_2.png",
        ]
    );
    assert!(!read(dir.path(), "report.md").contains("## Checks"));
}

/// A named figure item: its files are its name with what tells its figures apart, and its
/// captions its title after the paper's figure.
#[test]
fn named_figures_take_their_name_title_and_paper() {
    let figure = FigureSpec {
        by: vec!["G".into()],
        name: Some("fig4_7".into()),
        title: Some("MPM convergence".into()),
        paper: Some("Gong 2015, Fig 4.7".into()),
        ..FigureSpec::new(FigureKind::Convergence, vec!["velocity".into()], "rms")
    };
    let exp = experiment(vec![], vec![figure]);
    let (dir, names) = figure_names(&exp);
    assert_eq!(
        names,
        [
            "figures/fig4_7_method_mpm.png",
            "figures/fig4_7_method_usl.png"
        ]
    );
    let md = read(dir.path(), "report.md");
    let caption =
        "![Gong 2015, Fig 4.7: MPM convergence (method=mpm)](figures/fig4_7_method_mpm.png)";
    assert!(md.contains(caption), "{md}");
    let csv = read(dir.path(), "figures/fig4_7_method_mpm.csv");
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .contains("velocity error, rms norm (m/s)"),
        "{csv}"
    );
    assert!(csv.lines().any(|l| l.contains(",fit,")), "{csv}");
}

/// The report of `exp` over the fixture's runs in a temporary directory, and its figures'
/// files.
fn figure_names(exp: &Experiment) -> (tempfile::TempDir, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let runs = runs();
    let report = write_report(dir.path(), exp, &runs, &[], &fit_rates(exp, &runs), None).unwrap();
    let names = report
        .figures
        .iter()
        .map(|f| f.to_string_lossy().into_owned())
        .collect();
    (dir, names)
}

/// One figure per field of a group: each file names its field.
#[test]
fn single_field_figures_are_named_by_their_field() {
    let spec = |field: &str| FigureSpec {
        by: vec!["method".into(), "G".into()],
        ..FigureSpec::new(FigureKind::Convergence, vec![field.into()], "rms")
    };
    let exp = experiment(vec![], vec![spec("velocity"), spec("stress")]);
    let (_dir, names) = figure_names(&exp);
    assert_eq!(
        names,
        [
            "figures/gong_conv_all_velocity_rms.png",
            "figures/gong_conv_all_stress_rms.png",
        ]
    );
}

#[test]
fn a_matrix_over_cells_alone_is_one_group() {
    let mut exp = experiment(vec![], vec![]);
    exp.axes = vec!["cells".into()];
    let runs: Vec<RunSummary> = [8, 16, 32]
        .map(|cells| {
            let mut r = run("0.1", "mpm", cells);
            r.axes = params(&[("cells", &cells.to_string())]);
            r
        })
        .into();
    let dir = tempfile::tempdir().unwrap();
    let rates = fit_rates(&exp, &runs);
    assert!(rates.iter().all(|r| r.group.is_empty() && r.n == 3));
    let report = write_report(dir.path(), &exp, &runs, &[], &rates, None).unwrap();
    assert_eq!(
        report.figures,
        [std::path::PathBuf::from("figures/gong_conv_all_l2.png")]
    );
    assert!(read(dir.path(), "report.md").contains("| (all) | velocity | l2 | 2.00 |"));
}

fn read(dir: &Path, name: &str) -> String {
    fs::read_to_string(dir.join(name)).unwrap()
}

#[test]
fn figures_no_longer_drawn_are_removed() {
    let runs = runs();
    let exp = experiment(vec![], vec![]);
    let dir = tempfile::tempdir().unwrap();
    let stale = dir.path().join("figures").join("old_figure.png");
    std::fs::create_dir_all(stale.parent().unwrap()).unwrap();
    std::fs::write(&stale, b"old").unwrap();
    let report = write_report(dir.path(), &exp, &runs, &[], &fit_rates(&exp, &runs), None).unwrap();
    assert!(!stale.exists());
    assert!(!report.figures.is_empty());
    assert!(report.figures.iter().all(|f| dir.path().join(f).exists()));
}

/// A run of `method` with a probe `tip` over 11 steps (value t, exact reference 2t); a diverged
/// run stops after 6.
fn probed(method: &str, status: RunStatus) -> RunSummary {
    let mut run = run("0.1", method, 8);
    let steps = if status == RunStatus::Ok { 11 } else { 6 };
    let time: Vec<f64> = (0..steps).map(|s| s as f64 * 0.1).collect();
    run.status = status;
    run.probes = vec![ProbeRecord {
        name: "tip".into(),
        particle: 3,
        x0: vec![0.5, 1.0],
        quantity: "velocity".into(),
        component: vec![1],
        reference_kind: "exact".into(),
        value: time.clone(),
        reference: time.iter().map(|t| 2.0 * t).collect(),
        step: (0..steps as i64).collect(),
        time,
    }];
    run
}

fn history(probe: &str) -> FigureSpec {
    FigureSpec {
        by: vec!["method".into()],
        probe: Some(probe.into()),
        ..FigureSpec::new(FigureKind::History, Vec::new(), "l2")
    }
}

#[test]
fn history_figures_draw_every_run_and_name_unknown_probes() {
    let runs = vec![
        probed("mpm", RunStatus::Ok),
        probed("usl", RunStatus::Diverged),
    ];
    let exp = experiment(vec![], vec![history("tip")]);
    let dir = tempfile::tempdir().unwrap();
    let report = write_report(dir.path(), &exp, &runs, &[], &[], None).unwrap();
    assert_eq!(
        report.figures,
        [Path::new("figures/gong_conv_tip_G_0.1_cells_8.png")]
    );
    assert!(dir.path().join(&report.figures[0]).exists());

    let exp = experiment(vec![], vec![history("root")]);
    let error = write_report(dir.path(), &exp, &runs, &[], &[], None).unwrap_err();
    let message = error.to_string();
    assert!(message.contains("probe 'root'"), "{message}");
    assert!(message.contains("the runs record: tip"), "{message}");
}

fn probes_table(probe: &str) -> TableSpec {
    TableSpec {
        kind: TableKind::Probes,
        columns: None,
        select: Selection::default(),
        stability: None,
        measure: None,
        probe: Some(ProbeWindow {
            name: probe.into(),
            after: 0.5,
            tolerance: 0.3,
        }),
    }
}

/// The probe `tip` is t against its reference 2t. Over t >= 0.5 the finished run has six
/// points, t = 0.5 ... 1.0: mean 0.75, sd sqrt(0.175 / 6), reference 2 at the end, distance t
/// at most 1, farther than 0.3 from the first point on; the diverged run stopped at t = 0.5.
#[test]
fn probes_tables_list_every_run_and_name_unknown_probes() {
    let runs = vec![
        probed("mpm", RunStatus::Ok),
        probed("usl", RunStatus::Diverged),
    ];
    let mut exp = experiment(vec![], vec![]);
    exp.tables = vec![probes_table("tip")];
    let dir = tempfile::tempdir().unwrap();
    write_report(dir.path(), &exp, &runs, &[], &[], None).unwrap();
    let md = read(dir.path(), "report.md");
    assert!(md.contains("### Probe tip after t = 0.5"), "{md}");
    assert!(md.contains("| ok | 0.75 | 0.1708 | 2 | 1 | 0.5 |"), "{md}");
    assert!(
        md.contains("| diverged | 0.5 | 0 | 1 | 0.5 | 0.5 |"),
        "{md}"
    );

    exp.tables = vec![probes_table("root")];
    let message = write_report(dir.path(), &exp, &runs, &[], &[], None)
        .unwrap_err()
        .to_string();
    assert!(message.contains("probe 'root'"), "{message}");
    assert!(message.contains("the runs record: tip"), "{message}");
}

/// The conservation table lists every selected run's largest mapping errors as recorded.
#[test]
fn conservation_tables_list_each_runs_mapping_errors() {
    let mut runs = vec![run("0.1", "mpm", 8), run("0.1", "usl", 8)];
    runs[0].max_mass_error = 2.5e-15;
    runs[0].max_momentum_error = 3.0e-16;
    let mut exp = experiment(vec![], vec![]);
    exp.tables = vec![TableSpec {
        kind: TableKind::Conservation,
        columns: None,
        select: Selection::default(),
        stability: None,
        measure: None,
        probe: None,
    }];
    let dir = tempfile::tempdir().unwrap();
    write_report(dir.path(), &exp, &runs, &[], &[], None).unwrap();
    let md = read(dir.path(), "report.md");
    assert!(
        md.contains("### Largest relative mass and momentum errors"),
        "{md}"
    );
    assert!(
        md.contains("| 0.1 | mpm | 8 | ok | 2.5e-15 | 3e-16 |"),
        "{md}"
    );
    assert!(md.contains("| 0.1 | usl | 8 | ok | NaN | NaN |"), "{md}");
}

/// `run` at 8 cells with a final particle state of two particles, whose stress yy is `yy`.
fn mapped(g: &str, method: &str, yy: [f64; 2]) -> RunSummary {
    let mut run = run(g, method, 8);
    run.final_state = Some(ParticleState {
        dim: 2,
        time: 0.5,
        x0: vec![0.25, 0.25, 0.75, 0.25],
        x: vec![0.25, 0.2, 0.75, 0.2],
        velocity: vec![0.0; 4],
        stress: vec![0.0, 0.0, 0.0, yy[0], 0.0, 0.0, 0.0, yy[1]],
        density: vec![1.0, 1.0],
        volume: vec![0.25, 0.25],
    });
    run
}

fn field_map(field: &str) -> FigureSpec {
    FigureSpec {
        by: vec!["method".into()],
        paper: Some("Paper, Fig 1".into()),
        map: Some(FieldMapSpec {
            field: field.into(),
        }),
        ..FigureSpec::new(FigureKind::FieldMap, Vec::new(), "l2")
    }
}

/// One map per group of the axes other than `by`, a panel per run, and one colour scale for
/// every panel of the entry; the data file holds each cell as drawn.
#[test]
fn field_maps_are_planned_per_group_on_one_scale() {
    let runs = vec![
        mapped("0.1", "mpm", [-1.0, -2.0]),
        mapped("0.1", "usl", [-1.5, -3.0]),
        mapped("0.05", "mpm", [-0.5, -1.0]),
    ];
    let exp = experiment(vec![], vec![field_map("stress_yy")]);
    let plots = figures::plan(&exp, &runs).unwrap();
    assert!(plots.is_empty());
    let maps = figures::plan_maps(&exp, &runs, &plots).unwrap();
    let files: Vec<&Path> = maps.iter().map(|m| m.file.as_path()).collect();
    assert_eq!(
        files,
        [
            Path::new("figures/gong_conv_map_stress_yy_G_0.05_cells_8.png"),
            Path::new("figures/gong_conv_map_stress_yy_G_0.1_cells_8.png"),
        ]
    );
    let map = &maps[1];
    assert_eq!(map.title, "Paper, Fig 1: stress yy at t = 0.5 s");
    assert_eq!(map.scope, "G=0.1 cells=8");
    assert_eq!(map.value_label, "stress yy (Pa)");
    let labels: Vec<&str> = map.panels.iter().map(|p| p.label.as_str()).collect();
    assert_eq!(labels, ["method=mpm", "method=usl"]);
    let cell = map.panels[1].cells[1];
    assert_eq!(
        (cell.x, cell.y, cell.width, cell.value),
        (0.75, 0.2, 0.5, -3.0)
    );
    // The scale spans every panel of both maps.
    for map in &maps {
        assert_eq!((map.scale.lo, map.scale.hi), (-3.0, -0.5));
    }

    let dir = tempfile::tempdir().unwrap();
    let report = write_report(dir.path(), &exp, &runs, &[], &[], None).unwrap();
    assert_eq!(report.figures, files);
    for file in &report.figures {
        assert!(dir.path().join(file).exists());
    }
    let csv = read(
        dir.path(),
        "figures/gong_conv_map_stress_yy_G_0.1_cells_8.csv",
    );
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "panel,role,x (m),y (m),width,height,stress yy (Pa)"
    );
    assert_eq!(lines[4], "method=usl,cell,0.75,0.2,0.5,0.5,-3.0");
    assert_eq!(lines.len(), 5);
    let md = read(dir.path(), "report.md");
    assert!(
        md.contains(
            "![Paper, Fig 1: stress yy at t = 0.5 s: G=0.1 cells=8]\
             (figures/gong_conv_map_stress_yy_G_0.1_cells_8.png)"
        ),
        "{md}"
    );
}

/// A map of runs that are all 1D has nothing to draw, which the report says.
#[test]
fn field_maps_of_1d_runs_are_an_error() {
    let mut one_d = run("0.1", "mpm", 8);
    one_d.dim = 1;
    let exp = experiment(vec![], vec![field_map("stress_yy")]);
    let message = figures::plan_maps(&exp, &[one_d], &[]).unwrap_err();
    assert!(message.contains("no selected run is 2D"), "{message}");
}

fn claim(line: usize, rate: f64, differs: Option<&str>) -> PaperClaim {
    PaperClaim {
        item: "Gong 2015, Fig 4.7".into(),
        claim: "second order".into(),
        figure: None,
        select: Selection::from(&params(&[("G", "0.1"), ("method", "mpm")])),
        field: "displacement".into(),
        norm: "l2".into(),
        value: ClaimedValue::Rate(rate),
        tolerance: 0.1,
        differs: differs.map(String::from),
        line,
    }
}

/// A claim within its tolerance is reproduced; outside it needs a note, and a note on one
/// that is within is stale: `--check` fails on both. report.md and the index show them all.
#[test]
fn paper_claims_get_verdicts_and_fail_the_check_when_unexplained() {
    let mut exp = experiment(vec![], vec![]);
    exp.paper_claims = vec![
        claim(1, 2.0, None),
        claim(2, 3.0, None),
        claim(3, 3.0, Some("docs/NOTES.md, item 9")),
        claim(4, 2.0, Some("docs/NOTES.md, item 9")),
    ];
    let runs = runs();
    let rates = fit_rates(&exp, &runs);
    let outcomes = claims::evaluate(&exp, &rates, &runs);
    let verdicts: Vec<Verdict> = outcomes.iter().map(|o| o.verdict).collect();
    assert_eq!(
        verdicts,
        [
            Verdict::Reproduced,
            Verdict::Unexplained,
            Verdict::Differs,
            Verdict::Stale
        ]
    );
    assert_eq!(outcomes[0].ours_text(), "2");
    let failed: Vec<usize> = check(&exp, &rates, &runs).iter().map(|f| f.line).collect();
    assert_eq!(failed, [2, 4]);
    let dir = tempfile::tempdir().unwrap();
    write_report(dir.path(), &exp, &runs, &[], &rates, None).unwrap();
    let md = read(dir.path(), "report.md");
    assert!(
        md.contains("| Gong 2015, Fig 4.7 | second order | displacement l2 | rate 3 | 2 | ± 0.1 | differs |  | docs/NOTES.md, item 9 |"),
        "{md}"
    );
    let indexed = index::Indexed {
        dir: "gong_conv",
        experiment: &exp,
        claims: outcomes,
        figures: Vec::new(),
        maps: Vec::new(),
        unreadable_runs: 0,
    };
    let front = index::index_md(&[indexed], &[]);
    assert!(
        front.contains("| reproduced | 1 |\n| differs | 1 |\n| differs, unexplained | 1 |"),
        "{front}"
    );
    assert!(front.contains("## Gong 2015: claims"), "{front}");
}
