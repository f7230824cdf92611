//! Methods composed of named parts: a run that names a preset's shape function, transfer and
//! integrator instead of the preset computes the preset's numbers to the bit, and an
//! experiment file can make the parts its matrix axes, with or without a preset.

use std::path::Path;

use mpmlab::benchmarks::thesis_params;
use mpmlab::experiment;
use mpmlab::experiment::ResolvedRun;
use mpmlab::methods::{COMPOSED, GAMMA_KEY};
use mpmlab::output::{RunRecord, RunStatus};
use mpmlab::params::{ParamValue, Params};
use mpmlab::run_spec::RunSpec;
use mpmlab::solver::simulate;

fn run(method: &str, extra: &[(&str, ParamValue)]) -> RunRecord {
    let mut params = thesis_params(1e-4, 16, 2);
    params.extend(extra.iter().map(|(k, v)| (k.to_string(), v.clone())));
    let record = simulate(
        &ResolvedRun::resolve(RunSpec {
            experiment: "composed_methods".into(),
            run_id: method.into(),
            benchmark: "mms1d_gong".into(),
            method: method.into(),
            params,
            axes: Params::new(),
            output_every: 4,
            config_yaml: String::new(),
        })
        .unwrap(),
    );
    assert_eq!(record.status, RunStatus::Ok, "{method}: {}", record.message);
    record
}

fn text(s: &str) -> ParamValue {
    ParamValue::Str(s.into())
}

/// Every number a run records, as text that round-trips each f64 (so equal text is equal
/// bits, -0.0 apart from 0.0).
fn numbers(record: &RunRecord) -> String {
    format!(
        "{:?} {:?} {:?} {:?} {:?}",
        record.history, record.grid, record.errors, record.conservation, record.particles
    )
}

#[test]
fn a_composed_run_computes_its_presets_numbers_bit_for_bit() {
    let cases = [
        ("mpm", ["linear", "shepard", "leapfrog"]),
        ("cpdi_mls", ["cpdi2", "mls_velocity", "leapfrog"]),
        ("imls", ["linear", "imls", "musl"]),
        ("bsmpm_tls", ["quadratic_bspline", "tls", "musl"]),
        ("ddmpm", ["dual_domain", "shepard", "musl"]),
        ("lme", ["lme", "shepard", "predictor_corrector"]),
    ];
    for (preset, [shape, transfer, integrator]) in cases {
        let gamma: Vec<(&str, ParamValue)> = if shape == "lme" {
            vec![(GAMMA_KEY, ParamValue::Float(1.8))]
        } else {
            Vec::new()
        };
        let mut parts = vec![
            ("shape", text(shape)),
            ("transfer", text(transfer)),
            ("integrator", text(integrator)),
        ];
        parts.extend(gamma.iter().cloned());
        let (own, composed) = (run(preset, &gamma), run(COMPOSED, &parts));
        assert_eq!(own.parts, composed.parts, "{preset}");
        assert!(numbers(&own) == numbers(&composed), "{preset}");
    }
}

const PARTS_AS_AXES: &str = "name: parts
benchmark: mms1d_gong
params: {G: 0.1, ppc: 2, cfl: 0.4, t_end: 0.02, cells: 16}
matrix:
  - {shape: [linear, cpdi2], transfer: [shepard, mls_velocity], integrator: [leapfrog]}
  - {method: [mpm], transfer: [mls_velocity]}
";

#[test]
fn parts_are_matrix_axes_with_or_without_a_preset() {
    let e = experiment::parse(PARTS_AS_AXES, Path::new("parts.yaml")).unwrap();
    let methods: Vec<&str> = e.runs.iter().map(|r| r.spec.method.as_str()).collect();
    assert_eq!(methods, [COMPOSED, COMPOSED, COMPOSED, COMPOSED, "mpm"]);
    let ids: Vec<&str> = e.runs.iter().map(|r| r.spec.run_id.as_str()).collect();
    assert!(
        ids[..4].iter().all(|id| id.starts_with("composed-")),
        "{ids:?}"
    );
    // The preset with its transfer replaced is the composition of the same parts.
    let linear_fitted = &e.runs[1];
    assert_eq!(
        (
            linear_fitted.spec.params.get("shape"),
            linear_fitted.spec.params.get("transfer")
        ),
        (Some(&text("linear")), Some(&text("mls_velocity")))
    );
    let (a, b) = (simulate(linear_fitted), simulate(&e.runs[4]));
    assert_eq!(a.status, RunStatus::Ok, "{}", a.message);
    assert!(numbers(&a) == numbers(&b));
}

#[test]
fn parts_that_cannot_run_together_are_refused_where_the_file_names_them() {
    let text = PARTS_AS_AXES.replace(
        "transfer: [shepard, mls_velocity]",
        "transfer: [shepard, imls]",
    );
    let e = experiment::parse(&text, Path::new("parts.yaml")).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (5, "matrix[0].shape[1]"), "{e}");
    assert!(
        e.message.contains(
            "the imls transfer cannot run on the cpdi2 shape function (its fits evaluate the \
             linear hat at their own quadrature points); it runs on linear"
        ),
        "{e}"
    );
    // Without a preset, all three parts are needed.
    let text = PARTS_AS_AXES.replace(", integrator: [leapfrog]", "");
    let e = experiment::parse(&text, Path::new("parts.yaml")).unwrap_err();
    assert!(
        e.message
            .contains("method composed needs shape, transfer, integrator: integrator is not set"),
        "{e}"
    );
    let alone = text.replace("  - {method: [mpm], transfer: [mls_velocity]}\n", "");
    let e = experiment::parse(&alone, Path::new("parts.yaml")).unwrap_err();
    assert!(e.message.contains("'method' is required"), "{e}");
}

/// experiments/component_matrix*.yaml run every combination of parts that `methods::resolve`
/// accepts, each once, and nothing else: a new part, or a rule that changes, fails here until
/// the component matrices follow it.
#[test]
fn the_component_matrices_run_every_valid_combination_once() {
    use mpmlab::integrate::INTEGRATOR_NAMES;
    use mpmlab::methods::{resolve, PRESETS, SHAPE_KEY, TRANSFER_KEY};
    use mpmlab::reconstruct::TRANSFER_NAMES;
    use mpmlab::shape::SHAPE_NAMES;
    use std::collections::BTreeSet;

    let composed = PRESETS.find(COMPOSED).unwrap();
    let mut valid = BTreeSet::new();
    for shape in SHAPE_NAMES {
        for transfer in TRANSFER_NAMES {
            for integrator in INTEGRATOR_NAMES {
                // The parts as a run of the component matrix on Gong's problem names them.
                let mut params = thesis_params(0.1, 16, 2);
                params.insert(SHAPE_KEY.into(), text(shape));
                params.insert(TRANSFER_KEY.into(), text(transfer));
                params.insert("integrator".into(), text(integrator));
                if shape == "lme" {
                    params.insert(GAMMA_KEY.into(), ParamValue::Float(1.8));
                }
                if resolve(composed, &params, 1).is_ok() {
                    valid.insert([shape, transfer, integrator].map(String::from));
                }
            }
        }
    }
    for file in [
        "experiments/component_matrix.yaml",
        "experiments/component_matrix_dyka.yaml",
    ] {
        let e = experiment::load(Path::new(file)).unwrap();
        let parts: Vec<[String; 3]> = e
            .runs
            .iter()
            .map(|r| {
                ["shape", "transfer", "integrator"].map(|k| match r.spec.params.get(k) {
                    Some(ParamValue::Str(s)) => s.clone(),
                    other => panic!("{file}: {}: {k} is {other:?}", r.spec.run_id),
                })
            })
            .collect();
        let ran: BTreeSet<[String; 3]> = parts.iter().cloned().collect();
        assert_eq!(ran.len(), parts.len(), "{file} runs a combination twice");
        let missing: Vec<_> = valid.difference(&ran).collect();
        let extra: Vec<_> = ran.difference(&valid).collect();
        assert!(
            missing.is_empty() && extra.is_empty(),
            "{file}: missing {missing:?}, not valid {extra:?}"
        );
    }
}
