//! Where a function is sampled: equally spaced or seeded random points, a fixed number per
//! cell of the grid.

use crate::rng::Lcg;

/// How the data points are placed in each cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// `ppc` points at x_c + (j - 1/2) h/ppc: cell-centred sub-intervals, the placement that
    /// reproduces Gong's Table 4.1 (ERRATA).
    Equal,
    /// `ppc` points drawn uniformly in each cell (stratified). Gong's Table 4.2 used Matlab's
    /// `rand` over the whole interval; one stratum per cell keeps every node within reach of
    /// data on any grid, so refinement studies never meet an empty support.
    Random,
}

impl Spacing {
    pub const NAMES: [&'static str; 2] = ["equal", "random"];

    pub fn from_name(name: &str) -> Option<Spacing> {
        match name {
            "equal" => Some(Spacing::Equal),
            "random" => Some(Spacing::Random),
            _ => None,
        }
    }
}

/// The data points of `cells` cells of size `h` from `lower`, ascending. The random points
/// are drawn cell by cell from `Lcg::new(seed)` and sorted within each cell.
pub fn place(
    spacing: Spacing,
    lower: f64,
    h: f64,
    cells: usize,
    ppc: usize,
    seed: u64,
) -> Vec<f64> {
    let mut rng = Lcg::new(seed);
    let mut points = Vec::with_capacity(cells * ppc);
    for c in 0..cells {
        let mut fractions: Vec<f64> = match spacing {
            Spacing::Equal => (0..ppc).map(|j| (j as f64 + 0.5) / ppc as f64).collect(),
            Spacing::Random => (0..ppc).map(|_| rng.unit()).collect(),
        };
        fractions.sort_by(f64::total_cmp);
        points.extend(fractions.iter().map(|f| lower + (c as f64 + f) * h));
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_points_are_cell_centred() {
        let x = place(Spacing::Equal, -1.0, 0.2, 10, 4, 0);
        assert_eq!(x.len(), 40);
        assert!((x[0] - (-1.0 + 0.025)).abs() < 1e-15);
        assert!((x[39] - (1.0 - 0.025)).abs() < 1e-15);
    }

    #[test]
    fn random_points_fill_every_cell_and_repeat_with_the_seed() {
        let x = place(Spacing::Random, 0.0, 0.1, 10, 3, 7);
        for (c, cell) in x.chunks(3).enumerate() {
            assert!(cell.windows(2).all(|w| w[0] <= w[1]));
            let lo = c as f64 * 0.1;
            assert!(cell.iter().all(|&p| p >= lo && p < lo + 0.1 + 1e-15));
        }
        assert_eq!(x, place(Spacing::Random, 0.0, 0.1, 10, 3, 7));
        assert_ne!(x, place(Spacing::Random, 0.0, 0.1, 10, 3, 8));
    }
}
