//! Critical speeds and mode labels of the textbook rotor (config/textbook_disc_midspan.yaml)
//! against its closed form: a disc of mass m, polar and diametral inertias Ip, Id at the middle of
//! a massless Timoshenko shaft on pinned supports (Friswell et al., *Dynamics of Rotating
//! Machines*, CUP 2010, §3.6; Genta, *Dynamics of Rotating Systems*, Springer 2005, §4.4).
//! At midspan translation and tilt decouple: the translation whirls at ω = √(k/m) forward and
//! backward at every speed (a repeated eigenvalue), the tilt at
//! ω_f,b = [√((IpΩ)² + 4 Id kθ) ± IpΩ]/(2Id). The forward translation crosses 1X at
//! Ω = √(k/m): the one forward critical speed, since the forward tilt would need
//! (Id − Ip)Ω² = kθ and Ip > Id (a disc-like rotor has no forward tilt critical speed).

use rotor_twin::rotor::{
    campbell, critical_speeds, natural_frequencies, static_solution, Constraint,
    MachineDescription, Rotor, WhirlDirection,
};
use std::f64::consts::PI;

const E: f64 = 2.1e11;
const NU: f64 = 0.3;

fn textbook() -> Rotor {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/textbook_disc_midspan.yaml");
    Rotor::from_description(&MachineDescription::from_file(&path).unwrap())
}

/// Translation stiffness k (N/m) and tilt stiffness kθ (N·m/rad) at midspan, Timoshenko
/// flexibilities 1/k = L³/(48EI) + L/(4κGA), 1/kθ = L/(12EI) + 1/(κGAL), κ of Cowper (1966).
fn midspan_stiffnesses() -> (f64, f64) {
    let (d, l): (f64, f64) = (0.03, 0.8);
    let ei = E * PI * d.powi(4) / 64.0;
    let kga = 6.0 * (1.0 + NU) / (7.0 + 6.0 * NU) * E / (2.0 * (1.0 + NU)) * PI * d * d / 4.0;
    (
        1.0 / (l.powi(3) / (48.0 * ei) + l / (4.0 * kga)),
        1.0 / (l / (12.0 * ei) + 1.0 / (kga * l)),
    )
}

/// One forward critical speed in 300–6,000 rpm, at 60·√(k/m)/(2π) rpm within 0.02 % (the FE
/// model is exact for a point load on a Timoshenko beam to 1e-4, tests/rotor_fe.rs; the
/// translation frequency does not vary with speed, so interpolating the crossing adds nothing).
/// Four modes, each followed by its shape, each keeping its whirl sense at every speed.
#[test]
fn textbook_rotor_has_the_closed_form_critical_speed_and_no_spurious_ones() {
    let rotor = textbook();
    let statics = static_solution(&rotor).unwrap();
    let speeds: Vec<f64> = (0..=38).map(|i| 300.0 + 150.0 * i as f64).collect();
    let points = campbell(&rotor, &statics, &speeds, 6).unwrap();
    let (k, _) = midspan_stiffnesses();
    let expected_rpm = (k / 20.0).sqrt() * 30.0 / PI;
    let found = critical_speeds(&points);
    println!("critical speeds {found:?}, closed form {expected_rpm:.2} rpm");
    assert_eq!(found.len(), 1, "{found:?}");
    let rel = (found[0].speed_rpm - expected_rpm).abs() / expected_rpm;
    assert!(rel < 2e-4, "{} vs {expected_rpm}", found[0].speed_rpm);
    // the massless shaft's own modes (MHz) are not in the diagram: four modes at each speed
    for p in &points {
        assert_eq!(p.modes.len(), 4, "{} rpm", p.speed_rpm);
        assert!(p.modes.iter().all(|m| m.frequency_hz < 300.0));
    }
    // each track keeps its sense: 0/1 the translation pair, 2/3 the tilt pair
    for id in 0..4 {
        let senses: Vec<WhirlDirection> = points
            .iter()
            .map(|p| p.modes[p.tracks.iter().position(|&t| t == id).unwrap()].direction)
            .collect();
        assert!(
            senses.iter().all(|s| *s == senses[0]),
            "track {id}: {senses:?}"
        );
    }
}

/// At rest, pinned: the translation √(k/m) and tilt √(kθ/Id) frequencies once each (1e-4);
/// free–free: no mode of the machine (the rigid disc on a massless shaft has only rigid-body
/// modes), and the massless shaft's own modes set apart, not reported as the machine's.
#[test]
fn textbook_rotor_natural_frequencies_leave_out_the_massless_shafts_own_modes() {
    let rotor = textbook();
    let (k, k_tilt) = midspan_stiffnesses();
    let pinned = natural_frequencies(&rotor, Constraint::Pinned).unwrap();
    let expected = [
        (k / 20.0).sqrt() / (2.0 * PI),
        (k_tilt / 0.15).sqrt() / (2.0 * PI),
    ];
    assert_eq!(pinned.hz.len(), 2, "{pinned:?}");
    for (f, e) in pinned.hz.iter().zip(expected) {
        assert!((f - e).abs() < 1e-4 * e, "{f} vs {e}");
    }
    let free = natural_frequencies(&rotor, Constraint::FreeFree).unwrap();
    assert!(free.hz.is_empty(), "{free:?}");
    assert!(free.massless_shaft_hz.first().is_some_and(|f| *f > 1e5));
}
