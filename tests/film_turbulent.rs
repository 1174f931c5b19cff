//! The turbulent film (issue 18; `src/film/turbulence.rs`, eq. T1–T3): its laminar limit, its
//! coefficients against a second method, and its short-bearing limit against the Ng–Pan short
//! bearing closed form (an independent quadrature, not the solver).

mod common;
use common::finite_difference;
use nalgebra::Matrix2;
use rotor_twin::film::{
    BearingGeometry, FilmCoefficients, FilmGrid, FilmModel, FilmResult, FiniteFilm, FlowRegime,
    JournalKinematics, Lubricant,
};
use std::f64::consts::PI;

fn film(length_m: f64, density: f64, grid: FilmGrid, flow: FlowRegime) -> FiniteFilm {
    let g = BearingGeometry::plain(0.060, length_m, 40e-6).unwrap();
    let oil = Lubricant::new(density, 0.8e-3).unwrap();
    FiniteFilm::new(g, oil, grid).unwrap().with_flow(flow)
}

fn kin(eps: f64, attitude: f64, rpm: f64, velocity: [f64; 2]) -> JournalKinematics {
    JournalKinematics {
        position_m: [eps * 40e-6 * attitude.cos(), eps * 40e-6 * attitude.sin()],
        velocity_m_s: velocity,
        speed_rad_s: rpm * PI / 30.0,
    }
}

/// Re → 0 (density 1e-9 kg/m³: Re ≈ 1e-9): the turbulent solver is the laminar one to 1e-9, in
/// force, power, the eight coefficients, at rest and moving.
#[test]
fn the_turbulent_film_at_vanishing_reynolds_number_is_the_laminar_film() {
    let grid = FilmGrid::new(60, 10).unwrap();
    let mut lam = film(0.03, 1e-9, grid, FlowRegime::Laminar);
    let mut tur = film(0.03, 1e-9, grid, FlowRegime::Turbulent);
    for k in [
        kin(0.53, 0.93, 9000.0, [0.0; 2]),
        kin(0.8, -2.0, 5000.0, [3e-3, -2e-3]),
    ] {
        let a = lam.solve_with_coefficients(&k).unwrap();
        let b = tur.solve_with_coefficients(&k).unwrap();
        assert_same_film(&a, &b, 1e-9);
    }
}

/// Force, power loss and the eight coefficients of `a` equal `b`'s to `tol` (relative to the
/// force's size and each matrix's largest entry).
fn assert_same_film(
    (a, ca): &(FilmResult, FilmCoefficients),
    (b, cb): &(FilmResult, FilmCoefficients),
    tol: f64,
) {
    let size = b.force_n[0].hypot(b.force_n[1]);
    for i in 0..2 {
        assert!(
            (a.force_n[i] - b.force_n[i]).abs() < tol * size,
            "{a:?} vs {b:?}"
        );
    }
    assert!((a.power_loss_w / b.power_loss_w - 1.0).abs() < tol);
    let close = |x: &Matrix2<f64>, y: &Matrix2<f64>| (x - y).amax() < tol * x.amax();
    assert!(close(&ca.stiffness_n_per_m, &cb.stiffness_n_per_m));
    assert!(close(&ca.damping_n_s_per_m, &cb.damping_n_s_per_m));
}

/// Second method: the turbulent perturbation coefficients (the conductances' slopes dG/dH with
/// dk/dH) against central differences of the turbulent force, the seed bearing at Re 1,270 and
/// 2,540 (density ×2), at rest and moving. 1 % of the matrix's largest entry (as the laminar
/// check in `film_perturbation.rs`).
#[test]
fn turbulent_coefficients_are_the_slopes_of_the_turbulent_force() {
    let grid = FilmGrid::new(60, 10).unwrap();
    for density in [900.0, 1800.0] {
        let mut f = film(0.03, density, grid, FlowRegime::Turbulent);
        for k in [
            kin(0.5, 0.9, 9000.0, [0.0; 2]),
            kin(0.7, 2.5, 9000.0, [2e-3, 1e-3]),
        ] {
            let (_, c) = f.solve_with_coefficients(&k).unwrap();
            let fd = finite_difference(&mut f, k, 1e-9, 1e-5);
            for (m, n) in [
                (&c.stiffness_n_per_m, &fd.stiffness_n_per_m),
                (&c.damping_n_s_per_m, &fd.damping_n_s_per_m),
            ] {
                let s = m.amax();
                for (p, q) in m.iter().zip(n.iter()) {
                    assert!((p - q).abs() < 0.01 * s, "ρ {density}: {m:?} vs {n:?}");
                }
            }
        }
    }
}

/// The Ng–Pan short bearing: with ∂p/∂x dropped, eq. T1 gives Ocvirk's pressure times
/// k_z(Re_h)/12 at each angle, so its load is ∫ (k_z/12)·(Ocvirk's ∫p dz) over the π film, the
/// Taylor–Dowson k_z = 12 + 0.0043 Re_h^0.96 (an independent quadrature here). At L/D 1/8 the
/// finite solver's turbulent-to-laminar load ratio equals the short form's within 1 % (the
/// laminar finite and short loads themselves differ by 1.9 % at this L/D: README validation).
#[test]
fn turbulent_short_limit_matches_the_ng_pan_short_bearing() {
    let (l, c, r) = (0.060 / 8.0, 40e-6, 0.030);
    let grid = FilmGrid::new(120, 10).unwrap();
    for (density, eps) in [(900.0, 0.5), (1800.0, 0.7)] {
        let k = kin(eps, 0.0, 9000.0, [0.0; 2]);
        let load = |flow| {
            let mut f = film(l, density, grid, flow);
            let res = f.solve(&k).unwrap();
            res.force_n[0].hypot(res.force_n[1])
        };
        let finite_ratio = load(FlowRegime::Turbulent) / load(FlowRegime::Laminar);
        // short form: ∫p dz ∝ ∂h/∂θ / h³ · k_z(Re h)/12 with h = c(1 − ε cos θ) (journal on +x):
        // pressure where h decreases, force components by the midpoint rule
        let re = density * (9000.0 * PI / 30.0) * r * c / 0.8e-3;
        let n = 200_000;
        let (mut lam, mut tur) = ([0.0; 2], [0.0; 2]);
        for i in 0..n {
            let t = (i as f64 + 0.5) * 2.0 * PI / n as f64;
            let h = 1.0 - eps * t.cos();
            let dh = eps * t.sin();
            if dh >= 0.0 {
                continue; // diverging film: cavitated (π film)
            }
            let p = -dh / h.powi(3);
            let kz = 12.0 + 0.0043 * (re * h).powf(0.96);
            for (a, f) in [(&mut lam, 1.0), (&mut tur, kz / 12.0)] {
                a[0] += f * p * t.cos();
                a[1] += f * p * t.sin();
            }
        }
        let short_ratio = tur[0].hypot(tur[1]) / lam[0].hypot(lam[1]);
        println!("ρ {density} ε {eps}: finite {finite_ratio:.4}, short {short_ratio:.4}");
        assert!(short_ratio > 1.05, "turbulence must show: {short_ratio}");
        assert!((finite_ratio / short_ratio - 1.0).abs() < 0.01);
    }
}

/// `flow: turbulent` in the machine file reaches the film, and a viscosity scale (a live oil
/// temperature, a heat balance, a calibration) is exact for it: the scaled film takes its
/// Reynolds number at the scaled viscosity (session 20; it was refused before, since Re = ρωRc/µ
/// changes with µ). Reference: a turbulent film built with the scaled viscosity itself, to
/// 1e-10 in force, power and the eight coefficients, at ×0.8 and ×1.1; scaling the outputs with
/// Re held at the file's µ (the naive scaling) would be off by more than 0.5 % (printed). A
/// short-bearing entry with turbulent flow is refused. (The table takes turbulent flow since
/// session 12, over (ε, ψ, Re): `tests/film_turbulent_table.rs`.)
#[test]
fn turbulent_films_scale_with_viscosity_through_their_reynolds_number() {
    use rotor_twin::rotor::{BearingModel, MachineDescription, Rotor};
    let text = std::fs::read_to_string("config/orc_microturbine_100kw.yaml").unwrap();
    let turbulent = text.replace("    grid: 60x10", "    grid: 60x10\n    flow: turbulent");
    let desc = MachineDescription::from_yaml(&turbulent, "t.yaml").unwrap();
    let mut rotor = Rotor::from_description(&desc);
    let grid = FilmGrid::new(60, 10).unwrap();
    let k = kin(0.6, -0.9, 9000.0, [2e-3, -1e-3]);
    for scale in [0.8, 1.1] {
        rotor.set_viscosity_scale(scale).unwrap();
        let BearingModel::Film(f) = &rotor.bearings[0].model else {
            panic!("film bearing expected")
        };
        assert_eq!(f.flow, FlowRegime::Turbulent);
        let (a, ca) = f.solver().solve_with_coefficients(&k).unwrap();
        let g = f.geometry.clone();
        let oil = Lubricant::new(
            f.lubricant.density_kg_m3,
            f.lubricant.viscosity_pa_s * scale,
        );
        let mut exact = FiniteFilm::new(g.clone(), oil.unwrap(), grid)
            .unwrap()
            .with_flow(FlowRegime::Turbulent);
        let (b, cb) = exact.solve_with_coefficients(&k).unwrap();
        let mut naive = FiniteFilm::new(g, f.lubricant, grid)
            .unwrap()
            .with_flow(FlowRegime::Turbulent);
        let n = naive.solve(&k).unwrap();
        let size = b.force_n[0].hypot(b.force_n[1]);
        let naive_off =
            (n.force_n[0] * scale - b.force_n[0]).hypot(n.force_n[1] * scale - b.force_n[1]) / size;
        println!(
            "×{scale}: scaled {:?} N, exact {:?} N; naive scaling off by {:.2} %",
            a.force_n,
            b.force_n,
            100.0 * naive_off
        );
        assert_same_film(&(a, ca), &(b, cb), 1e-10);
        assert!(
            naive_off > 5e-3,
            "the check must be able to fail: {naive_off}"
        );
    }
    let short = turbulent.replacen("model: finite", "model: short", 1);
    let err = MachineDescription::from_yaml(&short, "s.yaml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("flow"), "{err}");
}
