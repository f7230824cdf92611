//! `reference`: the run every other run of a 1D simulation experiment is compared with at the
//! final time (e.g. ULFEM on the finest mesh), named by its matrix-axis values (`cells`
//! included).

use crate::benchmarks::{BenchmarkInfo, BenchmarkKind};
use crate::params::Params;

use super::error::ConfigError;
use super::resolved::ResolvedRun;
use super::select::listed;
use super::space::ParamSpace;
use super::values::normalize;
use super::yaml::{child_field, Entry};
use crate::run_spec::RunSpec;

const FIELD: &str = "reference";

/// The axis values of the reference run, if the file names one.
pub(crate) fn read(
    section: Option<&Entry>,
    space: &ParamSpace,
    info: &BenchmarkInfo,
    kind: BenchmarkKind,
) -> Result<Option<Params>, ConfigError> {
    let Some(section) = section else {
        return Ok(None);
    };
    if kind != BenchmarkKind::Simulation || info.dim() != 1 {
        return Err(ConfigError::at(
            section.key_pos,
            FIELD,
            format!(
                "a reference run compares fields along a bar; {} is not a 1D simulation",
                info.name
            ),
        ));
    }
    let entries = section.value.entries(FIELD)?;
    let mut select = Params::new();
    for e in &entries {
        let field = child_field(FIELD, e.key);
        let axis = space
            .axes()
            .into_iter()
            .find(|a| a.key == e.key)
            .ok_or_else(|| {
                ConfigError::at(
                    e.key_pos,
                    &field,
                    format!("'{}' is not a matrix axis", e.key),
                )
                .with_valid(space.axes().iter().map(|a| a.key.as_str()))
            })?;
        if listed(axis.kind, e.value).is_some() {
            return Err(ConfigError::at(
                e.value.pos,
                field,
                format!(
                    "the reference is one run: give one value of '{}', not a list",
                    e.key
                ),
            )
            .with_valid(space.axis_values(e.key)));
        }
        let value = normalize(axis.kind, e.value, &field)?;
        select.insert(e.key.to_string(), value);
    }
    if select.is_empty() {
        return Err(ConfigError::at(
            section.value.pos,
            FIELD,
            "name the reference run by its matrix-axis values, e.g. {method: ulfem, cells: 1280}",
        )
        .with_valid(space.axes().iter().map(|a| a.key.as_str())));
    }
    Ok(Some(select))
}

/// The reference selector must pick exactly one run of the expanded matrix.
pub(crate) fn check_unique(
    select: &Params,
    runs: &[ResolvedRun],
    section: &Entry,
) -> Result<(), ConfigError> {
    let matching: Vec<&RunSpec> = runs
        .iter()
        .map(|run| &run.spec)
        .filter(|run| select.iter().all(|(k, v)| run.axes.get(k) == Some(v)))
        .collect();
    if matching.len() == 1 {
        return Ok(());
    }
    let ids: Vec<&str> = matching.iter().map(|r| r.run_id.as_str()).collect();
    Err(ConfigError::at(
        section.value.pos,
        FIELD,
        format!(
            "the reference must be one run; these values select {} ({}); add axis values",
            matching.len(),
            ids.join(", ")
        ),
    ))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::experiment::parse;

    const BAR: &str = "\
name: ref
benchmark: vibrating_bar
params: {exact: none, ppc: 2}
matrix:
  method: [mpm_musl, ulfem]
  cells: [5, 10]
reference: REFERENCE
";

    #[test]
    fn the_reference_takes_one_value_per_axis() {
        let read = |reference: &str| parse(&BAR.replace("REFERENCE", reference), Path::new("r"));
        let exp = read("{method: ulfem, cells: 10}").unwrap();
        assert_eq!(exp.reference.unwrap()["method"].to_string(), "ulfem");
        let e = read("{method: [ulfem], cells: 10}").unwrap_err();
        assert_eq!(
            e.to_string(),
            "r:7:21: field 'reference.method': the reference is one run: give one value of \
             'method', not a list (valid: mpm_musl, ulfem)"
        );
    }
}
