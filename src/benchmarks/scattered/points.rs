//! Where a function is sampled: equally spaced or seeded random points, a fixed number per
//! cell of the grid, or Wobbes et al.'s mix of both.

use crate::params::ParamError;
use crate::rng::Lcg;

/// How the data points are placed in each cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// `ppc` points at x_c + (j - 1/2) h/ppc: cell-centred sub-intervals, the placement that
    /// reproduces Gong's Table 4.1 (ERRATA).
    Equal,
    /// `ppc` points at x_e + j h/(ppc + 1), j = 1..ppc (x_e the cell's left edge): equal gaps
    /// between the points and to the edges (Wobbes Fig 2: 1/3, 2/3 and 1/4, 1/2, 3/4 of the
    /// element).
    Interior,
    /// `ppc` points drawn uniformly in each cell (stratified). Gong's Table 4.2 used Matlab's
    /// `rand` over the whole interval; one stratum per cell keeps every node within reach of
    /// data on any grid, so refinement studies never meet an empty support.
    Random,
    /// Wobbes Fig 1's mix of distributions: the first cell has points on both its edges and
    /// the rest drawn inside, the second one on its left edge (where the first cell's last
    /// point is) and the rest drawn, the third is `Equal`, every further cell `Random`.
    Mixed,
}

impl Spacing {
    pub const NAMES: [&'static str; 4] = ["equal", "interior", "random", "mixed"];

    pub fn from_name(name: &str) -> Option<Spacing> {
        match name {
            "equal" => Some(Spacing::Equal),
            "interior" => Some(Spacing::Interior),
            "random" => Some(Spacing::Random),
            "mixed" => Some(Spacing::Mixed),
            _ => None,
        }
    }
}

/// `Mixed` puts points on both edges of its first cell.
pub fn check_ppc(spacing: Spacing, ppc: usize) -> Result<(), ParamError> {
    if spacing == Spacing::Mixed && ppc < 2 {
        return Err(ParamError::new(
            "ppc",
            format!("spacing mixed puts points on both edges of the first cell: ppc = {ppc} must be at least 2"),
        ));
    }
    Ok(())
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
        let fractions = cell_fractions(spacing, c, ppc, &mut rng);
        points.extend(fractions.iter().map(|f| lower + (c as f64 + f) * h));
    }
    points
}

/// Where the `n` points of cell `c` go along one axis, as ascending fractions of the cell in
/// [0, 1]; random fractions come from `rng`. `Mixed` needs n >= 2 (`check_ppc`).
pub fn cell_fractions(spacing: Spacing, c: usize, n: usize, rng: &mut Lcg) -> Vec<f64> {
    let mut draw = |k: usize| -> Vec<f64> { (0..k).map(|_| rng.unit()).collect() };
    let mut fractions: Vec<f64> = match (spacing, c) {
        (Spacing::Equal, _) | (Spacing::Mixed, 2) => {
            (0..n).map(|j| (j as f64 + 0.5) / n as f64).collect()
        }
        (Spacing::Interior, _) => (1..=n).map(|j| j as f64 / (n + 1) as f64).collect(),
        (Spacing::Mixed, 0) => [vec![0.0, 1.0], draw(n - 2)].concat(),
        (Spacing::Mixed, 1) => [vec![0.0], draw(n - 1)].concat(),
        (Spacing::Random | Spacing::Mixed, _) => draw(n),
    };
    fractions.sort_by(f64::total_cmp);
    fractions
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

    #[test]
    fn interior_and_mixed_placements() {
        let x = place(Spacing::Interior, 0.0, 1.0, 2, 3, 0);
        assert_eq!(x, [0.25, 0.5, 0.75, 1.25, 1.5, 1.75]);
        let x = place(Spacing::Mixed, 0.0, 1.0, 5, 3, 4);
        assert_eq!((x[0], x[2], x[3]), (0.0, 1.0, 1.0));
        assert!(x[1] > 0.0 && x[1] < 1.0 && x[4] > 1.0 && x[5] < 2.0);
        assert_eq!(&x[6..9], &place(Spacing::Equal, 2.0, 1.0, 1, 3, 0)[..]);
        assert!(x.windows(2).all(|w| w[0] <= w[1]));
        assert!(x[9..].iter().all(|&p| p > 3.0 && p < 5.0));
    }
}
