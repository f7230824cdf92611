//! mpmlab: a research pipeline for the Material Point Method.
//!
//! The modules form layers, each importing only from those below it: `docs/ARCHITECTURE.md`
//! orders them, and `tests/layers.rs` holds the code to that order.

pub mod benchmarks;
pub mod catalog;
pub mod collect;
pub mod divergence;
pub mod experiment;
pub mod fallible;
pub mod gauss;
pub mod grid;
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
pub mod run_spec;
pub mod runner;
pub mod shape;
pub mod shape_methods;
pub mod shard;
pub mod slurm;
pub mod solver;
