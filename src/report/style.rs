//! The look of every series of a figure: colour, marker and line pattern, chosen so that no
//! two series of one figure look alike.
//!
//! Series are taken in order. The k-th series that is not neutral gets palette colour
//! k mod 7 and the marker and line its figure asked for; when an earlier series already has
//! that look, it takes the next free variant in its own colour: a series with markers the
//! next marker (circle, square, triangle, diamond, cross), then the next line pattern; a line
//! without markers the next pattern (solid, dashed, dotted), then markers along it. A fit or
//! bound (`Series::dashed`) is never solid. Only when every variant of its colour is taken
//! does a series move to the next colour. Neutral series are grey, which no other series
//! gets, and vary the same way. Every look is unique up to 35 series of markers alone, and
//! far beyond that for lines.

use plotters::style::RGBColor;

use super::figures::{Marker, Series};

/// Colour-blind-safe qualitative palette (Okabe-Ito with grey for its yellow, which is too pale
/// on white); the last entry, grey, is kept for neutral series.
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(120, 120, 120),
];
const NEUTRAL: usize = PALETTE.len() - 1;

/// Marker shapes in the order variants take them.
const MARKERS: [Marker; 5] = [
    Marker::Circle,
    Marker::Square,
    Marker::Triangle,
    Marker::Diamond,
    Marker::Cross,
];

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pattern {
    Solid,
    Dashed,
    Dotted,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Style {
    /// Index into `PALETTE`.
    pub colour: usize,
    /// At the series' markers, or for a line without markers at a few of its points.
    pub marker: Option<Marker>,
    /// `None` for a series without a line.
    pub line: Option<Pattern>,
}

impl Style {
    pub fn rgb(&self) -> RGBColor {
        PALETTE[self.colour]
    }
}

/// One style per series, in order (see the module comment for the rule).
pub fn assign(series: &[Series]) -> Vec<Style> {
    let mut taken: Vec<Style> = Vec::with_capacity(series.len());
    let mut coloured = 0;
    for s in series {
        // Its own colour first, then the others in palette order.
        let colours: Vec<usize> = if s.neutral {
            vec![NEUTRAL]
        } else {
            coloured += 1;
            (0..NEUTRAL).map(|k| (coloured - 1 + k) % NEUTRAL).collect()
        };
        let mut candidates = colours.into_iter().flat_map(|colour| {
            variants(s).map(move |(marker, line)| Style {
                colour,
                marker,
                line,
            })
        });
        let style = match candidates.clone().find(|c| !taken.contains(c)) {
            Some(free) => free,
            // Past every variant of every colour a look repeats rather than fail the figure.
            None => candidates.next().expect("every series has a variant"),
        };
        taken.push(style);
    }
    taken
}

/// The (marker, line) variants of a series, the look its figure asked for first.
fn variants(s: &Series) -> impl Iterator<Item = (Option<Marker>, Option<Pattern>)> + Clone {
    let has_line = !s.line.is_empty();
    let has_markers = !s.markers.is_empty();
    let preferred = s.marker;
    let shapes =
        std::iter::once(preferred).chain(MARKERS.into_iter().filter(move |&m| m != preferred));
    let markers: Vec<Option<Marker>> = if has_markers {
        shapes.map(Some).collect()
    } else if has_line {
        std::iter::once(None).chain(shapes.map(Some)).collect()
    } else {
        vec![None]
    };
    let patterns: Vec<Option<Pattern>> = match (has_line, s.dashed) {
        (false, _) => vec![None],
        (true, true) => vec![Some(Pattern::Dashed), Some(Pattern::Dotted)],
        (true, false) => vec![
            Some(Pattern::Solid),
            Some(Pattern::Dashed),
            Some(Pattern::Dotted),
        ],
    };
    // Markers carry a series that has them, the pattern a bare line.
    let (m, p) = (markers.len(), patterns.len());
    (0..m * p).map(move |v| {
        if has_markers {
            (markers[v % m], patterns[v / m])
        } else {
            (markers[v / p], patterns[v % p])
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line() -> Series {
        Series::line("line".into(), vec![(0.0, 1.0), (1.0, 2.0)])
    }

    fn markers() -> Series {
        Series::markers("markers".into(), Marker::Circle, vec![(0.0, 1.0)])
    }

    /// Data as markers with its fit dashed, as convergence figures draw them.
    fn fit() -> Series {
        let mut s = markers();
        s.line = vec![(0.0, 1.0), (1.0, 2.0)];
        s.dashed = true;
        s
    }

    fn neutral(mut s: Series) -> Series {
        s.neutral = true;
        s
    }

    fn assert_distinct(series: &[Series]) {
        let styles = assign(series);
        for (i, a) in styles.iter().enumerate() {
            if let Some(j) = styles[..i].iter().position(|b| b == a) {
                panic!("series {j} and {i} of {} share {a:?}", series.len());
            }
        }
    }

    #[test]
    fn no_two_series_of_a_figure_look_alike() {
        for n in 1..=35 {
            assert_distinct(&vec![markers(); n]);
            assert_distinct(&vec![line(); n]);
            assert_distinct(&vec![fit(); n]);
            // Mixed figures, with references among them.
            let mixed: Vec<Series> = (0..n)
                .map(|i| match i % 5 {
                    0 => line(),
                    1 => fit(),
                    2 => markers(),
                    3 => neutral(line()),
                    _ => {
                        let mut s = line();
                        s.dashed = true;
                        s
                    }
                })
                .collect();
            assert_distinct(&mixed);
        }
        assert_distinct(&vec![neutral(line()); 12]);
    }

    #[test]
    fn the_first_series_keep_the_look_asked_for_in_their_own_colours() {
        let mut series = vec![fit(), neutral(markers()), line()];
        series[2].marker = Marker::Square;
        let styles = assign(&series);
        let look = |colour, marker, line| Style {
            colour,
            marker,
            line,
        };
        assert_eq!(
            styles,
            [
                look(0, Some(Marker::Circle), Some(Pattern::Dashed)),
                look(NEUTRAL, Some(Marker::Circle), None),
                look(1, None, Some(Pattern::Solid)),
            ]
        );
        // The eighth fit returns to the first colour with the next marker, a line to the
        // next pattern; neither ever gets the neutral grey.
        let fits = assign(&vec![fit(); 15]);
        assert_eq!(
            fits[7],
            look(0, Some(Marker::Square), Some(Pattern::Dashed))
        );
        assert_eq!(fits[14].marker, Some(Marker::Triangle));
        let lines = assign(&vec![line(); 22]);
        assert_eq!(lines[7], look(0, None, Some(Pattern::Dashed)));
        assert_eq!(
            lines[21],
            look(0, Some(Marker::Circle), Some(Pattern::Solid))
        );
        assert!(fits.iter().chain(&lines).all(|s| s.colour != NEUTRAL));
    }

    #[test]
    fn fits_and_bounds_are_never_solid() {
        let mut bound = line();
        bound.dashed = true;
        let styles = assign(&[vec![fit(); 30], vec![bound; 30]].concat());
        assert!(styles.iter().all(|s| s.line != Some(Pattern::Solid)));
    }
}
