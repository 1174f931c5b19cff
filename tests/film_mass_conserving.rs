//! The mass-conserving (JFO / Elrod–Adams) film of `src/film/finite/mass_conserving.rs`
//! against the Reynolds-condition solver, the flow balance, and its transient.
//!
//! References: for a steadily loaded bearing whose film is flooded at the start of its
//! convergent part, the JFO rupture condition is the Reynolds condition (p = ∂p/∂n = 0) and the
//! two films differ only where the JFO film re-forms (Jakobsson & Floberg 1957; Braun & Hannon
//! 2010, "Cavitation formation and modelling for fluid film bearings: a review", who report
//! load capacities within a few per cent). Conservation is exact in (M3); the Reynolds condition
//! creates fluid at its re-forming boundary, which the same flow accounting shows.

mod common;
use common::*;
use rotor_twin::film::{
    AxialGroove, BearingGeometry, Cavitation, FilmGrid, FilmModel, FilmResult, FiniteFilm,
    JournalKinematics,
};
use std::f64::consts::PI;

const C: f64 = 40e-6;

fn film(geometry: BearingGeometry, grid: FilmGrid, cavitation: Cavitation) -> FiniteFilm {
    FiniteFilm::new(geometry, mdm(), grid)
        .unwrap()
        .with_cavitation(cavitation)
}

fn at(eps: f64) -> JournalKinematics {
    JournalKinematics::at_position([eps * C, 0.0], OMEGA_9000_RPM)
}

fn load(r: &FilmResult) -> f64 {
    r.force_n[0].hypot(r.force_n[1])
}

/// Angle of the rupture boundary past the minimum film (θ = 0 for a journal at +x), deg.
fn rupture_deg(r: &FilmResult) -> f64 {
    let a = r.film_end_rad.to_degrees();
    if a > 180.0 {
        a - 360.0
    } else {
        a
    }
}

/// The seed bearing with a narrow feed groove at ambient pressure at θ = 180°, the widest gap
/// of a journal displaced along +x.
fn fed_at_widest_gap(l_over_d: f64) -> BearingGeometry {
    let mut g = seed_bearing(l_over_d);
    g.grooves = vec![AxialGroove {
        center_rad: PI,
        width_rad: 1f64.to_radians(),
        supply_pressure_pa: 0.0,
    }];
    g
}

#[test]
fn steady_load_and_rupture_agree_with_the_reynolds_condition() {
    // measured on 60×10: |ΔW|/W ≤ 0.54 %, |Δζ2| ≤ 0.03°, |Δp_max| ≤ 0.9 %, attitude ≤ 3.2°
    // apart (the JFO film starts at the feed, 180°; the Reynolds zone of the unfed plain bearing
    // 15–39° earlier). Tolerances: the "few per cent" of the references, 1 % and 0.5° (one grid
    // cell is 6°), the attitude 4°.
    for l_over_d in [0.5, 1.0] {
        for eps in [0.3, 0.5, 0.7, 0.9] {
            let grid = FilmGrid::DEFAULT;
            let g = seed_bearing(l_over_d);
            let reynolds = film(g.clone(), grid, Cavitation::Reynolds)
                .solve(&at(eps))
                .unwrap();
            let mut mc = film(g, grid, Cavitation::MassConserving);
            let jfo = mc.solve(&at(eps)).unwrap();
            let dw = load(&jfo) / load(&reynolds) - 1.0;
            let att = |r: &FilmResult| r.force_n[1].atan2(-r.force_n[0]).to_degrees();
            let dz2 = rupture_deg(&jfo) - rupture_deg(&reynolds);
            println!(
                "L/D {l_over_d} ε {eps}: W {:.1} vs {:.1} N ({:+.2} %), attitude {:.2} vs {:.2}°, \
                 ζ2 {:.2} vs {:.2}° ({dz2:+.2}°), ζ1 {:.1} vs {:.1}°, pmax {:.3} vs {:.3} MPa, \
                 passes {}",
                load(&jfo),
                load(&reynolds),
                100.0 * dw,
                att(&jfo),
                att(&reynolds),
                rupture_deg(&jfo),
                rupture_deg(&reynolds),
                jfo.film_start_rad.to_degrees(),
                reynolds.film_start_rad.to_degrees(),
                jfo.max_pressure_pa / 1e6,
                reynolds.max_pressure_pa / 1e6,
                mc.last_active_set_passes()
            );
            let at = format!("L/D {l_over_d} ε {eps}");
            assert!(dw.abs() < 0.01, "{at}: load {dw:+e}");
            assert!(dz2.abs() < 0.5, "{at}: ζ2 {dz2:+}°");
            let dp = jfo.max_pressure_pa / reynolds.max_pressure_pa - 1.0;
            assert!(dp.abs() < 0.01, "{at}: p_max {dp:+e}");
            assert!((att(&jfo) - att(&reynolds)).abs() < 4.0, "{at}: attitude");
            // the JFO film re-forms at the feed, 180° (one cell either side)
            let z1 = jfo.film_start_rad.to_degrees();
            assert!((z1 - 180.0).abs() < 6.0, "{at}: ζ1 {z1}°");
        }
    }
}

#[test]
fn the_film_balance_closes_with_mass_conservation_and_not_with_the_reynolds_condition() {
    for eps in [0.3, 0.6, 0.9] {
        let g = fed_at_widest_gap(0.5);
        let mut mc = film(g.clone(), FilmGrid::DEFAULT, Cavitation::MassConserving);
        mc.solve(&at(eps)).unwrap();
        let b = mc.flow_balance();
        let mut re = film(g, FilmGrid::DEFAULT, Cavitation::Reynolds);
        re.solve(&at(eps)).unwrap();
        let r = re.flow_balance();
        println!(
            "ε {eps}: JFO feed {:.4e} side {:.4e} storage {:.1e} m³/s; Reynolds feed {:.4e} side \
             {:.4e} ({:+.2} %)",
            b.feed_m3_s,
            b.side_m3_s,
            b.storage_m3_s,
            r.feed_m3_s,
            r.side_m3_s,
            100.0 * (r.side_m3_s / r.feed_m3_s - 1.0)
        );
        // JFO: what the feed delivers leaves at the ends (steady, storage 0), to round-off
        assert!(b.storage_m3_s == 0.0);
        assert!((b.feed_m3_s - b.side_m3_s).abs() < 1e-10 * b.side_m3_s);
        // Reynolds condition, the same feed, the same pressure field: the ruptured zone is
        // taken full (φ = 1), so the Couette flow that reaches the feed is the full ωRh/2 and
        // the feed delivers nothing net: the side flow is fluid the condition creates
        assert!(r.feed_m3_s.abs() < 0.1 * r.side_m3_s, "{r:?}");
        assert!(
            (r.side_m3_s / b.side_m3_s - 1.0).abs() < 1e-9,
            "same pressure field"
        );
    }
}

/// A journal whirling at half the running speed about ε 0.5 (orbit radius 0.3c), the film fed
/// by a fixed groove at 180°: every step's flow balance closes, and the fluid volume after many
/// steps is the start's plus the net inflow.
#[test]
fn a_whirling_journal_conserves_the_fluid_step_by_step() {
    let mut mc = film(
        fed_at_widest_gap(0.5),
        FilmGrid::DEFAULT,
        Cavitation::MassConserving,
    );
    let w = OMEGA_9000_RPM;
    let orbit = |t: f64| half_speed_whirl(C, w, t);
    mc.solve(&orbit(0.0)).unwrap();
    let dt = 2.0 * PI / w / 100.0;
    mc.set_time_step(Some(dt)).unwrap();
    let v0 = mc.fluid_volume_m3();
    let (mut net, mut worst, mut ruptured) = (0.0, 0.0_f64, 0.0_f64);
    for n in 1..=400 {
        let r = mc.solve(&orbit(n as f64 * dt)).unwrap();
        assert!(r.force_n.iter().all(|f| f.is_finite()));
        let b = mc.flow_balance();
        let scale = b.feed_m3_s.abs() + b.side_m3_s.abs() + b.storage_m3_s.abs();
        worst = worst.max((b.feed_m3_s - b.side_m3_s - b.storage_m3_s).abs() / scale);
        net += dt * (b.feed_m3_s - b.side_m3_s);
        mc.commit_step();
        let least = (0..60).map(|i| mc.fluid_fraction(i, 0)).fold(1.0, f64::min);
        ruptured = ruptured.max(1.0 - least);
    }
    let dv = mc.fluid_volume_m3() - v0;
    println!(
        "whirl: worst step imbalance {worst:.2e} of the flows; volume change {dv:.4e} m³ vs net \
         inflow {net:.4e} m³ (V0 {v0:.4e} m³); deepest rupture 1 − φ = {ruptured:.3}"
    );
    // round-off of a converged solve (the band LU's residual on ~600 unknowns)
    assert!(worst < 1e-9, "flow balance off by {worst:e}");
    assert!(
        (dv - net).abs() < 1e-9 * v0,
        "volume {dv:e} vs net inflow {net:e}"
    );
    // the film does rupture and re-form on this orbit (else the test checks nothing of φ)
    assert!(ruptured > 0.2, "deepest rupture {ruptured}");
}

/// The journal jumps from ε 0.5 to ε 0.7 and stays: the transient film relaxes to the steady
/// mass-conserving solution (a second path to the same state), in a few revolutions — how long
/// the film "remembers" its prehistory.
#[test]
fn the_transient_film_relaxes_to_the_steady_solution() {
    let g = fed_at_widest_gap(0.5);
    let steady = film(g.clone(), FilmGrid::DEFAULT, Cavitation::MassConserving)
        .solve(&at(0.7))
        .unwrap();
    for per_rev in [100, 200] {
        let mut mc = film(g.clone(), FilmGrid::DEFAULT, Cavitation::MassConserving);
        mc.solve(&at(0.5)).unwrap();
        let dt = 2.0 * PI / OMEGA_9000_RPM / per_rev as f64;
        mc.set_time_step(Some(dt)).unwrap();
        let mut within_1_percent = None;
        let mut last = 0.0;
        for n in 1..=8 * per_rev {
            let r = mc.solve(&at(0.7)).unwrap();
            mc.commit_step();
            let d = load(&r) / load(&steady) - 1.0;
            if d.abs() > 0.01 {
                within_1_percent = None;
            } else if within_1_percent.is_none() {
                within_1_percent = Some(n as f64 / per_rev as f64);
            }
            last = d;
        }
        println!(
            "{per_rev} steps/rev: load within 1 % of steady after {:?} rev; after 8 rev {:+.2e}",
            within_1_percent, last
        );
        assert!(last.abs() < 1e-6, "after 8 revolutions: {last:e}");
    }
}

/// The opposite sense of rotation (the Couette flux upwinded the other way): the mirror image
/// of the forward film (F_x the same, F_y and ζ mirrored).
#[test]
fn reversed_rotation_gives_the_mirror_image() {
    let mut fwd = film(
        seed_bearing(0.5),
        FilmGrid::DEFAULT,
        Cavitation::MassConserving,
    );
    let mut rev = fwd.clone();
    let a = fwd.solve(&at(0.6)).unwrap();
    let mut k = at(0.6);
    k.speed_rad_s = -k.speed_rad_s;
    let b = rev.solve(&k).unwrap();
    assert!(
        (a.force_n[0] - b.force_n[0]).abs() < 1e-9 * load(&a),
        "{a:?} {b:?}"
    );
    assert!(
        (a.force_n[1] + b.force_n[1]).abs() < 1e-9 * load(&a),
        "{a:?} {b:?}"
    );
    // the feed delivers the same flow, now carried towards −θ, and it leaves at the ends
    let (f, r) = (fwd.flow_balance(), rev.flow_balance());
    assert!(
        (f.feed_m3_s - r.feed_m3_s).abs() < 1e-9 * f.feed_m3_s,
        "{f:?} {r:?}"
    );
    assert!(
        (r.feed_m3_s - r.side_m3_s).abs() < 1e-10 * r.feed_m3_s,
        "{r:?}"
    );
}

/// Grid convergence of the steady JFO film (L/D 0.5, ε 0.6): load and rupture angle on
/// 60×10, 120×20, 240×40.
#[test]
fn grid_convergence_of_the_steady_film() {
    let mut loads = Vec::new();
    for (nt, nz) in [(60, 10), (120, 20), (240, 40)] {
        let grid = FilmGrid::new(nt, nz).unwrap();
        let mut mc = film(seed_bearing(0.5), grid, Cavitation::MassConserving);
        let r = mc.solve(&at(0.6)).unwrap();
        let mut re = film(seed_bearing(0.5), grid, Cavitation::Reynolds);
        let q = re.solve(&at(0.6)).unwrap();
        println!(
            "{nt}×{nz}: JFO W {:.2} N ζ2 {:.2}° pmax {:.4} MPa ({} passes); Reynolds W {:.2} N ζ2 {:.2}°",
            load(&r),
            rupture_deg(&r),
            r.max_pressure_pa / 1e6,
            mc.last_active_set_passes(),
            load(&q),
            rupture_deg(&q)
        );
        loads.push(load(&r));
    }
    // measured: 60×10 → 120×20 +0.26 %, 120×20 → 240×40 +0.042 %: the default grid is within
    // the project's 0.5 % on refinement
    let first = (loads[1] / loads[0] - 1.0).abs();
    let last = (loads[2] / loads[1] - 1.0).abs();
    println!(
        "60×10 → 120×20: {:.3} %, 120×20 → 240×40: {:.3} %",
        100.0 * first,
        100.0 * last
    );
    assert!(first < 0.005 && last < 0.005 && last < first, "{loads:?}");
}

/// A film state recorded by the study `seed_case_comparison` (`tests/twin_mass_conserving.rs`)
/// with `ROTOR_TWIN_MCAV_DUMP` set: the kinematics, the committed fluid fraction φ⁰ and the
/// active sets of a solve whose active set cycled (`src/film/finite/mass_conserving_sweep.rs`).
struct RecordedState {
    film: FiniteFilm,
    kin: JournalKinematics,
}

fn recorded_state(file: &str, passes: usize) -> RecordedState {
    let path = format!("{}/tests/reference/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    let field = |key: &str| -> Vec<f64> {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(key))
            .unwrap();
        line.split_whitespace()
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (nt, nz) = (field("n_theta")[0] as usize, field("n_z")[0] as usize);
    let c = field("clearance_m")[0];
    let g = BearingGeometry::plain(2.0 * field("radius_m")[0], field("length_m")[0], c).unwrap();
    let oil =
        rotor_twin::film::Lubricant::new(field("density_kg_m3")[0], field("viscosity_pa_s")[0])
            .unwrap();
    let mut film = FiniteFilm::new(g, oil, FilmGrid::new(nt, nz).unwrap())
        .unwrap()
        .with_cavitation(Cavitation::MassConserving)
        .with_active_set_passes(passes);
    let speed = field("speed_rad_s")[0];
    // the feed at the recorded column: a steady solve whose widest gap is there (h = 1 − X cos θ
    // − Y sin θ), then the twin's transient form keeps it
    let feed = field("feed_column")[0] * 2.0 * PI / nt as f64;
    let away = [-0.5 * c * feed.cos(), -0.5 * c * feed.sin()];
    film.solve(&JournalKinematics::at_position(away, speed))
        .unwrap();
    FilmModel::begin_step(&mut film, 1.0 / field("inverse_step_1_s")[0]);
    film.set_committed_fraction(&field("phi0")).unwrap();
    let full: Vec<bool> = field("full").iter().map(|&f| f > 0.5).collect();
    film.set_full_nodes(&full).unwrap();
    let (p, v) = (field("position_m"), field("velocity_m_s"));
    let kin = JournalKinematics {
        position_m: [p[0], p[1]],
        velocity_m_s: [v[0], v[1]],
        speed_rad_s: speed,
    };
    RecordedState { film, kin }
}

/// Issue 18: where the seed case's whip nears the wall (9,000 rpm, kicked, ε 0.970, the journal
/// running into the wall at 47 mm/s, t = 0.1205 s), main's solver gave up (200 active-set
/// passes; the state recorded here is that solve's). There (M4) of session 12 gave φ at the
/// minimum gap a negative coefficient and the active set flipped that column each pass. Now:
/// the active set settles, projected Gauss–Seidel alone (M5, convergent for an M-function:
/// Rheinboldt 1970) reaches the same film (force within 1e-9: the solution is unique), a cold
/// start too, and the flow balance closes to round-off (1e-9 of the flows, as the other
/// balance tests).
#[test]
fn the_near_wall_whip_state_converges() {
    let file = "mcav_near_wall_9000rpm.txt";
    let mut state = recorded_state(file, 40);
    let r = state.film.solve(&state.kin).unwrap();
    let passes = state.film.last_active_set_passes();
    let b = state.film.flow_balance();
    let flows = b.feed_m3_s.abs() + b.side_m3_s.abs() + b.storage_m3_s.abs();
    let imbalance = (b.feed_m3_s - b.side_m3_s - b.storage_m3_s).abs() / flows;
    let eps = state.kin.position_m[0].hypot(state.kin.position_m[1]) / C;
    let least = (0..60)
        .flat_map(|i| (0..10).map(move |j| (i, j)))
        .map(|(i, j)| state.film.fluid_fraction(i, j))
        .fold(1.0, f64::min);
    println!(
        "near-wall state ε {eps:.4}: settled after {passes} passes, force ({:.1}, {:.1}) N, \
         p_max {:.2} MPa, imbalance {imbalance:.2e} of the flows, φ_min {least:.3}",
        r.force_n[0],
        r.force_n[1],
        1e-6 * r.max_pressure_pa
    );
    assert!(imbalance < 1e-9, "imbalance {imbalance}");
    assert!((0.0..=1.0).contains(&least), "φ_min {least}");
    let mut swept = recorded_state(file, 0);
    let s = swept.film.solve(&swept.kin).unwrap();
    let sb = swept.film.flow_balance();
    let s_imbalance = (sb.feed_m3_s - sb.side_m3_s - sb.storage_m3_s).abs() / flows;
    state.film.reset_warm_start();
    let cold = state.film.solve(&state.kin).unwrap();
    let gap = |x: &FilmResult| (x.force_n[0] - r.force_n[0]).hypot(x.force_n[1] - r.force_n[1]);
    println!(
        "sweeps alone: force differs by {:.2e} of it, imbalance {s_imbalance:.2e}; cold start: \
         {:.2e} ({} passes)",
        gap(&s) / load(&r),
        gap(&cold) / load(&r),
        state.film.last_active_set_passes()
    );
    assert!(gap(&s) < 1e-9 * load(&r), "sweeps differ by {} N", gap(&s));
    assert!(s_imbalance < 1e-9, "sweeps' imbalance {s_imbalance}");
    assert!(
        gap(&cold) < 1e-9 * load(&r),
        "cold start differs by {} N",
        gap(&cold)
    );
}
