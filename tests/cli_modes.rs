//! The `rotor-twin modes` command-line contract: JSON keys, plot file, errors.

mod common;
use common::run_cli;

use serde_json::Value;

/// The built-in microturbine: the contracted keys, a Campbell diagram, and the linear threshold
/// where the seed puts it for the linear model: ABOVE the rated 9,000 rpm ("a linear model predicts
/// stable operation" there; reading (B), the Ø63 body, the default since session 15:
/// config/orc_microturbine_100kw.yaml, 9,291 rpm in README "The microturbine"), with a
/// half-frequency whirl (0.488 there).
#[test]
fn modes_json_and_plot_for_the_builtin_machine() {
    let svg = std::env::temp_dir().join(format!("rotor-twin-campbell-{}.svg", std::process::id()));
    let (ok, out, err) = run_cli(&[
        "modes",
        "--json",
        "--from-rpm",
        "2000",
        "--to-rpm",
        "12000",
        "--step-rpm",
        "500",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    for key in [
        "critical_speeds_rpm",
        "threshold_speed_rpm",
        "whirl_ratio_at_threshold",
        "bearing_loads_n",
        "campbell",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    let campbell = v["campbell"].as_array().unwrap();
    assert_eq!(campbell.len(), 21);
    let mode = &campbell[0]["modes"][0];
    for key in ["frequency_hz", "log_dec", "direction"] {
        assert!(mode.get(key).is_some(), "mode lacks {key}");
    }
    let threshold = v["threshold_speed_rpm"].as_f64().unwrap();
    assert!(
        (9000.0..9400.0).contains(&threshold),
        "threshold {threshold}: reading (B) is linear-stable at the rated 9,000 rpm"
    );
    let ratio = v["whirl_ratio_at_threshold"].as_f64().unwrap();
    assert!((0.45..0.5).contains(&ratio), "whirl ratio {ratio}");
    let loads: f64 = v["bearing_loads_n"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f[1].as_f64().unwrap())
        .sum();
    assert!(
        (loads + 56.0 * 9.81).abs() < 0.01 * 56.0 * 9.81,
        "Σ loads {loads}"
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("Campbell diagram"));
    std::fs::remove_file(svg).ok();
}

#[test]
fn bad_modes_input_is_named() {
    for (args, word) in [
        (vec!["modes", "--from-rpm", "-5"], "--from-rpm"),
        (
            vec!["modes", "--from-rpm", "5000", "--to-rpm", "4000"],
            "--to-rpm",
        ),
        (vec!["modes", "--step-rpm", "0.001"], "--step-rpm"),
        (
            vec!["modes", "--config", "/nonexistent.yaml"],
            "/nonexistent.yaml",
        ),
    ] {
        let (ok, _, err) = run_cli(&args);
        assert!(!ok, "{args:?} should fail");
        assert!(err.contains(word), "{args:?}: '{err}' does not name {word}");
    }
}
