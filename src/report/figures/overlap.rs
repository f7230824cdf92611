//! Series that lie on top of each other: the later one's legend entry says which earlier
//! series hides it, so a reader never takes a hidden curve for a missing one.

use super::{Figure, Scale, Series};
use crate::report::fit::min_max;

/// Two series coincide when no pair of their points is farther apart than this fraction of
/// the y axis (about 3 pixels of the axes).
const TOLERANCE: f64 = 0.005;

/// Appends `(on top of <label>)` to each series whose points coincide with an earlier one's.
pub(super) fn mark_coincident(figure: &mut Figure) {
    let log = matches!(figure.scale, Scale::LogLog | Scale::LogY);
    let to_axis = |y: f64| if log { y.log10() } else { y };
    let (lo, hi) = min_max(
        figure
            .series
            .iter()
            .flat_map(|s| s.markers.iter().chain(&s.line))
            .map(|p| to_axis(p.1))
            .filter(|y| y.is_finite()),
    );
    // No finite point at all: nothing can hide anything. A flat figure compares exactly.
    let span = hi - lo;
    if !span.is_finite() {
        return;
    }
    let close = |a: &Series, b: &Series| {
        let same = |p: &[(f64, f64)], q: &[(f64, f64)]| {
            p.len() == q.len()
                && p.iter().zip(q).all(|(u, v)| {
                    u.0 == v.0 && (to_axis(u.1) - to_axis(v.1)).abs() <= TOLERANCE * span
                })
        };
        let drawn = |s: &Series| !s.markers.is_empty() || !s.line.is_empty();
        drawn(a) && same(&a.markers, &b.markers) && same(&a.line, &b.line)
    };
    for j in 1..figure.series.len() {
        let Some(i) = (0..j).find(|&i| close(&figure.series[i], &figure.series[j])) else {
            continue;
        };
        let under = distinct(&figure.series[i].label, &figure.series[j].label);
        figure.series[j]
            .label
            .push_str(&format!(" (on top of {under})"));
    }
}

/// The series `under` named by the comma-separated parts of its name that `own`'s name lacks
/// ("ppc=2" for "velocity, transfer=shepard, ppc=2" under "velocity, transfer=shepard, ppc=4"),
/// so that the note stays short; its whole name when every part is shared. A field's unit is
/// left out of the note, which holds no parentheses.
fn distinct(under: &str, own: &str) -> String {
    let own: Vec<&str> = name(own).split(", ").collect();
    let mut parts: Vec<&str> = name(under)
        .split(", ")
        .filter(|part| !own.contains(part))
        .collect();
    if parts.is_empty() {
        parts = name(under).split(", ").collect();
    }
    parts
        .iter()
        .map(|part| part.split(" (").next().unwrap_or(part))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A series' name: its label without the remarks that follow it, `(rate ...)` and
/// `(on top of ...)`; a field's unit, which follows the field in parentheses, stays.
fn name(label: &str) -> &str {
    let end = [" (rate ", " (on top of "]
        .iter()
        .filter_map(|remark| label.find(remark))
        .min()
        .unwrap_or(label.len());
    &label[..end]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::figures::Marker;

    fn figure(series: Vec<Series>) -> Figure {
        Figure {
            file: "f".into(),
            title: String::new(),
            variant: Vec::new(),
            x_label: String::new(),
            y_label: String::new(),
            scale: Scale::LogLog,
            series,
            notes: Vec::new(),
            drawn_by: None,
        }
    }

    #[test]
    fn a_hidden_series_names_the_one_over_it() {
        let points = |k: f64| vec![(0.1, 1.0 * k), (0.05, 0.25 * k), (0.025, 0.0625 * k)];
        let mut f = figure(vec![
            Series::markers("mpm (rate 2.00)".into(), Marker::Circle, points(1.0)),
            Series::markers("mpm_tls (rate 2.00)".into(), Marker::Square, points(1.001)),
            Series::markers("ddmpm (rate 2.00)".into(), Marker::Square, points(2.0)),
        ]);
        mark_coincident(&mut f);
        assert_eq!(f.series[0].label, "mpm (rate 2.00)");
        assert_eq!(f.series[1].label, "mpm_tls (rate 2.00) (on top of mpm)");
        assert_eq!(f.series[2].label, "ddmpm (rate 2.00)");
    }

    /// Names that share parts are told apart by the parts that differ.
    #[test]
    fn the_note_names_the_parts_that_differ() {
        let points = vec![(0.1, 1.0), (0.05, 0.25)];
        let mut f = figure(vec![
            Series::markers(
                "v, transfer=tls, ppc=2 (rate 2.00)".into(),
                Marker::Circle,
                points.clone(),
            ),
            Series::markers(
                "v, transfer=tls, ppc=4 (rate 2.00)".into(),
                Marker::Square,
                points,
            ),
        ]);
        mark_coincident(&mut f);
        assert_eq!(
            f.series[1].label,
            "v, transfer=tls, ppc=4 (rate 2.00) (on top of ppc=2)"
        );
    }

    /// A field's unit in parentheses is part of the name, not a remark, and stays out of the
    /// note.
    #[test]
    fn units_are_kept_apart_from_the_remarks() {
        let points = vec![(0.1, 1.0), (0.05, 0.25)];
        let series = |label: &str| Series::markers(label.into(), Marker::Square, points.clone());
        let mut f = figure(vec![
            series("v (m/s), method=a (rate 2.00)"),
            series("v (m/s), method=b (rate 2.00)"),
            series("u (m), method=a (rate 2.00)"),
        ]);
        mark_coincident(&mut f);
        assert_eq!(
            f.series[1].label,
            "v (m/s), method=b (rate 2.00) (on top of method=a)"
        );
        assert_eq!(
            f.series[2].label,
            "u (m), method=a (rate 2.00) (on top of v)"
        );
    }
}
