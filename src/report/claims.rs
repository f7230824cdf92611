//! The papers' claims against our runs: each `paper_claims` entry's number beside what the
//! selected runs measure, and a verdict.

use super::figures::Figure;
use super::format::general;
use super::group::{label, ordered_runs, selects};
use super::RateRow;
use crate::experiment::{ClaimedValue, Experiment, PaperClaim};
use crate::output::{RunStatus, RunSummary};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Every measured value is within the tolerance of the paper's.
    Reproduced,
    /// Ours is outside, and docs/NOTES.md isolates why (`differs`).
    Differs,
    /// Ours is outside and nothing explains it.
    Unexplained,
    /// Ours is within the tolerance, yet the claim says it differs: the note is stale.
    Stale,
    /// No run measures it (none selected, none finished, no fitted rate).
    Unmeasured,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::Differs => "differs",
            Verdict::Unexplained => "differs, unexplained",
            Verdict::Stale => "reproduced, but marked as differing",
            Verdict::Unmeasured => "not measured",
        }
    }
}

/// One claim with what our runs measure for it: (which group or run, value).
pub struct Outcome<'a> {
    pub claim: &'a PaperClaim,
    pub ours: Vec<(String, f64)>,
    pub verdict: Verdict,
}

impl Outcome<'_> {
    /// The paper's number as printed in tables.
    pub fn paper_text(&self) -> String {
        match self.claim.value {
            ClaimedValue::Rate(r) => format!("rate {}", general(r, 3)),
            ClaimedValue::Error(e) => format!("error {}", general(e, 4)),
        }
    }

    /// Ours, each value after its group when there are several.
    pub fn ours_text(&self) -> String {
        let one = self.ours.len() == 1;
        let values: Vec<String> = self
            .ours
            .iter()
            .map(|(at, v)| match (one || at.is_empty(), self.claim.value) {
                (true, ClaimedValue::Rate(_)) => general(*v, 3),
                (true, ClaimedValue::Error(_)) => general(*v, 4),
                (false, _) => format!("{at}: {}", general(*v, 4)),
            })
            .collect();
        values.join("; ")
    }

    /// The row of a claims table (`COLUMNS`), with `figures` as its links.
    pub fn cells(&self, figures: String) -> Vec<String> {
        vec![
            self.claim.item.clone(),
            self.claim.claim.clone(),
            format!("{} {}", self.claim.field, self.claim.norm),
            self.paper_text(),
            self.ours_text(),
            self.tolerance_text(),
            self.verdict.as_str().to_string(),
            figures,
            self.claim.differs.clone().unwrap_or_default(),
        ]
    }

    pub fn tolerance_text(&self) -> String {
        match self.claim.value {
            ClaimedValue::Rate(_) => format!("± {}", general(self.claim.tolerance, 3)),
            ClaimedValue::Error(_) => format!("± {} %", general(100.0 * self.claim.tolerance, 3)),
        }
    }
}

/// The header of a claims table.
pub const COLUMNS: [&str; 9] = [
    "item",
    "claim",
    "field",
    "paper",
    "ours",
    "tolerance",
    "verdict",
    "figures",
    "why it differs",
];

pub fn evaluate<'a>(
    experiment: &'a Experiment,
    rates: &[RateRow],
    runs: &[RunSummary],
) -> Vec<Outcome<'a>> {
    experiment
        .paper_claims
        .iter()
        .map(|claim| {
            let ours = measured(claim, rates, runs);
            let within = |v: f64| match claim.value {
                ClaimedValue::Rate(r) => (v - r).abs() <= claim.tolerance,
                ClaimedValue::Error(e) => (v / e - 1.0).abs() <= claim.tolerance,
            };
            let reproduced = ours.iter().all(|&(_, v)| within(v));
            let verdict = match (ours.is_empty(), reproduced, claim.differs.is_some()) {
                (true, _, _) => Verdict::Unmeasured,
                (false, true, false) => Verdict::Reproduced,
                (false, true, true) => Verdict::Stale,
                (false, false, true) => Verdict::Differs,
                (false, false, false) => Verdict::Unexplained,
            };
            Outcome {
                claim,
                ours,
                verdict,
            }
        })
        .collect()
}

/// The fitted rates of the selected groups, or the final errors of the selected runs that
/// finished.
fn measured(claim: &PaperClaim, rates: &[RateRow], runs: &[RunSummary]) -> Vec<(String, f64)> {
    match claim.value {
        ClaimedValue::Rate(_) => rates
            .iter()
            .filter(|r| r.field == claim.field && r.norm == claim.norm)
            .filter(|r| selects(&claim.select, &r.group_axes))
            .map(|r| (r.group.clone(), r.rate))
            .collect(),
        ClaimedValue::Error(_) => ordered_runs(runs)
            .into_iter()
            .filter(|run| run.status == RunStatus::Ok && selects(&claim.select, &run.axes))
            .filter_map(|run| {
                let key = (claim.field.clone(), claim.norm.clone());
                Some((label(&run.axes), *run.final_norms.get(&key)?))
            })
            .collect(),
    }
}

/// The figures the claim's `figure` item drew of the runs the claim selects: those whose
/// variant values its selectors allow.
pub fn claim_figures<'a>(
    outcome: &'a Outcome,
    figures: &'a [Figure],
) -> impl Iterator<Item = &'a Figure> + 'a {
    let claim = outcome.claim;
    let name = claim.figure.as_deref();
    let allows = move |(axis, value): &(String, String)| {
        claim
            .select
            .get(axis)
            .is_none_or(|allowed| allowed.values().iter().any(|v| v.to_string() == *value))
    };
    figures.iter().filter(move |f| {
        name.is_some() && f.drawn_by.as_deref() == name && f.variant.iter().all(allows)
    })
}
