//! Colours of field maps: a value's colour on a scale the panels of one map share. Fields take
//! viridis (perceptually uniform, readable in grey and by the colour-blind) from their smallest
//! to their largest value; errors and derivatives, whose sign is the point, a blue-white-red
//! map centred on zero, so that white is zero and the sign reads at a glance.

use plotters::style::RGBColor;

/// Viridis (matplotlib) at nine evenly spaced stops, interpolated linearly between them.
const VIRIDIS: [RGBColor; 9] = [
    RGBColor(68, 1, 84),
    RGBColor(72, 40, 120),
    RGBColor(62, 73, 137),
    RGBColor(49, 104, 142),
    RGBColor(38, 130, 142),
    RGBColor(31, 158, 137),
    RGBColor(53, 183, 121),
    RGBColor(110, 206, 88),
    RGBColor(253, 231, 37),
];

/// ColorBrewer's RdBu at eleven stops, blue for the negative end: a diverging map with the
/// same lightness on either side of its white middle.
const BLUE_WHITE_RED: [RGBColor; 11] = [
    RGBColor(5, 48, 97),
    RGBColor(33, 102, 172),
    RGBColor(67, 147, 195),
    RGBColor(146, 197, 222),
    RGBColor(209, 229, 240),
    RGBColor(247, 247, 247),
    RGBColor(253, 219, 199),
    RGBColor(244, 165, 130),
    RGBColor(214, 96, 77),
    RGBColor(178, 24, 43),
    RGBColor(103, 0, 31),
];

/// What a value that is not a number is drawn in: a grey neither map contains.
pub const NOT_A_NUMBER: RGBColor = RGBColor(160, 160, 160);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Palette {
    Viridis,
    BlueWhiteRed,
}

/// The range of values a map's colours span, and the palette they are taken from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourScale {
    pub palette: Palette,
    pub lo: f64,
    pub hi: f64,
}

impl ColourScale {
    /// The scale of the finite `values` in `palette`: viridis over [min, max], blue-white-red
    /// over [-m, m] with m = max |v|. A range flat to rounding is widened as the line plots
    /// widen theirs, and no finite value at all gives [0, 1].
    pub fn fit(palette: Palette, values: impl IntoIterator<Item = f64>) -> ColourScale {
        let (lo, hi) = values
            .into_iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        let (lo, hi) = match palette {
            _ if lo > hi => (0.0, 1.0),
            Palette::Viridis => (lo, hi),
            Palette::BlueWhiteRed => {
                let m = lo.abs().max(hi.abs());
                (-m, m)
            }
        };
        let size = lo.abs().max(hi.abs());
        let (lo, hi) = if hi - lo <= 1e-9 * size.max(1e-300) {
            let pad = if size > 0.0 { 0.1 * size } else { 0.1 };
            (lo - pad, hi + pad)
        } else {
            (lo, hi)
        };
        ColourScale { palette, lo, hi }
    }

    /// The colour of `value`; values beyond the range take the colour of its end.
    pub fn colour(&self, value: f64) -> RGBColor {
        if !value.is_finite() {
            return NOT_A_NUMBER;
        }
        let t = ((value - self.lo) / (self.hi - self.lo)).clamp(0.0, 1.0);
        let stops: &[RGBColor] = match self.palette {
            Palette::Viridis => &VIRIDIS,
            Palette::BlueWhiteRed => &BLUE_WHITE_RED,
        };
        interpolate(stops, t)
    }
}

/// The colour at `t` in [0, 1] along evenly spaced stops.
fn interpolate(stops: &[RGBColor], t: f64) -> RGBColor {
    let span = t * (stops.len() - 1) as f64;
    let k = (span.floor() as usize).min(stops.len() - 2);
    let f = span - k as f64;
    let (a, b) = (stops[k], stops[k + 1]);
    let mix = |p: u8, q: u8| (f64::from(p) + f * (f64::from(q) - f64::from(p))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative luminance (sRGB, Rec. 709 weights) of a colour, 0 to 255.
    fn luminance(c: RGBColor) -> f64 {
        0.2126 * f64::from(c.0) + 0.7152 * f64::from(c.1) + 0.0722 * f64::from(c.2)
    }

    #[test]
    fn viridis_spans_the_values_from_min_to_max() {
        let scale = ColourScale::fit(Palette::Viridis, [-3.0, -1.0, f64::NAN, -2.0]);
        assert_eq!(
            scale,
            ColourScale {
                palette: Palette::Viridis,
                lo: -3.0,
                hi: -1.0
            }
        );
        assert_eq!(scale.colour(-3.0), VIRIDIS[0]);
        assert_eq!(scale.colour(-1.0), VIRIDIS[8]);
        assert_eq!(scale.colour(-2.0), VIRIDIS[4]);
        let signed = ColourScale::fit(Palette::Viridis, [-0.5, 2.0]);
        assert_eq!((signed.lo, signed.hi), (-0.5, 2.0));
    }

    #[test]
    fn the_diverging_map_is_centred_on_zero() {
        let scale = ColourScale::fit(Palette::BlueWhiteRed, [-0.5, 2.0, 1.0]);
        assert_eq!(
            scale,
            ColourScale {
                palette: Palette::BlueWhiteRed,
                lo: -2.0,
                hi: 2.0
            }
        );
        assert_eq!(scale.colour(0.0), BLUE_WHITE_RED[5]);
        assert_eq!(scale.colour(-2.0), BLUE_WHITE_RED[0]);
        assert_eq!(scale.colour(2.0), BLUE_WHITE_RED[10]);
        // One-signed values still put zero in the middle.
        let negative = ColourScale::fit(Palette::BlueWhiteRed, [-3.0, -1.0]);
        assert_eq!((negative.lo, negative.hi), (-3.0, 3.0));
    }

    #[test]
    fn flat_and_empty_ranges_still_span_a_range() {
        let scale = ColourScale::fit(Palette::Viridis, [2.0, 2.0 + 1e-15]);
        assert!(scale.lo < 2.0 && scale.hi > 2.0 + 1e-15, "{scale:?}");
        for palette in [Palette::Viridis, Palette::BlueWhiteRed] {
            let zero = ColourScale::fit(palette, [0.0]);
            assert_eq!((zero.lo, zero.hi), (-0.1, 0.1));
            let none = ColourScale::fit(palette, [f64::NAN, f64::INFINITY]);
            assert_eq!((none.lo, none.hi), (0.0, 1.0));
            assert_eq!(none.colour(f64::NAN), NOT_A_NUMBER);
        }
    }

    #[test]
    fn colours_clamp_and_interpolate_between_stops() {
        let scale = ColourScale::fit(Palette::Viridis, [0.0, 8.0]);
        assert_eq!(scale.colour(-1.0), VIRIDIS[0]);
        assert_eq!(scale.colour(9.0), VIRIDIS[8]);
        // Halfway between stops 0 and 1: the rounded mean of each channel.
        assert_eq!(scale.colour(0.5), RGBColor(70, 21, 102));
    }

    /// Viridis grows lighter from end to end, and the diverging map is lightest in its middle
    /// and darkens towards both ends: the order of values reads without the hue.
    #[test]
    fn lightness_orders_the_values() {
        let viridis = ColourScale::fit(Palette::Viridis, [0.0, 1.0]);
        let steps: Vec<f64> = (0..=40)
            .map(|k| luminance(viridis.colour(k as f64 / 40.0)))
            .collect();
        assert!(steps.windows(2).all(|w| w[1] > w[0]), "{steps:?}");
        let diverging = ColourScale::fit(Palette::BlueWhiteRed, [-1.0, 1.0]);
        let side = |sign: f64| -> Vec<f64> {
            (0..=20)
                .map(|k| luminance(diverging.colour(sign * k as f64 / 20.0)))
                .collect()
        };
        for half in [side(1.0), side(-1.0)] {
            assert!(half.windows(2).all(|w| w[1] < w[0]), "{half:?}");
        }
    }
}
