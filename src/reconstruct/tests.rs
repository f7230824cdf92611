//! Reproduction, agreement and rank-loss tests of the least-squares reconstructions.

use nalgebra::SVector;

use super::least_squares::Components;
use super::*;
use crate::grid::{Domain, Grid};
use crate::rng::Lcg;

fn grid<const D: usize>(cells: usize) -> Grid<D> {
    Grid::new(&Domain {
        lower: SVector::repeat(-1.0),
        upper: SVector::repeat(1.0),
        cells,
    })
}

fn recipe(weight: Weight, scale: f64, degree: Degree, solver: Solver) -> Recipe {
    Recipe {
        kernel: Kernel { weight, scale },
        degree,
        solver,
    }
}

/// `n` uniformly random points in [-1, 1]^D.
fn random_points<const D: usize>(n: usize, seed: u64) -> Vec<SVector<f64, D>> {
    let mut rng = Lcg::new(seed);
    (0..n)
        .map(|_| SVector::from_fn(|_, _| -1.0 + 2.0 * rng.unit()))
        .collect()
}

/// Reconstructs `f` sampled at `x` on the lattice; returns (point, exact, reconstructed)
/// for the covered points.
fn reconstruct<const D: usize>(
    rec: &mut Reconstructor<D>,
    x: &[SVector<f64, D>],
    f: impl Fn(&SVector<f64, D>) -> f64,
) -> Vec<(SVector<f64, D>, f64, f64)> {
    rec.fit(x).expect("fit");
    let values: Vec<f64> = x.iter().map(&f).collect();
    let mut out = vec![0.0; rec.lattice().len()];
    rec.apply(&values, &mut out);
    (0..out.len())
        .filter(|&e| rec.covered(e))
        .map(|e| {
            let xe = rec.lattice().point(e);
            (xe, f(&xe), out[e])
        })
        .collect()
}

fn check_reproduction<const D: usize>(degree: Degree, solver: Solver, weight: Weight) {
    let g = grid::<D>(8);
    let x = random_points::<D>(400 * D * D, 7 + D as u64);
    let mut rec = Reconstructor::new(recipe(weight, 1.0, degree, solver), Lattice::nodes(&g));
    let linear = |p: &SVector<f64, D>| 0.7 - 1.3 * p[0] + 2.1 * p[D - 1];
    let quadratic = |p: &SVector<f64, D>| linear(p) + 0.9 * p[0] * p[D - 1] - 1.7 * p[0] * p[0];
    type Field<'a, const D: usize> = &'a dyn Fn(&SVector<f64, D>) -> f64;
    let cases: Vec<Field<D>> = if degree == Degree::QUADRATIC {
        vec![&linear, &quadratic]
    } else {
        vec![&linear]
    };
    for f in cases {
        let rows = reconstruct(&mut rec, &x, f);
        assert_eq!(rows.len(), g.num_nodes(), "every node is reached");
        for (xe, exact, got) in rows {
            assert!(
                (exact - got).abs() < 1e-12,
                "D={D} {degree:?} {solver:?} {weight}: at {xe:?} exact {exact} got {got}"
            );
        }
    }
}

#[test]
fn mls_and_imls_reproduce_their_basis_on_random_points() {
    for solver in [Solver::Mls, Solver::Imls] {
        for weight in [Weight::Hat, Weight::QuadraticSpline, Weight::CubicSpline] {
            check_reproduction::<1>(Degree::LINEAR, solver, weight);
            check_reproduction::<2>(Degree::LINEAR, solver, weight);
            check_reproduction::<1>(Degree::QUADRATIC, solver, weight);
            check_reproduction::<2>(Degree::QUADRATIC, solver, weight);
        }
    }
}

/// Shepard (degree 0) reproduces constants only: a linear function on random points is
/// off by O(h).
#[test]
fn shepard_reproduces_constants_not_linears() {
    let g = grid::<1>(10);
    let x = random_points::<1>(40, 3);
    let mut rec = Reconstructor::new(
        recipe(Weight::Hat, 1.0, Degree::CONSTANT, Solver::Mls),
        Lattice::nodes(&g),
    );
    for (_, exact, got) in reconstruct(&mut rec, &x, |_| 2.5) {
        assert!((exact - got).abs() < 1e-14);
    }
    let worst = reconstruct(&mut rec, &x, |p| p[0])
        .iter()
        .map(|r| (r.1 - r.2).abs())
        .fold(0.0, f64::max);
    assert!(worst > 1e-3, "largest error {worst}");
}

/// Where the moment matrix is well conditioned, IMLS and MLS are the same reconstruction.
fn check_imls_equals_mls<const D: usize>(degree: Degree) {
    let g = grid::<D>(6);
    let x = random_points::<D>(300 * D * D, 11);
    let f = |p: &SVector<f64, D>| (3.0 * p[0]).sin() + (2.0 * p[D - 1]).cos();
    let weight = Weight::QuadraticSpline;
    let mut mls = Reconstructor::new(
        recipe(weight, 1.0, degree, Solver::Mls),
        Lattice::gauss(&g, 2),
    );
    let mut imls = Reconstructor::new(
        recipe(weight, 1.0, degree, Solver::Imls),
        Lattice::gauss(&g, 2),
    );
    let a = reconstruct(&mut mls, &x, f);
    let b = reconstruct(&mut imls, &x, f);
    assert_eq!(a.len(), b.len());
    for (ra, rb) in a.iter().zip(&b) {
        assert!((ra.2 - rb.2).abs() < 1e-11, "MLS {} vs IMLS {}", ra.2, rb.2);
    }
}

#[test]
fn imls_equals_mls_when_well_conditioned() {
    check_imls_equals_mls::<1>(Degree::LINEAR);
    check_imls_equals_mls::<1>(Degree::QUADRATIC);
    check_imls_equals_mls::<2>(Degree::LINEAR);
    check_imls_equals_mls::<2>(Degree::QUADRATIC);
}

/// Moments of `points` about the origin with a hat weight wide enough to reach all of them
/// (rank does not depend on the positive weights).
fn moments<const D: usize>(points: &[SVector<f64, D>], degree: Degree) -> (Moments, usize) {
    let wide = Kernel {
        weight: Weight::Hat,
        scale: 10.0,
    };
    moment_matrix(&wide, degree, points)
}

/// Tran eq 17: with r independent data the basis keeps r polynomials. 1, 2 and 3 points
/// with the quadratic basis in 1D; with the linear basis in 2D, collinear points lose one.
#[test]
fn imls_degrades_to_the_rank_of_the_data() {
    let pts =
        |xs: &[f64]| -> Vec<SVector<f64, 1>> { xs.iter().map(|&x| SVector::from([x])).collect() };
    for (xs, rank) in [
        (vec![0.3], 1),
        (vec![-0.5, 0.5], 2),
        (vec![-0.5, 0.1, 0.5], 3),
        (vec![0.2, 0.2, 0.2], 1),
    ] {
        let (a, terms) = moments(&pts(&xs), Degree::QUADRATIC);
        let basis = OrthogonalBasis::from_moments(&a, terms);
        assert_eq!(basis.rank(), rank, "points {xs:?}");
    }
    let (a, terms) = moments(&pts(&[-0.5, 0.5]), Degree::LINEAR);
    assert_eq!(OrthogonalBasis::from_moments(&a, terms).rank(), 2);

    let p2 = |v: &[(f64, f64)]| -> Vec<SVector<f64, 2>> {
        v.iter().map(|&(x, y)| SVector::from([x, y])).collect()
    };
    for (v, rank) in [
        (vec![(0.1, 0.2)], 1),
        (vec![(0.0, 0.0), (0.3, 0.6), (-0.2, -0.4)], 2),
        (vec![(0.0, 0.0), (0.3, 0.6), (-0.2, 0.4)], 3),
    ] {
        let (a, terms) = moments(&p2(&v), Degree::LINEAR);
        assert_eq!(
            OrthogonalBasis::from_moments(&a, terms).rank(),
            rank,
            "{v:?}"
        );
        // MLS has no such fallback: the same data make its moment matrix singular.
        assert_eq!(
            super::solve::mls_coefficients::<MAX_TERMS>(&a, MAX_TERMS, terms).is_some(),
            rank == terms
        );
    }
}

/// Tran Fig 3: for two points p3 vanishes at both, so <p3, p3> = 0, and the fit through
/// the two kept polynomials still reproduces the linear data exactly.
#[test]
fn two_points_make_the_quadratic_polynomial_vanish() {
    let xs = [-0.6, 0.4];
    let kernel = Kernel {
        weight: Weight::QuadraticSpline,
        scale: 2.0,
    };
    let w = |x: f64| kernel.eval(&SVector::<f64, 1>::from([x]));
    let offsets: Vec<SVector<f64, 1>> = xs.iter().map(|&x| SVector::from([x])).collect();
    let (a, terms) = moment_matrix(&kernel, Degree::QUADRATIC, &offsets);
    assert_eq!(terms, 3);
    let mut q = [0.0; MAX_TERMS];
    let basis = OrthogonalBasis::from_moments(&a, 3);
    assert!(!basis.kept[2]);
    assert!(basis.norms[2].abs() < 1e-15 * a[2 * MAX_TERMS + 2]);
    for &x in &xs {
        monomials(Degree::QUADRATIC, &SVector::<f64, 1>::from([x]), &mut q);
        assert!(
            basis.eval(2, &q).abs() < 1e-14,
            "p3({x}) = {}",
            basis.eval(2, &q)
        );
    }
    // u = 2 - 3x at the points; the degraded fit evaluated at 0 gives u(0) = 2.
    let c = basis.shape_coefficients::<3>();
    let u0: f64 = xs
        .iter()
        .map(|&x| {
            monomials(Degree::QUADRATIC, &SVector::<f64, 1>::from([x]), &mut q);
            w(x) * (0..3).map(|j| q[j] * c[j]).sum::<f64>() * (2.0 - 3.0 * x)
        })
        .sum();
    assert!((u0 - 2.0).abs() < 1e-14);
}

/// The widest support the node lattice accepts is accepted: benchmarks check against it.
#[test]
fn the_widest_node_support_fits() {
    let kernel = Kernel {
        weight: Weight::Hat,
        scale: MAX_NODE_SUPPORT_CELLS,
    };
    let mut rec = Reconstructor::new(
        Recipe {
            kernel,
            degree: Degree::CONSTANT,
            solver: Solver::Mls,
        },
        Lattice::nodes(&grid::<1>(4)),
    );
    assert_eq!(rec.fit(&[SVector::from([0.3])]).unwrap().fits, 5);
}

/// A reconstruction with too few points counts its rank losses (IMLS) or stops (MLS).
#[test]
fn sparse_data_is_counted_or_refused() {
    let g = grid::<1>(4);
    let x = vec![SVector::<f64, 1>::from([0.05])];
    let mut imls = Reconstructor::new(
        recipe(Weight::CubicSpline, 1.0, Degree::LINEAR, Solver::Imls),
        Lattice::nodes(&g),
    );
    let stats = imls.fit(&x).unwrap();
    assert_eq!(stats.fits, 4, "nodes within 2h of the point");
    assert_eq!(stats.rank_deficient, 4);
    let mut mls = Reconstructor::new(
        recipe(Weight::CubicSpline, 1.0, Degree::LINEAR, Solver::Mls),
        Lattice::nodes(&g),
    );
    assert!(mls.fit(&x).is_err());
}

/// Gong Table 4.1: 10 cells on [-1, 1] (h = 0.2), 4 cell-centred points per cell, Shepard
/// with the hat weight. Printed to 4 decimals; the boundary values of u = x are exactly
/// -/+ 11h/32 = 0.06875, half-way between the printed 0.0688 and 0.0687.
#[test]
fn shepard_reproduces_gong_table_4_1() {
    let g = grid::<1>(10);
    let x: Vec<SVector<f64, 1>> = (0..40)
        .map(|p| SVector::from([-1.0 + (p as f64 + 0.5) * 0.05]))
        .collect();
    let mut rec = Reconstructor::new(
        recipe(Weight::Hat, 1.0, Degree::CONSTANT, Solver::Mls),
        Lattice::nodes(&g),
    );
    let printed_x = [-0.0688, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0687];
    let printed_x2 = [
        0.1306, -0.0069, -0.0069, -0.0069, -0.0069, -0.0069, -0.0069, -0.0069, -0.0069, -0.0069,
        0.1306,
    ];
    let ones = reconstruct(&mut rec, &x, |_| 1.0);
    let lin = reconstruct(&mut rec, &x, |p| p[0]);
    let quad = reconstruct(&mut rec, &x, |p| p[0] * p[0]);
    for i in 0..11 {
        assert!((ones[i].1 - ones[i].2).abs() < 1e-15);
        assert!(
            (lin[i].1 - lin[i].2 - printed_x[i]).abs() <= 1e-4 + 1e-12,
            "x at node {i}"
        );
        assert!(
            (quad[i].1 - quad[i].2 - printed_x2[i]).abs() <= 0.5e-4 + 1e-12,
            "x^2 at node {i}"
        );
    }
    assert!((lin[0].1 - lin[0].2 + 11.0 * 0.2 / 32.0).abs() < 1e-14);
    assert!((quad[5].1 - quad[5].2 + 11.0 * 0.04 / 64.0).abs() < 1e-14);
}

/// The one-pass velocity fit (c_e . sum_p w q u_p) is `fit` then `apply` with its sums
/// regrouped: the same counters and zero at the points no particle reaches on data covering
/// part of the grid (where IMLS also loses rank at the data's edge), and the same values to
/// round-off on data covering all of it. (At the edge of partial data the moment matrices are
/// ill-conditioned, and the two orders differ by round-off times their condition number.)
fn check_one_pass_velocity_fit<const D: usize>() {
    let g = grid::<D>(8);
    let everywhere = random_points::<D>(400 * D * D, 11 + D as u64);
    let part: Vec<SVector<f64, D>> = everywhere
        .iter()
        .map(|p| p.map(|c| 0.6 * c - 0.2))
        .collect();
    let velocity = |x: &[SVector<f64, D>]| -> Vec<SVector<f64, D>> {
        x.iter()
            .map(|p| SVector::from_fn(|k, _| 0.5 + (k + 1) as f64 * p[0] - 2.0 * p[D - 1]))
            .collect()
    };
    for solver in [Solver::Mls, Solver::Imls] {
        for weight in [Weight::Hat, Weight::QuadraticSpline, Weight::CubicSpline] {
            for degree in [Degree::CONSTANT, Degree::LINEAR, Degree::QUADRATIC] {
                let r = recipe(weight, 1.0, degree, solver);
                for (x, covers_all) in [(&everywhere, true), (&part, false)] {
                    let v = velocity(x);
                    let mut two_pass = Reconstructor::new(r, Lattice::nodes(&g));
                    let mut one_pass = Reconstructor::new(r, Lattice::nodes(&g));
                    let n = g.num_nodes();
                    let mut expected = vec![SVector::<f64, D>::zeros(); n];
                    let mut got = expected.clone();
                    let stats = two_pass.fit(x);
                    assert_eq!(one_pass.fit_apply(x, &v, &mut got), stats, "{r}");
                    if stats.is_err() {
                        assert!(!covers_all, "{r} fits data covering the grid");
                        continue;
                    }
                    two_pass.apply(&v, &mut expected);
                    let covered = (0..n).filter(|&e| one_pass.covered(e)).count();
                    assert_eq!(covered == n, covers_all, "{r}");
                    for e in 0..n {
                        if !one_pass.covered(e) {
                            assert_eq!(got[e], SVector::<f64, D>::zeros(), "{r} at node {e}");
                        } else if covers_all {
                            let scale = expected[e].norm().max(1.0);
                            assert!(
                                (got[e] - expected[e]).norm() < 1e-13 * scale,
                                "{r} at node {e}: {} against {}",
                                got[e],
                                expected[e]
                            );
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn one_pass_velocity_fit_equals_fit_then_apply() {
    check_one_pass_velocity_fit::<1>();
    check_one_pass_velocity_fit::<2>();
}

#[test]
#[should_panic(expected = "more values than particles in the last `fit`")]
fn a_one_pass_fit_keeps_no_entries_to_apply() {
    let g = grid::<2>(4);
    let x = random_points::<2>(200, 3);
    let v = vec![SVector::<f64, 2>::zeros(); x.len()];
    let r = recipe(Weight::CubicSpline, 1.0, Degree::LINEAR, Solver::Mls);
    let mut rec = Reconstructor::new(r, Lattice::nodes(&g));
    let mut out = vec![SVector::zeros(); g.num_nodes()];
    rec.fit(&x).unwrap();
    rec.fit_apply(&x, &v, &mut out).unwrap();
    rec.apply(&v, &mut out);
}

/// The bits of every component of `u`, for comparisons to the last bit.
fn bits<const D: usize>(u: &[SVector<f64, D>]) -> Vec<u64> {
    u.iter()
        .flat_map(|u| u.iter().map(|c| c.to_bits()))
        .collect()
}

/// Particles two per cell and axis, jiggled, on a lattice of two Gauss points per cell: every
/// row of a particle's entries begins on one parity, so after the first fit the pairing of the
/// points turns to make rows begin pairs (`Pairing`); and neighbours across a cell face reach
/// the same points, so the pairing of the particles turns to take those two at a time
/// (`ParticlePairing`). The next fit at the same positions then keeps its sums elsewhere and
/// adds its particles in other groups, and must give the same values to the bit, by `fit`
/// then `apply` and by `fit_apply`.
fn check_pairing_changes_no_value<const D: usize>() {
    let g = grid::<D>(6);
    let mut rng = Lcg::new(5 + D as u64);
    let per_axis = 2 * g.cells;
    let x: Vec<SVector<f64, D>> = (0..per_axis.pow(D as u32))
        .map(|p| {
            SVector::from_fn(|k, _| {
                let i = (p / per_axis.pow(k as u32)) % per_axis;
                g.lower[k] + g.h * (0.25 + 0.5 * i as f64 + 0.04 * (rng.unit() - 0.5))
            })
        })
        .collect();
    let v: Vec<SVector<f64, D>> = x
        .iter()
        .map(|p| SVector::from_fn(|k, _| (k as f64 + 1.0) * p[0] - p[D - 1] * p[D - 1]))
        .collect();
    let r = recipe(Weight::QuadraticSpline, 1.0, Degree::LINEAR, Solver::Imls);
    let mut fit = Reconstructor::new(r, Lattice::gauss(&g, 2));
    let mut one_pass = Reconstructor::new(r, Lattice::gauss(&g, 2));
    let n = fit.lattice().len();
    let mut runs = Vec::new();
    for _ in 0..2 {
        // Of the points, then of the particles.
        let phase = [
            fit.pairing_phase(),
            one_pass.pairing_phase(),
            fit.particle_pairing_phase(),
            one_pass.particle_pairing_phase(),
        ];
        let mut applied = vec![SVector::<f64, D>::zeros(); n];
        let mut fitted = applied.clone();
        let stats = fit.fit(&x).unwrap();
        fit.apply(&v, &mut applied);
        assert_eq!(one_pass.fit_apply(&x, &v, &mut fitted).unwrap(), stats);
        runs.push((phase, applied, fitted));
    }
    let [(before, applied_0, fitted_0), (after, applied_1, fitted_1)] = &runs[..] else {
        unreachable!("two fits")
    };
    assert_eq!(
        (*before, *after),
        ([0; 4], [1; 4]),
        "{D}D: the pairings turned"
    );
    assert_eq!(bits(applied_0), bits(applied_1), "{D}D: fit then apply");
    assert_eq!(bits(fitted_0), bits(fitted_1), "{D}D: one pass");
}

#[test]
fn the_pairing_of_the_sums_changes_no_value() {
    check_pairing_changes_no_value::<1>();
    check_pairing_changes_no_value::<2>();
}

/// A reused reconstructor gives a fresh one's values to the bit: the sums of every fit and
/// application start from zero, though each use zeroes its sums as it reads them instead of
/// clearing them before it sums (`ZeroSums`). Before its uses here, a fit and a one-pass fit
/// were stopped by a singular moment matrix (one particle) with sums left unread. Lattices of
/// an odd and an even count of points, so that a pair's second lane lies past the last point
/// under one phase or the other.
fn check_reuse_starts_from_zero<const D: usize>() {
    for cells in [4, 5] {
        let g = grid::<D>(cells);
        let x = random_points::<D>(120 * D * D, 31 + cells as u64);
        let v: Vec<SVector<f64, D>> = x
            .iter()
            .map(|p| SVector::from_fn(|k, _| p[k] - 0.5 * p[0] * p[D - 1]))
            .collect();
        let r = recipe(Weight::QuadraticSpline, 1.0, Degree::LINEAR, Solver::Mls);
        let n = Lattice::nodes(&g).len();
        let uses = |fit: &mut Reconstructor<D>| {
            let mut applied = vec![SVector::<f64, D>::zeros(); n];
            let mut fitted = applied.clone();
            fit.fit(&x).unwrap();
            fit.apply(&v, &mut applied);
            fit.fit_apply(&x, &v, &mut fitted).unwrap();
            (bits(&applied), bits(&fitted))
        };
        let fresh = uses(&mut Reconstructor::new(r, Lattice::nodes(&g)));
        let mut reused = Reconstructor::new(r, Lattice::nodes(&g));
        let alone = [SVector::<f64, D>::repeat(0.1)];
        let mut out = vec![SVector::<f64, D>::zeros(); n];
        assert!(
            reused.fit(&alone).is_err(),
            "{D}D: one particle is singular"
        );
        assert!(reused.fit_apply(&alone, &v[..1], &mut out).is_err());
        for round in 0..2 {
            assert!(
                uses(&mut reused) == fresh,
                "{D}D, {cells} cells, round {round}"
            );
        }
    }
}

#[test]
fn reused_sums_start_from_zero() {
    check_reuse_starts_from_zero::<1>();
    check_reuse_starts_from_zero::<2>();
}

/// An application to values of several components (`Components`) sums each component as an
/// application to that component alone does, to the bit, on either pairing of the points.
fn check_components_apply_apart<const D: usize>() {
    let g = grid::<D>(5);
    let x = random_points::<D>(150 * D * D, 17 + D as u64);
    let v: Vec<SVector<f64, D>> = x
        .iter()
        .map(|p| SVector::from_fn(|k, _| (2.0 - k as f64) * p[0] + p[D - 1] * p[D - 1]))
        .collect();
    for lattice in [Lattice::nodes(&g), Lattice::gauss(&g, 2)] {
        let r = recipe(Weight::QuadraticSpline, 1.0, Degree::LINEAR, Solver::Mls);
        let mut fit = Reconstructor::new(r, lattice);
        let n = fit.lattice().len();
        for _ in 0..2 {
            fit.fit(&x).unwrap();
            let mut together = vec![SVector::<f64, D>::zeros(); n];
            fit.apply(&v, &mut together);
            for k in 0..D {
                let component: Vec<f64> = v.iter().map(|v| v[k]).collect();
                let mut apart = vec![0.0; n];
                fit.apply(&component, &mut apart);
                for (e, (u, a)) in together.iter().zip(&apart).enumerate() {
                    assert_eq!(u[k].to_bits(), a.to_bits(), "{D}D point {e} component {k}");
                }
            }
        }
    }
}

#[test]
fn an_application_sums_each_component_apart() {
    check_components_apply_apart::<1>();
    check_components_apply_apart::<2>();
}

/// Seven components, the last of which may copy the third (as the quadrature fields' stress
/// above its diagonal copies the one below).
#[derive(Clone, Copy)]
struct Seven([f64; 7]);

impl Components for Seven {
    const COUNT: usize = 7;
    const LAST_MAY_COPY: Option<usize> = Some(2);

    fn component(&self, c: usize) -> f64 {
        self.0[c]
    }

    fn from_components(component: impl Fn(usize) -> f64) -> Self {
        Seven(std::array::from_fn(component))
    }
}

/// Values whose last component copies another are summed once for both, to the bit: every
/// component of the application is the application to that component alone, whether or not
/// the values copy (`apply_with`'s two paths).
#[test]
fn a_copied_component_is_summed_as_its_own() {
    let g = grid::<2>(5);
    let x = random_points::<2>(600, 29);
    let r = recipe(Weight::QuadraticSpline, 1.0, Degree::LINEAR, Solver::Imls);
    let mut fit = Reconstructor::new(r, Lattice::gauss(&g, 2));
    fit.fit(&x).unwrap();
    let n = fit.lattice().len();
    for copies in [true, false] {
        let values: Vec<Seven> = x
            .iter()
            .map(|p| {
                let mut v: [f64; 7] =
                    std::array::from_fn(|c| (c as f64 + 1.0) * p[c % 2] - p[0] * p[1]);
                v[6] = if copies { v[2] } else { v[2] + 0.5 };
                Seven(v)
            })
            .collect();
        let mut together = vec![Seven([0.0; 7]); n];
        fit.apply(&values, &mut together);
        for c in 0..7 {
            let component: Vec<f64> = values.iter().map(|v| v.0[c]).collect();
            let mut apart = vec![0.0; n];
            fit.apply(&component, &mut apart);
            for (e, (u, a)) in together.iter().zip(&apart).enumerate() {
                assert_eq!(
                    u.0[c].to_bits(),
                    a.to_bits(),
                    "copies {copies}, point {e}, component {c}"
                );
            }
        }
    }
}
