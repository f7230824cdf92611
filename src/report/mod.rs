//! Reports over a results directory: summary.csv, rates.csv, figures and report.md, and
//! the `--check` of an experiment's expectations.
