//! One run of the element-wise benchmark `recon_tls`: each element's Taylor least-squares fit
//! of its own data (Wobbes et al. 2018 sec 2), then u and u^h at Gauss points, the RMS error
//! and the relative error of the Gauss integral of u^h (sec 2.1).

use nalgebra::SVector;

use crate::benchmarks::scattered::{ElementData, ExactField};
use crate::gauss::gauss_legendre_rule;
use crate::grid::lattice_coords;
use crate::output::ElementRecord;
use crate::reconstruct::{taylor_terms, Conservation, TaylorCell, TaylorFit};

/// Plot samples per element along x.
const CURVE_SAMPLES: usize = 101;
/// Map samples per axis across a 2D domain, about: each element gets MAP_SAMPLES / cells per
/// axis (at least one), so the map stays the same size however fine the grid.
const MAP_SAMPLES: usize = 60;

/// Fits every element of `data` at `degree` and measures the errors.
pub(super) fn reconstruct<const D: usize, F: ExactField<D>>(
    data: &ElementData<D, F>,
    degree: usize,
    conservation: Conservation,
) -> ElementRecord {
    let u = &data.function;
    let cells = data.domain.cells;
    let h = data.h();
    let terms = taylor_terms(D, degree);
    let (nodes, weights) = gauss_legendre_rule(data.gauss);
    // The row of elements the plot samples run through, and the height they run at (2D).
    let curve_row = cells / 2;
    let curve_y = data.domain.lower[D - 1] + (curve_row as f64 + 0.5) * h;
    let map_samples = (MAP_SAMPLES / cells).max(1);
    let mut out = ElementRecord {
        formula: u.formula().to_string(),
        conservation: conservation.to_string(),
        dim: D,
        degree: degree as i64,
        gauss: data.gauss as i64,
        ..Default::default()
    };
    let mut fit = TaylorFit::<D>::default();
    let mut values = Vec::new();
    let mut integral = 0.0;
    let mut squares = 0.0;
    for (e, points) in data.points.iter().enumerate() {
        let index = lattice_coords(e, &[cells; D]);
        let corner = |offset: usize| {
            SVector::<f64, D>::from_fn(|k, _| data.domain.lower[k] + (index[k] + offset) as f64 * h)
        };
        let cell = TaylorCell::new(corner(0), corner(1));
        let used = fit.factor(&cell, degree, conservation, points);
        values.clear();
        values.extend(points.iter().map(|x| u.value(x)));
        let mean = u.box_integral(cell.lower(), cell.upper()) / cell.volume();
        let a = fit.solve(&values, mean);
        let eval = |x: &SVector<f64, D>| -> f64 {
            let psi = cell.basis(used, x);
            (0..terms).map(|i| a[i] * psi[i]).sum()
        };
        out.lower.extend(cell.lower().iter());
        out.upper.extend(cell.upper().iter());
        out.mean.push(mean);
        out.element_degree.push(used as i64);
        out.coefficients.extend(&a[..terms]);
        out.degraded += i64::from(used < degree);
        for (x, &value) in points.iter().zip(&values) {
            out.data_x.extend(x.iter());
            out.data_u.push(value);
            out.data_element.push(e as i64);
        }
        for g in 0..data.gauss.pow(D as u32) {
            let at = lattice_coords(g, &[data.gauss; D]);
            let x = SVector::<f64, D>::from_fn(|k, _| {
                cell.centre()[k] + nodes[at[k]] * cell.half_widths()[k]
            });
            let w: f64 = (0..D)
                .map(|k| weights[at[k]] * cell.half_widths()[k])
                .product();
            let (exact, reconstructed) = (u.value(&x), eval(&x));
            out.gauss_x.extend(x.iter());
            out.gauss_weight.push(w);
            out.gauss_element.push(e as i64);
            out.exact.push(exact);
            out.reconstructed.push(reconstructed);
            out.error.push(exact - reconstructed);
            integral += w * reconstructed;
            squares += (exact - reconstructed).powi(2);
        }
        if D == 1 || index[D - 1] == curve_row {
            for s in 0..CURVE_SAMPLES {
                let t = s as f64 / (CURVE_SAMPLES - 1) as f64;
                let x = SVector::<f64, D>::from_fn(|k, _| {
                    if k == 0 {
                        cell.lower()[0] + t * (cell.upper()[0] - cell.lower()[0])
                    } else {
                        curve_y
                    }
                });
                out.curve_x.extend(x.iter());
                out.curve_element.push(e as i64);
                out.curve_exact.push(u.value(&x));
                out.curve_reconstructed.push(eval(&x));
            }
        }
        if D == 2 {
            for s in 0..map_samples.pow(2) {
                let at = lattice_coords(s, &[map_samples; D]);
                let x = SVector::<f64, D>::from_fn(|k, _| {
                    let t = (at[k] as f64 + 0.5) / map_samples as f64;
                    cell.lower()[k] + t * (cell.upper()[k] - cell.lower()[k])
                });
                out.map_x.extend(x.iter());
                out.map_element.push(e as i64);
                out.map_exact.push(u.value(&x));
                out.map_reconstructed.push(eval(&x));
            }
        }
    }
    out.rms = (squares / out.exact.len() as f64).sqrt();
    out.integral = integral;
    out.exact_integral = u.box_integral(&data.domain.lower, &data.domain.upper);
    out.integral_error = (integral - out.exact_integral).abs() / out.exact_integral.abs();
    out
}
