//! The linear unbalance response against closed forms and against the transient model.

mod common;
use common::run_cli;
use rotor_twin::rotor::{
    response_peaks, static_solution, unbalance_response, MachineDescription, Rotor,
};
use std::f64::consts::PI;

/// A damped Jeffcott rotor: the textbook disc (20 kg) at midspan of a massless shaft on linear
/// bearings, stiff (1e12 N/m) so that the shaft's stiffness-proportional damping C = βK acts on
/// (nearly) all of the flexibility: m ẍ + βk ẋ + k x = m e Ω² cos Ωt per plane, k the shaft's
/// Timoshenko midspan stiffness (tests/rotor_critical_speeds.rs) in series with the two bearings
/// (their share is 2e-8 of it, below the tolerances). Closed form:
/// X = m e Ω² / (k − mΩ² + iΩβk): the phase lag is 90° at Ω = ω_n = √(k/m) exactly, the peak is
/// where d|X|/dΩ = 0, and the half-power amplification factor is ≈ 1/(2ζ), ζ = βω_n/2
/// (Friswell et al. 2010, §3.4; API 684 §2.5.1).
#[test]
fn jeffcott_rotor_peak_phase_and_amplification_factor() {
    let (e, nu, d, l, m): (f64, f64, f64, f64, f64) = (2.1e11, 0.3, 0.03, 0.8, 20.0);
    let beta = 2e-4;
    let yaml = format!(
        r#"
name: damped jeffcott
rated_speed_rpm: 3000
gravity_m_s2: [0.0, 0.0]
shaft_damping_beta_s: {beta}
materials: {{massless: {{youngs_modulus_pa: {e}, poisson_ratio: {nu}, density_kg_m3: 1.0e-3}}}}
shaft: [{{length_m: {l}, outer_diameter_m: {d}, material: massless, elements: 8}}]
discs: [{{name: disc, node: 4, mass_kg: {m}, polar_inertia_kg_m2: 0.25, diametral_inertia_kg_m2: 0.15}}]
bearings:
  - {{name: left, node: 0, model: linear, stiffness_n_per_m: [[1.0e12, 0.0], [0.0, 1.0e12]], damping_n_s_per_m: [[0.0, 0.0], [0.0, 0.0]]}}
  - {{name: right, node: 8, model: linear, stiffness_n_per_m: [[1.0e12, 0.0], [0.0, 1.0e12]], damping_n_s_per_m: [[0.0, 0.0], [0.0, 0.0]]}}
unbalance: [{{node: 4, magnitude_g_mm: 100.0, phase_deg: 0.0}}]
probes: [{{name: disc_probe, node: 4, angles_deg: [0.0, 90.0]}}]
"#
    );
    let rotor = Rotor::from_description(&MachineDescription::from_yaml(&yaml, "test").unwrap());
    let statics = static_solution(&rotor).unwrap();
    let ei = e * PI * d.powi(4) / 64.0;
    let kga = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu) * e / (2.0 * (1.0 + nu)) * PI * d * d / 4.0;
    let k_shaft = 1.0 / (l.powi(3) / (48.0 * ei) + l / (4.0 * kga));
    let k = 1.0 / (1.0 / k_shaft + 1.0 / (2.0 * 1e12)); // bearings in series, both ends
    let wn = (k / m).sqrt();
    let zeta = beta * wn / 2.0;
    let nc_rpm = wn * 30.0 / PI;
    // closed-form peak of |X(Ω)| on a fine grid
    let me = 100.0e-6;
    let closed = |w: f64| {
        let (re, im) = (k - m * w * w, w * beta * k);
        me * w * w / re.hypot(im)
    };
    let (peak_w, peak_x) = (0..200_000)
        .map(|i| wn * (0.9 + 0.2 * i as f64 / 200_000.0))
        .map(|w| (w, closed(w)))
        .fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    let speeds: Vec<f64> = (0..=400)
        .map(|i| nc_rpm * (0.8 + 0.001 * i as f64))
        .collect();
    let r = unbalance_response(&rotor, &statics, &speeds).unwrap();
    let probe = r
        .stations
        .iter()
        .position(|s| s.name == "disc_probe")
        .unwrap();
    let amp: Vec<f64> = r.response[probe]
        .iter()
        .map(|s| s.major_semi_axis_m)
        .collect();
    let peaks = response_peaks(&speeds, &amp, 3000.0, 3000.0);
    assert_eq!(peaks.len(), 1, "{peaks:?}");
    let p = peaks[0];
    let af = p.amplification_factor.unwrap();
    println!(
        "peak {:.2} rpm (closed form {:.2}), {:.4e} m ({peak_x:.4e}), AF {af:.2} (1/2ζ {:.2})",
        p.speed_rpm,
        peak_w * 30.0 / PI,
        p.amplitude_m,
        1.0 / (2.0 * zeta)
    );
    assert!((p.speed_rpm - peak_w * 30.0 / PI).abs() < 1e-3 * nc_rpm);
    assert!((p.amplitude_m - peak_x).abs() < 0.01 * peak_x);
    assert!(
        (af - 1.0 / (2.0 * zeta)).abs() < 0.03 / (2.0 * zeta),
        "AF {af}"
    );
    // phase lag through the critical: 90° at ω_n (interpolated), within 0.5°
    let lag: Vec<f64> = r.response[probe]
        .iter()
        .map(|s| s.x_phase_lag_deg)
        .collect();
    let j = speeds.iter().position(|&s| s > nc_rpm).unwrap();
    let t = (nc_rpm - speeds[j - 1]) / (speeds[j] - speeds[j - 1]);
    let lag_at_nc = lag[j - 1] + t * (lag[j] - lag[j - 1]);
    assert!((lag_at_nc - 90.0).abs() < 0.5, "lag at ω_n {lag_at_nc}°");
    assert!(
        lag[0] < 20.0 && lag[400] > 160.0,
        "{} → {}",
        lag[0],
        lag[400]
    );
    // the x and y responses of the isotropic rotor are a forward circle: y lags x by 90°
    let s = r.response[probe][200];
    assert!((s.x_amplitude_m - s.y_amplitude_m).abs() < 1e-6 * s.x_amplitude_m);
    assert!(((s.y_phase_lag_deg - s.x_phase_lag_deg).rem_euclid(360.0) - 90.0).abs() < 1e-3);
}

/// The microturbine at 8,000 rpm (below its threshold, a stable 1X orbit): the linear model's 1X
/// semi-major axis at each bearing against the nonlinear transient's (`simulate`, a second
/// method: implicit Newmark with the finite film, 1X from the orbit's order spectrum), within 5 %
/// — the orbit is small (ε varies by ±0.05 about 0.55), so the film is nearly linear.
#[test]
fn microturbine_1x_at_8000_rpm_matches_the_transient_model() {
    let (ok, out, err) = run_cli(&["simulate", "--speed-rpm", "8000", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let desc = MachineDescription::builtin_default();
    let rotor = Rotor::from_description(&desc);
    let statics = static_solution(&rotor).unwrap();
    let r = unbalance_response(&rotor, &statics, &[8000.0]).unwrap();
    for b in v["bearings"].as_array().unwrap() {
        let name = b["name"].as_str().unwrap();
        let transient = b["one_x_amplitude_m"].as_f64().unwrap();
        let s = r.stations.iter().position(|s| s.name == name).unwrap();
        let linear = r.response[s][0].major_semi_axis_m;
        println!("{name}: linear {linear:.4e} m, transient {transient:.4e} m");
        assert!(
            (linear - transient).abs() < 0.05 * transient,
            "{name}: linear {linear} vs transient {transient}"
        );
    }
}
