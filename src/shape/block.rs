//! Stencils over a block of grid nodes per axis, shared by the shapes whose support at a point
//! is wider than one cell: `NODES_PER_AXIS` for particle domains and the dual-domain gradient,
//! as many as the cut-off radius spans for local maximum entropy.

use nalgebra::SVector;

use crate::grid::Grid;

/// Nodes per axis in a block stencil: a particle domain may span up to three cells, and the
/// dual-domain gradient reaches one node beyond the point's cell on each side.
pub const NODES_PER_AXIS: usize = 4;

/// The first block start along each axis that keeps a block of `per_axis` nodes inside the grid.
fn last_start<const D: usize>(grid: &Grid<D>, per_axis: usize) -> usize {
    grid.cells.saturating_sub(per_axis - 1)
}

/// The first node along each axis of a block of `per_axis` nodes per axis that holds the hat
/// supports reaching a bounding box [lo, hi] (in cell units from the grid's lower corner), or
/// `None` when the box spans more cells than the block. Blocks of different widths start at the
/// same node except where the grid ends, so a narrower block lists the same nonzero entries in
/// the same order.
pub fn block_start<const D: usize>(
    grid: &Grid<D>,
    lo: &SVector<f64, D>,
    hi: &SVector<f64, D>,
    per_axis: usize,
) -> Option<[usize; D]> {
    let last_start = last_start(grid, per_axis);
    let mut start = [0; D];
    for k in 0..D {
        // Truncation through i64 then max(0) is floor().max(0.0) for every input, NaN and
        // infinities included, without a call to floor or usize's conversion branches.
        start[k] = ((lo[k] as i64).max(0) as usize).min(last_start);
        if hi[k] > (start[k] + per_axis - 1) as f64 {
            return None;
        }
    }
    Some(start)
}

/// The first node of the block around `cell`: its nodes and one more on each side, the block
/// shifted inwards where the grid ends.
pub fn block_around_cell<const D: usize>(grid: &Grid<D>, cell: &[usize; D]) -> [usize; D] {
    let last_start = last_start(grid, NODES_PER_AXIS);
    std::array::from_fn(|k| cell[k].saturating_sub(1).min(last_start))
}

/// The first node of a block of `per_axis` nodes per axis that holds every node from `lo` (in
/// cell units from the grid's lower corner) to `per_axis - 1` cells beyond it, shifted inwards
/// where the grid ends.
pub fn block_from<const D: usize>(
    grid: &Grid<D>,
    lo: &SVector<f64, D>,
    per_axis: usize,
) -> [usize; D] {
    let last_start = last_start(grid, per_axis);
    std::array::from_fn(|k| ceil_at_least_zero(lo[k]).min(last_start))
}

/// max(ceil(x), 0) as an index (0 for NaN), through i64: truncation is ceil for x <= 0 and
/// one below it for a fractional x > 0, without libm's `ceil` (a call on the baseline x86-64
/// target) or usize's conversion branches.
#[inline]
fn ceil_at_least_zero(x: f64) -> usize {
    let truncated = x as i64;
    let ceil = if (truncated as f64) < x {
        truncated.saturating_add(1)
    } else {
        truncated
    };
    ceil.max(0) as usize
}

/// Calls `visit(e, index, local)` for the entries `e = 0, 1, ...` of a block of `A` nodes per
/// axis starting at `start`, the first axis fastest, with each entry's node index and its
/// coordinates within the block, from per-axis tables of the nodes' index terms and counted up
/// axis by axis instead of divided out, as the per-particle stencils need it for every entry.
/// Entries past the grid (grids with fewer than `A - 1` cells) repeat the last node and must
/// carry zero weight.
#[inline]
pub fn for_each_block_node<const D: usize, const A: usize>(
    grid: &Grid<D>,
    start: &[usize; D],
    mut visit: impl FnMut(usize, usize, &[usize; D]),
) {
    let along: [[usize; A]; D] = std::array::from_fn(|k| {
        std::array::from_fn(|l| (start[k] + l).min(grid.cells) * grid.stride(k))
    });
    let mut local = [0; D];
    for e in 0..A.pow(D as u32) {
        let index = (0..D).map(|k| along[k][local[k]]).sum();
        visit(e, index, &local);
        next_block_entry(&mut local, A);
    }
}

/// Moves the coordinates `local` within a block of `per_axis` nodes per axis to the next
/// entry, the first axis fastest: counted up instead of divided out of the entry index. Always
/// inlined: as a call it costs the dual-domain stencil 8 % of its step, and a constant
/// `per_axis` stays one.
#[inline(always)]
pub fn next_block_entry(local: &mut [usize], per_axis: usize) {
    for l in local {
        *l += 1;
        if *l < per_axis {
            return;
        }
        *l = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same index as `ceil` and usize's saturating conversion, at integers, just off
    /// them, negatives, NaN and beyond i64.
    #[test]
    fn ceil_at_least_zero_is_ceil_clamped() {
        let mut xs = vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e300,
            -1e300,
            9.3e18,
        ];
        for i in -4..6 {
            let x = i as f64;
            xs.extend([x, x + 0.5, x.next_up(), x.next_down(), x + 1e-9, x - 1e-9]);
        }
        for x in xs {
            let expected = (x.ceil().max(0.0) as usize).min(1 << 40);
            assert_eq!(ceil_at_least_zero(x).min(1 << 40), expected, "{x}");
        }
    }
}
