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
    common::journal_state(c, OMEGA_9000_RPM, eps, phi, vr, vt)
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
/// sub-phases (32 in all): a reference whose own phase dependence (against 128 phases) is
/// ≤ 0.25 % of the coefficient scale up to ε 0.98 and ≤ 0.45 % beyond (measured by
/// `coefficient_reference_diagnosis`).
fn finer_phase_average(
    direct: &mut FiniteFilm,
    kin: &JournalKinematics,
) -> rotor_twin::film::FilmCoefficients {
    analytic_reference(direct, kin, 60, 4)
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
    let (mut worst, mut worst_at) = (0.0_f64, 0.0);
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
        let e = common::coefficient_error(&a, &b, OMEGA_9000_RPM);
        if e > worst {
            (worst, worst_at) = (e, eps);
        }
    }
    println!("table coefficients over the whip domain: worst {worst:.4} of scale at ε {worst_at}");
    assert!(worst < 0.005, "worst {worst} at ε {worst_at}");
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

/// The table's force and eight coefficients over the whole domain a whip visits (ε 0–0.995
/// in 8 bands, any attitude, radial and tangential velocities up to ±0.6 c ω: `banded_states`,
/// 20 states a band) against the direct solver averaged over 32 grid phases (128 for the
/// coefficients in ε 0.98–0.995, [`WALL_BAND`]) (force: of |F|;
/// coefficients: of the state's coefficient scale, `coefficient_error`): within the issue's
/// 0.5 % everywhere. Measured, by band (`BANDS`), this table (u = atanh ε, 160 rows, 192
/// columns × 8 phases, and 384 columns × 32 phases on the 98 rows at ε ≥ 0.90 (`WallRows`),
/// U with the grid's Couette factor κ, the force in the source's frame): force 0.001, 0.001,
/// 0.001, 0.001, 0.010, 0.001, 0.006, 0.014 %; coefficients 0.110, 0.073, 0.157, 0.124, 0.271,
/// 0.187, 0.278, 0.274 % (session 14; with the wall rows from ε 0.95, session 13: 0.11, 0.07,
/// 0.16, 0.12, 0.23, 0.32, 0.28, 0.27 %). The uniform 160 × 192 × 8 table of session
/// 12 (main) reads 0.46 % in ε 0.95–0.98 and 1.17 % in ε 0.98–0.995, where the developed whip
/// of the built-in rotor at 9,000 rpm spends all its time (ε 0.985–0.993): it fails here. The
/// cause was the interpolation in ψ (session 12, `wall_error_decomposition`); finer columns
/// alone do not do (512 × 8 on the wall rows: 0.61 / 1.63 %), as the phase average's jitter
/// along ψ is divided by the spacing in the ψ-slope: 512 × 16 0.33 / 0.67 %, 256 × 32
/// 0.60 / 0.81 %, 384 × 32 0.28 / 0.27 %, 512 × 32 0.25 / 0.27 %. With the force held along the
/// line of centres (session 10) the coefficients were 0.77 % at the centre: it fails here too.
#[test]
fn force_and_coefficients_over_the_whole_domain() {
    let (mut table, _, _, _) = models();
    let (ef, ec) = banded_errors(&mut table, &banded_states(STATES_PER_BAND));
    for (b, range) in BANDS.iter().enumerate() {
        println!(
            "ε {range:?}: force {:.3} %, coefficients {:.3} %",
            100.0 * ef[b],
            100.0 * ec[b]
        );
    }
    // allowed, % by band
    let force = [0.5; 8];
    let coefficients = [0.5; 8];
    for (b, range) in BANDS.iter().enumerate() {
        assert!(
            100.0 * ef[b] < force[b],
            "force, ε {range:?}: worst {}",
            ef[b]
        );
        assert!(
            100.0 * ec[b] < coefficients[b],
            "coefficients, ε {range:?}: worst {}",
            ec[b]
        );
    }
}

/// A second, independent set of states for the whole domain (the referee of session 13: the
/// wall rows at ε ≥ 0.95 were chosen on `banded_states`' own states, seed 0x57D1): the same 8
/// bands, the same number of states a band (so 40 beyond ε 0.95 and 100 in the whip's ε
/// 0.3–0.995), drawn from another sequence, the 4-dimensional Kronecker (R₄) sequence of
/// Roberts (2018, "The unreasonable effectiveness of quasirandom sequences": x_n = frac(½ +
/// n α), α_j = g^−(j+1), g the real root of g⁵ = g + 1) over (ε in the band, attitude,
/// radial and tangential velocity up to ±0.6 c ω); the same references (32 grid phases, 128 for
/// the coefficients in ε 0.98–0.995) and the same bound, 0.5 % in every band (issue 11).
/// Measured with the wall rows from ε 0.90 (session 14): force ≤ 0.031 %; coefficients 0.223,
/// 0.094, 0.087, 0.114, 0.187, 0.217, 0.311, 0.332 % by band. With the wall rows from ε 0.95
/// (session 13) this set found their edge: 0.637 % in ε 0.95–0.98 at one state, ε 0.9504
/// (0.700 % against 128 phases: the table, not the reference); `second_set_diagnosis` scanned
/// it: 1.88 % at ε 0.950, 0.55 % at 0.948. From ε 0.90 the scan over ε 0.890–0.910
/// (`EDGE_SCAN_FROM=0.890`) reads ≤ 0.38 % (0.376 % at 0.897 and 0.900).
#[test]
fn force_and_coefficients_over_the_whole_domain_on_a_second_set() {
    let (mut table, _, _, _) = models();
    let (ef, ec) = banded_errors(&mut table, &second_set(STATES_PER_BAND));
    for (b, range) in BANDS.iter().enumerate() {
        println!(
            "second set, ε {range:?}: force {:.3} %, coefficients {:.3} %",
            100.0 * ef[b],
            100.0 * ec[b]
        );
    }
    // allowed, % by band: the 0.5 %
    for (b, range) in BANDS.iter().enumerate() {
        assert!(100.0 * ef[b] < 0.5, "force, ε {range:?}: worst {}", ef[b]);
        assert!(
            100.0 * ec[b] < 0.5,
            "coefficients, ε {range:?}: worst {}",
            ec[b]
        );
    }
}

/// `per_band` states in each band of [`BANDS`] from the R₄ Kronecker sequence (see
/// `force_and_coefficients_over_the_whole_domain_on_a_second_set`) with their direct references.
fn second_set(per_band: usize) -> Vec<Referenced> {
    let g = (0..60).fold(1.0_f64, |g, _| (1.0 + g).powf(0.2));
    let alpha: [f64; 4] = std::array::from_fn(|j| g.powi(-(j as i32 + 1)));
    let mut n = 0_u32;
    referenced_states(per_band, |c, (lo, hi)| {
        n += 1;
        let u: [f64; 4] = std::array::from_fn(|j| (0.5 + f64::from(n) * alpha[j]).fract());
        state(
            c,
            lo + (hi - lo) * u[0],
            TAU * u[1],
            1.2 * (u[2] - 0.5),
            1.2 * (u[3] - 0.5),
        )
    })
}

/// The second set's coefficient error in ε 0.9–0.995 against the 32-phase reference (A32, the
/// test's below ε 0.98) and the 128-phase one (A128), per state: which of the table and the
/// reference a miss is (a diagnosis, run by hand: `-- --ignored --nocapture
/// second_set_diagnosis`; the table from the tests' disk cache when there).
#[test]
#[ignore]
fn second_set_diagnosis() {
    rotor_twin::film::set_disk_cache(Some(rotor_twin::film::TableCache::new(
        common::test_cache_dir(),
    )));
    let (mut table, mut direct, c, nt) = models();
    for (b, kin, _, a) in second_set(STATES_PER_BAND).iter().filter(|s| s.0 >= 5) {
        let (_, k) = table.solve_with_coefficients(kin).unwrap();
        let a128 = analytic_reference(&mut direct, kin, nt, 16);
        let e = |r| 100.0 * common::coefficient_error(r, &k, kin.speed_rad_s);
        let eps = kin.position_m[0].hypot(kin.position_m[1]) / c;
        println!(
            "band {b} ε {eps:.5}: table–A32 {:.3} %, table–A128 {:.3} %, A32–A128 {:.3} %",
            e(a),
            e(&a128),
            100.0 * common::coefficient_error(&a128, a, kin.speed_rad_s)
        );
    }
    // the edge of the wall rows (ε 0.95): worst of 12 states (any attitude, ±0.6 c ω) per ε
    let mut rng = Rng(0xED6E);
    let start: f64 = std::env::var("EDGE_SCAN_FROM")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.940);
    for i in 0..=20 {
        let eps = start + 0.001 * f64::from(i);
        let worst = (0..12)
            .map(|_| {
                let kin = state(
                    c,
                    eps,
                    TAU * rng.next(),
                    1.2 * (rng.next() - 0.5),
                    1.2 * (rng.next() - 0.5),
                );
                let (_, k) = table.solve_with_coefficients(&kin).unwrap();
                let a128 = analytic_reference(&mut direct, &kin, nt, 16);
                common::coefficient_error(&a128, &k, kin.speed_rad_s)
            })
            .fold(0.0_f64, f64::max);
        println!("edge ε {eps:.3}: worst table–A128 {:.3} %", 100.0 * worst);
    }
}

/// The coefficients near the centre, where those across the line of centres are the
/// difference of two terms of order 1/ε (the frame's turn and ∂f/∂ψ): at ε 0.001–0.03, any
/// attitude and velocities up to ±0.6 c ω, against the direct solver's perturbation
/// coefficients averaged over 32 grid phases (`finer_phase_average`), within 0.5 % of the
/// state's coefficient scale (`coefficient_error`). With the force held along the line of
/// centres (session 10) the interpolation error of ∂f/∂ψ was multiplied by 1/ε: measured
/// 0.77 % in ε 0–0.03 and growing toward the centre, so this failed there.
#[test]
fn coefficients_near_the_centre_agree() {
    let (mut table, _, _, _) = models();
    let (worst, worst_at) = centre_error(&mut table);
    println!("centre: worst {:.4} % at ε {worst_at}", 100.0 * worst);
    assert!(worst < 0.005, "worst {worst} at ε {worst_at}");
}

/// The worst coefficient error of `table` at the states of `coefficients_near_the_centre_agree`
/// and the ε where it is.
fn centre_error(table: &mut TabulatedFilm) -> (f64, f64) {
    let geometry = seed_bearing(0.5);
    let c = geometry.radial_clearance_m;
    let mut direct = FiniteFilm::new(geometry, mdm(), FilmGrid::new(60, 10).unwrap()).unwrap();
    let mut rng = Rng(0xCE47);
    let (mut worst, mut worst_at) = (0.0_f64, 0.0);
    for eps in [0.001, 0.002, 0.005, 0.01, 0.02, 0.03] {
        for _ in 0..4 {
            let kin = state(
                c,
                eps,
                TAU * rng.next(),
                1.2 * (rng.next() - 0.5),
                1.2 * (rng.next() - 0.5),
            );
            let a = finer_phase_average(&mut direct, &kin);
            let (_, b) = table.solve_with_coefficients(&kin).unwrap();
            let e = common::coefficient_error(&a, &b, OMEGA_9000_RPM);
            if e > worst {
                (worst, worst_at) = (e, eps);
            }
        }
    }
    (worst, worst_at)
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

/// The direct force averaged over 32 grid phases (4 sub-phases of the 8-phase average): the
/// converged phase average the study measures the table against (N).
fn force_reference_32(direct: &mut FiniteFilm, kin: &JournalKinematics, nt: usize) -> [f64; 2] {
    force_reference(direct, kin, nt, 4)
}

/// The direct force averaged over 8 × `sub` grid phases (N).
fn force_reference(
    direct: &mut FiniteFilm,
    kin: &JournalKinematics,
    nt: usize,
    sub: usize,
) -> [f64; 2] {
    let mut f = [0.0; 2];
    let share = 1.0 / sub as f64;
    for k in 0..sub {
        let a = k as f64 * TAU / nt as f64 / (8 * sub) as f64;
        let (ca, sa) = (a.cos(), a.sin());
        let turned = JournalKinematics {
            position_m: [
                ca * kin.position_m[0] - sa * kin.position_m[1],
                sa * kin.position_m[0] + ca * kin.position_m[1],
            ],
            velocity_m_s: [
                ca * kin.velocity_m_s[0] - sa * kin.velocity_m_s[1],
                sa * kin.velocity_m_s[0] + ca * kin.velocity_m_s[1],
            ],
            speed_rad_s: kin.speed_rad_s,
        };
        let (g, _, _) = phase_averaged(direct, &turned, nt);
        f[0] += share * (ca * g[0] + sa * g[1]);
        f[1] += share * (-sa * g[0] + ca * g[1]);
    }
    f
}

use common::ECC_BANDS as BANDS;

/// States a band of [`BANDS`] in the tests of the whole domain (and the study's default).
const STATES_PER_BAND: usize = 20;

/// A journal state of band `.0` with its 32-phase direct force and coefficients.
type Referenced = (
    usize,
    JournalKinematics,
    [f64; 2],
    rotor_twin::film::FilmCoefficients,
);

/// The first band of [`BANDS`] whose coefficient reference averages 128 grid phases, not 32
/// (ε 0.98–0.995): there the 32-phase average still moves by up to 0.45 % of the coefficient
/// scale on the way to 128 (`coefficient_reference_diagnosis`), as much as the bound;
/// two 128-phase averages (from a grid line and from the state's attitude) differ by ≤ 0.12 %
/// (`wall_error_decomposition`).
const WALL_BAND: usize = 7;

/// `per_band` states in each band of [`BANDS`] (`whip_state`, seed 0x57D1) with their direct
/// references (force: 32 grid phases; coefficients: 32, 128 from [`WALL_BAND`] on): the same
/// states for the study and for the whole-domain test.
fn banded_states(per_band: usize) -> Vec<Referenced> {
    let mut rng = Rng(0x57D1);
    referenced_states(per_band, |c, range| whip_state(&mut rng, c, range).0)
}

/// `per_band` states in each band of [`BANDS`] drawn by `sample(c, band's ε range)`, with
/// their direct references (force: 32 grid phases; coefficients: 32, 128 from [`WALL_BAND`] on).
fn referenced_states(
    per_band: usize,
    mut sample: impl FnMut(f64, (f64, f64)) -> JournalKinematics,
) -> Vec<Referenced> {
    let geometry = seed_bearing(0.5);
    let grid = FilmGrid::new(60, 10).unwrap();
    let mut direct = FiniteFilm::new(geometry.clone(), mdm(), grid).unwrap();
    let c = geometry.radial_clearance_m;
    let mut out = Vec::new();
    for (b, &range) in BANDS.iter().enumerate() {
        for _ in 0..per_band {
            let kin = sample(c, range);
            let f = force_reference_32(&mut direct, &kin, grid.n_theta);
            let sub = if b >= WALL_BAND { 16 } else { 4 };
            out.push((
                b,
                kin,
                f,
                analytic_reference(&mut direct, &kin, grid.n_theta, sub),
            ));
        }
    }
    out
}

/// The worst force error (of |F|) and coefficient error (of the coefficient scale,
/// `coefficient_error`) of `model` in each band of [`BANDS`].
fn banded_errors(model: &mut TabulatedFilm, states: &[Referenced]) -> ([f64; 8], [f64; 8]) {
    let (mut ef, mut ec) = ([0.0_f64; 8], [0.0_f64; 8]);
    for (b, kin, fr, cr) in states {
        let (r, k) = model.solve_with_coefficients(kin).unwrap();
        let f = r.force_n;
        ef[*b] = ef[*b].max((f[0] - fr[0]).hypot(f[1] - fr[1]) / fr[0].hypot(fr[1]));
        ec[*b] = ec[*b].max(common::coefficient_error(cr, &k, kin.speed_rad_s));
    }
    (ef, ec)
}

/// The convergence study of the table's resolution (README "The film table's resolution"):
/// for each resolution (`ROTOR_TWIN_TABLE_STUDY`, e.g. `atanh:160x192x8,log:160x192x8`), the
/// worst force and coefficient error against the 32-phase direct reference per ε band, at
/// `ROTOR_TWIN_TABLE_STUDY_N` (default [`STATES_PER_BAND`]) states a band (`banded_states` ), the build time and
/// the time of one force + coefficients evaluation, and the change on refinement: the worst
/// difference per band from the list's first table at the same states (`banded_change`).
/// `+F×N×P` after the dimensions: the rows at ε ≥ F/1000 with N columns and P phases
/// (`WallRows`), so `atanh:240x288x16+900x384x32` refines the centre rows (ε < 0.90) of the
/// default `atanh:160x192x8+900x384x32` by 1.5 in ε and ψ and 2 in phases (the rows are
/// equally spaced in u over the whole table, so the wall rows are 1.5× denser in ε too).
/// A study, not a check: run by hand with
/// `cargo test --release --test film_table -- --ignored --nocapture resolution_study`.
#[test]
#[ignore]
fn resolution_study() {
    use rotor_twin::film::{EccentricityMap, ForceFrame, TableResolution, WallRows};
    let geometry = seed_bearing(0.5);
    let grid = FilmGrid::new(60, 10).unwrap();
    let per_band: usize = std::env::var("ROTOR_TWIN_TABLE_STUDY_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(STATES_PER_BAND);
    let states = banded_states(per_band);
    // the first table's answers: each later table's change on refinement is against them
    let mut first = None;
    let list = std::env::var("ROTOR_TWIN_TABLE_STUDY")
        .unwrap_or_else(|_| "atanh-loc:160x192x8,atanh:160x192x8".into());
    for spec in list.split(',') {
        let (map, dims) = spec.split_once(':').expect("map:NxMxP");
        // `…+950x384x8`: the rows at ε ≥ 0.950 with 384 columns and 8 phases (`WallRows`)
        let (dims, wall) = dims.split_once('+').unwrap_or((dims, ""));
        let numbers = |t: &str| -> Vec<usize> {
            t.split('x')
                .filter(|v| !v.is_empty())
                .map(|v| v.parse().expect("number"))
                .collect()
        };
        let (d, w) = (numbers(dims), numbers(wall));
        let res = TableResolution {
            n_ecc: d[0],
            n_psi: d[1],
            grid_phases: d[2],
            map: if map.starts_with("log") {
                EccentricityMap::Log
            } else {
                EccentricityMap::Atanh
            },
            // `atanh-loc:…`: the force held along the line of centres (session 10)
            frame: if map.ends_with("-loc") {
                ForceFrame::LineOfCentres
            } else {
                ForceFrame::Source
            },
            wall: (w.len() == 3).then(|| WallRows {
                from_ecc_per_mille: w[0] as u32,
                n_psi: w[1],
                grid_phases: w[2],
            }),
        };
        let t0 = std::time::Instant::now();
        let table = FilmTable::build_with(&geometry, mdm(), grid, res).unwrap();
        let build_s = t0.elapsed().as_secs_f64();
        let mut model = TabulatedFilm::new(std::sync::Arc::new(table));
        let t1 = std::time::Instant::now();
        let (ef, ec) = banded_errors(&mut model, &states);
        let eval_us = t1.elapsed().as_secs_f64() * 1e6 / states.len() as f64;
        let (centre, centre_at) = centre_error(&mut model);
        let answers = table_answers(&mut model, &states);
        let change = first.get_or_insert_with(|| answers.clone());
        let (cf, cc) = banded_change(change, &answers, &states);
        let pct = |v: &[f64; 8]| {
            v.iter()
                .map(|e| format!("{:.2}", 100.0 * e))
                .collect::<Vec<_>>()
                .join(" ")
        };
        println!(
            "STUDY {spec}: solves {} build {build_s:.1} s eval {eval_us:.2} µs | force % by band: {} | coefficients %: {} | centre (ε 0.001–0.03) {:.3} % at ε {centre_at} | change from the first table: force % {} coefficients % {}",
            res.solves(),
            pct(&ef),
            pct(&ec),
            100.0 * centre,
            pct(&cf),
            pct(&cc)
        );
    }
}

/// The force (N) and eight coefficients of `model` at each of `states`.
fn table_answers(
    model: &mut TabulatedFilm,
    states: &[Referenced],
) -> Vec<([f64; 2], rotor_twin::film::FilmCoefficients)> {
    states
        .iter()
        .map(|(_, kin, _, _)| {
            let (r, k) = model.solve_with_coefficients(kin).unwrap();
            (r.force_n, k)
        })
        .collect()
}

/// The study's change on refinement: the worst difference per band of [`BANDS`] between two
/// tables' answers at the same states (force: of the first's |F|; coefficients: of the first's
/// coefficient scale, `coefficient_error`), the table against itself refined, no reference.
fn banded_change(
    first: &[([f64; 2], rotor_twin::film::FilmCoefficients)],
    other: &[([f64; 2], rotor_twin::film::FilmCoefficients)],
    states: &[Referenced],
) -> ([f64; 8], [f64; 8]) {
    let (mut cf, mut cc) = ([0.0_f64; 8], [0.0_f64; 8]);
    for (((b, kin, _, _), (fa, ka)), (fb, kb)) in states.iter().zip(first).zip(other) {
        let df = (fa[0] - fb[0]).hypot(fa[1] - fb[1]) / fa[0].hypot(fa[1]);
        cf[*b] = cf[*b].max(df);
        cc[*b] = cc[*b].max(common::coefficient_error(ka, kb, kin.speed_rad_s));
    }
    (cf, cc)
}

/// The built-in machine's stability threshold with the tabulated film (equilibria and
/// coefficients from the table) against the direct solver's (`modes`, 8-phase averaged
/// coefficients on the same 60 × 10 grid), bisection to 0.5 rpm: within 0.5 % (issue 11).
/// The machine is the built-in default, reading (B) of the seed since session 15 (Ø63 body,
/// 56 kg), linear-stable at 9,000 rpm (asserted: its point): measured direct 9,291.1 rpm, table
/// 9,286.7 rpm (−0.05 %; grid-converged 9,285.0 on 180 × 30, `film_linearised.rs`). Reading (A) (Ø55, `config/orc_microturbine_100kw_d55.yaml`, the default until
/// session 15): direct 8,471.3 rpm, table 8,458.5 rpm (−0.15 %).
#[test]
fn the_tables_threshold_is_within_half_a_percent_of_the_direct_solvers() {
    use rotor_twin::rotor::{
        stability_threshold, stability_threshold_tabulated, static_solution, MachineDescription,
        Rotor, DEFAULT_MACHINE_YAML,
    };
    let rotor = Rotor::from_description(
        &MachineDescription::from_yaml(DEFAULT_MACHINE_YAML, "built-in").unwrap(),
    );
    let st = static_solution(&rotor).unwrap();
    let direct = stability_threshold(&rotor, &st, 9000.0, 9600.0, 300.0)
        .unwrap()
        .expect("a threshold below 9,600 rpm")
        .speed_rpm;
    let table = stability_threshold_tabulated(&rotor, &st, [9000.0, 9600.0, 300.0])
        .unwrap()
        .expect("a threshold below 9,600 rpm")
        .speed_rpm;
    println!("threshold: direct {direct:.1} rpm, table {table:.1} rpm");
    // reading (B): linear-stable at 9,000 rpm (the search returns 9,000 if not)
    assert!(direct > 9000.5 && table > 9000.5, "{direct} {table}");
    assert!(
        (table / direct - 1.0).abs() < 0.005,
        "direct {direct} table {table}"
    );
}

/// Where the table's force differs most from the 32-phase direct reference, per band (a
/// diagnosis, run by hand: `-- --ignored --nocapture worst_states_diagnosis`): the state, |F|,
/// the error, and two checks of the reference: the same source with the journal's rotation
/// traded for whirl (ω = 0, U kept: the table's own definition; the Reynolds problem is the
/// same, so the force must be too) and the reference over 128 phases instead of 32.
#[test]
#[ignore]
fn worst_states_diagnosis() {
    let (mut table, mut direct, c, nt) = models();
    let states = banded_states(STATES_PER_BAND);
    for (band, range) in BANDS.iter().enumerate() {
        let mut worst = (0.0_f64, 0usize);
        for (i, (b, kin, fr, _)) in states.iter().enumerate() {
            if *b != band {
                continue;
            }
            let f = table.solve(kin).unwrap().force_n;
            let e = (f[0] - fr[0]).hypot(f[1] - fr[1]) / fr[0].hypot(fr[1]);
            if e > worst.0 {
                worst = (e, i);
            }
        }
        let (_, kin, fr, _) = &states[worst.1];
        let [x, y] = kin.position_m;
        let [vx, vy] = kin.velocity_m_s;
        let e = x.hypot(y);
        let (cp, sp) = (x / e, y / e);
        let v_t = -vx * sp + vy * cp;
        let v_r = vx * cp + vy * sp;
        let u = kin.speed_rad_s * e / c - 2.0 * v_t / c;
        let w = 2.0 * v_r / c;
        // ω = 0, whirl carrying U: v_t' = −U c / 2
        let vt0 = -0.5 * u * c;
        let still = JournalKinematics {
            position_m: kin.position_m,
            velocity_m_s: [v_r * cp - vt0 * sp, v_r * sp + vt0 * cp],
            speed_rad_s: 0.0,
        };
        let f0 = force_reference_32(&mut direct, &still, nt);
        let f128 = force_reference(&mut direct, kin, nt, 16);
        let d = |a: [f64; 2]| (a[0] - fr[0]).hypot(a[1] - fr[1]) / fr[0].hypot(fr[1]);
        println!(
            "ε {range:?}: worst {:.3} % at ε {:.4} ψ {:.3} V {:.1} |F| {:.2} N; ω = 0 {:.4} %, 128 phases {:.4} %",
            100.0 * worst.0,
            e / c,
            w.atan2(u),
            u.hypot(w),
            fr[0].hypot(fr[1]),
            100.0 * d(f0),
            100.0 * d(f128)
        );
    }
}

/// The direct solver's perturbation coefficients averaged over 8 × `sub` grid phases (the
/// 8-phase `linearised_coefficients` at `sub` sub-phases; `finer_phase_average` is `sub` = 4).
fn analytic_reference(
    direct: &mut FiniteFilm,
    kin: &JournalKinematics,
    nt: usize,
    sub: usize,
) -> rotor_twin::film::FilmCoefficients {
    let mut out = rotor_twin::film::FilmCoefficients::default();
    for k in 0..sub {
        let a = k as f64 * TAU / nt as f64 / (8 * sub) as f64;
        let (ca, sa) = (a.cos(), a.sin());
        let turn = |v: [f64; 2]| [ca * v[0] - sa * v[1], sa * v[0] + ca * v[1]];
        let turned = JournalKinematics {
            position_m: turn(kin.position_m),
            velocity_m_s: turn(kin.velocity_m_s),
            speed_rad_s: kin.speed_rad_s,
        };
        let l = direct.linearised_coefficients(&turned).unwrap();
        let r = nalgebra::Matrix2::new(ca, -sa, sa, ca);
        let w = 1.0 / sub as f64;
        out.stiffness_n_per_m += w * r.transpose() * l.stiffness_n_per_m * r;
        out.damping_n_s_per_m += w * r.transpose() * l.damping_n_s_per_m * r;
    }
    out
}

/// The eight coefficients as central differences of the direct force averaged over 8 × `sub`
/// grid phases (`force_reference`): position steps `h` c, velocity steps `h` c ω.
fn difference_reference(
    direct: &mut FiniteFilm,
    kin: &JournalKinematics,
    nt: usize,
    sub: usize,
    h: f64,
) -> rotor_twin::film::FilmCoefficients {
    let c = seed_bearing(0.5).radial_clearance_m;
    let (dq, dv) = (h * c, h * c * kin.speed_rad_s);
    let mut out = rotor_twin::film::FilmCoefficients::default();
    for j in 0..2 {
        let (mut p, mut m) = (*kin, *kin);
        p.position_m[j] += dq;
        m.position_m[j] -= dq;
        let (fp, fm) = (
            force_reference(direct, &p, nt, sub),
            force_reference(direct, &m, nt, sub),
        );
        let (mut pv, mut mv) = (*kin, *kin);
        pv.velocity_m_s[j] += dv;
        mv.velocity_m_s[j] -= dv;
        let (gp, gm) = (
            force_reference(direct, &pv, nt, sub),
            force_reference(direct, &mv, nt, sub),
        );
        for i in 0..2 {
            out.stiffness_n_per_m[(i, j)] = -(fp[i] - fm[i]) / (2.0 * dq);
            out.damping_n_s_per_m[(i, j)] = -(gp[i] - gm[i]) / (2.0 * dv);
        }
    }
    out
}

/// Which reference of the coefficients is right where the table and the 32-phase analytic
/// reference differ (the centre and beyond ε 0.95; a diagnosis, run by hand:
/// `-- --ignored --nocapture coefficient_reference_diagnosis`). Per state of the study: the
/// table against A (32 phases of the perturbation coefficients), A128 (128 phases), D(h)
/// (central differences of the 32-phase force, steps h c and h c ω); then at the band's
/// worst states the same against the grid-refined film (120 × 20, 240 × 40, 8 phases of its
/// own grid, perturbation coefficients and differences of the force). (In band 7,
/// [`WALL_BAND`], A averages 128 phases since session 12.)
#[test]
#[ignore]
fn coefficient_reference_diagnosis() {
    let (mut table, mut direct, _, nt) = models();
    let states = banded_states(STATES_PER_BAND);
    let bands: Vec<usize> = std::env::var("ROTOR_TWIN_DIAG_BANDS")
        .ok()
        .map(|v| v.split(',').map(|b| b.parse().expect("band")).collect())
        .unwrap_or_else(|| vec![0, 3, 6, 7]);
    let w = OMEGA_9000_RPM;
    let mut fine: Vec<(usize, FiniteFilm)> = [(120, 20), (240, 40)]
        .iter()
        .map(|&(a, b)| {
            (
                a,
                FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::new(a, b).unwrap()).unwrap(),
            )
        })
        .collect();
    for &band in &bands {
        let mut rows = Vec::new();
        for (b, kin, _, a32) in states.iter().filter(|s| s.0 == band) {
            let (_, t) = table.solve_with_coefficients(kin).unwrap();
            let a128 = analytic_reference(&mut direct, kin, nt, 16);
            let d: Vec<_> = [1e-4, 1e-3]
                .iter()
                .map(|&h| difference_reference(&mut direct, kin, nt, 4, h))
                .collect();
            let e = |x: &rotor_twin::film::FilmCoefficients,
                     y: &rotor_twin::film::FilmCoefficients| {
                100.0 * common::coefficient_error(x, y, w)
            };
            let eps =
                kin.position_m[0].hypot(kin.position_m[1]) / seed_bearing(0.5).radial_clearance_m;
            println!(
                "band {b} ε {eps:.5}: T–A {:.3} T–A128 {:.3} T–D1e-4 {:.3} T–D1e-3 {:.3} | A–A128 {:.3} A–D1e-4 {:.3} A–D1e-3 {:.3} D1e-4–D1e-3 {:.3}",
                e(a32, &t), e(&a128, &t), e(&d[0], &t), e(&d[1], &t),
                e(&a128, a32), e(&d[0], a32), e(&d[1], a32), e(&d[1], &d[0])
            );
            rows.push((e(a32, &t), *kin, t, *a32, d[0]));
        }
        rows.sort_by(|x, y| y.0.total_cmp(&x.0));
        for (_, kin, t, a, d) in rows.iter().take(2) {
            for (n, film) in fine.iter_mut() {
                let ntf = *n;
                let lin = film.linearised_coefficients(kin).unwrap();
                let dif = difference_reference(film, kin, ntf, 1, 1e-4);
                let e = |x: &rotor_twin::film::FilmCoefficients,
                         y: &rotor_twin::film::FilmCoefficients| {
                    100.0 * common::coefficient_error(x, y, w)
                };
                println!(
                    "  band {band} {n}: lin–dif {:.3} | vs lin: T {:.3} A {:.3} D {:.3} | vs dif: T {:.3} A {:.3} D {:.3}",
                    e(&lin, &dif), e(&lin, t), e(&lin, a), e(&lin, d), e(&dif, t), e(&dif, a), e(&dif, d)
                );
            }
        }
    }
}

/// The direct perturbation coefficients averaged over 8 × `sub` grid phases starting on a grid
/// line, α_k = kΔθ/(8 sub), with the state turned to the attitude φ = 0 and the coefficients
/// turned back: what a table node averaging 8 × `sub` phases holds (`row` in
/// src/film/table/mod.rs), without its interpolation.
fn grid_aligned_reference(
    direct: &mut FiniteFilm,
    kin: &JournalKinematics,
    nt: usize,
    sub: usize,
) -> rotor_twin::film::FilmCoefficients {
    let phi = kin.position_m[1].atan2(kin.position_m[0]);
    let (ca, sa) = (phi.cos(), phi.sin());
    // turn by −φ
    let turn = |v: [f64; 2]| [ca * v[0] + sa * v[1], -sa * v[0] + ca * v[1]];
    let aligned = JournalKinematics {
        position_m: turn(kin.position_m),
        velocity_m_s: turn(kin.velocity_m_s),
        speed_rad_s: kin.speed_rad_s,
    };
    let l = analytic_reference(direct, &aligned, nt, sub);
    let r = nalgebra::Matrix2::new(ca, sa, -sa, ca);
    rotor_twin::film::FilmCoefficients {
        stiffness_n_per_m: r.transpose() * l.stiffness_n_per_m * r,
        damping_n_s_per_m: r.transpose() * l.damping_n_s_per_m * r,
        ..l
    }
}

/// The wall band's coefficient error split into its parts (a diagnosis, run by hand:
/// `-- --ignored --nocapture wall_error_decomposition`, bands from `ROTOR_TWIN_DIAG_BANDS`,
/// default 6,7): per state of the study, the table T against I_m, the direct coefficients
/// averaged over m grid phases from a grid line (what a node of m phases holds: T–I8 is the
/// interpolation error alone), and I_m, T, A (32 phases at the state's attitude) against
/// A128 (128 phases at the state's attitude, the reference least dependent on the phase).
#[test]
#[ignore]
fn wall_error_decomposition() {
    let (mut table, mut direct, _, nt) = models();
    let states = banded_states(STATES_PER_BAND);
    let bands: Vec<usize> = std::env::var("ROTOR_TWIN_DIAG_BANDS")
        .ok()
        .map(|v| v.split(',').map(|b| b.parse().expect("band")).collect())
        .unwrap_or_else(|| vec![6, 7]);
    let w = OMEGA_9000_RPM;
    let e = |x: &rotor_twin::film::FilmCoefficients, y: &rotor_twin::film::FilmCoefficients| {
        100.0 * common::coefficient_error(x, y, w)
    };
    for &band in &bands {
        let mut worst = [0.0_f64; 9];
        for (_, kin, _, a32) in states.iter().filter(|s| s.0 == band) {
            let (_, t) = table.solve_with_coefficients(kin).unwrap();
            let a128 = analytic_reference(&mut direct, kin, nt, 16);
            let i: Vec<_> = [1, 2, 4, 16]
                .iter()
                .map(|&sub| grid_aligned_reference(&mut direct, kin, nt, sub))
                .collect();
            let eps =
                kin.position_m[0].hypot(kin.position_m[1]) / seed_bearing(0.5).radial_clearance_m;
            let row = [
                e(a32, &t),
                e(&a128, &t),
                e(&i[0], &t),
                e(&a128, &i[0]),
                e(&a128, &i[1]),
                e(&a128, &i[2]),
                e(&a128, &i[3]),
                e(&a128, a32),
                e(&i[2], &t),
            ];
            for (w, r) in worst.iter_mut().zip(row) {
                *w = w.max(r);
            }
            println!(
                "band {band} ε {eps:.5}: T–Aref {:.3} T–A128 {:.3} T–I8 {:.3} | vs A128: I8 {:.3} I16 {:.3} I32 {:.3} I128 {:.3} Aref {:.3} | T–I32 {:.3}",
                row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7], row[8]
            );
        }
        println!("band {band} worst: {worst:.3?}");
    }
}
