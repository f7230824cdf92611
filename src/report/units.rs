//! The quantity and unit an axis or a legend entry of a figure names.

use crate::output::REFERENCE_NORM;

/// The SI unit of an error field; `None` for a dimensionless
/// one (a reconstructed function, a consistency error).
pub fn field_unit(field: &str) -> Option<&'static str> {
    match field {
        "displacement" => Some("m"),
        "velocity" | "grid_velocity" => Some("m/s"),
        "stress" => Some("Pa"),
        "density" => Some("kg/m^3"),
        _ => None,
    }
}

/// `stress (Pa)`: a field's values on an axis.
pub fn quantity(field: &str) -> String {
    match field_unit(field) {
        Some(unit) => format!("{field} ({unit})"),
        None => field.to_string(),
    }
}

/// Whether `norm` divides by the size of the exact (or reference) field.
pub fn is_relative(norm: &str) -> bool {
    matches!(norm, "integral" | REFERENCE_NORM)
}

/// The unit of `field`'s error in `norm`: `l2 = sqrt(sum_p V_p e_p^2)` carries the volume's
/// m^(D/2), `rms` and `max` the field's unit, relative norms none ("-").
pub fn error_unit(field: &str, norm: &str, dim: usize) -> String {
    let Some(unit) = field_unit(field).filter(|_| !is_relative(norm)) else {
        return "-".into();
    };
    match (norm, dim) {
        ("l2", 1) => format!("{unit}·m^1/2"),
        ("l2", 2) => format!("{unit}·m"),
        ("l2", 3) => format!("{unit}·m^3/2"),
        _ => unit.to_string(),
    }
}

/// The cell size axis: in metres for a simulation, whose grid is physical.
pub fn cell_size_label(physical: bool) -> String {
    if physical {
        "h, cell size (m)".into()
    } else {
        "h, cell size (dimensionless)".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn l2_errors_carry_the_volume() {
        assert_eq!(error_unit("stress", "l2", 1), "Pa·m^1/2");
        assert_eq!(error_unit("velocity", "l2", 2), "m/s·m");
        assert_eq!(error_unit("velocity", "rms", 2), "m/s");
        assert_eq!(error_unit("stress", "reference", 1), "-");
        assert_eq!(error_unit("u", "rms", 1), "-");
    }
}
