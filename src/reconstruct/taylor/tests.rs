//! The Taylor basis against eq 2, conservation with a prescribed a_1 (eq 5), reproduction of
//! quadratics, an independent least-squares solve, and the documented loss of degree.

use nalgebra::{DMatrix, DVector, SVector};

use super::*;
use crate::gauss::gauss_legendre_rule;
use crate::rng::Lcg;

/// The integral of `f` over the cell by the `n`-point Gauss rule per axis.
fn integrate<const D: usize>(
    cell: &TaylorCell<D>,
    n: usize,
    f: impl Fn(&SVector<f64, D>) -> f64,
) -> f64 {
    let (nodes, weights) = gauss_legendre_rule(n);
    let mut sum = 0.0;
    for index in 0..n.pow(D as u32) {
        let mut x = SVector::<f64, D>::zeros();
        let mut w = 1.0;
        let mut rest = index;
        for k in 0..D {
            let g = rest % n;
            rest /= n;
            x[k] = cell.centre()[k] + nodes[g] * cell.half_widths()[k];
            w *= weights[g] * cell.half_widths()[k];
        }
        sum += w * f(&x);
    }
    sum
}

/// sum_i a_i psi_i(x).
fn evaluate<const D: usize>(
    cell: &TaylorCell<D>,
    degree: usize,
    a: &[f64; MAX_TAYLOR_TERMS],
    x: &SVector<f64, D>,
) -> f64 {
    let psi = cell.basis(degree, x);
    (0..MAX_TAYLOR_TERMS).map(|i| a[i] * psi[i]).sum()
}

/// `n` uniformly random points in the cell.
fn random_points<const D: usize>(
    cell: &TaylorCell<D>,
    n: usize,
    seed: u64,
) -> Vec<SVector<f64, D>> {
    let mut rng = Lcg::new(seed);
    (0..n)
        .map(|_| {
            SVector::from_fn(|k, _| {
                cell.lower()[k] + (cell.upper()[k] - cell.lower()[k]) * rng.unit()
            })
        })
        .collect()
}

fn cell_1d() -> TaylorCell<1> {
    TaylorCell::new([0.3].into(), [2.1].into())
}

/// Anisotropic and away from the origin, so that a missing scale or centre shows.
fn cell_2d() -> TaylorCell<2> {
    TaylorCell::new([-1.5, 2.0].into(), [0.5, 2.25].into())
}

fn quadratic_1d(x: &SVector<f64, 1>) -> f64 {
    1.3 - 0.7 * x[0] + 2.2 * x[0] * x[0]
}

fn quadratic_2d(x: &SVector<f64, 2>) -> f64 {
    0.4 + 1.1 * x[0] - 2.0 * x[1] + 0.8 * x[0] * x[0] - 1.7 * x[0] * x[1] + 3.1 * x[1] * x[1]
}

/// Eq 2: the integral of psi_1 is |Omega_e| and of every other psi_i zero. Two Gauss points
/// per axis integrate the (at most quadratic) basis exactly.
#[test]
fn basis_integrals_are_the_volume_and_zero() {
    fn check<const D: usize>(cell: &TaylorCell<D>) {
        let volume = cell.volume();
        for i in 0..taylor_terms(D, 2) {
            let integral = integrate(cell, 2, |x| cell.basis(2, x)[i]);
            let expected = if i == 0 { volume } else { 0.0 };
            assert!(
                (integral - expected).abs() <= 1e-15 * volume,
                "D = {D}, psi_{}: {integral} against {expected}",
                i + 1
            );
        }
    }
    check(&cell_1d());
    check(&cell_2d());
    assert!((cell_2d().volume() - 0.5).abs() < 1e-15);
    // The functions are the printed ones: at the lower corner s = t = -1.
    let psi = cell_2d().basis(2, &[-1.5, 2.0].into());
    let expected = [1.0, -1.0, -1.0, 1.0 / 3.0, 1.0 / 3.0, 1.0];
    for i in 0..6 {
        assert!((psi[i] - expected[i]).abs() < 1e-15, "{psi:?}");
    }
    assert_eq!(cell_2d().basis(1, &[0.0, 2.1].into())[3..], [0.0; 3]);
    assert_eq!(
        (
            taylor_terms(1, 0),
            taylor_terms(1, 2),
            taylor_terms(2, 1),
            taylor_terms(2, 2)
        ),
        (1, 3, 3, 6)
    );
}

/// Eq 4-5: with a_1 = c/|Omega_e| the integral of the fit is c whatever the data, to rounding:
/// |int u^h - c| <= 1e-14 |c| by 2 and by 10 Gauss points per axis. A fitted a_1 does not
/// conserve c (the check can fail).
#[test]
fn fixed_conserves_the_element_integral() {
    fn check<const D: usize>(cell: &TaylorCell<D>, f: impl Fn(&SVector<f64, D>) -> f64) {
        let points = random_points(cell, 4 * D + 3, 11 + D as u64);
        let values: Vec<f64> = points.iter().map(&f).collect();
        let c = integrate(cell, 10, &f);
        let mut fit = TaylorFit::<D>::default();
        let degree = fit.factor(cell, 2, Conservation::Fixed, &points);
        assert_eq!(degree, 2);
        let a = fit.solve(&values, c / cell.volume());
        for n in [2, 10] {
            let integral = integrate(cell, n, |x| evaluate(cell, degree, &a, x));
            assert!(
                (integral - c).abs() <= 1e-14 * c.abs(),
                "D = {D}, {n} points: {integral} against {c}"
            );
        }
        fit.factor(cell, 2, Conservation::Fitted, &points);
        let a = fit.solve(&values, c / cell.volume());
        let fitted = integrate(cell, 2, |x| evaluate(cell, 2, &a, x));
        assert!(
            (fitted - c).abs() > 1e-6 * c.abs(),
            "D = {D}: {fitted} against {c}"
        );
    }
    check(&cell_1d(), |x| (2.0 * x[0]).sin() + 2.0);
    check(&cell_2d(), |x| x[0].sin() * (3.0 * x[1]).cos() + 2.0);
}

/// Quadratics are reproduced exactly from as few points as determine them, in both modes
/// (Fixed with the exact mean).
#[test]
fn quadratics_are_reproduced_where_full_rank() {
    fn check<const D: usize>(cell: &TaylorCell<D>, f: fn(&SVector<f64, D>) -> f64) {
        let mean = integrate(cell, 2, f) / cell.volume();
        let probes = random_points(cell, 20, 99);
        for (conservation, n) in [
            (Conservation::Fitted, taylor_terms(D, 2)),
            (Conservation::Fixed, taylor_terms(D, 2) - 1),
            (Conservation::Fixed, taylor_terms(D, 2) + 4),
        ] {
            let points = random_points(cell, n, 5 + n as u64);
            let values: Vec<f64> = points.iter().map(f).collect();
            let mut fit = TaylorFit::<D>::default();
            assert_eq!(fit.factor(cell, 2, conservation, &points), 2);
            assert_eq!(fit.degree(), 2);
            let a = fit.solve(&values, mean);
            for x in &probes {
                let (got, exact) = (evaluate(cell, 2, &a, x), f(x));
                assert!(
                    (got - exact).abs() < 1e-11,
                    "D = {D}, {conservation:?}, {n} points: {got} against {exact} at {x:?}"
                );
            }
        }
    }
    check(&cell_1d(), quadratic_1d);
    check(&cell_2d(), quadratic_2d);
}

/// The coefficients agree with an independent least-squares solve (SVD of the basis values
/// at the data) for smooth non-polynomial data.
#[test]
fn agrees_with_a_direct_least_squares_solve() {
    let cell = cell_2d();
    let points = random_points(&cell, 11, 3);
    let f = |x: &SVector<f64, 2>| (x[0] + x[1]).exp();
    let values: Vec<f64> = points.iter().map(f).collect();
    let mean = 1.7;
    for (conservation, first) in [(Conservation::Fitted, 0), (Conservation::Fixed, 1)] {
        let shift = if first == 1 { mean } else { 0.0 };
        let b = DMatrix::from_fn(points.len(), 6 - first, |p, j| {
            cell.basis(2, &points[p])[first + j]
        });
        let u = DVector::from_iterator(values.len(), values.iter().map(|v| v - shift));
        let direct = b.svd(true, true).solve(&u, 1e-14).unwrap();
        let mut fit = TaylorFit::<2>::default();
        fit.factor(&cell, 2, conservation, &points);
        let a = fit.solve(&values, mean);
        if first == 1 {
            assert_eq!(a[0], mean);
        }
        for j in 0..6 - first {
            assert!(
                (a[first + j] - direct[j]).abs() < 1e-9 * direct.amax(),
                "{conservation:?}: {a:?} against {direct}"
            );
        }
    }
}

/// Wobbes' 2D example (ERRATA): two x-values per cell make psi_4 constant at the data, a
/// multiple of psi_1. Fitted loses rank and drops to the linear fit; Fixed fits psi_2..psi_6,
/// which are independent there, and reproduces quadratics.
#[test]
fn wobbes_points_degrade_fitted_and_not_fixed() {
    let cell = TaylorCell::<2>::new([2.0, 1.0].into(), [3.0, 2.0].into());
    let mut points = Vec::new();
    for x in [2.0 + 1.0 / 3.0, 3.0 - 1.0 / 3.0] {
        for y in [1.25, 1.5, 1.75] {
            points.push(SVector::<f64, 2>::new(x, y));
        }
    }
    for x in &points {
        assert!(
            (cell.basis(2, x)[3] + 1.0 / 9.0).abs() < 1e-15,
            "psi_4 = -1/9 at the data"
        );
    }
    let probes = random_points(&cell, 10, 4);
    let mut fit = TaylorFit::<2>::default();
    assert_eq!(fit.factor(&cell, 2, Conservation::Fitted, &points), 1);
    let linear = |x: &SVector<f64, 2>| 0.5 - 2.0 * x[0] + 0.25 * x[1];
    let values: Vec<f64> = points.iter().map(linear).collect();
    let a = fit.solve(&values, f64::NAN);
    assert_eq!(a[3..], [0.0; 3]);
    for x in &probes {
        assert!((evaluate(&cell, 1, &a, x) - linear(x)).abs() < 1e-13);
    }
    assert_eq!(fit.factor(&cell, 2, Conservation::Fixed, &points), 2);
    let values: Vec<f64> = points.iter().map(quadratic_2d).collect();
    let a = fit.solve(&values, integrate(&cell, 2, quadratic_2d) / cell.volume());
    for x in &probes {
        assert!((evaluate(&cell, 2, &a, x) - quadratic_2d(x)).abs() < 1e-12);
    }
}

/// Too few or dependent points lower the degree a whole step at a time.
#[test]
fn dependent_points_drop_whole_degrees() {
    let cell = cell_1d();
    let mut fit = TaylorFit::<1>::default();
    // Two distinct values: a line; the coincident pair adds nothing.
    let points: Vec<SVector<f64, 1>> = [0.5, 1.6, 1.6].map(|x| [x].into()).to_vec();
    assert_eq!(fit.factor(&cell, 2, Conservation::Fitted, &points), 1);
    let a = fit.solve(&[1.0, 2.1, 2.1], 0.0);
    assert!((evaluate(&cell, 1, &a, &[0.5].into()) - 1.0).abs() < 1e-14);
    assert_eq!(a[2], 0.0);
    // With a_1 prescribed the same points determine psi_2 and psi_3.
    assert_eq!(fit.factor(&cell, 2, Conservation::Fixed, &points), 2);
    // Collinear points in 2D carry no information across the line: y = x makes psi_3 a
    // multiple of psi_2 (in scaled coordinates), so only the constant is left.
    let square = TaylorCell::<2>::new([0.0, 0.0].into(), [1.0, 1.0].into());
    let diagonal: Vec<SVector<f64, 2>> = [0.1, 0.4, 0.7, 0.9].map(|t| [t, t].into()).to_vec();
    let mut fit2 = TaylorFit::<2>::default();
    assert_eq!(fit2.factor(&square, 2, Conservation::Fitted, &diagonal), 0);
    assert_eq!(
        fit2.solve(&[1.0, 2.0, 3.0, 6.0], 0.0),
        [3.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    );
}

/// Degree 0: Fixed returns the prescribed mean whatever the data, Fitted the average.
#[test]
fn degree_zero_cases() {
    let cell = cell_1d();
    let centre: Vec<SVector<f64, 1>> = vec![[1.2].into()];
    let mut fit = TaylorFit::<1>::default();
    // One point at the centre: psi_2 vanishes there, nothing can be fitted.
    assert_eq!(fit.factor(&cell, 2, Conservation::Fixed, &centre), 0);
    assert_eq!(fit.solve(&[5.0], 0.25), [0.25, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(fit.factor(&cell, 2, Conservation::Fitted, &centre), 0);
    assert_eq!(fit.solve(&[5.0], 0.25), [5.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    // One point off the centre: Fixed fits the slope through it.
    let off: Vec<SVector<f64, 1>> = vec![[2.0].into()];
    assert_eq!(fit.factor(&cell, 2, Conservation::Fixed, &off), 1);
    let a = fit.solve(&[5.0], 0.25);
    assert!((evaluate(&cell, 1, &a, &off[0]) - 5.0).abs() < 1e-14);
    // Degree 0 asked for: the mean, or the average of the values.
    let points = random_points(&cell, 4, 8);
    assert_eq!(fit.factor(&cell, 0, Conservation::Fixed, &points), 0);
    assert_eq!(fit.solve(&[1.0, 2.0, 3.0, 4.0], -1.0)[0], -1.0);
    assert_eq!(fit.factor(&cell, 0, Conservation::Fitted, &points), 0);
    assert_eq!(fit.solve(&[1.0, 2.0, 3.0, 4.5], -1.0)[0], 2.625);
}

/// A fit reused for smaller and equal point sets keeps its buffer.
#[test]
fn factor_reuses_its_buffers() {
    let cell = cell_2d();
    let mut fit = TaylorFit::<2>::default();
    fit.factor(&cell, 2, Conservation::Fixed, &random_points(&cell, 12, 1));
    let buffer = (fit.psi.as_ptr(), fit.psi.capacity());
    for n in [5, 12, 1] {
        fit.factor(
            &cell,
            2,
            Conservation::Fitted,
            &random_points(&cell, n, n as u64),
        );
        assert_eq!((fit.psi.as_ptr(), fit.psi.capacity()), buffer);
    }
}

/// Three points crowded into one end of the element (condition number about 2e4 of the basis
/// at the data, 3e8 of its normal matrix): the refined solve agrees with an SVD solve of the
/// data to 1e-10 (both are good to about kappa eps = 2e-12), where the normal equations alone
/// are off by about 3e-8.
#[test]
fn crowded_points_are_solved_as_accurately_as_by_an_orthogonal_factorisation() {
    let cell = TaylorCell::<1>::new(
        [3.828_816_046_562_56].into(),
        [3.926_990_816_987_241].into(),
    );
    let points: Vec<SVector<f64, 1>> = [3.829_805_47, 3.830_140_59, 3.834_068_5]
        .map(|x| [x].into())
        .to_vec();
    let values: Vec<f64> = points.iter().map(|x| x[0].sin() + 2.0).collect();
    let b = DMatrix::from_fn(3, 3, |p, j| cell.basis(2, &points[p])[j]);
    let direct = b
        .svd(true, true)
        .solve(&DVector::from_vec(values.clone()), 1e-15)
        .unwrap();
    let mut fit = TaylorFit::<1>::default();
    assert_eq!(fit.factor(&cell, 2, Conservation::Fitted, &points), 2);
    let a = fit.solve(&values, 0.0);
    for j in 0..3 {
        assert!(
            (a[j] - direct[j]).abs() < 1e-10 * direct.amax(),
            "{a:?} against {direct}"
        );
    }
}

/// Four points of a slightly deformed 2 x 2 lattice (MPM's 2 points per cell and axis) cannot
/// carry the five or six quadratic unknowns, however rounding makes the last of them look.
#[test]
fn more_unknowns_than_points_lower_the_degree() {
    let cell = TaylorCell::<2>::new([0.0, 0.0].into(), [1.0, 1.0].into());
    let mut rng = Lcg::new(29);
    let mut fit = TaylorFit::<2>::default();
    for strain in [0.0, 1e-4, 1e-3, 1e-2, 5e-2] {
        let points: Vec<SVector<f64, 2>> = [[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]]
            .map(|[x, y]| {
                let mut jitter = |_: usize| strain * (rng.unit() - 0.5);
                SVector::from([x + jitter(0), y + jitter(1)])
            })
            .to_vec();
        for conservation in [Conservation::Fixed, Conservation::Fitted] {
            assert_eq!(
                fit.factor(&cell, 2, conservation, &points),
                1,
                "strain {strain}, {conservation:?}"
            );
        }
    }
}
