use nalgebra::{SMatrix, SVector};

use crate::fallible::filled;
use crate::parallel;

use super::{DualDomain, LinearHat, Shape};

use crate::grid::Grid;

/// The velocity gradient at a particle, sum_i v_i (x) grad N_ip, one stencil entry at a time.
pub trait VelocityGradient<const D: usize>: Sync {
    /// The term of entry (node i, N_ip, grad N_ip).
    fn term(&self, i: usize, w: f64, g: &SVector<f64, D>) -> SMatrix<f64, D, D>;
}

/// The sum over the entries' gradients, v_i (x) grad N_ip, for the nodal velocity v_i.
pub struct EntryGradients<'a, const D: usize>(pub &'a [SVector<f64, D>]);

impl<const D: usize> VelocityGradient<D> for EntryGradients<'_, D> {
    #[inline(always)]
    fn term(&self, i: usize, _: f64, g: &SVector<f64, D>) -> SMatrix<f64, D, D> {
        self.0[i] * g.transpose()
    }
}

/// The sum in factored form, N_jp G_j, from the nodal averages G_j of the velocity gradient
/// (`DualDomain::velocity_gradients`).
pub struct NodeGradients<const D: usize>(pub Vec<SMatrix<f64, D, D>>);

impl<const D: usize> VelocityGradient<D> for NodeGradients<D> {
    #[inline(always)]
    fn term(&self, j: usize, w: f64, _: &SVector<f64, D>) -> SMatrix<f64, D, D> {
        self.0[j] * w
    }
}

/// Shape-function values of every particle, `per_point` entries each, stored flat so
/// that the transfer loops walk memory in order and nothing is allocated per step.
pub struct Stencils<const D: usize> {
    pub per_point: usize,
    pub node: Vec<u32>,
    pub weight: Vec<f64>,
    pub grad: Vec<SVector<f64, D>>,
    /// For a basis whose values reach fewer nodes than its gradients, each point's entries
    /// with nonzero values in stencil order, padded with zero values (gradients unused).
    values: Option<Box<Stencils<D>>>,
    /// For stencils that list the entries that can be nonzero first (LME's selected nodes),
    /// how many each point has: the rest hold zero values and gradients, which the sums skip.
    /// Empty when every entry counts.
    leading: Vec<u32>,
    /// The dual-domain basis at the particles: the entries are the hat's, and the gradients
    /// are taken from the nodal averages in factored form (`DualDomain::velocity_gradients`,
    /// `DualDomain::subtract_divergence`), 2^D entries per particle instead of 4^D.
    dual: Option<Box<DualDomain<D>>>,
}

impl<const D: usize> Stencils<D> {
    pub fn new(per_point: usize, particles: usize) -> Self {
        let n = per_point.saturating_mul(particles);
        Stencils {
            per_point,
            node: filled(n, 0, "the stencils' nodes"),
            weight: filled(n, 0.0, "the stencils' values"),
            grad: filled(n, SVector::zeros(), "the stencils' gradients"),
            values: None,
            leading: Vec::new(),
            dual: None,
        }
    }

    /// The points' counts of leading entries that the last `set_leading` recorded, or none
    /// if the entries have been written otherwise since (`update`, `reshape`); every entry
    /// counts until the next `set_leading`.
    pub fn take_leading(&mut self) -> Vec<u32> {
        std::mem::take(&mut self.leading)
    }

    /// Marks each point p's entries after its first `leading[p]` as zero values and
    /// gradients, which the sums then skip. A sum that holds anything but -0 is left as it is
    /// by a zero term, so the sums keep every bit; only one made of -0 terms alone from a -0
    /// start keeps its sign now where the skipped +0 terms made it +0.
    pub fn set_leading(&mut self, leading: Vec<u32>) {
        debug_assert_eq!(leading.len() * self.per_point, self.node.len());
        debug_assert!(leading.iter().all(|&n| n as usize <= self.per_point));
        self.leading = leading;
    }

    /// The range of point `p`'s entries that can be nonzero.
    #[inline]
    fn entries(&self, p: usize) -> std::ops::Range<usize> {
        let start = p * self.per_point;
        let count = match self.leading.get(p) {
            Some(&n) => n as usize,
            None => self.per_point,
        };
        start..start + count
    }

    /// Makes these the particles' stencils of the dual-domain basis with the integrals of
    /// `dual` (`update_dual_domain`).
    pub fn attach_dual_domain(&mut self, dual: DualDomain<D>) {
        let corners = Shape::<D>::nodes_per_point(&LinearHat);
        if self.per_point != corners {
            self.reshape(corners);
        }
        self.dual = Some(Box::new(dual));
    }

    /// The dual-domain integrals whose averages give these stencils' gradients, if any.
    pub fn dual_domain(&self) -> Option<&DualDomain<D>> {
        self.dual.as_deref()
    }

    /// The hat's entries at `positions`, then the attached dual-domain integrals over the
    /// particles with the volumes `volumes` in the cells `cells`, which are returned. Fails
    /// as `update` does.
    pub fn update_dual_domain(
        &mut self,
        grid: &Grid<D>,
        positions: &[SVector<f64, D>],
        volumes: &[f64],
        cells: &[usize],
    ) -> Result<&DualDomain<D>, usize> {
        self.update(&LinearHat, grid, positions)?;
        let mut dual = self
            .dual
            .take()
            .expect("`attach_dual_domain` comes before the updates");
        dual.integrate(self, volumes, cells);
        Ok(self.dual.insert(dual))
    }

    /// The entries to sum values over (mass, momentum, N-weighted gathers): each point's
    /// entries with nonzero values where the basis has fewer of them than gradients, else
    /// all of them. The terms left out add exact zeros to sums that start from +0, so every
    /// sum is the same to the last bit.
    #[inline]
    pub fn for_values(&self) -> &Stencils<D> {
        self.values.as_deref().unwrap_or(self)
    }

    /// Whether `for_values` lists fewer entries than these stencils.
    pub fn has_value_entries(&self) -> bool {
        self.values.is_some()
    }

    /// Gives every point `per_point` entries, all zero until filled again.
    pub fn reshape(&mut self, per_point: usize) {
        let points = self.node.len() / self.per_point.max(1);
        *self = Stencils::new(per_point, points);
    }

    /// Evaluates the shape functions at every position, `parallel::CHUNK` positions per task;
    /// on failure returns the index of the first particle outside the grid.
    pub fn update<S: Shape<D> + ?Sized>(
        &mut self,
        shape: &S,
        grid: &Grid<D>,
        positions: &[SVector<f64, D>],
    ) -> Result<(), usize> {
        self.leading.clear();
        let k = self.per_point;
        let len = k * parallel::CHUNK;
        let chunks = self
            .node
            .chunks_mut(len)
            .zip(self.weight.chunks_mut(len))
            .zip(self.grad.chunks_mut(len))
            .zip(positions.chunks(parallel::CHUNK))
            .enumerate();
        type Chunk<'a, const D: usize> = (
            usize,
            (
                ((&'a mut [u32], &'a mut [f64]), &'a mut [SVector<f64, D>]),
                &'a [SVector<f64, D>],
            ),
        );
        let evaluate = |(c, (((node, weight), grad), positions)): Chunk<D>| {
            let entries = node
                .chunks_exact_mut(k)
                .zip(weight.chunks_exact_mut(k))
                .zip(grad.chunks_exact_mut(k));
            for (q, ((node, weight), grad)) in entries.enumerate() {
                if !shape.eval(grid, &positions[q], node, weight, grad) {
                    return Err(c * parallel::CHUNK + q);
                }
            }
            Ok(())
        };
        parallel::map_chunks(chunks, evaluate)
            .into_iter()
            .collect::<Result<(), usize>>()?;
        let value_nodes = shape.value_nodes_per_point();
        if value_nodes < k {
            let points = self.node.len() / k;
            let mut values = match self.values.take() {
                Some(values) if values.node.len() == value_nodes * points => values,
                _ => Box::new(Stencils::new(value_nodes, points)),
            };
            self.copy_values_to(&mut values);
            self.values = Some(values);
        } else {
            self.values = None;
        }
        Ok(())
    }

    /// Each point's entries with nonzero values into `values` (`values.per_point` of them per
    /// point), in stencil order, the rest of its entries zero values at the point's first node.
    fn copy_values_to(&self, values: &mut Stencils<D>) {
        let (k, v) = (self.per_point, values.per_point);
        let targets = values
            .node
            .chunks_mut(v * parallel::CHUNK)
            .zip(values.weight.chunks_mut(v * parallel::CHUNK));
        let sources = self
            .node
            .chunks(k * parallel::CHUNK)
            .zip(self.weight.chunks(k * parallel::CHUNK));
        type Target<'a> = (&'a mut [u32], &'a mut [f64]);
        type Source<'a> = (&'a [u32], &'a [f64]);
        let copy = |((to_node, to_weight), (node, weight)): (Target, Source)| {
            let points = to_node
                .chunks_exact_mut(v)
                .zip(to_weight.chunks_exact_mut(v))
                .zip(node.chunks_exact(k))
                .zip(weight.chunks_exact(k));
            for (((to_node, to_weight), node), weight) in points {
                // Each entry written once: filling the padding first made a memset call of
                // a few bytes per point.
                let mut nonzero = node.iter().zip(weight).filter(|(_, &w)| w != 0.0);
                for (to_node, to_weight) in to_node.iter_mut().zip(to_weight.iter_mut()) {
                    (*to_node, *to_weight) = match nonzero.next() {
                        Some((&i, &w)) => (i, w),
                        None => (node[0], 0.0),
                    };
                }
                debug_assert!(nonzero.next().is_none());
            }
        };
        parallel::map_chunks(targets.zip(sources), copy);
    }

    /// Adds the contributions of points `0..points` to nodal arrays cut into blocks of
    /// `block_len` nodes (`blocks`, in node order): `add(block, i - start, value, N_ip, grad
    /// N_ip)` for each of point p's entries whose node i lies in the block starting at
    /// `start`, with `value = point(p)` computed once per point and block it reaches. Each
    /// block's task walks the points in order, so every node's sum is in point order
    /// whatever the blocks, and blocks run in parallel (`parallel::map_chunks`).
    pub fn scatter<B: Send, T>(
        &self,
        points: usize,
        block_len: usize,
        blocks: impl Iterator<Item = B>,
        point: impl Fn(usize) -> T + Sync,
        add: impl Fn(&mut B, usize, &T, f64, &SVector<f64, D>) + Sync,
    ) {
        let k = self.per_point;
        let mut blocks: Vec<B> = blocks.collect();
        if let [block] = blocks.as_mut_slice() {
            // One block holds every node (one thread): the plain loop, without the tests
            // that keep a block's task to its nodes.
            for p in 0..points {
                let value = point(p);
                let range = self.entries(p);
                let entries = self.node[range.clone()]
                    .iter()
                    .zip(&self.weight[range.clone()]);
                for ((&i, &w), g) in entries.zip(&self.grad[range]) {
                    add(block, i as usize, &value, w, g);
                }
            }
            return;
        }
        // The nodes each chunk of points reaches, so that a block's task skips the chunks that
        // add nothing to it: points seeded along the grid give each task about its share.
        let reach = |nodes: &[u32]| {
            let lo = nodes.iter().min().map_or(usize::MAX, |&i| i as usize);
            let hi = nodes.iter().max().map_or(0, |&i| i as usize);
            (lo, hi)
        };
        let reaches = parallel::map_chunks(
            self.node[..points * k].chunks((k * parallel::CHUNK).max(1)),
            reach,
        );
        let fill = |(b, mut block): (usize, B)| {
            let start = b * block_len;
            let inside = start..start + block_len;
            for (c, &(lo, hi)) in reaches.iter().enumerate() {
                if hi < start || lo >= inside.end {
                    continue;
                }
                for p in c * parallel::CHUNK..((c + 1) * parallel::CHUNK).min(points) {
                    let range = self.entries(p);
                    let nodes = &self.node[range.clone()];
                    if !nodes.iter().any(|&i| inside.contains(&(i as usize))) {
                        continue;
                    }
                    let value = point(p);
                    let entries = nodes.iter().zip(&self.weight[range.clone()]);
                    for ((&i, &w), g) in entries.zip(&self.grad[range]) {
                        if inside.contains(&(i as usize)) {
                            add(&mut block, i as usize - start, &value, w, g);
                        }
                    }
                }
            }
        };
        parallel::map_chunks(blocks.into_iter().enumerate(), fill);
    }

    /// The largest distance between two node numbers in one point's stencil: the
    /// sub-diagonals of a matrix assembled from products N_i N_j at these points.
    pub fn bandwidth(&self) -> usize {
        self.node
            .chunks_exact(self.per_point.max(1))
            .map(|nodes| {
                let (lo, hi) = (nodes.iter().min(), nodes.iter().max());
                lo.zip(hi).map_or(0, |(lo, hi)| (hi - lo) as usize)
            })
            .max()
            .unwrap_or(0)
    }

    /// The nodes and values N of particle `p`'s entries.
    #[inline]
    pub fn values_of(&self, p: usize) -> (&[u32], &[f64]) {
        let range = p * self.per_point..(p + 1) * self.per_point;
        (&self.node[range.clone()], &self.weight[range])
    }

    /// Entries of particle `p`: (node, N, grad N), without the trailing zeros `set_leading`
    /// marks.
    #[inline]
    pub fn of(&self, p: usize) -> impl Iterator<Item = (usize, f64, &SVector<f64, D>)> {
        let range = self.entries(p);
        self.node[range.clone()]
            .iter()
            .zip(&self.weight[range.clone()])
            .zip(&self.grad[range])
            .map(|((&i, &w), g)| (i as usize, w, g))
    }
}

/// Asserts that the gradients `shape` gives at `x` agree with central differences of its
/// values within `tolerance`; `x` must be away from cell faces, where values have kinks.
#[cfg(test)]
pub(crate) fn assert_gradient_matches_differences<S: Shape<D> + ?Sized, const D: usize>(
    shape: &S,
    grid: &Grid<D>,
    x: &SVector<f64, D>,
    tolerance: f64,
) {
    let stencil = |y: &SVector<f64, D>| {
        let mut st = Stencils::new(shape.nodes_per_point(), 1);
        st.update(shape, grid, std::slice::from_ref(y)).unwrap();
        st
    };
    let value = |y: &SVector<f64, D>, node: usize| {
        stencil(y)
            .of(0)
            .find(|(i, _, _)| *i == node)
            .map_or(0.0, |(_, w, _)| w)
    };
    let eps = 1e-6;
    for (i, _, grad) in stencil(x).of(0) {
        for k in 0..D {
            let mut xp = *x;
            let mut xm = *x;
            xp[k] += eps;
            xm[k] -= eps;
            let fd = (value(&xp, i) - value(&xm, i)) / (2.0 * eps);
            assert!(
                (fd - grad[k]).abs() < tolerance,
                "node {i} axis {k} at {x:?}: {fd} vs {}",
                grad[k]
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::Domain;
    use crate::shape::LinearHat;

    fn grid<const D: usize>(cells: usize) -> Grid<D> {
        Grid::new(&Domain {
            lower: SVector::repeat(-0.5),
            upper: SVector::repeat(1.5),
            cells,
        })
    }

    /// Deterministic pseudo-random points in the grid (no RNG dependency needed).
    fn points<const D: usize>(n: usize) -> Vec<SVector<f64, D>> {
        let mut rng = crate::rng::Lcg::new(0x9e3779b97f4a7c15);
        (0..n)
            .map(|_| SVector::from_fn(|_, _| -0.5 + 2.0 * rng.unit()))
            .collect()
    }

    /// Partition of unity, zero gradient sum, linear reproduction and its gradient.
    fn check_consistency<const D: usize>() {
        let g = grid::<D>(7);
        let xs = points::<D>(500);
        let mut st = Stencils::new(1 << D, xs.len());
        st.update(&LinearHat, &g, &xs).unwrap();
        for (p, x) in xs.iter().enumerate() {
            let sum_w: f64 = st.of(p).map(|(_, w, _)| w).sum();
            let sum_g: SVector<f64, D> = st.of(p).map(|(_, _, gr)| *gr).sum();
            let sum_wx: SVector<f64, D> = st.of(p).map(|(i, w, _)| g.node_position(i) * w).sum();
            let sum_gx: nalgebra::SMatrix<f64, D, D> = st
                .of(p)
                .map(|(i, _, gr)| g.node_position(i) * gr.transpose())
                .sum();
            assert!((sum_w - 1.0).abs() < 1e-14);
            assert!(sum_g.norm() < 1e-12);
            assert!((sum_wx - x).norm() < 1e-14);
            assert!((sum_gx - nalgebra::SMatrix::<f64, D, D>::identity()).norm() < 1e-12);
            assert!(st.of(p).all(|(_, w, _)| w >= 0.0));
        }
    }

    #[test]
    fn linear_hat_consistency_1d() {
        check_consistency::<1>();
    }

    #[test]
    fn linear_hat_consistency_2d() {
        check_consistency::<2>();
    }

    /// Gradients agree with central differences of the values away from cell faces.
    #[test]
    fn linear_hat_gradient_matches_finite_differences_2d() {
        let x = SVector::<f64, 2>::new(0.31, 0.77);
        assert_gradient_matches_differences(&LinearHat, &grid::<2>(5), &x, 1e-8);
    }

    #[test]
    fn outside_points_are_reported() {
        let g = grid::<2>(4);
        let xs = vec![
            SVector::<f64, 2>::new(0.0, 0.0),
            SVector::<f64, 2>::new(1.6, 0.0),
        ];
        let mut st = Stencils::new(4, 2);
        assert_eq!(st.update(&LinearHat, &g, &xs), Err(1));
        let nan = vec![SVector::<f64, 2>::new(f64::NAN, 0.0)];
        assert_eq!(Stencils::new(4, 1).update(&LinearHat, &g, &nan), Err(0));
    }
}
