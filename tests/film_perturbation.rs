//! The eight coefficients from the perturbation equations (seed eq. 3–4) against a second
//! method: central finite differences of the computed film force. Also: the warm start changes
//! nothing but the cost, and an equilibrium balances its load.

mod common;
use common::*;
use rotor_twin::film::{
    equilibrium_under_load, FilmCoefficients, FilmGrid, FilmModel, FiniteFilm, JournalKinematics,
    ShortFilm,
};

/// Each coefficient within 1 % of the largest entry of its matrix (an entry near zero, such as
/// k_yx around ε ≈ 0.7, has no meaningful relative error of its own).
fn assert_close(tag: &str, a: &FilmCoefficients, b: &FilmCoefficients) {
    let mut worst = 0.0_f64;
    for (name, m, r) in [
        ("k", a.stiffness_n_per_m, b.stiffness_n_per_m),
        ("c", a.damping_n_s_per_m, b.damping_n_s_per_m),
    ] {
        let scale = r.amax();
        for i in 0..2 {
            for j in 0..2 {
                let miss = (m[(i, j)] - r[(i, j)]).abs() / scale;
                worst = worst.max(miss);
                assert!(
                    miss < 0.01,
                    "{tag}: {name}{i}{j} perturbation {:.5e} vs difference {:.5e}",
                    m[(i, j)],
                    r[(i, j)]
                );
            }
        }
    }
    println!(
        "{tag}: largest difference {:.2e} of the matrix scale",
        worst
    );
}

fn states() -> Vec<JournalKinematics> {
    let (c, w) = (40e-6, OMEGA_9000_RPM);
    let at = |eps: f64, deg: f64, vx: f64, vy: f64| JournalKinematics {
        position_m: [
            eps * c * deg.to_radians().cos(),
            eps * c * deg.to_radians().sin(),
        ],
        velocity_m_s: [vx * c * w, vy * c * w],
        speed_rad_s: w,
    };
    vec![
        at(0.3, 60.0, 0.0, 0.0),
        at(0.6, 35.0, 0.0, 0.0),
        at(0.85, 200.0, 0.0, 0.0),
        // moving journals: the coefficients depend on velocity too (seed eq. 3–4)
        at(0.5, 45.0, 0.1, -0.05),
        at(0.7, 300.0, -0.08, 0.12),
    ]
}

#[test]
fn finite_film_perturbation_equals_finite_difference() {
    let mut film =
        FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::new(72, 12).unwrap()).unwrap();
    for (n, kin) in states().into_iter().enumerate() {
        let (_, pert) = film.solve_with_coefficients(&kin).unwrap();
        let fd = finite_difference(&mut film, kin, 1e-4 * 40e-6, 1e-4 * 40e-6 * OMEGA_9000_RPM);
        assert_close(&format!("finite, state {n}"), &pert, &fd);
    }
}

#[test]
fn short_film_perturbation_equals_finite_difference() {
    let mut film = ShortFilm::new(seed_bearing(0.5), mdm()).unwrap();
    for (n, kin) in states().into_iter().enumerate() {
        let (_, pert) = film.solve_with_coefficients(&kin).unwrap();
        let fd = finite_difference(&mut film, kin, 1e-6 * 40e-6, 1e-6 * 40e-6 * OMEGA_9000_RPM);
        assert_close(&format!("short, state {n}"), &pert, &fd);
    }
}

/// A warm-started solve lands on the same solution as a cold one (to round-off), whatever the
/// previous state was.
#[test]
fn warm_start_changes_nothing_but_the_cost() {
    let mut warm = FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::DEFAULT).unwrap();
    let mut cold = warm.clone();
    let states = states();
    for (n, kin) in states.iter().enumerate() {
        // warm: starts from the previous state's pressure zone
        let a = warm.solve(kin).unwrap();
        cold.reset_warm_start();
        let b = cold.solve(kin).unwrap();
        for i in 0..2 {
            assert!(
                (a.force_n[i] - b.force_n[i]).abs() <= 1e-9 * b.force_n[i].abs().max(1.0),
                "state {n}"
            );
        }
        assert_eq!(a.film_end_rad, b.film_end_rad, "state {n}");
    }
}

/// At the equilibrium the film force balances the load, for both models and any load direction.
#[test]
fn equilibrium_balances_the_load() {
    for load in [[275.0, 0.0], [0.0, -1500.0], [-800.0, 600.0]] {
        let mut finite = FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::DEFAULT).unwrap();
        let mut short = ShortFilm::new(seed_bearing(0.5), mdm()).unwrap();
        for model in [&mut finite as &mut dyn FilmModel, &mut short] {
            let e = equilibrium_under_load(model, 0.0008, load, OMEGA_9000_RPM).unwrap();
            let f = e.film.force_n;
            let w = load[0].hypot(load[1]);
            assert!(
                (f[0] + load[0]).hypot(f[1] + load[1]) < 1e-6 * w,
                "{load:?}: {f:?}"
            );
            assert!(e.eccentricity_ratio > 0.0 && e.eccentricity_ratio < 1.0);
        }
    }
}
