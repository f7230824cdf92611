//! Local maximum-entropy (LME) shape functions (Arroyo & Ortiz 2006) on the nodes of the uniform
//! grid, as Molinos et al. use them in MPM (sec 5, eqs 32-38).
//!
//! At a point x the weights are p_a = exp(f_a) / Z with f_a = -beta |x - x_a|^2 + lambda . (x - x_a)
//! and Z = sum_a exp(f_a) (eqs 32, 33), beta = gamma / h^2. The multiplier lambda minimises
//! log Z, whose gradient r = sum_a p_a (x - x_a) (eq 38) vanishes exactly when the weights
//! reproduce x; its Hessian J = sum_a p_a (x - x_a)(x - x_a)^T - r r^T (eq 37) is the covariance
//! of the offsets under p. Everything below works in the scaled offsets d_a = (x - x_a) / h, where
//! f_a = -gamma |d_a|^2 + mu . d_a with mu = lambda h, so that r and J are O(1) whatever h.

use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{SMatrix, SVector};

use super::block::{block_from, next_block_entry};
use super::{Shape, Stencils};
use crate::grid::{index_to_f64, Dofs, Grid};

/// Default neighbour cut-off (Molinos et al. sec 5): nodes whose prior weight
/// exp(-beta |x - x_a|^2) is below it are left out.
pub const DEFAULT_TOLERANCE: f64 = 1e-6;

/// Default Newton iteration limit. A point on a face of the grid needs 25-27 steps at
/// gamma = 0.8 and 3: its multiplier is infinite (see `LocalMaxEnt`), and each step shrinks the
/// weight off the face by a factor of about e.
pub const MAX_ITERATIONS: usize = 100;

/// Newton stops when |r| < RESIDUAL_TOLERANCE h, i.e. when sum_a p_a x_a reproduces x to that.
pub const RESIDUAL_TOLERANCE: f64 = 1e-12;

/// Most nodes in the stencil block of one point. Every particle holds up to that many nodes,
/// weights and gradients (those within the radius of some point), so this bounds the memory
/// of the basis: 1024 (32 x 32 in 2D) takes
/// gamma down to 0.054 in 2D and 5.3e-5 in 1D at the default tolerance, where the committed
/// studies need at most 196 (gamma 0.3 in 2D).
pub const MAX_STENCIL_NODES: usize = 1024;

/// The most nodes per axis of a 2D stencil block: MAX_STENCIL_NODES is 32 x 32.
const MAX_SIDE_2D: usize = 32;

/// Largest |x_a| = |step . d_a| (bounded by |step| times the cut-off radius) for which a
/// Newton step updates the weights by exp(x_a) = 1 + x_a + x_a^2 / 2 instead of exp: the
/// terms left out, at most 1.7e-19 of a weight, are far below its round-off (1.1e-16). Near
/// the solution the full Newton step decreases log Z, so such a step skips the line search.
/// From a warm start the one Newton step is of this size in nearly every evaluation.
const SMALL_STEP: f64 = 1e-6;

/// Sufficient-decrease factor of the Armijo test on log Z.
const ARMIJO: f64 = 1e-4;

/// Backtracking halves the step at most this often (to 2^-50 of the Newton step).
const MAX_HALVINGS: usize = 50;

/// Relative size of the round-off in log Z, a sum of exponents of up to gamma r^2 + |mu| r:
/// near the solution the decrease of a Newton step falls below it, and the step is taken.
const ROUNDOFF: f64 = 64.0 * f64::EPSILON;

/// The LME basis with locality gamma = beta h^2 on a grid of `Dofs::Nodes` in `D` dimensions.
///
/// **Stencil.** The nodes a with exp(-gamma |d_a|^2) >= tolerance, i.e. within the cut-off
/// radius r = h sqrt(-ln(tolerance) / gamma). Along each axis they lie among the
/// floor(2 r / h) + 1 nodes from x - r on, the block that is searched (shifted inwards at the
/// grid's ends). A stencil lists them in the block's order, then other nodes of the block with
/// zero weight and gradient, as many as fill it to the most nodes any point can have within r
/// (`most_within`): in 2D about pi r^2 / h^2 of the block's (2 r / h)^2. Nodes
/// outside the grid do not exist, so near a boundary the weights live on the grid's nodes
/// alone and keep the convex-hull property.
///
/// **Boundary.** On a face of the grid x is on the boundary of the nodes' convex hull: the
/// minimiser of log Z is at infinity, the limit weights are the LME of the face's nodes, and
/// Newton approaches it until the weight off the face is below the residual tolerance.
///
/// **Failures.** `evaluate` returns why Newton stopped short. `eval`, whose interface has no
/// error channel, then fills the stencil from the last iterate (non-negative weights that sum to
/// one, whose first moment misses x by the final residual, with their exact gradients, zero
/// where J is singular) and adds one to `failures()`, which callers read after a pass; it never
/// panics.
#[derive(Debug)]
pub struct LocalMaxEnt<const D: usize> {
    gamma: f64,
    /// The cut-off radius in units of h.
    radius: f64,
    /// Nodes per axis of the block searched for the stencil.
    per_axis: usize,
    /// Entries of a stencil: the most nodes within the cut-off radius of any point.
    per_point: usize,
    /// Largest Newton step |Delta mu|. The weights are a Gaussian centred at d = mu / (2 gamma),
    /// so the limit 2 gamma r / h moves the centre by at most the cut-off radius per step.
    max_step: f64,
    /// exp(-2 gamma), by which the ratio of neighbouring columns' or rows' exponentials
    /// changes from one to the next (`shifted_exponentials`).
    decay: f64,
    max_iterations: usize,
    failures: AtomicUsize,
    /// Each particle's solution from the last `update_particles`, from which its next Newton
    /// iteration starts; `None` (a cold start) before the first and after one that fell short.
    warm: Vec<Option<Solution<D>>>,
    /// In 2D, each particle's block and its rows' runs of selected nodes (`per_axis` per
    /// particle) as its stencil holds them from the last `update_particles`.
    held_start: Vec<[u32; 2]>,
    held_runs: Vec<(u8, u8)>,
}

/// What a particle's 2D stencil holds from the last `update_particles`: the first node of its
/// block and each block row's run of selected nodes. `fill` writes the nodes and the
/// zero-weight entries again only where these changed; a particle moves a small part of a
/// cell a step, so nearly always they did not.
struct Held<'a> {
    start: &'a mut [u32; 2],
    runs: &'a mut [(u8, u8)],
}

/// A run no scan gives (its start past its end): a particle whose held runs are these has its
/// stencil written afresh.
const NOT_HELD: (u8, u8) = (1, 0);

/// A converged multiplier mu at the scaled position s = (x - x_0) / h, with J^-1 there.
#[derive(Clone, Copy, Debug)]
struct Solution<const D: usize> {
    s: SVector<f64, D>,
    mu: SVector<f64, D>,
    inverse: SMatrix<f64, D, D>,
}

impl<const D: usize> Solution<D> {
    /// The multiplier at `s` to first order. Moving x by delta h shifts every d_a by delta,
    /// which turns the weights at mu into those at mu - 2 gamma delta about the old offsets
    /// and adds delta to r: r = 0 again at mu + 2 gamma delta - J^-1 delta.
    fn predict(&self, s: &SVector<f64, D>, gamma: f64) -> SVector<f64, D> {
        let delta = s - self.s;
        self.mu + delta * (2.0 * gamma) - self.inverse * delta
    }
}

/// gamma and tolerance for which the LME problem has no solution at some point of the grid, or
/// whose stencil is larger than `MAX_STENCIL_NODES`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LmeParamError {
    pub gamma: f64,
    pub tolerance: f64,
    pub dimension: usize,
    /// The nodes per point of the stencil when its size is what is refused.
    pub stencil_nodes: Option<f64>,
}

impl fmt::Display for LmeParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(nodes) = self.stencil_nodes {
            // floor(2 r) + 1 <= n nodes per axis holds exactly when r < n / 2.
            let per_axis = largest_block_side(self.dimension) as f64;
            let gamma_min = -self.tolerance.ln() / (0.25 * per_axis * per_axis);
            return write!(
                f,
                "gamma = {:?} with tolerance = {:?} gives the cut-off radius {:.4e} h and a \
                 stencil of {nodes:.4e} nodes per point in {}D; at most {MAX_STENCIL_NODES} \
                 are supported, which needs gamma > {gamma_min:.4e} at this tolerance",
                self.gamma,
                self.tolerance,
                cut_off_radius(self.gamma, self.tolerance),
                self.dimension
            );
        }
        write!(
            f,
            "LME needs gamma > 0, 0 < tolerance < 1 and, in {}D, a cut-off radius \
             sqrt(-ln(tolerance) / gamma) above {} h; gamma = {} and tolerance = {} give {} h",
            self.dimension,
            surround_radius(self.dimension),
            self.gamma,
            self.tolerance,
            cut_off_radius(self.gamma, self.tolerance)
        )
    }
}

/// Why `LocalMaxEnt::evaluate` gave no converged basis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LmeFailure {
    /// The point is outside the grid; nothing was filled.
    Outside,
    /// The iteration limit left |r| = `residual` h, at or above `RESIDUAL_TOLERANCE` h.
    NotConverged { residual: f64 },
    /// J was not positive definite, or no step along the Newton direction decreased log Z.
    Stalled { residual: f64 },
}

/// The cut-off radius in units of h.
fn cut_off_radius(gamma: f64, tolerance: f64) -> f64 {
    (-tolerance.ln() / gamma).sqrt()
}

/// Nodes per axis of the stencil block of a cut-off radius (in units of h): those from x - r
/// to x + r. A real, so that an overlong radius does not overflow.
fn block_side(radius: f64) -> f64 {
    (2.0 * radius).floor() + 1.0
}

/// The most nodes per axis of a stencil block within `MAX_STENCIL_NODES` in `dimension`
/// dimensions.
fn largest_block_side(dimension: usize) -> usize {
    let fits = |side: usize| {
        u32::try_from(dimension)
            .ok()
            .and_then(|d| side.checked_pow(d))
            .is_some_and(|nodes| nodes <= MAX_STENCIL_NODES)
    };
    (1..=MAX_STENCIL_NODES)
        .take_while(|&side| fits(side))
        .last()
        .unwrap_or(1)
}

/// The smallest cut-off radius (in units of h) for which every point strictly inside the grid
/// lies strictly inside the convex hull of its selected nodes: a point just off a cell face,
/// midway along it, needs the nodes of the next layer, sqrt(1 + (D - 1) / 4) away.
fn surround_radius(dimension: usize) -> f64 {
    (1.0 + (dimension as f64 - 1.0) / 4.0).sqrt()
}

/// The most grid nodes within `radius` (in units of h) of any point in `dimension` (1 or 2)
/// dimensions: the entries a stencil needs.
///
/// In 1D that is floor(2 radius) + 1. In 2D the count changes only where a node crosses the
/// circle about the point, so as the point moves it is constant on the faces of the
/// arrangement of circles of the radius about the nodes, and at a vertex of a face, where two
/// circles cross, it is at least the face's (the test counts a node on the circle): the
/// largest count is at a vertex. The circles about node 0 and about each node within twice
/// the radius give every vertex up to a lattice translation, and the nodes (i, j) with
/// 0 <= j <= i every vertex up to the lattice's reflections as well, which keep the count.
/// Counting within a margin over the radius covers the round-off of the selection test and of
/// the vertices computed here.
fn most_within(radius: f64, dimension: usize) -> usize {
    const MARGIN: f64 = 1e-9;
    let r = radius + MARGIN;
    if dimension == 1 {
        // Below MAX_STENCIL_NODES, so the cast is exact.
        return (2.0 * r).floor() as usize + 1;
    }
    let reach = r.ceil() as i64 + 1;
    let count = |x: f64, y: f64| {
        let (x, y) = (x.rem_euclid(1.0), y.rem_euclid(1.0));
        let near = -reach..=reach + 1;
        near.clone()
            .flat_map(|i| near.clone().map(move |j| (i, j)))
            .filter(|&(i, j)| (x - i as f64).powi(2) + (y - j as f64).powi(2) <= r * r)
            .count()
    };
    (0..=2 * reach)
        .flat_map(|i| (0..=i).map(move |j| (i as f64, j as f64)))
        .filter(|&(i, j)| {
            let apart = i * i + j * j;
            apart > 0.0 && apart <= 4.0 * radius * radius
        })
        .flat_map(|(i, j)| {
            // The circles about (0, 0) and (i, j) cross on the perpendicular bisector.
            let apart = (i * i + j * j).sqrt();
            let along = (radius * radius - 0.25 * apart * apart).max(0.0).sqrt() / apart;
            [1.0, -1.0].map(|side| count(0.5 * i - side * along * j, 0.5 * j + side * along * i))
        })
        .max()
        .unwrap_or(1)
}

impl<const D: usize> LocalMaxEnt<D> {
    /// The basis with the default cut-off tolerance.
    pub fn new(gamma: f64) -> Result<Self, LmeParamError> {
        Self::with_tolerance(gamma, DEFAULT_TOLERANCE)
    }

    /// The basis with cut-off `tolerance`; its radius must surround every point of a cell
    /// (`surround_radius`), which bounds gamma by -ln(tolerance) in 1D and 0.8 (-ln(tolerance))
    /// in 2D.
    pub fn with_tolerance(gamma: f64, tolerance: f64) -> Result<Self, LmeParamError> {
        let radius = cut_off_radius(gamma, tolerance);
        let valid = gamma > 0.0
            && tolerance > 0.0
            && tolerance < 1.0
            && radius.is_finite()
            && radius > surround_radius(D);
        let error = |stencil_nodes| LmeParamError {
            gamma,
            tolerance,
            dimension: D,
            stencil_nodes,
        };
        if !valid {
            return Err(error(None));
        }
        let side = block_side(radius);
        let nodes = side.powi(D as i32);
        if nodes > MAX_STENCIL_NODES as f64 {
            return Err(error(Some(nodes)));
        }
        Ok(LocalMaxEnt {
            gamma,
            radius,
            // At most MAX_STENCIL_NODES, so the cast is exact.
            per_axis: side as usize,
            per_point: most_within(radius, D).min(nodes as usize),
            max_step: 2.0 * gamma * radius,
            decay: (-2.0 * gamma).exp(),
            max_iterations: MAX_ITERATIONS,
            failures: AtomicUsize::new(0),
            warm: Vec::new(),
            held_start: Vec::new(),
            held_runs: Vec::new(),
        })
    }

    /// The same basis with another Newton iteration limit.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// The cut-off radius in units of h.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// How many evaluations through `Shape::eval` did not converge.
    pub fn failures(&self) -> usize {
        self.failures.load(Ordering::Relaxed)
    }

    /// Fills the stencil of `x` as `Shape::eval` does; returns the number of Newton steps, or
    /// why Newton stopped short (the stencil then holds the last iterate, see `LocalMaxEnt`).
    pub fn evaluate(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> Result<usize, LmeFailure> {
        self.fill(
            grid,
            x,
            &mut None,
            &mut Factors::default(),
            None,
            node,
            weight,
            grad,
        )
        .0
    }

    /// Fills the stencils of the particles at `positions` as `Stencils::update` does with
    /// `Shape::eval`, except that each particle's Newton iteration starts from its solution of
    /// the last call, moved to its new position to first order (`Solution::predict`): a
    /// particle moves little per step, so Newton needs a step or two instead of several from
    /// zero. The result differs from a cold start's within the Newton tolerance. In 2D the
    /// stencils' nodes are written again only where a particle's selection changed: the
    /// stencils must be those of the last call, unless their entries have been written since
    /// (`Stencils::update`, `Stencils::reshape`), which `Stencils::take_leading` tells. Returns
    /// the first particle outside the grid.
    pub fn update_particles(
        &mut self,
        stencils: &mut Stencils<D>,
        grid: &Grid<D>,
        positions: &[SVector<f64, D>],
    ) -> Result<(), usize> {
        let mut warm = std::mem::take(&mut self.warm);
        warm.resize(positions.len(), None);
        let mut leading = stencils.take_leading();
        let (held_points, per_axis) = match D {
            2 => (positions.len(), self.per_axis),
            _ => (0, 0),
        };
        let held_len = held_points * per_axis;
        let (mut held_start, mut held_runs) = (
            std::mem::take(&mut self.held_start),
            std::mem::take(&mut self.held_runs),
        );
        // Held layouts describe these stencils only if the last call wrote them whole (it
        // set the leading counts, which any other write clears) for as many particles.
        if leading.len() != positions.len() || held_runs.len() != held_len {
            held_runs.clear();
        }
        leading.resize(positions.len(), 0);
        held_start.resize(held_points, [0; 2]);
        held_runs.resize(held_len, NOT_HELD);
        let mut held = held_start
            .iter_mut()
            .zip(held_runs.chunks_exact_mut(per_axis.max(1)))
            .map(|(start, runs)| Held { start, runs });
        let k = stencils.per_point;
        let chunks = stencils
            .node
            .chunks_exact_mut(k)
            .zip(stencils.weight.chunks_exact_mut(k))
            .zip(stencils.grad.chunks_exact_mut(k))
            .zip(positions.iter().zip(warm.iter_mut()));
        let mut factors = Factors::default();
        for (p, ((((node, weight), grad), (x, solution)), leading)) in
            chunks.zip(leading.iter_mut()).enumerate()
        {
            let held = if D == 2 { held.next() } else { None };
            let (status, selected) =
                self.fill(grid, x, solution, &mut factors, held, node, weight, grad);
            if !self.count(status) {
                // The leading counts stay unset, so the next call writes every stencil.
                (self.warm, self.held_start, self.held_runs) = (warm, held_start, held_runs);
                return Err(p);
            }
            *leading = selected as u32;
        }
        stencils.set_leading(leading);
        (self.warm, self.held_start, self.held_runs) = (warm, held_start, held_runs);
        Ok(())
    }

    /// Whether the point was on the grid; counts the evaluations that stopped short.
    fn count(&self, status: Result<usize, LmeFailure>) -> bool {
        match status {
            Ok(_) => true,
            Err(LmeFailure::Outside) => false,
            Err(_) => {
                self.failures.fetch_add(1, Ordering::Relaxed);
                true
            }
        }
    }

    /// `evaluate` with Newton starting from the prediction of `warm`, or from zero without
    /// one, and the number of selected nodes, which lead the stencil; `warm` is left at this
    /// solution, or at `None` when Newton stopped short. With `held` (2D) the nodes are
    /// written only if they differ from what it says the stencil holds, and it is updated.
    // The stencil's slots stay separate arguments: as `&mut` arguments they are known not to
    // alias, which a struct of them loses (0.7 % of `lme`'s instructions at gamma 3).
    #[allow(clippy::too_many_arguments)]
    fn fill(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        warm: &mut Option<Solution<D>>,
        factors: &mut Factors,
        mut held: Option<Held>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> (Result<usize, LmeFailure>, usize) {
        debug_assert_eq!(grid.dofs(), Dofs::Nodes);
        if grid.locate(x).is_none() {
            return (Err(LmeFailure::Outside), 0);
        }
        let s = (x - grid.lower) * grid.inv_h();
        let start = block_from(grid, &s.add_scalar(-self.radius), self.per_axis);
        // Row by row along the first axis, so that the other axes' part of the node index is
        // taken once a row; the rows' coordinates counted up, not divided out of an index
        // (perf's cycle samples sat on the two integer divisions per row).
        let radius_squared = self.radius * self.radius;
        let on_grid_along = (grid.cells + 1).saturating_sub(start[0]).min(self.per_axis);
        let held_start = std::array::from_fn(|k| start[k.min(D - 1)] as u32);
        let mut unchanged = held.as_ref().is_some_and(|held| *held.start == held_start);
        // (selected, unused): the stencil's slots taken from the front and from the back.
        let mut ends = (0, node.len());
        let mut local = [0; D];
        let mut rows = Rows::new(&s, &start);
        for row in 0..self.per_axis.pow(D as u32 - 1) {
            let block_row = BlockRow::new(grid, &s, &start, &local);
            let within = |along: usize| block_row.offset(along).norm_squared() <= radius_squared;
            // The row's selected nodes are a run lo..hi: the distance falls, then rises,
            // along it, and the nodes on the grid are a run from its start.
            let (mut lo, mut hi) = (0, if block_row.on_grid { on_grid_along } else { 0 });
            while lo < hi && !within(lo) {
                lo += 1;
            }
            while hi > lo && !within(hi - 1) {
                hi -= 1;
            }
            match &mut held {
                Some(held) => {
                    // A 2D block row has at most MAX_SIDE_2D nodes, so the casts are exact.
                    let run = (lo as u8, hi as u8);
                    unchanged &= held.runs[row] == run;
                    held.runs[row] = run;
                    ends.0 += hi - lo;
                }
                None => write_row(
                    &block_row,
                    lo..hi,
                    self.per_axis,
                    true,
                    &mut ends,
                    node,
                    weight,
                    grad,
                ),
            }
            if let Some(rows) = &mut rows {
                rows.push(lo..hi, local[D - 1]);
            }
            next_block_entry(&mut local[1..], self.per_axis);
        }
        let selected = ends.0;
        if let Some(held) = held.filter(|_| !unchanged) {
            // The nodes alone: in 2D the offsets are taken from the rows (`Rows::offsets`).
            *held.start = held_start;
            ends = (0, node.len());
            let mut local = [0; D];
            for &(lo, hi) in held.runs.iter() {
                let block_row = BlockRow::new(grid, &s, &start, &local);
                let run = usize::from(lo)..usize::from(hi);
                write_row(
                    &block_row,
                    run,
                    self.per_axis,
                    false,
                    &mut ends,
                    node,
                    weight,
                    grad,
                );
                next_block_entry(&mut local[1..], self.per_axis);
            }
            debug_assert_eq!(ends.0, selected);
        }
        let (offsets, weights) = (&mut grad[..selected], &mut weight[..selected]);
        let cold = SVector::zeros();
        let start_mu = warm.map_or(cold, |solution| solution.predict(&s, self.gamma));
        let (mut solved, mut by_rows) =
            self.newton(start_mu, rows.as_ref(), factors, offsets, weights);
        if solved.2.is_err() && warm.is_some() {
            // A warm start that falls short (from a multiplier grown large on a face, say)
            // is not yet a failure: the cold start may still converge.
            (solved, by_rows) = self.newton(cold, rows.as_ref(), factors, offsets, weights);
        }
        let (mu, at, status) = solved;
        // Eq 36 with the offsets taken about their mean r: at r = 0 it is eq 36, and at any
        // iterate it is the exact gradient of weights whose first moment misses x by the fixed
        // r, so sum_a grad p_a = 0 and sum_a x_a (x) grad p_a = I hold to round-off.
        let inverse = spd_inverse(&at.j);
        *warm = inverse
            .filter(|_| status.is_ok())
            .map(|inverse| Solution { s, mu, inverse });
        let gradient = |g: &mut SVector<f64, D>, d: SVector<f64, D>, p: f64| {
            *g = match &inverse {
                Some(inverse) => -(inverse * (d - at.r)) * (p * grid.inv_h()),
                None => SVector::zeros(),
            };
        };
        let (weight, grad) = (&mut weight[..selected], &mut grad[..selected]);
        match by_rows {
            Some(by_rows) => by_rows.write(&at.z, weight, grad, gradient),
            // Node by node the offsets are in `grad`.
            None => {
                for (g, p) in grad.iter_mut().zip(weight.iter()) {
                    gradient(g, *g, *p);
                }
            }
        }
        (status, selected)
    }

    /// Newton's method on log Z from `mu`, by rows where there are rows and their largest
    /// column and row meet at every iterate, node by node otherwise: the last iterate, its
    /// moments, and the number of steps or why Newton stopped short, and the rows' factors,
    /// from which `ByRows::write` takes the weights; without them the weights are left in
    /// `weight`, and the selected nodes' offsets in `offsets` (which the rows write there
    /// when there are rows; without rows they are there already).
    fn newton<'a>(
        &self,
        mu: SVector<f64, D>,
        rows: Option<&'a Rows>,
        factors: &'a mut Factors,
        offsets: &mut [SVector<f64, D>],
        weight: &mut [f64],
    ) -> (Solved<D>, Option<ByRows<'a>>) {
        if let Some(rows) = rows {
            let mut by_rows = ByRows::new(rows, factors, self.decay);
            if let Ok(solved) = self.solve(mu, &mut by_rows) {
                return (solved, Some(by_rows));
            }
            rows.offsets(offsets);
        }
        let offsets = &*offsets;
        let Ok(solved) = self.solve(mu, &mut ByNode { offsets, weight });
        (solved, None)
    }

    /// Newton's method on log Z from `mu` over the exponentials of `nodes`: the last iterate,
    /// its moments, and the number of steps or why Newton stopped short; `Err` when the
    /// exponentials cannot be taken that way at some iterate.
    fn solve<E: Evaluation<D>>(
        &self,
        mut mu: SVector<f64, D>,
        nodes: &mut E,
    ) -> Result<Solved<D>, E::Unusable> {
        let mut at = nodes.moments_at(self.gamma, &mu)?;
        let mut steps = 0;
        loop {
            let residual = at.r.norm();
            if residual < RESIDUAL_TOLERANCE {
                return Ok((mu, at, Ok(steps)));
            }
            if steps == self.max_iterations {
                return Ok((mu, at, Err(LmeFailure::NotConverged { residual })));
            }
            let Some(inverse) = spd_inverse(&at.j) else {
                return Ok((mu, at, Err(LmeFailure::Stalled { residual })));
            };
            let mut step = -(inverse * at.r);
            // Compared squared: the square root and division are taken only for a long step.
            let mut length_squared = step.norm_squared();
            if length_squared > self.max_step * self.max_step {
                step *= self.max_step / length_squared.sqrt();
                length_squared = step.norm_squared();
            }
            if length_squared * (self.radius * self.radius) <= SMALL_STEP * SMALL_STEP {
                let z = nodes.small_step(&step, &at.z);
                at = nodes.moments(z);
                mu += step;
                steps += 1;
                continue;
            }
            match self.line_search(&mu, &step, &at, nodes)? {
                Some((next_mu, next)) => (mu, at) = (next_mu, next),
                None => {
                    // The rejected trials replaced the exponentials.
                    let at = nodes.moments_at(self.gamma, &mu)?;
                    return Ok((mu, at, Err(LmeFailure::Stalled { residual })));
                }
            }
            steps += 1;
        }
    }

    /// The first of mu + step, mu + step / 2, ... whose log Z passes the Armijo test (up to
    /// round-off), with its moments; `None` when every halving fails.
    fn line_search<E: Evaluation<D>>(
        &self,
        mu: &SVector<f64, D>,
        step: &SVector<f64, D>,
        at: &Moments<D>,
        nodes: &mut E,
    ) -> Result<Option<(SVector<f64, D>, Moments<D>)>, E::Unusable> {
        let slope = at.r.dot(step);
        let log_z = at.log_z();
        let slack = ROUNDOFF * (1.0 + log_z.abs());
        let mut alpha = 1.0;
        for _ in 0..=MAX_HALVINGS {
            let trial_mu = mu + step * alpha;
            // The test needs log Z alone: r and J only for the trial taken.
            let trial = nodes.exponentials(self.gamma, &trial_mu)?;
            if trial.log_z() <= log_z + ARMIJO * alpha * slope + slack {
                return Ok(Some((trial_mu, nodes.moments(trial))));
            }
            alpha *= 0.5;
        }
        Ok(None)
    }
}

/// The multiplier Newton stopped at, its moments, and the number of steps or why it stopped
/// short.
type Solved<const D: usize> = (SVector<f64, D>, Moments<D>, Result<usize, LmeFailure>);

/// J^-1 of a covariance J, or `None` where J is not positive definite (to round-off). In 1D
/// and 2D it is the adjugate over the determinant, one division: the Cholesky factor and its
/// inverse are a chain of square roots and divisions that each Newton step and each gradient
/// of a point waits on.
fn spd_inverse<const D: usize>(j: &SMatrix<f64, D, D>) -> Option<SMatrix<f64, D, D>> {
    match D {
        1 => (j[0] > 0.0).then(|| SMatrix::from_element(1.0 / j[0])),
        2 => {
            let (a, b, c) = (j[(0, 0)], j[(1, 0)], j[(1, 1)]);
            let det = a * c - b * b;
            (a > 0.0 && det > 0.0).then(|| {
                let inv_det = 1.0 / det;
                SMatrix::from_fn(|k, l| match (k, l) {
                    (0, 0) => c * inv_det,
                    (1, 1) => a * inv_det,
                    _ => -b * inv_det,
                })
            })
        }
        _ => j.cholesky().map(|c| c.inverse()),
    }
}

/// The selected nodes in 2D as runs of columns (nodes along the first axis), one run per row
/// (along the second axis) of the block, in the stencil's order. |d_a|^2 and mu . d_a are
/// sums over the axes, so exp(f_a) is the product of a column's exponential and a row's
/// (`ByRows`), taken per column and row instead of per node (about pi r^2).
struct Rows {
    /// The point's scaled position and the block's first node, per axis: a column's or a
    /// row's offset is taken from them by `block_offset`, as `fill` takes the nodes'.
    s: [f64; 2],
    start: [usize; 2],
    /// The columns with a selected node in some row.
    columns: std::ops::Range<usize>,
    /// The first row with a selected node; those with one are consecutive (the rows of the
    /// grid meet the disc of the cut-off radius in a range).
    first_row: usize,
    /// Each row's selected columns, from `first_row` on.
    run: [(u8, u8); MAX_SIDE_2D],
    /// Rows with a selected node.
    count: usize,
}

impl Rows {
    /// No rows yet for the block from `start` about the scaled position `s`, in 2D; `None`
    /// in 1D, where each node is its own column.
    fn new<const D: usize>(s: &SVector<f64, D>, start: &[usize; D]) -> Option<Self> {
        (D == 2).then(|| Rows {
            s: [s[0], s[D - 1]],
            start: [start[0], start[D - 1]],
            // Empty, and any run pushed widens it to that run.
            columns: std::ops::Range {
                start: usize::MAX,
                end: 0,
            },
            first_row: 0,
            run: [(0, 0); MAX_SIDE_2D],
            count: 0,
        })
    }

    /// Adds row `row` of the block, whose selected columns are `run`, if any.
    fn push(&mut self, run: std::ops::Range<usize>, row: usize) {
        if run.is_empty() {
            return;
        }
        if self.count == 0 {
            self.first_row = row;
        }
        debug_assert_eq!(row, self.first_row + self.count);
        self.columns = self.columns.start.min(run.start)..self.columns.end.max(run.end);
        // A row of a 2D block has at most MAX_SIDE_2D nodes, so the casts are exact.
        self.run[self.count] = (run.start as u8, run.end as u8);
        self.count += 1;
    }

    /// The offset along `axis` of the block's `index`-th node on it.
    fn offset(&self, axis: usize, index: usize) -> f64 {
        block_offset(self.s[axis], self.start[axis] + index)
    }

    /// The selected nodes' offsets d_a, in the stencil's order, into `out`.
    fn offsets<const D: usize>(&self, out: &mut [SVector<f64, D>]) {
        let runs = self.run[..self.count].iter().zip(self.first_row..);
        let mut out = out.iter_mut();
        for (&(lo, hi), j) in runs {
            for i in usize::from(lo)..usize::from(hi) {
                let d = out.next().expect("a slot per selected node");
                *d = SVector::from_fn(|k, _| self.offset(k.min(1), if k == 0 { i } else { j }));
            }
        }
    }
}

/// The scaled offset s - node of the node numbered `node` along an axis from the scaled
/// position `s`.
#[inline]
fn block_offset(s: f64, node: usize) -> f64 {
    s - index_to_f64(node)
}

/// One row along the first axis of a point's stencil block: its nodes' indices and offsets.
struct BlockRow<const D: usize> {
    /// The other axes' part of the node index.
    first: usize,
    /// Whether the row lies on the grid.
    on_grid: bool,
    /// The offsets along the other axes; the first axis' entry is the point's s.
    across: SVector<f64, D>,
    start: usize,
    stride: usize,
    cells: usize,
}

impl<const D: usize> BlockRow<D> {
    /// The row `local` (the first axis' entry unused) of the block from `start` about the
    /// scaled position `s`.
    #[inline(always)]
    fn new(grid: &Grid<D>, s: &SVector<f64, D>, start: &[usize; D], local: &[usize; D]) -> Self {
        BlockRow {
            first: (1..D)
                .map(|k| (start[k] + local[k]).min(grid.cells) * grid.stride(k))
                .sum(),
            on_grid: (1..D).all(|k| start[k] + local[k] <= grid.cells),
            across: SVector::from_fn(|k, _| {
                if k == 0 {
                    s[0]
                } else {
                    block_offset(s[k], start[k] + local[k])
                }
            }),
            start: start[0],
            stride: grid.stride(0),
            cells: grid.cells,
        }
    }

    /// The index of the row's node `along`.
    #[inline(always)]
    fn index(&self, along: usize) -> u32 {
        (self.first + (self.start + along).min(self.cells) * self.stride) as u32
    }

    /// The offset d_a of the row's node `along`.
    #[inline(always)]
    fn offset(&self, along: usize) -> SVector<f64, D> {
        let mut d = self.across;
        d[0] = block_offset(self.across[0], self.start + along);
        d
    }
}

/// Writes a block row's entries into a stencil whose slots `ends` = (selected, unused) are
/// taken from the front and the back: the selected nodes `run` at the front, with their
/// offsets in `grad` if `offsets`, and the row's other nodes from the back with zero weight
/// and gradient while there is room. A selected node found later may take such a slot back,
/// so the full stencil lists each node once, the selected ones first.
// The stencil's slots stay separate `&mut` arguments, as in `fill`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn write_row<const D: usize>(
    row: &BlockRow<D>,
    run: std::ops::Range<usize>,
    per_axis: usize,
    offsets: bool,
    ends: &mut (usize, usize),
    node: &mut [u32],
    weight: &mut [f64],
    grad: &mut [SVector<f64, D>],
) {
    let (selected, unused) = ends;
    for along in (0..run.start).chain(run.end..per_axis) {
        if *unused <= *selected {
            break;
        }
        *unused -= 1;
        node[*unused] = row.index(along);
        weight[*unused] = 0.0;
        grad[*unused] = SVector::zeros();
    }
    for along in run {
        node[*selected] = row.index(along);
        if offsets {
            grad[*selected] = row.offset(along);
        }
        *selected += 1;
    }
}

/// Z, r and J at one multiplier mu, in scaled units. log Z is taken when asked for: a
/// Newton iteration that converges at its first moments or after a small step never needs
/// the last one's.
struct Moments<const D: usize> {
    z: Exponentials,
    r: SVector<f64, D>,
    j: SMatrix<f64, D, D>,
}

impl<const D: usize> Moments<D> {
    fn log_z(&self) -> f64 {
        self.z.log_z()
    }
}

/// Z at one multiplier mu as exp(`largest`) `z`, where the exponentials an `Evaluation` holds
/// are exp(f_a - largest): `largest` is at least the largest f_a when they are taken afresh,
/// so that none overflows.
#[derive(Clone, Copy)]
struct Exponentials {
    largest: f64,
    z: f64,
}

impl Exponentials {
    fn log_z(&self) -> f64 {
        self.largest + self.z.ln()
    }
}

/// The exponentials exp(f_a) of the selected nodes at Newton's current multiplier, and the
/// moments taken from them.
trait Evaluation<const D: usize> {
    /// Why the exponentials cannot be taken this way at some multiplier.
    type Unusable;

    /// Takes the exponentials at `mu`, in place of the last ones.
    fn exponentials(
        &mut self,
        gamma: f64,
        mu: &SVector<f64, D>,
    ) -> Result<Exponentials, Self::Unusable>;

    /// Multiplies the exponentials, whose sum is `z`, by exp(step . d_a) for a step with
    /// |step . d_a| <= SMALL_STEP, as 1 + x + x^2 / 2 (the terms left out are under 1.7e-19
    /// of a weight, below its round-off): Z at mu + `step`.
    fn small_step(&mut self, step: &SVector<f64, D>, z: &Exponentials) -> Exponentials;

    /// r and J of the exponentials, whose sum is `z`.
    fn moments(&mut self, z: Exponentials) -> Moments<D>;

    /// `exponentials` at `mu`, then their moments.
    fn moments_at(
        &mut self,
        gamma: f64,
        mu: &SVector<f64, D>,
    ) -> Result<Moments<D>, Self::Unusable> {
        let z = self.exponentials(gamma, mu)?;
        Ok(self.moments(z))
    }
}

/// The exponentials node by node, held in the weights: exp(f_a - largest) once taken, and
/// normalised to p_a by `moments`.
struct ByNode<'a, const D: usize> {
    offsets: &'a [SVector<f64, D>],
    weight: &'a mut [f64],
}

impl<const D: usize> Evaluation<D> for ByNode<'_, D> {
    type Unusable = std::convert::Infallible;

    fn exponentials(
        &mut self,
        gamma: f64,
        mu: &SVector<f64, D>,
    ) -> Result<Exponentials, Self::Unusable> {
        // Subtracting the largest exponent keeps exp from overflowing and Z >= 1. The exponents
        // are finite, so a comparison does what f64::max does without its NaN handling.
        let mut largest = f64::NEG_INFINITY;
        for (p, d) in self.weight.iter_mut().zip(self.offsets) {
            *p = -gamma * d.norm_squared() + mu.dot(d);
            if *p > largest {
                largest = *p;
            }
        }
        let mut z = 0.0;
        for p in self.weight.iter_mut() {
            *p = (*p - largest).exp();
            z += *p;
        }
        Ok(Exponentials { largest, z })
    }

    /// After `moments` the weights are p_a, whose sum stands for Z(mu): Z(mu + step) =
    /// Z(mu) sum_a p_a exp(step . d_a).
    fn small_step(&mut self, step: &SVector<f64, D>, z: &Exponentials) -> Exponentials {
        let mut sum = 0.0;
        for (p, d) in self.weight.iter_mut().zip(self.offsets) {
            let x = step.dot(d);
            *p *= 1.0 + x * (1.0 + 0.5 * x);
            sum += *p;
        }
        Exponentials {
            largest: z.log_z(),
            z: sum,
        }
    }

    /// Normalises the exponentials to p_a and takes r and J from them.
    fn moments(&mut self, z: Exponentials) -> Moments<D> {
        let mut r = SVector::zeros();
        // One division per evaluation instead of one per node.
        let inv_z = 1.0 / z.z;
        for (p, d) in self.weight.iter_mut().zip(self.offsets) {
            *p *= inv_z;
            r += d * *p;
        }
        // The covariance sum_a p_a (d_a - r)(d_a - r)^T is eq 37's J without its cancellation,
        // summed in its lower triangle: c_k c_l = c_l c_k, so the upper one is the same.
        let mut j = SMatrix::<f64, D, D>::zeros();
        for (p, d) in self.weight.iter().zip(self.offsets) {
            let c = d - r;
            for l in 0..D {
                for k in l..D {
                    j[(k, l)] += c[k] * c[l] * *p;
                }
            }
        }
        j.fill_upper_triangle_with_lower_triangle();
        Moments { z, r, j }
    }
}

/// The largest column and row do not meet at a selected node, which takes a large mu (a
/// point near a face that Newton has not resolved): the sums by rows could underflow or
/// cancel.
struct Apart;

/// The exponentials in 2D by the block's columns and rows (`Rows`): f_a is a term of the
/// node's column (its offset d along the first axis) plus a term of its row (its offset e
/// along the second), so exp(f_a) = c_i w_j, each factor shifted by the largest of its axis.
/// The moments are sums of such products too. About the offsets (m, n) of the largest column
/// and row, with a row's sums C_k = sum_i c_i (d_i - m)^k over its run, Z = sum_j w_j C_0,
/// Z (r - (m, n)) = (sum_j w_j C_1, sum_j w_j (e_j - n) C_0) and Z (J + (r - (m, n))(r - (m,
/// n))^T) = sum_j w_j [C_2, (e_j - n) C_1; (e_j - n) C_1, (e_j - n)^2 C_0]. Newton then
/// works on 2 per_axis factors, not on every node (about pi r^2), and the weights are written
/// once, at the end.
///
/// **Round-off.** A row's C_k is a difference of prefix sums over the columns. Where the
/// largest column and row meet at a selected node, c_i, w_j <= 1 and Z >= 1, so what the
/// differences cancel is at most round-off of the sum of all columns times all rows, a few
/// tens of ulps of Z. About (m, n), the mode of a unimodal distribution, J's cancellation is
/// bounded too: (r - m)^2 <= 3 J for such a distribution, where about the origin r^2 could
/// dwarf J (a point between nodes at a large gamma).
struct ByRows<'a> {
    rows: &'a Rows,
    f: &'a mut Factors,
    /// The offsets (m, n) of the largest column and row when the exponentials were taken.
    mode: [f64; 2],
    /// exp(-2 gamma).
    decay: f64,
    /// Z, Z (r - (m, n)) and Z (J + (r - (m, n))(r - (m, n))^T) / exp(largest): (sum_j w_j
    /// C_0, sum_j w_j C_1, sum_j w_j (e_j - n) C_0, sum_j w_j C_2, sum_j w_j (e_j - n) C_1,
    /// sum_j w_j (e_j - n)^2 C_0).
    totals: [f64; 6],
}

/// The arrays of `ByRows`, kept from one point to the next so that they are not zeroed for
/// each.
struct Factors {
    /// The block's columns' offsets d and exponentials c, by column.
    column_offset: [f64; MAX_SIDE_2D],
    column: [f64; MAX_SIDE_2D],
    /// The rows' offsets e and exponentials w, from `Rows::first_row`.
    row_offset: [f64; MAX_SIDE_2D],
    row: [f64; MAX_SIDE_2D],
    /// By column, the sums of c_i (d_i - m)^k over the columns before it from
    /// `Rows::columns`' start. As long as a `u8` can count, so that a run's ends index it
    /// unchecked.
    prefix: [[f64; 3]; 256],
}

impl Default for Factors {
    fn default() -> Self {
        Factors {
            column_offset: [0.0; MAX_SIDE_2D],
            column: [0.0; MAX_SIDE_2D],
            row_offset: [0.0; MAX_SIDE_2D],
            row: [0.0; MAX_SIDE_2D],
            prefix: [[0.0; 3]; 256],
        }
    }
}

impl<'a> ByRows<'a> {
    fn new(rows: &'a Rows, f: &'a mut Factors, decay: f64) -> Self {
        let columns = rows.columns.clone();
        for (d, i) in f.column_offset[columns.clone()].iter_mut().zip(columns) {
            *d = rows.offset(0, i);
        }
        for (e, j) in f.row_offset[..rows.count].iter_mut().zip(rows.first_row..) {
            *e = rows.offset(1, j);
        }
        ByRows {
            rows,
            f,
            decay,
            mode: [0.0; 2],
            totals: [0.0; 6],
        }
    }

    /// The totals of the factors about the mode.
    fn sum_rows(&mut self) {
        let f = &mut *self.f;
        let columns = self.rows.columns.clone();
        let [m, n] = self.mode;
        f.prefix[columns.start] = [0.0; 3];
        for i in columns {
            let (c, d) = (f.column[i], f.column_offset[i] - m);
            let cd = c * d;
            let before = f.prefix[i];
            f.prefix[i + 1] = [before[0] + c, before[1] + cd, before[2] + cd * d];
        }
        let mut totals = [0.0; 6];
        let rows = self.rows.run[..self.rows.count]
            .iter()
            .zip(&f.row)
            .zip(&f.row_offset);
        for ((run, w), e) in rows {
            let (lo, hi) = (f.prefix[usize::from(run.0)], f.prefix[usize::from(run.1)]);
            let sums = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
            let e = e - n;
            let we = w * e;
            totals[0] += w * sums[0];
            totals[1] += w * sums[1];
            totals[2] += we * sums[0];
            totals[3] += w * sums[2];
            totals[4] += we * sums[1];
            totals[5] += we * e * sums[0];
        }
        self.totals = totals;
    }

    /// Writes the weights p_a = c_i w_j / Z of the factors, whose sum is `z`, in the
    /// stencil's order, and calls `gradient(g_a, d_a, p_a)` on each node's gradient slot,
    /// with its offset d_a from its column's and row's.
    fn write<const D: usize>(
        &self,
        z: &Exponentials,
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
        gradient: impl Fn(&mut SVector<f64, D>, SVector<f64, D>, f64),
    ) {
        let inv_z = 1.0 / z.z;
        let (mut weight, mut grad) = (weight, grad);
        let rows = self.rows.run[..self.rows.count]
            .iter()
            .zip(&self.f.row)
            .zip(&self.f.row_offset);
        for ((run, w), &e) in rows {
            let (lo, hi) = (usize::from(run.0), usize::from(run.1));
            let (p, after) = weight.split_at_mut(hi - lo);
            let (g, grad_after) = grad.split_at_mut(hi - lo);
            let w = w * inv_z;
            let columns = self.f.column[lo..hi]
                .iter()
                .zip(&self.f.column_offset[lo..hi]);
            for ((p, g), (c, &d)) in p.iter_mut().zip(g).zip(columns) {
                *p = c * w;
                gradient(g, SVector::from_fn(|k, _| if k == 0 { d } else { e }), *p);
            }
            (weight, grad) = (after, grad_after);
        }
    }
}

impl<const D: usize> Evaluation<D> for ByRows<'_> {
    type Unusable = Apart;

    fn exponentials(&mut self, gamma: f64, mu: &SVector<f64, D>) -> Result<Exponentials, Apart> {
        let (columns, rows) = (self.rows.columns.clone(), self.rows.count);
        let (column_largest, mode_column) = shifted_exponentials(
            gamma,
            self.decay,
            mu[0],
            &self.f.column_offset[columns.clone()],
            &mut self.f.column[columns.clone()],
        );
        let (row_largest, mode_row) = shifted_exponentials(
            gamma,
            self.decay,
            mu[D - 1],
            &self.f.row_offset[..rows],
            &mut self.f.row[..rows],
        );
        let (run, mode_column) = (self.rows.run[mode_row], columns.start + mode_column);
        if !(usize::from(run.0)..usize::from(run.1)).contains(&mode_column) {
            return Err(Apart);
        }
        self.mode = [
            self.f.column_offset[mode_column],
            self.f.row_offset[mode_row],
        ];
        self.sum_rows();
        Ok(Exponentials {
            largest: column_largest + row_largest,
            z: self.totals[0],
        })
    }

    /// Each factor takes its axis' part of step . d_a: exp(x + y) = exp(x) exp(y), each to
    /// second order. The factors stay within 1e-6 of their largest's, which still meet.
    fn small_step(&mut self, step: &SVector<f64, D>, z: &Exponentials) -> Exponentials {
        let (columns, rows) = (self.rows.columns.clone(), self.rows.count);
        let scale = |factors: &mut [f64], offsets: &[f64], step: f64| {
            for (f, d) in factors.iter_mut().zip(offsets) {
                let x = step * d;
                *f *= 1.0 + x * (1.0 + 0.5 * x);
            }
        };
        let f = &mut *self.f;
        scale(
            &mut f.column[columns.clone()],
            &f.column_offset[columns],
            step[0],
        );
        scale(&mut f.row[..rows], &f.row_offset[..rows], step[D - 1]);
        self.sum_rows();
        Exponentials {
            largest: z.largest,
            z: self.totals[0],
        }
    }

    fn moments(&mut self, z: Exponentials) -> Moments<D> {
        let inv_z = 1.0 / z.z;
        let t = self.totals;
        let from_mode = [t[1] * inv_z, t[2] * inv_z];
        let second = [t[3], t[4], t[5]];
        Moments {
            z,
            r: SVector::from_fn(|k, _| from_mode[k.min(1)] + self.mode[k.min(1)]),
            j: SMatrix::from_fn(|k, l| {
                let (k, l) = (k.min(1), l.min(1));
                second[k + l] * inv_z - from_mode[k] * from_mode[l]
            }),
        }
    }
}

/// exp(e_k - largest) into `out` for the exponents e_k = -gamma d_k^2 + mu d_k of one axis'
/// offsets d_k, which fall by 1 from one node to the next; returns the largest and its
/// position. Two calls of exp: the neighbours of the largest take exp(e_k - largest), and from
/// there each next ratio exp(e_k+1 - e_k) = exp(2 gamma d_k - gamma - mu) is the last one
/// times `decay` = exp(-2 gamma), on either side. The products carry about k^2 / 2 ulps at k
/// nodes from the largest, as many as rounding exponents of up to gamma r^2 costs exp.
fn shifted_exponentials(
    gamma: f64,
    decay: f64,
    mu: f64,
    offsets: &[f64],
    out: &mut [f64],
) -> (f64, usize) {
    let (mut largest, mut at) = (f64::NEG_INFINITY, 0);
    for (k, (e, d)) in out.iter_mut().zip(offsets).enumerate() {
        *e = -gamma * (d * d) + mu * d;
        if *e > largest {
            (largest, at) = (*e, k);
        }
    }
    let (below, rest) = out.split_at_mut(at);
    let Some((mode, above)) = rest.split_first_mut() else {
        return (largest, at);
    };
    *mode = 1.0;
    decaying(above.iter_mut(), largest, decay);
    decaying(below.iter_mut().rev(), largest, decay);
    (largest, at)
}

/// The exponentials along one side of the largest, nearest first, from their exponents in
/// `side` (`shifted_exponentials`).
fn decaying<'a>(mut side: impl Iterator<Item = &'a mut f64>, largest: f64, decay: f64) {
    let Some(first) = side.next() else {
        return;
    };
    let mut ratio = (*first - largest).exp();
    *first = ratio;
    let mut last = ratio;
    for e in side {
        ratio *= decay;
        last *= ratio;
        *e = last;
    }
}

impl<const D: usize> Shape<D> for LocalMaxEnt<D> {
    fn nodes_per_point(&self) -> usize {
        self.per_point
    }

    fn eval(
        &self,
        grid: &Grid<D>,
        x: &SVector<f64, D>,
        node: &mut [u32],
        weight: &mut [f64],
        grad: &mut [SVector<f64, D>],
    ) -> bool {
        self.count(self.evaluate(grid, x, node, weight, grad))
    }
}

#[cfg(test)]
mod tests;
