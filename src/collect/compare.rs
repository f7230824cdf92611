//! Relative errors against the experiment's reference run: each run's field at its particles
//! compared with the reference field interpolated in the reference coordinate X, piecewise
//! linearly through the reference's points (element centroids for ULFEM) and extended
//! linearly beyond the first and last of them.

use crate::output::{ParticleState, RunStatus, RunSummary, ERROR_FIELDS, REFERENCE_NORM};
use crate::params::Params;

/// Sets every run's `reference` norm of each field: sqrt(sum_p V_p (f_p - f_ref(X_p))^2) /
/// sqrt(sum_p V_p f_ref(X_p)^2) with the run's current volumes V_p; NaN when either run did
/// not finish. The reference run itself gets 0.
pub fn attach_reference_errors(select: &Params, runs: &mut [RunSummary]) {
    let is_reference = |run: &RunSummary| select.iter().all(|(k, v)| run.axes.get(k) == Some(v));
    let reference = runs
        .iter()
        .find(|run| is_reference(run))
        .filter(|run| run.status == RunStatus::Ok)
        .and_then(|run| run.profile.clone());
    for run in runs.iter_mut() {
        let itself = is_reference(run);
        for field in ERROR_FIELDS {
            let error = match (&reference, &run.profile) {
                // Exactly zero, not the round-off of interpolating at its own points, so that
                // rate fits (which need a positive error) leave it out.
                (Some(_), _) if itself => 0.0,
                (Some(reference), Some(profile)) if run.status == RunStatus::Ok => {
                    relative_error(profile, reference, field)
                }
                _ => f64::NAN,
            };
            run.final_norms
                .insert((field.to_string(), REFERENCE_NORM.to_string()), error);
        }
    }
}

fn relative_error(run: &ParticleState, reference: &ParticleState, field: &str) -> f64 {
    let values = run.field(field);
    let table = Interpolant::new(&reference.x0, &reference.field(field));
    let (mut difference, mut size) = (0.0, 0.0);
    for ((&x0, &value), &volume) in run.x0.iter().zip(&values).zip(&run.volume) {
        let exact = table.at(x0);
        difference += volume * (value - exact) * (value - exact);
        size += volume * exact * exact;
    }
    (difference / size).sqrt()
}

/// Piecewise-linear interpolation through points sorted by abscissa.
pub struct Interpolant {
    points: Vec<(f64, f64)>,
}

impl Interpolant {
    pub fn new(x: &[f64], y: &[f64]) -> Self {
        let mut points: Vec<(f64, f64)> = x.iter().copied().zip(y.iter().copied()).collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        Interpolant { points }
    }

    /// The value at `x`; outside the points, the line through the two nearest.
    pub fn at(&self, x: f64) -> f64 {
        let n = self.points.len();
        if n == 1 {
            return self.points[0].1;
        }
        let upper = self.points.partition_point(|p| p.0 < x).clamp(1, n - 1);
        let ((x0, y0), (x1, y1)) = (self.points[upper - 1], self.points[upper]);
        y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_extends_linearly() {
        let t = Interpolant::new(&[0.75, 0.25], &[3.0, 1.0]);
        assert_eq!(t.at(0.5), 2.0);
        assert_eq!(t.at(0.0), 0.0);
        assert_eq!(t.at(1.0), 4.0);
    }

    fn profile(x0: &[f64], stress: &[f64]) -> ParticleState {
        ParticleState {
            dim: 1,
            time: 1.0,
            x0: x0.to_vec(),
            x: x0.to_vec(),
            velocity: vec![0.0; x0.len()],
            stress: stress.to_vec(),
            density: vec![1.0; x0.len()],
            volume: vec![1.0 / x0.len() as f64; x0.len()],
        }
    }

    #[test]
    fn relative_error_of_a_linear_field_on_another_mesh() {
        let reference = profile(&[0.125, 0.375, 0.625, 0.875], &[1.0, 3.0, 5.0, 7.0]);
        // sigma = 8 X: exact through the reference, so only the perturbation counts.
        let run = profile(&[0.25, 0.75], &[2.0 * 1.1, 6.0]);
        let expected = (0.5_f64 * 0.2 * 0.2 / (0.5 * (4.0 + 36.0))).sqrt();
        assert!((relative_error(&run, &reference, "stress") - expected).abs() < 1e-15);
    }
}
