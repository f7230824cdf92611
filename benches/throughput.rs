//! Particle-steps per second of each method on the manufactured solutions and a large-strain
//! bar, one core, with each run's wall time relative to `mpm`'s on the same case, timed
//! alternately with it, and, on the 2D case, the cost each method should come within; and the
//! cost of one LME evaluation (its Newton solve) against the hat's.
//! Beside the times, each run's peak heap per particle (a counting allocator: what the run
//! allocates above what was live when it started, over its particles).
//! Run with `cargo bench --bench throughput` (or `make bench`); a bare word filters by method
//! (`mpm` is timed in any case, as the reference of the ratios).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use nalgebra::SVector;

use mpmlab::benchmarks::{self, thesis_params};

use mpmlab::experiment::ResolvedRun;
use mpmlab::grid::{Domain, Grid};
use mpmlab::integrate::INTEGRATOR_NAMES;
use mpmlab::methods::{self, GAMMA_KEY, INTEGRATOR_KEY};
use mpmlab::output::RunStatus;
use mpmlab::params::{ParamValue, Params};
use mpmlab::rng::Lcg;
use mpmlab::run_spec::RunSpec;
use mpmlab::shape::{LinearHat, LocalMaxEnt, Shape, ShapeKind, Stencils};
use mpmlab::solver::simulate;

/// The system allocator, counting the bytes live and their peak since the last `reset`.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let ptr = System.alloc(layout);
        if !ptr.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        ptr
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout);
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Peak heap bytes of `f` above what was live when it started.
fn peak_bytes<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let start = LIVE.load(Ordering::Relaxed);
    PEAK.store(start, Ordering::Relaxed);
    let out = f();
    (out, PEAK.load(Ordering::Relaxed) - start)
}

struct Case {
    benchmark: &'static str,
    params: fn() -> Params,
}

const CASES: &[Case] = &[
    Case {
        benchmark: "mms1d_gong",
        params: || manufactured(1024, 4, 0.01),
    },
    Case {
        benchmark: "mms2d_gong",
        params: || manufactured(64, 2, 0.005),
    },
    Case {
        benchmark: "vibrating_bar",
        params: large_strain_bar,
    },
];

/// Gong's problem at small deformation (G = 1e-4), cfl 0.2, to `t_end`: the cost of a step
/// depends on none of these, and every method but TLS in 1D runs to the end (TLS diverges on
/// fine 1D meshes, B-spline TLS at cfl 0.4; docs/NOTES.md).
fn manufactured(cells: i64, ppc: i64, t_end: f64) -> Params {
    let mut params = thesis_params(1e-4, cells, ppc);
    params.insert("cfl".into(), ParamValue::Float(0.2));
    params.insert("t_end".into(), ParamValue::Float(t_end));
    params
}

/// The wall time each method should come within, relative to `mpm`, on the 2D case: set by
/// the work it does per particle and step (stencil size, local fits, a Newton solve).
const TARGETS_2D: &[(&str, f64)] = &[
    ("bsmpm", 2.0),
    ("ugimp", 2.5),
    ("cpgimp", 2.5),
    ("cpdi1", 3.0),
    ("cpdi2", 3.0),
    ("ddmpm", 2.5),
    ("mpm_tls_lumped", 3.0),
    ("cpdi_mls", 4.0),
    ("impm", 4.0),
    ("imls", 5.0),
    ("mpm_tls", 5.0),
    ("bsmpm_tls", 8.0),
    ("ddmpm_tls", 8.0),
    ("lme g=3", 6.0),
    ("lme g=0.8", 15.0),
];

fn target(label: &str, benchmark: &str) -> String {
    TARGETS_2D
        .iter()
        .find(|(name, _)| *name == label && benchmark == "mms2d_gong")
        .map_or_else(|| "-".to_string(), |(_, t)| format!("{t:.1}"))
}

/// Wobbes' bar with large strain (Table 2), 160 cells and 12 points per cell, to t = 0.02 s:
/// a 1D case that the TLS compositions run.
fn large_strain_bar() -> Params {
    let bar = benchmarks::CATALOG
        .find("vibrating_bar")
        .expect("the catalogue has the bar");
    let mut params = benchmarks::default_params(bar.params);
    for (key, value) in [("E", 4.0e4), ("v0", 0.8), ("dt", 1.0e-5), ("t_end", 0.02)] {
        params.insert(key.into(), ParamValue::Float(value));
    }
    params.insert("exact".into(), ParamValue::Str("none".into()));
    params.insert("cells".into(), ParamValue::Int(160));
    params.insert("ppc".into(), ParamValue::Int(12));
    params
}

/// The LME locality values of Molinos et al. (Figs 10-11).
const GAMMAS: [f64; 2] = [0.8, 3.0];

/// A timed configuration: a preset with the method parameters it is timed with.
struct Variant {
    label: String,
    preset: &'static str,
    method_params: Params,
}

/// Every preset as it stands, LME at each of `GAMMAS`, and the original MPM with each
/// integrator it does not use by default (the particle update is what they change).
fn variants(filter: Option<&str>) -> Vec<Variant> {
    let mut variants = Vec::new();
    for preset in methods::PRESETS.entries {
        let skipped = filter.is_some_and(|f| f != preset.name) && preset.name != "mpm";
        // The composed method is whatever parts a run names: no preset to time.
        if skipped || preset.name == methods::COMPOSED {
            continue;
        }
        let is_lme = matches!(preset.method.shape, ShapeKind::LocalMaxEnt(_));
        if is_lme {
            for gamma in GAMMAS {
                variants.push(Variant {
                    label: format!("{} g={gamma}", preset.name),
                    preset: preset.name,
                    method_params: [(GAMMA_KEY.to_string(), ParamValue::Float(gamma))].into(),
                });
            }
            continue;
        }
        variants.push(Variant {
            label: preset.name.to_string(),
            preset: preset.name,
            method_params: Params::new(),
        });
        if preset.name == "mpm" && filter.is_none_or(|f| f == "mpm") {
            for &integrator in &INTEGRATOR_NAMES[1..] {
                variants.push(Variant {
                    label: format!("mpm {integrator}"),
                    preset: preset.name,
                    method_params: [(
                        INTEGRATOR_KEY.to_string(),
                        ParamValue::Str(integrator.into()),
                    )]
                    .into(),
                });
            }
        }
    }
    variants
}

fn spec(case: &Case, variant: &Variant) -> ResolvedRun {
    let mut params = (case.params)();
    params.extend(variant.method_params.clone());
    let spec = RunSpec {
        experiment: "bench".into(),
        run_id: "bench".into(),
        benchmark: case.benchmark.into(),
        method: variant.preset.into(),
        params,
        axes: Params::new(),
        output_every: 0,
        config_yaml: String::new(),
    };
    ResolvedRun::resolve(spec).expect("the bench cases are valid runs")
}

/// Microseconds per point of `shape` at `points` random points of a 32-cell grid, best of
/// three passes.
fn evaluation_cost<const D: usize>(shape: &dyn Shape<D>, points: usize) -> f64 {
    let domain = Domain {
        lower: SVector::zeros(),
        upper: SVector::repeat(1.0),
        cells: 32,
    };
    let grid = Grid::new(&domain);
    let mut rng = Lcg::new(7);
    let x: Vec<SVector<f64, D>> = (0..points)
        .map(|_| SVector::from_fn(|_, _| rng.unit()))
        .collect();
    let mut stencils = Stencils::new(shape.nodes_per_point(), points);
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let started = Instant::now();
        stencils
            .update(shape, &grid, &x)
            .expect("the points are on the grid");
        best = best.min(started.elapsed().as_secs_f64());
    }
    best / points as f64 * 1e6
}

/// The cost of the LME basis per point (a safeguarded Newton solve over its stencil) beside
/// the hat's, in 1D and 2D.
fn lme_evaluation_costs() {
    println!(
        "\n{:<16} {:>4} {:>8} {:>12}",
        "basis", "dim", "nodes", "us/point"
    );
    let row = |label: &str, dim: usize, nodes: usize, cost: f64| {
        println!("{label:<16} {dim:>4} {nodes:>8} {cost:>12.3}");
    };
    row("hat", 1, 2, evaluation_cost::<1>(&LinearHat, 200_000));
    row("hat", 2, 4, evaluation_cost::<2>(&LinearHat, 200_000));
    for gamma in GAMMAS {
        let label = format!("lme g={gamma}");
        let lme1 = LocalMaxEnt::<1>::new(gamma).expect("valid in 1D");
        row(
            &label,
            1,
            lme1.nodes_per_point(),
            evaluation_cost(&lme1, 200_000),
        );
        let lme2 = LocalMaxEnt::<2>::new(gamma).expect("valid in 2D");
        row(
            &label,
            2,
            lme2.nodes_per_point(),
            evaluation_cost(&lme2, 50_000),
        );
    }
}

/// The best wall time of `spec` over up to three runs (the machine is shared, the minimum is
/// the least disturbed; runs over ten seconds are timed once), its peak heap and its record,
/// and with a `reference` the best wall time of that over as many runs, each right after one
/// of `spec`'s, so that a change in the machine's speed reaches both times of the ratio.
fn timed(
    spec: &ResolvedRun,
    reference: Option<&ResolvedRun>,
) -> (f64, f64, usize, mpmlab::output::RunRecord) {
    let mut best = f64::INFINITY;
    let mut best_reference = f64::INFINITY;
    let mut peak = 0;
    let mut record = None;
    for _ in 0..3 {
        if best > 10.0 && record.is_some() {
            break;
        }
        let started = Instant::now();
        let (r, bytes) = peak_bytes(|| simulate(spec));
        best = best.min(started.elapsed().as_secs_f64());
        peak = bytes;
        record = Some(r);
        if let Some(reference) = reference {
            let started = Instant::now();
            simulate(reference);
            best_reference = best_reference.min(started.elapsed().as_secs_f64());
        }
    }
    let reference_seconds = reference.map_or(best, |_| best_reference);
    (
        best,
        reference_seconds,
        peak,
        record.expect("three runs were made"),
    )
}

fn main() {
    // Bench harnesses are passed flags such as --bench; a bare word filters by method.
    let filter: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    println!(
        "{:<24} {:<14} {:>10} {:>8} {:>10} {:>14} {:>9} {:>7} {:>11}",
        "method",
        "benchmark",
        "particles",
        "steps",
        "seconds",
        "Mparticle-steps/s",
        "cost/mpm",
        "target",
        "B/particle"
    );
    let variants = variants(filter.as_deref());
    let mpm = variants.iter().find(|v| v.label == "mpm");
    for case in CASES {
        let reference = mpm.map(|mpm| spec(case, mpm));
        for variant in &variants {
            // `mpm` itself is its own reference.
            let beside = reference.as_ref().filter(|_| variant.label != "mpm");
            let (seconds, mpm_seconds, peak, record) = timed(&spec(case, variant), beside);
            if record.status != RunStatus::Ok {
                println!(
                    "{:<24} {:<14} {}: {}",
                    variant.label,
                    case.benchmark,
                    record.status.as_str(),
                    record.message
                );
                continue;
            }
            let particles = record.particles.len();
            let rate = (particles * record.steps) as f64 / seconds / 1e6;
            println!(
                "{:<24} {:<14} {:>10} {:>8} {:>10.3} {:>14.1} {:>9.2} {:>7} {:>11.0}",
                variant.label,
                case.benchmark,
                particles,
                record.steps,
                seconds,
                rate,
                seconds / mpm_seconds,
                target(&variant.label, case.benchmark),
                peak as f64 / particles as f64
            );
        }
    }
    if filter.as_deref().is_none_or(|f| f == "lme") {
        lme_evaluation_costs();
    }
}
