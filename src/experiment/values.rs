//! Scalar values: the kind each settable key takes, and the normalisation of what the file
//! wrote into the canonical `ParamValue` that run ids hash (`G: 1` and `G: 1.0` are one run).

use crate::benchmarks::{self, BenchmarkInfo, BenchmarkKind, ParamKind};
use crate::params::ParamValue;
use crate::{methods, reconstruction_methods, reference, shape_methods};

use super::error::ConfigError;
use super::yaml::{child_field, item_field, Entry, Node, NodeKind};

/// The key that selects the method; settable like a benchmark parameter.
pub(crate) const METHOD_KEY: &str = "method";

/// Most numbers a list parameter (the `points` of a reconstruction) may hold: 100,000 points
/// is far more than a reconstruction study needs, and well within what the YAML reader takes.
pub const MAX_LIST_VALUES: usize = 100_000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ValueKind {
    Param(ParamKind),
    /// A method from the catalogue that serves this kind of benchmark.
    Method(BenchmarkKind),
}

/// The methods a kind of benchmark accepts: MPM presets and reference solvers for
/// simulations (which benchmark a reference solver solves is checked per run), the
/// element-wise reconstruction methods for the element-wise benchmark, the local ones for the
/// other reconstruction benchmarks, the grid bases for shape-function evaluation.
pub(crate) fn method_names(kind: BenchmarkKind) -> Vec<&'static str> {
    if kind.steps() {
        let mut names = methods::PRESETS.names();
        names.extend(reference::METHODS.names());
        return names;
    }
    if kind == BenchmarkKind::ShapeFunctions {
        return shape_methods::METHODS.names();
    }
    let elementwise = kind == BenchmarkKind::Elementwise;
    reconstruction_methods::METHODS
        .entries
        .iter()
        .filter(|m| m.is_elementwise() == elementwise)
        .map(|m| m.name)
        .collect()
}

/// The kind of a key of `params` or `matrix`: a parameter of the benchmark or the method.
/// Any other key is an error listing the valid ones.
pub(crate) fn settable_kind(
    info: &BenchmarkInfo,
    entry: &Entry,
    parent: &str,
) -> Result<ValueKind, ConfigError> {
    if entry.key == METHOD_KEY {
        return Ok(ValueKind::Method(info.kind));
    }
    let (method_params, limits) = if info.kind.steps() {
        (methods::METHOD_PARAMS, benchmarks::LIMIT_PARAMS)
    } else {
        (&[][..], &[][..])
    };
    let settable = || info.params.iter().chain(method_params).chain(limits);
    match settable().find(|p| p.key == entry.key) {
        Some(p) => Ok(ValueKind::Param(p.kind)),
        None => {
            let valid = settable().map(|p| p.key).chain([METHOD_KEY]);
            Err(ConfigError::at(
                entry.key_pos,
                child_field(parent, entry.key),
                format!("unknown parameter '{}' for {}", entry.key, info.name),
            )
            .with_valid(valid))
        }
    }
}

pub(crate) fn normalize(
    kind: ValueKind,
    node: &Node,
    field: &str,
) -> Result<ParamValue, ConfigError> {
    match kind {
        ValueKind::Method(kind) => {
            choice(node, field, "method", &method_names(kind)).map(ParamValue::Str)
        }
        ValueKind::Param(ParamKind::Real) => finite(node, field).map(ParamValue::Float),
        ValueKind::Param(ParamKind::PositiveReal) => positive(node, field).map(ParamValue::Float),
        ValueKind::Param(ParamKind::PositiveInt) => positive_int(node, field).map(ParamValue::Int),
        ValueKind::Param(ParamKind::Choice(names)) => {
            choice(node, field, "value", names).map(ParamValue::Str)
        }
        ValueKind::Param(ParamKind::RealList) => real_list(node, field).map(ParamValue::List),
    }
}

/// A non-empty list of at most `MAX_LIST_VALUES` finite numbers; a bad element is reported at
/// its own position.
fn real_list(node: &Node, field: &str) -> Result<Vec<f64>, ConfigError> {
    const EXPECTED: &str = "a non-empty list of finite numbers";
    match &node.kind {
        NodeKind::List(items) if items.len() > MAX_LIST_VALUES => Err(ConfigError::at(
            node.pos,
            field,
            format!(
                "the list holds {} numbers; at most {MAX_LIST_VALUES} are accepted",
                items.len()
            ),
        )),
        NodeKind::List(items) if !items.is_empty() => items
            .iter()
            .enumerate()
            .map(|(i, item)| finite(item, &item_field(field, i)))
            .collect(),
        _ => Err(node.expected(field, EXPECTED)),
    }
}

/// A finite number, integer or not.
pub(crate) fn finite(node: &Node, field: &str) -> Result<f64, ConfigError> {
    real_where(node, field, "a finite number", |_| true)
}

/// A finite number > 0.
pub(crate) fn positive(node: &Node, field: &str) -> Result<f64, ConfigError> {
    real_where(node, field, "a finite number > 0", |x| x > 0.0)
}

fn real_where(
    node: &Node,
    field: &str,
    expected: &str,
    accept: impl Fn(f64) -> bool,
) -> Result<f64, ConfigError> {
    let value = match node.kind {
        NodeKind::Int(i) => Some(i as f64),
        NodeKind::Float(x) if x.is_finite() => Some(x),
        _ => None,
    };
    match value {
        // Adding 0.0 turns -0.0 into 0.0, so both spellings give the same run.
        Some(x) if accept(x) => Ok(x + 0.0),
        _ => Err(node.expected(field, expected)),
    }
}

/// An integer >= 1; `8.0` is rejected too, since a count written as a real is likely a slip.
pub(crate) fn positive_int(node: &Node, field: &str) -> Result<i64, ConfigError> {
    match node.kind {
        NodeKind::Int(i) if i >= 1 => i64::try_from(i)
            .map_err(|_| node.expected(field, "an integer >= 1 that fits in 64 bits")),
        _ => Err(node.expected(field, "an integer >= 1")),
    }
}

/// Text that must be one of `valid`; `what` names the thing chosen, for the message.
pub(crate) fn choice(
    node: &Node,
    field: &str,
    what: &str,
    valid: &[&str],
) -> Result<String, ConfigError> {
    pick(node, field, what, valid, |v| v).map(|v| v.to_string())
}

/// The option whose name the node's text is.
pub(crate) fn pick<'o, T>(
    node: &Node,
    field: &str,
    what: &str,
    options: &'o [T],
    name: impl Fn(&T) -> &str,
) -> Result<&'o T, ConfigError> {
    let names = || options.iter().map(&name).collect::<Vec<_>>();
    let text = node.as_text(field).map_err(|e| e.with_valid(names()))?;
    options.iter().find(|o| name(o) == text).ok_or_else(|| {
        ConfigError::at(node.pos, field, format!("unknown {what} '{text}'")).with_valid(names())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::yaml::parse_tree;

    /// The value of `v: ...` as a node.
    fn node(yaml_value: &str) -> Node {
        let tree = parse_tree(&format!("v: {yaml_value}")).unwrap();
        let entries = tree.entries("").unwrap();
        entries[0].value.clone()
    }

    fn norm(kind: ParamKind, yaml_value: &str) -> Result<ParamValue, ConfigError> {
        normalize(ValueKind::Param(kind), &node(yaml_value), "params.v")
    }

    #[test]
    fn reals_normalise_to_floats() {
        assert_eq!(norm(ParamKind::Real, "1"), Ok(ParamValue::Float(1.0)));
        assert_eq!(norm(ParamKind::Real, "1.0"), Ok(ParamValue::Float(1.0)));
        assert_eq!(norm(ParamKind::Real, "-0.0").unwrap().to_string(), "0.0");
        assert_eq!(
            norm(ParamKind::PositiveReal, "1.0e7"),
            Ok(ParamValue::Float(1e7))
        );
        for bad in [
            ".nan", ".inf", "-.inf", "1e999", "'1.0'", "[1]", "true", "~",
        ] {
            let e = norm(ParamKind::Real, bad).unwrap_err();
            assert!(e.message.contains("expected a finite number"), "{bad}: {e}");
            assert_eq!((e.line, e.column), (1, 4));
        }
        for bad in ["0", "-2.5", "0.0"] {
            let e = norm(ParamKind::PositiveReal, bad).unwrap_err();
            assert!(e.message.contains("> 0"), "{bad}: {e}");
        }
    }

    #[test]
    fn counts_must_be_integers_of_at_least_one() {
        assert_eq!(norm(ParamKind::PositiveInt, "8"), Ok(ParamValue::Int(8)));
        for bad in [
            "8.5",
            "8.0",
            "0",
            "-3",
            "'8'",
            "1e3",
            "18446744073709551615",
        ] {
            let e = norm(ParamKind::PositiveInt, bad).unwrap_err();
            assert!(e.message.contains("expected an integer"), "{bad}: {e}");
        }
    }

    #[test]
    fn methods_are_checked_against_the_presets() {
        let simulation = ValueKind::Method(BenchmarkKind::Simulation);
        let ok = normalize(simulation, &node("mpm"), "params.method");
        assert_eq!(ok, Ok(ParamValue::Str("mpm".into())));
        let e = normalize(simulation, &node("flip"), "params.method").unwrap_err();
        assert!(e.message.contains("unknown method 'flip'"));
        assert!(e.valid.contains(&"mpm".to_string()));
        let e = normalize(simulation, &node("3"), "params.method").unwrap_err();
        assert!(e.valid.contains(&"mpm".to_string()), "{e}");
    }

    #[test]
    fn reconstruction_benchmarks_take_reconstruction_methods() {
        let kind = ValueKind::Method(BenchmarkKind::Reconstruction);
        let ok = normalize(kind, &node("shepard"), "params.method");
        assert_eq!(ok, Ok(ParamValue::Str("shepard".into())));
        let e = normalize(kind, &node("mpm"), "params.method").unwrap_err();
        assert!(e.valid.contains(&"imls_quadratic".to_string()), "{e}");
        let e = normalize(kind, &node("tls_fixed"), "params.method").unwrap_err();
        assert!(!e.valid.contains(&"tls_fixed".to_string()), "{e}");
        let elements = ValueKind::Method(BenchmarkKind::Elementwise);
        let ok = normalize(elements, &node("tls_fitted"), "params.method");
        assert_eq!(ok, Ok(ParamValue::Str("tls_fitted".into())));
        let e = normalize(elements, &node("shepard"), "params.method").unwrap_err();
        assert_eq!(e.valid, ["tls_fixed", "tls_fitted"]);
        let bases = ValueKind::Method(BenchmarkKind::ShapeFunctions);
        let ok = normalize(bases, &node("lme"), "params.method");
        assert_eq!(ok, Ok(ParamValue::Str("lme".into())));
        let e = normalize(bases, &node("mpm"), "params.method").unwrap_err();
        assert_eq!(
            e.valid,
            ["lme", "linear", "quadratic_bspline", "cubic_bspline"]
        );
    }

    #[test]
    fn choices_and_lists() {
        let kind = ParamKind::Choice(&["equal", "random"]);
        assert_eq!(norm(kind, "random"), Ok(ParamValue::Str("random".into())));
        let e = norm(kind, "rand").unwrap_err();
        assert_eq!(
            e.to_string(),
            ":1:4: field 'params.v': unknown value 'rand' (valid: equal, random)"
        );
        assert_eq!(
            norm(ParamKind::RealList, "[-1, 0.5]"),
            Ok(ParamValue::List(vec![-1.0, 0.5]))
        );
        let e = norm(ParamKind::RealList, "[0.1, x]").unwrap_err();
        assert_eq!((e.field.as_str(), e.column), ("params.v[1]", 10));
        for bad in ["[]", "0.5", "x"] {
            let e = norm(ParamKind::RealList, bad).unwrap_err();
            assert!(e.message.contains("non-empty list"), "{bad}: {e}");
        }
    }
}
