//! Draws a field map to PNG: its panels in rows of up to four, each a filled rectangle per
//! cell on axes of one scale in x and y (so shapes are not distorted and panels compare), the
//! markers over them, and one colour bar for all panels on the right.

use std::io;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

use super::figures::{FieldMap, Panel};
use super::fit::min_max;
use super::plot::{caption_size, linear_tick_label, png, register_fonts, FONT};

/// The plotting area of a panel along the longer side of the domain, in pixels.
const PANEL_SIDE: u32 = 300;
const MAX_COLUMNS: usize = 4;
/// The narrowest image, so that the caption fits; narrower content is centred in it.
const MIN_WIDTH: u32 = 900;
/// Around the image, and around each panel's axes.
const MARGIN: u32 = 20;
const PANEL_MARGIN: u32 = 12;
const PANEL_LABEL: u32 = 26;
const X_LABEL_AREA: u32 = 50;
const Y_LABEL_AREA: u32 = 62;
/// The caption's two lines: what is drawn, then the group of runs.
const TITLE_LINE: u32 = 32;
const SCOPE_LINE: u32 = 24;
const LEGEND_ROW: u32 = 28;
/// The colour bar, the room for its ticks and its label, and the steps it is drawn in.
const BAR_WIDTH: u32 = 26;
const BAR_LABEL_AREA: u32 = 72;
const BAR_STEPS: usize = 256;
/// The radius of a marker, and of the white ring that keeps it visible on dark cells.
const MARKER_RADIUS: u32 = 2;
const RING_RADIUS: u32 = 3;
const TICKS: usize = 6;

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn std::error::Error>>;

/// Draws `map` as the bytes of a PNG, which `path` names in errors.
pub fn render(path: &Path, map: &FieldMap) -> io::Result<Vec<u8>> {
    register_fonts();
    draw(map).map_err(|e| io::Error::other(format!("{}: {e}", path.display())))
}

/// The extent of the data every panel shares, and the size of one panel's plotting area.
struct Layout {
    x: (f64, f64),
    y: (f64, f64),
    plot: (u32, u32),
    columns: usize,
    rows: usize,
}

impl Layout {
    fn of(map: &FieldMap) -> Layout {
        let cells = map.panels.iter().flat_map(|p| &p.cells);
        let xs = cells
            .clone()
            .flat_map(|c| [c.x - 0.5 * c.width, c.x + 0.5 * c.width]);
        let ys = cells.flat_map(|c| [c.y - 0.5 * c.height, c.y + 0.5 * c.height]);
        let markers = map.panels.iter().flat_map(|p| &p.markers);
        let x = padded(min_max(xs.chain(markers.clone().map(|m| m.0))));
        let y = padded(min_max(ys.chain(markers.map(|m| m.1))));
        let (sx, sy) = (x.1 - x.0, y.1 - y.0);
        let side = f64::from(PANEL_SIDE);
        let plot = if sx >= sy {
            (PANEL_SIDE, (side * sy / sx).round().max(1.0) as u32)
        } else {
            ((side * sx / sy).round().max(1.0) as u32, PANEL_SIDE)
        };
        let columns = map.panels.len().clamp(1, MAX_COLUMNS);
        Layout {
            x,
            y,
            plot,
            columns,
            rows: map.panels.len().div_ceil(columns).max(1),
        }
    }

    /// One panel's area: its label above the axes with their tick labels.
    fn panel(&self) -> (u32, u32) {
        (
            self.plot.0 + Y_LABEL_AREA + 2 * PANEL_MARGIN,
            PANEL_LABEL + self.plot.1 + X_LABEL_AREA + 2 * PANEL_MARGIN,
        )
    }

    fn caption_height(map: &FieldMap) -> u32 {
        TITLE_LINE + if map.scope.is_empty() { 0 } else { SCOPE_LINE }
    }
}

/// The range widened by 1 % on each side, so that ticks at its ends are drawn; one of zero
/// width (a single cell or marker) by 0.5.
fn padded((lo, hi): (f64, f64)) -> (f64, f64) {
    let pad = if hi > lo { 0.01 * (hi - lo) } else { 0.5 };
    (lo - pad, hi + pad)
}

fn draw(map: &FieldMap) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    let layout = Layout::of(map);
    let (panel_w, panel_h) = layout.panel();
    let caption = Layout::caption_height(map);
    let legend = if map.marker_label.is_empty() {
        0
    } else {
        LEGEND_ROW
    };
    let content = layout.columns as u32 * panel_w + BAR_WIDTH + BAR_LABEL_AREA;
    let width = (content + 2 * MARGIN).max(MIN_WIDTH);
    let left = (width - content) / 2;
    let height = MARGIN + caption + layout.rows as u32 * panel_h + legend + MARGIN / 2;
    png((width, height), |root| {
        root.fill(&WHITE)?;
        draw_caption(&root, map, width)?;
        let top = (MARGIN + caption) as i32;
        for (i, panel) in map.panels.iter().enumerate() {
            let (column, row) = ((i % layout.columns) as u32, (i / layout.columns) as u32);
            let x0 = (left + column * panel_w) as i32;
            let y0 = top + (row * panel_h) as i32;
            let area = root.clone().shrink((x0, y0), (panel_w, panel_h));
            draw_panel(&area, map, panel, &layout)?;
        }
        // The bar runs from the top of the first row's axes to the bottom of the last row's.
        let bar_top = top + (PANEL_LABEL + PANEL_MARGIN) as i32;
        let bar_height =
            layout.rows as u32 * panel_h - PANEL_LABEL - X_LABEL_AREA - 2 * PANEL_MARGIN;
        let bar_left = (left + layout.columns as u32 * panel_w) as i32;
        let bar = root.clone().shrink(
            (bar_left, bar_top),
            (BAR_WIDTH + BAR_LABEL_AREA, bar_height),
        );
        draw_colour_bar(&bar, map)?;
        if legend > 0 {
            let y = top + (layout.rows as u32 * panel_h) as i32 + (LEGEND_ROW / 2) as i32;
            draw_legend(&root, map, (left + Y_LABEL_AREA + PANEL_MARGIN) as i32, y)?;
        }
        root.present()?;
        Ok(())
    })
}

/// The title in bold, each line shrunk to fit the width, and the group below it.
fn draw_caption(root: &Area, map: &FieldMap, width: u32) -> DrawResult {
    let room = width - 2 * MARGIN;
    let centre = (width / 2) as i32;
    let bold = (FONT, caption_size(&map.title, room))
        .into_font()
        .style(FontStyle::Bold);
    let style = TextStyle::from(bold).pos(Pos::new(HPos::Center, VPos::Center));
    let y = (MARGIN + TITLE_LINE / 2) as i32 - 4;
    root.draw(&Text::new(map.title.clone(), (centre, y), style))?;
    if !map.scope.is_empty() {
        // Regular text is narrower than bold: about 0.55 em per character.
        let size = (f64::from(room) / (0.55 * map.scope.chars().count() as f64)).clamp(11.0, 16.0);
        let style =
            TextStyle::from((FONT, size).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        let y = (MARGIN + TITLE_LINE + SCOPE_LINE / 2) as i32 - 4;
        root.draw(&Text::new(map.scope.clone(), (centre, y), style))?;
    }
    Ok(())
}

fn draw_panel(area: &Area, map: &FieldMap, panel: &Panel, layout: &Layout) -> DrawResult {
    let (label_area, axes_area) = area.split_vertically(PANEL_LABEL);
    let (w, _) = label_area.dim_in_pixel();
    // Centred over the plotting area, which starts after the y tick labels.
    let centre = (PANEL_MARGIN + Y_LABEL_AREA + layout.plot.0 / 2) as i32;
    let size = (f64::from(w) / (0.55 * panel.label.chars().count() as f64)).clamp(11.0, 16.0);
    let style = TextStyle::from((FONT, size).into_font()).pos(Pos::new(HPos::Center, VPos::Bottom));
    label_area.draw(&Text::new(
        panel.label.clone(),
        (centre, PANEL_LABEL as i32 - 4),
        style,
    ))?;
    let mut chart = ChartBuilder::on(&axes_area)
        .margin(PANEL_MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(layout.x.0..layout.x.1, layout.y.0..layout.y.1)?;
    let (x_range, y_range) = (layout.x, layout.y);
    let x_tick = |v: &f64| linear_tick_label(*v, x_range);
    let y_tick = |v: &f64| linear_tick_label(*v, y_range);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(TICKS)
        .y_labels(TICKS)
        .x_desc(&map.x_label)
        .y_desc(&map.y_label)
        .x_label_formatter(&x_tick)
        .y_label_formatter(&y_tick)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()?;
    chart.draw_series(panel.cells.iter().map(|c| {
        let (hw, hh) = (0.5 * c.width, 0.5 * c.height);
        Rectangle::new(
            [(c.x - hw, c.y - hh), (c.x + hw, c.y + hh)],
            map.scale.colour(c.value).filled(),
        )
    }))?;
    for &point in &panel.markers {
        chart.draw_series([Circle::new(point, RING_RADIUS, WHITE.filled())])?;
        chart.draw_series([Circle::new(point, MARKER_RADIUS, BLACK.filled())])?;
    }
    Ok(())
}

/// The scale's colours from its low end (bottom) to its high end, with ticks and the field's
/// label on the right.
fn draw_colour_bar(area: &Area, map: &FieldMap) -> DrawResult {
    let scale = map.scale;
    let range = (scale.lo, scale.hi);
    let mut chart = ChartBuilder::on(area)
        .set_label_area_size(LabelAreaPosition::Right, BAR_LABEL_AREA)
        .build_cartesian_2d(0.0..1.0, scale.lo..scale.hi)?;
    let tick = |v: &f64| linear_tick_label(*v, range);
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(TICKS + 2)
        .y_desc(&map.value_label)
        .y_label_formatter(&tick)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()?;
    let step = (scale.hi - scale.lo) / BAR_STEPS as f64;
    chart.draw_series((0..BAR_STEPS).map(|k| {
        let lo = scale.lo + k as f64 * step;
        let mid = lo + 0.5 * step;
        Rectangle::new([(0.0, lo), (1.0, lo + step)], scale.colour(mid).filled())
    }))?;
    Ok(())
}

fn draw_legend(root: &Area, map: &FieldMap, x: i32, y: i32) -> DrawResult {
    root.draw(&Circle::new((x, y), RING_RADIUS, WHITE.filled()))?;
    root.draw(&Circle::new((x, y), MARKER_RADIUS, BLACK.filled()))?;
    let style = TextStyle::from((FONT, 15).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    root.draw(&Text::new(map.marker_label.clone(), (x + 12, y), style))?;
    Ok(())
}
