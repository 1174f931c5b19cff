//! `rotor-twin bearing --speeds`: a bearing's equilibrium and eight coefficients over a speed
//! range, checked against Ocvirk's short-bearing closed form (every speed), against Raimondi &
//! Boyd's finite-bearing table (a machine file's bearing), against the single-speed analysis in
//! the load frame (the turn from the machine frame), and its plots read back.

mod common;
mod svg_check;
use common::{run_cli, short_bearing_coefficients};
use serde_json::Value;
use std::f64::consts::PI;

fn json(args: &[&str]) -> Value {
    let (ok, out, err) = run_cli(args);
    assert!(ok, "rotor-twin {args:?} failed: {err}");
    serde_json::from_str(&out).unwrap_or_else(|e| panic!("not JSON ({e}): {out}"))
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number {key} in {v}"))
}

fn matrix(v: &Value, key: &str) -> [[f64; 2]; 2] {
    let m = &v[key];
    let at = |i: usize, j: usize| m[i][j].as_f64().expect("a 2 × 2 matrix");
    [[at(0, 0), at(0, 1)], [at(1, 0), at(1, 1)]]
}

/// Ocvirk's load relation inverted here by bisection (not the library's): the ε at which a short
/// bearing of slenderness `ld` carries Sommerfeld number `s`,
/// S (L/D)² = (1 − ε²)² / (π ε √(16ε² + π²(1 − ε²))) (Friswell et al. 2010, eq. 5.45).
fn ocvirk_eccentricity(s: f64, ld: f64) -> f64 {
    let f =
        |e: f64| (1.0 - e * e).powi(2) / (PI * e * (16.0 * e * e + PI * PI * (1.0 - e * e)).sqrt());
    let (mut lo, mut hi) = (1e-9, 1.0 - 1e-12);
    while hi - lo > 1e-14 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > s * ld * ld {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

fn max_abs(m: &[[f64; 2]; 2]) -> f64 {
    m.iter().flatten().fold(0.0, |a, v| a.max(v.abs()))
}

/// The short bearing (the seed's Ø60 × 30 mm, c 40 µm, 275 N) from 1,000 to 12,000 rpm: at every
/// speed S is its definition µNLD/W (R/c)², ε and φ are Ocvirk's (tan φ = π√(1−ε²)/(4ε)), and
/// the dimensionless K and B are the closed forms', within 1e-6; ε falls and φ rises with speed
/// (S grows with N).
#[test]
fn short_bearing_sweep_is_ocvirks_closed_form_at_every_speed() {
    let v = json(&[
        "bearing",
        "--model",
        "short",
        "--speeds",
        "1000:12000:500",
        "--json",
    ]);
    let rows = v["speeds"].as_array().unwrap();
    assert_eq!(rows.len(), 23);
    let mut last: Option<(f64, f64)> = None;
    for r in rows {
        let n = num(r, "speed_rpm");
        let s = num(r, "sommerfeld_number");
        let s_def = 0.0008 * n / 60.0 * 0.03 * 0.06 / 275.0 * (0.03 / 40e-6_f64).powi(2);
        assert!((s / s_def - 1.0).abs() < 1e-9, "{n} rpm: S {s} vs {s_def}");
        let e = num(r, "eccentricity_ratio");
        let e_ref = ocvirk_eccentricity(s, 0.5);
        assert!((e - e_ref).abs() < 1e-6, "{n} rpm: ε {e} vs Ocvirk {e_ref}");
        let phi = num(r, "attitude_angle_deg");
        let phi_ref = (PI * (1.0 - e_ref * e_ref).sqrt())
            .atan2(4.0 * e_ref)
            .to_degrees();
        assert!(
            (phi - phi_ref).abs() < 1e-4,
            "{n} rpm: φ {phi} vs {phi_ref}"
        );
        let (k_ref, b_ref) = short_bearing_coefficients(e_ref);
        let (k, b) = (
            matrix(r, "stiffness_dimensionless"),
            matrix(r, "damping_dimensionless"),
        );
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (k[i][j] - k_ref[i][j]).abs() < 1e-6 * max_abs(&k_ref) * 10.0,
                    "{n} rpm: K{i}{j} {} vs {}",
                    k[i][j],
                    k_ref[i][j]
                );
                assert!(
                    (b[i][j] - b_ref[i][j]).abs() < 1e-6 * max_abs(&b_ref) * 10.0,
                    "{n} rpm: B{i}{j} {} vs {}",
                    b[i][j],
                    b_ref[i][j]
                );
            }
        }
        if let Some((e0, phi0)) = last {
            assert!(
                e < e0 && phi > phi0,
                "{n} rpm: ε {e0} → {e}, φ {phi0} → {phi}"
            );
        }
        last = Some((e, phi));
    }
}

/// The microturbine's pulley-end bearing (finite film, 60 × 10, L/D 0.5) under its static load
/// from 1,000 to 12,000 rpm: ε falls monotonically, and where it passes ε = 0.6 and 0.8 the
/// Sommerfeld number (interpolated in ln S between neighbouring speeds) is Raimondi & Boyd's
/// (tests/reference/raimondi_boyd.csv: 0.319 and 0.0923) within 3 %, the attitude angle (48.14°,
/// 33.31°) within 1.5° (the tolerances of tests/film_raimondi_boyd.rs).
#[test]
fn machine_bearing_sweep_follows_raimondi_and_boyd() {
    let v = json(&[
        "bearing",
        "--config",
        "config/orc_microturbine_100kw.yaml",
        "--bearing",
        "bearing_pulley_end",
        "--speeds",
        "1000:12000:250",
        "--json",
    ]);
    assert_eq!(v["bearing"], "bearing_pulley_end");
    assert!(
        (num(&v, "load_direction_deg") + 90.0).abs() < 1e-6,
        "gravity along −y"
    );
    let rows = v["speeds"].as_array().unwrap();
    let pts: Vec<(f64, f64, f64)> = rows
        .iter()
        .map(|r| {
            (
                num(r, "eccentricity_ratio"),
                num(r, "sommerfeld_number").ln(),
                num(r, "attitude_angle_deg"),
            )
        })
        .collect();
    assert!(
        pts.windows(2).all(|w| w[1].0 < w[0].0),
        "ε does not fall monotonically: {:?}",
        pts.iter().map(|p| p.0).collect::<Vec<_>>()
    );
    let table = common::reference_table("raimondi_boyd.csv");
    for eps in [0.6, 0.8] {
        let row = table
            .iter()
            .find(|r| r["LD"] == 0.5 && (r["eps"] - eps).abs() < 1e-9)
            .expect("table row");
        let w = pts
            .windows(2)
            .find(|w| w[1].0 <= eps && eps <= w[0].0)
            .unwrap_or_else(|| panic!("ε {eps} not crossed"));
        let t = (eps - w[0].0) / (w[1].0 - w[0].0);
        let s = (w[0].1 + t * (w[1].1 - w[0].1)).exp();
        let phi = w[0].2 + t * (w[1].2 - w[0].2);
        assert!(
            (s / row["S"] - 1.0).abs() < 0.03,
            "ε {eps}: S {s} vs Raimondi & Boyd {}",
            row["S"]
        );
        assert!(
            (phi - row["phi_deg"]).abs() < 1.5,
            "ε {eps}: φ {phi} vs {}",
            row["phi_deg"]
        );
    }
}

/// The machine's bearing is solved in the machine frame (load along −y) and its coefficients
/// turned into the load frame (K' = Rᵀ K R): at 9,000 rpm they are the single-speed analysis's
/// with the same load along +x, within 1.5 % of each matrix's largest entry (the finite grid is
/// not rotationally invariant: 1.2 % spread over grid phases, README "Validation"); a wrong turn
/// would swap or flip the cross terms. ε and φ within 0.005 and 0.5°.
#[test]
fn machine_frame_coefficients_are_turned_into_the_load_frame() {
    let v = json(&[
        "bearing",
        "--config",
        "config/orc_microturbine_100kw.yaml",
        "--speeds",
        "9000:9000:1",
        "--json",
    ]);
    let row = &v["speeds"][0];
    let load = format!("{:.12}", num(&v, "load_n"));
    let one = json(&[
        "bearing",
        "--speed-rpm",
        "9000",
        "--load-n",
        &load,
        "--json",
    ]);
    assert!((num(row, "eccentricity_ratio") - num(&one, "eccentricity_ratio")).abs() < 0.005);
    assert!((num(row, "attitude_angle_deg") - num(&one, "attitude_angle_deg")).abs() < 0.5);
    for key in ["stiffness_n_per_m", "damping_n_s_per_m"] {
        let (a, b) = (matrix(row, key), matrix(&one, key));
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (a[i][j] - b[i][j]).abs() < 0.015 * max_abs(&b),
                    "{key}[{i}][{j}]: sweep {} vs single speed {}",
                    a[i][j],
                    b[i][j]
                );
            }
        }
    }
    // the centerline: the journal below the centre (load along −y), displaced towards +x by
    // the attitude angle (rotation from +x towards +y)
    let p = &row["journal_position_machine_m"];
    let (x, y) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
    let phi = num(row, "attitude_angle_deg").to_radians();
    let e = num(row, "eccentricity_ratio") * 40e-6;
    assert!(
        (x - e * phi.sin()).abs() < 1e-9 && (y + e * phi.cos()).abs() < 1e-9,
        "{x} {y}"
    );
}

/// Both plots read back: titles, axes with units, legend right of the data; the centerline 1:1.
#[test]
fn coefficient_and_centerline_plots() {
    let dir =
        std::env::temp_dir().join(format!("rotor-twin-bearing-speeds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (coef, centre) = (dir.join("coef.svg"), dir.join("centerline.svg"));
    let (ok, out, err) = run_cli(&[
        "bearing",
        "--config",
        "config/orc_microturbine_100kw.yaml",
        "--speeds",
        "1000:12000:500",
        "--plot",
        coef.to_str().unwrap(),
        "--centerline-plot",
        centre.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("kxx") && out.contains("MN/m") && out.lines().count() == 3 + 23,
        "{out}"
    );
    let c = svg_check::read(&coef);
    c.assert_texts(&[
        "Bearing coefficients against speed: bearing_pulley_end (orc_microturbine_100kw)",
        "eccentricity ratio ε",
        "attitude angle φ (deg)",
        "stiffness k (MN/m)",
        "damping c (kN·s/m)",
        "speed (rpm)",
        "legend",
        "kxy, cxy",
    ]);
    c.assert_legend_right_of_data();
    let s = svg_check::read(&centre);
    s.assert_texts(&[
        "Shaft centerline: bearing_pulley_end (orc_microturbine_100kw)",
        "x, journal centre (µm)",
        "y, journal centre (µm)",
        "legend",
        "clearance circle, c = 40.0 µm",
    ]);
    s.assert_legend_right_of_data();
    let (px_x, px_y) = s.px_per_unit();
    assert!(
        (px_x / px_y - 1.0).abs() < 0.01,
        "centerline aspect {px_x} vs {px_y} px/µm"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Bad speeds, an unknown bearing and flags the machine file overrides are refused, named.
#[test]
fn bad_sweep_input_is_named() {
    let cases: [(&[&str], &str); 4] = [
        (
            &["bearing", "--speeds", "12000:1000:500"],
            "TO 1000 is below FROM 12000",
        ),
        (
            &["bearing", "--speeds", "1000:12000:0"],
            "STEP '0' must be a finite speed above zero",
        ),
        (
            &["bearing", "--speeds", "1000:12000"],
            "expected FROM:TO:STEP",
        ),
        (
            &[
                "bearing",
                "--config",
                "config/orc_microturbine_100kw.yaml",
                "--bearing",
                "nope",
                "--speeds",
                "1000:2000:500",
            ],
            "its film bearings: bearing_pulley_end, bearing_outboard",
        ),
    ];
    for (args, want) in cases {
        let (ok, _, err) = run_cli(args);
        assert!(!ok && err.contains(want), "{args:?}: {err}");
    }
    let (ok, _, err) = run_cli(&[
        "bearing",
        "--config",
        "config/orc_microturbine_100kw.yaml",
        "--diameter-m",
        "0.1",
        "--speeds",
        "1000:2000:500",
    ]);
    assert!(!ok && err.contains("cannot be used with"), "{err}");
}
