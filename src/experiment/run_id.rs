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

/// Longest run id. Its files' names add at most `.` and `.h5.tmp-<pid>` (16 bytes with a
/// 32-bit process id), far below the 255 bytes a file name may have.
pub const MAX_RUN_ID_LEN: usize = 120;

/// A list value written longer than this enters the id as `list<length>`: its numbers are in
/// the hash. The committed studies' lists are at most 42 characters long.
const MAX_LIST_TEXT: usize = 48;

/// `<method>-<axis><value>-...-<hash12>` over the non-method axes in file order; a list
/// value is written with `_` between its numbers (`list<length>` when that is longer than
/// `MAX_LIST_TEXT`). Past `MAX_RUN_ID_LEN` the axis values are cut; the hash, of the whole
/// configuration, still tells the runs apart.
pub(crate) fn run_id(method: &str, axes: &[(&str, &ParamValue)], body: &str) -> String {
    let mut id = method.to_string();
    for (key, value) in axes {
        match value {
            ParamValue::List(values) => {
                let items: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
                let text = items.join("_");
                if text.len() > MAX_LIST_TEXT {
                    let _ = write!(id, "-{key}list{}", values.len());
                } else {
                    let _ = write!(id, "-{key}{text}");
                }
            }
            _ => {
                let _ = write!(id, "-{key}{value}");
            }
        }
    }
    // The top 48 bits of the hash: 12 hex digits.
    let hash = format!("-{:012x}", fnv1a64(body.as_bytes()) >> 16);
    // Every character becomes one ASCII byte, so the cut falls between characters.
    let mut id: String = id
        .chars()
        .map(|c| match c {
            'A'..='Z' | 'a'..='z' | '0'..='9' | '.' | '_' | '-' => c,
            _ => '_',
        })
        .collect();
    id.truncate(MAX_RUN_ID_LEN - hash.len());
    id + &hash
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

    #[test]
    fn ids_are_bounded() {
        let hash = format!("{:012x}", fnv1a64(b"body") >> 16);
        // Short lists are written out, long ones by their length.
        let short = ParamValue::List(vec![-0.6666666666666666, 0.0, 0.6666666666666666]);
        let id = run_id("imls", &[("points", &short)], "body");
        assert_eq!(
            id,
            format!("imls-points-0.6666666666666666_0.0_0.6666666666666666-{hash}")
        );
        let long = ParamValue::List((0..40).map(|i| f64::from(i) / 40.0).collect());
        let g = ParamValue::Float(0.1);
        let id = run_id("imls", &[("points", &long), ("G", &g)], "body");
        assert_eq!(id, format!("imls-pointslist40-G0.1-{hash}"));
        // Many axes are cut to the bound, the hash kept.
        let keys: Vec<String> = (0..30).map(|i| format!("key{i}")).collect();
        let axes: Vec<(&str, &ParamValue)> = keys.iter().map(|k| (k.as_str(), &g)).collect();
        let id = run_id("mpm", &axes, "body");
        assert_eq!(id.len(), MAX_RUN_ID_LEN);
        assert!(id.starts_with("mpm-key00.1-key10.1-"), "{id}");
        assert!(id.ends_with(&format!("-{hash}")), "{id}");
    }
}
