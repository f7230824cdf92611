//! Experiment files: the YAML schema, validation with file/line/column errors, matrix
//! expansion and stable run ids. Knows nothing of HDF5 or numerics.

mod claims;
mod document;
mod error;
mod expand;
mod expect;
mod figures;
mod kinds;
mod measures;
mod reference;
mod resolved;
mod run_id;
mod run_spec;
mod select;
mod space;
mod stability;
mod tables;
mod values;
mod yaml;

use std::path::{Path, PathBuf};

use crate::benchmarks::{self, BenchmarkKind};
use crate::output::Measures;
use crate::params::Params;

pub use document::MAX_NAME_LEN;
pub use error::ConfigError;
pub use expand::{sample_count, MAX_RUNS, MAX_SAMPLES};
pub use resolved::{ResolvedRun, RunMethod};
pub use run_id::MAX_RUN_ID_LEN;
pub use select::{Allowed, Selection};
pub use values::MAX_LIST_VALUES;

use document::Sections;
use error::{Pos, FILE_FIELD};
use space::ParamSpace;

/// Reads and validates an experiment file; an unreadable file, or one that is not UTF-8
/// text, is a `ConfigError` too.
pub fn load(path: &Path) -> Result<Experiment, ConfigError> {
    let bytes = std::fs::read(path).map_err(|e| {
        ConfigError::at(Pos::START, FILE_FIELD, format!("cannot read the file: {e}")).in_file(path)
    })?;
    let text = yaml::decode(&bytes).map_err(|e| e.in_file(path))?;
    parse(text, path)
}

/// Validates the text of an experiment file and expands its matrix; `path` names the file in
/// errors and in `Experiment::source_path`.
pub fn parse(text: &str, path: &Path) -> Result<Experiment, ConfigError> {
    build(text, path).map_err(|e| e.in_file(path))
}

fn build(text: &str, path: &Path) -> Result<Experiment, ConfigError> {
    let root = yaml::parse_tree(text)?;
    let sections = Sections::read(&root)?;
    let name = document::name(&sections)?;
    let description = document::description(&sections)?;
    let benchmark = document::benchmark(&sections)?;
    let kind = benchmark.info.kind;
    let space = ParamSpace::read(&sections, benchmark.info)?;
    let (output, every_pos) = document::output(&sections)?;
    let reference = reference::read(sections.get("reference"), &space, benchmark.info, kind)?;
    let measures = Measures::of_benchmark(benchmark.info).with_reference(reference.is_some());
    let expect = expect::read(sections.get("expect"), &space, measures)?;
    let figures = figures::read(sections.get("figures"), &space, kind, measures)?;
    let tables = tables::read(sections.get("tables"), &space, kind, measures)?;
    let paper_claims = claims::read(sections.get("paper_claims"), &space, measures, &figures)?;
    let sampling = expand::Sampling {
        every: output.every,
        pos: every_pos,
    };
    let runs = expand::expand(&name, &benchmark, &space, &sampling)?;
    if let (Some(select), Some(section)) = (&reference, sections.get("reference")) {
        reference::check_unique(select, &runs, section)?;
    }
    Ok(Experiment {
        name,
        description,
        source_path: path.to_path_buf(),
        source_text: text.to_string(),
        benchmark: benchmark.info.name.to_string(),
        kind,
        axes: space.axes().iter().map(|a| a.key.clone()).collect(),
        output,
        expect,
        figures,
        tables,
        paper_claims,
        reference,
        runs,
    })
}

/// A validated experiment file with its matrix expanded.
#[derive(Clone, Debug)]
pub struct Experiment {
    pub name: String,
    /// Free text for the report (what is reproduced, what the paper leaves open).
    pub description: String,
    /// The file it was read from, and its text (copied next to the results so that a
    /// report can be made from a results directory alone).
    pub source_path: PathBuf,
    pub source_text: String,
    pub benchmark: String,
    pub kind: BenchmarkKind,
    /// Matrix axis names in file order (`method` and `cells` included when they are axes).
    pub axes: Vec<String>,
    pub output: OutputSpec,
    pub expect: Vec<Expectation>,
    pub figures: Vec<FigureSpec>,
    pub paper_claims: Vec<PaperClaim>,
    pub tables: Vec<TableSpec>,
    /// Axis values of the run the others are compared with at the final time (`reference`).
    pub reference: Option<Params>,
    /// One entry per run, in expansion order (the cartesian product, last axis fastest).
    pub runs: Vec<ResolvedRun>,
}

impl Experiment {
    /// The error fields and norms of its runs: those of its benchmark
    /// (`Measures::of_benchmark`), and the relative error against the reference run when it
    /// names one.
    pub fn measures(&self) -> Measures {
        benchmarks::CATALOG
            .find(&self.benchmark)
            .map_or(Measures::of(self.kind), Measures::of_benchmark)
            .with_reference(self.reference.is_some())
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct OutputSpec {
    /// History sampling interval in steps (t = 0 and the final time are always sampled).
    pub every: usize,
}

/// One `expect` entry, checked by `mpmlab report --check`.
#[derive(Clone, Debug, PartialEq)]
pub struct Expectation {
    /// Matrix-axis values the entry applies to (e.g. method: [mpm, usl], G: 0.1); empty = all
    /// groups.
    pub select: Selection,
    pub field: String,
    pub norm: String,
    pub rate_min: Option<f64>,
    pub rate_max: Option<f64>,
    /// Bounds on the final error of every matching run: a printed value is matched by both.
    pub error_min: Option<f64>,
    pub error_max: Option<f64>,
    /// A stability-limit expectation (`sweep`, `limit_min`, `limit_max`); its `field` and
    /// `norm` are those the stability criterion reads (velocity, l2).
    pub limit: Option<LimitBound>,
    /// Line of the entry in the source file, for messages.
    pub line: usize,
}

/// One `paper_claims` entry: the paper's number for a field and norm of the selected runs.
#[derive(Clone, Debug, PartialEq)]
pub struct PaperClaim {
    /// The paper's figure or table, e.g. "Gong 2015, Fig 4.7".
    pub item: String,
    /// What the paper says, in a few words.
    pub claim: String,
    /// The `name` of the figure of this experiment that shows it.
    pub figure: Option<String>,
    /// The runs that measure it: one fitted group for a rate, the runs of one error.
    pub select: Selection,
    pub field: String,
    pub norm: String,
    pub value: ClaimedValue,
    /// A rate's absolute tolerance; an error's relative one.
    pub tolerance: f64,
    /// Where docs/NOTES.md isolates why ours differs, for a claim ours does not reproduce.
    pub differs: Option<String>,
    pub line: usize,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClaimedValue {
    /// A convergence rate: the slope of log error against log h.
    Rate(f64),
    /// A final error in the claim's norm.
    Error(f64),
}

/// The measured stability limit along `sweep` must lie in [min, max]: in every group of the
/// other axes the last stable value is at least `min` and the first unstable one at most
/// `max`.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitBound {
    pub sweep: String,
    pub min: f64,
    pub max: f64,
}

/// The axes of a stability study: `sweep`, along which runs are taken towards instability,
/// and `x`, whose values are a stability figure's abscissa and a stability table's rows
/// (none for growth figures, which draw one figure per group).
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityAxes {
    pub sweep: String,
    pub x: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum FigureKind {
    /// log10(error) against log10(h) with fitted slopes.
    Convergence,
    /// Per run: u(x), the reconstructed nodal values (or each element's fit) and the data
    /// points.
    Reconstruction,
    /// Per run: the weighted orthogonal polynomials with the data points on them.
    Basis,
    /// Fields along the bar at the final time against the current position, one line per
    /// run, with the reference run as grey markers (Wobbes Fig 4).
    Profile,
    /// The measured stability limit along `sweep` (last stable and first unstable value)
    /// against `x`, with the predicted bounds when `x` is the particles per cell.
    Stability,
    /// Per group: the l2 velocity error over time of the runs on either side of the limit.
    Growth,
    /// Per group of the axes other than the method and `by`: N_a of the centre node and
    /// dN_a/dx along the line through it parallel to x, one curve per run, the hat in grey
    /// (Molinos et al. Fig 3).
    ShapeFunctions,
    /// A probe's value over time, one line per run (per value of `by` in one figure), with
    /// the benchmark's reference for it in grey (Molinos Figs 5-13).
    History,
    /// A field over the plane of 2D runs, one coloured panel per run (per value of `by` in one
    /// figure) on a colour scale the panels share: the particle state at the last sample, an
    /// element-wise fit (Wobbes Fig 2), a shape function (Molinos Fig 3) or its derivative.
    FieldMap,
}

#[derive(Clone, Debug, PartialEq)]
pub struct FigureSpec {
    /// The file stem: `figures/<name>.png`, `<name>_<variant>.png` for each of several figures
    /// the item draws; without it a stem from the experiment and the figure's scope.
    pub name: Option<String>,
    /// What the figure shows, and `paper` the figure it reproduces ("Gong 2015, Fig 4.7"):
    /// together the caption, in place of one made from the axes.
    pub title: Option<String>,
    pub paper: Option<String>,
    pub kind: FigureKind,
    pub fields: Vec<String>,
    pub norm: String,
    /// Axes whose values become separate curves in one figure (others make separate figures):
    /// one at most, except for history figures, whose lines may differ in several (a method
    /// with a gamma axis beside methods without).
    pub by: Vec<String>,
    /// Axis values a run must have (one of those listed per axis) to be drawn; empty = every run.
    pub select: Selection,
    /// Stability and growth figures only.
    pub stability: Option<StabilityAxes>,
    /// History figures only: the probe drawn (checked against the run files by the report).
    pub probe: Option<String>,
    /// Field maps only.
    pub map: Option<FieldMapSpec>,
}

impl FigureSpec {
    /// A figure of `kind` over every run: no `by`, selector, name or kind-specific part.
    pub fn new(kind: FigureKind, fields: Vec<String>, norm: &str) -> Self {
        FigureSpec {
            name: None,
            title: None,
            paper: None,
            kind,
            fields,
            norm: norm.to_string(),
            by: Vec::new(),
            select: Selection::default(),
            stability: None,
            probe: None,
            map: None,
        }
    }
}

/// What a field map draws.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldMapSpec {
    /// One of the map fields of the benchmark's kind (`output::map_fields`).
    pub field: String,
}

#[derive(Clone, Debug, PartialEq)]
pub enum TableKind {
    /// u - u^h at every node, one column per value of `columns` (Gong Tables 4.1-4.2).
    NodalErrors,
    /// <p_i, p_i> and the kept polynomials, one row per run (Tran Figs 1-3).
    BasisNorms,
    /// One row per value of `x`: the measured stability limit along `sweep` and the
    /// predicted bounds.
    Stability,
    /// One row per element-wise run: RMS and integral errors, and the elements whose fit
    /// dropped a degree (Wobbes sec 2.1).
    ElementFits,
    /// One row per run: its axis values and its final error in one field and norm (Molinos
    /// eq 40 with velocity and rms).
    Errors,
    /// One row per run, from the smallest final error in one field and norm to the largest
    /// (and in costs.md from the shortest wall time to the longest).
    Ranking,
    /// One row per run: how a probe's history settles against its reference after a time
    /// (Molinos Figs 10-11: which runs stay stable, when the others leave).
    Probes,
    /// One row per run: the largest relative mass and momentum errors of its mappings
    /// (Wobbes Table 3).
    Conservation,
}

#[derive(Clone, Debug, PartialEq)]
pub struct TableSpec {
    pub kind: TableKind,
    /// Axis whose values become the columns of one table (others make separate tables).
    pub columns: Option<String>,
    /// Axis values a run must have (one of those listed per axis) to be listed; empty = every
    /// run.
    pub select: Selection,
    /// Stability tables only.
    pub stability: Option<StabilityAxes>,
    /// Errors tables only: the (field, norm) listed.
    pub measure: Option<(String, String)>,
    /// Probes tables only: the probe and the window it is judged over.
    pub probe: Option<ProbeWindow>,
}

/// What a probes table reads of a probe's history.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeWindow {
    /// The probe's name (checked against the run files by the report).
    pub name: String,
    /// The statistics are taken over t >= after (s).
    pub after: f64,
    /// A run has left its reference at the first t >= after with |value - reference| above
    /// this (in the probe's unit).
    pub tolerance: f64,
}
