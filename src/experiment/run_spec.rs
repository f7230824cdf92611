//! How a run presents itself: as JSON (for tools) and as one line (for `mpmlab expand`).

use std::fmt::Write;

use serde_json::{json, Map, Value};

use crate::params::{ParamValue, Params};

use super::values::METHOD_KEY;
use crate::run_spec::RunSpec;

impl RunSpec {
    pub fn to_json(&self) -> Value {
        json!({
            "run_id": self.run_id,
            "experiment": self.experiment,
            "benchmark": self.benchmark,
            "method": self.method,
            "axes": params_json(&self.axes),
            "params": params_json(&self.params),
            "output_every": self.output_every,
        })
    }

    /// `run_id  benchmark method key=value ...` over the non-method axes.
    pub fn describe(&self) -> String {
        let mut line = format!("{}  {} {}", self.run_id, self.benchmark, self.method);
        for (key, value) in self.axes.iter().filter(|(k, _)| k.as_str() != METHOD_KEY) {
            // Writing to a String cannot fail.
            let _ = write!(line, " {key}={value}");
        }
        line
    }
}

fn params_json(params: &Params) -> Value {
    let map: Map<String, Value> = params
        .iter()
        .map(|(key, value)| {
            let value = match value {
                ParamValue::Int(i) => Value::from(*i),
                ParamValue::Float(x) => Value::from(*x),
                ParamValue::Str(s) => Value::from(s.as_str()),
                ParamValue::List(values) => Value::from(values.clone()),
            };
            (key.clone(), value)
        })
        .collect();
    Value::Object(map)
}
