//! The `simulate` and `sweep` command-line contracts: JSON keys, plot files, CSV, errors.

mod common;
mod svg_check;
use common::run_cli;

use serde_json::Value;

fn scratch(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("rotor-twin-{name}-{}", std::process::id()))
}

#[test]
fn simulate_json_and_plots() {
    let dir = scratch("plots");
    let (ok, out, err) = run_cli(&[
        "simulate",
        "--speed-rpm",
        "8000",
        "--revs",
        "20",
        "--json",
        "--plot",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    for key in [
        "state",
        "rev_to_rev_orbit_diff",
        "rev_to_rev_pressure_diff",
        "wall_time_s",
        "real_time_factor",
        "bearings",
        "evidence",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["state"], "stable");
    let b = &v["bearings"][0];
    for key in [
        "name",
        "orbit_pp_x_m",
        "orbit_pp_y_m",
        "max_eccentricity_ratio",
        "one_x_amplitude_m",
        "subsync_ratio",
        "subsync_amplitude_m",
        "max_pressure_pa",
    ] {
        assert!(b.get(key).is_some(), "bearing lacks {key}");
    }
    // the built-in machine's bearing names
    assert_eq!(b["name"], "bearing_pulley_end");
    for kind in ["orbit", "spectrum", "pressure"] {
        let f = dir.join(format!("{kind}_bearing_outboard.svg"));
        let text = std::fs::read_to_string(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(text.starts_with("<svg"));
    }
    // the orbit is drawn 1:1 (a circle is a circle), its legend beside the chart
    let orbit = svg_check::read(&dir.join("orbit_bearing_outboard.svg"));
    orbit.assert_texts(&["x (µm)", "y (µm)", "legend", "clearance circle (40 µm)"]);
    let (px_x, px_y) = orbit.px_per_unit();
    assert!(
        (px_x / px_y - 1.0).abs() < 0.005,
        "orbit aspect {px_x} vs {px_y} px/µm"
    );
    orbit.assert_legend_right_of_data();
    // the pressure map: degrees of shaft rotation and of the bearing, a scale in MPa
    let map = svg_check::read(&dir.join("pressure_bearing_outboard.svg"));
    map.assert_texts(&[
        "shaft rotation over the last two revolutions (deg)",
        "bearing angle from +x (deg)",
        "pressure (MPa)",
        // degree ticks, not step numbers
        "700",
        "350",
    ]);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn sweep_writes_csv_and_svg() {
    let dir = scratch("sweep");
    let (ok, out, err) = run_cli(&[
        "sweep",
        "--from-rpm",
        "6000",
        "--to-rpm",
        "7000",
        "--step-rpm",
        "1000",
        "--revs",
        "12",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["points"].as_array().unwrap().len(), 2);
    assert!(v.get("onset_speed_rpm").is_some());
    let csv = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3);
    assert!(csv.starts_with("speed_rpm,state,growth_per_rev"));
    assert!(std::fs::read_to_string(dir.join("sweep.svg"))
        .unwrap()
        .starts_with("<svg"));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_simulation_input_is_named() {
    for (args, word) in [
        (vec!["simulate", "--speed-rpm", "-1"], "speed"),
        (vec!["simulate", "--speed-rpm", "NaN"], "speed"),
        (
            vec![
                "simulate",
                "--speed-rpm",
                "8000",
                "--model",
                "prehistory",
                "--delta",
                "0",
            ],
            "--delta",
        ),
        (
            vec!["simulate", "--speed-rpm", "8000", "--revs", "1"],
            "revolutions",
        ),
        (
            vec!["simulate", "--speed-rpm", "8000", "--steps-per-rev", "5"],
            "steps per revolution",
        ),
        (
            vec!["simulate", "--speed-rpm", "8000", "--grid", "4x4"],
            "grid",
        ),
        (
            vec![
                "sweep",
                "--from-rpm",
                "9000",
                "--to-rpm",
                "8000",
                "--step-rpm",
                "100",
            ],
            "--to-rpm",
        ),
    ] {
        let (ok, out, err) = run_cli(&args);
        assert!(!ok, "{args:?} should fail");
        assert!(err.contains(word), "{args:?}: '{err}' does not name {word}");
        assert!(!out.contains("NaN"));
    }
}
