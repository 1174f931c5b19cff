//! A malformed machine description gives an error naming the file, the field, the value and the
//! rule it breaks; nothing panics.

use rotor_twin::rotor::{ConfigError, MachineDescription, DEFAULT_MACHINE_YAML};

fn error_of(yaml: &str) -> ConfigError {
    MachineDescription::from_yaml(yaml, "machine.yaml").unwrap_err()
}

/// The built-in machine with one line replaced.
fn with(from: &str, to: &str) -> String {
    assert!(
        DEFAULT_MACHINE_YAML.contains(from),
        "fixture line not found: {from}"
    );
    DEFAULT_MACHINE_YAML.replacen(from, to, 1)
}

/// The built-in machine's MDM viscosity table, as both film bearings carry it.
const MDM_TABLE: &str = "        table: {temperatures_c: [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0, 110.0, 120.0],\n                viscosities_pa_s: [1.16888e-3, 1.02439e-3, 0.903011e-3, 0.800000e-3, 0.712838e-3, 0.639124e-3,\n                                   0.575962e-3, 0.520959e-3, 0.472895e-3, 0.431143e-3, 0.394765e-3, 0.362473e-3]}\n";

/// The built-in machine with the first film bearing's MDM table replaced by Walther's two points
/// at 40 and 80 °C (kinematic viscosities `nu_mm2_s`, as YAML text).
fn with_walther(nu_mm2_s: &str) -> String {
    with(
        MDM_TABLE,
        &format!(
            "        temperatures_c: [40.0, 80.0]\n        kinematic_viscosities_mm2_s: {nu_mm2_s}\n"
        ),
    )
}

fn says(e: &ConfigError, field: &str, value: &str, rule: &str) {
    let text = e.to_string();
    assert!(text.starts_with("machine.yaml: "), "{text}");
    assert!(text.contains(field), "'{text}' does not name field {field}");
    assert!(text.contains(value), "'{text}' does not show value {value}");
    assert!(text.contains(rule), "'{text}' does not state rule '{rule}'");
}

#[test]
fn out_of_range_values_are_named_with_field_value_and_rule() {
    says(
        &error_of(&with("outer_diameter_m: 0.063", "outer_diameter_m: -0.063")),
        "shaft[3].outer_diameter_m",
        "-0.063",
        "greater than zero",
    );
    says(
        &error_of(&with(
            "radial_clearance_m: 40.0e-6",
            "radial_clearance_m: 0.0",
        )),
        "bearings[0].radial_clearance_m",
        "0",
        "greater than zero",
    );
    says(
        &error_of(&with(
            "{node: 15, magnitude_g_mm: 140.0",
            "{node: 99, magnitude_g_mm: 140.0",
        )),
        "unbalance[0].node",
        "99",
        "must be a shaft node, 0 to 30",
    );
    says(
        &error_of(&with(
            "material: steel, elements: 22",
            "material: unobtainium, elements: 22",
        )),
        "shaft[3].material",
        "unobtainium",
        "must name an entry of materials",
    );
    says(
        &error_of(&with("viscosity_pa_s: 0.0008\n", "viscosity_pa_s: .nan\n")),
        "bearings[0].lubricant.viscosity_pa_s",
        "NaN",
        "finite",
    );
    // the viscosity–temperature law (issue 12): points, range, agreement at the design point
    says(
        &error_of(&with_walther("[0.60, 0.889]")),
        "bearings[0].lubricant.viscosity_temperature.(law)",
        "[0.6, 0.889]",
        "must fall as the temperature rises",
    );
    says(
        &error_of(&with_walther("[0.95, 0.60]")),
        "bearings[0].lubricant.viscosity_temperature.kinematic_viscosities_mm2_s",
        "[0.95, 0.6]",
        "agree within 1 %",
    );
    says(
        &error_of(&with(
            "design_supply_temperature_c: 40.0",
            "design_supply_temperature_c: 150.0",
        )),
        "bearings[0].lubricant.viscosity_temperature.design_supply_temperature_c",
        "150",
        "inside valid_range_c",
    );
    says(
        &error_of(&with(
            "valid_range_c: [10.0, 120.0]",
            "valid_range_c: [.nan, 120.0]",
        )),
        "bearings[0].lubricant.viscosity_temperature.valid_range_c",
        "NaN",
        "finite",
    );
    // one oil supply reaches every film: a film bearing without a law beside one with a law is
    // refused, not silently left at the machine file's viscosity (each may have its own law)
    says(
        &error_of(&with(
            &format!("      viscosity_temperature:  # as bearing_pulley_end's (one oil supply)\n{MDM_TABLE}        design_supply_temperature_c: 40.0\n        valid_range_c: [10.0, 120.0]\n"),
            "",
        )),
        "bearings[1].lubricant.viscosity_temperature",
        "(missing)",
        "every film bearing needs one",
    );
    // a second bearing with a law of its own is taken (one scale per bearing)
    assert!(MachineDescription::from_yaml(
        &with(
            &format!("(one oil supply)\n{MDM_TABLE}"),
            "(one oil supply)\n        temperatures_c: [40.0, 80.0]\n        kinematic_viscosities_mm2_s: [0.889, 0.50]\n",
        ),
        "own law"
    )
    .is_ok());
    says(
        &error_of(&with(
            "angles_deg: [45.0, 135.0]",
            "angles_deg: [45.0, 225.0]",
        )),
        "probes[0].angles_deg",
        "225",
        "same line",
    );
}

#[test]
fn structural_mistakes_are_named_by_their_path() {
    // a misspelt field
    let e = error_of(&with("rated_speed_rpm: 9000", "rated_speed_rmp: 9000"));
    says(&e, "rated_speed_rmp", "", "unknown field");
    // a word where a number belongs
    let e = error_of(&with("mass_kg: 1.50", "mass_kg: heavy"));
    says(&e, "discs[0].mass_kg", "", "invalid type");
    // a film bearing without its clearance
    let e = error_of(&with("    radial_clearance_m: 40.0e-6\n", ""));
    says(
        &e,
        "bearings[0].radial_clearance_m",
        "(missing)",
        "required for a film bearing",
    );
    // not YAML at all
    let e = error_of("{ this is: [not closed");
    assert!(e.to_string().starts_with("machine.yaml: "), "{e}");
}

#[test]
fn a_missing_file_is_named() {
    let e = MachineDescription::from_file(std::path::Path::new("/nonexistent/machine.yaml"))
        .unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("/nonexistent/machine.yaml") && text.contains("cannot be read"),
        "{text}"
    );
}

/// The bearing entry is parsed into one variant per model: each model's data must be there and
/// nothing another model needs is accepted; a machine the model cannot represent is refused.
#[test]
fn bearing_entries_are_parsed_by_their_model() {
    // a second bearing on the first one's node: one support point cannot hold the tilt
    let e = error_of(&with(
        "    node: 27\n    model: finite",
        "    node: 3\n    model: finite",
    ));
    says(&e, "bearings", "node(s) [3]", "two or more shaft nodes");
    // a short bearing has no grooves
    let e = error_of(&with(
        "    node: 3\n    model: finite",
        "    node: 3\n    model: short\n    grooves: two-axial",
    ));
    says(&e, "bearings[0].grooves", "two-axial", "no grooves");
    // a linear bearing with a negative direct stiffness carries no rotor
    let linear = "    node: 3\n    model: linear\n    stiffness_n_per_m: [[-1.0e8, 0.0], [0.0, 1.0e8]]\n  - name: other\n    node: 4\n    model: rigid\n  - name: unused\n    node: 5\n    model: finite";
    let e = error_of(&with("    node: 3\n    model: finite", linear));
    says(
        &e,
        "bearings[0].stiffness_n_per_m[0][0]",
        "-100000000",
        "greater than zero",
    );
    // a rigid bearing has no flexible support
    let rigid = "    node: 3\n    model: rigid\n    support: {mass_kg: 10.0, stiffness_n_per_m: [[1.0e8, 0.0], [0.0, 1.0e8]]}\n  - name: unused\n    node: 5\n    model: finite";
    let e = error_of(&with("    node: 3\n    model: finite", rigid));
    says(&e, "bearings[0].support", "(given)", "no flexible support");
    // an unknown model is named by serde with the choices
    let e = error_of(&with(
        "    node: 3\n    model: finite",
        "    node: 3\n    model: tilting_pad",
    ));
    says(&e, "bearings[0].model", "", "unknown variant `tilting_pad`");
    // a probe's unit and coupling are names of their own, refused with the choices
    let probe = |unit: &str, coupling: &str| {
        format!("{DEFAULT_MACHINE_YAML}\nproximity_probes:\n  - {{name: px, station: probe_outboard, angle_deg: 45.0, unit: {unit}, coupling: {coupling}}}\n")
    };
    let e = error_of(&probe("mm", "ac"));
    says(&e, "proximity_probes[0].unit", "", "unknown variant `mm`");
    // a linear range that is empty or beyond any probe's reach is named with its value
    let e = error_of(&format!(
        "{DEFAULT_MACHINE_YAML}\nproximity_probes:\n  - {{name: px, station: probe_outboard, angle_deg: 45.0, linear_range: [250.0, 250.0]}}\n"
    ));
    says(
        &e,
        "proximity_probes[0].linear_range",
        "[250.0, 250.0]",
        "two different finite readings",
    );
    let e = error_of(&probe("µm", "AC"));
    says(
        &e,
        "proximity_probes[0].coupling",
        "",
        "unknown variant `AC`",
    );
}
