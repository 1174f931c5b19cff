//! `rotor-twin response`: the JSON contract, the Bode and polar SVGs read back (title, axes
//! with units, legend clear of the data, polar 1:1), and bad input named.

mod common;
mod svg_check;
use common::run_cli;

/// The built-in microturbine (reading (B), Ø63, the default since session 15): its first forward
/// mode's peak near 4,600 rpm at each bearing (4,575 / 4,598 rpm measured in session 15; `modes`
/// puts the damped critical at 4,102 rpm with AF 2.54, and the films' damping carries the peak of
/// the bearings' response above it; (A), Ø55, peaked near 3,800) with an amplification factor and
/// the API 684 margin beside it; both plots complete.
#[test]
fn response_json_and_plots_for_the_builtin_machine() {
    let prefix = std::env::temp_dir().join(format!("rotor-twin-response-{}", std::process::id()));
    let (ok, out, err) = run_cli(&[
        "response",
        "--json",
        "--from-rpm",
        "1000",
        "--to-rpm",
        "12000",
        "--step-rpm",
        "100",
        "--plot",
        prefix.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let stations = v["stations"].as_array().unwrap();
    assert_eq!(stations.len(), 4);
    for s in stations {
        let peak = &s["peaks"][0];
        let nc = peak["speed_rpm"].as_f64().unwrap();
        assert!((4400.0..4800.0).contains(&nc), "{}: peak {nc}", s["name"]);
        for key in [
            "amplification_factor",
            "separation_margin_pct",
            "required_margin_pct",
            "meets_api_684",
        ] {
            assert!(peak.get(key).is_some(), "peak lacks {key}");
        }
        assert_eq!(s["response"].as_array().unwrap().len(), 111);
    }
    let bode = svg_check::read(&prefix.with_file_name(format!(
        "{}_bode.svg",
        prefix.file_name().unwrap().to_str().unwrap()
    )));
    bode.assert_texts(&[
        "Unbalance response (Bode): orc_microturbine_100kw",
        "speed (rpm)",
        "1X semi-major axis (µm)",
        "phase lag of x (deg)",
        "legend",
        "bearing_pulley_end",
        "bearing_outboard",
    ]);
    bode.assert_legend_right_of_data();
    // the probes stand at the bearings' nodes: their curves are the bearings', drawn once and
    // named as coinciding (the legend used to list four curves of which two were hidden)
    for probe in ["probe_pulley_end", "probe_outboard"] {
        assert!(
            bode.text(&format!("= {probe} (coincide)")).is_some(),
            "{probe} not said to coincide"
        );
    }
    let amplitude_curves = bode.polylines.iter().filter(|l| l.len() > 100).count();
    assert_eq!(amplitude_curves, 2, "amplitude curves drawn");
    // the peaks' labels clear of one another
    let peaks: Vec<_> = bode
        .texts
        .iter()
        .filter(|t| t.text.contains(", AF "))
        .collect();
    assert_eq!(peaks.len(), 2, "{peaks:?}");
    svg_check::assert_no_overlap(&peaks);
    let polar_path = prefix.with_file_name(format!(
        "{}_polar.svg",
        prefix.file_name().unwrap().to_str().unwrap()
    ));
    let polar = svg_check::read(&polar_path);
    polar.assert_texts(&[
        "Re X, in phase with the keyphasor (µm)",
        "Im X (µm)",
        "legend",
    ]);
    // the speed labels (whole rpm; tick labels have a decimal point) clear of one another:
    // they overprinted where two stations' curves start together (900 and 2979 twice)
    let speeds: Vec<_> = polar
        .texts
        .iter()
        .filter(|t| t.text.parse::<u32>().is_ok())
        .collect();
    assert!(speeds.len() >= 6, "{speeds:?}");
    svg_check::assert_no_overlap(&speeds);
    let (px_x, px_y) = polar.px_per_unit();
    assert!(
        (px_x / px_y - 1.0).abs() < 0.01,
        "polar aspect {px_x} vs {px_y} px/µm"
    );
    for suffix in ["_bode.svg", "_polar.svg"] {
        let mut p = prefix.clone().into_os_string();
        p.push(suffix);
        std::fs::remove_file(p).ok();
    }
}

#[test]
fn bad_response_input_is_named() {
    for (args, word) in [
        (vec!["response", "--from-rpm", "-5"], "--from-rpm"),
        (
            vec!["response", "--from-rpm", "5000", "--to-rpm", "4000"],
            "--to-rpm",
        ),
        (vec!["response", "--step-rpm", "0"], "--step-rpm"),
        (
            vec!["response", "--min-operating-rpm", "-1"],
            "--min-operating-rpm",
        ),
    ] {
        let (ok, _, err) = run_cli(&args);
        assert!(!ok, "{args:?} should fail");
        assert!(err.contains(word), "{args:?}: '{err}' does not name {word}");
    }
}
