//! `rotor-twin modes --thermal` (issue 18): the threshold with the adiabatic thermal film beside
//! the isothermal one, and the refusals. Machine: the built-in default, reading (B) (Ø63 body,
//! isothermal threshold 9,291 rpm), the one `modes` runs without `--config`.

mod common;
use common::run_cli;

use serde_json::Value;

/// The default machine over 6,000–12,000 rpm: the report's `thermal` block carries the thermal
/// threshold of tests/thermal_threshold.rs (the same search: the figure to the bisection's
/// 0.5 rpm), the isothermal one equal to the report's own, and the films at the threshold.
#[test]
fn modes_thermal_json_for_the_builtin_machine() {
    let (ok, out, err) = run_cli(&[
        "modes",
        "--json",
        "--thermal",
        "--from-rpm",
        "6000",
        "--to-rpm",
        "12000",
        "--step-rpm",
        "500",
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let t = &v["thermal"];
    let f = |k: &str| t[k].as_f64().unwrap_or_else(|| panic!("thermal.{k}: {t}"));
    let (thermal, iso) = (
        f("threshold_speed_rpm"),
        f("isothermal_threshold_speed_rpm"),
    );
    assert_eq!(iso, v["threshold_speed_rpm"].as_f64().unwrap());
    // measured 9,363.3 rpm (tests/thermal_threshold.rs, README "Thermal film"); isothermal
    // 9,291.1 rpm (README "Two readings of the seed")
    assert!((thermal - THERMAL_B_RPM).abs() < 1.0, "thermal {thermal}");
    assert!((iso - 9291.1).abs() < 1.0, "isothermal {iso}");
    assert!((f("change_rpm") - (thermal - iso)).abs() < 1e-9);
    assert_eq!(f("supply_temperature_c"), 40.0);
    assert_eq!(f("specific_heat_j_per_kg_k"), 1820.0);
    let bearings = t["bearings"].as_array().unwrap();
    assert_eq!(bearings.len(), 2);
    for b in bearings {
        // the films at the threshold heat a few kelvin (peak 48.1 °C measured): within 1 K
        let max = b["max_temperature_c"].as_f64().unwrap();
        assert!((max - 48.1).abs() < 1.0, "{b}");
    }
}

/// The thermal threshold of reading (B) measured by tests/thermal_threshold.rs (rpm).
const THERMAL_B_RPM: f64 = 9363.3;

/// The thermal options need `--thermal`, `--thermal` refuses the fluid-inertia options, a
/// supply outside the MDM table's 10–120 °C is refused naming the range, and so is a
/// one-point `--viscosity-points`.
#[test]
fn modes_thermal_refusals() {
    let (ok, _, err) = run_cli(&["modes", "--thermal", "--viscosity-points", "40:0.889"]);
    assert!(!ok && err.contains("exactly two"), "{err}");
    let (ok, _, err) = run_cli(&["modes", "--supply-temperature-c", "50"]);
    assert!(!ok && err.contains("--thermal"), "{err}");
    let (ok, _, err) = run_cli(&["modes", "--thermal", "--fluid-inertia"]);
    assert!(!ok && err.contains("--fluid-inertia"), "{err}");
    let (ok, _, err) = run_cli(&["modes", "--thermal", "--supply-temperature-c", "150"]);
    assert!(!ok && err.contains("10–120 °C"), "{err}");
}

/// `--viscosity-points` replaces the machine file's law: Walther's law through 0.888889 mm²/s
/// at 40 °C and 0.888888 at 80 °C with the bearings' 900 kg/m³ is flat to 1.2e-6 and 1e-6 off
/// the file's µ₀ = 0.8 mPa·s, so the thermal threshold is the isothermal one to the threshold's
/// sensitivity (|d ln N/d ln µ| 0.12, README "Thermal film") times 2e-6: asserted to 1e-5.
#[test]
fn modes_thermal_with_a_flat_walther_law_gives_the_isothermal_threshold() {
    let (ok, out, err) = run_cli(&[
        "modes",
        "--json",
        "--thermal",
        "--viscosity-points",
        "40:0.888889,80:0.888888",
        "--from-rpm",
        "6000",
        "--to-rpm",
        "12000",
        "--step-rpm",
        "500",
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let thermal = v["thermal"]["threshold_speed_rpm"].as_f64().unwrap();
    let iso = v["threshold_speed_rpm"].as_f64().unwrap();
    assert!((thermal - iso).abs() < 1e-5 * iso, "{thermal} vs {iso}");
}
