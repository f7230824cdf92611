//! Draws a convergence figure to PNG with plotters. Text uses the embedded DejaVu font, so
//! rendering needs no system fonts and gives the same bytes on every machine.

use std::io;
use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

use super::figures::Figure;
use super::fit::min_max;

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

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded fonts are valid TrueType files, so registration cannot fail.
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Writes `figure` as a PNG: error against h on log-log axes, markers per curve and its
/// fitted power law dashed, with the legend below the axes so it never hides data.
pub fn render(path: &Path, figure: &Figure) -> io::Result<()> {
    register_fonts();
    draw(path, figure).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn std::error::Error>>;

fn draw(path: &Path, figure: &Figure) -> DrawResult {
    let columns = legend_columns(figure);
    let rows = figure.curves.len().div_ceil(columns) as u32;
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
        .curves
        .iter()
        .flat_map(|c| c.points.iter().copied())
        .collect();
    let (x_lo, x_hi) = padded_range(data.iter().map(|p| p.0));
    let (y_lo, y_hi) = padded_range(data.iter().map(|p| p.1));
    let (x_major, x_minor) = log_ticks(x_lo, x_hi);
    let (y_major, y_minor) = log_ticks(y_lo, y_hi);

    let mut chart = ChartBuilder::on(area)
        .caption(&figure.title, (FONT, 22).into_font().style(FontStyle::Bold))
        .margin(MARGIN)
        .x_label_area_size(55)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(
            (x_lo..x_hi)
                .log_scale()
                .with_key_points(x_major)
                .with_light_points(x_minor),
            (y_lo..y_hi)
                .log_scale()
                .with_key_points(y_major)
                .with_light_points(y_minor),
        )?;
    chart
        .configure_mesh()
        .x_desc("h (cell size)")
        .y_desc(&figure.y_label)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .bold_line_style(BLACK.mix(0.25))
        .light_line_style(BLACK.mix(0.08))
        .draw()?;

    // Markers for the runs and a dashed line for the fit: a line through the markers
    // would hide the fit wherever the data follow it.
    for (i, curve) in figure.curves.iter().enumerate() {
        let style = curve_style(i);
        chart.draw_series(curve.points.iter().map(|&p| Circle::new(p, 4, style)))?;
        if let Some(fit) = curve.fit {
            let (h_lo, h_hi) = min_max(curve.points.iter().map(|p| p.0));
            let ends = [h_lo, h_hi].map(|h| (h, fit.eval(h)));
            chart.draw_series(DashedLineSeries::new(ends, 8, 5, style))?;
        }
    }
    Ok(())
}

fn legend_columns(figure: &Figure) -> usize {
    let longest = figure.curves.iter().map(|c| c.label.chars().count()).max();
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
    for (i, curve) in figure.curves.iter().enumerate() {
        let style = curve_style(i);
        let x = left + (i % columns) as i32 * column_width;
        let y = ((i / columns) as u32 * LEGEND_ROW + LEGEND_ROW / 2) as i32;
        area.draw(
            &(EmptyElement::at((x, y))
                + PathElement::new([(0, 0), (7, 0)], style)
                + PathElement::new([(17, 0), (24, 0)], style)
                + Circle::new((12, 0), 4, style)
                + Text::new(curve.label.clone(), (34, 0), font.clone())),
        )?;
    }
    Ok(())
}

fn curve_style(index: usize) -> ShapeStyle {
    PALETTE[index % PALETTE.len()].filled().stroke_width(2)
}

/// The data range widened by a tenth of its log span on each side (at least a tenth of a
/// decade), so markers never sit on the frame; a single value still gets a visible range.
fn padded_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = min_max(values);
    let pad = ((hi / lo).log10() * 0.1).max(0.1);
    (lo / 10f64.powf(pad), hi * 10f64.powf(pad))
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
        let (lo, hi) = padded_range([0.5, 0.5].into_iter());
        assert!(lo < 0.5 && hi > 0.5);
    }
}
