//! Experiment files: probe histories and errors tables.

use super::*;

const MOLINOS: &str = "\
name: molinos
benchmark: andersen_block
params: {t_end: 1.0}
matrix:
  - {method: [mpm], placement: [gauss]}
  - {method: [ugimp], placement: [centres]}
figures:
  - {kind: history, probe: top_displacement, by: method}
tables:
  - {kind: errors, field: velocity, norm: rms}
";

#[test]
fn history_figures_and_errors_tables_are_read() {
    let exp = parse(MOLINOS).unwrap();
    assert_eq!(exp.figures[0].kind, FigureKind::History);
    assert_eq!(exp.figures[0].probe.as_deref(), Some("top_displacement"));
    assert_eq!(
        exp.tables[0].measure,
        Some(("velocity".to_string(), "rms".to_string()))
    );
    assert_eq!(exp.runs.len(), 2);
}

#[test]
fn a_history_figure_needs_a_probe() {
    let text = MOLINOS.replace("probe: top_displacement, ", "");
    check(
        &error(&text),
        8,
        5,
        "figures[0].probe",
        "needs 'probe'",
        &[],
    );
}

#[test]
fn an_errors_table_needs_a_known_field() {
    let text = MOLINOS.replace("field: velocity, ", "");
    check(
        &error(&text),
        10,
        5,
        "tables[0].field",
        "needs 'field'",
        &["velocity", "stress"],
    );
    let text = MOLINOS.replace("field: velocity", "field: speed");
    check(
        &error(&text),
        10,
        27,
        "tables[0].field",
        "speed",
        &["velocity"],
    );
}

#[test]
fn probes_tables_are_read_with_their_window() {
    let text = MOLINOS.replace(
        "  - {kind: errors, field: velocity, norm: rms}",
        "  - {kind: probes, probe: top_displacement, after: 10.0, tolerance: 0.05}",
    );
    let exp = parse(&text).unwrap();
    let window = exp.tables[0].probe.as_ref().unwrap();
    assert_eq!(window.name, "top_displacement");
    assert_eq!((window.after, window.tolerance), (10.0, 0.05));
    let text = MOLINOS.replace(
        "  - {kind: errors, field: velocity, norm: rms}",
        "  - {kind: probes, probe: top_displacement, tolerance: 0.05}",
    );
    assert_eq!(
        parse(&text).unwrap().tables[0]
            .probe
            .as_ref()
            .unwrap()
            .after,
        0.0
    );
}

#[test]
fn a_probes_table_needs_a_probe_and_a_positive_tolerance() {
    let table =
        |entry: &str| MOLINOS.replace("  - {kind: errors, field: velocity, norm: rms}", entry);
    let text = table("  - {kind: probes, tolerance: 0.05}");
    check(
        &error(&text),
        10,
        5,
        "tables[0].probe",
        "needs 'probe'",
        &[],
    );
    let text = table("  - {kind: probes, probe: top_displacement}");
    check(
        &error(&text),
        10,
        5,
        "tables[0].tolerance",
        "needs 'tolerance'",
        &[],
    );
    let text = table("  - {kind: probes, probe: top_displacement, tolerance: -1.0}");
    check(&error(&text), 10, 56, "tables[0].tolerance", "> 0", &[]);
    let text =
        table("  - {kind: probes, probe: top_displacement, tolerance: 1.0, field: velocity}");
    let e = error(&text);
    assert_eq!(e.field, "tables[0].field", "{e}");
}

#[test]
fn gauss_placement_is_refused_with_particle_domains() {
    let text = MOLINOS.replace("placement: [centres]", "placement: [gauss]");
    check(
        &error(&text),
        6,
        35,
        "matrix[1].placement[0]",
        "ugimp takes the seed lattice's sub-cells as particle domains",
        &[],
    );
}

/// MOLINOS with a field map after its history figure (line 9).
fn with_map(entry: &str) -> String {
    edited_in(
        MOLINOS,
        "by: method}\n",
        &format!("by: method}}\n  - {entry}\n"),
    )
}

/// Line 9's column of `text` in `yaml`, 1-based.
fn column_in_line_9(yaml: &str, text: &str) -> usize {
    yaml.lines().nth(8).unwrap().find(text).unwrap() + 1
}

#[test]
fn field_maps_are_read_with_their_field_and_axes() {
    let text = with_map(
        "{kind: field_map, field: stress_yy, by: [method, placement], title: \"Molinos, Fig 11\"}",
    );
    let exp = parse(&text).unwrap();
    let map = &exp.figures[1];
    assert_eq!(map.kind, FigureKind::FieldMap);
    assert_eq!(map.by, ["method", "placement"]);
    assert_eq!(
        map.map,
        Some(FieldMapSpec {
            field: "stress_yy".into(),
        })
    );
    assert_eq!(map.title.as_deref(), Some("Molinos, Fig 11"));
    assert_eq!(exp.figures[0].map, None);
    let untitled = parse(&with_map("{kind: field_map, field: density}")).unwrap();
    assert_eq!(untitled.figures[1].title, None);
}

#[test]
fn a_field_map_needs_a_field_its_runs_record() {
    let text = with_map("{kind: field_map, field: stress_zz}");
    check(
        &error(&text),
        9,
        column_in_line_9(&text, "stress_zz"),
        "figures[1].field",
        "unknown map field 'stress_zz'",
        &["stress_yy", "displacement_y", "velocity_x", "density"],
    );
    let text = with_map("{kind: field_map, by: method}");
    check(
        &error(&text),
        9,
        5,
        "figures[1].field",
        "a field_map figure needs 'field'",
        &["stress_xx", "stress_yy", "stress_xy"],
    );
    // The fields are those of the benchmark's kind: an element-wise fit has no stress.
    let text = edited_in(
        ELEMENTS,
        "{kind: reconstruction, method: tls_fixed}",
        "{kind: field_map, field: stress_yy}",
    );
    let e = error(&text);
    assert_eq!(e.field, "figures[0].field", "{e}");
    assert_eq!(e.valid, ["reconstructed", "error"], "{e}");
    let text = edited_in(
        ELEMENTS,
        "{kind: reconstruction, method: tls_fixed}",
        "{kind: field_map, field: error, by: [method]}",
    );
    assert!(parse(&text).is_ok());
}

#[test]
fn field_maps_suit_2d_kinds_and_keep_their_keys() {
    // Nodal reconstructions are 1D: nothing to map.
    let e = error(&edited_in(
        RECONSTRUCTION,
        "{kind: reconstruction, method: mls_linear}",
        "{kind: field_map, field: u}",
    ));
    assert_eq!(e.field, "figures[0].kind", "{e}");
    assert!(
        e.message
            .contains("a field_map figure needs data that nodal reconstruction benchmarks"),
        "{e}"
    );
    assert!(!e.valid.contains(&"field_map".to_string()), "{e}");
    // `field` belongs to field maps.
    let text = edited_in(MOLINOS, "by: method}", "by: method, field: density}");
    check(
        &error(&text),
        8,
        text.lines().nth(7).unwrap().find("field").unwrap() + 1,
        "figures[0].field",
        "'field' applies to field_map figures only",
        &[],
    );
    let e = error(&with_map("{kind: field_map, field: density, norm: l2}"));
    assert_eq!(e.field, "figures[1].norm", "{e}");
    assert!(
        e.message.contains("applies to convergence figures only"),
        "{e}"
    );
}
