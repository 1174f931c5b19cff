//! Rotor-level checks: statics against equilibrium, the eigenvalue stability threshold against
//! Lund's closed-form rigid-rotor criterion, and the shipped machine descriptions.

mod common;
use common::short_bearing_coefficients;
use rotor_twin::rotor::{
    stability_threshold, static_solution, MachineDescription, Rotor, DEFAULT_MACHINE_YAML,
};
use std::f64::consts::PI;

fn load(path: &str) -> Rotor {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    Rotor::from_description(&MachineDescription::from_file(&p).unwrap())
}

/// Bearing reactions carry the weight (Σ F = m g) and balance its moment about z = 0
/// (Σ F_i z_i = m g z_cm): static equilibrium of the whole rotor, to round-off.
#[test]
fn bearing_reactions_balance_weight_and_moment() {
    for path in [
        "config/orc_microturbine_100kw.yaml",
        "config/test_rig_three_support.yaml",
    ] {
        let rotor = load(path);
        let st = static_solution(&rotor).unwrap();
        let w = rotor.rotor_mass_kg() * 9.81;
        let sum: f64 = st.bearing_loads_n.iter().map(|f| f[1]).sum();
        let moment: f64 = rotor
            .bearings
            .iter()
            .zip(&st.bearing_loads_n)
            .map(|(b, f)| f[1] * rotor.node_z_m[b.node])
            .sum();
        // loads point down (−y): the journal presses on the bearing
        assert!(
            (sum + w).abs() < 1e-9 * w,
            "{path}: Σ loads {sum} vs weight {w}"
        );
        let z_cm = rotor.centre_of_mass_z_m();
        assert!(
            (moment + w * z_cm).abs() < 1e-9 * w * z_cm,
            "{path}: moment {moment} vs {}",
            w * z_cm
        );
        assert!(st.bearing_loads_n.iter().all(|f| f[0].abs() < 1e-9 * w));
    }
}

/// The seed's machine as described by the paper: 56 kg, ≈ 1,020 mm long, bearings ≈ 800 mm apart,
/// seven stage discs between them, 30 elements, 9,000 rpm; the built-in default is this file.
#[test]
fn microturbine_matches_the_published_figures() {
    let rotor = load("config/orc_microturbine_100kw.yaml");
    assert!(
        (rotor.rotor_mass_kg() - 56.0).abs() < 0.28,
        "mass {} kg",
        rotor.rotor_mass_kg()
    );
    assert_eq!(rotor.elements.len(), 30);
    let length = rotor.node_z_m.last().unwrap();
    assert!((length - 1.020).abs() < 1e-6, "length {length}");
    let zb: Vec<f64> = rotor
        .bearings
        .iter()
        .map(|b| rotor.node_z_m[b.node])
        .collect();
    assert!((zb[1] - zb[0] - 0.800).abs() < 1e-6);
    let stages = rotor.discs.iter().filter(|d| {
        let z = rotor.node_z_m[d.node];
        z > zb[0] && z < zb[1]
    });
    assert_eq!(stages.count(), 7);
    assert!((rotor.rated_speed_rad_s - 9000.0 * PI / 30.0).abs() < 1e-9);
    let builtin = MachineDescription::builtin_default();
    let file = MachineDescription::from_file(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("config/orc_microturbine_100kw.yaml"),
    )
    .unwrap();
    assert_eq!(builtin, file);
    assert!(!DEFAULT_MACHINE_YAML.is_empty());
}

/// A rigid symmetric rotor on two identical short bearings: the eigenvalue threshold equals
/// Lund's closed-form criterion (closed_forms.md) within 1 %:
/// K_eq = (K_xx B_yy + K_yy B_xx − K_xy B_yx − K_yx B_xy)/(B_xx + B_yy),
/// γ² = [(K_xx − K_eq)(K_yy − K_eq) − K_xy K_yx]/(B_xx B_yy − B_xy B_yx),
/// unstable when m c ω²/W > K_eq/γ², with ε(ω) from S (L/D)² = (1−ε²)²/(πε√(16ε²+π²(1−ε²))).
#[test]
fn rigid_rotor_threshold_matches_lund_criterion() {
    // a quasi-rigid shaft (E 1000× steel, nearly massless) carrying a 40 kg disc midway
    let (m_disc, l_span) = (40.0, 0.4);
    let (d, lb, c, mu) = (0.05, 0.025, 50e-6, 0.01);
    let yaml = format!(
        r#"
name: rigid symmetric rotor
rated_speed_rpm: 10000
materials: {{rigid: {{youngs_modulus_pa: 2.1e14, poisson_ratio: 0.3, density_kg_m3: 1.0}}}}
shaft: [{{length_m: {l_span}, outer_diameter_m: 0.1, material: rigid, elements: 4}}]
discs: [{{node: 2, mass_kg: {m_disc}, polar_inertia_kg_m2: 0.05, diametral_inertia_kg_m2: 0.1}}]
bearings:
  - {{name: left, node: 0, model: short, diameter_m: {d}, length_m: {lb}, radial_clearance_m: {c}, lubricant: {{density_kg_m3: 870, viscosity_pa_s: {mu}}}}}
  - {{name: right, node: 4, model: short, diameter_m: {d}, length_m: {lb}, radial_clearance_m: {c}, lubricant: {{density_kg_m3: 870, viscosity_pa_s: {mu}}}}}
"#
    );
    let rotor = Rotor::from_description(&MachineDescription::from_yaml(&yaml, "test").unwrap());
    let st = static_solution(&rotor).unwrap();
    let th = stability_threshold(&rotor, &st, 500.0, 60000.0, 500.0)
        .unwrap()
        .expect("a threshold");

    // closed form
    let m_b = 0.5 * rotor.rotor_mass_kg();
    let w = m_b * 9.81;
    let margin = |omega: f64| {
        let s = mu * omega / (2.0 * PI) * lb * d / w * (0.5 * d / c).powi(2);
        let t = s * (lb / d).powi(2);
        let f = |e: f64| {
            (1.0 - e * e).powi(2) / (PI * e * (16.0 * e * e + PI * PI * (1.0 - e * e)).sqrt())
        };
        let (mut lo, mut hi) = (1e-6, 0.999);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if f(mid) > t {
                lo = mid
            } else {
                hi = mid
            }
        }
        let (k, b) = short_bearing_coefficients(0.5 * (lo + hi));
        let k_eq = (k[0][0] * b[1][1] + k[1][1] * b[0][0] - k[0][1] * b[1][0] - k[1][0] * b[0][1])
            / (b[0][0] + b[1][1]);
        let g2 = ((k[0][0] - k_eq) * (k[1][1] - k_eq) - k[0][1] * k[1][0])
            / (b[0][0] * b[1][1] - b[0][1] * b[1][0]);
        (m_b * c * omega * omega / w - k_eq / g2, g2.sqrt())
    };
    let (mut lo, mut hi) = (500.0 * PI / 30.0, 60000.0 * PI / 30.0);
    assert!(margin(lo).0 < 0.0 && margin(hi).0 > 0.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if margin(mid).0 < 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    let lund_rpm = lo * 30.0 / PI;
    let gamma = margin(lo).1;
    println!(
        "threshold: eigenvalues {:.1} rpm (whirl ratio {:.4}), Lund {:.1} rpm (γ {:.4})",
        th.speed_rpm, th.whirl_ratio, lund_rpm, gamma
    );
    assert!((th.speed_rpm - lund_rpm).abs() < 0.01 * lund_rpm);
    assert!((th.whirl_ratio - gamma).abs() < 0.01 * gamma);
}
