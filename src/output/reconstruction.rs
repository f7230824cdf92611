//! The `/reconstruction` group of a reconstruction run: evaluation points, exact and
//! reconstructed values, pointwise errors and their norms, the data, a fine sampling of u for
//! plots, rank-loss counts, and (for `recon1d_basis`) the weighted orthogonal basis.
//! Written and read with the same names, so the report sees exactly what the file holds.

use hdf5::{File, Group};

use super::h5::{
    attr_f64, attr_i64, attr_str, dataset, open_dataset, read_f64, read_i64, read_str,
};

const GROUP: &str = "reconstruction";
const BASIS: &str = "basis";
/// The benchmarks' functions and coordinates are dimensionless.
const UNIT: &str = "1";

/// One reconstruction: Ne evaluation points, Np data points, Nc plot samples.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReconstructionRecord {
    /// u(x) as the paper writes it, e.g. `x^2`.
    pub formula: String,
    /// The weight function, its support length in cells, the basis degree and the solver.
    pub weight: String,
    pub scale: f64,
    pub degree: i64,
    pub solver: String,
    /// Evaluation points (the grid nodes), u there, u^h there (NaN where no data point is
    /// in reach), and u - u^h.
    pub x: Vec<f64>,
    pub exact: Vec<f64>,
    pub reconstructed: Vec<f64>,
    pub error: Vec<f64>,
    pub data_x: Vec<f64>,
    pub data_u: Vec<f64>,
    /// u on a fine uniform sampling of the interval, for plots.
    pub curve_x: Vec<f64>,
    pub curve_u: Vec<f64>,
    /// sqrt(sum_e h error_e^2) and max_e |error_e|; NaN if any point is uncovered.
    pub l2: f64,
    pub max: f64,
    /// Evaluation points with data in reach, those whose fit lost rank (IMLS dropped a
    /// polynomial), and those without data in reach.
    pub fits: i64,
    pub rank_deficient: i64,
    pub uncovered: i64,
    pub basis: Option<BasisRecord>,
}

/// The weighted orthogonal polynomials p_1..p_m of Tran eq 16 at `centre`, in the monomials
/// of s = (x - centre)/h: p_i = sum_j coefficients[i][j] s^j.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BasisRecord {
    pub centre: f64,
    pub terms: usize,
    /// m x m, row-major, unit lower-triangular.
    pub coefficients: Vec<f64>,
    /// <p_i, p_i> = sum_p w_p p_i(x_p)^2.
    pub norms: Vec<f64>,
    /// 1 where p_i is kept, 0 where it is dropped (<p_i, p_i> vanishes, eq 17).
    pub kept: Vec<i64>,
    /// w(x_p - centre) of each data point.
    pub data_weight: Vec<f64>,
    /// m x Np: p_i at the data points.
    pub data_p: Vec<f64>,
    /// m x Nc: p_i at `curve_x`.
    pub curve_p: Vec<f64>,
}

pub(super) fn write(file: &File, r: &ReconstructionRecord) -> hdf5::Result<()> {
    let group = file.create_group(GROUP)?;
    for (name, value) in [
        ("formula", &r.formula),
        ("weight", &r.weight),
        ("solver", &r.solver),
    ] {
        attr_str(&group, name, value)?;
    }
    for (name, value) in [("scale", r.scale), ("l2", r.l2), ("max", r.max)] {
        attr_f64(&group, name, value)?;
    }
    for (name, value) in [
        ("degree", r.degree),
        ("fits", r.fits),
        ("rank_deficient", r.rank_deficient),
        ("uncovered", r.uncovered),
    ] {
        attr_i64(&group, name, value)?;
    }
    for (name, values) in [
        ("x", &r.x),
        ("exact", &r.exact),
        ("reconstructed", &r.reconstructed),
        ("error", &r.error),
        ("data_x", &r.data_x),
        ("data_u", &r.data_u),
        ("curve_x", &r.curve_x),
        ("curve_u", &r.curve_u),
    ] {
        dataset(&group, name, values, &[values.len()], UNIT)?;
    }
    if let Some(basis) = &r.basis {
        write_basis(&group, basis, r.data_x.len(), r.curve_x.len())?;
    }
    Ok(())
}

fn write_basis(parent: &Group, b: &BasisRecord, np: usize, nc: usize) -> hdf5::Result<()> {
    let group = parent.create_group(BASIS)?;
    attr_f64(&group, "centre", b.centre)?;
    let m = b.terms;
    dataset(&group, "coefficients", &b.coefficients, &[m, m], UNIT)?;
    dataset(&group, "norms", &b.norms, &[m], UNIT)?;
    dataset(&group, "kept", &b.kept, &[m], UNIT)?;
    dataset(&group, "data_weight", &b.data_weight, &[np], UNIT)?;
    dataset(&group, "data_p", &b.data_p, &[m, np], UNIT)?;
    dataset(&group, "curve_p", &b.curve_p, &[m, nc], UNIT)
}

/// The group of a reconstruction run; `None` for a simulation run.
pub(super) fn read(file: &File) -> hdf5::Result<Option<ReconstructionRecord>> {
    if !file.link_exists(GROUP) {
        return Ok(None);
    }
    let group = file.group(GROUP)?;
    let data = |name: &str| open_dataset(&group, name)?.read_raw::<f64>();
    let basis = if group.link_exists(BASIS) {
        Some(read_basis(&group.group(BASIS)?)?)
    } else {
        None
    };
    Ok(Some(ReconstructionRecord {
        formula: read_str(&group, "formula")?,
        weight: read_str(&group, "weight")?,
        scale: read_f64(&group, "scale")?,
        degree: read_i64(&group, "degree")?,
        solver: read_str(&group, "solver")?,
        x: data("x")?,
        exact: data("exact")?,
        reconstructed: data("reconstructed")?,
        error: data("error")?,
        data_x: data("data_x")?,
        data_u: data("data_u")?,
        curve_x: data("curve_x")?,
        curve_u: data("curve_u")?,
        l2: read_f64(&group, "l2")?,
        max: read_f64(&group, "max")?,
        fits: read_i64(&group, "fits")?,
        rank_deficient: read_i64(&group, "rank_deficient")?,
        uncovered: read_i64(&group, "uncovered")?,
        basis,
    }))
}

fn read_basis(group: &Group) -> hdf5::Result<BasisRecord> {
    let data = |name: &str| open_dataset(group, name)?.read_raw::<f64>();
    let norms = data("norms")?;
    Ok(BasisRecord {
        centre: read_f64(group, "centre")?,
        terms: norms.len(),
        coefficients: data("coefficients")?,
        norms,
        kept: open_dataset(group, "kept")?.read_raw::<i64>()?,
        data_weight: data("data_weight")?,
        data_p: data("data_p")?,
        curve_p: data("curve_p")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What is written is read back unchanged, NaN and all.
    #[test]
    fn round_trips_through_a_file() {
        let record = ReconstructionRecord {
            formula: "x^2".into(),
            weight: "quadratic".into(),
            scale: 2.0,
            degree: 2,
            solver: "imls".into(),
            x: vec![-1.0, 0.0, 1.0],
            exact: vec![1.0, 0.0, 1.0],
            reconstructed: vec![0.9, f64::NAN, 1.0],
            error: vec![0.1, f64::NAN, 0.0],
            data_x: vec![-0.6, 0.4],
            data_u: vec![0.36, 0.16],
            curve_x: vec![-1.0, 1.0],
            curve_u: vec![1.0, 1.0],
            l2: f64::NAN,
            max: f64::NAN,
            fits: 2,
            rank_deficient: 2,
            uncovered: 1,
            basis: Some(BasisRecord {
                centre: 0.0,
                terms: 3,
                coefficients: vec![1.0, 0.0, 0.0, 0.2, 1.0, 0.0, -0.24, 0.2, 1.0],
                norms: vec![1.5, 0.3, 1e-18],
                kept: vec![1, 1, 0],
                data_weight: vec![0.6, 0.7],
                data_p: vec![1.0, 1.0, -0.4, 0.6, 0.0, 0.0],
                curve_p: vec![1.0; 6],
            }),
        };
        let dir = tempfile::tempdir().unwrap();
        let file = File::create(dir.path().join("r.h5")).unwrap();
        write(&file, &record).unwrap();
        let back = read(&file).unwrap().unwrap();
        let bits = |r: &ReconstructionRecord| format!("{r:?}");
        assert_eq!(bits(&back), bits(&record));
        assert!(read(&File::create(dir.path().join("s.h5")).unwrap())
            .unwrap()
            .is_none());
    }
}
