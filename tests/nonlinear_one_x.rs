//! The nonlinear twin's steady 1X (`calibrate::nonlinear_one_x`, the trial run of the unbalance
//! refinement, issue 12) against the linear model's influence coefficients
//! (`rotor::influence_coefficients`, an independent route: the eight film coefficients at the
//! static equilibrium and a complex harmonic solve), on the built-in (B) at 8,000 rpm with the
//! unbalance at stage 7 (node 21). At a small unbalance the two must meet (the linearisation's
//! limit); at the 280 g·mm of the calibration tests they part, which is why the refinement exists.

use rotor_twin::calibrate::{nonlinear_one_x, NonlinearRefinement};
use rotor_twin::dynamics::FilmEvaluation;
use rotor_twin::rotor::{
    influence_coefficients, static_solution, MachineDescription, Rotor, UnbalanceSpec,
};

/// The built-in machine with its unbalance moved to stage 7 at 120°, `g_mm` g·mm.
fn machine(g_mm: f64) -> Rotor {
    let mut d = MachineDescription::builtin_default();
    d.unbalance = vec![UnbalanceSpec {
        node: 21,
        magnitude_g_mm: g_mm,
        phase_deg: 120.0,
        correction_radius_m: None,
    }];
    Rotor::from_description(&d)
}

/// The largest |X_nonlinear − X_linear| / |X_linear| over the probe stations and axes, and the
/// nonlinear 1X.
fn parting(g_mm: f64) -> (f64, Vec<[[f64; 2]; 2]>) {
    let rotor = machine(g_mm);
    let rpm = 8000.0;
    let how = NonlinearRefinement {
        film: FilmEvaluation::Direct,
        steps_per_rev: 64,
    };
    let nl = nonlinear_one_x(&rotor, rpm * std::f64::consts::PI / 30.0, how).unwrap();
    let statics = static_solution(&rotor).unwrap();
    let h = influence_coefficients(&rotor, &statics, rpm).unwrap();
    let u = &rotor.unbalance[0];
    let (s, c) = u.phase_rad.sin_cos();
    let mut worst = 0.0f64;
    for (k, station) in nl.iter().enumerate() {
        for (a, x) in station.iter().enumerate() {
            let hk = h[0][k][a];
            let lin = [
                u.magnitude_kg_m * (hk.re * c - hk.im * s),
                u.magnitude_kg_m * (hk.re * s + hk.im * c),
            ];
            let gap = (x[0] - lin[0]).hypot(x[1] - lin[1]) / lin[0].hypot(lin[1]);
            println!(
                "{g_mm} g·mm, station {k} axis {a}: nonlinear {:.4} µm, linear {:.4} µm, apart {:.2} %",
                x[0].hypot(x[1]) * 1e6,
                lin[0].hypot(lin[1]) * 1e6,
                100.0 * gap
            );
            worst = worst.max(gap);
        }
    }
    (worst, nl)
}

/// At a small unbalance the nonlinear twin's 1X is linear in it (10 g·mm gives twice 5 g·mm's
/// within 0.2 %: measured) and meets the influence coefficients within 2 % (measured 0.5–1.4 %
/// over the four probe axes; 64 and 256 steps a revolution, 24 and 400 revolutions settled give
/// the same to 0.05 %: the linear model's own route, the film coefficients by perturbation, not
/// the transient's steps); at 280 g·mm they part by more than 3 % (measured 4.0–10.3 %).
#[test]
fn the_nonlinear_one_x_meets_the_influence_coefficients_at_a_small_unbalance_and_parts_at_280() {
    let (small, x5) = parting(5.0);
    let (_, x10) = parting(10.0);
    let (large, _) = parting(280.0);
    println!(
        "apart: {:.3} % at 5 g·mm, {:.2} % at 280 g·mm",
        100.0 * small,
        100.0 * large
    );
    for (a, b) in x5.iter().flatten().zip(x10.iter().flatten()) {
        let ratio = b[0].hypot(b[1]) / a[0].hypot(a[1]);
        println!("10 / 5 g·mm: {ratio:.5}");
        assert!((ratio / 2.0 - 1.0).abs() < 0.002, "{ratio}");
    }
    assert!(small < 0.02, "{small}");
    assert!(large > 0.03, "{large}");
}
