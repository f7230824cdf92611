//! Stability limits measured from a sweep, and the report table of them beside the bounds
//! of `linear_stability`.
//!
//! Criterion: a run is *unstable* when it diverged (a non-finite state, J <= 0 or a particle
//! leaving the grid stops it with `status = diverged`), or when its l2 velocity error at some
//! sample exceeds the l2 norm of the velocity at t = 0, where the particles carry the exact
//! initial velocity: the error has grown as large as the solution (for the standing waves of
//! the manufactured benchmarks the exact velocity norm is largest at t = 0). A finished run
//! whose error stayed below that is *stable*; a failed run, or one without samples, is
//! neither. Along the swept axis the limit lies between the last stable value below the
//! first unstable one and that first unstable value.

use super::format::general;
use super::group::{group_runs, label, label_or_all, scoped_label, title_suffix};
use super::table::Table;
use crate::experiment::{StabilityAxes, TableSpec};
use crate::linear_stability::{
    printed_bound, projected_bound, projected_bound_fixed_ends, squared_bound,
};
use crate::output::{RunStatus, RunSummary};
use crate::params::{ParamValue, Params};

/// The error, relative to the solution, above which a run counts as unstable.
pub const THRESHOLD: f64 = 1.0;

/// The axis whose values the predicted bounds are functions of.
pub const PPC_AXIS: &str = "ppc";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Stable,
    Unstable,
}

/// One run of a sweep.
#[derive(Clone, Debug)]
pub struct Point<'a> {
    pub run: &'a RunSummary,
    /// The run's value of the swept axis.
    pub value: f64,
    pub verdict: Verdict,
    /// Largest l2 velocity error over the l2 velocity at t = 0 (infinite for a non-finite
    /// error, NaN when the run has no samples).
    pub peak: f64,
}

/// The runs of one group along the swept axis, in increasing order of it.
#[derive(Clone, Debug)]
pub struct Limit<'a> {
    /// The group's other axes.
    pub axes: Params,
    pub points: Vec<Point<'a>>,
}

impl<'a> Limit<'a> {
    pub fn first_unstable(&self) -> Option<&Point<'a>> {
        self.points.iter().find(|p| p.verdict == Verdict::Unstable)
    }

    /// The last stable value below the first unstable one (the last stable value at all when
    /// no run is unstable).
    pub fn last_stable(&self) -> Option<&Point<'a>> {
        let below = self.first_unstable().map_or(f64::INFINITY, |u| u.value);
        self.points
            .iter()
            .rev()
            .find(|p| p.verdict == Verdict::Stable && p.value < below)
    }

    /// Stable runs above the first unstable value: a limit that is not sharp.
    pub fn stable_above(&self) -> impl Iterator<Item = &Point<'a>> {
        let from = self.first_unstable().map_or(f64::INFINITY, |u| u.value);
        self.points
            .iter()
            .filter(move |p| p.verdict == Verdict::Stable && p.value > from)
    }

    /// The two runs that bracket the limit, the stable one first.
    pub fn bracket(&self) -> impl Iterator<Item = &Point<'a>> {
        self.last_stable().into_iter().chain(self.first_unstable())
    }
}

/// The peak error relative to the solution and what it makes of the run; `None` for a run
/// that cannot be judged (failed, or no samples).
pub fn verdict(run: &RunSummary) -> Option<(Verdict, f64)> {
    let peak = run.velocity_history.as_ref().map_or(f64::NAN, |h| {
        let largest = h
            .l2_error
            .iter()
            .map(|&e| if e.is_finite() { e } else { f64::INFINITY })
            .fold(0.0, f64::max);
        largest / h.initial_l2
    });
    match run.status {
        RunStatus::Failed => None,
        RunStatus::Diverged => Some((Verdict::Unstable, peak)),
        RunStatus::Ok if peak > THRESHOLD => Some((Verdict::Unstable, peak)),
        RunStatus::Ok if peak <= THRESHOLD => Some((Verdict::Stable, peak)),
        // No samples, or a solution of zero size.
        RunStatus::Ok => None,
    }
}

/// One `Limit` per group of the axes other than `sweep`, ordered as `group_runs` orders
/// groups; runs that cannot be judged are left out.
pub fn limits<'a>(runs: impl IntoIterator<Item = &'a RunSummary>, sweep: &str) -> Vec<Limit<'a>> {
    group_runs(runs, &[sweep])
        .into_iter()
        .map(|group| {
            let mut points: Vec<Point<'a>> = group
                .runs
                .iter()
                .filter_map(|&run| {
                    let value = run.axes.get(sweep)?.as_f64()?;
                    let (verdict, peak) = verdict(run)?;
                    Some(Point {
                        run,
                        value,
                        verdict,
                        peak,
                    })
                })
                .collect();
            points.sort_by(|a, b| a.value.total_cmp(&b.value));
            Limit {
                axes: group.axes,
                points,
            }
        })
        .collect()
}

/// How a run of the bracket ended: its peak error relative to the solution, and for a
/// diverged run after how many steps.
pub fn outcome(point: &Point) -> String {
    let peak = format!("error/solution {}", general(point.peak, 3));
    match point.run.status {
        RunStatus::Diverged => format!("{peak}, diverged after {} steps", point.run.steps),
        _ => peak,
    }
}

/// The column of `projected_bound_fixed_ends` on the runs' grid.
const FIXED_ENDS: &str = "with velocity projection, this grid (fixed ends)";

/// The predicted bounds of `linear_stability` at `n` particles per cell: eq 7.31 as printed,
/// eq 7.29 with sin^2 kept, and with the grid velocity rebuilt from the particles.
pub fn predicted(n: usize) -> [(&'static str, f64); 3] {
    [
        ("eq 7.31 as printed", printed_bound(n)),
        ("eq 7.29 with sin^2 kept", squared_bound(n)),
        ("with velocity projection", projected_bound(n)),
    ]
}

/// A value of the `ppc` axis as a count of particles per cell.
pub fn particles_per_cell(value: &ParamValue) -> Option<usize> {
    let n = usize::try_from(value.as_i64()?).ok()?;
    (n >= 1).then_some(n)
}

/// One table per group of the axes other than `x` and `sweep`, one row per value of `x`.
pub fn tables<'a>(runs: impl IntoIterator<Item = &'a RunSummary>, spec: &TableSpec) -> Vec<Table> {
    let Some(StabilityAxes { sweep, x: Some(x) }) = &spec.stability else {
        return Vec::new();
    };
    let with_bounds = x == PPC_AXIS;
    group_runs(runs, &[x, sweep])
        .into_iter()
        .filter_map(|group| {
            let rows: Vec<Vec<String>> = limits(group.runs.iter().copied(), sweep)
                .iter()
                .filter_map(|limit| row(limit, x, with_bounds))
                .collect();
            if rows.is_empty() {
                return None;
            }
            let mut header = vec![
                x.clone(),
                format!("last stable {sweep}"),
                format!("first unstable {sweep}"),
                "last stable run".into(),
                "first unstable run".into(),
            ];
            if with_bounds {
                header.extend(predicted(1).map(|(name, _)| name.to_string()));
                header.push(FIXED_ENDS.into());
            }
            header.push("remarks".into());
            Some(Table {
                title: format!(
                    "Stability limit along {sweep}{}",
                    title_suffix(&scoped_label(&group.axes, &spec.select))
                ),
                note: note(with_bounds),
                header,
                rows,
            })
        })
        .collect()
}

fn row(limit: &Limit, x: &str, with_bounds: bool) -> Option<Vec<String>> {
    let x_value = limit.axes.get(x)?;
    let value = |p: Option<&Point>| p.map_or_else(|| "none".to_string(), |p| general(p.value, 6));
    let run = |p: Option<&Point>| p.map_or_else(String::new, outcome);
    let mut row = vec![
        x_value.to_string(),
        value(limit.last_stable()),
        value(limit.first_unstable()),
        run(limit.last_stable()),
        run(limit.first_unstable()),
    ];
    if with_bounds {
        let cells = limit.points.first().map_or(0, |p| p.run.cells);
        match particles_per_cell(x_value).filter(|_| cells > 0) {
            Some(n) => {
                row.extend(predicted(n).map(|(_, bound)| format!("{bound:.4}")));
                row.push(format!("{:.4}", projected_bound_fixed_ends(n, cells)));
            }
            None => row.extend(["", "", "", ""].map(String::from)),
        }
    }
    let again: Vec<String> = limit.stable_above().map(|p| general(p.value, 6)).collect();
    row.push(if again.is_empty() {
        String::new()
    } else {
        format!("stable again at {}", again.join(", "))
    });
    Some(row)
}

fn note(with_bounds: bool) -> String {
    let mut note = format!(
        "A run is unstable when it diverged (non-finite state, J <= 0 or a particle leaving \
         the grid) or when its l2 velocity error at some sample exceeds {THRESHOLD} times the \
         l2 norm of the velocity at t = 0 (the exact initial velocity): the error has grown as \
         large as the solution. The limit lies between the last stable value and the first \
         unstable one; error/solution is the largest ratio over the run."
    );
    if with_bounds {
        note.push_str(
            " The predicted bounds (docs/NOTES.md, Gong chapter 7) are Courant numbers \
             c dt / h for the wave speed c of the linearised equations, the cfl of a 1D Gong \
             run with nu = 0. The first three are for an unbounded grid; the last is the \
             bound with velocity projection for the highest mode of the runs' grid with both \
             ends fixed.",
        );
    }
    note
}

/// `key=value` of the group, or `all` when the group has no axes: for titles and file names.
pub fn group_name(axes: &Params) -> String {
    label_or_all(&label(axes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::{Unstepped, VelocityHistory};
    use std::collections::BTreeMap;

    fn run(cfl: f64, status: RunStatus, errors: &[f64]) -> RunSummary {
        RunSummary {
            run_id: format!("mpm-cfl{cfl}"),
            experiment: "s".into(),
            benchmark: "mms1d_gong".into(),
            method: "mpm".into(),
            dim: 1,
            cells: 32,
            ppc: 1,
            h: 1.0 / 32.0,
            dt: 1e-4,
            steps: 100,
            status,
            message: String::new(),
            wall_seconds: 0.0,
            step_seconds: f64::NAN,
            axes: Params::from([("cfl".to_string(), ParamValue::Float(cfl))]),
            final_norms: BTreeMap::new(),
            unstepped: Unstepped::None,
            velocity_history: Some(VelocityHistory {
                time: (0..errors.len()).map(|k| k as f64).collect(),
                l2_error: errors.to_vec(),
                initial_l2: 2.0,
            }),
            max_mass_error: f64::NAN,
            max_momentum_error: f64::NAN,
            profile: None,
            probes: Vec::new(),
            final_state: None,
        }
    }

    #[test]
    fn verdicts_follow_the_error_against_the_solution() {
        let stable = run(0.5, RunStatus::Ok, &[0.0, 0.1, 2.0]);
        assert_eq!(verdict(&stable), Some((Verdict::Stable, 1.0)));
        let grown = run(0.6, RunStatus::Ok, &[0.0, 0.1, 2.5]);
        assert_eq!(verdict(&grown), Some((Verdict::Unstable, 1.25)));
        let nan = run(0.6, RunStatus::Ok, &[0.0, f64::NAN]);
        assert_eq!(verdict(&nan).unwrap().0, Verdict::Unstable);
        let diverged = run(0.7, RunStatus::Diverged, &[0.0, 0.1]);
        assert_eq!(verdict(&diverged), Some((Verdict::Unstable, 0.05)));
        assert_eq!(verdict(&run(0.7, RunStatus::Failed, &[])), None);
        let mut empty = run(0.7, RunStatus::Ok, &[]);
        empty.velocity_history = None;
        assert_eq!(verdict(&empty), None);
    }

    #[test]
    fn the_limit_brackets_the_first_unstable_value() {
        let runs = [
            run(0.8, RunStatus::Diverged, &[0.0]),
            run(0.6, RunStatus::Ok, &[0.0, 0.1]),
            run(0.7, RunStatus::Ok, &[0.0, 30.0]),
            run(0.65, RunStatus::Ok, &[0.0, 0.1]),
            run(0.75, RunStatus::Ok, &[0.0, 0.1]),
        ];
        let limits = limits(&runs, "cfl");
        assert_eq!(limits.len(), 1);
        let limit = &limits[0];
        assert_eq!(limit.last_stable().unwrap().value, 0.65);
        assert_eq!(limit.first_unstable().unwrap().value, 0.7);
        let again: Vec<f64> = limit.stable_above().map(|p| p.value).collect();
        assert_eq!(again, [0.75]);
        let bracket: Vec<f64> = limit.bracket().map(|p| p.value).collect();
        assert_eq!(bracket, [0.65, 0.7]);
        assert!(limit.axes.is_empty());
        assert_eq!(group_name(&limit.axes), "all");

        let stable_only = limits_of(&runs[1..2]);
        assert_eq!(stable_only.last_stable().unwrap().value, 0.6);
        assert!(stable_only.first_unstable().is_none());
    }

    fn limits_of(runs: &[RunSummary]) -> Limit<'_> {
        limits(runs, "cfl").remove(0)
    }
}
