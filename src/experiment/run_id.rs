//! Stable run identities: a canonical text of the resolved run and a hash of it that is the
//! same on every machine and Rust release (std's `DefaultHasher` promises neither).

use std::fmt::Write;

use crate::params::{ParamValue, Params};

/// The canonical resolved configuration without the experiment name, which is left out of
/// the hash so that renaming an experiment keeps its run ids. Keys are sorted (`Params` is
/// ordered) and values use `ParamValue`'s canonical Display.
pub(crate) fn config_body(
    benchmark: &str,
    method: &str,
    output_every: usize,
    params: &Params,
) -> String {
    let mut text = format!(
        "benchmark: {benchmark}\nmethod: {method}\noutput_every: {output_every}\nparams:\n"
    );
    for (key, value) in params {
        // Writing to a String cannot fail.
        let _ = writeln!(text, "  {key}: {value}");
    }
    text
}

/// The text stored with each run: the experiment name, then the hashed body.
pub(crate) fn config_yaml(experiment: &str, body: &str) -> String {
    format!("experiment: {experiment}\n{body}")
}

/// `<method>-<axis><value>-...-<hash12>` over the non-method axes in file order; a list
/// value is written with `_` between its numbers.
pub(crate) fn run_id(method: &str, axes: &[(&str, &ParamValue)], body: &str) -> String {
    let mut id = method.to_string();
    for (key, value) in axes {
        match value {
            ParamValue::List(values) => {
                let items: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
                let _ = write!(id, "-{key}{}", items.join("_"));
            }
            _ => {
                let _ = write!(id, "-{key}{value}");
            }
        }
    }
    // The top 48 bits of the hash: 12 hex digits.
    let _ = write!(id, "-{:012x}", fnv1a64(body.as_bytes()) >> 16);
    id.chars()
        .map(|c| match c {
            'A'..='Z' | 'a'..='z' | '0'..='9' | '.' | '_' | '-' => c,
            _ => '_',
        })
        .collect()
}

/// 64-bit FNV-1a.
pub(crate) fn fnv1a64(bytes: &[u8]) -> u64 {
    const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    bytes.iter().fold(OFFSET_BASIS, |hash, &b| {
        (hash ^ u64::from(b)).wrapping_mul(PRIME)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a64_matches_reference_vectors() {
        assert_eq!(fnv1a64(b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a64(b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x85944171f73967e8);
    }

    #[test]
    fn body_is_sorted_and_canonical() {
        let mut params = Params::new();
        params.insert("cells".into(), ParamValue::Int(8));
        params.insert("G".into(), ParamValue::Float(1e-4));
        let body = config_body("mms1d_gong", "mpm", 0, &params);
        assert_eq!(
            body,
            "benchmark: mms1d_gong\nmethod: mpm\noutput_every: 0\nparams:\n  G: 0.0001\n  cells: 8\n"
        );
        assert!(config_yaml("exp", &body).starts_with("experiment: exp\nbenchmark:"));
    }

    #[test]
    fn ids_list_axes_in_order_and_replace_odd_characters() {
        let g = ParamValue::Float(0.1);
        let tag = ParamValue::Str("a b/c".into());
        let points = ParamValue::List(vec![-0.5, 1.0]);
        let id = run_id("mpm", &[("G", &g), ("tag", &tag), ("x", &points)], "body");
        let hash = format!("{:012x}", fnv1a64(b"body") >> 16);
        assert_eq!(id, format!("mpm-G0.1-taga_b_c-x-0.5_1.0-{hash}"));
    }
}
