//! The Timoshenko FE rotor against closed forms (../shared/reference/closed_forms.md and the
//! textbook results cited at each test).

use rotor_twin::film::FilmCoefficients;
use rotor_twin::rotor::{
    damped_modes, undamped_frequencies_hz, Constraint, MachineDescription, Rotor, WhirlDirection,
};
use std::f64::consts::PI;

const E: f64 = 2.1e11;
const RHO: f64 = 7850.0;
const NU: f64 = 0.3;

/// A uniform steel shaft of diameter `d` (m) and length `l` (m) in `n` elements, pinned at both
/// ends.
fn uniform_shaft(d: f64, l: f64, n: usize) -> Rotor {
    let yaml = format!(
        r#"
name: uniform shaft
rated_speed_rpm: 3000
materials: {{steel: {{youngs_modulus_pa: {E}, poisson_ratio: {NU}, density_kg_m3: {RHO}}}}}
shaft: [{{length_m: {l}, outer_diameter_m: {d}, material: steel, elements: {n}}}]
bearings:
  - {{name: left, node: 0, model: rigid}}
  - {{name: right, node: {n}, model: rigid}}
"#
    );
    Rotor::from_description(&MachineDescription::from_yaml(&yaml, "test").unwrap())
}

/// √(EI/ρA) (m²/s) of a solid circular shaft.
fn beam_speed(d: f64) -> f64 {
    let i = PI * d.powi(4) / 64.0;
    let a = PI * d * d / 4.0;
    (E * i / (RHO * a)).sqrt()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Euler–Bernoulli pinned–pinned ω_n = (nπ/L)² √(EI/ρA) and free–free ω_n = (β_n/L)² √(EI/ρA),
/// β_n L = 4.7300, 7.8532, 10.9956 (closed_forms.md), on a slender shaft (L/d = 100, where shear
/// and rotary inertia lower the third mode by about 0.1 %): within 0.5 %.
#[test]
fn slender_shaft_matches_euler_bernoulli() {
    let (d, l) = (0.025, 2.5);
    let rotor = uniform_shaft(d, l, 40);
    let pinned = undamped_frequencies_hz(&rotor, Constraint::Pinned).unwrap();
    let free = undamped_frequencies_hz(&rotor, Constraint::FreeFree).unwrap();
    let c = beam_speed(d);
    for n in 1..=3 {
        let eb = (n as f64 * PI / l).powi(2) * c / (2.0 * PI);
        assert!(
            rel(pinned[n - 1], eb) < 0.005,
            "pinned mode {n}: {} vs {eb}",
            pinned[n - 1]
        );
    }
    for (k, beta) in [4.730_040_7, 7.853_204_6, 10.995_607_8].iter().enumerate() {
        let eb = (beta / l).powi(2) * c / (2.0 * PI);
        assert!(
            rel(free[k], eb) < 0.005,
            "free mode {}: {} vs {eb}",
            k + 1,
            free[k]
        );
    }
}

/// Timoshenko's frequency equation for a pinned–pinned beam, mode sin(kz), k = nπ/L:
/// det [[ρAω² − κGAk², κGAk], [κGAk, ρIω² − EIk² − κGA]] = 0, lower root (Timoshenko 1921;
/// e.g. Han, Benaroya & Wei, J. Sound Vib. 225 (1999) 935).
fn timoshenko_pinned_hz(d: f64, l: f64, n: usize) -> f64 {
    let (i, a) = (PI * d.powi(4) / 64.0, PI * d * d / 4.0);
    let g = E / (2.0 * (1.0 + NU));
    let kappa = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU);
    let k = n as f64 * PI / l;
    let (ka, ra, ri, ei) = (kappa * g * a, RHO * a, RHO * i, E * i);
    // (ra w − ka k²)(ri w − ei k² − ka) − (ka k)² = 0 in w = ω²
    let qa = ra * ri;
    let qb = -(ra * (ei * k * k + ka) + ri * ka * k * k);
    let qc = ka * k * k * (ei * k * k + ka) - (ka * k).powi(2);
    let w = (-qb - (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    w.sqrt() / (2.0 * PI)
}

/// A thick shaft (L/d = 5: shear and rotary inertia lower the third mode by ~25 %) against
/// Timoshenko's frequency equation: within 1 %.
#[test]
fn thick_shaft_matches_timoshenko_frequency_equation() {
    let (d, l) = (0.2, 1.0);
    let pinned = undamped_frequencies_hz(&uniform_shaft(d, l, 40), Constraint::Pinned).unwrap();
    for n in 1..=3 {
        let t = timoshenko_pinned_hz(d, l, n);
        let eb = (n as f64 * PI / l).powi(2) * beam_speed(d) / (2.0 * PI);
        println!(
            "mode {n}: FE {:.2} Hz, Timoshenko {t:.2} Hz, Euler–Bernoulli {eb:.2} Hz",
            pinned[n - 1]
        );
        assert!(
            rel(pinned[n - 1], t) < 0.01,
            "mode {n}: {} vs {t}",
            pinned[n - 1]
        );
    }
}

/// Mesh convergence: the error of the thick shaft's third mode shrinks at every doubling of the
/// element count, at second order (measured: 8.2 %, 2.0 %, 0.50 %, 0.12 % on 4, 8, 16, 32
/// elements; the same element converges at fourth order on a slender shaft), below 0.2 % at 32.
#[test]
fn mesh_refinement_converges() {
    let (d, l) = (0.2, 1.0);
    let t = timoshenko_pinned_hz(d, l, 3);
    let errors: Vec<f64> = [4, 8, 16, 32]
        .iter()
        .map(|&n| {
            rel(
                undamped_frequencies_hz(&uniform_shaft(d, l, n), Constraint::Pinned).unwrap()[2],
                t,
            )
        })
        .collect();
    println!("third-mode errors on 4, 8, 16, 32 elements: {errors:?}");
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 3.0, "{errors:?}");
    }
    assert!(errors[3] < 2e-3);
}

/// A disc at midspan of a pinned–pinned, (nearly) massless shaft: translation and tilt decouple.
/// Translation: ω² = k/m; tilt: Id ω² ∓ Ip Ω ω − k_θ = 0, so
/// ω_f,b = [√((IpΩ)² + 4 Id k_θ) ± IpΩ] / (2 Id) (gyroscopic 2-DOF rotor; Friswell et al. 2010,
/// §3.6; Genta, *Dynamics of Rotating Systems*, 2005, §4.4). The shaft's Timoshenko static
/// flexibilities at midspan: 1/k = L³/(48EI) + L/(4κGA) under a force, 1/k_θ = L/(12EI) +
/// 1/(κGAL) under a couple (bending plus shear; shear adds 0.3 % here). The shaft density is
/// 1e-3 kg/m³, so its inertia is below 1e-7 of the disc's.
#[test]
fn disc_on_massless_shaft_whirls_as_the_gyroscopic_two_dof_rotor() {
    // config/textbook_disc_midspan.yaml: d 30 mm, L 0.8 m, disc 20 kg, Ip 0.25, Id 0.15 kg·m²
    let (d, l): (f64, f64) = (0.03, 0.8);
    let (m, ip, id): (f64, f64, f64) = (20.0, 0.25, 0.15);
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/textbook_disc_midspan.yaml");
    let rotor = Rotor::from_description(&MachineDescription::from_file(&path).unwrap());
    assert!(
        (rotor.discs[0].mass_kg - m).abs() < 1e-12
            && (rotor.elements[0].outer_diameter_m - d).abs() < 1e-12
    );
    let ei = E * PI * d.powi(4) / 64.0;
    let kga = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU) * E / (2.0 * (1.0 + NU)) * PI * d * d / 4.0;
    let k_translation = 1.0 / (l.powi(3) / (48.0 * ei) + l / (4.0 * kga));
    let translation = (k_translation / m).sqrt() / (2.0 * PI);
    let k_tilt = 1.0 / (l / (12.0 * ei) + 1.0 / (kga * l));
    let none = vec![FilmCoefficients::default(); 2];
    for spin_rpm in [0.0_f64, 3000.0, 10000.0] {
        let spin = spin_rpm * PI / 30.0;
        let modes = damped_modes(&rotor, spin, &none).unwrap();
        let root = ((ip * spin).powi(2) + 4.0 * id * k_tilt).sqrt();
        let forward = (root + ip * spin) / (2.0 * id) / (2.0 * PI);
        let backward = (root - ip * spin) / (2.0 * id) / (2.0 * PI);
        let near = |f: f64| {
            modes
                .iter()
                .min_by(|a, b| rel(a.frequency_hz, f).total_cmp(&rel(b.frequency_hz, f)))
                .copied()
                .unwrap()
        };
        let (mf, mb) = (near(forward), near(backward));
        println!(
            "{spin_rpm} rpm: tilt forward {:.3}/{forward:.3} Hz, backward {:.3}/{backward:.3} Hz",
            mf.frequency_hz, mb.frequency_hz
        );
        assert!(
            rel(near(translation).frequency_hz, translation) < 1e-4,
            "translation at {spin_rpm} rpm"
        );
        assert!(
            rel(mf.frequency_hz, forward) < 1e-4,
            "forward tilt at {spin_rpm} rpm"
        );
        assert!(
            rel(mb.frequency_hz, backward) < 1e-4,
            "backward tilt at {spin_rpm} rpm"
        );
        if spin_rpm > 0.0 {
            assert_eq!(mf.direction, WhirlDirection::Forward, "{spin_rpm} rpm");
            assert_eq!(mb.direction, WhirlDirection::Backward, "{spin_rpm} rpm");
        }
        // undamped: every log decrement is zero to round-off
        assert!(modes.iter().take(6).all(|m| m.log_dec.abs() < 1e-6));
    }
}

/// Stiffness-proportional structural damping C = βK gives each undamped mode the damping ratio
/// ζ = βω/2, i.e. the log decrement δ = 2πζ/√(1−ζ²) (Rayleigh damping; e.g. Friswell et al. 2010,
/// §2.6): the first two modes of the pinned slender shaft with β = 1e-4 s, within 1 %.
#[test]
fn structural_damping_gives_rayleigh_log_decrements() {
    let yaml = format!(
        r#"
name: damped shaft
rated_speed_rpm: 3000
shaft_damping_beta_s: 1.0e-4
materials: {{steel: {{youngs_modulus_pa: {E}, poisson_ratio: {NU}, density_kg_m3: {RHO}}}}}
shaft: [{{length_m: 2.5, outer_diameter_m: 0.025, material: steel, elements: 40}}]
bearings:
  - {{name: left, node: 0, model: rigid}}
  - {{name: right, node: 40, model: rigid}}
"#
    );
    let rotor = Rotor::from_description(&MachineDescription::from_yaml(&yaml, "test").unwrap());
    let undamped = undamped_frequencies_hz(&rotor, Constraint::Pinned).unwrap();
    let modes = damped_modes(&rotor, 0.0, &[FilmCoefficients::default(); 2]).unwrap();
    for k in 0..2 {
        let omega = 2.0 * PI * undamped[k];
        let zeta = 1e-4 * omega / 2.0;
        let expected = 2.0 * PI * zeta / (1.0 - zeta * zeta).sqrt();
        let m = modes[2 * k];
        assert!(
            rel(m.log_dec, expected) < 0.01,
            "mode {k}: δ {} vs {expected}",
            m.log_dec
        );
    }
}
