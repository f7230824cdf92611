//! Splits the runs of one or more experiments into `N` shards of about equal cost, so that
//! `N` machines (or the tasks of a Slurm array) can each run one shard into the same results
//! directory without talking to each other.
//!
//! The split is a deterministic greedy (longest processing time first): the runs of all the
//! experiments together, each weighed by `runner::estimated_cost`, are taken largest cost
//! first (ties by experiment name, then run id) and each goes to the shard with the least
//! cost so far (ties to the lowest shard). It depends only on the runs' resolved parameters
//! and `N`, never on the machine, the order of the files or which runs are already done, so
//! every shard computes the same split on its own.

use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap};
use std::fmt;
use std::path::Path;
use std::str::FromStr;

use crate::experiment::Experiment;
use crate::output::run_path;
use crate::runner::{estimated_cost, results_dir};

/// Shard `index` of `count`, numbered from 1 (`--shard K/N`, 1 <= K <= N).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("'{s}': expected K/N with 1 <= K <= N, e.g. 2/8");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// One shard's share: its number of runs and their summed estimated cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Load {
    pub runs: usize,
    pub cost: u64,
}

/// The split of a set of experiments into shards.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Shard (1-based) of each run, by (experiment name, run id).
    assignment: BTreeMap<(String, String), usize>,
    /// What each shard got; `loads[k - 1]` is shard k.
    pub loads: Vec<Load>,
}

impl Plan {
    /// Splits the runs of `experiments` into `count` shards (`count` >= 1). A run that two
    /// experiments of the same name both list is counted once.
    pub fn new(experiments: &[Experiment], count: usize) -> Plan {
        assert!(count >= 1, "a split needs at least one shard");
        let mut costs = BTreeMap::new();
        for experiment in experiments {
            for run in &experiment.runs {
                costs
                    .entry((experiment.name.clone(), run.spec.run_id.clone()))
                    .or_insert_with(|| estimated_cost(run));
            }
        }
        let mut order: Vec<(&(String, String), u64)> =
            costs.iter().map(|(key, &cost)| (key, cost)).collect();
        // Largest first; the map's order (experiment, run id) breaks ties, and the sort is
        // stable.
        order.sort_by_key(|&(_, cost)| Reverse(cost));
        let mut loads = vec![Load::default(); count];
        let mut assignment = BTreeMap::new();
        // The least-loaded shard on top; among equal loads the lowest index.
        let mut heap: BinaryHeap<Reverse<(u64, usize)>> =
            (0..count).map(|k| Reverse((0, k))).collect();
        for (key, cost) in order {
            let Reverse((total, k)) = heap.pop().expect("count >= 1");
            let total = total.saturating_add(cost);
            loads[k].runs += 1;
            loads[k].cost = total;
            heap.push(Reverse((total, k)));
            assignment.insert(key.clone(), k + 1);
        }
        Plan { assignment, loads }
    }

    pub fn count(&self) -> usize {
        self.loads.len()
    }

    /// The shard (1-based) a run of the planned experiments belongs to.
    pub fn shard_of(&self, experiment: &str, run_id: &str) -> Option<usize> {
        self.assignment
            .get(&(experiment.to_string(), run_id.to_string()))
            .copied()
    }

    /// The experiment with only the runs of shard `index` (its other fields unchanged, so the
    /// copy of the experiment file written beside the runs is the same in every shard).
    pub fn select(&self, experiment: &Experiment, index: usize) -> Experiment {
        let mut part = experiment.clone();
        part.runs
            .retain(|run| self.shard_of(&experiment.name, &run.spec.run_id) == Some(index));
        part
    }

    /// (shard, experiment, run id) of each run of `experiments` that has no file under `out`
    /// yet, sorted by shard.
    pub fn missing(&self, experiments: &[Experiment], out: &Path) -> Vec<(usize, String, String)> {
        let mut missing = Vec::new();
        for experiment in experiments {
            let dir = results_dir(out, experiment);
            for run in &experiment.runs {
                if !run_path(&dir, &run.spec.run_id).exists() {
                    let shard = self
                        .shard_of(&experiment.name, &run.spec.run_id)
                        .unwrap_or(0);
                    missing.push((shard, experiment.name.clone(), run.spec.run_id.clone()));
                }
            }
        }
        missing.sort();
        missing
    }

    /// Estimated cost of the costliest shard over the mean shard cost (1 = perfectly even).
    pub fn imbalance(&self) -> f64 {
        let total: u64 = self.loads.iter().map(|l| l.cost).sum();
        let max = self.loads.iter().map(|l| l.cost).max().unwrap_or(0);
        if total == 0 {
            return 1.0;
        }
        max as f64 * self.count() as f64 / total as f64
    }

    /// One line per shard (`shard 3/8: 70 runs, estimated cost 1.2e9`), then the imbalance.
    pub fn describe(&self) -> Vec<String> {
        let n = self.count();
        let mut lines: Vec<String> = self
            .loads
            .iter()
            .enumerate()
            .map(|(k, load)| {
                format!(
                    "shard {}/{n}: {} runs, estimated cost {:.3e} particle-steps",
                    k + 1,
                    load.runs,
                    load.cost as f64
                )
            })
            .collect();
        lines.push(format!(
            "longest shard / mean shard (estimated cost): {:.3}",
            self.imbalance()
        ));
        lines
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_k_of_n() {
        assert_eq!(
            "2/8".parse::<Shard>().unwrap(),
            Shard { index: 2, count: 8 }
        );
        assert_eq!("1/1".parse::<Shard>().unwrap().to_string(), "1/1");
        for bad in ["0/4", "5/4", "2", "a/4", "2/", "/3", "1/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
