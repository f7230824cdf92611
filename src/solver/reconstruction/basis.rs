//! The weighted orthogonal polynomials of Tran eq 16 for the data points, built about a
//! centre from the same moments the reconstruction inverts, sampled for plots.

use nalgebra::SVector;

use crate::benchmarks::scattered::ScatteredData;
use crate::output::BasisRecord;
use crate::reconstruct::{moment_matrix, monomials, Degree, Kernel, OrthogonalBasis, MAX_TERMS};

pub(super) fn record(
    data: &ScatteredData,
    degree: Degree,
    h: f64,
    centre: f64,
    curve_x: &[f64],
) -> BasisRecord {
    let kernel = Kernel {
        weight: data.weight,
        scale: data.scale,
    };
    let offset = |x: f64| SVector::<f64, 1>::from([(x - centre) / h]);
    let offsets: Vec<SVector<f64, 1>> = data.points.iter().map(|&x| offset(x)).collect();
    let (moments, terms) = moment_matrix(&kernel, degree, &offsets);
    let basis = OrthogonalBasis::from_moments(&moments, terms);
    // p_i at each point, polynomial-major: row i holds p_i at every point.
    let sample = |xs: &[f64]| {
        let mut q = [0.0; MAX_TERMS];
        let mut values = vec![0.0; terms * xs.len()];
        for (k, &x) in xs.iter().enumerate() {
            monomials(degree, &offset(x), &mut q);
            for i in 0..terms {
                values[i * xs.len() + k] = basis.eval(i, &q);
            }
        }
        values
    };
    BasisRecord {
        centre,
        terms,
        coefficients: (0..terms)
            .flat_map(|i| basis.coeffs[i][..terms].to_vec())
            .collect(),
        norms: basis.norms[..terms].to_vec(),
        kept: basis.kept[..terms].iter().map(|&k| i64::from(k)).collect(),
        data_weight: offsets.iter().map(|d| kernel.eval(d)).collect(),
        data_p: sample(&data.points),
        curve_p: sample(curve_x),
    }
}
