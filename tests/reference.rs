//! The ULFEM reference solver on the small-strain vibrating bar converges to eq 15 at second
//! order in the l2 norm of displacement, velocity and stress, through the normal run path.

use mpmlab::experiment;
use mpmlab::output::{RunRecord, RunStatus};
use mpmlab::solver::simulate;

/// A small amplitude (strain about 1e-6) so that the difference between the rate law on the
/// current length and the small-strain eq 15 (relative size strain / 2) stays far below the
/// spatial error, and a time step so short that the spatial error dominates.
const MATRIX: &str = "\
name: ulfem_convergence
benchmark: vibrating_bar
params: {method: ulfem, v0: 2.8e-4, dt: 2.0e-6, t_end: 2.0e-3}
matrix:
  cells: [10, 20, 40, 80]
";

fn final_l2(record: &RunRecord, field: usize) -> f64 {
    *record.errors.l2[field].last().unwrap()
}

#[test]
fn ulfem_converges_at_second_order_on_the_small_strain_bar() {
    let e = experiment::parse(MATRIX, "ulfem_convergence.yaml".as_ref()).unwrap();
    let records: Vec<RunRecord> = e.runs.iter().map(simulate).collect();
    for r in &records {
        assert_eq!(r.status, RunStatus::Ok, "{}", r.message);
        assert_eq!(r.particles.len(), r.cells, "one point per element");
    }
    for (field, name) in ["displacement", "velocity", "stress"].iter().enumerate() {
        let errors: Vec<f64> = records.iter().map(|r| final_l2(r, field)).collect();
        let rates: Vec<f64> = errors.windows(2).map(|p| (p[0] / p[1]).log2()).collect();
        eprintln!("{name}: l2 errors {errors:?}, rates {rates:?}");
        for &rate in &rates {
            assert!(
                (1.9..2.1).contains(&rate),
                "{name}: observed rate {rate} between successive meshes, errors {errors:?}"
            );
        }
    }
}

#[test]
fn ulfem_is_refused_on_other_benchmarks() {
    let text = "name: x\nbenchmark: mms1d_tran\nparams: {method: ulfem, ppc: 2, cells: 8}\n";
    let e = experiment::parse(text, "x.yaml".as_ref()).unwrap_err();
    assert_eq!(e.field, "params.method");
    assert!(e.message.contains("vibrating_bar only"), "{e}");
    assert!(e.valid.contains(&"mpm".to_string()) && !e.valid.contains(&"ulfem".to_string()));
}
