//! Draws a figure to PNG with plotters: log-log convergence plots, linear plots of
//! reconstructed functions and stability limits, and log-linear error histories. Text uses the embedded DejaVu font, so rendering needs no system
//! fonts and gives the same bytes on every machine.

use std::io;
use std::path::Path;
use std::sync::Once;

use image::codecs::png::PngEncoder;
use image::{ColorType, ImageEncoder};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::{DashedPathElement, DottedPathElement, Drawable, PointCollection};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};
use plotters_backend::{BackendCoord, DrawingErrorKind};

use super::figures::{Figure, Marker, Scale, Series};
use super::fit::min_max;
use super::format::general;
use super::style::{self, Pattern, Style};

/// Width and height of the axes part of the image; the legend adds rows below it, so many
/// curves make a taller image rather than squeezed axes.
const WIDTH: u32 = 800;
const AXES_HEIGHT: u32 = 530;
const MARGIN: u32 = 20;
const Y_LABEL_AREA: u32 = 80;
const LEGEND_ROW: u32 = 24;
/// Labels longer than this (about 300 px at 16 px) would run into the next column.
const LEGEND_COLUMN_CHARS: usize = 34;
/// Longest line of a legend entry in one column: what fits beside the glyph at its font.
const LEGEND_LINE_CHARS: usize = 78;
/// The legend's sample of a series, and where its label starts.
const GLYPH_WIDTH: i32 = 30;
const LABEL_OFFSET: i32 = 38;
pub(super) const FONT: &str = "sans-serif";
/// Half the side of a square marker and the radius of a circle, in pixels.
const MARKER_SIZE: i32 = 4;
/// Dashes and their gaps, and the spacing and radius of dots, in pixels.
const DASH: i32 = 8;
const GAP: i32 = 5;
const DOT_SPACING: i32 = 5;
const DOT_RADIUS: i32 = 1;
/// A line without markers of its own that needs them to be told apart carries this many.
const MARKS_PER_LINE: usize = 8;
/// A figure's notes under the legend: their font size, row height and the characters that
/// fit one row.
const NOTE_FONT: u32 = 14;
const NOTE_ROW: u32 = 19;
const NOTE_CHARS: usize = 95;

/// The caption's font size: 22 px, smaller for a title that would not fit `width` at 22 px
/// (DejaVu Sans Bold averages about 0.62 em per character), but never below 12 px.
pub(super) fn caption_size(title: &str, width: u32) -> f64 {
    let fitting = f64::from(width) / (0.62 * title.chars().count() as f64);
    fitting.clamp(12.0, 22.0)
}

pub(super) fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded fonts are valid TrueType files, so registration cannot fail.
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// Draws `figure` as the bytes of a PNG, which `path` names in errors: each series' markers
/// and its line in the style `style` gives it, with the legend below the axes so it never
/// hides data.
pub fn render(path: &Path, figure: &Figure) -> io::Result<Vec<u8>> {
    register_fonts();
    draw(figure).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn std::error::Error>>;

/// An RGB image of `size` drawn by `draw` into memory, encoded as PNG as plotters would write
/// it to a file; the report writes it under a temporary name (`write_report`).
pub(super) fn png(
    size: (u32, u32),
    draw: impl FnOnce(Area) -> DrawResult,
) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    let mut pixels = vec![0; 3 * size.0 as usize * size.1 as usize];
    draw(BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area())?;
    let mut png = Vec::new();
    PngEncoder::new(&mut png).write_image(&pixels, size.0, size.1, ColorType::Rgb8)?;
    Ok(png)
}

fn draw(figure: &Figure) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    let columns = legend_columns(figure);
    let labels = legend_labels(&figure.series, columns);
    let rows = match columns {
        1 => labels.iter().map(Vec::len).sum::<usize>() as u32,
        _ => figure.series.len().div_ceil(columns) as u32,
    };
    let notes: Vec<String> = figure
        .notes
        .iter()
        .flat_map(|n| wrap(n, NOTE_CHARS))
        .collect();
    let legend_height = rows * LEGEND_ROW;
    let height = AXES_HEIGHT + legend_height + notes.len() as u32 * NOTE_ROW + MARGIN / 2;
    png((WIDTH, height), |root| {
        root.fill(&WHITE)?;
        let (axes, below) = root.split_vertically(AXES_HEIGHT);
        let (legend, note_area) = below.split_vertically(legend_height);
        let styles = style::assign(&figure.series);
        draw_axes(&axes, figure, &styles)?;
        draw_legend(&legend, &labels, &styles, columns)?;
        draw_notes(&note_area, &notes)?;
        root.present()?;
        Ok(())
    })
}

fn draw_axes(area: &Area, figure: &Figure, styles: &[Style]) -> DrawResult {
    let data: Vec<(f64, f64)> = figure
        .series
        .iter()
        .flat_map(|s| s.markers.iter().chain(&s.line).chain(&s.fit).copied())
        .collect();
    let xs = data.iter().map(|p| p.0);
    let ys = data.iter().map(|p| p.1);
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(
            &figure.title,
            (FONT, caption_size(&figure.title, WIDTH - 2 * MARGIN))
                .into_font()
                .style(FontStyle::Bold),
        )
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
            draw_series(chart, figure, styles, &label, &label)
        }
        Scale::Linear => {
            let x_range = padded_linear_range(xs);
            let y_range = padded_linear_range(ys);
            let chart: ChartContext<_, Cartesian2d<RangedCoordf64, RangedCoordf64>> =
                builder.build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)?;
            let x_label = |v: &f64| linear_tick_label(*v, x_range);
            let y_label = |v: &f64| linear_tick_label(*v, y_range);
            draw_series(chart, figure, styles, &x_label, &y_label)
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
            draw_series(chart, figure, styles, &x_label, &y_label)
        }
    }
}

/// The mesh with its labels, then every series: its line, and its markers over it.
fn draw_series<X, Y>(
    mut chart: ChartContext<'_, BitMapBackend<'_>, Cartesian2d<X, Y>>,
    figure: &Figure,
    styles: &[Style],
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
    for (series, style) in figure.series.iter().zip(styles) {
        let shape = shape_style(style);
        if let (Some(pattern), false) = (style.line, series.line.is_empty()) {
            chart.draw_series([path(series.line.clone(), pattern, shape)])?;
        }
        if !series.fit.is_empty() {
            let thin = shape.stroke_width(1);
            chart.draw_series([path(series.fit.clone(), Pattern::Dashed, thin)])?;
        }
        if let Some(marker) = style.marker {
            let points = if series.markers.is_empty() {
                marks_along(&series.line)
            } else {
                series.markers.clone()
            };
            chart.draw_series(points.into_iter().map(|p| marker_at(p, marker, shape)))?;
        }
    }
    Ok(())
}

fn shape_style(style: &Style) -> ShapeStyle {
    style.rgb().filled().stroke_width(2)
}

/// A line through points of any coordinate system (data on the axes, pixels in the legend),
/// in one of the patterns.
struct Polyline<C> {
    points: Vec<C>,
    pattern: Pattern,
    style: ShapeStyle,
}

fn path<C>(points: Vec<C>, pattern: Pattern, style: ShapeStyle) -> Polyline<C> {
    Polyline {
        points,
        pattern,
        style,
    }
}

impl<'a, C> PointCollection<'a, C> for &'a Polyline<C> {
    type Point = &'a C;
    type IntoIter = &'a [C];

    fn point_iter(self) -> &'a [C] {
        &self.points
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Polyline<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        points: I,
        backend: &mut DB,
        size: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let pixels: Vec<BackendCoord> = points.collect();
        let style = self.style;
        match self.pattern {
            Pattern::Solid => backend.draw_path(pixels, &style),
            Pattern::Dashed => DashedPathElement::new(pixels.clone(), DASH, GAP, style).draw(
                pixels.into_iter(),
                backend,
                size,
            ),
            Pattern::Dotted => DottedPathElement::new(pixels.clone(), 0, DOT_SPACING, move |c| {
                Circle::new(c, DOT_RADIUS, style)
            })
            .draw(pixels.into_iter(), backend, size),
        }
    }
}

/// A marker centred on a point of any coordinate system, its shape drawn in pixels around it.
struct MarkerAt<C> {
    at: C,
    marker: Marker,
    style: ShapeStyle,
}

fn marker_at<C>(at: C, marker: Marker, style: ShapeStyle) -> MarkerAt<C> {
    MarkerAt { at, marker, style }
}

impl<'a, C> PointCollection<'a, C> for &'a MarkerAt<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;

    fn point_iter(self) -> std::iter::Once<&'a C> {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for MarkerAt<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = points.next() else {
            return Ok(());
        };
        let s = MARKER_SIZE;
        // The triangle and diamond a pixel larger, to look as big as the circle and square.
        let t = s + 1;
        let style = &self.style;
        match self.marker {
            Marker::Circle => backend.draw_circle((x, y), s.unsigned_abs(), style, true),
            Marker::Square => backend.draw_rect((x - s, y - s), (x + s, y + s), style, true),
            Marker::Triangle => {
                backend.fill_polygon([(x, y - t), (x + t, y + t), (x - t, y + t)], style)
            }
            Marker::Diamond => {
                backend.fill_polygon([(x, y - t), (x + t, y), (x, y + t), (x - t, y)], style)
            }
            Marker::Cross => {
                let c = 2 * s;
                backend.draw_line((x - c, y - c), (x + c, y + c), style)?;
                backend.draw_line((x - c, y + c), (x + c, y - c), style)
            }
        }
    }
}

/// At most `MARKS_PER_LINE` points of a line, evenly spaced along its points and including
/// both ends, for a line whose look needs markers.
fn marks_along(line: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let n = line.len();
    let marks = n.min(MARKS_PER_LINE);
    if marks < 2 {
        return line.to_vec();
    }
    (0..marks)
        .map(|k| line[k * (n - 1) / (marks - 1)])
        .collect()
}

fn legend_columns(figure: &Figure) -> usize {
    let longest = figure.series.iter().map(|c| c.label.chars().count()).max();
    if longest.unwrap_or(0) > LEGEND_COLUMN_CHARS {
        1
    } else {
        2
    }
}

/// Each series' legend entry in lines: one in two columns, whose labels are short; in one
/// column broken at spaces where it is longer than the legend is wide.
fn legend_labels(series: &[Series], columns: usize) -> Vec<Vec<String>> {
    series
        .iter()
        .map(|s| match columns {
            1 => wrap(&s.label, LEGEND_LINE_CHARS),
            _ => vec![s.label.clone()],
        })
        .collect()
}

/// Legend entries in columns aligned with the plot's left edge, filled row by row; in one
/// column an entry's further lines follow it.
fn draw_legend(
    area: &Area,
    labels: &[Vec<String>],
    styles: &[Style],
    columns: usize,
) -> DrawResult {
    let left = (MARGIN + Y_LABEL_AREA) as i32;
    let column_width = (WIDTH - MARGIN - Y_LABEL_AREA - MARGIN) as i32 / columns as i32;
    let font = TextStyle::from((FONT, 16).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let mut row = 0;
    for (i, (lines, style)) in labels.iter().zip(styles).enumerate() {
        let x = left + (i % columns) as i32 * column_width;
        if columns > 1 {
            row = (i / columns) as u32;
        }
        let y = |row: u32| (row * LEGEND_ROW + LEGEND_ROW / 2) as i32;
        draw_glyph(area, style, (x, y(row)))?;
        for line in lines {
            area.draw(&Text::new(
                line.clone(),
                (x + LABEL_OFFSET, y(row)),
                font.clone(),
            ))?;
            row += 1;
        }
    }
    Ok(())
}

/// The notes in grey, one row each, from the plot's left edge.
fn draw_notes(area: &Area, rows: &[String]) -> DrawResult {
    let left = (MARGIN + Y_LABEL_AREA) as i32;
    let font = TextStyle::from((FONT, NOTE_FONT).into_font())
        .color(&RGBColor(80, 80, 80))
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (i, row) in rows.iter().enumerate() {
        let y = (i as u32 * NOTE_ROW + NOTE_ROW / 2) as i32;
        area.draw(&Text::new(row.clone(), (left, y), font.clone()))?;
    }
    Ok(())
}

/// `text` broken at spaces into rows of at most `width` characters (a longer word is a row
/// of its own), the rows after the first indented.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut rows: Vec<String> = Vec::new();
    let mut row = String::new();
    for word in text.split_whitespace() {
        if !row.is_empty() && row.chars().count() + 1 + word.chars().count() > width {
            rows.push(std::mem::take(&mut row));
            row.push_str("  ");
        }
        if !row.trim().is_empty() {
            row.push(' ');
        }
        row.push_str(word);
    }
    if !row.trim().is_empty() {
        rows.push(row);
    }
    rows
}

/// The series' look as drawn on the axes: its line across the glyph in its pattern, its
/// marker over the middle.
fn draw_glyph(area: &Area, style: &Style, (x, y): (i32, i32)) -> DrawResult {
    let shape = shape_style(style);
    if let Some(pattern) = style.line {
        area.draw(&path(vec![(x, y), (x + GLYPH_WIDTH, y)], pattern, shape))?;
    }
    if let Some(marker) = style.marker {
        area.draw(&marker_at((x + GLYPH_WIDTH / 2, y), marker, shape))?;
    }
    Ok(())
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
pub(super) fn linear_tick_label(v: f64, (lo, hi): (f64, f64)) -> String {
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
    fn long_legend_entries_wrap_in_one_column() {
        let long =
            "v, method=a, sampled_velocity=centred, dt=1e-7 (rate 1.99) (on top of method=b)";
        let series = |label: &str| Series::markers(label.into(), Marker::Circle, vec![(1.0, 1.0)]);
        let labels = legend_labels(&[series("short"), series(long)], 1);
        assert_eq!(labels[0], ["short"]);
        assert_eq!(labels[1].len(), 2);
        assert!(labels[1]
            .iter()
            .all(|line| line.chars().count() <= LEGEND_LINE_CHARS));
        assert_eq!(
            labels[1]
                .join(" ")
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" "),
            long
        );
        assert_eq!(legend_labels(&[series(long)], 2), [[long]]);
    }

    #[test]
    fn notes_wrap_at_spaces() {
        assert_eq!(wrap("a bb ccc", 4), ["a bb", "  ccc"]);
        assert_eq!(wrap("", 4), Vec::<String>::new());
        assert_eq!(wrap("abcdefg hi", 4), ["abcdefg", "  hi"]);
    }

    #[test]
    fn linear_ticks_hide_rounding() {
        assert_eq!(linear_tick_label(2.7e-17, (-1.0, 1.0)), "0");
        assert_eq!(linear_tick_label(0.25, (-1.0, 1.0)), "0.25");
    }
}
