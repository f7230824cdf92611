//! Particle-domain shape functions (Gong ch. 6): each particle carries a domain Omega_p, and
//! its effective basis is the grid hat averaged over that domain,
//! S_ip = (1/V_p) int_{Omega_p} N_i and grad S_ip = (1/V_p) int_{Omega_p} grad N_i (eqs 6.4-6.5).
//! GIMP averages the hat itself over an axis-aligned box; CPDI averages its interpolant from
//! the domain's corners. The nodes a domain touches are the block of grid nodes around its
//! bounding box, found from the box alone.

mod cpdi;
mod gimp;
#[cfg(test)]
mod tests;

use std::fmt;

use nalgebra::SVector;

use super::block::{block_start, for_each_block_node, NODES_PER_AXIS};
use super::{LinearHat, Shape, Stencils};
use crate::divergence::DomainFault;
use crate::grid::{index_to_f64, lattice_coords, lattice_strides, Grid};
use crate::particles::Particles;
use cpdi::{corner_weights, reference_corner, MAX_CORNERS};
use gimp::{averaged_hats, hat};

/// How a particle's domain is represented and follows the deformation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DomainShape {
    /// uGIMP: the initial axis-aligned box around x_p, never deformed.
    FixedBox,
    /// cpGIMP: the box with each half-width stretched by the diagonal entry F_kk.
    StretchedBox,
    /// CPDI1: the parallelogram spanned by r_k = F r_k^0 around x_p (eq 6.21).
    Parallelogram,
    /// CPDI2: the quadrilateral whose corners move with the grid velocity (eq 6.28).
    Quadrilateral,
}

impl DomainShape {
    pub fn name(self) -> &'static str {
        match self {
            DomainShape::FixedBox => "ugimp",
            DomainShape::StretchedBox => "cpgimp",
            DomainShape::Parallelogram => "cpdi1",
            DomainShape::Quadrilateral => "cpdi2",
        }
    }
}

impl fmt::Display for DomainShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Nodes per axis in a stencil while every domain's box ends within two cells of the cell its
/// lower corner lies in, as every domain at most a cell wide does.
const NARROW_PER_AXIS: usize = 3;

/// The domains of all particles and what is needed to evaluate their effective basis.
pub struct ParticleDomains<const D: usize> {
    shape: DomainShape,
    /// Half-width of every initial domain: half the seed spacing.
    half0: f64,
    /// CPDI2: the corners of the seed lattice, shared by neighbouring domains.
    corners: Vec<SVector<f64, D>>,
    /// CPDI2: for each particle, the index of its lowest corner.
    first_corner: Vec<u32>,
    /// CPDI2: index of corner a (in the order of `reference_corner`) less the lowest one.
    corner_offset: [usize; MAX_CORNERS],
}

impl<const D: usize> ParticleDomains<D> {
    /// The initial domains: the seed sub-cells, which tile the body.
    pub fn new(shape: DomainShape, particles: &Particles<D>) -> Self {
        let lattice = &particles.lattice;
        let mut domains = ParticleDomains {
            shape,
            half0: 0.5 * lattice.spacing,
            corners: Vec::new(),
            first_corner: Vec::new(),
            corner_offset: [0; MAX_CORNERS],
        };
        if shape == DomainShape::Quadrilateral {
            let points: [usize; D] = std::array::from_fn(|k| lattice.per_axis[k] + 1);
            let strides = lattice_strides(&points);
            let count: usize = points.iter().product();
            domains.corners = (0..count)
                .map(|c| {
                    let m = lattice_coords(c, &points);
                    SVector::from_fn(|k, _| lattice.lower[k] + m[k] as f64 * lattice.spacing)
                })
                .collect();
            let index = |m: [usize; D]| (0..D).map(|k| m[k] * strides[k]).sum::<usize>();
            domains.first_corner = (0..particles.len())
                .map(|p| index(lattice.cell_of(p)) as u32)
                .collect();
            for (a, offset) in domains.corner_offset.iter_mut().take(1 << D).enumerate() {
                let r = reference_corner::<D>(a);
                *offset = index(std::array::from_fn(|k| usize::from(r[k] > 0.0)));
            }
        }
        domains
    }

    /// The most nodes a stencil holds: a domain may span up to `NODES_PER_AXIS - 1` cells.
    pub fn nodes_per_point() -> usize {
        NODES_PER_AXIS.pow(D as u32)
    }

    /// The nodes a stencil holds while every domain fits `NARROW_PER_AXIS`, as the seed
    /// sub-cells do until a domain stretches past a cell: the hats of the widest block's last
    /// node along each axis are then zero over the whole domain.
    pub fn narrow_nodes_per_point() -> usize {
        NARROW_PER_AXIS.pow(D as u32)
    }

    /// Fills every particle's stencil with S_ip and grad S_ip. CPDI2 also sets each
    /// particle's volume to the area of its quadrilateral. Narrow stencils that a domain has
    /// outgrown are widened to `nodes_per_point` and filled again; they stay wide after.
    pub fn fill(
        &self,
        grid: &Grid<D>,
        particles: &mut Particles<D>,
        stencils: &mut Stencils<D>,
    ) -> Result<(), DomainFault> {
        if stencils.per_point == Self::narrow_nodes_per_point() {
            match self.fill_blocks::<NARROW_PER_AXIS>(grid, particles, stencils) {
                Err(DomainFault::TooWide { .. }) => stencils.reshape(Self::nodes_per_point()),
                done => return done,
            }
        }
        self.fill_blocks::<NODES_PER_AXIS>(grid, particles, stencils)
    }

    /// `fill` with blocks of `A` nodes per axis, which `stencils` must hold (a constant, so
    /// that the loops over a block unroll).
    fn fill_blocks<const A: usize>(
        &self,
        grid: &Grid<D>,
        particles: &mut Particles<D>,
        stencils: &mut Stencils<D>,
    ) -> Result<(), DomainFault> {
        let mut corners = [SVector::<f64, D>::zeros(); MAX_CORNERS];
        let corners = &mut corners[..1 << D];
        for p in 0..particles.len() {
            let range = p * stencils.per_point..(p + 1) * stencils.per_point;
            let node = &mut stencils.node[range.clone()];
            let weight = &mut stencils.weight[range.clone()];
            let grad = &mut stencils.grad[range];
            let x = particles.x[p];
            if grid.locate(&x).is_none() {
                return Err(DomainFault::Outside(p));
            }
            if let Some(half) = self.box_half_widths(particles, p) {
                fill_box::<D, A>(grid, &x, &half, node, weight, grad).ok_or(
                    DomainFault::TooWide {
                        particle: p,
                        max_cells: NODES_PER_AXIS - 1,
                    },
                )?;
                continue;
            }
            self.corners_of(particles, p, corners);
            for corner in corners.iter_mut() {
                *corner = clamp_to_grid(grid, corner);
            }
            let cw = corner_weights(corners).ok_or(DomainFault::Inverted(p))?;
            fill_corners::<D, A>(grid, corners, &cw, node, weight, grad).ok_or(
                DomainFault::TooWide {
                    particle: p,
                    max_cells: NODES_PER_AXIS - 1,
                },
            )?;
            if self.shape == DomainShape::Quadrilateral {
                particles.volume[p] = cw.volume;
            }
        }
        Ok(())
    }

    /// GIMP: the half-widths of particle `p`'s box; `None` for CPDI, whose domains are
    /// given by corners.
    fn box_half_widths(&self, particles: &Particles<D>, p: usize) -> Option<SVector<f64, D>> {
        match self.shape {
            DomainShape::FixedBox => Some(SVector::repeat(self.half0)),
            DomainShape::StretchedBox => Some(particles.f[p].diagonal() * self.half0),
            DomainShape::Parallelogram | DomainShape::Quadrilateral => None,
        }
    }

    /// CPDI: the corners of particle `p`'s domain in the order of `reference_corner`, before
    /// they are moved onto the grid.
    #[inline(always)]
    fn corners_of(&self, particles: &Particles<D>, p: usize, out: &mut [SVector<f64, D>]) {
        for (a, corner) in out.iter_mut().enumerate() {
            *corner = if self.shape == DomainShape::Quadrilateral {
                self.corners[self.first_corner[p] as usize + self.corner_offset[a]]
            } else {
                particles.x[p] + particles.f[p] * reference_corner::<D>(a) * self.half0
            };
        }
    }

    /// CPDI2 (eq 6.28): every corner moves with the grid velocity interpolated by the hat,
    /// x_a += dt sum_i N_i(x_a) v_i. Other shapes keep no corners.
    pub fn advance_corners(
        &mut self,
        grid: &Grid<D>,
        velocity: &[SVector<f64, D>],
        dt: f64,
    ) -> Result<(), DomainFault> {
        let per_point = Shape::<D>::nodes_per_point(&LinearHat);
        let mut node = [0u32; MAX_CORNERS];
        let mut weight = [0.0; MAX_CORNERS];
        let mut grad = [SVector::<f64, D>::zeros(); MAX_CORNERS];
        for (c, corner) in self.corners.iter_mut().enumerate() {
            let (node, weight) = (&mut node[..per_point], &mut weight[..per_point]);
            if !LinearHat.eval(grid, corner, node, weight, &mut grad[..per_point]) {
                return Err(DomainFault::CornerOutside(c));
            }
            let v: SVector<f64, D> = node
                .iter()
                .zip(weight.iter())
                .map(|(&i, &n)| velocity[i as usize] * n)
                .sum();
            *corner += v * dt;
        }
        Ok(())
    }
}

/// A point moved onto the grid along each axis. The benchmarks' bodies fill the grid, so a
/// domain reaches past it only by the small mismatch between the convected domain and the
/// material (CPDI1 corners x_p +- F r^0 at a fixed face); the part outside is folded onto the
/// face, which keeps the partition of unity.
fn clamp_to_grid<const D: usize>(grid: &Grid<D>, x: &SVector<f64, D>) -> SVector<f64, D> {
    let upper = grid.cells as f64 * grid.h;
    SVector::from_fn(|k, _| x[k].clamp(grid.lower[k], grid.lower[k] + upper))
}

/// GIMP: the box [x - half, x + half], cut to the grid, as a product of per-axis averages.
fn fill_box<const D: usize, const A: usize>(
    grid: &Grid<D>,
    x: &SVector<f64, D>,
    half: &SVector<f64, D>,
    node: &mut [u32],
    weight: &mut [f64],
    grad: &mut [SVector<f64, D>],
) -> Option<()> {
    let inv_h = grid.inv_h();
    let cells = grid.cells as f64;
    let lo = SVector::<f64, D>::from_fn(|k, _| {
        (((x[k] - half[k]) - grid.lower[k]) * inv_h).clamp(0.0, cells)
    });
    let hi = SVector::<f64, D>::from_fn(|k, _| {
        (((x[k] + half[k]) - grid.lower[k]) * inv_h).clamp(0.0, cells)
    });
    let start = block_start(grid, &lo, &hi, A)?;
    let mut value = [[0.0; A]; D];
    let mut slope = [[0.0; A]; D];
    for k in 0..D {
        averaged_hats(lo[k], hi[k], start[k], &mut value[k], &mut slope[k]);
    }
    for_each_block_node::<D, A>(grid, &start, |e, index, local| {
        let mut w = 1.0;
        let mut g = SVector::<f64, D>::repeat(inv_h);
        for k in 0..D {
            w *= value[k][local[k]];
            for l in 0..D {
                g[l] *= if l == k {
                    slope[k][local[k]]
                } else {
                    value[k][local[k]]
                };
            }
        }
        node[e] = index as u32;
        weight[e] = w;
        grad[e] = g;
    });
    Some(())
}

/// CPDI: S_ip = sum_a w_a N_i(x_a), grad S_ip = sum_a g_a N_i(x_a) over the corners.
fn fill_corners<const D: usize, const A: usize>(
    grid: &Grid<D>,
    corners: &[SVector<f64, D>],
    cw: &cpdi::CornerWeights<D>,
    node: &mut [u32],
    weight: &mut [f64],
    grad: &mut [SVector<f64, D>],
) -> Option<()> {
    let inv_h = grid.inv_h();
    let local = |c: &SVector<f64, D>| (c - grid.lower) * inv_h;
    let mut lo = local(&corners[0]);
    let mut hi = lo;
    // Plain compare-and-selects: the corners lie on the grid (clamped, and a NaN one fails
    // `corner_weights`), so `inf` and `sup`'s NaN rules, several instructions each, are not
    // needed.
    for c in &corners[1..] {
        let c = local(c);
        lo = lo.zip_map(&c, |l, c| if c < l { c } else { l });
        hi = hi.zip_map(&c, |h, c| if c > h { c } else { h });
    }
    let start = block_start(grid, &lo, &hi, A)?;
    // hats[a][k][j]: the hat of the block's j-th node along axis k at corner a.
    let mut hats = [[[0.0; A]; D]; MAX_CORNERS];
    for (a, c) in corners.iter().enumerate() {
        let s = local(c);
        for k in 0..D {
            for j in 0..A {
                hats[a][k][j] = hat(s[k] - index_to_f64(start[k] + j));
            }
        }
    }
    for_each_block_node::<D, A>(grid, &start, |e, index, at| {
        let mut w = 0.0;
        let mut g = SVector::<f64, D>::zeros();
        for a in 0..corners.len() {
            let n: f64 = (0..D).map(|k| hats[a][k][at[k]]).product();
            w += cw.value[a] * n;
            g += cw.gradient[a] * n;
        }
        node[e] = index as u32;
        weight[e] = w;
        grad[e] = g;
    });
    Some(())
}
