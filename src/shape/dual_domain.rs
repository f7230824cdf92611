//! The modified gradient of the dual-domain MPM (DDMPM; Zhang, Ma & Giguere 2011), as Wobbes
//! et al. (2018) use it: the values are the hat's, S_i(x) = N_i(x), and the gradient is the
//! node average
//!     grad S~_i(x) = sum_j S_j(x) (int grad S_i S_j) / (int S_j),
//! with both integrals over the material: sums over the particles (as Zhang et al. and
//! Wobbes et al. define it) or exact integrals over the cells that hold particles.

use nalgebra::{SMatrix, SVector};

use super::block::{block_around_cell, for_each_block_node, NODES_PER_AXIS};
use super::{Shape, Stencils};
use crate::grid::{lattice_coords, Dofs, Grid};
use crate::parallel;

/// Offsets i - j per axis of the nodes i whose hat overlaps that of node j: -1, 0, 1.
const NEIGHBOURS_PER_AXIS: usize = 3;

/// Block places (first axis fastest) per axis in at most two dimensions.
const BLOCK_PLACE: [usize; 2] = [1, NODES_PER_AXIS];

/// Entry (first axis fastest) of the block node at coordinates `local`.
const fn block_entry<const D: usize>(local: &[usize; D]) -> usize {
    let (mut entry, mut k) = (0, 0);
    while k < D {
        entry += local[k] * BLOCK_PLACE[k];
        k += 1;
    }
    entry
}

/// Per offset o in {0, 1, 2}^D (first axis fastest), the block entry of o counted from the
/// block's first node.
const fn neighbour_steps<const D: usize>() -> [usize; 9] {
    let mut steps = [0; 9];
    let mut n = 0;
    while n < NEIGHBOURS_PER_AXIS.pow(D as u32) {
        let (mut rest, mut k) = (n, 0);
        while k < D {
            steps[n] += rest % NEIGHBOURS_PER_AXIS * BLOCK_PLACE[k];
            rest /= NEIGHBOURS_PER_AXIS;
            k += 1;
        }
        n += 1;
    }
    steps
}

/// Bit n set for each offset o in {0, 1, 2}^D (n = o in base 3, first axis fastest) that
/// takes the node at `local` to node `local + o - 1` of a lattice of `len` nodes per axis.
fn neighbours_within<const D: usize>(local: &[usize; D], len: usize) -> u32 {
    let (mut reached, mut width) = (1, 1);
    for &l in local {
        let mut next = 0;
        for o in 0..NEIGHBOURS_PER_AXIS {
            if (1..=len).contains(&(l + o)) {
                next |= reached << (o * width);
            }
        }
        (reached, width) = (next, width * NEIGHBOURS_PER_AXIS);
    }
    reached
}

/// `visit(n, value)` for every node n and its entry of `nodal`, over blocks of nodes in
/// parallel (`parallel::map_chunks`); each node's work is its own, so any cut gives the same
/// bits.
fn per_node<T: Send>(nodal: &mut [T], visit: impl Fn(usize, &mut T) + Sync) {
    let len = parallel::block_len(nodal.len());
    let block = |(b, values): (usize, &mut [T])| {
        for (m, value) in values.iter_mut().enumerate() {
            visit(b * len + m, value);
        }
    };
    parallel::map_chunks(nodal.chunks_mut(len).enumerate(), block);
}

/// How the integrals over the material are taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DualIntegrals {
    /// MPM's particle quadrature, int f ~ sum_p f(x_p) V_p with the current volumes: the dual
    /// domain of node j is the material under its hat as the particles carry it. A particle
    /// crossing a node moves its whole share across the jump of grad N_i, so the averages
    /// keep part of MPM's grid-crossing error (docs/NOTES.md).
    Particles,
    /// Exact integrals over the cells holding at least one particle. A body that fills the
    /// grid gives the same, fixed, integrals whatever its particles do; a boundary cell that
    /// the material fills in part counts as full.
    ActiveCells,
}

/// The nodal integrals of one step, and through them the modified basis at any point.
///
/// A node whose hat covers no material (int S_j = 0) has no average and is dropped from the
/// sum over j (see `eval`). Integrals over the particles' boxes (cpGIMP domains) were tried
/// and dropped: the DDMPM gradient that updates F is not the one that moves the particles, so
/// the boxes open gaps (docs/NOTES.md).
pub struct DualDomain<const D: usize> {
    integrals: DualIntegrals,
    grid: Grid<D>,
    /// Per offset o in {0, 1, 2}^D (first axis fastest), the grid index of node n + o - 1
    /// counted from that of n - 1 (every axis).
    grid_steps: [usize; 9],
    /// Per cell, whether a particle is in it.
    active: Vec<bool>,
    /// int S_j per node j.
    volume: Vec<f64>,
    /// Per node j (slowest), then per offset i - j in {-1, 0, 1}^D (first axis fastest):
    /// the average (int grad S_i S_j) / (int S_j) of grad S_i over the dual domain of j;
    /// zero when int S_j = 0.
    average: Vec<SVector<f64, D>>,
}

impl<const D: usize> DualDomain<D> {
    /// Empty integrals on a grid of hat nodes.
    pub fn new(grid: &Grid<D>, integrals: DualIntegrals) -> Self {
        debug_assert_eq!(grid.dofs(), Dofs::Nodes);
        let n = grid.num_nodes();
        DualDomain {
            integrals,
            grid: grid.clone(),
            grid_steps: std::array::from_fn(|o| {
                let digits = lattice_coords(o, &[NEIGHBOURS_PER_AXIS; D]);
                (0..D).map(|k| digits[k] * grid.stride(k)).sum()
            }),
            active: vec![false; grid.cells.pow(D as u32)],
            volume: vec![0.0; n],
            average: vec![SVector::zeros(); n * Self::neighbours()],
        }
    }

    fn neighbours() -> usize {
        NEIGHBOURS_PER_AXIS.pow(D as u32)
    }

    /// The integrals over this step's material: the particles of the hat stencils `hat`
    /// with the volumes `volumes`, each inside the cell listed in `cells` (flat indices,
    /// `Grid::cell_index`). Sums run particle by particle, or cell by cell in index order: a
    /// fixed summation order either way.
    pub fn integrate(&mut self, hat: &Stencils<D>, volumes: &[f64], cells: &[usize]) {
        self.volume.fill(0.0);
        self.average.fill(SVector::zeros());
        match self.integrals {
            DualIntegrals::Particles => self.sum_particles(hat, volumes),
            DualIntegrals::ActiveCells => self.integrate_cells(cells),
        }
        let stride = Self::neighbours();
        for (j, &volume) in self.volume.iter().enumerate() {
            let scale = if volume > 0.0 { 1.0 / volume } else { 0.0 };
            for g in &mut self.average[j * stride..(j + 1) * stride] {
                *g *= scale;
            }
        }
    }

    /// int S_j ~ sum_p N_j(x_p) V_p and int grad S_i S_j ~ sum_p grad N_i(x_p) N_j(x_p) V_p,
    /// with the hat's entries of every particle (corner order, as `LinearHat` lists them).
    fn sum_particles(&mut self, hat: &Stencils<D>, volumes: &[f64]) {
        let corners = 1 << D;
        debug_assert_eq!(hat.per_point, corners);
        let stride = Self::neighbours();
        let entries = hat
            .node
            .chunks_exact(corners)
            .zip(hat.weight.chunks_exact(corners))
            .zip(hat.grad.chunks_exact(corners));
        for (((node, weight), grad), &v) in entries.zip(volumes) {
            for b in 0..corners {
                let j = node[b] as usize;
                let share = weight[b] * v;
                self.volume[j] += share;
                let average = &mut self.average[j * stride..(j + 1) * stride];
                for a in 0..corners {
                    average[corner_offset::<D>(a, b)] += grad[a] * share;
                }
            }
        }
    }

    /// Per node j, G_j = sum_i v_i (x) A_ij with A_ij = (int grad S_i S_j) / (int S_j), the
    /// node's average of the velocity gradient for the nodal velocity `velocity`: the modified
    /// velocity gradient at a point x is sum_j S_j(x) G_j, which is sum_i v_i (x)
    /// grad S~_i(x) with the sums taken the other way round. Nodes without material get
    /// zero.
    pub fn velocity_gradients(&self, velocity: &[SVector<f64, D>]) -> Vec<SMatrix<f64, D, D>> {
        let mut out = vec![SMatrix::zeros(); velocity.len()];
        per_node(&mut out, |j, g| {
            if self.volume[j] > 0.0 {
                self.for_each_neighbour(j, |o, i| {
                    *g += velocity[i] * self.average[j * Self::neighbours() + o].transpose();
                });
            }
        });
        out
    }

    /// f_i -= sum_j T_j A_ij over the nodes j whose hats overlap that of i, for nodal tensors
    /// T_j = sum_p S_j(x_p) V_p sigma_p (`stress`): the internal force sum_p V_p sigma_p
    /// grad S~_i(x_p) with the sums taken the other way round.
    pub fn subtract_divergence(
        &self,
        stress: &[SMatrix<f64, D, D>],
        force: &mut [SVector<f64, D>],
    ) {
        // Node j = i + 1 - d is reached from i by the offset o = 2 - d, so that i is j's
        // neighbour d = (3^D - 1) - o.
        let last = Self::neighbours() - 1;
        per_node(force, |i, f| {
            self.for_each_neighbour(i, |o, j| {
                *f -= stress[j] * self.average[j * Self::neighbours() + last - o];
            });
        });
    }

    /// `visit(o, m)` for each offset o in {0, 1, 2}^D (in base 3, first axis fastest, in
    /// increasing order) that takes node `n` to a node m = n + o - 1 of the grid.
    #[inline]
    fn for_each_neighbour(&self, n: usize, mut visit: impl FnMut(usize, usize)) {
        let coords = self.grid.node_coords(n);
        let reached = neighbours_within(&coords, self.grid.nodes_per_dim());
        let first = (0..D).fold(n, |m, k| m.wrapping_sub(self.grid.stride(k)));
        for (o, step) in self.grid_steps[..Self::neighbours()].iter().enumerate() {
            if reached >> o & 1 == 1 {
                visit(o, first.wrapping_add(*step));
            }
        }
    }

    /// The exact integrals over the active cells among `cells`.
    fn integrate_cells(&mut self, cells: &[usize]) {
        let grid = &self.grid;
        self.active.fill(false);
        for &c in cells {
            self.active[c] = true;
        }
        let corners = 1 << D;
        let stride = Self::neighbours();
        // Over a cell, per axis, the hats of its lower (0) and upper (1) node: int N_a = h/2,
        // int N_a N_b = h/3 (a = b) or h/6, int N_a' N_b = -1/2 (a lower) or 1/2.
        let h = grid.h;
        let value = h / 2.0;
        let product = |a: usize, b: usize| if a == b { h / 3.0 } else { h / 6.0 };
        let slope = |a: usize| if a == 0 { -0.5 } else { 0.5 };
        let cell_volume: f64 = value.powi(D as i32);
        for (c, _) in self
            .active
            .iter()
            .enumerate()
            .filter(|(_, active)| **active)
        {
            let cell = lattice_coords(c, &[grid.cells; D]);
            for b in 0..corners {
                let j = grid.node_index(std::array::from_fn(|k| cell[k] + (b >> k & 1)));
                self.volume[j] += cell_volume;
                for a in 0..corners {
                    let integral = SVector::<f64, D>::from_fn(|l, _| {
                        (0..D)
                            .map(|k| {
                                let (ak, bk) = (a >> k & 1, b >> k & 1);
                                if k == l {
                                    slope(ak)
                                } else {
                                    product(ak, bk)
                                }
                            })
                            .product()
                    });
                    self.average[j * stride + corner_offset::<D>(a, b)] += integral;
                }
            }
        }
    }
}

/// Index in {-1, 0, 1}^D (first axis fastest) of the offset from hat corner `b` of a cell to
/// corner `a` (bit k of a corner is set for the upper node along axis k, as in `LinearHat`).
#[inline]
fn corner_offset<const D: usize>(a: usize, b: usize) -> usize {
    let mut offset = 0;
    let mut place = 1;
    for k in 0..D {
        offset += (1 + (a >> k & 1) - (b >> k & 1)) * place;
        place *= NEIGHBOURS_PER_AXIS;
    }
    offset
}

/// The modified basis at any point of the grid from the integrals of the last `integrate`:
/// the hat's values and grad S~_i(x) = sum_j S_j(x) (int grad S_i S_j) / (int S_j) over the
/// corners j of x's cell. The nodes i are the block of 4 per axis around the cell (shifted
/// inwards at the grid ends), which holds every node whose hat overlaps a corner's; entries
/// of nodes that do not reach x carry zero. A corner with int S_j = 0 (no material under
/// its hat) contributes nothing: where that happens the gradient loses linear consistency,
/// sum_i x_i (x) grad S~_i = (sum of S_j(x) over the corners with material) I, and at the
/// particles themselves it cannot happen, since every corner with S_j(x_p) > 0 has at least
/// particle p's share. sum_i grad S~_i = 0 at every point.
///
/// This evaluates the run's basis at arbitrary points, e.g. the Gauss points of a quadrature
/// transfer, through `Stencils::update`.
impl<const D: usize> DualDomain<D> {
    /// The nodes of every point's stencil: the block of 4 per axis around its cell.
    pub fn stencil_nodes() -> usize {
        NODES_PER_AXIS.pow(D as u32)
    }
}

impl<const D: usize> Shape<D> for DualDomain<D> {
    fn nodes_per_point(&self) -> usize {
        Self::stencil_nodes()
    }

    /// The hat's values, at the corners of the point's cell.
    fn value_nodes_per_point(&self) -> usize {
        1 << D
    }

    fn eval(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> bool {
        let Some((cell, xi)) = grid.locate(x) else {
            return false;
        };
        let start = block_around_cell(grid, &cell);
        let stride = DualDomain::<D>::neighbours();
        // Slices cut to the entry count, so that zeroing them is a few stores, not a call.
        let count = Self::stencil_nodes();
        let (node, weight, grad) = (&mut node[..count], &mut weight[..count], &mut grad[..count]);
        weight.fill(0.0);
        grad.fill(SVector::zeros());
        let base = grid.node_index(cell);
        // Away from the grid's ends the block is centred on the cell and holds every
        // neighbour of every corner, at entries fixed by the corner: no test per neighbour.
        // A path of its own, not a full mask on the shifted path: with the mask `ddmpm`'s
        // 16-step 2D case takes 755 M instructions instead of 704 M.
        let centred = (0..D).all(|k| start[k] + 1 == cell[k]);
        let steps = const { neighbour_steps::<D>() };
        for b in 0..1 << D {
            // The hat of corner j = b of the cell, as `LinearHat` evaluates it.
            let mut hat = 1.0;
            let mut j = base;
            let mut upper = [0; D];
            for k in 0..D {
                upper[k] = b >> k & 1;
                hat *= if upper[k] == 1 { xi[k] } else { 1.0 - xi[k] };
                j += upper[k] * grid.stride(k);
            }
            // The neighbours i = j + o - 1 (o in {0, 1, 2}^D), from block entry `first`.
            let averages = self.average[j * stride..(j + 1) * stride]
                .iter()
                .zip(&steps);
            if centred {
                // The corner is block entry 1 + upper, its neighbours start at `upper`.
                let first = block_entry::<D>(&upper);
                weight[first + const { block_entry::<D>(&[1; D]) }] = hat;
                for (average, step) in averages {
                    grad[first + step] += average * hat;
                }
            } else {
                // Neighbours outside the shifted block are off the grid, where the averages
                // are zero.
                let local: [usize; D] = std::array::from_fn(|k| cell[k] + upper[k] - start[k]);
                let entry = block_entry::<D>(&local);
                weight[entry] = hat;
                let reached = neighbours_within(&local, NODES_PER_AXIS);
                let first = entry.wrapping_sub(const { block_entry::<D>(&[1; D]) });
                for (n, (average, step)) in averages.enumerate() {
                    if reached >> n & 1 == 1 {
                        grad[first.wrapping_add(*step)] += average * hat;
                    }
                }
            }
        }
        for_each_block_node::<D, NODES_PER_AXIS>(grid, &start, |e, index, _| {
            node[e] = index as u32;
        });
        true
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::SMatrix;

    use super::*;
    use crate::grid::{lattice_coords, Domain};
    use crate::rng::Lcg;
    use crate::shape::LinearHat;

    fn grid<const D: usize>(cells: usize) -> Grid<D> {
        Grid::new(&Domain {
            lower: SVector::zeros(),
            upper: SVector::repeat(1.0),
            cells,
        })
    }

    /// The integrals of `integrals` over particles at `positions` with volumes `volumes`.
    fn integrated<const D: usize>(
        g: &Grid<D>,
        integrals: DualIntegrals,
        positions: &[SVector<f64, D>],
        volumes: &[f64],
    ) -> DualDomain<D> {
        let mut dual = DualDomain::new(g, integrals);
        let mut hat = Stencils::new(Shape::<D>::nodes_per_point(&LinearHat), positions.len());
        hat.update(&LinearHat, g, positions).unwrap();
        dual.integrate(&hat, volumes, &cells_of(g, positions));
        dual
    }

    /// The flat index of each point's cell.
    fn cells_of<const D: usize>(g: &Grid<D>, positions: &[SVector<f64, D>]) -> Vec<usize> {
        positions
            .iter()
            .map(|x| g.cell_index(g.locate(x).expect("inside the grid").0))
            .collect()
    }

    /// The modified basis at `x`: (node, S_i, grad S~_i) of every stencil entry.
    fn basis_at<const D: usize>(
        dual: &DualDomain<D>,
        g: &Grid<D>,
        x: &SVector<f64, D>,
    ) -> Vec<(usize, f64, SVector<f64, D>)> {
        let n = dual.nodes_per_point();
        let (mut node, mut weight, mut grad) =
            (vec![0; n], vec![0.0; n], vec![SVector::zeros(); n]);
        assert!(dual.eval(g, x, &mut node, &mut weight, &mut grad));
        (0..n)
            .map(|e| (node[e] as usize, weight[e], grad[e]))
            .collect()
    }

    /// `n` particles at random in [0, 0.6]^D (the cells beyond 2/3 empty), every `face`-th
    /// of them moved onto the grid's upper face x_0 = 1, and their random volumes.
    fn scattered<const D: usize>(
        rng: &mut Lcg,
        n: usize,
        face: Option<usize>,
    ) -> (Vec<SVector<f64, D>>, Vec<f64>) {
        let positions: Vec<SVector<f64, D>> = (0..n)
            .map(|p| {
                let on_face = face.is_some_and(|every| p % every == 0);
                SVector::from_fn(|k, _| {
                    if on_face && k == 0 {
                        1.0
                    } else {
                        0.6 * rng.unit()
                    }
                })
            })
            .collect();
        let volumes = positions
            .iter()
            .map(|_| 1e-3 * (0.5 + rng.unit()))
            .collect();
        (positions, volumes)
    }

    /// Random particles with random volumes in [0, 0.6]^D (the cells beyond 2/3 empty) and
    /// random points, for both integrals. Where every corner of the point's cell has material,
    /// sum_i grad S~_i = 0 and sum_i x_i (x) grad S~_i = I; where some has none, the second is
    /// the sum of the corners' S_j that have material, times I.
    fn check_consistency<const D: usize>(integrals: DualIntegrals) {
        let g = grid::<D>(6);
        let mut rng = Lcg::new(2011);
        let (positions, volumes) = scattered::<D>(&mut rng, 300 * D, None);
        let dual = integrated(&g, integrals, &positions, &volumes);
        let (mut filled, mut partial) = (0, 0);
        let points = (0..500).map(|_| SVector::from_fn(|_, _| rng.unit()));
        for x in positions.iter().copied().chain(points) {
            let entries = basis_at(&dual, &g, &x);
            let sum_w: f64 = entries.iter().map(|e| e.1).sum();
            let sum_g: SVector<f64, D> = entries.iter().map(|e| e.2).sum();
            let sum_gx: SMatrix<f64, D, D> = entries
                .iter()
                .map(|(i, _, gr)| g.node_position(*i) * gr.transpose())
                .sum();
            let with_material: f64 = entries
                .iter()
                .filter(|(i, w, _)| *w > 0.0 && dual.volume[*i] > 0.0)
                .map(|e| e.1)
                .sum();
            if (with_material - 1.0).abs() < 1e-14 {
                filled += 1;
            } else {
                partial += 1;
            }
            let identity = SMatrix::<f64, D, D>::identity();
            assert!((sum_w - 1.0).abs() < 1e-14);
            assert!(sum_g.norm() < 1e-11, "{x:?}: sum grad = {sum_g:?}");
            assert!(
                (sum_gx - identity * with_material).norm() < 1e-12,
                "{x:?}: sum x (x) grad = {sum_gx:?}, corners with material {with_material}"
            );
        }
        assert!(
            filled > 300 * D && partial > 100,
            "{filled} filled, {partial} partial"
        );
    }

    #[test]
    fn dual_domain_gradient_is_consistent_where_there_is_material_1d() {
        check_consistency::<1>(DualIntegrals::Particles);
        check_consistency::<1>(DualIntegrals::ActiveCells);
    }

    #[test]
    fn dual_domain_gradient_is_consistent_where_there_is_material_2d() {
        check_consistency::<2>(DualIntegrals::Particles);
        check_consistency::<2>(DualIntegrals::ActiveCells);
    }

    /// The value entries list each point's nonzero values in stencil order (at most the 2^D
    /// corners of its cell, on faces and at the grid's ends too), and sums over them equal the
    /// sums over the whole stencil bit for bit.
    fn check_value_entries<const D: usize>() {
        let g = grid::<D>(5);
        let mut rng = Lcg::new(2018);
        let positions: Vec<SVector<f64, D>> = (0..200)
            .map(|n| match n % 4 {
                // On a cell face, where an upper corner's hat is zero.
                0 => SVector::from_fn(|_, _| (5.0 * rng.unit()).floor() / 5.0),
                // At the grid's ends, where the block is shifted inwards.
                1 => SVector::from_fn(|k, _| if k == 0 { 1.0 } else { rng.unit() }),
                _ => SVector::from_fn(|_, _| rng.unit()),
            })
            .collect();
        let volumes = vec![1e-3; positions.len()];
        let dual = integrated(&g, DualIntegrals::Particles, &positions, &volumes);
        let mut st = Stencils::new(dual.nodes_per_point(), positions.len());
        st.update(&dual, &g, &positions).unwrap();
        assert!(st.has_value_entries());
        let values = st.for_values();
        assert_eq!(values.per_point, 1 << D);
        let u: Vec<f64> = (0..g.num_nodes()).map(|_| rng.unit() - 0.5).collect();
        for p in 0..positions.len() {
            let nonzero: Vec<(usize, f64)> = st
                .of(p)
                .filter(|(_, w, _)| *w != 0.0)
                .map(|(i, w, _)| (i, w))
                .collect();
            let listed: Vec<(usize, f64)> = values.of(p).map(|(i, w, _)| (i, w)).collect();
            assert_eq!(&listed[..nonzero.len()], &nonzero[..]);
            assert!(listed[nonzero.len()..].iter().all(|&(_, w)| w == 0.0));
            let full: f64 = st.of(p).map(|(i, w, _)| u[i] * w).sum();
            let compact: f64 = values.of(p).map(|(i, w, _)| u[i] * w).sum();
            assert_eq!(full.to_bits(), compact.to_bits());
        }
    }

    #[test]
    fn value_entries_are_the_nonzero_values_1d() {
        check_value_entries::<1>();
    }

    #[test]
    fn value_entries_are_the_nonzero_values_2d() {
        check_value_entries::<2>();
    }

    /// The factored gradients are the explicit ones with the sums taken the other way round:
    /// for scattered particles with random volumes (cells beyond 2/3 empty, points on the
    /// grid's upper faces), random nodal velocities and particle stresses, sum_j N_jp G_j
    /// equals sum_i v_i (x) grad S~_i(x_p) at every particle, -sum_j T_j A_ij equals
    /// -sum_p V_p sigma_p grad S~_i(x_p) at every node, both to round-off, and the internal
    /// forces sum to zero.
    fn check_factored<const D: usize>() {
        for integrals in [DualIntegrals::Particles, DualIntegrals::ActiveCells] {
            check_factored_with::<D>(integrals);
        }
    }

    fn check_factored_with<const D: usize>(integrals: DualIntegrals) {
        let g = grid::<D>(6);
        let mut rng = Lcg::new(2012);
        let (positions, volumes) = scattered::<D>(&mut rng, 300 * D, Some(10));
        let dual = integrated(&g, integrals, &positions, &volumes);
        let mut explicit = Stencils::new(dual.nodes_per_point(), positions.len());
        explicit.update(&dual, &g, &positions).unwrap();
        let mut hat = Stencils::new(Shape::<D>::nodes_per_point(&LinearHat), positions.len());
        hat.update(&LinearHat, &g, &positions).unwrap();
        let velocity: Vec<SVector<f64, D>> = (0..g.num_nodes())
            .map(|_| SVector::from_fn(|_, _| rng.unit() - 0.5))
            .collect();
        let stress: Vec<SMatrix<f64, D, D>> = positions
            .iter()
            .map(|_| SMatrix::from_fn(|_, _| 1e3 * (rng.unit() - 0.5)))
            .collect();

        let nodal = dual.velocity_gradients(&velocity);
        for p in 0..positions.len() {
            let direct: SMatrix<f64, D, D> = explicit
                .of(p)
                .map(|(i, _, gr)| velocity[i] * gr.transpose())
                .sum();
            let factored: SMatrix<f64, D, D> = hat.of(p).map(|(j, w, _)| nodal[j] * w).sum();
            let scale = explicit.of(p).map(|(_, _, gr)| gr.norm()).sum::<f64>();
            assert!(
                (direct - factored).norm() <= 1e-14 * scale,
                "{p}: {direct:?} vs {factored:?}"
            );
        }

        let mut direct = vec![SVector::<f64, D>::zeros(); g.num_nodes()];
        let mut sums = vec![SMatrix::<f64, D, D>::zeros(); g.num_nodes()];
        let mut scale = 0.0;
        for p in 0..positions.len() {
            let vs = stress[p] * volumes[p];
            for (i, _, gr) in explicit.of(p) {
                direct[i] -= vs * gr;
                scale += (vs * gr).norm();
            }
            for (j, w, _) in hat.of(p) {
                sums[j] += vs * w;
            }
        }
        let mut factored = vec![SVector::<f64, D>::zeros(); g.num_nodes()];
        dual.subtract_divergence(&sums, &mut factored);
        for (i, (a, b)) in direct.iter().zip(&factored).enumerate() {
            assert!((a - b).norm() <= 1e-14 * scale, "node {i}: {a:?} vs {b:?}");
        }
        let total: SVector<f64, D> = factored.iter().sum();
        assert!(total.norm() <= 1e-14 * scale, "sum of forces {total:?}");
    }

    #[test]
    fn factored_gradients_equal_the_explicit_ones_1d() {
        check_factored::<1>();
    }

    #[test]
    fn factored_gradients_equal_the_explicit_ones_2d() {
        check_factored::<2>();
    }

    /// `ppc` particles per cell and axis at the centres of equal sub-cells (the seeding), each
    /// with its sub-cell's volume: every cell active, the grid uniformly filled.
    fn uniform<const D: usize>(g: &Grid<D>, ppc: usize, integrals: DualIntegrals) -> DualDomain<D> {
        let per_axis = [g.cells * ppc; D];
        let spacing = g.h / ppc as f64;
        let positions: Vec<SVector<f64, D>> = (0..per_axis[0].pow(D as u32))
            .map(|p| {
                let m = lattice_coords(p, &per_axis);
                SVector::from_fn(|k, _| (m[k] as f64 + 0.5) * spacing)
            })
            .collect();
        let volumes = vec![spacing.powi(D as i32); positions.len()];
        integrated(g, integrals, &positions, &volumes)
    }

    /// Wherever the particles sit, a grid with a particle in every cell has the integrals of
    /// the uniform fill, and a cell holding one particle counts as much as one holding many:
    /// particles crossing nodes change nothing.
    #[test]
    fn integrals_depend_only_on_the_active_cells() {
        let g = grid::<2>(5);
        let reference = uniform(&g, 2, DualIntegrals::ActiveCells);
        let mut rng = Lcg::new(9);
        let mut positions: Vec<SVector<f64, 2>> = (0..25)
            .map(|c| {
                let cell = lattice_coords(c, &[5, 5]);
                SVector::from_fn(|k, _| (cell[k] as f64 + rng.unit()) * g.h)
            })
            .collect();
        positions.extend((0..40).map(|_| SVector::from_fn(|_, _| rng.unit())));
        let volumes = vec![1.0; positions.len()];
        let dual = integrated(&g, DualIntegrals::ActiveCells, &positions, &volumes);
        assert_eq!(dual.volume, reference.volume);
        assert_eq!(dual.average, reference.average);
    }

    /// 1D, uniformly filled: the modified gradient of a nodal field u is the hat
    /// interpolation of the nodal central differences (u_{j+1} - u_{j-1})/(2h), one-sided
    /// (u_1 - u_0)/h and (u_n - u_{n-1})/h at the end nodes, whose dual domain is a half cell,
    /// with either integrals (in 1D the midpoint rule integrates N_j grad N_i exactly).
    #[test]
    fn uniform_fill_interpolates_central_differences_1d() {
        let g = grid::<1>(8);
        for integrals in [DualIntegrals::Particles, DualIntegrals::ActiveCells] {
            check_central_differences_1d(&g, &uniform(&g, 2, integrals));
        }
    }

    fn check_central_differences_1d(g: &Grid<1>, dual: &DualDomain<1>) {
        let mut rng = Lcg::new(5);
        let u: Vec<f64> = (0..=g.cells).map(|_| rng.unit() - 0.5).collect();
        let n = g.cells;
        let nodal = |j: usize| match j {
            0 => (u[1] - u[0]) / g.h,
            j if j == n => (u[n] - u[n - 1]) / g.h,
            j => (u[j + 1] - u[j - 1]) / (2.0 * g.h),
        };
        for x in (0..200)
            .map(|_| SVector::<f64, 1>::new(rng.unit()))
            .chain([SVector::<f64, 1>::new(0.0), SVector::<f64, 1>::new(1.0)])
        {
            let entries = basis_at(dual, g, &x);
            let du: f64 = entries.iter().map(|(i, _, gr)| u[*i] * gr[0]).sum();
            let expected: f64 = entries.iter().map(|(j, s, _)| s * nodal(*j)).sum();
            assert!((du - expected).abs() < 1e-12, "{x:?}: {du} vs {expected}");
        }
    }

    /// 2D, uniformly filled, at cells whose corners are interior nodes: the x-derivative is
    /// the hat interpolation of central differences along x averaged across y with the
    /// weights int N_j N_{j+d} dy / int N_j dy, d = -1, 0, 1: exactly 1/6, 2/3, 1/6 over the
    /// active cells, and from the particle sums (a midpoint rule with n points per cell)
    /// 1/6 + 1/(12 n^2), 2/3 - 1/(6 n^2), 1/6 + 1/(12 n^2).
    #[test]
    fn uniform_fill_averages_central_differences_2d() {
        let g = grid::<2>(6);
        let ppc = 2;
        let side = 1.0 / (12.0 * (ppc * ppc) as f64);
        check_central_differences_2d(
            &g,
            &uniform(&g, ppc, DualIntegrals::Particles),
            [1.0 / 6.0 + side, 2.0 / 3.0 - 2.0 * side, 1.0 / 6.0 + side],
        );
        check_central_differences_2d(
            &g,
            &uniform(&g, ppc, DualIntegrals::ActiveCells),
            [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
        );
    }

    fn check_central_differences_2d(g: &Grid<2>, dual: &DualDomain<2>, across: [f64; 3]) {
        let mut rng = Lcg::new(6);
        let u: Vec<f64> = (0..g.num_nodes()).map(|_| rng.unit() - 0.5).collect();
        let at = |i: usize, j: usize| u[g.node_index([i, j])];
        for _ in 0..300 {
            // Inside cells 1 .. cells - 2 along both axes.
            let x = SVector::<f64, 2>::from_fn(|_, _| (1.0 + 4.0 * rng.unit()) * g.h);
            let entries = basis_at(dual, g, &x);
            let du: SVector<f64, 2> = entries.iter().map(|(i, _, gr)| gr * u[*i]).sum();
            let mut expected = SVector::<f64, 2>::zeros();
            for (node, s, _) in entries.iter().filter(|e| e.1 > 0.0) {
                let [i, j] = g.node_coords(*node);
                for (d, w) in across.iter().enumerate() {
                    let (ia, ja) = (i + d - 1, j + d - 1);
                    expected[0] += s * w * (at(i + 1, ja) - at(i - 1, ja)) / (2.0 * g.h);
                    expected[1] += s * w * (at(ia, j + 1) - at(ia, j - 1)) / (2.0 * g.h);
                }
            }
            assert!(
                (du - expected).norm() < 1e-12,
                "{x:?}: {du:?} vs {expected:?}"
            );
        }
    }
}
