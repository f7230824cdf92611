//! Figures of one reconstruction run each: u with its reconstructed nodal values and the data
//! (Gong Figs 4.1-4.6, 5.1-5.2), u with each element's fit (Wobbes Figs 1-2), and the
//! weighted orthogonal basis (Tran Figs 1-3).

use super::{default_stem, Figure, Marker, Scale, Series};
use crate::output::{ReconstructionRecord, RunSummary};
use crate::params::ParamValue;
use crate::report::format::general;
use crate::report::group::label;

/// u(x) as a line, u^h at the nodes as circles, the data (x_p, u_p) as squares.
pub(super) fn reconstructions(runs: &[&RunSummary]) -> Vec<Figure> {
    with_record(runs, |run, r| {
        let nodes: Vec<(f64, f64)> = pairs(&r.x, &r.reconstructed)
            .filter(|p| p.1.is_finite())
            .collect();
        let series = vec![
            Series::line(
                format!("u = {}", r.formula),
                pairs(&r.curve_x, &r.curve_u).collect(),
            ),
            Series::markers("u^h at the nodes".into(), Marker::Circle, nodes),
            Series::markers(
                "data points (x_p, u_p)".into(),
                Marker::Square,
                pairs(&r.data_x, &r.data_u).collect(),
            ),
        ];
        Figure {
            file: default_stem(&format!("reconstruction_{}", label(&run.axes))),
            title: title(&format!("{}: u = {}", run.method, r.formula), run),
            variant: pairs_of(run),
            x_label: "x (dimensionless)".into(),
            y_label: "u (dimensionless)".into(),
            scale: Scale::Linear,
            series,
            notes: Vec::new(),
            drawn_by: None,
        }
    })
}

/// u as a line, each element's fit u^h as a line of its own (with the degree it settled on),
/// and the data as squares: along x in 1D; in 2D along the line y = const through the middle
/// of the middle row of elements, with the data on that line.
pub(super) fn element_fits(runs: &[&RunSummary]) -> Vec<Figure> {
    runs.iter()
        .filter_map(|run| {
            let r = run.unstepped.elements()?;
            let d = r.dim;
            // The height of the samples in 2D; every sample of a 1D run is on the line.
            let level = (d == 2).then(|| r.curve_x.get(1).copied()).flatten();
            let on_line =
                |x: &[f64]| level.is_none_or(|y| (x[1] - y).abs() <= 1e-12 * y.abs().max(1.0));
            let curve: Vec<(f64, i64, f64, f64)> = (0..r.curve_exact.len())
                .map(|c| {
                    (
                        r.curve_x[c * d],
                        r.curve_element[c],
                        r.curve_exact[c],
                        r.curve_reconstructed[c],
                    )
                })
                .collect();
            let mut series = vec![Series::line(
                format!("u = {}", r.formula),
                curve.iter().map(|c| (c.0, c.2)).collect(),
            )];
            let mut elements: Vec<i64> = curve.iter().map(|c| c.1).collect();
            elements.dedup();
            for e in elements {
                let k = e as usize;
                let degree = r.element_degree.get(k).copied().unwrap_or_default();
                let (a, b) = (r.lower[k * d], r.upper[k * d]);
                series.push(Series::line(
                    format!(
                        "u^h on [{}, {}], degree {degree}",
                        general(a, 4),
                        general(b, 4)
                    ),
                    curve
                        .iter()
                        .filter(|c| c.1 == e)
                        .map(|c| (c.0, c.3))
                        .collect(),
                ));
            }
            let data = r
                .data_x
                .chunks(d.max(1))
                .zip(&r.data_u)
                .filter(|(x, _)| on_line(x))
                .map(|(x, &u)| (x[0], u))
                .collect();
            series.push(Series::markers("data points".into(), Marker::Square, data));
            let elements = r.element_degree.len();
            let at = match level {
                Some(y) => format!(" at y = {}", general(y, 4)),
                None => String::new(),
            };
            Some(Figure {
                file: default_stem(&format!("elements_{}", label(&run.axes))),
                title: format!("{}: u = {}{at}, {elements} elements", run.method, r.formula),
                variant: pairs_of(run),
                x_label: "x (dimensionless)".into(),
                y_label: "u (dimensionless)".into(),
                scale: Scale::Linear,
                series,
                notes: Vec::new(),
                drawn_by: None,
            })
        })
        .filter(|figure| figure.series.iter().any(|s| !s.line.is_empty()))
        .collect()
}

/// p_1 .. p_m as lines with the data points on them; a dropped polynomial says so.
pub(super) fn bases(runs: &[&RunSummary]) -> Vec<Figure> {
    with_record(runs, |run, r| {
        let basis = r.basis.as_ref()?;
        let (np, nc) = (r.data_x.len(), r.curve_x.len());
        let series = (0..basis.terms)
            .map(|i| {
                let dropped = if basis.kept[i] == 0 { ", dropped" } else { "" };
                Series {
                    label: format!(
                        "p{} (<p{0},p{0}> = {}{dropped})",
                        i + 1,
                        general(basis.norms[i], 3)
                    ),
                    markers: pairs(&r.data_x, &basis.data_p[i * np..(i + 1) * np]).collect(),
                    marker: Marker::Circle,
                    line: pairs(&r.curve_x, &basis.curve_p[i * nc..(i + 1) * nc]).collect(),
                    dashed: false,
                    fit: Vec::new(),
                    neutral: false,
                }
            })
            .collect();
        Some(Figure {
            file: default_stem(&format!("basis_{}", label(&run.axes))),
            variant: pairs_of(run),
            title: format!(
                "x_p = {}: {} weight at {}",
                short_list(&r.data_x),
                r.weight,
                general(basis.centre, 4)
            ),
            x_label: "x (dimensionless)".into(),
            y_label: "p_i(x) (dimensionless)".into(),
            scale: Scale::Linear,
            series,
            notes: Vec::new(),
            drawn_by: None,
        })
    })
}

/// `draw` for every run that recorded a reconstruction; runs without one are left out.
fn with_record<F, R>(runs: &[&RunSummary], mut draw: F) -> Vec<Figure>
where
    F: FnMut(&RunSummary, &ReconstructionRecord) -> R,
    R: Into<Option<Figure>>,
{
    runs.iter()
        .filter_map(|run| {
            let record = run.unstepped.reconstruction()?;
            draw(run, record).into()
        })
        .filter(|figure| {
            figure
                .series
                .iter()
                .any(|s| !s.markers.is_empty() || !s.line.is_empty())
        })
        .collect()
}

fn pairs<'a>(x: &'a [f64], y: &'a [f64]) -> impl Iterator<Item = (f64, f64)> + 'a {
    x.iter().copied().zip(y.iter().copied())
}

/// `what`, then the run's other axes in parentheses (numbers to 4 digits, so the title fits).
fn title(what: &str, run: &RunSummary) -> String {
    let others: Vec<String> = run
        .axes
        .iter()
        .filter(|(key, _)| !["method", "function"].contains(&key.as_str()))
        .map(|(key, value)| match value {
            ParamValue::Float(x) => format!("{key}={}", general(*x, 4)),
            ParamValue::List(values) => format!("{key}=[{}]", short_list(values)),
            _ => format!("{key}={value}"),
        })
        .collect();
    if others.is_empty() {
        what.to_string()
    } else {
        format!("{what} ({})", others.join(" "))
    }
}

fn short_list(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|&x| general(x, 4)).collect();
    items.join(", ")
}

/// A run's axis values, which tell its figure from the other runs', lists of points to four
/// digits so that a file named by them stays short.
fn pairs_of(run: &RunSummary) -> Vec<(String, String)> {
    run.axes
        .iter()
        .map(|(k, v)| match v {
            ParamValue::List(values) => (k.clone(), short_list(values)),
            _ => (k.clone(), v.to_string()),
        })
        .collect()
}
