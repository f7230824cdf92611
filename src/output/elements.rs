//! The `/elements` group of an element-wise reconstruction run (Taylor least squares, Wobbes
//! et al. 2018): the elements, their data, the coefficients of each element's fit, and u and
//! u^h at the Gauss points where the RMS and integral errors are measured. Written and read
//! with the same names, so the report and a reader with h5py see exactly what the file holds.

use hdf5::{File, Group};

use super::h5::{
    attr_f64, attr_i64, attr_str, dataset, open_dataset, read_f64, read_i64, read_str,
};

const GROUP: &str = "elements";
/// The benchmarks' functions and coordinates are dimensionless.
const UNIT: &str = "1";

/// One element-wise reconstruction in `dim` dimensions: Ne elements, Np data points (a point on
/// an edge shared by two elements is listed once for each), Ng Gauss points, Nc plot samples,
/// T coefficients per element (the Taylor basis of the requested degree).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementRecord {
    /// u as the paper writes it, e.g. `sin(x) + 2`.
    pub formula: String,
    /// `fixed` (a_1 = the exact element mean, eq 5) or `fitted` (a_1 by least squares).
    pub conservation: String,
    pub dim: usize,
    /// The requested degree and the Gauss points per element and axis.
    pub degree: i64,
    pub gauss: i64,
    /// Ne x D: each element's box.
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// Ne: the exact element mean c_e / |Omega_e| (the prescribed a_1 when fixed).
    pub mean: Vec<f64>,
    /// Ne: the degree each fit settled on (lower than `degree` where the data lost rank).
    pub element_degree: Vec<i64>,
    /// Ne x T: a_1..a_T of each element, zero beyond its degree's terms.
    pub coefficients: Vec<f64>,
    /// Np x D, Np, Np: the data points, u there, and the element each belongs to.
    pub data_x: Vec<f64>,
    pub data_u: Vec<f64>,
    pub data_element: Vec<i64>,
    /// Ng x D, Ng, Ng: Gauss points, their weights and elements.
    pub gauss_x: Vec<f64>,
    pub gauss_weight: Vec<f64>,
    pub gauss_element: Vec<i64>,
    /// Ng: u, u^h and u - u^h at the Gauss points.
    pub exact: Vec<f64>,
    pub reconstructed: Vec<f64>,
    pub error: Vec<f64>,
    /// Nc x D, Nc, Nc, Nc: samples for plots along the first axis, element by element (in 2D
    /// along the middle of the middle row of elements).
    pub curve_x: Vec<f64>,
    pub curve_element: Vec<i64>,
    pub curve_exact: Vec<f64>,
    pub curve_reconstructed: Vec<f64>,
    /// Nm x D, Nm, Nm, Nm: samples for maps over the plane, in 2D only (none in 1D, where the
    /// curve is the whole domain): a lattice of cell centres in each element, x fastest,
    /// element by element.
    pub map_x: Vec<f64>,
    pub map_element: Vec<i64>,
    pub map_exact: Vec<f64>,
    pub map_reconstructed: Vec<f64>,
    /// sqrt(sum_g error_g^2 / Ng), unweighted as in Wobbes sec 2.1.
    pub rms: f64,
    /// sum_g w_g u^h(x_g), the exact integral of u over the domain, and
    /// |integral - exact_integral| / |exact_integral|.
    pub integral: f64,
    pub exact_integral: f64,
    pub integral_error: f64,
    /// Elements whose fit settled on a lower degree than requested.
    pub degraded: i64,
}

impl ElementRecord {
    /// Coefficients per element.
    pub fn terms(&self) -> usize {
        self.coefficients
            .len()
            .checked_div(self.mean.len())
            .unwrap_or(0)
    }
}

pub(super) fn write(file: &File, r: &ElementRecord) -> hdf5::Result<()> {
    let group = file.create_group(GROUP)?;
    attr_str(&group, "formula", &r.formula)?;
    attr_str(&group, "conservation", &r.conservation)?;
    for (name, value) in [
        ("degree", r.degree),
        ("gauss", r.gauss),
        ("degraded", r.degraded),
    ] {
        attr_i64(&group, name, value)?;
    }
    for (name, value) in [
        ("rms", r.rms),
        ("integral", r.integral),
        ("exact_integral", r.exact_integral),
        ("integral_error", r.integral_error),
    ] {
        attr_f64(&group, name, value)?;
    }
    let d = r.dim;
    let (ne, np, ng, nc, nm) = (
        r.mean.len(),
        r.data_u.len(),
        r.exact.len(),
        r.curve_exact.len(),
        r.map_exact.len(),
    );
    let f64_sets: [(&str, &Vec<f64>, Vec<usize>); 17] = [
        ("lower", &r.lower, vec![ne, d]),
        ("upper", &r.upper, vec![ne, d]),
        ("mean", &r.mean, vec![ne]),
        ("coefficients", &r.coefficients, vec![ne, r.terms()]),
        ("data_x", &r.data_x, vec![np, d]),
        ("data_u", &r.data_u, vec![np]),
        ("gauss_x", &r.gauss_x, vec![ng, d]),
        ("gauss_weight", &r.gauss_weight, vec![ng]),
        ("exact", &r.exact, vec![ng]),
        ("reconstructed", &r.reconstructed, vec![ng]),
        ("error", &r.error, vec![ng]),
        ("curve_x", &r.curve_x, vec![nc, d]),
        ("curve_exact", &r.curve_exact, vec![nc]),
        ("curve_reconstructed", &r.curve_reconstructed, vec![nc]),
        ("map_x", &r.map_x, vec![nm, d]),
        ("map_exact", &r.map_exact, vec![nm]),
        ("map_reconstructed", &r.map_reconstructed, vec![nm]),
    ];
    for (name, values, shape) in f64_sets {
        dataset(&group, name, values, &shape, UNIT)?;
    }
    for (name, values) in [
        ("element_degree", &r.element_degree),
        ("data_element", &r.data_element),
        ("gauss_element", &r.gauss_element),
        ("curve_element", &r.curve_element),
        ("map_element", &r.map_element),
    ] {
        dataset(&group, name, values, &[values.len()], UNIT)?;
    }
    Ok(())
}

/// The group of an element-wise reconstruction run; `None` for any other run.
pub(super) fn read(file: &File) -> hdf5::Result<Option<ElementRecord>> {
    if !file.link_exists(GROUP) {
        return Ok(None);
    }
    let group: Group = file.group(GROUP)?;
    let real = |name: &str| open_dataset(&group, name)?.read_raw::<f64>();
    let int = |name: &str| open_dataset(&group, name)?.read_raw::<i64>();
    let lower = open_dataset(&group, "lower")?;
    Ok(Some(ElementRecord {
        formula: read_str(&group, "formula")?,
        conservation: read_str(&group, "conservation")?,
        dim: lower.shape().get(1).copied().unwrap_or(0),
        degree: read_i64(&group, "degree")?,
        gauss: read_i64(&group, "gauss")?,
        lower: lower.read_raw::<f64>()?,
        upper: real("upper")?,
        mean: real("mean")?,
        element_degree: int("element_degree")?,
        coefficients: real("coefficients")?,
        data_x: real("data_x")?,
        data_u: real("data_u")?,
        data_element: int("data_element")?,
        gauss_x: real("gauss_x")?,
        gauss_weight: real("gauss_weight")?,
        gauss_element: int("gauss_element")?,
        exact: real("exact")?,
        reconstructed: real("reconstructed")?,
        error: real("error")?,
        curve_x: real("curve_x")?,
        curve_element: int("curve_element")?,
        curve_exact: real("curve_exact")?,
        curve_reconstructed: real("curve_reconstructed")?,
        map_x: real("map_x")?,
        map_element: int("map_element")?,
        map_exact: real("map_exact")?,
        map_reconstructed: real("map_reconstructed")?,
        rms: read_f64(&group, "rms")?,
        integral: read_f64(&group, "integral")?,
        exact_integral: read_f64(&group, "exact_integral")?,
        integral_error: read_f64(&group, "integral_error")?,
        degraded: read_i64(&group, "degraded")?,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What is written is read back unchanged, NaN and all.
    #[test]
    fn round_trips_through_a_file() {
        let record = ElementRecord {
            formula: "sin(x) cos(y)".into(),
            conservation: "fixed".into(),
            dim: 2,
            degree: 2,
            gauss: 1,
            lower: vec![0.0, 0.0, 1.0, 0.0],
            upper: vec![1.0, 1.0, 2.0, 1.0],
            mean: vec![0.25, -0.5],
            element_degree: vec![2, 1],
            coefficients: vec![0.25, 1.0, 2.0, 3.0, 4.0, 5.0, -0.5, 1.0, 2.0, 0.0, 0.0, 0.0],
            data_x: vec![0.5, 0.5, 1.5, 0.5, 1.0, 0.5],
            data_u: vec![0.1, 0.2, 0.3],
            data_element: vec![0, 1, 1],
            gauss_x: vec![0.5, 0.5, 1.5, 0.5],
            gauss_weight: vec![1.0, 1.0],
            gauss_element: vec![0, 1],
            exact: vec![0.1, 0.2],
            reconstructed: vec![0.1, f64::NAN],
            error: vec![0.0, f64::NAN],
            curve_x: vec![0.0, 0.5, 1.0, 0.5],
            curve_element: vec![0, 0],
            curve_exact: vec![0.0, 0.4],
            curve_reconstructed: vec![0.01, 0.41],
            map_x: vec![0.5, 0.25, 1.5, 0.75, 0.5, 0.75],
            map_element: vec![0, 1, 0],
            map_exact: vec![0.2, 0.3, 0.4],
            map_reconstructed: vec![0.21, f64::NAN, 0.39],
            rms: f64::NAN,
            integral: 0.3,
            exact_integral: 0.3,
            integral_error: 1e-16,
            degraded: 1,
        };
        assert_eq!(record.terms(), 6);
        let dir = tempfile::tempdir().unwrap();
        let file = File::create(dir.path().join("e.h5")).unwrap();
        write(&file, &record).unwrap();
        let back = read(&file).unwrap().unwrap();
        assert_eq!(format!("{back:?}"), format!("{record:?}"));
        assert!(read(&File::create(dir.path().join("f.h5")).unwrap())
            .unwrap()
            .is_none());
    }
}
