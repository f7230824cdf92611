//! Parameter values as they come out of an experiment file, shared by the experiment
//! schema (which validates them) and the benchmarks (which consume them).

use std::collections::BTreeMap;
use std::fmt;

/// One scalar parameter value. Integers stay integers so that `cells: 8` and `cells: 8.0`
/// are told apart by validation and print the way the user wrote them.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Int(i64),
    Float(f64),
    Str(String),
    /// Finite reals, e.g. the coordinates of a given point set.
    List(Vec<f64>),
}

impl ParamValue {
    /// The value as a real number; integers convert exactly up to 2^53.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            ParamValue::Int(i) => Some(*i as f64),
            ParamValue::Float(x) => Some(*x),
            _ => None,
        }
    }

    pub fn as_i64(&self) -> Option<i64> {
        match self {
            ParamValue::Int(i) => Some(*i),
            _ => None,
        }
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            ParamValue::Str(s) => Some(s),
            _ => None,
        }
    }

    pub fn as_list(&self) -> Option<&[f64]> {
        match self {
            ParamValue::List(values) => Some(values),
            _ => None,
        }
    }

    /// Name of the value's type, for error messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            ParamValue::Int(_) => "integer",
            ParamValue::Float(_) => "number",
            ParamValue::Str(_) => "string",
            ParamValue::List(_) => "list",
        }
    }
}

/// Canonical text: integers in decimal, floats in Rust's shortest round-trip form
/// (always with a `.` or exponent), strings verbatim, lists as `[a, b]` of such floats. Run
/// ids hash this text, so it must never change for a given value.
impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Int(i) => write!(f, "{i}"),
            ParamValue::Float(x) => write!(f, "{x:?}"),
            ParamValue::Str(s) => f.write_str(s),
            ParamValue::List(values) => {
                let items: Vec<String> = values.iter().map(|x| format!("{x:?}")).collect();
                write!(f, "[{}]", items.join(", "))
            }
        }
    }
}

/// Resolved parameters of one run, ordered by key so every listing is canonical.
pub type Params = BTreeMap<String, ParamValue>;

/// A parameter that failed a benchmark's own checks; the experiment layer turns it into an
/// error located at the offending key in the YAML file.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub key: String,
    pub message: String,
}

impl ParamError {
    pub fn new(key: &str, message: impl Into<String>) -> Self {
        ParamError {
            key: key.to_string(),
            message: message.into(),
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.key, self.message)
    }
}

/// Typed access to resolved parameters. Validation has already run when these are called,
/// so a missing or mistyped key is reported as an error rather than a panic.
pub fn get_f64(params: &Params, key: &str) -> Result<f64, ParamError> {
    params
        .get(key)
        .and_then(ParamValue::as_f64)
        .ok_or_else(|| ParamError::new(key, "missing or not a number"))
}

pub fn get_str<'a>(params: &'a Params, key: &str) -> Result<&'a str, ParamError> {
    params
        .get(key)
        .and_then(ParamValue::as_str)
        .ok_or_else(|| ParamError::new(key, "missing or not text"))
}

pub fn get_list<'a>(params: &'a Params, key: &str) -> Result<&'a [f64], ParamError> {
    params
        .get(key)
        .and_then(ParamValue::as_list)
        .ok_or_else(|| ParamError::new(key, "missing or not a list of numbers"))
}

pub fn get_usize(params: &Params, key: &str) -> Result<usize, ParamError> {
    params
        .get(key)
        .and_then(ParamValue::as_i64)
        .and_then(|i| usize::try_from(i).ok())
        .ok_or_else(|| ParamError::new(key, "missing or not a non-negative integer"))
}
