//! Draws a figure to PNG with plotters: log-log convergence plots, linear plots of
//! reconstructed functions and stability limits, and log-linear error histories. Text uses the embedded DejaVu font, so rendering needs no system
//! fonts and gives the same bytes on every machine.

use std::io;
use std::path::Path;
use std::sync::Once;

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

use super::figures::{Figure, Marker, Scale, Series};
use super::fit::min_max;
use super::format::general;

/// Width and height of the axes part of the image; the legend adds rows below it, so many
/// curves make a taller image rather than squeezed axes.
const WIDTH: u32 = 800;
const AXES_HEIGHT: u32 = 530;
const MARGIN: u32 = 20;
const Y_LABEL_AREA: u32 = 80;
const LEGEND_ROW: u32 = 24;
/// Labels longer than this (about 300 px at 16 px) would run into the next column.
const LEGEND_COLUMN_CHARS: usize = 34;
const FONT: &str = "sans-serif";
/// Colour-blind-safe qualitative palette (Okabe-Ito, grey for its yellow, which is too pale
/// on white), cycled when curves outnumber it.
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(120, 120, 120),
];
/// Half the side of a square marker and the radius of a circle, in pixels.
const MARKER_SIZE: i32 = 4;

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded fonts are valid TrueType files, so registration cannot fail.
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Writes `figure` as a PNG: each series' markers and its line (dashed for fits), with the
/// legend below the axes so it never hides data.
pub fn render(path: &Path, figure: &Figure) -> io::Result<()> {
    register_fonts();
    draw(path, figure).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn std::error::Error>>;

fn draw(path: &Path, figure: &Figure) -> DrawResult {
    let columns = legend_columns(figure);
    let rows = figure.series.len().div_ceil(columns) as u32;
    let height = AXES_HEIGHT + rows * LEGEND_ROW + MARGIN / 2;
    let root = BitMapBackend::new(path, (WIDTH, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let (axes, legend) = root.split_vertically(AXES_HEIGHT);
    draw_axes(&axes, figure)?;
    draw_legend(&legend, figure, columns)?;
    root.present()?;
    Ok(())
}

fn draw_axes(area: &Area, figure: &Figure) -> DrawResult {
    let data: Vec<(f64, f64)> = figure
        .series
        .iter()
        .flat_map(|s| s.markers.iter().chain(&s.line).copied())
        .collect();
    let xs = data.iter().map(|p| p.0);
    let ys = data.iter().map(|p| p.1);
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(&figure.title, (FONT, 22).into_font().style(FontStyle::Bold))
        .margin(MARGIN)
        .x_label_area_size(55)
        .y_label_area_size(Y_LABEL_AREA);
    match figure.scale {
        Scale::LogLog => {
            let (x_lo, x_hi) = padded_log_range(xs);
            let (y_lo, y_hi) = padded_log_range(ys);
            let (x_major, x_minor) = log_ticks(x_lo, x_hi);
            let (y_major, y_minor) = log_ticks(y_lo, y_hi);
            let chart = builder.build_cartesian_2d(
                (x_lo..x_hi)
                    .log_scale()
                    .with_key_points(x_major)
                    .with_light_points(x_minor),
                (y_lo..y_hi)
                    .log_scale()
                    .with_key_points(y_major)
                    .with_light_points(y_minor),
            )?;
            let label = |v: &f64| tick_label(*v);
            draw_series(chart, figure, &label, &label)
        }
        Scale::Linear => {
            let x_range = padded_linear_range(xs);
            let y_range = padded_linear_range(ys);
            let chart: ChartContext<_, Cartesian2d<RangedCoordf64, RangedCoordf64>> =
                builder.build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)?;
            let x_label = |v: &f64| linear_tick_label(*v, x_range);
            let y_label = |v: &f64| linear_tick_label(*v, y_range);
            draw_series(chart, figure, &x_label, &y_label)
        }
        Scale::LogY => {
            let x_range = padded_linear_range(xs);
            let (y_lo, y_hi) = padded_log_range(ys);
            let (y_major, y_minor) = log_ticks(y_lo, y_hi);
            let chart = builder.build_cartesian_2d(
                x_range.0..x_range.1,
                (y_lo..y_hi)
                    .log_scale()
                    .with_key_points(y_major)
                    .with_light_points(y_minor),
            )?;
            let x_label = |v: &f64| linear_tick_label(*v, x_range);
            let y_label = |v: &f64| tick_label(*v);
            draw_series(chart, figure, &x_label, &y_label)
        }
    }
}

/// The mesh with its labels, then every series: markers, and the line through its own points
/// (dashed for a fit: a solid line through the markers would hide it where data follow it).
fn draw_series<X, Y>(
    mut chart: ChartContext<'_, BitMapBackend<'_>, Cartesian2d<X, Y>>,
    figure: &Figure,
    x_label: &dyn Fn(&f64) -> String,
    y_label: &dyn Fn(&f64) -> String,
) -> DrawResult
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(&figure.x_label)
        .y_desc(&figure.y_label)
        .x_label_formatter(x_label)
        .y_label_formatter(y_label)
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .bold_line_style(BLACK.mix(0.25))
        .light_line_style(BLACK.mix(0.08))
        .draw()?;
    for (i, series) in figure.series.iter().enumerate() {
        let style = curve_style(i, series);
        if series.dashed {
            chart.draw_series(DashedLineSeries::new(series.line.clone(), 8, 5, style))?;
        } else if !series.line.is_empty() {
            chart.draw_series(LineSeries::new(series.line.clone(), style))?;
        }
        let points = series.markers.iter().copied();
        match series.marker {
            Marker::Circle => {
                chart.draw_series(points.map(|p| Circle::new(p, MARKER_SIZE, style)))?;
            }
            Marker::Square => {
                chart.draw_series(points.map(|p| EmptyElement::at(p) + square((0, 0), style)))?;
            }
            Marker::Cross => {
                chart.draw_series(points.map(|p| Cross::new(p, 2 * MARKER_SIZE, style)))?;
            }
        }
    }
    Ok(())
}

/// A square marker centred on `c` in pixels.
fn square(c: (i32, i32), style: ShapeStyle) -> Rectangle<(i32, i32)> {
    let s = MARKER_SIZE;
    Rectangle::new([(c.0 - s, c.1 - s), (c.0 + s, c.1 + s)], style)
}

fn legend_columns(figure: &Figure) -> usize {
    let longest = figure.series.iter().map(|c| c.label.chars().count()).max();
    if longest.unwrap_or(0) > LEGEND_COLUMN_CHARS {
        1
    } else {
        2
    }
}

/// Legend entries in columns aligned with the plot's left edge, filled row by row.
fn draw_legend(area: &Area, figure: &Figure, columns: usize) -> DrawResult {
    let left = (MARGIN + Y_LABEL_AREA) as i32;
    let column_width = (WIDTH - MARGIN - Y_LABEL_AREA - MARGIN) as i32 / columns as i32;
    let font = TextStyle::from((FONT, 16).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (i, series) in figure.series.iter().enumerate() {
        let style = curve_style(i, series);
        let x = left + (i % columns) as i32 * column_width;
        let y = ((i / columns) as u32 * LEGEND_ROW + LEGEND_ROW / 2) as i32;
        draw_glyph(area, series, (x, y), style)?;
        area.draw(&Text::new(series.label.clone(), (x + 34, y), font.clone()))?;
    }
    Ok(())
}

/// A short line where the series has one, broken by its marker where it has markers.
fn draw_glyph(area: &Area, series: &Series, (x, y): (i32, i32), style: ShapeStyle) -> DrawResult {
    let segment = |from: i32, to: i32| PathElement::new([(x + from, y), (x + to, y)], style);
    if !series.line.is_empty() {
        area.draw(&segment(0, 7))?;
        area.draw(&segment(17, 24))?;
    }
    match (series.markers.is_empty(), series.marker) {
        (true, _) => area.draw(&segment(7, 17))?,
        (false, Marker::Circle) => area.draw(&Circle::new((x + 12, y), MARKER_SIZE, style))?,
        (false, Marker::Square) => area.draw(&square((x + 12, y), style))?,
        (false, Marker::Cross) => area.draw(&Cross::new((x + 12, y), 2 * MARKER_SIZE, style))?,
    }
    Ok(())
}

fn curve_style(index: usize, series: &Series) -> ShapeStyle {
    let colour = if series.neutral {
        PALETTE[PALETTE.len() - 1]
    } else {
        PALETTE[index % PALETTE.len()]
    };
    colour.filled().stroke_width(2)
}

/// The data range widened by a tenth of its log span on each side (at least a tenth of a
/// decade), so markers never sit on the frame; a single value still gets a visible range.
fn padded_log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = min_max(values);
    let pad = ((hi / lo).log10() * 0.1).max(0.1);
    (lo / 10f64.powf(pad), hi * 10f64.powf(pad))
}

/// The finite data range widened by 5 % on each side; a range flat to rounding (a reproduced
/// constant) is widened to +/- 10 % of its value, or +/- 0.1 around 0.
fn padded_linear_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = min_max(values.filter(|v| v.is_finite()));
    // No finite value at all: any range will do.
    if lo > hi {
        return (0.0, 1.0);
    }
    let size = lo.abs().max(hi.abs());
    if hi - lo <= 1e-9 * size.max(1e-300) {
        let pad = if size > 0.0 { 0.1 * size } else { 0.1 };
        return (lo - pad, hi + pad);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// A linear tick: three significant digits, and 0 for a tick that is zero up to rounding.
fn linear_tick_label(v: f64, (lo, hi): (f64, f64)) -> String {
    if v.abs() <= 1e-9 * (hi - lo) {
        "0".into()
    } else {
        general(v, 3)
    }
}

/// Labelled ticks and unlabelled grid lines for a log axis over [lo, hi]. Powers of ten are
/// labelled when at least three fall in range; otherwise 2x and 5x multiples too, and
/// failing that every multiple, so a short axis still carries at least two labels.
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let first = lo.log10().floor() as i32;
    let last = hi.log10().ceil() as i32;
    let grid: Vec<(u32, f64)> = (first..=last)
        .flat_map(|k| (1..=9).map(move |m| (m, f64::from(m) * 10f64.powi(k))))
        .filter(|&(_, v)| v >= lo && v <= hi)
        .collect();
    let pick = |mantissas: &[u32]| -> Vec<f64> {
        grid.iter()
            .filter(|(m, _)| mantissas.contains(m))
            .map(|&(_, v)| v)
            .collect()
    };
    let decades = pick(&[1]);
    let one_two_five = pick(&[1, 2, 5]);
    let major = if decades.len() >= 3 {
        decades
    } else if one_two_five.len() >= 2 {
        one_two_five
    } else {
        grid.iter().map(|&(_, v)| v).collect()
    };
    let minor = grid
        .iter()
        .map(|&(_, v)| v)
        .filter(|v| !major.contains(v))
        .collect();
    (major, minor)
}

/// `m·10^k` written compactly: `1e-2`, `5e-3`.
fn tick_label(v: f64) -> String {
    let k = (v.log10() + 1e-9).floor() as i32;
    let m = (v / 10f64.powi(k)).round();
    if m == 1.0 {
        format!("1e{k}")
    } else {
        format!("{m}e{k}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(ticks: &[f64]) -> Vec<String> {
        ticks.iter().map(|&v| tick_label(v)).collect()
    }

    #[test]
    fn wide_ranges_label_decades_only() {
        let (major, minor) = log_ticks(3e-4, 0.2);
        assert_eq!(labels(&major), ["1e-3", "1e-2", "1e-1"]);
        let (major, _) = log_ticks(3e-3, 0.2);
        assert_eq!(
            labels(&major),
            ["5e-3", "1e-2", "2e-2", "5e-2", "1e-1", "2e-1"]
        );
        assert!(minor.len() > 10);
    }

    #[test]
    fn narrow_ranges_label_multiples() {
        let (major, _) = log_ticks(0.012, 0.14);
        assert_eq!(labels(&major), ["2e-2", "5e-2", "1e-1"]);
        let (major, _) = log_ticks(0.025, 0.15);
        assert_eq!(labels(&major), ["5e-2", "1e-1"]);
        let (major, _) = log_ticks(0.021, 0.045);
        assert_eq!(labels(&major), ["3e-2", "4e-2"]);
    }

    #[test]
    fn padding_keeps_points_inside() {
        let (lo, hi) = padded_log_range([0.5, 0.5].into_iter());
        assert!(lo < 0.5 && hi > 0.5);
        let (lo, hi) = padded_linear_range([1.0, 1.0 + 1e-16].into_iter());
        assert!(lo < 0.95 && hi > 1.05, "{lo} {hi}");
        assert_eq!(padded_linear_range([0.0, 0.0].into_iter()), (-0.1, 0.1));
        let (lo, hi) = padded_linear_range([-1.0, f64::NAN, 1.0].into_iter());
        assert!((lo + 1.1).abs() < 1e-12 && (hi - 1.1).abs() < 1e-12);
    }

    #[test]
    fn linear_ticks_hide_rounding() {
        assert_eq!(linear_tick_label(2.7e-17, (-1.0, 1.0)), "0");
        assert_eq!(linear_tick_label(0.25, (-1.0, 1.0)), "0.25");
    }
}
