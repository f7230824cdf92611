//! Order in time of the integrators on a smooth problem: the small-strain vibrating bar on a
//! fixed grid and particle set (10 cells, 4 points per cell; the particles move 0.15 mm and
//! never leave their cells), stepped with dt, dt/2, dt/4 and dt/8. The spatial error is the
//! same in every run, so the differences between successive runs are the time-stepping error
//! alone, and their ratio gives its order.
//!
//! The amplitude is small (v0 / c = 5e-4) because every integrator evaluates grad N at the
//! start-of-step positions, an O(dt) error relative to the solution of size v0 / c.
//! The leapfrog (`mpm`'s integrator) is left out: it converges at first order in velocity
//! here (docs/NOTES.md).

use std::path::Path;

use mpmlab::experiment;

use mpmlab::experiment::ResolvedRun;
use mpmlab::output::{RunRecord, RunStatus};
use mpmlab::solver::simulate;

/// Time steps from Courant number 0.24 down to 0.03 (c = 59.2 m/s, h = 0.1 m); 0.05 s is
/// one and a half periods of the bar.
const MATRIX: &str = "\
name: time_order
benchmark: vibrating_bar
params: {H: 1.0, rho0: 2.0e3, E: 7.0e6, v0: 0.028, t_end: 0.05, exact: small_strain, ppc: 4, cells: 10}
matrix:
  - {method: [mpm], dt: [4.0e-4, 2.0e-4, 1.0e-4, 5.0e-5],
     integrator: [predictor_corrector, leapfrog, euler, euler_corrected]}
  - {method: [lme], gamma: [1.5], dt: [4.0e-4, 2.0e-4, 1.0e-4, 5.0e-5],
     integrator: [predictor_corrector]}
";

/// Positions, velocities and stresses of every particle at the last sample.
fn last_sample(record: &RunRecord) -> [Vec<f64>; 3] {
    assert_eq!(record.status, RunStatus::Ok, "{}", record.message);
    let h = &record.history;
    let np = record.particles.len();
    let last = |values: &[f64]| values[values.len() - np..].to_vec();
    [last(&h.x), last(&h.v), last(&h.stress)]
}

/// The last samples of the runs of `method` with `integrator`, coarsest time step first.
fn final_states(method: &str, integrator: &str) -> Vec<[Vec<f64>; 3]> {
    let exp = experiment::parse(MATRIX, Path::new("time_order.yaml")).unwrap();
    let dt = |r: &ResolvedRun| r.spec.params["dt"].as_f64().unwrap();
    let mut runs: Vec<&ResolvedRun> = exp
        .runs
        .iter()
        .filter(|r| {
            r.spec.method == method && r.spec.params["integrator"].as_str() == Some(integrator)
        })
        .collect();
    runs.sort_by(|a, b| dt(b).total_cmp(&dt(a)));
    assert_eq!(runs.len(), 4, "{method} with {integrator}");
    runs.into_iter()
        .map(|spec| last_sample(&simulate(spec)))
        .collect()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// log2 of the ratio of successive differences, for position, velocity and stress: the
/// observed orders between dt/2 -> dt/4 and dt/4 -> dt/8.
fn orders(method: &str, integrator: &str) -> Vec<[f64; 3]> {
    let states = final_states(method, integrator);
    let differences: Vec<[f64; 3]> = states
        .windows(2)
        .map(|w| std::array::from_fn(|f| distance(&w[0][f], &w[1][f])))
        .collect();
    differences
        .windows(2)
        .map(|w| std::array::from_fn(|f| (w[0][f] / w[1][f]).log2()))
        .collect()
}

/// Checks the orders of the first `fields` of position, velocity and stress.
fn assert_orders_within(method: &str, integrator: &str, fields: usize, low: f64, high: f64) {
    let names = ["position", "velocity", "stress"];
    for order in orders(method, integrator) {
        for (field, p) in names.iter().zip(order).take(fields) {
            assert!(
                (low..=high).contains(&p),
                "{method} with {integrator}: {field} converges at order {p} in time, not in \
                 [{low}, {high}]"
            );
        }
    }
}

/// The authors' predictor-corrector damps every mode by (w dt)^2 / 4 per step (the
/// one-oscillator test in `integrate::predictor_corrector`): first order in position,
/// velocity and stress (0.90-0.97 in position and velocity, approaching 1 from below, and
/// 0.98-1.04 in stress over these pairs).
#[test]
fn predictor_corrector_is_first_order_in_time() {
    assert_orders_within("mpm", "predictor_corrector", 3, 0.88, 1.1);
    assert_orders_within("lme", "predictor_corrector", 3, 0.88, 1.1);
}

/// Eqs 21-24 advance the particles with the start-of-step nodal velocity and their velocities
/// with the start-of-step acceleration: first order in both.
#[test]
fn forward_euler_updates_are_first_order_in_time() {
    assert_orders_within("mpm", "euler", 2, 0.9, 1.1);
    assert_orders_within("mpm", "euler_corrected", 2, 0.9, 1.1);
}
