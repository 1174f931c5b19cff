//! The Campbell diagram read back from its SVG: title, axes with units, a legend for every colour
//! and line, the critical speed marked, and the legend clear of the data (in its own panel, right
//! of every data point).

mod common;
mod svg_check;
use common::run_cli;

#[test]
fn campbell_svg_has_title_axes_legend_clear_of_data_and_critical_speed() {
    let svg_path =
        std::env::temp_dir().join(format!("rotor-twin-campbell-tb-{}.svg", std::process::id()));
    let (ok, _, err) = run_cli(&[
        "modes",
        "--config",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/config/textbook_disc_midspan.yaml"
        ),
        "--to-rpm",
        "6000",
        "--plot",
        svg_path.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let svg = svg_check::read(&svg_path);
    svg.assert_texts(&[
        "Campbell diagram: textbook_disc_midspan",
        "speed (rpm)",
        "damped natural frequency (Hz)",
        "logarithmic decrement (–)",
        "legend",
        "forward whirl",
        "backward whirl",
        "unstable (log dec < 0)",
        "1X running speed",
        "1X",
        "0.5X",
        "forward critical speed",
        // the closed-form critical speed, 1886.3 rpm (tests/rotor_critical_speeds.rs)
        "1886 rpm",
    ]);
    let legend_x = svg.text("legend").unwrap().x;
    // data points are dots of radius 3 px, the legend's swatches 4 px
    let data: Vec<_> = svg.circles.iter().filter(|c| c.2 == 3.0).collect();
    let data_right = data.iter().map(|c| c.0).fold(f64::MIN, f64::max);
    assert!(
        data.len() > 100 && legend_x > data_right + 10.0,
        "legend at x = {legend_x} px, data reach {data_right} px"
    );
    std::fs::remove_file(svg_path).ok();
}

/// The microturbine with the convective film inertia (`--fluid-inertia-full`): its forward
/// modes cross 1X many times near 2,600–3,200 rpm heavily damped; only the crossings with an
/// amplification factor 1/(2ζ) ≥ 2.5 (API 684) are listed and labelled as critical speeds, the
/// others drawn as grey rings and listed apart; the labels (critical speeds, 1X, 0.5X) are
/// clear of one another (they overprinted before).
#[test]
fn campbell_labels_do_not_overprint_with_the_full_film_inertia() {
    let svg_path =
        std::env::temp_dir().join(format!("rotor-twin-campbell-fi-{}.svg", std::process::id()));
    let (ok, out, err) = run_cli(&[
        "modes",
        "--fluid-inertia-full",
        "--from-rpm",
        "1000",
        "--to-rpm",
        "12000",
        "--step-rpm",
        "500",
        "--json",
        "--plot",
        svg_path.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let critical = v["critical_speeds"].as_array().unwrap();
    for c in critical {
        assert!(c["amplification_factor"].as_f64().unwrap() >= 2.5, "{c}");
        assert_eq!(c["critical"].as_bool(), Some(true), "{c}");
    }
    for c in v["critically_damped_crossings"].as_array().unwrap() {
        assert!(c["amplification_factor"].as_f64().unwrap() < 2.5, "{c}");
    }
    let svg = svg_check::read(&svg_path);
    // the chart's labels, not the legend's entries
    let legend_x = svg.text("legend").unwrap().x;
    let labels: Vec<_> = svg
        .texts
        .iter()
        .filter(|t| t.x < legend_x)
        .filter(|t| t.text.ends_with(" rpm") || t.text == "1X" || t.text == "0.5X")
        .filter(|t| !t.text.starts_with("threshold"))
        .collect();
    assert_eq!(labels.len(), critical.len() + 2, "{labels:?}");
    svg_check::assert_no_overlap(&labels);
    std::fs::remove_file(svg_path).ok();
}
