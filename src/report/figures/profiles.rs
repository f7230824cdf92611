//! Figures of one reconstruction run each: u with its reconstructed nodal values and the data
//! (Gong Figs 4.1-4.6, 5.1-5.2), and the weighted orthogonal basis (Tran Figs 1-3).

use super::{Figure, Marker, Names, Scale, Series};
use crate::experiment::Experiment;
use crate::output::{ReconstructionRecord, RunSummary};
use crate::params::ParamValue;
use crate::report::format::general;
use crate::report::group::label;

/// u(x) as a line, u^h at the nodes as circles, the data (x_p, u_p) as squares.
pub(super) fn reconstructions(
    experiment: &Experiment,
    runs: &[&RunSummary],
    names: &mut Names,
) -> Vec<Figure> {
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
            file: names.file(experiment, &format!("reconstruction_{}", label(&run.axes))),
            title: title(&format!("{}: u = {}", run.method, r.formula), run),
            x_label: "x".into(),
            y_label: "u".into(),
            scale: Scale::Linear,
            series,
        }
    })
}

/// p_1 .. p_m as lines with the data points on them; a dropped polynomial says so.
pub(super) fn bases(
    experiment: &Experiment,
    runs: &[&RunSummary],
    names: &mut Names,
) -> Vec<Figure> {
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
                    neutral: false,
                }
            })
            .collect();
        Some(Figure {
            file: names.file(experiment, &format!("basis_{}", label(&run.axes))),
            title: format!(
                "x_p = {}: {} weight at {}",
                short_list(&r.data_x),
                r.weight,
                general(basis.centre, 4)
            ),
            x_label: "x".into(),
            y_label: "p_i(x)".into(),
            scale: Scale::Linear,
            series,
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
            let record = run.reconstruction.as_ref()?;
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
