use nalgebra::{SMatrix, SVector};

use super::*;
use crate::grid::{lattice_coords, Domain};
use crate::rng::Lcg;
use crate::shape::stencils::assert_gradient_matches_differences;
use crate::shape::{LinearHat, Stencils};

/// The two values of gamma Molinos et al. run.
const PAPER_GAMMAS: [f64; 2] = [0.8, 3.0];

fn grid<const D: usize>(cells: usize) -> Grid<D> {
    Grid::new(&Domain {
        lower: SVector::repeat(-0.5),
        upper: SVector::repeat(1.5),
        cells,
    })
}

/// One point's stencil, (node, p_a, grad p_a) per entry, and the Newton result.
type Basis<const D: usize> = (
    Vec<(usize, f64, SVector<f64, D>)>,
    Result<usize, LmeFailure>,
);

fn basis_at<const D: usize>(lme: &LocalMaxEnt<D>, g: &Grid<D>, x: &SVector<f64, D>) -> Basis<D> {
    let n = lme.nodes_per_point();
    let (mut node, mut weight, mut grad) = (vec![0; n], vec![0.0; n], vec![SVector::zeros(); n]);
    let status = lme.evaluate(g, x, &mut node, &mut weight, &mut grad);
    let entries = (0..n)
        .map(|e| (node[e] as usize, weight[e], grad[e]))
        .collect();
    (entries, status)
}

/// Along each axis (in cells from the lower face): the faces, points 1e-10 and 1e-3 cells
/// inside them, the middle of the first cell, the nodes next to the faces and a middle node.
fn special_coordinates(cells: usize) -> Vec<f64> {
    let c = cells as f64;
    let half = (cells / 2) as f64;
    vec![
        0.0,
        1e-10,
        1e-3,
        0.5,
        1.0,
        half,
        c - 1.0,
        c - 1e-3,
        c - 1e-10,
        c,
    ]
}

/// Random points and every combination of the special coordinates.
fn points<const D: usize>(g: &Grid<D>, seed: u64) -> Vec<SVector<f64, D>> {
    let length = g.cells as f64 * g.h;
    let mut rng = Lcg::new(seed);
    let mut xs: Vec<SVector<f64, D>> = (0..200)
        .map(|_| g.lower + SVector::from_fn(|_, _| length * rng.unit()))
        .collect();
    let special = special_coordinates(g.cells);
    let n = [special.len(); D];
    for m in 0..special.len().pow(D as u32) {
        let ijk = lattice_coords(m, &n);
        xs.push(g.lower + SVector::from_fn(|k, _| special[ijk[k]] * g.h));
    }
    xs
}

/// Partition of unity, non-negativity, sum_a p_a x_a = x, sum_a grad p_a = 0 and
/// sum_a x_a (x) grad p_a = I.
fn check_consistency<const D: usize>(gamma: f64, cells: usize) {
    let g = grid::<D>(cells);
    let lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    for x in points(&g, 0x2545f4914f6cdd1d) {
        let (entries, status) = basis_at(&lme, &g, &x);
        status.unwrap_or_else(|e| panic!("{x:?}: {e:?}"));
        let sum_w: f64 = entries.iter().map(|e| e.1).sum();
        let sum_wx: SVector<f64, D> = entries
            .iter()
            .map(|(i, w, _)| g.node_position(*i) * *w)
            .sum();
        let sum_g: SVector<f64, D> = entries.iter().map(|e| e.2).sum();
        let sum_gx: SMatrix<f64, D, D> = entries
            .iter()
            .map(|(i, _, gr)| g.node_position(*i) * gr.transpose())
            .sum();
        assert!((sum_w - 1.0).abs() < 1e-14, "{x:?}: sum p = {sum_w}");
        assert!(entries.iter().all(|e| e.1 >= 0.0), "{x:?}: negative p");
        let miss = (sum_wx - x).norm() / g.h;
        assert!(
            miss < RESIDUAL_TOLERANCE,
            "{x:?}: |sum p x_a - x| = {miss} h"
        );
        assert!(sum_g.norm() * g.h < 1e-12, "{x:?}: sum grad p = {sum_g:?}");
        let identity = SMatrix::<f64, D, D>::identity();
        assert!((sum_gx - identity).norm() < 1e-12, "{x:?}: {sum_gx:?}");
    }
    assert_eq!(lme.failures(), 0);
}

#[test]
fn lme_consistency_1d() {
    for gamma in PAPER_GAMMAS {
        for cells in [2, 5, 12] {
            check_consistency::<1>(gamma, cells);
        }
    }
}

#[test]
fn lme_consistency_2d() {
    for gamma in PAPER_GAMMAS {
        for cells in [2, 5, 10] {
            check_consistency::<2>(gamma, cells);
        }
    }
}

/// The most Newton steps at the points at least `from_face` cells from every face and at the
/// others.
fn most_steps<const D: usize>(gamma: f64, cells: usize, from_face: f64) -> (usize, usize) {
    let g = grid::<D>(cells);
    let lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    let (mut inside, mut near_face) = (0, 0);
    for x in points(&g, 0x2545f4914f6cdd1d) {
        let steps = basis_at(&lme, &g, &x).1.unwrap();
        let s = (x - g.lower) / g.h;
        if s.iter()
            .all(|&s| s >= from_face && s <= cells as f64 - from_face)
        {
            inside = inside.max(steps);
        } else {
            near_face = near_face.max(steps);
        }
    }
    (inside, near_face)
}

/// At gamma = 0.8 and 3 Newton needs at most 10 steps at 1e-4 cells or more from the faces
/// (1-4 at most random points, 8-10 at 1e-3 cells from a face); 22-24 at 1e-10 cells and
/// 25-27 on a face, where the multiplier is infinite.
#[test]
fn lme_paper_gammas_converge_in_few_iterations() {
    for gamma in PAPER_GAMMAS {
        let one = most_steps::<1>(gamma, 12, 1e-4);
        let two = most_steps::<2>(gamma, 10, 1e-4);
        for (inside, near_face) in [one, two] {
            assert!(inside <= 10, "gamma {gamma}: {inside} steps");
            assert!(near_face <= 30, "gamma {gamma}: {near_face} steps");
        }
    }
}

/// The stencil holds every grid node within the cut-off radius, once, and no other node with
/// a weight.
fn check_stencil<const D: usize>(gamma: f64, cells: usize) {
    let g = grid::<D>(cells);
    let lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    for x in points(&g, 11) {
        let (entries, _) = basis_at(&lme, &g, &x);
        let mut weighted: Vec<usize> = entries.iter().filter(|e| e.1 > 0.0).map(|e| e.0).collect();
        weighted.sort_unstable();
        let within: Vec<usize> = (0..g.num_nodes())
            .filter(|&i| (g.node_position(i) - x).norm() <= lme.radius() * g.h)
            .collect();
        assert_eq!(weighted, within, "{x:?}");
        assert!(entries.iter().all(|e| e.0 < g.num_nodes()));
    }
}

#[test]
fn lme_stencil_holds_the_nodes_within_the_cut_off() {
    let sizes: Vec<(usize, usize)> = PAPER_GAMMAS
        .iter()
        .map(|&gamma| {
            let one = LocalMaxEnt::<1>::new(gamma).unwrap().nodes_per_point();
            let two = LocalMaxEnt::<2>::new(gamma).unwrap().nodes_per_point();
            (one, two)
        })
        .collect();
    assert_eq!(sizes, vec![(9, 58), (5, 16)]);
    for gamma in PAPER_GAMMAS {
        check_stencil::<1>(gamma, 3);
        check_stencil::<1>(gamma, 12);
        check_stencil::<2>(gamma, 3);
        check_stencil::<2>(gamma, 10);
    }
}

/// Gradients agree with central differences of the values at random points, next to the
/// faces (1e-3 cells inside, beyond the difference step) and at nodes.
fn check_gradient<const D: usize>(gamma: f64) {
    let g = grid::<D>(10);
    let lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    for x in points(&g, 77) {
        let s = (x - g.lower) / g.h;
        if s.iter().all(|&s| s >= 1e-3 && s <= g.cells as f64 - 1e-3) {
            assert_gradient_matches_differences(&lme, &g, &x, 1e-6);
        }
    }
}

#[test]
fn lme_gradient_matches_finite_differences_1d() {
    for gamma in PAPER_GAMMAS {
        check_gradient::<1>(gamma);
    }
}

#[test]
fn lme_gradient_matches_finite_differences_2d() {
    for gamma in PAPER_GAMMAS {
        check_gradient::<2>(gamma);
    }
}

/// The largest difference between the weights and the hat's, over random points, points
/// next to and on the faces, and nodes.
fn distance_to_hat<const D: usize>(gamma: f64) -> f64 {
    let g = grid::<D>(6);
    // A cut-off beyond sqrt(D) h keeps every corner of the point's cell: with fewer, the
    // large-gamma limit in 2D is linear on triangles, not the bilinear hat.
    let lme = LocalMaxEnt::<D>::with_tolerance(gamma, (-2.5 * gamma).exp()).unwrap();
    let hat = <LinearHat as Shape<D>>::nodes_per_point(&LinearHat);
    let mut worst: f64 = 0.0;
    for x in points(&g, 5) {
        let (entries, status) = basis_at(&lme, &g, &x);
        status.unwrap_or_else(|e| panic!("{x:?}: {e:?}"));
        let (mut node, mut weight, mut grad) =
            (vec![0; hat], vec![0.0; hat], vec![SVector::zeros(); hat]);
        assert!(LinearHat.eval(&g, &x, &mut node, &mut weight, &mut grad));
        for (i, p, _) in &entries {
            let n: f64 = (0..hat)
                .filter(|&c| node[c] as usize == *i)
                .map(|c| weight[c])
                .sum();
            if *p > 0.0 || n > 0.0 {
                worst = worst.max((p - n).abs());
            }
        }
    }
    worst
}

/// As gamma grows the weights tend to the hat's. The largest difference is at a node, where
/// its 2D neighbours take about e^-gamma each, until the Newton residual dominates.
#[test]
fn lme_tends_to_the_linear_hat() {
    for gamma in [10.0_f64, 30.0, 100.0] {
        let bound = |d: f64| 2.0 * d * (-gamma).exp() + 2.0 * RESIDUAL_TOLERANCE;
        let one = distance_to_hat::<1>(gamma);
        let two = distance_to_hat::<2>(gamma);
        assert!(one <= bound(1.0), "gamma {gamma}: {one:e}");
        assert!(two <= bound(2.0), "gamma {gamma}: {two:e}");
    }
}

/// An iteration limit of one step fails at most points: `eval` still fills a partition of
/// unity and counts each failure; a point outside the grid is not a failure.
#[test]
fn lme_failures_are_counted() {
    let g = grid::<2>(6);
    let lme = LocalMaxEnt::<2>::new(0.8).unwrap().with_max_iterations(1);
    let xs = points(&g, 3);
    let n = lme.nodes_per_point();
    let mut failed = 0;
    for x in &xs {
        let (entries, status) = basis_at(&lme, &g, x);
        if let Err(failure) = status {
            assert!(matches!(failure, LmeFailure::NotConverged { residual } if residual > 0.0));
            failed += 1;
        }
        let sum_w: f64 = entries.iter().map(|e| e.1).sum();
        assert!((sum_w - 1.0).abs() < 1e-14 && entries.iter().all(|e| e.1 >= 0.0));
    }
    assert!(failed > xs.len() / 2, "{failed} of {}", xs.len());
    let (mut node, mut weight, mut grad) = (vec![0; n], vec![0.0; n], vec![SVector::zeros(); n]);
    for x in &xs {
        assert!(lme.eval(&g, x, &mut node, &mut weight, &mut grad));
    }
    assert_eq!(lme.failures(), failed);
    let outside = SVector::<f64, 2>::new(1.6, 0.0);
    assert!(!lme.eval(&g, &outside, &mut node, &mut weight, &mut grad));
    assert_eq!(lme.failures(), failed);
}

/// gamma and tolerance must give a cut-off radius that surrounds every point of a cell: more
/// than h in 1D, more than sqrt(5)/2 h in 2D.
#[test]
fn lme_parameters_are_validated() {
    assert!(LocalMaxEnt::<1>::new(0.0).is_err());
    assert!(LocalMaxEnt::<1>::new(-1.0).is_err());
    assert!(LocalMaxEnt::<1>::with_tolerance(1.0, 1.0).is_err());
    assert!(LocalMaxEnt::<1>::with_tolerance(1.0, 0.0).is_err());
    assert!(LocalMaxEnt::<1>::new(12.0).is_ok());
    assert!(LocalMaxEnt::<2>::new(12.0).is_err());
    assert!(LocalMaxEnt::<2>::new(11.0).is_ok());
    let radius = LocalMaxEnt::<2>::new(0.8).unwrap().radius();
    assert!((radius - 4.1556).abs() < 1e-4, "{radius}");
}

/// The stencil block is at most MAX_STENCIL_NODES nodes: gamma is bounded below at each
/// tolerance, and the message gives the stencil and the smallest gamma it allows.
#[test]
fn stencils_are_bounded() {
    // 2D, tolerance 1e-6: gamma > 4 (-ln 1e-6) / 32^2 = 0.05396.
    assert!(LocalMaxEnt::<2>::new(0.054).is_ok());
    let e = LocalMaxEnt::<2>::new(0.0539).unwrap_err();
    assert_eq!(e.stencil_nodes, Some(33.0 * 33.0));
    let text = e.to_string();
    assert!(
        text.contains("1.0890e3 nodes per point in 2D; at most 1024")
            && text.contains("gamma > 5.3967e-2"),
        "{text}"
    );
    // 1D: gamma = 1e-9 would take 235,079 nodes per point.
    assert_eq!(
        LocalMaxEnt::<1>::new(5.3e-5).unwrap().nodes_per_point(),
        1022
    );
    let e = LocalMaxEnt::<1>::new(1e-9).unwrap_err();
    assert_eq!(e.stencil_nodes, Some(235_079.0));
    // A tiny tolerance widens the stencil as a tiny gamma does.
    assert!(LocalMaxEnt::<1>::with_tolerance(1.0, 1e-300).is_ok());
    assert!(LocalMaxEnt::<2>::with_tolerance(1.0, 1e-300).is_err());
}

/// Stencils of `lme` evaluated cold, through `Shape::eval`.
fn cold_stencils<const D: usize>(
    lme: &LocalMaxEnt<D>,
    g: &Grid<D>,
    xs: &[SVector<f64, D>],
) -> Stencils<D> {
    let mut stencils = Stencils::new(lme.nodes_per_point(), xs.len());
    stencils.update(lme, g, xs).unwrap();
    stencils
}

/// The entries `of` leaves out of `update_particles`' stencils are the zero ones, and there
/// are some: the selected nodes lead each stencil.
fn assert_skips_only_zeros<const D: usize>(stencils: &Stencils<D>) {
    let k = stencils.per_point;
    let mut skipped = 0;
    for p in 0..stencils.node.len() / k {
        let listed = stencils.of(p).count();
        let (weight, grad) = (&stencils.weight[p * k..][..k], &stencils.grad[p * k..][..k]);
        assert!(weight[listed..].iter().all(|&w| w == 0.0));
        assert!(grad[listed..].iter().all(|g| g.iter().all(|&c| c == 0.0)));
        assert!(weight[..listed].iter().all(|&w| w > 0.0), "{weight:?}");
        skipped += k - listed;
    }
    assert!(skipped > 0);
}

/// `update_particles` starts cold, bit for bit `eval`'s stencils; after the particles move
/// (off the faces too, where the last multiplier was huge) its warm starts agree with cold
/// evaluations to the Newton tolerance, and still reproduce x to it.
fn check_warm_start<const D: usize>(gamma: f64) {
    let g = grid::<D>(6);
    let cold_lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    let mut lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    let mut xs = points(&g, 0x9e3779b97f4a7c15);
    let mut warm = Stencils::new(lme.nodes_per_point(), xs.len());
    lme.update_particles(&mut warm, &g, &xs).unwrap();
    let cold = cold_stencils(&cold_lme, &g, &xs);
    assert_eq!(
        (&warm.node, &warm.weight, &warm.grad),
        (&cold.node, &cold.weight, &cold.grad)
    );
    assert_skips_only_zeros(&warm);
    let centre = g.lower + SVector::repeat(0.5 * g.cells as f64 * g.h);
    for pass in 1..=3 {
        let shrink = 1.0 - 1e-4 * f64::from(pass);
        for x in &mut xs {
            *x = centre + (*x - centre) * shrink;
        }
        lme.update_particles(&mut warm, &g, &xs).unwrap();
        assert_skips_only_zeros(&warm);
        let cold = cold_stencils(&cold_lme, &g, &xs);
        assert_eq!(warm.node, cold.node);
        for (p, x) in xs.iter().enumerate() {
            let moment: SVector<f64, D> = warm.of(p).map(|(i, w, _)| g.node_position(i) * w).sum();
            assert!(
                (moment - x).norm() < 1.1 * RESIDUAL_TOLERANCE * g.h,
                "{x:?}"
            );
            for ((_, w, gr), (_, wc, grc)) in warm.of(p).zip(cold.of(p)) {
                assert!((w - wc).abs() < 1e-11, "{x:?}: {w} vs {wc}");
                assert!((gr - grc).norm() < 1e-9 / g.h, "{x:?}: {gr:?} vs {grc:?}");
            }
        }
    }
    assert_eq!(lme.failures(), 0);
}

#[test]
fn lme_warm_start_agrees_with_cold_start() {
    for gamma in PAPER_GAMMAS {
        check_warm_start::<1>(gamma);
        check_warm_start::<2>(gamma);
    }
}

/// `update_particles` writes a stencil's nodes again where the selection changed, and only
/// there, matching cold evaluations node for node, and starts afresh on stencils that were
/// written otherwise in between.
fn check_held_layouts<const D: usize>(gamma: f64) {
    let g = grid::<D>(6);
    let cold_lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    let mut lme = LocalMaxEnt::<D>::new(gamma).unwrap();
    // The same special points, different random ones: some selections change, some do not.
    let (xs, ys) = (
        points(&g, 0x9e3779b97f4a7c15),
        points(&g, 0x2545f4914f6cdd1d),
    );
    let mut stencils = Stencils::new(lme.nodes_per_point(), xs.len());
    let agree = |stencils: &Stencils<D>, at: &[SVector<f64, D>]| {
        let cold = cold_stencils(&cold_lme, &g, at);
        assert_eq!(stencils.node, cold.node);
        assert_skips_only_zeros(stencils);
        for (w, wc) in stencils.weight.iter().zip(&cold.weight) {
            assert!((w - wc).abs() < 1e-11, "{w} vs {wc}");
        }
    };
    for at in [&xs, &ys, &xs] {
        lme.update_particles(&mut stencils, &g, at).unwrap();
        agree(&stencils, at);
    }
    stencils.update(&cold_lme, &g, &ys).unwrap();
    lme.update_particles(&mut stencils, &g, &xs).unwrap();
    agree(&stencils, &xs);
    assert_eq!(lme.failures(), 0);
}

#[test]
fn lme_stencils_are_rewritten_where_the_selection_changed() {
    for gamma in PAPER_GAMMAS {
        check_held_layouts::<1>(gamma);
        check_held_layouts::<2>(gamma);
    }
}

/// The most nodes the selection test admits around any of the points of a fine lattice over
/// one cell (and its faces), counted as `fill` counts them.
fn most_selected_on_lattice<const D: usize>(radius: f64, steps: usize) -> usize {
    let reach = radius.ceil() as i64 + 1;
    let radius_squared = radius * radius;
    let fractions: Vec<f64> = (0..=steps).map(|i| i as f64 / steps as f64).collect();
    let side = 2 * reach + 1;
    let offsets: Vec<[i64; D]> = (0..side.pow(D as u32))
        .map(|e| {
            let mut rest = e;
            std::array::from_fn(|_| {
                let o = rest % side;
                rest /= side;
                o - reach
            })
        })
        .collect();
    let positions = fractions.len().pow(D as u32);
    (0..positions)
        .map(|q| {
            let mut rest = q;
            let s: [f64; D] = std::array::from_fn(|_| {
                let f = fractions[rest % fractions.len()];
                rest /= fractions.len();
                f + 7.0
            });
            offsets
                .iter()
                .filter(|o| {
                    let d = SVector::<f64, D>::from_fn(|k, _| s[k] - (7 + o[k]) as f64);
                    d.norm_squared() <= radius_squared
                })
                .count()
        })
        .max()
        .unwrap()
}

/// The stencil's entry count is the most nodes a point selects: a lattice of 401^2 points over
/// a cell reaches it and none exceeds it (at gamma 0.8, 58 of the 81 nodes searched in 2D).
#[test]
fn lme_stencil_entries_are_the_most_nodes_within_the_radius() {
    for gamma in [0.3, 0.8, 1.5, 3.0, 6.0, 10.0] {
        let lme1 = LocalMaxEnt::<1>::new(gamma).unwrap();
        let lme2 = LocalMaxEnt::<2>::new(gamma).unwrap();
        let seen1 = most_selected_on_lattice::<1>(lme1.radius(), 4000);
        let seen2 = most_selected_on_lattice::<2>(lme2.radius(), 400);
        assert_eq!(
            (lme1.nodes_per_point(), seen1),
            (seen1, seen1),
            "gamma {gamma}, 1D"
        );
        assert_eq!(
            (lme2.nodes_per_point(), seen2),
            (seen2, seen2),
            "gamma {gamma}, 2D"
        );
    }
}

/// The selected nodes of a 2D block of `side` nodes per axis about the scaled position `s`
/// (block coordinates), as `fill` lists them: row by row, the nodes within `radius`.
fn selected_by_rows(s: [f64; 2], side: usize, radius: f64) -> (Vec<SVector<f64, 2>>, Rows) {
    let mut rows = Rows::new(&SVector::<f64, 2>::from(s), &[0, 0]).unwrap();
    let mut offsets = Vec::new();
    for row in 0..side {
        let across = s[1] - row as f64;
        let within: Vec<usize> = (0..side)
            .filter(|&c| (s[0] - c as f64).powi(2) + across * across <= radius * radius)
            .collect();
        let run = within
            .first()
            .map_or(0..0, |&lo| lo..within.last().unwrap() + 1);
        offsets.extend(
            run.clone()
                .map(|c| SVector::<f64, 2>::new(s[0] - c as f64, across)),
        );
        rows.push(run, row);
    }
    (offsets, rows)
}

/// The weights of `ByRows` at `z`, in the stencil's order.
fn row_weights(by_rows: &ByRows, z: &Exponentials, nodes: usize) -> Vec<f64> {
    let (mut weight, mut grad) = (vec![0.0; nodes], vec![SVector::<f64, 2>::zeros(); nodes]);
    by_rows.write(z, &mut weight, &mut grad, |_, _, _| {});
    weight
}

/// The offsets the rows give, to `Rows::offsets` (Newton's node-by-node fallback) and to
/// `ByRows::write` (the gradients), are those `fill` takes node by node, to the last bit.
#[test]
fn lme_rows_give_the_nodes_offsets() {
    let mut rng = Lcg::new(5);
    for gamma in PAPER_GAMMAS {
        let radius = cut_off_radius(gamma, DEFAULT_TOLERANCE);
        let side = block_side(radius) as usize;
        let mut factors = Factors::default();
        for _ in 0..100 {
            let s = [radius + rng.unit(), radius + rng.unit()];
            let (offsets, rows) = selected_by_rows(s, side, radius);
            let mut from_rows = vec![SVector::<f64, 2>::zeros(); offsets.len()];
            rows.offsets(&mut from_rows);
            assert_eq!(from_rows, offsets);
            let mut by_rows = ByRows::new(&rows, &mut factors, (-2.0 * gamma).exp());
            let Ok(a) = by_rows.moments_at(gamma, &SVector::<f64, 2>::zeros()) else {
                panic!("gamma {gamma}: refused at mu = 0");
            };
            let (mut weight, mut written) = (vec![0.0; offsets.len()], from_rows);
            by_rows.write(&a.z, &mut weight, &mut written, |g, d, _| *g = d);
            assert_eq!(written, offsets);
        }
    }
}

/// Z, r, J and the weights taken by rows are those taken node by node to round-off. Where
/// the largest column and row do not meet at a selected node (a large mu) the rows are
/// refused, and node by node they are not.
#[test]
fn lme_moments_by_rows_match_node_by_node() {
    let mut rng = Lcg::new(11);
    for gamma in [0.3, 0.8, 3.0] {
        let radius = cut_off_radius(gamma, DEFAULT_TOLERANCE);
        let side = block_side(radius) as usize;
        let mut factors = Factors::default();
        let mut refused = 0;
        for trial in 0..200 {
            let s = [radius + rng.unit(), radius + rng.unit()];
            let (offsets, rows) = selected_by_rows(s, side, radius);
            let scale = if trial % 2 == 0 { 1.0 } else { 20.0 * gamma };
            let mu = SVector::<f64, 2>::new(
                scale * (2.0 * rng.unit() - 1.0),
                scale * (2.0 * rng.unit() - 1.0),
            );
            let mut by_node = vec![0.0; offsets.len()];
            let b = ByNode {
                offsets: &offsets,
                weight: &mut by_node,
            }
            .moments_at(gamma, &mu)
            .unwrap();
            let mut by_rows = ByRows::new(&rows, &mut factors, (-2.0 * gamma).exp());
            let Ok(a) = by_rows.moments_at(gamma, &mu) else {
                // Only a large mu pulls the largest column and row apart.
                assert!(scale > 1.0, "gamma {gamma}, mu {mu:?}: refused");
                refused += 1;
                continue;
            };
            assert!((a.log_z() - b.log_z()).abs() < 1e-13 * (1.0 + b.log_z().abs()));
            // r and J are sums of offsets up to the radius, weighted by p_a.
            assert!(
                (a.r - b.r).norm() < 1e-14 * radius,
                "gamma {gamma}, mu {mu:?}"
            );
            assert!(
                (a.j - b.j).norm() < 1e-14 * radius * radius,
                "gamma {gamma}"
            );
            let weights = row_weights(&by_rows, &a.z, offsets.len());
            for (x, y) in weights.iter().zip(&by_node) {
                assert!((x - y).abs() < 1e-14, "gamma {gamma}, mu {mu:?}");
            }
        }
        assert!(refused < 100, "gamma {gamma}: every large mu refused");
        // mu pulls the mass to the first column and the last row, which do not meet: the
        // last row's run is short, and the first column is reached by the wider rows alone.
        let s = [radius, radius];
        let (offsets, rows) = selected_by_rows(s, side, radius);
        let mu = SVector::<f64, 2>::new(4000.0 / radius, -4000.0 / radius);
        let mut by_rows = ByRows::new(&rows, &mut factors, (-2.0 * gamma).exp());
        assert!(Evaluation::<2>::exponentials(&mut by_rows, gamma, &mu).is_err());
        let mut by_node = vec![0.0; offsets.len()];
        let b = ByNode {
            offsets: &offsets,
            weight: &mut by_node,
        }
        .exponentials(gamma, &mu)
        .unwrap();
        assert!(b.z >= 1.0);
    }
}

/// A Newton step of |step . d_a| <= SMALL_STEP updates the weights, Z and the moments as
/// evaluating them afresh at mu + step does, to round-off, node by node and by rows.
#[test]
fn lme_small_step_matches_a_fresh_evaluation() {
    let mut rng = Lcg::new(5);
    let mut factors = Factors::default();
    for gamma in [0.8, 3.0] {
        let radius = cut_off_radius(gamma, DEFAULT_TOLERANCE);
        let side = block_side(radius) as usize;
        for _ in 0..100 {
            let s = [radius + rng.unit(), radius + rng.unit()];
            let (offsets, rows) = selected_by_rows(s, side, radius);
            let mu = SVector::<f64, 2>::new(rng.unit() - 0.5, rng.unit() - 0.5);
            let angle = std::f64::consts::TAU * rng.unit();
            let step = SVector::<f64, 2>::new(angle.cos(), angle.sin()) * (SMALL_STEP / radius);
            let mut fresh = vec![0.0; offsets.len()];
            let mut by_node = ByNode {
                offsets: &offsets,
                weight: &mut fresh,
            };
            let direct = by_node.moments_at(gamma, &(mu + step)).unwrap();
            let mut updated = vec![0.0; offsets.len()];
            let mut by_node = ByNode {
                offsets: &offsets,
                weight: &mut updated,
            };
            let at = by_node.moments_at(gamma, &mu).unwrap();
            let z = by_node.small_step(&step, &at.z);
            let small = by_node.moments(z);
            let mut by_rows = ByRows::new(&rows, &mut factors, (-2.0 * gamma).exp());
            let Ok(at) = by_rows.moments_at(gamma, &mu) else {
                panic!("gamma {gamma}: the largest column and row apart");
            };
            let z = Evaluation::<2>::small_step(&mut by_rows, &step, &at.z);
            let small_by_rows: Moments<2> = by_rows.moments(z);
            let row_updated = row_weights(&by_rows, &small_by_rows.z, offsets.len());
            for (small, updated) in [(small, updated), (small_by_rows, row_updated)] {
                for (a, b) in updated.iter().zip(&fresh) {
                    // A fresh evaluation rounds exponents up to gamma r^2 = 13.8: its own
                    // weights carry some 10 ulps. Leaving x^2 / 2 out would miss by up to
                    // 5e-13.
                    assert!(
                        (a - b).abs() <= 64.0 * f64::EPSILON * b,
                        "gamma {gamma}: {a} vs {b}"
                    );
                }
                let log_z = direct.log_z();
                assert!((small.log_z() - log_z).abs() < 1e-14 * (1.0 + log_z.abs()));
                assert!((small.r - direct.r).norm() < 1e-14 * radius);
                assert!((small.j - direct.j).norm() < 1e-14 * radius * radius);
            }
        }
    }
}

/// The closed-form inverse of Newton's Hessian is the Cholesky inverse to round-off on
/// covariances of any conditioning, and refuses the ones that are not positive definite.
#[test]
fn lme_closed_form_inverse_matches_cholesky() {
    let mut rng = Lcg::new(11);
    for _ in 0..2000 {
        // Eigenvalues 1 and 10^-8 to 10^2 along a random direction.
        let (s, c) = (std::f64::consts::PI * rng.unit()).sin_cos();
        let (l0, l1) = (1.0, 10f64.powf(10.0 * rng.unit() - 8.0));
        let j = SMatrix::<f64, 2, 2>::new(
            l0 * c * c + l1 * s * s,
            (l0 - l1) * c * s,
            (l0 - l1) * c * s,
            l0 * s * s + l1 * c * c,
        );
        let expected = j.cholesky().unwrap().inverse();
        let inverse = spd_inverse(&j).unwrap();
        let condition = l0.max(l1) / l0.min(l1);
        let tolerance = 8.0 * f64::EPSILON * condition * expected.norm();
        assert!(
            (inverse - expected).norm() <= tolerance,
            "{j} {inverse} {expected}"
        );
        let one = SMatrix::<f64, 1, 1>::new(j[(0, 0)]);
        assert_eq!(spd_inverse(&one).unwrap()[0], 1.0 / j[(0, 0)]);
    }
    for j in [
        SMatrix::<f64, 2, 2>::new(1.0, 1.0, 1.0, 1.0),
        SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 1.0),
        SMatrix::<f64, 2, 2>::new(-1.0, 0.0, 0.0, -1.0),
        SMatrix::<f64, 2, 2>::new(f64::NAN, 0.0, 0.0, 1.0),
    ] {
        assert!(spd_inverse(&j).is_none(), "{j}");
        assert!(j.cholesky().is_none() || j[(0, 0)].is_nan(), "{j}");
    }
    assert!(spd_inverse(&SMatrix::<f64, 1, 1>::new(0.0)).is_none());
}
