//! The short-bearing model against the closed forms of Ocvirk's theory (Friswell et al.,
//! *Dynamics of Rotating Machines*, CUP 2010, ch. 5; ../shared/reference/closed_forms.md), and the
//! finite solver approaching it as L/D → 0.

mod common;
use common::*;
use rotor_twin::film::{
    equilibrium_at_eccentricity, FilmGrid, FilmModel, FiniteFilm, JournalKinematics, ShortFilm,
};
use std::f64::consts::PI;

#[test]
fn short_model_matches_ocvirk_closed_forms() {
    let (c, w, mu) = (40e-6, OMEGA_9000_RPM, mdm().viscosity_pa_s);
    let ld = 0.5;
    for eps in [0.2, 0.5, 0.8] {
        let mut film = ShortFilm::new(seed_bearing(ld), mdm()).unwrap();
        let e = equilibrium_at_eccentricity(&mut film, mu, eps, w).unwrap();
        let phi_ref = (PI * (1.0 - eps * eps).sqrt() / (4.0 * eps)).atan();
        let q = 1.0 - eps * eps;
        let s_ref = q * q / (PI * eps * (16.0 * eps * eps + PI * PI * q).sqrt()) / (ld * ld);
        assert!((e.attitude_angle_rad - phi_ref).abs() < 1e-6, "ε {eps}: φ");
        assert!(
            rel(e.sommerfeld_number, s_ref) < 1e-6,
            "ε {eps}: S {} vs {s_ref}",
            e.sommerfeld_number
        );
        let load = e.load_n[0];
        let k = e.coefficients.dimensionless_stiffness(load, c);
        let b = e.coefficients.dimensionless_damping(load, c, w);
        let (k_ref, b_ref) = short_bearing_coefficients(eps);
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (k[(i, j)] - k_ref[i][j]).abs() < 1e-6 * (1.0 + k_ref[i][j].abs()),
                    "ε {eps} K{i}{j}: {} vs {}",
                    k[(i, j)],
                    k_ref[i][j]
                );
                assert!(
                    (b[(i, j)] - b_ref[i][j]).abs() < 1e-6 * (1.0 + b_ref[i][j].abs()),
                    "ε {eps} B{i}{j}: {} vs {}",
                    b[(i, j)],
                    b_ref[i][j]
                );
            }
        }
    }
}

/// The spot values printed in closed_forms.md at ε = 0.5 (to their last digit).
#[test]
fn short_model_reproduces_published_spot_values() {
    let mut film = ShortFilm::new(seed_bearing(0.5), mdm()).unwrap();
    let e = equilibrium_at_eccentricity(&mut film, 0.0008, 0.5, OMEGA_9000_RPM).unwrap();
    let load = e.load_n[0];
    let k = e.coefficients.dimensionless_stiffness(load, 40e-6);
    let b = e
        .coefficients
        .dimensionless_damping(load, 40e-6, OMEGA_9000_RPM);
    assert!((e.attitude_angle_rad.to_degrees() - 53.68).abs() < 0.005);
    let k_ref = [[2.923, 3.977], [-0.858, 2.210]];
    let b_ref = [[6.615, 2.245], [2.245, 3.054]];
    for i in 0..2 {
        for j in 0..2 {
            assert!(
                (k[(i, j)] - k_ref[i][j]).abs() < 0.0006,
                "K{i}{j} {}",
                k[(i, j)]
            );
            assert!(
                (b[(i, j)] - b_ref[i][j]).abs() < 0.0006,
                "B{i}{j} {}",
                b[(i, j)]
            );
        }
    }
}

/// Force components along and across the line of centres for a journal displaced in an
/// arbitrary direction: F_r = −µUL³/c² ε²/(1−ε²)², F_t = µUL³/(4c²) πε/(1−ε²)^1.5.
#[test]
fn short_model_force_components_in_any_direction() {
    let (r, l, c, mu, w): (f64, f64, f64, f64, f64) = (0.03, 0.03, 40e-6, 0.0008, OMEGA_9000_RPM);
    let mut film = ShortFilm::new(seed_bearing(0.5), mdm()).unwrap();
    for (eps, angle_deg) in [(0.3_f64, 40.0_f64), (0.7, 200.0)] {
        let a = angle_deg.to_radians();
        let kin = JournalKinematics::at_position([eps * c * a.cos(), eps * c * a.sin()], w);
        let f = film.solve(&kin).unwrap().force_n;
        let radial = f[0] * a.cos() + f[1] * a.sin();
        let tangential = -f[0] * a.sin() + f[1] * a.cos();
        let u = w * r;
        let fr = -mu * u * l.powi(3) / (c * c) * eps * eps / (1.0 - eps * eps).powi(2);
        let ft = mu * u * l.powi(3) / (4.0 * c * c) * PI * eps / (1.0 - eps * eps).powf(1.5);
        assert!(rel(radial, fr) < 1e-8, "ε {eps}: F_r {radial} vs {fr}");
        assert!(
            rel(tangential, ft) < 1e-8,
            "ε {eps}: F_t {tangential} vs {ft}"
        );
    }
}

/// As L/D → 0 the finite solution (Reynolds condition) approaches the short-bearing one
/// (π-film): the gap in load capacity shrinks at every halving of L/D (measured: 6.1 %, 1.9 %,
/// 0.8 % at L/D = 1/4, 1/8, 1/16 for ε = 0.5), and at L/D = 1/16 the
/// two agree within 2 % in S and 1° in φ.
#[test]
fn finite_film_tends_to_short_bearing_as_length_shrinks() {
    let (mu, w) = (mdm().viscosity_pa_s, OMEGA_9000_RPM);
    let mut gaps = Vec::new();
    for ld in [0.25, 0.125, 0.0625] {
        let mut finite =
            FiniteFilm::new(seed_bearing(ld), mdm(), FilmGrid::new(240, 8).unwrap()).unwrap();
        let mut short = ShortFilm::new(seed_bearing(ld), mdm()).unwrap();
        let ef = equilibrium_at_eccentricity(&mut finite, mu, 0.5, w).unwrap();
        let es = equilibrium_at_eccentricity(&mut short, mu, 0.5, w).unwrap();
        let ds = rel(ef.sommerfeld_number, es.sommerfeld_number);
        let dphi = (ef.attitude_angle_rad - es.attitude_angle_rad)
            .to_degrees()
            .abs();
        println!(
            "L/D {ld}: S finite {:.5} short {:.5} ({:.2} %), φ gap {dphi:.2}°",
            ef.sommerfeld_number,
            es.sommerfeld_number,
            100.0 * ds
        );
        gaps.push((ds, dphi));
    }
    assert!(
        gaps[1].0 < 0.75 * gaps[0].0 && gaps[2].0 < 0.75 * gaps[1].0,
        "{gaps:?}"
    );
    assert!(gaps[2].0 < 0.02 && gaps[2].1 < 1.0, "{gaps:?}");
}
