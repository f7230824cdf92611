//! Which figures a report draws and what goes into each; drawing is `plot`'s job.

mod along_bar;
mod convergence;
mod field_map;
mod history;
mod profiles;
mod shape_functions;
mod stability;

use std::collections::BTreeSet;
use std::path::PathBuf;

use super::group::{selects, slug};
use crate::benchmarks::BenchmarkKind;
use crate::experiment::{Experiment, FigureKind, FigureSpec, Selection};
use crate::output::RunSummary;

pub use field_map::{Cell, FieldMap, Panel};

/// How the axes of a figure are scaled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Linear,
    /// log10 on both axes (convergence figures).
    LogLog,
    /// Linear x, log10 y (error histories).
    LogY,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Marker {
    Circle,
    Square,
    Triangle,
    Diamond,
    /// Where a diverged run stopped.
    Cross,
}

impl Marker {
    /// The shapes for data series that may lie on top of each other, in turn: where two
    /// series have the same values, both shapes stay visible.
    pub const DATA: [Marker; 4] = [
        Marker::Circle,
        Marker::Square,
        Marker::Triangle,
        Marker::Diamond,
    ];
}

/// One legend entry: markers at some points and a line through others, in one colour. The
/// marker and line asked for here are what the series gets unless an earlier series of the
/// figure already looks so (`report::style`).
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    pub markers: Vec<(f64, f64)>,
    pub marker: Marker,
    pub line: Vec<(f64, f64)>,
    /// A fit or a bound: the line is dashed (dotted to tell it from another), never solid.
    pub dashed: bool,
    /// Drawn in grey whatever its place: a reference the other series are judged against.
    pub neutral: bool,
}

impl Series {
    pub fn markers(label: String, marker: Marker, points: Vec<(f64, f64)>) -> Self {
        Series {
            label,
            markers: points,
            marker,
            line: Vec::new(),
            dashed: false,
            neutral: false,
        }
    }

    pub fn line(label: String, points: Vec<(f64, f64)>) -> Self {
        Series {
            label,
            markers: Vec::new(),
            marker: Marker::Circle,
            line: points,
            dashed: false,
            neutral: false,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Relative to the report directory.
    pub file: PathBuf,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub scale: Scale,
    pub series: Vec<Series>,
}

/// Every figure of the report: the experiment's own, or when it asks for none one convergence
/// figure per group with all fields in the first norm (the shape-function figures for a
/// shape-function benchmark, which does not refine). Figures without a single usable point
/// are left out. A history figure of a probe no run records is an error.
pub fn plan(experiment: &Experiment, runs: &[RunSummary]) -> Result<Vec<Figure>, String> {
    let measures = experiment.measures();
    let default = [FigureSpec {
        kind: if experiment.kind == BenchmarkKind::ShapeFunctions {
            FigureKind::ShapeFunctions
        } else {
            FigureKind::Convergence
        },
        fields: measures.fields.iter().map(|f| f.to_string()).collect(),
        norm: measures.norms[0].to_string(),
        by: Vec::new(),
        select: Selection::default(),
        stability: None,
        probe: None,
        map: None,
    }];
    let specs = if experiment.figures.is_empty() {
        &default[..]
    } else {
        &experiment.figures
    };
    let mut names = Names::default();
    let mut figures = Vec::new();
    for spec in specs {
        let selected: Vec<&RunSummary> = runs
            .iter()
            .filter(|run| selects(&spec.select, &run.axes))
            .collect();
        match spec.kind {
            FigureKind::Convergence => figures.extend(convergence::figures(
                experiment, &selected, spec, &mut names,
            )),
            FigureKind::Reconstruction => {
                figures.extend(profiles::reconstructions(experiment, &selected, &mut names));
                figures.extend(profiles::element_fits(experiment, &selected, &mut names));
            }
            FigureKind::Basis => figures.extend(profiles::bases(experiment, &selected, &mut names)),
            FigureKind::Stability => figures.extend(stability::limit_figures(
                experiment, &selected, spec, &mut names,
            )),
            FigureKind::Growth => figures.extend(stability::growth_figures(
                experiment, &selected, spec, &mut names,
            )),
            FigureKind::Profile => figures.extend(along_bar::figures(
                experiment, runs, &selected, spec, &mut names,
            )),
            FigureKind::ShapeFunctions => figures.extend(shape_functions::figures(
                experiment, &selected, spec, &mut names,
            )),
            FigureKind::History => {
                figures.extend(history::figures(experiment, &selected, spec, &mut names)?)
            }
            // Not a plot of series: `plan_maps` plans these.
            FigureKind::FieldMap => {}
        }
    }
    Ok(figures)
}

/// The field maps of the experiment's `field_map` entries, named after the `figures` that
/// `plan` gave out. A map whose selected runs are all 1D is an error.
pub fn plan_maps(
    experiment: &Experiment,
    runs: &[RunSummary],
    figures: &[Figure],
) -> Result<Vec<FieldMap>, String> {
    let mut names = Names::after(figures);
    let mut maps = Vec::new();
    for spec in &experiment.figures {
        if spec.kind != FigureKind::FieldMap {
            continue;
        }
        let selected: Vec<&RunSummary> = runs
            .iter()
            .filter(|run| selects(&spec.select, &run.axes))
            .collect();
        maps.extend(field_map::figures(experiment, &selected, spec, &mut names)?);
    }
    Ok(maps)
}

/// File names already given out: two figures may land on the same stem, and later ones get
/// a numeric suffix.
#[derive(Default)]
struct Names(BTreeSet<String>);

impl Names {
    /// With the names of `figures` given out already.
    fn after(figures: &[Figure]) -> Names {
        let stems = figures.iter().filter_map(|f| f.file.file_stem());
        Names(stems.map(|s| s.to_string_lossy().into_owned()).collect())
    }

    /// `figures/<experiment>_<what>.png`, made unique.
    fn file(&mut self, experiment: &Experiment, what: &str) -> PathBuf {
        let stem = format!("{}_{}", slug(&experiment.name), slug(what));
        let mut name = stem.clone();
        let mut k = 2;
        while !self.0.insert(name.clone()) {
            name = format!("{stem}_{k}");
            k += 1;
        }
        PathBuf::from("figures").join(name + ".png")
    }
}
