//! Explicit updated-Lagrangian FEM in 1D: 2-node linear elements with one Gauss point, lumped
//! mass, nodes that move with the material, the stress advanced by the problem's material with
//! the element's velocity gradient, and central differences (leapfrog) in time.
//!
//! Between steps the nodes carry v^{n-1/2}, as the `mpm` leapfrog does; the first kick is a
//! half step from v^0.

use nalgebra::{SMatrix, SVector};

use crate::benchmarks::Problem;
use crate::divergence::Divergence;
use crate::material::Material;
use crate::particles::{Particles, SeedLattice};

/// The mesh and its state. Element e joins nodes e and e + 1.
pub struct UlFem {
    x: Vec<f64>,
    /// Half-step velocities between steps.
    v: Vec<f64>,
    /// Accelerations of the current forces; zero at fixed nodes.
    a: Vec<f64>,
    /// Lumped nodal masses.
    mass: Vec<f64>,
    fixed: [bool; 2],
    material: Material,
    /// One point per element at its centroid: reference and current position, the element's
    /// mass, length (volume), F = J = l / L and stress.
    points: Particles<1>,
}

impl UlFem {
    /// The problem's domain meshed with its `cells` elements, at rest in the reference
    /// configuration with the initial velocity at the nodes.
    pub fn new(problem: &dyn Problem<1>) -> Self {
        let domain = problem.domain();
        let (lower, upper) = (domain.lower[0], domain.upper[0]);
        let elements = domain.cells;
        let h = (upper - lower) / elements as f64;
        let x: Vec<f64> = (0..=elements).map(|i| lower + i as f64 * h).collect();
        let v = x
            .iter()
            .map(|&xi| problem.initial_velocity(&SVector::repeat(xi))[0])
            .collect();
        let element_mass = problem.rho0() * h;
        let mut mass = vec![0.0; elements + 1];
        for e in 0..elements {
            mass[e] += 0.5 * element_mass;
            mass[e + 1] += 0.5 * element_mass;
        }
        let centroids: Vec<SVector<f64, 1>> = (0..elements)
            .map(|e| SVector::repeat(0.5 * (x[e] + x[e + 1])))
            .collect();
        let faces = problem.fixed_faces();
        let points = Particles {
            x: centroids.clone(),
            x0: centroids,
            v: vec![SVector::zeros(); elements],
            f: vec![SMatrix::identity(); elements],
            j: vec![1.0; elements],
            stress: vec![SMatrix::zeros(); elements],
            mass: vec![element_mass; elements],
            volume0: vec![h; elements],
            volume: vec![h; elements],
            lattice: SeedLattice {
                lower: SVector::repeat(lower),
                spacing: h,
                per_axis: [elements],
            },
        };
        UlFem {
            a: vec![0.0; x.len()],
            x,
            v,
            mass,
            fixed: faces[0],
            material: problem.material(),
            points,
        }
    }

    /// Nodal accelerations from the element stresses: element e pulls node e with +sigma_e
    /// and node e + 1 with -sigma_e (the internal force -int dN/dx sigma dx with one Gauss
    /// point); fixed ends have none.
    pub fn accelerate(&mut self) {
        self.a.fill(0.0);
        for (e, stress) in self.points.stress.iter().enumerate() {
            let s = stress[(0, 0)];
            self.a[e] += s;
            self.a[e + 1] -= s;
        }
        for (a, m) in self.a.iter_mut().zip(&self.mass) {
            *a /= m;
        }
        let last = self.a.len() - 1;
        for (node, fixed) in [0, last].into_iter().zip(self.fixed) {
            if fixed {
                self.a[node] = 0.0;
                self.v[node] = 0.0;
            }
        }
    }

    /// v += kick a.
    pub fn kick(&mut self, kick: f64) {
        for (v, a) in self.v.iter_mut().zip(&self.a) {
            *v += a * kick;
        }
    }

    /// x^{n+1} = x^n + dt v^{n+1/2}, then each element's F = l / L and its stress advanced with
    /// grad v = (v_{e+1} - v_e) / l^{n+1/2}, the gradient on the length at the middle of the
    /// step (the midpoint rule for the rate of deformation).
    pub fn drift(&mut self, dt: f64) -> Result<(), Divergence> {
        let p = &mut self.points;
        let mut left_old = self.x[0];
        self.x[0] += self.v[0] * dt;
        for e in 0..p.len() {
            let right_old = self.x[e + 1];
            self.x[e + 1] += self.v[e + 1] * dt;
            let length = self.x[e + 1] - self.x[e];
            let mid = 0.5 * ((right_old - left_old) + length);
            let j = length / p.volume0[e];
            if !(j.is_finite() && mid.is_finite()) {
                return Err(Divergence::NonFinite {
                    particle: e,
                    what: "element length",
                });
            }
            if j <= 0.0 || mid <= 0.0 {
                return Err(Divergence::Jacobian { particle: e, j });
            }
            let grad_v = SMatrix::<f64, 1, 1>::new((self.v[e + 1] - self.v[e]) / mid);
            let f = SMatrix::<f64, 1, 1>::new(j);
            p.stress[e] = self.material.stress(&p.stress[e], &f, j, &grad_v, dt);
            p.f[e] = f;
            p.j[e] = j;
            p.volume[e] = length;
            p.x[e] = SVector::repeat(self.x[e] + 0.5 * length);
            left_old = right_old;
        }
        Ok(())
    }

    /// The element points with their velocity at the integer time level: the mean of the
    /// element's nodal velocities v^n = v^{n-1/2} + half a^n (half = dt/2, or 0 at the start,
    /// where the nodes still carry v^0), written into `velocity`.
    pub fn points(&self, half: f64, velocity: &mut [SVector<f64, 1>]) -> &Particles<1> {
        for (e, out) in velocity.iter_mut().enumerate() {
            let at = |i: usize| self.v[i] + half * self.a[i];
            *out = SVector::repeat(0.5 * (at(e) + at(e + 1)));
        }
        &self.points
    }

    /// The sum of the lumped nodal masses, in node order.
    pub fn nodal_mass(&self) -> f64 {
        self.mass.iter().sum()
    }

    pub fn elements(&self) -> usize {
        self.points.len()
    }

    /// The element points, for the run record.
    pub fn into_points(self) -> Particles<1> {
        self.points
    }
}
