//! Shape-function figures (Molinos et al. Fig 3): N_a of the centre node and dN_a/dx along the
//! line through it parallel to x (in 2D the section y = y_a), one curve per run, the hat in grey.

use std::cmp::Ordering;

use super::{default_stem, Figure, Scale, Series};
use crate::experiment::FigureSpec;
use crate::output::{RunSummary, ShapeFunctionRecord};
use crate::report::format::general;
use crate::report::group::{group_runs, label, label_or_all, scoped_pairs, title_suffix};

/// The basis drawn in grey, as the reference LME tends to for large gamma.
const REFERENCE_BASIS: &str = "linear";
/// The run axis naming the basis; its runs share a figure.
const METHOD_AXIS: &str = "method";

/// Per group of the axes other than the method and `by`: a figure of N_a and one of dN_a/dx.
pub(super) fn figures(selected: &[&RunSummary], spec: &FigureSpec) -> Vec<Figure> {
    let mut drop = vec![METHOD_AXIS];
    drop.extend(spec.by.iter().map(String::as_str));
    let mut figures = Vec::new();
    for group in group_runs(selected.iter().copied(), &drop) {
        let mut runs: Vec<(&RunSummary, &ShapeFunctionRecord)> = group
            .runs
            .iter()
            .filter_map(|run| Some((*run, run.unstepped.shape_functions()?)))
            .filter(|(_, r)| r.point_count() > 0)
            .collect();
        runs.sort_by(|a, b| lme_first(a.1, b.1));
        if runs.is_empty() {
            continue;
        }
        let pairs = scoped_pairs(&group.axes, &spec.select);
        let scope = label(pairs.iter().map(|(k, v)| (k, v)));
        for (what, y_label, component) in [
            ("value", "N_a", None),
            ("gradient", "dN_a/dx (1/h)", Some(0)),
        ] {
            let series = runs
                .iter()
                .map(|(_, r)| {
                    let mut s = Series::line(curve_label(r), along_x(r, component));
                    s.neutral = r.basis == REFERENCE_BASIS;
                    s
                })
                .collect();
            let mut variant = pairs.clone();
            variant.push(("quantity".into(), what.into()));
            figures.push(Figure {
                file: default_stem(&format!("shape_functions_{what}_{}", label_or_all(&scope))),
                variant,
                title: format!(
                    "{y_label} of the centre node along y = y_a{}",
                    title_suffix(&scope)
                ),
                x_label: "(x - x_a) / h (dimensionless)".into(),
                y_label: y_label.into(),
                scale: Scale::Linear,
                series,
                notes: Vec::new(),
                drawn_by: None,
            });
        }
    }
    figures
}

/// The LME bases by gamma, then the other bases by name.
pub(super) fn lme_first(a: &ShapeFunctionRecord, b: &ShapeFunctionRecord) -> Ordering {
    let key = |r: &ShapeFunctionRecord| (r.basis != "lme", r.gamma);
    let (ka, kb) = (key(a), key(b));
    ka.0.cmp(&kb.0)
        .then(ka.1.total_cmp(&kb.1))
        .then(a.basis.cmp(&b.basis))
}

/// The basis, with gamma for LME.
pub(super) fn curve_label(r: &ShapeFunctionRecord) -> String {
    if r.gamma.is_finite() {
        format!("{} gamma = {}", r.basis, general(r.gamma, 3))
    } else {
        r.basis.clone()
    }
}

/// ((x - x_a) / h, N_a) of the centre node, or a component of grad N_a times h, at the points
/// on the line through x_a parallel to x; h = 1 on the benchmark's grid.
fn along_x(r: &ShapeFunctionRecord, component: Option<usize>) -> Vec<(f64, f64)> {
    let (d, nn, c) = (r.dim, r.node_count(), r.centre as usize);
    let xa = &r.node_x[c * d..(c + 1) * d];
    (0..r.point_count())
        .filter(|&p| (1..d).all(|k| (r.x[p * d + k] - xa[k]).abs() <= 1e-12))
        .map(|p| {
            let y = match component {
                None => r.value[p * nn + c],
                Some(k) => r.gradient[(p * nn + c) * d + k],
            };
            (r.x[p * d] - xa[0], y)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn takes_the_section_through_the_centre_node() {
        // Two nodes at (1, 1) and (2, 1), points (0, 0), (1, 1) and (2, 1).
        let r = ShapeFunctionRecord {
            basis: "linear".into(),
            dim: 2,
            gamma: f64::NAN,
            x: vec![0.0, 0.0, 1.0, 1.0, 2.0, 1.0],
            nodes: vec![8, 9],
            centre: 1,
            node_x: vec![1.0, 1.0, 2.0, 1.0],
            value: vec![0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
            gradient: (0..12).map(f64::from).collect(),
            ..Default::default()
        };
        assert_eq!(along_x(&r, None), [(-1.0, 0.0), (0.0, 1.0)]);
        assert_eq!(along_x(&r, Some(0)), [(-1.0, 6.0), (0.0, 10.0)]);
        assert_eq!(curve_label(&r), "linear");
    }
}
