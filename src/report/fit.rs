//! Least-squares power laws: `error = 10^intercept * h^rate`, fitted as a straight line
//! through (log10 h, log10 error).

/// A straight-line fit in log10-log10 space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    pub slope: f64,
    pub intercept: f64,
    /// Coefficient of determination of the line in log space.
    pub r2: f64,
}

impl LineFit {
    /// The fitted error at cell size `h`.
    pub fn eval(&self, h: f64) -> f64 {
        10f64.powf(self.intercept + self.slope * h.log10())
    }
}

/// Fits `points` = (h, error), all finite and positive. `None` when the slope is undefined:
/// fewer than two points or a single distinct h.
pub fn fit_loglog(points: &[(f64, f64)]) -> Option<LineFit> {
    if points.len() < 2 {
        return None;
    }
    let logs: Vec<(f64, f64)> = points
        .iter()
        .map(|&(h, e)| (h.log10(), e.log10()))
        .collect();
    let n = logs.len() as f64;
    let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / n;
    // Centred sums avoid the cancellation of the textbook `sum xy - n mean_x mean_y` form.
    let sxx: f64 = logs.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let syy: f64 = logs.iter().map(|p| (p.1 - mean_y).powi(2)).sum();
    if sxx == 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = mean_y - slope * mean_x;
    let ss_res: f64 = logs
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    // Errors that do not change with h are fitted exactly by a flat line.
    let r2 = if syy == 0.0 { 1.0 } else { 1.0 - ss_res / syy };
    Some(LineFit {
        slope,
        intercept,
        r2,
    })
}

/// The log-log slope between successive points in order of decreasing h (points of equal h
/// give none).
pub fn segment_slopes(points: &[(f64, f64)]) -> Vec<f64> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| b.0.total_cmp(&a.0));
    sorted
        .windows(2)
        .filter(|w| w[0].0 != w[1].0)
        .map(|w| (w[1].1 / w[0].1).log10() / (w[1].0 / w[0].0).log10())
        .collect()
}

/// Smallest and largest of `values` (infinities when there are none).
pub fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_power_law_exactly() {
        let c = 3.5;
        let points: Vec<(f64, f64)> = [8.0, 16.0, 32.0, 64.0]
            .iter()
            .map(|cells| {
                let h = 1.0 / cells;
                (h, c * h * h)
            })
            .collect();
        let fit = fit_loglog(&points).unwrap();
        assert!((fit.slope - 2.0).abs() < 1e-12, "{fit:?}");
        assert!((fit.intercept - c.log10()).abs() < 1e-12, "{fit:?}");
        assert!((fit.r2 - 1.0).abs() < 1e-12, "{fit:?}");
        assert!((fit.eval(0.01) - c * 1e-4).abs() < 1e-15);
    }

    #[test]
    fn noisy_data_has_r2_below_one() {
        let points = [
            (0.1, 1.1e-2),
            (0.05, 2.3e-3),
            (0.025, 7.0e-4),
            (0.0125, 1.4e-4),
        ];
        let fit = fit_loglog(&points).unwrap();
        assert!(fit.r2 < 1.0 && fit.r2 > 0.9, "{fit:?}");
        assert!(fit.slope > 1.5 && fit.slope < 2.5, "{fit:?}");
    }

    #[test]
    fn degenerate_inputs_have_no_fit() {
        assert_eq!(fit_loglog(&[]), None);
        assert_eq!(fit_loglog(&[(0.1, 1e-3)]), None);
        assert_eq!(fit_loglog(&[(0.1, 1e-3), (0.1, 2e-3)]), None);
    }

    #[test]
    fn segments_show_a_floor_the_fit_hides() {
        // Second order, then flat: h = 0.1, 0.05 in any order, then a floor at 0.025.
        let points = [(0.05, 2.5e-3), (0.1, 1e-2), (0.025, 2.5e-3)];
        let slopes = segment_slopes(&points);
        assert_eq!(slopes.len(), 2);
        assert!((slopes[0] - 2.0).abs() < 1e-12, "{slopes:?}");
        assert!(slopes[1].abs() < 1e-12, "{slopes:?}");
    }
}
