//! Which figures a report draws and what goes into each; drawing is `plot`'s job.

mod along_bar;
mod convergence;
mod field_map;
mod history;
mod overlap;
mod profiles;
mod shape_functions;
mod stability;

use std::collections::BTreeSet;
use std::path::PathBuf;

use super::group::{label, selects, slug};
use crate::benchmarks::BenchmarkKind;
use crate::experiment::{Experiment, FigureKind, FigureSpec};
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
    /// A law fitted to the markers, drawn dashed in the series' colour.
    pub fit: Vec<(f64, f64)>,
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
            fit: Vec::new(),
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
            fit: Vec::new(),
            neutral: false,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Relative to the report directory. A kind's module gives the stem the file gets when
    /// its `figures` item names none (`default_stem`); `plan` names the file.
    pub file: PathBuf,
    pub title: String,
    /// The axis values (and for some kinds the quantity) that tell this figure from the
    /// others its `figures` item draws; `plan` names the figure by those that differ.
    pub variant: Vec<(String, String)>,
    pub x_label: String,
    pub y_label: String,
    pub scale: Scale,
    pub series: Vec<Series>,
    /// Lines under the legend: what the series do not show by themselves (the fits'
    /// pattern, runs that did not finish).
    pub notes: Vec<String>,
    /// The `name` of the figures item that drew it (`plan` sets it).
    pub drawn_by: Option<String>,
}

/// Every figure of the report: the experiment's own, or when it asks for none one convergence
/// figure per group with all fields in the first norm (the shape-function figures for a
/// shape-function benchmark, which does not refine). Figures without a single usable point
/// are left out. A history figure of a probe no run records is an error.
pub fn plan(experiment: &Experiment, runs: &[RunSummary]) -> Result<Vec<Figure>, String> {
    let measures = experiment.measures();
    let kind = if experiment.kind == BenchmarkKind::ShapeFunctions {
        FigureKind::ShapeFunctions
    } else {
        FigureKind::Convergence
    };
    let fields = measures.fields.iter().map(|f| f.to_string()).collect();
    let default = [FigureSpec::new(kind, fields, measures.norms[0])];
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
        let mut drawn = match spec.kind {
            FigureKind::Convergence => convergence::figures(experiment, &selected, spec),
            FigureKind::Reconstruction => {
                let mut drawn = profiles::reconstructions(&selected);
                drawn.extend(profiles::element_fits(&selected));
                drawn
            }
            FigureKind::Basis => profiles::bases(&selected),
            FigureKind::Stability => stability::limit_figures(experiment, &selected, spec),
            FigureKind::Growth => stability::growth_figures(experiment, &selected, spec),
            FigureKind::Profile => along_bar::figures(experiment, runs, &selected, spec),
            FigureKind::ShapeFunctions => shape_functions::figures(&selected, spec),
            FigureKind::History => history::figures(experiment, &selected, spec)?,
            // Not a plot of series: `plan_maps` plans these.
            FigureKind::FieldMap => Vec::new(),
        };
        name(experiment, spec, &mut drawn, &mut names);
        drawn.iter_mut().for_each(overlap::mark_coincident);
        figures.extend(drawn);
    }
    Ok(figures)
}

/// The stem a figure's file gets when its item names none: `what` after the experiment.
fn default_stem(what: &str) -> PathBuf {
    PathBuf::from(slug(what))
}

/// Gives the figures one `spec` drew their files and, when it has a `title`, their captions:
/// `<name>` for a single figure, `<name>_<variant>` for each of several, where the variant is
/// the axis values that differ between them; the `paper` reference opens the caption.
fn name(experiment: &Experiment, spec: &FigureSpec, drawn: &mut [Figure], names: &mut Names) {
    let several = drawn.len() > 1;
    let shared: Vec<(String, String)> = match drawn.split_first() {
        Some((first, rest)) => first
            .variant
            .iter()
            .filter(|pair| rest.iter().all(|f| f.variant.contains(pair)))
            .cloned()
            .collect(),
        None => Vec::new(),
    };
    for figure in drawn.iter_mut() {
        let distinct: Vec<&(String, String)> = figure
            .variant
            .iter()
            .filter(|pair| !shared.contains(pair))
            .collect();
        let distinct = label(distinct.iter().map(|(k, v)| (k, v)));
        let stem = match &spec.name {
            Some(name) if several && !distinct.is_empty() => format!("{name}_{}", slug(&distinct)),
            Some(name) => name.clone(),
            None => format!("{}_{}", slug(&experiment.name), figure.file.display()),
        };
        figure.file = names.file(&stem);
        figure.drawn_by = spec.name.clone();
        if let Some(title) = &spec.title {
            figure.title = match several && !distinct.is_empty() {
                true => format!("{title} ({distinct})"),
                false => title.clone(),
            };
        }
        if let Some(paper) = &spec.paper {
            figure.title = format!("{paper}: {}", figure.title);
        }
    }
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

/// The caption's opening: the item's `paper` and `title`, either alone, or the experiment's
/// name when it gives neither.
fn heading(experiment: &Experiment, spec: &FigureSpec) -> String {
    match (&spec.paper, &spec.title) {
        (Some(paper), Some(title)) => format!("{paper}: {title}"),
        (Some(text), None) | (None, Some(text)) => text.clone(),
        (None, None) => experiment.name.clone(),
    }
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

    /// `figures/<stem>.png`, made unique.
    fn file(&mut self, stem: &str) -> PathBuf {
        let mut name = stem.to_string();
        let mut k = 2;
        while !self.0.insert(name.clone()) {
            name = format!("{stem}_{k}");
            k += 1;
        }
        PathBuf::from("figures").join(name + ".png")
    }
}
