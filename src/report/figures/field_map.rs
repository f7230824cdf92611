//! Field maps: a field over the plane of 2D runs, one panel per run, every panel of one
//! `figures` entry on one colour scale so that they compare. A simulation's particles are
//! squares of their current area at their current position, coloured by the field at the last
//! sample (Molinos Fig 11); an element-wise fit is drawn at its map samples, with the data
//! points over it (Wobbes Fig 2); a shape function at its lattice of points, with its node
//! marked (Molinos Fig 3).

use std::cmp::Ordering;
use std::path::PathBuf;

use super::shape_functions::{curve_label, lme_first};
use super::{heading, Names};
use crate::experiment::{Experiment, FigureSpec};
use crate::output::{ElementRecord, ParticleState, RunSummary, ShapeFunctionRecord};
use crate::params::Params;
use crate::report::colour_map::{ColourScale, Palette};
use crate::report::format::general;
use crate::report::group::{cmp_params, group_runs, label, label_or_all, scoped_label, slug};

/// Names of the components of vectors and tensors, by index.
const AXIS_NAMES: &str = "xyz";

#[derive(Clone, Debug, PartialEq)]
pub struct FieldMap {
    /// Relative to the report directory.
    pub file: PathBuf,
    /// What is drawn (first line of the caption), and the group of runs (second line).
    pub title: String,
    pub scope: String,
    pub x_label: String,
    pub y_label: String,
    /// The colour bar's label: the field and its unit.
    pub value_label: String,
    pub scale: ColourScale,
    pub panels: Vec<Panel>,
    /// What the points drawn over the cells are, for the legend; empty when there are none.
    pub marker_label: String,
    /// The `name` of the figures item that drew it.
    pub drawn_by: Option<String>,
}

impl FieldMap {
    /// The title and the group on one line, as report.md shows it.
    pub fn caption(&self) -> String {
        if self.scope.is_empty() {
            self.title.clone()
        } else {
            format!("{}: {}", self.title, self.scope)
        }
    }
}

/// One run's map.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    pub label: String,
    pub cells: Vec<Cell>,
    pub markers: Vec<(f64, f64)>,
}

/// A rectangle centred on (x, y), filled with the colour of `value`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    pub x: f64,
    pub y: f64,
    pub width: f64,
    pub height: f64,
    pub value: f64,
}

/// What one run contributes to a map.
struct Layer {
    cells: Vec<Cell>,
    markers: Vec<(f64, f64)>,
    /// The time of a particle state.
    time: Option<f64>,
    /// For the panel's label (a fit's RMS error), or empty.
    note: String,
}

/// The axis labels, the colour bar's label, the words of the title, what the markers are and
/// the palette, for one field of one kind of run.
struct Labels {
    x: String,
    y: String,
    value: String,
    what: String,
    markers: String,
    palette: Palette,
}

/// One figure per group of the axes other than `by`, a panel per run of the group, on the
/// colour scale of all their values. An error when runs are selected but none of them is 2D.
pub(super) fn figures(
    experiment: &Experiment,
    selected: &[&RunSummary],
    spec: &FigureSpec,
    names: &mut Names,
) -> Result<Vec<FieldMap>, String> {
    let Some(map) = &spec.map else {
        return Ok(Vec::new());
    };
    if !selected.is_empty() && selected.iter().all(|run| run.dim != 2) {
        return Err(format!(
            "field_map figure of {}: no selected run is 2D (its runs are {}D)",
            experiment.name, selected[0].dim
        ));
    }
    let by: Vec<&str> = spec.by.iter().map(String::as_str).collect();
    let mut groups = Vec::new();
    for group in group_runs(selected.iter().copied(), &by) {
        let mut runs: Vec<(&RunSummary, Layer)> = group
            .runs
            .iter()
            .filter_map(|run| Some((*run, layer(run, &map.field)?)))
            .collect();
        if let Some(labels) = runs.first().and_then(|(run, _)| labels(run, &map.field)) {
            runs.sort_by(|a, b| panel_order(a.0, b.0, &by));
            groups.push((group.axes, runs, labels));
        }
    }
    // One field, so one palette.
    let Some(palette) = groups.first().map(|(_, _, labels)| labels.palette) else {
        return Ok(Vec::new());
    };
    let values = groups.iter().flat_map(|(_, runs, _)| runs);
    let scale = ColourScale::fit(
        palette,
        values.flat_map(|(_, layer)| layer.cells.iter().map(|c| c.value)),
    );
    let several = groups.len() > 1;
    let mut maps = Vec::new();
    for (axes, runs, labels) in groups {
        let times: Vec<f64> = runs.iter().filter_map(|(_, l)| l.time).collect();
        let common_time = times
            .first()
            .filter(|t| times.iter().all(|u| u == *t))
            .copied();
        let panels = runs
            .into_iter()
            .map(|(run, layer)| Panel {
                label: panel_label(run, &by, &layer, common_time.is_none()),
                cells: layer.cells,
                markers: layer.markers,
            })
            .collect();
        let scope = scoped_label(&axes, &spec.select);
        let what = match common_time {
            Some(t) => format!("{} at t = {} s", labels.what, general(t, 4)),
            None => labels.what,
        };
        maps.push(FieldMap {
            file: names.file(&match (&spec.name, several) {
                (Some(name), false) => name.clone(),
                (Some(name), true) => format!("{name}_{}", slug(&label_or_all(&scope))),
                (None, _) => format!(
                    "{}_map_{}_{}",
                    slug(&experiment.name),
                    map.field,
                    slug(&label_or_all(&scope))
                ),
            }),
            title: format!("{}: {what}", heading(experiment, spec)),
            drawn_by: spec.name.clone(),
            scope,
            x_label: labels.x,
            y_label: labels.y,
            value_label: labels.value,
            scale,
            panels,
            marker_label: labels.markers,
        });
    }
    Ok(maps)
}

/// Shape functions as their line figures order them (LME by gamma, then the other bases);
/// other runs by their values of the `by` axes.
fn panel_order(a: &RunSummary, b: &RunSummary, by: &[&str]) -> Ordering {
    if let (Some(ra), Some(rb)) = (a.unstepped.shape_functions(), b.unstepped.shape_functions()) {
        return lme_first(ra, rb);
    }
    cmp_params(&by_axes(a, by), &by_axes(b, by))
}

fn by_axes(run: &RunSummary, by: &[&str]) -> Params {
    run.axes
        .iter()
        .filter(|(k, _)| by.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect()
}

/// The run's values of the `by` axes (a shape function: its basis and gamma), what its layer
/// notes, and its time when the panels differ in it.
fn panel_label(run: &RunSummary, by: &[&str], layer: &Layer, with_time: bool) -> String {
    let axes = match run.unstepped.shape_functions() {
        Some(r) => curve_label(r),
        None => label(&by_axes(run, by)),
    };
    let time = match (with_time, layer.time) {
        (true, Some(t)) => format!("t = {} s", general(t, 4)),
        _ => String::new(),
    };
    let parts = [axes, layer.note.clone(), time];
    let parts: Vec<String> = parts.into_iter().filter(|p| !p.is_empty()).collect();
    parts.join(", ")
}

/// The run's cells and markers for `field`; `None` for a run that is not 2D or has nothing
/// to draw.
fn layer(run: &RunSummary, field: &str) -> Option<Layer> {
    if run.dim != 2 {
        return None;
    }
    let layer = if let Some(state) = &run.final_state {
        particles(state, field)?
    } else if let Some(r) = run.unstepped.elements() {
        elements(r, field)?
    } else {
        shape_function(run.unstepped.shape_functions()?, field)?
    };
    (!layer.cells.is_empty()).then_some(layer)
}

/// How `field` is labelled and coloured for a run of its kind.
fn labels(run: &RunSummary, field: &str) -> Option<Labels> {
    if run.final_state.is_some() {
        let (quantity, unit) = particle_quantity(field)?;
        return Some(Labels {
            x: "x (m)".into(),
            y: "y (m)".into(),
            value: format!("{quantity} ({unit})"),
            what: quantity,
            markers: String::new(),
            palette: Palette::Viridis,
        });
    }
    if let Some(r) = run.unstepped.elements() {
        let (quantity, what, palette) = match field {
            "reconstructed" => ("u^h", "the element-wise fit of", Palette::Viridis),
            "error" => (
                "u - u^h",
                "the error of the element-wise fit of",
                Palette::BlueWhiteRed,
            ),
            _ => return None,
        };
        return Some(Labels {
            x: "x (dimensionless)".into(),
            y: "y (dimensionless)".into(),
            value: format!("{quantity} (dimensionless)"),
            what: format!("{quantity}, {what} u = {}", r.formula),
            markers: "data points".into(),
            palette,
        });
    }
    run.unstepped.shape_functions()?;
    let (quantity, unit, palette) = match field {
        "value" => ("N_a", "dimensionless", Palette::Viridis),
        "gradient_x" => ("dN_a/dx", "1/h", Palette::BlueWhiteRed),
        "gradient_y" => ("dN_a/dy", "1/h", Palette::BlueWhiteRed),
        _ => return None,
    };
    Some(Labels {
        x: "(x - x_a) / h".into(),
        y: "(y - y_a) / h".into(),
        value: format!("{quantity} ({unit})"),
        what: format!("{quantity} of the centre node a"),
        markers: "node a".into(),
        palette,
    })
}

/// `stress_yy` is ("stress yy", "Pa"): a particle field's words and unit.
fn particle_quantity(field: &str) -> Option<(String, &'static str)> {
    let (quantity, component) = field.split_once('_').unwrap_or((field, ""));
    let unit = match quantity {
        "displacement" => "m",
        "velocity" => "m/s",
        "stress" => "Pa",
        // Mass per area in 2D.
        "density" => "kg/m^2",
        _ => return None,
    };
    let words = if component.is_empty() {
        quantity.to_string()
    } else {
        format!("{quantity} {component}")
    };
    Some((words, unit))
}

/// Each particle a square of its current area at its current position.
fn particles(state: &ParticleState, field: &str) -> Option<Layer> {
    let d = state.dim;
    let (quantity, component) = field.split_once('_').unwrap_or((field, ""));
    let axes: Vec<usize> = component
        .chars()
        .map(|c| AXIS_NAMES.find(c).filter(|&k| k < d))
        .collect::<Option<_>>()?;
    let value: Box<dyn Fn(usize) -> f64 + '_> = match (quantity, axes.as_slice()) {
        ("displacement", &[k]) => Box::new(move |p| state.x[p * d + k] - state.x0[p * d + k]),
        ("velocity", &[k]) => Box::new(move |p| state.velocity[p * d + k]),
        ("stress", &[i, j]) => Box::new(move |p| state.stress[(p * d + i) * d + j]),
        ("density", &[]) => Box::new(|p| state.density[p]),
        _ => return None,
    };
    let cells = (0..state.len())
        .map(|p| {
            let side = state.volume[p].sqrt();
            Cell {
                x: state.x[p * d],
                y: state.x[p * d + 1],
                width: side,
                height: side,
                value: value(p),
            }
        })
        .collect();
    Some(Layer {
        cells,
        markers: Vec::new(),
        time: Some(state.time),
        note: String::new(),
    })
}

/// The fit (or its error) at the map samples, the data points over it.
fn elements(r: &ElementRecord, field: &str) -> Option<Layer> {
    let values: Vec<f64> = match field {
        "reconstructed" => r.map_reconstructed.clone(),
        "error" => r
            .map_exact
            .iter()
            .zip(&r.map_reconstructed)
            .map(|(u, uh)| u - uh)
            .collect(),
        _ => return None,
    };
    let points: Vec<(f64, f64)> = r.map_x.chunks(2).map(|p| (p[0], p[1])).collect();
    let markers = r.data_x.chunks(2).map(|p| (p[0], p[1])).collect();
    Some(Layer {
        cells: lattice_cells(&points, &values),
        markers,
        time: None,
        note: format!("RMS {}", general(r.rms, 3)),
    })
}

/// N_a of the centre node, or a component of its gradient, at every point, relative to the
/// node (h = 1 on the benchmark's grid).
fn shape_function(r: &ShapeFunctionRecord, field: &str) -> Option<Layer> {
    let (nn, c) = (r.node_count(), r.centre as usize);
    let component = match field {
        "value" => None,
        "gradient_x" => Some(0),
        "gradient_y" => Some(1),
        _ => return None,
    };
    let xa = (*r.node_x.get(2 * c)?, *r.node_x.get(2 * c + 1)?);
    let points: Vec<(f64, f64)> = r.x.chunks(2).map(|p| (p[0] - xa.0, p[1] - xa.1)).collect();
    let values: Vec<f64> = (0..r.point_count())
        .map(|p| match component {
            None => r.value[p * nn + c],
            Some(k) => r.gradient[(p * nn + c) * 2 + k],
        })
        .collect();
    Some(Layer {
        cells: lattice_cells(&points, &values),
        markers: vec![(0.0, 0.0)],
        time: None,
        note: String::new(),
    })
}

/// Points of a regular lattice as cells as wide and high as its spacing in x and y.
fn lattice_cells(points: &[(f64, f64)], values: &[f64]) -> Vec<Cell> {
    let width = spacing(points.iter().map(|p| p.0));
    let height = spacing(points.iter().map(|p| p.1));
    points
        .iter()
        .zip(values)
        .map(|(&(x, y), &value)| Cell {
            x,
            y,
            width,
            height,
            value,
        })
        .collect()
}

/// The smallest distance between distinct coordinates, telling apart those that differ by
/// more than rounding of the largest; 1 when all are equal.
fn spacing(coords: impl Iterator<Item = f64>) -> f64 {
    let mut sorted: Vec<f64> = coords.collect();
    sorted.sort_by(f64::total_cmp);
    let size = sorted
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|&gap| gap > 1e-9 * size)
        .fold(None, |m: Option<f64>, gap| {
            Some(m.map_or(gap, |m| m.min(gap)))
        })
        .unwrap_or(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::benchmarks::BenchmarkKind;
    use crate::output::map_fields;

    #[test]
    fn lattice_spacing_ignores_rounding() {
        let coords = [0.0, 0.1, 0.2 + 1e-17, 0.30000000000000004, 0.1, 0.0];
        assert!((spacing(coords.into_iter()) - 0.1).abs() < 1e-15);
        assert_eq!(spacing([2.0, 2.0].into_iter()), 1.0);
    }

    fn state() -> ParticleState {
        ParticleState {
            dim: 2,
            time: 1.5,
            x0: vec![0.5, 0.5, 1.5, 0.5],
            x: vec![0.5, 0.4, 1.5, 0.45],
            velocity: vec![0.0, -1.0, 0.0, -2.0],
            stress: vec![1.0, 2.0, 2.0, -3.0, 5.0, 6.0, 6.0, -7.0],
            density: vec![10.0, 11.0],
            volume: vec![0.81, 1.0],
        }
    }

    /// Every particle field has a value per particle and a label, and the squares take the
    /// particles' areas.
    #[test]
    fn particle_fields_pick_their_components() {
        let s = state();
        let values = |field: &str| -> Vec<f64> {
            particles(&s, field)
                .unwrap()
                .cells
                .iter()
                .map(|c| c.value)
                .collect()
        };
        for field in map_fields(BenchmarkKind::Simulation) {
            assert_eq!(values(field).len(), 2, "{field}");
            assert!(particle_quantity(field).is_some(), "{field}");
        }
        assert_eq!(values("stress_yy"), [-3.0, -7.0]);
        assert_eq!(values("stress_xy"), [2.0, 6.0]);
        assert_eq!(values("velocity_y"), [-1.0, -2.0]);
        let dy = values("displacement_y");
        assert!((dy[0] + 0.1).abs() < 1e-15 && (dy[1] + 0.05).abs() < 1e-15);
        assert_eq!(
            particle_quantity("stress_yy"),
            Some(("stress yy".to_string(), "Pa"))
        );
        let cells = particles(&s, "density").unwrap().cells;
        assert_eq!((cells[0].width, cells[0].height), (0.9, 0.9));
        assert_eq!((cells[1].x, cells[1].y), (1.5, 0.45));
        assert!(particles(&s, "stress_zz").is_none());
    }

    /// The centre node's N_a and dN_a/dx at a 2 x 2 lattice, relative to the node.
    #[test]
    fn shape_maps_centre_on_the_node() {
        let r = ShapeFunctionRecord {
            basis: "linear".into(),
            dim: 2,
            gamma: f64::NAN,
            x: vec![0.5, 0.5, 1.0, 0.5, 0.5, 1.0, 1.0, 1.0],
            nodes: vec![4, 5],
            centre: 0,
            node_x: vec![1.0, 1.0, 2.0, 1.0],
            value: vec![0.25, 0.0, 0.5, 0.0, 0.5, 0.0, 1.0, 0.0],
            gradient: (0..16).map(f64::from).collect(),
            ..Default::default()
        };
        for field in map_fields(BenchmarkKind::ShapeFunctions) {
            assert!(shape_function(&r, field).is_some(), "{field}");
        }
        let layer = shape_function(&r, "value").unwrap();
        assert_eq!(layer.markers, [(0.0, 0.0)]);
        let first = layer.cells[0];
        assert_eq!(
            (first.x, first.y, first.width, first.height),
            (-0.5, -0.5, 0.5, 0.5)
        );
        let values: Vec<f64> = layer.cells.iter().map(|c| c.value).collect();
        assert_eq!(values, [0.25, 0.5, 0.5, 1.0]);
        let dx = shape_function(&r, "gradient_x").unwrap();
        let dx: Vec<f64> = dx.cells.iter().map(|c| c.value).collect();
        assert_eq!(dx, [0.0, 4.0, 8.0, 12.0]);
    }

    #[test]
    fn element_maps_draw_the_fit_or_its_error() {
        let r = ElementRecord {
            dim: 2,
            rms: 0.5,
            data_x: vec![0.25, 0.75],
            map_x: vec![0.25, 0.25, 0.75, 0.25],
            map_exact: vec![1.0, 2.0],
            map_reconstructed: vec![0.5, 2.5],
            ..Default::default()
        };
        for field in map_fields(BenchmarkKind::Elementwise) {
            assert!(elements(&r, field).is_some(), "{field}");
        }
        let fit = elements(&r, "reconstructed").unwrap();
        assert_eq!(fit.markers, [(0.25, 0.75)]);
        assert_eq!(fit.note, "RMS 0.5");
        let error: Vec<f64> = elements(&r, "error")
            .unwrap()
            .cells
            .iter()
            .map(|c| c.value)
            .collect();
        assert_eq!(error, [0.5, -0.5]);
    }
}
