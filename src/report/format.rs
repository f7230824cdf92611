//! Number formatting shared by the tables, the figures and the messages.

/// A float that parses back to the same value (Rust's shortest round-trip form).
pub fn exact(x: f64) -> String {
    format!("{x:?}")
}

/// A convergence rate as shown to readers (legends, report tables).
pub fn rate(x: f64) -> String {
    format!("{x:.2}")
}

/// `%g`-style text with `sig` significant digits: fixed notation for magnitudes in
/// [1e-3, 1e5), scientific otherwise, trailing zeros trimmed.
pub fn general(x: f64, sig: usize) -> String {
    let sig = sig.max(1);
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let exponent = x.abs().log10().floor() as i32;
    if (-3..5).contains(&exponent) {
        let decimals = (sig as i32 - 1 - exponent).max(0) as usize;
        trim_zeros(&format!("{x:.decimals$}")).to_string()
    } else {
        let text = format!("{x:.prec$e}", prec = sig - 1);
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        format!("{}e{exponent}", trim_zeros(mantissa))
    }
}

fn trim_zeros(fixed: &str) -> &str {
    if fixed.contains('.') {
        fixed.trim_end_matches('0').trim_end_matches('.')
    } else {
        fixed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn general_picks_notation_by_magnitude() {
        assert_eq!(general(0.125, 4), "0.125");
        assert_eq!(general(1.0 / 48.0, 4), "0.02083");
        assert_eq!(general(1.98765, 3), "1.99");
        assert_eq!(general(2.0, 3), "2");
        assert_eq!(general(3.2e-7, 3), "3.2e-7");
        assert_eq!(general(-1.5e6, 3), "-1.5e6");
        assert_eq!(general(0.0, 3), "0");
        assert_eq!(general(f64::NAN, 3), "NaN");
    }

    #[test]
    fn exact_round_trips() {
        let x = 1.0 / 3.0;
        assert_eq!(exact(x).parse::<f64>().unwrap(), x);
        assert_eq!(exact(1e-7), "1e-7");
    }
}
