use nalgebra::SVector;

use super::Shape;

use crate::grid::{Dofs, Grid};

/// The piecewise-linear hat of Gong eq 4.8, a tensor product in 2D: 2^D nodes per point, the
/// corners of the point's cell, entry `corner` with bit k set for the upper node along axis k.
/// It lives on a grid of `Dofs::Nodes`.
#[derive(Clone, Copy, Debug, Default)]
pub struct LinearHat;

impl<const D: usize> Shape<D> for LinearHat {
    fn nodes_per_point(&self) -> usize {
        1 << D
    }

    #[inline]
    fn eval(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> bool {
        debug_assert_eq!(grid.dofs(), Dofs::Nodes);
        let Some((cell, xi)) = grid.locate(x) else {
            return false;
        };
        let base = grid.node_index(cell);
        let inv_h = grid.inv_h();
        for corner in 0..(1usize << D) {
            let mut index = base;
            let mut w = 1.0;
            let mut g = SVector::<f64, D>::repeat(inv_h);
            for k in 0..D {
                let upper = corner >> k & 1 == 1;
                let (wk, dk) = if upper {
                    (xi[k], 1.0)
                } else {
                    (1.0 - xi[k], -1.0)
                };
                if upper {
                    index += grid.stride(k);
                }
                w *= wk;
                for l in 0..D {
                    g[l] *= if l == k { dk } else { wk };
                }
            }
            node[corner] = index as u32;
            weight[corner] = w;
            grad[corner] = g;
        }
        true
    }
}
