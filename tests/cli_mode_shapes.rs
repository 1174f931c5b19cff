//! `rotor-twin modes --shapes-rpm N --shapes-plot F --rotor-plot F`: the damped mode shapes of
//! the textbook rotor (a disc at the middle of a massless Timoshenko shaft, pinned ends) against
//! the closed-form static deflection lines its modes must follow, the MAC of its repeated
//! forward/backward pairs from the eigen solver, and both drawings read back.

mod common;
mod svg_check;
use common::run_cli;
use rotor_twin::film::FilmCoefficients;
use rotor_twin::rotor::{
    damped_mode_shapes, mode_tracking::mac, MachineDescription, Rotor, WhirlDirection,
};
use serde_json::Value;
use std::f64::consts::PI;

const TEXTBOOK: &str = "config/textbook_disc_midspan.yaml";
const E: f64 = 2.1e11;
const NU: f64 = 0.3;
const D: f64 = 0.03;
const L: f64 = 0.8;

fn shapes_json(config: &str, rpm: &str, modes: &str) -> Value {
    let (ok, out, err) = run_cli(&[
        "modes",
        "--config",
        config,
        "--from-rpm",
        "300",
        "--to-rpm",
        "3000",
        "--modes",
        modes,
        "--shapes-rpm",
        rpm,
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    v["mode_shapes"].clone()
}

fn column(mode: &Value, key: &str) -> Vec<f64> {
    mode["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n[key].as_f64().unwrap())
        .collect()
}

/// Static deflection of a pinned–pinned Timoshenko beam under a force P at midspan, z ≤ L/2:
/// y = P z (3L² − 4z²)/(48 EI) + P z/(2 κGA) (Timoshenko & Gere; κ of Cowper 1966), P = 1.
fn point_force_line(z: f64) -> f64 {
    let z = z.min(L - z);
    let ei = E * PI * D.powi(4) / 64.0;
    let kga = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU) * E / (2.0 * (1.0 + NU)) * PI * D * D / 4.0;
    z * (3.0 * L * L - 4.0 * z * z) / (48.0 * ei) + z / (2.0 * kga)
}

/// The same beam under a couple at midspan, z ≤ L/2: y = M z (L² − 4z²)/(24 EI L), antisymmetric
/// (Roark, table 8.1 case 3e); the shear is constant and only turns the line, which the pinned
/// ends take out, so it adds nothing.
fn couple_line(z: f64) -> f64 {
    if z <= 0.5 * L {
        z * (L * L - 4.0 * z * z)
    } else {
        -couple_line(L - z)
    }
}

/// At 3,000 rpm the two lowest modes are the disc's translation, forward and backward at the
/// same 31.44 Hz: each deflected line is the point-force line normalised to midspan (symmetric,
/// no node inside the span) within 1e-6, each orbit circular (minor = major within 1e-6) and
/// whirling in the mode's sense. Modes 3 and 4 (109.40 backward, 192.73 forward, the disc's
/// tilt) follow the couple line, antisymmetric about the disc, within 1e-6.
#[test]
fn textbook_mode_shapes_are_the_closed_form_deflection_lines() {
    let s = shapes_json(TEXTBOOK, "3000", "4");
    let modes = s["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 4);
    let z = column(&modes[0], "z_m");
    let expect_dir = ["forward", "backward", "backward", "forward"];
    let expect_hz = [31.44, 31.44, 109.40, 192.73];
    for (k, m) in modes.iter().enumerate() {
        let f = m["frequency_hz"].as_f64().unwrap();
        assert!((f - expect_hz[k]).abs() < 0.006, "mode {k}: {f} Hz");
        assert_eq!(m["direction"], expect_dir[k], "mode {k}");
        let d = column(m, "deflection");
        let (major, minor) = (column(m, "semi_major"), column(m, "semi_minor"));
        let reference: Vec<f64> = if k < 2 {
            z.iter()
                .map(|&z| point_force_line(z) / point_force_line(0.5 * L))
                .collect()
        } else {
            // normalised to the largest node value; the overall sign is the solver's choice
            let top = z.iter().map(|&z| couple_line(z).abs()).fold(0.0, f64::max);
            let line: Vec<f64> = z.iter().map(|&z| couple_line(z) / top).collect();
            let sign = line
                .iter()
                .zip(&d)
                .map(|(a, b)| a * b)
                .sum::<f64>()
                .signum();
            line.iter().map(|v| sign * v).collect()
        };
        for i in 0..z.len() {
            assert!(
                (d[i] - reference[i]).abs() < 1e-6,
                "mode {k}, z {}: deflection {} vs closed form {}",
                z[i],
                d[i],
                reference[i]
            );
            if major[i] > 1e-6 {
                assert!(
                    (minor[i] / major[i] - 1.0).abs() < 1e-6,
                    "mode {k} node {i}: not circular"
                );
                assert_eq!(m["nodes"][i]["direction"], expect_dir[k]);
            }
        }
        if k < 2 {
            assert!(
                d[1..z.len() - 1].iter().all(|v| *v > 0.0),
                "mode {k} has a node: {d:?}"
            );
        }
    }
}

/// The eigen solver's repeated pairs of the textbook rotor, rotated into circular modes: at rest
/// both the translation (31.44 Hz) and the tilt (145.21 Hz) pairs are repeated, at 3,000 rpm the
/// translation pair still is. In each pair MAC(forward, backward) < 1e-9 (orthogonal), each
/// MAC with itself 1, and the two share one deflected line (their x components' MAC is 1 within
/// 1e-9): one mode whirling both ways, not two modes.
#[test]
fn repeated_pairs_are_mac_orthogonal_forward_and_backward() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(TEXTBOOK);
    let rotor = Rotor::from_description(&MachineDescription::from_file(&path).unwrap());
    let coefs = vec![FilmCoefficients::default(); rotor.bearings.len()];
    let (n, ell2) = (rotor.n_nodes(), 0.08_f64.powi(2));
    for (rpm, pairs) in [
        (0.0, vec![(0, 31.44), (2, 145.21)]),
        (3000.0, vec![(0, 31.44)]),
    ] {
        let omega = rpm * PI / 30.0;
        let shapes = damped_mode_shapes(&rotor, omega, &coefs).unwrap();
        for (first, hz) in pairs {
            let (a, b) = (&shapes[first], &shapes[first + 1]);
            let what = format!("{rpm} rpm, pair at {hz} Hz");
            assert!(
                (a.mode.frequency_hz - hz).abs() < 0.006,
                "{what}: {:?}",
                a.mode
            );
            assert!(
                (a.mode.frequency_hz - b.mode.frequency_hz).abs() < 1e-6 * hz,
                "{what}"
            );
            let dirs = [a.mode.direction, b.mode.direction];
            assert!(
                dirs.contains(&WhirlDirection::Forward) && dirs.contains(&WhirlDirection::Backward),
                "{what}: {dirs:?}"
            );
            let m = mac(&a.shape, &b.shape, n, ell2);
            assert!(m < 1e-9, "{what}: MAC(forward, backward) = {m:e}");
            assert!((mac(&a.shape, &a.shape, n, ell2) - 1.0).abs() < 1e-12);
            let only_x = |s: &[faer::c64]| -> Vec<faer::c64> {
                s.iter()
                    .enumerate()
                    .map(|(i, v)| {
                        if i % 4 == 0 {
                            *v
                        } else {
                            faer::c64::new(0.0, 0.0)
                        }
                    })
                    .collect()
            };
            let same_line = mac(&only_x(&a.shape), &only_x(&b.shape), n, ell2);
            assert!(
                (same_line - 1.0).abs() < 1e-9,
                "{what}: line MAC {same_line}"
            );
        }
    }
}

/// The microturbine's mode shapes at 9,000 rpm and both drawings: the plots read back (titles,
/// axes with units, legends right of the data), the rotor drawing 1:1 with each disc, bearing
/// and probe named, and the largest stage drawn at the diameter its m and Ip give on the body's
/// bore: (A)'s inertias were computed for Ø300 mm on a 55 mm bore; (B)'s are × 0.8803 with the
/// masses, so on (B)'s 63 mm bore R² = 2Ip/m − r² gives Ø298.4 mm (the drawing infers it back from
/// m, Ip and the bore) within 1 %.
#[test]
fn mode_shape_and_rotor_drawings() {
    let dir = std::env::temp_dir().join(format!("rotor-twin-shapes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (shapes, rotor) = (dir.join("shapes.svg"), dir.join("rotor.svg"));
    let (ok, out, err) = run_cli(&[
        "modes",
        "--from-rpm",
        "1000",
        "--to-rpm",
        "9000",
        "--shapes-rpm",
        "9000",
        "--shapes-plot",
        shapes.to_str().unwrap(),
        "--rotor-plot",
        rotor.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("damped mode shapes at 9000 rpm:"), "{out}");
    let s = svg_check::read(&shapes);
    s.assert_texts(&[
        "Damped mode shapes at 9000 rpm: orc_microturbine_100kw",
        "axial position z (m)",
        "deflection (normalised)",
        "legend",
        "orbit, forward whirl",
        "orbit, backward whirl",
        "bearing_pulley_end",
        "bearing_outboard",
    ]);
    assert!(
        // reading (B), the default: the least-damped mode at 9,000 rpm is the 0.50X forward mode
        // (75.15 Hz, log dec +0.039: linear-stable, the half-speed window of its whip; `modes
        // --shapes-rpm 9000`, session 15)
        s.texts.iter().any(|t| t.text.starts_with("mode 1: 75.")),
        "mode 1 title"
    );
    s.assert_legend_right_of_data();
    let r = svg_check::read(&rotor);
    r.assert_texts(&[
        "Rotor model: orc_microturbine_100kw",
        "axial position z (mm)",
        "radius (mm)",
        "legend",
        // (B)'s stages are (A)'s × 0.8803 in mass and inertia (same Ip/m) on the Ø63 body: the
        // outer diameter inferred from m, Ip and the 63 mm bore is 298 mm (300 with (A)'s 55 mm)
        "stage_7 Ø298",
        "probe_pulley_end",
        "probe_outboard",
        "bearing_pulley_end (finite Ø60×30)",
        "140 g·mm at 0°",
    ]);
    let (px_x, px_y) = r.px_per_unit();
    assert!(
        (px_x / px_y - 1.0).abs() < 0.01,
        "rotor drawing aspect {px_x} vs {px_y} px/mm"
    );
    // the tallest narrow rectangle (under 50 px wide: not the background, not a shaft section)
    // is the largest stage: its height over the scale is its diameter
    let tallest = r
        .rects
        .iter()
        .filter(|q| q[2] < 50.0)
        .map(|q| q[3])
        .fold(0.0, f64::max);
    assert!(
        (tallest / px_y / 298.4 - 1.0).abs() < 0.01,
        "stage 7 drawn Ø{:.1} mm",
        tallest / px_y
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Bad speeds for the shapes are named.
#[test]
fn bad_shape_speed_is_named() {
    for (rpm, want) in [
        ("-5", "invalid --shapes-rpm -5"),
        ("0", "invalid --shapes-rpm 0"),
    ] {
        let (ok, _, err) = run_cli(&["modes", "--shapes-rpm", rpm]);
        assert!(!ok && err.contains(want), "{rpm}: {err}");
    }
}
