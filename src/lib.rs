//! mpmlab: a research pipeline for the Material Point Method.
//!
//! Layers, top to bottom: `experiment` (YAML, matrix), `runner` (runs a matrix in parallel),
//! `output` (HDF5 layout), `report` (rates, tables, figures), `solver` (the step loop),
//! `benchmarks`, `shape`, `reconstruct`, `integrate`, `material`.

pub mod benchmarks;
pub mod experiment;
pub mod material;
pub mod methods;
pub mod params;
pub mod output;
pub mod report;
