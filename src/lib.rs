//! mpmlab: a research pipeline for the Material Point Method.
//!
//! Layers, top to bottom: `slurm` (a matrix as a Slurm job array), `shard` (splits a matrix
//! for several machines), `experiment` (YAML, matrix), `runner` (runs a matrix in parallel),
//! `output` (HDF5 layout), `report` (rates, tables, figures), `solver` (one run),
//! `benchmarks`, `integrate`, `reconstruct`, `shape`, `material`. `linear_stability` holds
//! the predicted stability bounds that `report` draws beside measured ones.

pub mod benchmarks;
pub mod collect;

pub mod experiment;
pub mod fallible;
pub mod integrate;
pub mod linear_stability;
pub mod material;
pub mod methods;
pub mod output;
pub mod parallel;
pub mod params;
pub mod particles;
pub mod reconstruct;
pub mod reconstruction_methods;
pub mod reference;
pub mod report;
pub mod rng;
pub mod runner;
pub mod shape;
pub mod shape_methods;
pub mod shard;
pub mod slurm;
pub mod solver;
