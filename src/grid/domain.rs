//! The box a grid covers.

use nalgebra::SVector;

/// A uniform background grid over a box, `cells` cells per direction.
#[derive(Clone, Copy, Debug)]
pub struct Domain<const D: usize> {
    pub lower: SVector<f64, D>,
    pub upper: SVector<f64, D>,
    pub cells: usize,
}

impl<const D: usize> Domain<D> {
    /// The box [0, (cells + extra) h]^D with h = length / cells: a body of side `length` from
    /// the origin, with `extra` empty cells beyond its upper faces for it to move into.
    pub fn padded(length: f64, cells: usize, extra: usize) -> Self {
        let total = cells + extra;
        Domain {
            lower: SVector::zeros(),
            upper: SVector::repeat(total as f64 * (length / cells as f64)),
            cells: total,
        }
    }
}
