use nalgebra::{SMatrix, SVector};

use super::cpdi::{corner_weights, jacobian_coefficients, reference_corner};
use super::*;
use crate::benchmarks::{gong_mms, thesis_params, Problem, SineMms};
use crate::gauss::gauss_legendre;
use crate::rng::Lcg;
use crate::shape::LinearHat;

const SHAPES: [DomainShape; 4] = [
    DomainShape::FixedBox,
    DomainShape::StretchedBox,
    DomainShape::Parallelogram,
    DomainShape::Quadrilateral,
];

/// Particles of Gong's box (6 cells, 2 per cell and axis) moved, sheared and stretched at
/// random, with CPDI2 corners jiggled the same way, and their stencils.
fn deformed<const D: usize>(
    shape: DomainShape,
    seed: u64,
) -> (Grid<D>, Particles<D>, ParticleDomains<D>, Stencils<D>) {
    let problem: SineMms<D> = gong_mms(&thesis_params(0.1, 6, 2)).unwrap();
    let grid = Grid::new(&problem.domain());
    let mut particles = problem.seed_particles(&grid);
    let mut rng = Lcg::new(seed);
    let mut rand = move || rng.unit() - 0.5;
    let spacing = particles.lattice.spacing;
    let mut domains = ParticleDomains::new(shape, &particles);
    for c in domains.corners.iter_mut() {
        *c += SVector::from_fn(|_, _| 0.3 * spacing * rand());
    }
    for p in 0..particles.len() {
        particles.x[p] += SVector::from_fn(|_, _| 0.4 * spacing * rand());
        particles.f[p] = SMatrix::identity() + SMatrix::from_fn(|_, _| 0.4 * rand());
    }
    let mut stencils = Stencils::new(ParticleDomains::<D>::nodes_per_point(), particles.len());
    domains.fill(&grid, &mut particles, &mut stencils).unwrap();
    (grid, particles, domains, stencils)
}

/// The domain of particle `p` as its corners (boxes as their four corners), cut to the grid.
fn domain_corners<const D: usize>(
    grid: &Grid<D>,
    particles: &Particles<D>,
    domains: &ParticleDomains<D>,
    p: usize,
) -> Vec<SVector<f64, D>> {
    let mut corners = vec![SVector::zeros(); 1 << D];
    match domains.box_half_widths(particles, p) {
        Some(half) => {
            for (a, c) in corners.iter_mut().enumerate() {
                *c = particles.x[p] + half.component_mul(&reference_corner::<D>(a));
            }
        }
        None => domains.corners_of(particles, p, &mut corners),
    }
    corners.iter().map(|c| clamp_to_grid(grid, c)).collect()
}

/// Partition of unity, zero gradient sum, sum_i x_i S_ip = the domain's centroid and
/// sum_i x_i (x) grad S_ip = I, for every shape at randomly deformed particles.
fn check_consistency<const D: usize>() {
    for shape in SHAPES {
        let (grid, particles, domains, st) = deformed::<D>(shape, 7);
        for p in 0..particles.len() {
            let sum_w: f64 = st.of(p).map(|(_, w, _)| w).sum();
            let sum_g: SVector<f64, D> = st.of(p).map(|(_, _, g)| *g).sum();
            let first: SVector<f64, D> = st.of(p).map(|(i, w, _)| grid.node_position(i) * w).sum();
            let second: SMatrix<f64, D, D> = st
                .of(p)
                .map(|(i, _, g)| grid.node_position(i) * g.transpose())
                .sum();
            let corners = domain_corners(&grid, &particles, &domains, p);
            let centroid = match shape {
                DomainShape::Parallelogram | DomainShape::Quadrilateral => {
                    let cw = corner_weights(&corners).unwrap();
                    (0..corners.len()).map(|a| corners[a] * cw.value[a]).sum()
                }
                // A box's centroid is the middle of its (cut) extent.
                _ => (corners[0] + corners[(1 << D) / 2]) / 2.0,
            };
            assert!(
                (sum_w - 1.0).abs() < 1e-13,
                "{shape} p {p}: sum S = {sum_w}"
            );
            assert!(sum_g.norm() < 1e-9, "{shape} p {p}: sum grad S = {sum_g}");
            assert!(
                (first - centroid).norm() < 1e-13,
                "{shape} p {p}: {first} vs {centroid}"
            );
            let identity = SMatrix::<f64, D, D>::identity();
            assert!(
                (second - identity).norm() < 1e-11,
                "{shape} p {p}: {second}"
            );
            assert!(st.of(p).all(|(_, w, _)| w >= 0.0));
        }
    }
}

#[test]
fn partition_of_unity_and_linear_reproduction_1d() {
    check_consistency::<1>();
}

#[test]
fn partition_of_unity_and_linear_reproduction_2d() {
    check_consistency::<2>();
}

/// uGIMP's gradient is the derivative of S_ip with respect to x_p where the box moves
/// rigidly, i.e. where the grid's edge does not cut it.
#[test]
fn gimp_gradient_matches_finite_differences() {
    let (grid, particles, domains, st) = deformed::<2>(DomainShape::FixedBox, 3);
    let eps = 1e-7;
    let upper = grid.lower + SVector::repeat(grid.cells as f64 * grid.h);
    let mut checked = 0;
    for p in 0..particles.len() {
        let x = particles.x[p];
        let margin = domains.half0 + 2.0 * eps;
        if (0..2).any(|k| x[k] - margin < grid.lower[k] || x[k] + margin > upper[k]) {
            continue;
        }
        checked += 1;
        for k in 0..2 {
            let values_at = |delta: f64| {
                let mut y = x;
                y[k] += delta;
                let half = SVector::repeat(domains.half0);
                let mut s = Stencils::new(st.per_point, 1);
                fill_box::<2, NODES_PER_AXIS>(
                    &grid,
                    &y,
                    &half,
                    &mut s.node,
                    &mut s.weight,
                    &mut s.grad,
                )
                .unwrap();
                s
            };
            let (plus, minus) = (values_at(eps), values_at(-eps));
            for (e, (i, _, g)) in st.of(p).enumerate() {
                assert_eq!((plus.node[e] as usize, minus.node[e] as usize), (i, i));
                let fd = (plus.weight[e] - minus.weight[e]) / (2.0 * eps);
                let scale = grid.inv_h();
                assert!(
                    (fd - g[k]).abs() < 1e-6 * scale,
                    "p {p} node {i}: {fd} vs {}",
                    g[k]
                );
            }
        }
    }
    assert!(checked > 50, "only {checked} particles away from the edges");
}

/// GIMP tends to the linear hat as the box shrinks to a point: values uniformly, at first
/// order in the half-width even where the box straddles a grid line (the hat's kink), and
/// gradients exactly once the box no longer reaches a grid line.
#[test]
fn gimp_tends_to_the_hat() {
    let problem: SineMms<2> = gong_mms(&thesis_params(0.1, 5, 1)).unwrap();
    let grid = Grid::new(&problem.domain());
    let deviation = |x: SVector<f64, 2>, half: f64| {
        let mut hat_st = Stencils::new(4, 1);
        hat_st
            .update(&LinearHat, &grid, std::slice::from_ref(&x))
            .unwrap();
        let mut st = Stencils::new(ParticleDomains::<2>::nodes_per_point(), 1);
        let h = SVector::repeat(half * grid.h);
        fill_box::<2, NODES_PER_AXIS>(&grid, &x, &h, &mut st.node, &mut st.weight, &mut st.grad)
            .unwrap();
        let (mut value, mut gradient): (f64, f64) = (0.0, 0.0);
        for (i, w, g) in st.of(0) {
            let (hw, hg) = hat_st
                .of(0)
                .find(|(j, _, _)| *j == i)
                .map_or((0.0, SVector::zeros()), |(_, hw, hg)| (hw, *hg));
            value = value.max((w - hw).abs());
            gradient = gradient.max((g - hg).norm() * grid.h);
        }
        (value, gradient)
    };
    let inside = SVector::<f64, 2>::new(0.3171, 0.5523);
    let mut previous = f64::INFINITY;
    for half in [1e-1, 1e-2, 1e-3, 1e-4] {
        // Straddling the grid lines x = 0.4 and y = 0.6.
        let kink = SVector::<f64, 2>::new(0.4, 0.6) + SVector::repeat(0.5 * half * grid.h);
        let (value, _) = deviation(kink, half);
        assert!(
            value < half && value < previous,
            "half-width {half}: {value}"
        );
        previous = value;
        // Exact up to the cancellation in (int N)/(b - a), which grows as 1/half.
        let (value, gradient) = deviation(inside, half);
        let round_off = 1e-15 / half;
        assert!(
            value < round_off && gradient < round_off,
            "half-width {half}: {value} {gradient}"
        );
    }
}

/// The corner weights of a general quadrilateral: the volume is the shoelace area, the
/// weights are Sadeghirad's (eq 6.30 with 1 read as 6 V), and weights and gradient vectors
/// equal (1/V) int N_a and (1/V) int grad N_a by 3x3-point Gauss quadrature of the
/// isoparametric definitions (exact: the integrands are quadratic in each reference coordinate).
#[test]
fn quadrilateral_weights_match_quadrature() {
    let corners: Vec<SVector<f64, 2>> = [(0.1, 0.2), (1.3, 0.0), (1.1, 0.9), (0.3, 1.4)]
        .iter()
        .map(|&(x, y)| SVector::<f64, 2>::new(x, y))
        .collect();
    let cw = corner_weights(&corners).unwrap();
    let (x, y) = (|a: usize| corners[a][0], |a: usize| corners[a][1]);
    let shoelace = 0.5
        * (0..4)
            .map(|a| x(a) * y((a + 1) % 4) - x((a + 1) % 4) * y(a))
            .sum::<f64>();
    assert!((cw.volume - shoelace).abs() < 1e-15);
    let a = (x(3) - x(0)) * (y(1) - y(2)) - (x(1) - x(2)) * (y(3) - y(0));
    let b = (x(2) - x(3)) * (y(0) - y(1)) - (x(0) - x(1)) * (y(2) - y(3));
    let v = cw.volume;
    let sadeghirad = [
        6.0 * v - a - b,
        6.0 * v - a + b,
        6.0 * v + a + b,
        6.0 * v + a - b,
    ];
    for k in 0..4 {
        assert!(
            (cw.value[k] - sadeghirad[k] / (24.0 * v)).abs() < 1e-14,
            "corner {k}"
        );
    }
    let (nodes, weights) = gauss_legendre(3);
    let mut integral = [0.0; 4];
    let mut grad_integral = [SVector::<f64, 2>::zeros(); 4];
    for (i, &s) in nodes.iter().enumerate() {
        for (j, &t) in nodes.iter().enumerate() {
            let n = |c: usize| {
                let r = reference_corner::<2>(c);
                (1.0 + r[0] * s) * (1.0 + r[1] * t) / 4.0
            };
            let dn = |c: usize| {
                let r = reference_corner::<2>(c);
                SVector::<f64, 2>::new(r[0] * (1.0 + r[1] * t), r[1] * (1.0 + r[0] * s)) / 4.0
            };
            let jac: SMatrix<f64, 2, 2> = (0..4).map(|c| corners[c] * dn(c).transpose()).sum();
            let det = jac.determinant();
            let inv_t = jac.try_inverse().unwrap().transpose();
            for c in 0..4 {
                integral[c] += weights[i] * weights[j] * det * n(c);
                grad_integral[c] += inv_t * dn(c) * (weights[i] * weights[j] * det);
            }
        }
    }
    for c in 0..4 {
        assert!((integral[c] / v - cw.value[c]).abs() < 1e-14, "weight {c}");
        assert!(
            (grad_integral[c] / v - cw.gradient[c]).norm() < 1e-13,
            "gradient {c}"
        );
    }
    assert!(corner_weights(&[corners[0], corners[3], corners[2], corners[1]]).is_none());
}

/// `corner_weights` divides once for each pair of opposite corners; every weight and
/// gradient vector must equal the corner-by-corner formula of eqs 6.30 and 6.32 from the same
/// J0, J1, J2 exactly (`==`, which takes a zero of either sign as equal), on random
/// quadrilaterals and on the unit square, whose differences are exact and whose zeros are
/// exact zeros.
#[test]
fn corner_weights_are_the_corner_by_corner_formula() {
    let mut rng = Lcg::new(31);
    let mut quads = vec![[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]];
    for _ in 0..1000 {
        let mut jiggle = |x: f64, y: f64| (x + 0.4 * rng.unit(), y + 0.4 * rng.unit());
        quads.push([
            jiggle(0.0, 0.0),
            jiggle(1.0, 0.0),
            jiggle(1.0, 1.0),
            jiggle(0.0, 1.0),
        ]);
    }
    for quad in quads {
        let corners: Vec<SVector<f64, 2>> = quad
            .iter()
            .map(|&(x, y)| SVector::<f64, 2>::from([x, y]))
            .collect();
        let cw = corner_weights(&corners).unwrap();
        let (j0, j1, j2) = jacobian_coefficients(&corners);
        let volume = 4.0 * j0;
        assert_eq!(cw.volume, volume);
        for a in 0..4 {
            let r = reference_corner::<2>(a);
            let value = (j0 + (j1 * r[0] + j2 * r[1]) / 3.0) / volume;
            let (next, prev) = (corners[(a + 1) % 4], corners[(a + 3) % 4]);
            let gradient =
                SVector::<f64, 2>::from([next[1] - prev[1], prev[0] - next[0]]) / (2.0 * volume);
            assert_eq!(cw.value[a], value, "weight of corner {a} of {quad:?}");
            assert_eq!(
                cw.gradient[a], gradient,
                "gradient of corner {a} of {quad:?}"
            );
        }
    }
}

/// In 1D, CPDI1's interval x_p +- F l^0 and CPDI2's tracked interval give the same stencils
/// when the corners sit where F puts them.
#[test]
fn one_dimensional_parallelogram_and_quadrilateral_agree() {
    let (grid, mut particles, mut quad, _) = deformed::<1>(DomainShape::Quadrilateral, 11);
    let para = ParticleDomains::new(DomainShape::Parallelogram, &particles);
    for p in 0..particles.len() {
        let c0 = quad.first_corner[p] as usize;
        quad.corners[c0 + quad.corner_offset[1]] =
            quad.corners[c0] + particles.f[p] * SVector::repeat(2.0 * quad.half0);
    }
    // Centres at the middle of the tracked intervals, F from their lengths.
    for p in 0..particles.len() {
        let (l, r) = (
            quad.corners[quad.first_corner[p] as usize],
            quad.corners[quad.first_corner[p] as usize + quad.corner_offset[1]],
        );
        particles.x[p] = (l + r) / 2.0;
        particles.f[p] = SMatrix::repeat((r - l)[0] / (2.0 * quad.half0));
    }
    let mut a = Stencils::new(ParticleDomains::<1>::nodes_per_point(), particles.len());
    let mut b = Stencils::new(ParticleDomains::<1>::nodes_per_point(), particles.len());
    para.fill(&grid, &mut particles, &mut a).unwrap();
    quad.fill(&grid, &mut particles, &mut b).unwrap();
    for p in 0..particles.len() {
        for ((i, w, g), (j, v, f)) in a.of(p).zip(b.of(p)) {
            assert_eq!(i, j);
            assert!((w - v).abs() < 1e-13 && (g - f).norm() < 1e-9 * grid.inv_h());
        }
    }
}

#[test]
fn faults_name_the_particle() {
    let (grid, mut particles, domains, mut st) = deformed::<2>(DomainShape::Parallelogram, 5);
    particles.f[4] *= 8.0;
    assert_eq!(
        domains.fill(&grid, &mut particles, &mut st),
        Err(DomainFault::TooWide {
            particle: 4,
            max_cells: NODES_PER_AXIS - 1
        })
    );
    particles.f[4] = SMatrix::from_diagonal(&SVector::<f64, 2>::new(-1.0, 1.0));
    assert_eq!(
        domains.fill(&grid, &mut particles, &mut st),
        Err(DomainFault::Inverted(4))
    );
    particles.x[2][0] = f64::NAN;
    assert_eq!(
        domains.fill(&grid, &mut particles, &mut st),
        Err(DomainFault::Outside(2))
    );
}

/// Narrow stencils list exactly the nonzero entries of the widest ones, in the same order, so
/// that every sum over a stencil is the same; a domain that outgrows them widens all of them.
#[test]
fn narrow_stencils_hold_the_nonzero_entries_and_widen_when_outgrown() {
    let nonzero = |st: &Stencils<2>, p: usize| {
        st.of(p)
            .filter(|(_, w, g)| *w != 0.0 || g.norm() != 0.0)
            .map(|(i, w, g)| (i, w, *g))
            .collect::<Vec<_>>()
    };
    for shape in SHAPES {
        let (grid, mut particles, domains, wide) = deformed::<2>(shape, 11);
        let narrow_len = ParticleDomains::<2>::narrow_nodes_per_point();
        let mut narrow = Stencils::new(narrow_len, particles.len());
        domains.fill(&grid, &mut particles, &mut narrow).unwrap();
        assert_eq!(narrow.per_point, narrow_len, "{shape}");
        for p in 0..particles.len() {
            assert_eq!(nonzero(&narrow, p), nonzero(&wide, p), "{shape} p {p}");
        }
        if matches!(shape, DomainShape::FixedBox | DomainShape::Quadrilateral) {
            continue; // their domains do not follow F
        }
        // Particle 14's domain, stretched along x to 2.05 cells, needs four nodes along x.
        particles.f[14] = SMatrix::from_diagonal(&SVector::<f64, 2>::new(4.1, 1.0));
        let mut wide = Stencils::new(ParticleDomains::<2>::nodes_per_point(), particles.len());
        domains.fill(&grid, &mut particles, &mut wide).unwrap();
        domains.fill(&grid, &mut particles, &mut narrow).unwrap();
        assert_eq!(narrow.per_point, wide.per_point, "{shape}");
        assert_eq!(
            (&narrow.node, &narrow.weight, &narrow.grad),
            (&wide.node, &wide.weight, &wide.grad),
            "{shape}"
        );
    }
}
