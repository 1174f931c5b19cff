//! The mass-conserving (JFO) film inside the rotor transient (issue 18): the twin's transient
//! form (M4) of `src/film/finite/mass_conserving.rs`, its flow balance step by step, its
//! agreement with the Reynolds-condition twin on a stable orbit, and (ignored: a long study) the
//! seed case with both cavitation models.
//!
//! References: (M4) is backward Euler of ∂(φH)/∂t with the step's starting gap H − ḢΔt, φ⁰Ḣ + H(φ − φ⁰)/Δt; where the film is
//! whole (φ = 1) it is the Reynolds film's squeeze term, and for a film fed at the start of its
//! convergent part the JFO rupture is the Reynolds condition (Jakobsson & Floberg 1957; Braun &
//! Hannon 2010), so a stable orbit close to the equilibrium must match the Reynolds twin.

mod common;
use common::*;
use rotor_twin::dynamics::{Coupling, StepInput, Twin, TwinConfig};
use rotor_twin::film::{
    AxialGroove, Cavitation, FilmGrid, FilmModel, FiniteFilm, JournalKinematics,
};
use rotor_twin::rotor::{MachineDescription, Rotor};
use std::f64::consts::PI;

const C: f64 = 40e-6;

/// The seed bearing (L/D 0.5) fed by a narrow groove at ambient pressure at 180°, the twin's
/// transient form with `per_rev` steps a revolution at 9,000 rpm, a journal whirling at ½ω on
/// a radius 0.3c about ε 0.5 (the film ruptures to φ ≈ 0.2 and re-forms each revolution).
/// Returns (worst step imbalance over the flows, |ΔV − ∫(feed − side)dt| / ∫|feed|dt over
/// 4 revolutions, deepest rupture 1 − φ).
fn whirl(per_rev: usize) -> (f64, f64, f64) {
    let mut g = seed_bearing(0.5);
    g.grooves = vec![AxialGroove {
        center_rad: PI,
        width_rad: 1f64.to_radians(),
        supply_pressure_pa: 0.0,
    }];
    let mut mc = FiniteFilm::new(g, mdm(), FilmGrid::DEFAULT)
        .unwrap()
        .with_cavitation(Cavitation::MassConserving);
    let w = OMEGA_9000_RPM;
    let orbit = |t: f64| half_speed_whirl(C, w, t);
    mc.solve(&orbit(0.0)).unwrap();
    let dt = 2.0 * PI / w / per_rev as f64;
    let v0 = mc.fluid_volume_m3();
    let (mut net, mut gross, mut worst, mut ruptured) = (0.0, 0.0, 0.0_f64, 0.0_f64);
    for n in 1..=4 * per_rev {
        FilmModel::begin_step(&mut mc, dt);
        let r = mc.solve(&orbit(n as f64 * dt)).unwrap();
        assert!(r.force_n.iter().all(|f| f.is_finite()));
        let b = mc.flow_balance();
        let scale = b.feed_m3_s.abs() + b.side_m3_s.abs() + b.storage_m3_s.abs();
        worst = worst.max((b.feed_m3_s - b.side_m3_s - b.storage_m3_s).abs() / scale);
        net += dt * (b.feed_m3_s - b.side_m3_s);
        gross += dt * b.feed_m3_s.abs();
        FilmModel::commit_step(&mut mc);
        let least = (0..60).map(|i| mc.fluid_fraction(i, 0)).fold(1.0, f64::min);
        ruptured = ruptured.max(1.0 - least);
    }
    let dv = mc.fluid_volume_m3() - v0;
    ((worst), (dv - net).abs() / gross, ruptured)
}

/// Mass conservation of the twin's form (M4) over each step: feed = side flow + d/dt∫φh dA at
/// every solve (the discrete equations themselves: round-off), and over 4 revolutions the fluid
/// volume's change against the time integral of the net inflow: (M4) takes Ḣ at the end of
/// the step where the volume changes by the step's mean Ḣ, a first-order defect, so it must
/// shrink about 2× when the step is halved.
#[test]
fn the_twin_form_conserves_the_fluid_each_step() {
    let (worst_100, drift_100, rupture) = whirl(100);
    let (worst_200, drift_200, _) = whirl(200);
    println!(
        "twin form, whirl: worst step imbalance {worst_100:.2e} / {worst_200:.2e} of the flows \
         (100 / 200 steps a rev); volume drift over 4 rev {drift_100:.3e} / {drift_200:.3e} of \
         the fed volume; deepest rupture 1 − φ {rupture:.3}"
    );
    // round-off of a converged solve (band LU on ~600 unknowns)
    assert!(worst_100 < 1e-9 && worst_200 < 1e-9);
    // first order in Δt: a small share of the fed volume, halved (±15 %) with the step
    // measured 8.8e-4 and 4.4e-4 of the fed volume (6.8e-4, 3.4e-4 with the φḢ form of session 12)
    assert!(drift_100 < 2e-3, "drift {drift_100}");
    let ratio = drift_100 / drift_200;
    assert!((1.7..2.3).contains(&ratio), "drift ratio {ratio}");
    // the film ruptures and re-forms on this orbit (else φ is not tested)
    assert!(rupture > 0.2, "deepest rupture {rupture}");
}

/// One twin of reading (A) (config/orc_microturbine_100kw_d55.yaml, Ø55: the built-in machine
/// until session 15, on which the recorded states and the README's mass-conserving figures were
/// taken; nonlinear coupling, direct film) at `rpm` with the cavitation model `cavitation`,
/// `per_rev` steps a revolution.
fn seed_twin(rpm: f64, cavitation: Cavitation, per_rev: usize) -> (Twin, StepInput) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/config/orc_microturbine_100kw_d55.yaml"
    );
    let desc = MachineDescription::load(Some(std::path::Path::new(path))).unwrap();
    let mut rotor = Rotor::from_description(&desc);
    rotor.set_cavitation(cavitation).unwrap();
    let w = rpm * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, per_rev);
    let twin = Twin::new(&rotor, config, w).unwrap();
    let input = StepInput {
        speed_rad_s: w,
        accel_rad_s2: 0.0,
    };
    (twin, input)
}

/// At 8,000 rpm (below the seed case's threshold 8,471 rpm) from the static equilibrium, the
/// unbalance orbit of the mass-conserving twin (its feed at the widest gap of the equilibrium)
/// follows the Reynolds twin: journal positions within 1 % of the clearance, p_max within 1.5 %,
/// the rupture angle ζ2 within one grid cell (6°), over 6 revolutions at 64 steps. The steady
/// films differ by 0.54 % in load and 0.03° in ζ2 (`film_mass_conserving.rs`), the orbit is a
/// few µm about ε ≈ 0.5, so the ruptured zone's fluid re-forms at the feed and the films stay
/// alike.
#[test]
fn a_stable_8000_rpm_orbit_agrees_with_the_reynolds_twin() {
    let per_rev = 64;
    let revs = 6;
    let (mut re, input) = seed_twin(8000.0, Cavitation::Reynolds, per_rev);
    let (mut mc, _) = seed_twin(8000.0, Cavitation::MassConserving, per_rev);
    let c = re.bearing_clearances_m();
    let (mut dx, mut dp, mut dz, mut ruptured) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    let mut phi = vec![0.0; 60];
    let mut amplitude = 0.0_f64;
    for _ in 0..revs * per_rev {
        let a = re.step(&input).unwrap().clone();
        let b = mc.step(&input).unwrap().clone();
        for (k, (x, y)) in a.bearings.iter().zip(&b.bearings).enumerate() {
            let d = (x.position_m[0] - y.position_m[0]).hypot(x.position_m[1] - y.position_m[1]);
            dx = dx.max(d / c[k]);
            dp = dp.max((y.max_pressure_pa / x.max_pressure_pa - 1.0).abs());
            let z = (y.film_end_rad - x.film_end_rad)
                .to_degrees()
                .rem_euclid(360.0);
            dz = dz.max(z.min(360.0 - z));
            amplitude = amplitude.max(x.eccentricity_ratio);
            mc.midplane_fluid_fraction(k, &mut phi);
            ruptured = ruptured.max(1.0 - phi.iter().copied().fold(1.0, f64::min));
        }
    }
    println!(
        "8,000 rpm, {revs} rev × {per_rev}: largest position gap {dx:.4} c, p_max {:.3} %, ζ2 \
         {dz:.2}°; ε up to {amplitude:.3}; JFO deepest rupture 1 − φ {ruptured:.3}",
        100.0 * dp
    );
    // measured 0.0056 c, 0.69 %, 3.01° (64 steps, 6 rev)
    assert!(dx < 0.01, "position gap {dx} c");
    assert!(dp < 0.015, "p_max gap {dp}");
    assert!(dz < 6.0, "ζ2 gap {dz}°");
    // the JFO film does rupture (else nothing of φ was in the run)
    assert!(ruptured > 0.3, "deepest rupture {ruptured}");
}

/// How long the film remembers: the plain seed bearing at its 9,000 rpm equilibrium (ε 0.53,
/// fed at its widest gap), journal held, the twin's form at 128 steps a revolution; the
/// committed fluid fraction of the ruptured zone is halved once. In the ruptured zone (M1) is
/// ∂(φH)/∂t + (ω/2)∂(φH)/∂θ = 0: the missing fluid, spread evenly in angle (φH is constant
/// there), drifts at ω/2 into the feed, so half of it is gone after L/ω, L the ruptured arc:
/// L/2π revolutions. The upwind scheme smears the front, not the centroid: within 15 %.
#[test]
fn a_fluid_fraction_disturbance_drifts_out_at_half_the_shaft_speed() {
    let per_rev = 128;
    let mut mc = FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::DEFAULT)
        .unwrap()
        .with_cavitation(Cavitation::MassConserving);
    let kin = JournalKinematics::at_position([0.5323 * C, 0.0], OMEGA_9000_RPM);
    mc.solve(&kin).unwrap();
    let v_ref = mc.fluid_volume_m3();
    let arc = (0..60).filter(|&i| mc.fluid_fraction(i, 0) < 1.0).count() as f64 * 6.0;
    let dt = 2.0 * PI / OMEGA_9000_RPM / per_rev as f64;
    FilmModel::begin_step(&mut mc, dt);
    mc.disturb_committed_fraction(0.5);
    let mut missing = Vec::new();
    for _ in 0..2 * per_rev {
        FilmModel::begin_step(&mut mc, dt);
        let r = mc.solve(&kin).unwrap();
        assert!(r.force_n.iter().all(|f| f.is_finite()));
        FilmModel::commit_step(&mut mc);
        missing.push(v_ref - mc.fluid_volume_m3());
    }
    let first = missing[0];
    let revs_to = |share: f64| {
        let n = missing
            .iter()
            .position(|&m| m < share * first)
            .unwrap_or(missing.len());
        (n + 1) as f64 / per_rev as f64
    };
    let (half, tenth, hundredth) = (revs_to(0.5), revs_to(0.1), revs_to(0.01));
    let expected = arc / 360.0;
    println!(
        "memory: ruptured arc {arc:.0}° (mid-plane), missing volume {first:.3e} m³ ({:.1} % of \
         the film's); half gone after {half:.3} rev (drift estimate L/2π = {expected:.3}), 90 % \
         after {tenth:.3}, 99 % after {hundredth:.3} rev",
        100.0 * first / v_ref
    );
    assert!(first > 0.0);
    assert!(
        (half / expected - 1.0).abs() < 0.15,
        "half-life {half} rev vs {expected}"
    );
    // and the film forgets: 99 % of the disturbance gone within two revolutions
    assert!(hundredth < 2.0, "99 % gone after {hundredth} rev");
}

/// The fluid-fraction map of a run (`TransientResult::fluid_fraction_maps`, drawn by
/// `simulate --plot` as `fluid_fraction_<bearing>.svg`): with mass conservation one row a step
/// over the last two revolutions at the final speed, every φ in [0, 1] (the complementarity
/// bounds, M2), the ruptured zone's streamers below 0.9 (8,000 rpm: 0.27–0.28, README "In the
/// rotor transient") and the pressure zone full; a Reynolds run has none. The plot is written
/// and names φ's floor.
#[test]
fn a_run_keeps_its_fluid_fraction_map_and_plots_it() {
    use rotor_twin::transient::{run_transient, TransientSpec, FLUID_FRACTION_POINTS};
    let per_rev = 32;
    let spec = TransientSpec {
        speed_rpm: 8000.0,
        revolutions: 3,
        coupling: Coupling::Nonlinear,
        steps_per_rev: per_rev,
        grid: None,
        film: rotor_twin::dynamics::FilmEvaluation::Direct,
    };
    let desc = MachineDescription::load(None).unwrap();
    let mut rotor = Rotor::from_description(&desc);
    let reynolds = run_transient(&rotor, &spec).unwrap();
    assert!(reynolds.fluid_fraction_maps.iter().all(Vec::is_empty));
    rotor.set_cavitation(Cavitation::MassConserving).unwrap();
    let r = run_transient(&rotor, &spec).unwrap();
    assert_eq!(r.fluid_fraction_maps.len(), 2);
    for map in &r.fluid_fraction_maps {
        assert_eq!(map.len(), 2 * per_rev, "rows: two revolutions of steps");
        assert!(map.iter().all(|row| row.len() == FLUID_FRACTION_POINTS));
        let all = || map.iter().flatten().copied();
        assert!(all().all(|v| (0.0..=1.0).contains(&v)));
        let lowest = all().fold(1.0_f64, f64::min);
        let full =
            all().filter(|&v| v == 1.0).count() as f64 / (map.len() * FLUID_FRACTION_POINTS) as f64;
        println!(
            "φ down to {lowest:.3}, {:.0} % of the cells full",
            100.0 * full
        );
        assert!(
            lowest < 0.9,
            "the ruptured zone holds streamers: φ {lowest}"
        );
        assert!(full > 0.3, "the pressure zone is full: {full}");
    }
    // the plain bearing's feed line: fixed where the gap was widest at the start, opposite the
    // loaded side (the static load points down, −y: the gap is widest above the journal,
    // turned on by the attitude, here 144° from +x within the grid's 6° columns); full on every
    // row of the map
    assert_eq!(reynolds.feed_angles_rad, vec![None, None]);
    for (b, map) in r.fluid_fraction_maps.iter().enumerate() {
        let feed = r.feed_angles_rad[b].expect("a mass-conserving plain film has a feed line");
        let deg = feed.to_degrees();
        println!("bearing {b}: feed line at {deg:.1}°");
        assert!((90.0..180.0).contains(&deg), "above the journal: {deg}°");
        let k = (deg / 360.0 * FLUID_FRACTION_POINTS as f64).round() as usize;
        assert!(map.iter().all(|row| row[k % FLUID_FRACTION_POINTS] == 1.0));
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("fluid_fraction_plot");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("phi.svg");
    let feed = r.feed_angles_rad[0].map(f64::to_degrees);
    rotor_twin::plot::fluid_fraction_map_svg(&path, "test", &r.fluid_fraction_maps[0], feed)
        .unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.contains("φ down to"), "the title names the floor");
    assert!(
        svg.contains("feed line"),
        "the feed line is drawn and named"
    );
}

/// `simulate` and `sweep` run the mass-conserving film (the JSON says so) and refuse it with the
/// film table, naming the reason.
#[test]
fn the_cli_runs_the_mass_conserving_film_and_refuses_the_table() {
    let (ok, out, err) = run_cli(&[
        "simulate",
        "--speed-rpm",
        "8000",
        "--revs",
        "2",
        "--steps-per-rev",
        "32",
        "--cavitation",
        "mass-conserving",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["cavitation"], "mass-conserving", "{out}");
    // the 8,000 rpm static film: p_max ≈ 0.37–0.46 MPa over the unbalance orbit (README)
    let p = v["bearings"][0]["max_pressure_pa"].as_f64().unwrap();
    assert!((0.3e6..0.6e6).contains(&p), "p_max {p}");
    for cmd in ["simulate", "sweep"] {
        let mut args = vec![
            cmd,
            "--revs",
            "2",
            "--cavitation",
            "mass-conserving",
            "--film",
            "table",
        ];
        if cmd == "simulate" {
            args.extend(["--speed-rpm", "8000"]);
        } else {
            args.extend([
                "--from-rpm",
                "8000",
                "--to-rpm",
                "8000",
                "--step-rpm",
                "100",
            ]);
        }
        let (ok, _, err) = run_cli(&args);
        assert!(!ok, "{cmd} ran the table with mass conservation");
        assert!(err.contains("needs --film direct"), "{cmd}: {err}");
    }
}

/// The seed case with both cavitation models (ignored: minutes; `MCAV_REVS` revolutions,
/// default 60, 128 steps a revolution, a 2 N·s kick at node 15 at 0.05 s as in "Existence
/// range of the whip"). Prints one line per speed and model and writes the fluid-fraction maps
/// of the last two revolutions to `target/mcav/`.
#[test]
#[ignore]
fn seed_case_comparison() {
    use rotor_twin::monitor::{ClassifierSettings, Monitor};
    let revs: usize = std::env::var("MCAV_REVS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    let speeds: Vec<f64> = std::env::var("MCAV_SPEEDS")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![8000.0, 8500.0, 9000.0]);
    let per_rev = 128;
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("../mcav");
    std::fs::create_dir_all(&dir).unwrap();
    for &rpm in &speeds {
        for cav in [Cavitation::Reynolds, Cavitation::MassConserving] {
            let (mut twin, input) = seed_twin(rpm, cav, per_rev);
            let h = twin.config().time_step_s;
            let mut monitor = Monitor::new(&twin, per_rev + 2, ClassifierSettings::default());
            let n = twin.bearing_clearances_m().len();
            let (mut maps, mut zeta) = (
                vec![Vec::new(); n],
                vec![[f64::MAX, f64::MIN, f64::MAX, f64::MIN]; n],
            );
            let (mut pmax, mut phimin) = (vec![0.0_f64; n], vec![1.0_f64; n]);
            let start = std::time::Instant::now();
            let total = revs * per_rev;
            for step in 0..total {
                let t = twin.time_s();
                let kick = if t <= 0.05 && 0.05 < t + h {
                    2.0 / h
                } else {
                    0.0
                };
                twin.set_external_force(15, [kick, 0.0]).unwrap();
                let out = match twin.step(&input) {
                    Ok(out) => out.clone(),
                    Err(e) => {
                        if let Ok(path) = std::env::var("MCAV_STATE_OUT") {
                            write_twin_state(&twin, rpm, per_rev, &path);
                        }
                        panic!("{rpm:.0} rpm {cav:?}, step {step}: {e}");
                    }
                };
                monitor.record(&twin);
                if step >= total - 2 * per_rev {
                    for (b, s) in out.bearings.iter().enumerate() {
                        let mut phi = vec![0.0; 60];
                        twin.midplane_fluid_fraction(b, &mut phi);
                        phimin[b] = phimin[b].min(phi.iter().copied().fold(1.0, f64::min));
                        maps[b].push(phi);
                        pmax[b] = pmax[b].max(s.max_pressure_pa);
                        // from the journal's line of centres (the thinnest film), in (−270°, 90°]: ζ1
                        // before it, ζ2 after
                        let rel = |a: f64| {
                            let d = (a - s.attitude_rad).to_degrees().rem_euclid(360.0);
                            if d > 90.0 {
                                d - 360.0
                            } else {
                                d
                            }
                        };
                        let (z1, z2) = (rel(s.film_start_rad), rel(s.film_end_rad));
                        let z = &mut zeta[b];
                        *z = [z[0].min(z1), z[1].max(z1), z[2].min(z2), z[3].max(z2)];
                    }
                }
            }
            let wall = start.elapsed().as_secs_f64();
            let rep = monitor.report();
            for (b, r) in rep.bearings.iter().enumerate() {
                println!(
                    "MCAV {rpm:.0} {cav:?} b{b}: state {:?}, 1X {:.2} µm, sub-sync {:.2} µm at {:.3}X, \
                     ε_max {:.3}, p_max {:.3} MPa, ζ1 {:.0}–{:.0}°, ζ2 {:.0}–{:.0}° (from the \
                     journal's line of centres), φ_min {:.3}; {revs} rev in {wall:.0} s",
                    r.state,
                    1e6 * r.one_x_amplitude_m,
                    1e6 * r.subsync_amplitude_m,
                    r.subsync_ratio,
                    r.max_eccentricity_ratio,
                    1e-6 * pmax[b],
                    zeta[b][0],
                    zeta[b][1],
                    zeta[b][2],
                    zeta[b][3],
                    phimin[b],
                );
                if cav == Cavitation::MassConserving {
                    let csv: String = maps[b]
                        .iter()
                        .map(|row| {
                            let cells: Vec<String> =
                                row.iter().map(|v| format!("{v:.4}")).collect();
                            cells.join(",") + "\n"
                        })
                        .collect();
                    std::fs::write(dir.join(format!("phi_{rpm:.0}_b{b}.csv")), csv).unwrap();
                    let path = dir.join(format!("phi_{rpm:.0}_b{b}.svg"));
                    fluid_fraction_map_svg(
                        &path,
                        &format!(
                            "fluid fraction, mid-plane, bearing {b}, {rpm:.0} rpm, last 2 rev"
                        ),
                        &maps[b],
                        720.0,
                    )
                    .unwrap();
                }
            }
        }
    }
}

/// Writes the twin's state (the start of a step that failed: the step leaves it unchanged) for
/// [`recorded_twin`]: speed, steps a revolution, angle, time, q, q̇, q̈, and each bearing's
/// film memory (φ⁰, full nodes).
fn write_twin_state(twin: &Twin, rpm: f64, per_rev: usize, path: &str) {
    let line = |key: &str, v: &[f64]| {
        let cells: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        format!("{key} {}\n", cells.join(" "))
    };
    let (q, qd, qdd) = twin.state_vectors();
    let out = twin.output();
    let mut text = format!(
        "# the mass-conserving twin (seed machine, nonlinear, direct film, kicked 2 N·s at node 15 \
         at 0.05 s) at the start of a step it could not take (t = {:.6} s)\n",
        out.time_s
    );
    text += &line("rpm", &[rpm]);
    text += &line("per_rev", &[per_rev as f64]);
    text += &line("angle_rad", &[out.angle_rad]);
    text += &line("time_s", &[out.time_s]);
    text += &line("q", q);
    text += &line("qd", qd);
    text += &line("qdd", qdd);
    for b in 0..twin.bearing_clearances_m().len() {
        if let Some((phi0, full)) = twin.film_memory(b) {
            text += &line(&format!("phi0_{b}"), &phi0);
            let f: Vec<f64> = full.iter().map(|&x| f64::from(u8::from(x))).collect();
            text += &line(&format!("full_{b}"), &f);
        }
    }
    std::fs::write(path, text).unwrap();
}

/// The mass-conserving seed twin at `per_rev` steps a revolution put into the state recorded by
/// [`write_twin_state`] in `tests/reference/<file>` (after one step from the equilibrium, so
/// the films are in their time-step form and keep the feed line the recorded run had).
/// Returns the twin, its input and the recorded time (s).
fn recorded_twin(file: &str, per_rev: usize) -> (Twin, StepInput, f64) {
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
    let (mut twin, input) = seed_twin(field("rpm")[0], Cavitation::MassConserving, per_rev);
    twin.step(&input).unwrap();
    twin.set_state_vectors(&field("q"), &field("qd"), &field("qdd"))
        .unwrap();
    twin.shift_angle(field("angle_rad")[0] - twin.output().angle_rad);
    for b in 0..twin.bearing_clearances_m().len() {
        let full: Vec<bool> = field(&format!("full_{b}"))
            .iter()
            .map(|&f| f > 0.5)
            .collect();
        twin.set_film_memory(b, &field(&format!("phi0_{b}")), &full)
            .unwrap();
    }
    (twin, input, field("time_s")[0])
}

/// Issue 18: the kicked 9,000 rpm mass-conserving whip at the wall (recorded at the start of
/// the step main could not take, t = 0.352188 s, revolution 52.8: both journals in wall contact
/// at ε 0.996 / 0.997). Main's Newton cycled between two iterates 40 pm apart at h, h/2 and h/4
/// (the film's slope changes there: φ's sets switch) and gave up. With the substep levels h/8
/// and h/16 the step is taken (at h/16), and the next ones whole. Check of the result: the same
/// 4 steps taken by a twin with a 4× smaller step (512 a revolution, 16 steps) — Newmark's
/// error — give the same journal positions within 0.05 % of the clearance (measured 0.004 %).
#[test]
fn the_wall_contact_step_of_the_whip_is_taken() {
    let file = "twin_mcav_wall_9000rpm.txt";
    let (mut coarse, input, _) = recorded_twin(file, 128);
    let (mut fine, _, _) = recorded_twin(file, 512);
    let (t_coarse, t_fine) = (coarse.time_s(), fine.time_s());
    let c = coarse.bearing_clearances_m();
    let mut substeps = Vec::new();
    for _ in 0..4 {
        substeps.push(coarse.step(&input).unwrap().substeps);
    }
    for _ in 0..16 {
        fine.step(&input).unwrap();
    }
    let (a, b) = (coarse.output(), fine.output());
    let mut gap = 0.0_f64;
    let mut eps = Vec::new();
    for (k, (x, y)) in a.bearings.iter().zip(&b.bearings).enumerate() {
        let d = (x.position_m[0] - y.position_m[0]).hypot(x.position_m[1] - y.position_m[1]);
        gap = gap.max(d / c[k]);
        eps.push(x.eccentricity_ratio);
    }
    println!(
        "wall-contact step: substeps {substeps:?}, ε after 4 steps {eps:.5?}, h vs h/4 \
         positions differ by {:.4} % of c after {:.3e} / {:.3e} s",
        100.0 * gap,
        a.time_s - t_coarse,
        b.time_s - t_fine
    );
    assert_eq!(
        substeps[0], 16,
        "the recorded step needs h/16 (main: not converged at h/4)"
    );
    assert!(gap < 5e-4, "h vs h/4: {gap}");
    // still at the wall (contact from ε 0.99; the wall spring lets the journal in ≈ 1 % of c)
    assert!(eps.iter().all(|e| (0.99..1.01).contains(e)), "ε {eps:?}");
}

/// Diagnosis (ignored): steps the recorded wall-contact state `MCAV_STATE` (a file in
/// tests/reference) `MCAV_STEPS` times at 128 steps a revolution and prints each step.
#[test]
#[ignore]
fn recorded_wall_state_steps() {
    let file = std::env::var("MCAV_STATE").unwrap_or_else(|_| "twin_mcav_wall_9000rpm.txt".into());
    let steps: usize = std::env::var("MCAV_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    let (mut twin, input, t0) = recorded_twin(&file, 128);
    let c = twin.bearing_clearances_m();
    for k in 0..steps {
        match twin.step(&input) {
            Ok(out) => {
                let e: Vec<String> = out
                    .bearings
                    .iter()
                    .zip(&c)
                    .map(|(b, c)| {
                        format!(
                            "ε {:.5} contact {} p_max {:.1} MPa",
                            b.position_m[0].hypot(b.position_m[1]) / c,
                            b.contact,
                            1e-6 * b.max_pressure_pa
                        )
                    })
                    .collect();
                println!(
                    "step {k} (from t0 {t0:.6} s): {} iterations, {} substeps; {}",
                    out.newton_iterations,
                    out.substeps,
                    e.join("; ")
                );
            }
            Err(e) => {
                println!("step {k}: {e}");
                break;
            }
        }
    }
}

// --- the fluid-fraction map of the study (plotters' SVG backend, as `src/plot`): bearing angle
// against shaft rotation, white = no fluid (φ = 0), dark blue = whole film (φ = 1) ---
use plotters::prelude::*;
use std::path::Path;

/// Colour of the fluid fraction `phi` (clamped to [0, 1]).
fn fraction_shade(phi: f64) -> RGBColor {
    let f = phi.clamp(0.0, 1.0);
    let mix = |full: f64| (255.0 + (full - 255.0) * f).round() as u8;
    RGBColor(mix(20.0), mix(50.0), mix(140.0))
}

/// Mid-plane fluid fraction `map[t][k]` (time sample t, bearing angle 360°·k/len from +x) over
/// `span_deg` degrees of shaft rotation, with a colour bar.
fn fluid_fraction_map_svg(
    path: &Path,
    title: &str,
    map: &[Vec<f64>],
    span_deg: f64,
) -> anyhow::Result<()> {
    let steps = map.len().max(1);
    let points = map.first().map_or(1, Vec::len).max(1);
    let span = if span_deg.is_finite() && span_deg > 0.0 {
        span_deg
    } else {
        720.0
    };
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 18))?;
    let (map_area, bar_area) = root.split_horizontally(790);
    let mut chart = ChartBuilder::on(&map_area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..span, 0.0..360.0)?;
    chart
        .configure_mesh()
        .x_desc("shaft rotation (deg)")
        .y_desc("bearing angle from +x (deg)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()?;
    let (dx, dy) = (span / steps as f64, 360.0 / points as f64);
    chart.draw_series(map.iter().enumerate().flat_map(|(t, row)| {
        row.iter().enumerate().map(move |(k, &phi)| {
            let x = t as f64 * dx;
            Rectangle::new(
                [(x, k as f64 * dy), (x + dx, (k + 1) as f64 * dy)],
                fraction_shade(phi).filled(),
            )
        })
    }))?;
    let mut bar = ChartBuilder::on(&bar_area)
        .margin_top(15)
        .margin_bottom(55)
        .margin_right(10)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, 0.0..1.0)?;
    bar.configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_desc("fluid fraction φ")
        .y_label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 13))
        .draw()?;
    let n = 50;
    bar.draw_series((0..n).map(|i| {
        let (a, b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
        Rectangle::new([(0.0, a), (1.0, b)], fraction_shade(a).filled())
    }))?;
    root.present()?;
    Ok(())
}

/// The onset study's machine: `MCAV_ONSET_CONFIG` (a machine file's path), else reading (A),
/// `config/orc_microturbine_100kw_d55.yaml`.
fn onset_machine() -> Rotor {
    let path = std::env::var("MCAV_ONSET_CONFIG").unwrap_or_else(|_| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/config/orc_microturbine_100kw_d55.yaml"
        )
        .to_string()
    });
    let desc = MachineDescription::load(Some(std::path::Path::new(&path))).unwrap();
    Rotor::from_description(&desc)
}

/// The growth rate (1/s) of a small free whirl of (A) at `rpm` with cavitation `cav`: no
/// unbalance, a `kick` (N·s) at node 15 from the static equilibrium, then `revs` revolutions;
/// the largest distance of the pulley-end journal from its equilibrium in each window of 4
/// revolutions (the whirl near ½X takes 2), and the log-linear slope of those peaks over the
/// windows after the first 2 (the kick's other modes decayed). Also the whirl's last peak (m)
/// and the wall time (s).
fn free_whirl_growth(
    rpm: f64,
    (cav, table): (Cavitation, bool),
    kick: f64,
    revs: usize,
) -> (f64, f64, f64) {
    // steps a revolution: 128, or `MCAV_ONSET_STEPS` (the step convergence of the onset)
    let per_rev: usize = std::env::var("MCAV_ONSET_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(128);
    let mut rotor = onset_machine();
    rotor.unbalance.clear();
    rotor.set_cavitation(cav).unwrap();
    let w = rpm * PI / 30.0;
    let mut config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, per_rev);
    if table {
        rotor_twin::film::set_disk_cache(Some(rotor_twin::film::TableCache::new(
            common::test_cache_dir(),
        )));
        config.film = rotor_twin::dynamics::FilmEvaluation::Table;
    }
    let mut twin = Twin::new(&rotor, config, w).unwrap();
    let input = StepInput {
        speed_rad_s: w,
        accel_rad_s2: 0.0,
    };
    let h = twin.config().time_step_s;
    let eq = twin.output().bearings[0].position_m;
    let started = std::time::Instant::now();
    let window = 4 * per_rev;
    let mut peaks = Vec::new();
    let mut peak = 0.0_f64;
    for step in 0..revs * per_rev {
        let f = if step == 0 { kick / h } else { 0.0 };
        twin.set_external_force(15, [f, 0.0]).unwrap();
        let p = twin.step(&input).unwrap().bearings[0].position_m;
        peak = peak.max((p[0] - eq[0]).hypot(p[1] - eq[1]));
        if (step + 1) % window == 0 {
            peaks.push(peak);
            peak = 0.0;
        }
    }
    let skip = std::env::var("MCAV_ONSET_SKIP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2);
    let fit: Vec<(f64, f64)> = (peaks.iter().enumerate().skip(skip))
        .map(|(k, a)| ((k as f64 + 0.5) * window as f64 * h, a.ln()))
        .collect();
    let n = fit.len() as f64;
    let (mt, my) = (
        fit.iter().map(|p| p.0).sum::<f64>() / n,
        fit.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = fit.iter().map(|p| (p.0 - mt) * (p.1 - my)).sum::<f64>()
        / fit.iter().map(|p| (p.0 - mt).powi(2)).sum::<f64>();
    let last = *peaks.last().unwrap();
    (slope, last, started.elapsed().as_secs_f64())
}

/// The onset speed with mass conservation (issue 18; a study, not run by `cargo test`: ≈ 1 s
/// a revolution for the mass-conserving film). The growth rate of a small free whirl of
/// reading (A) (no unbalance, a 0.05 N·s kick) at held speeds, both films; its zero by linear
/// interpolation between the speeds that bracket it. Reference for the method: the Reynolds
/// film's zero against its linear threshold (8,471.3 rpm, `modes` on 60 × 10); the
/// mass-conserving film's zero is the figure sought.
/// `MCAV_ONSET_SPEEDS=8300,8500,8700 MCAV_ONSET_REVS=40 cargo test --release --test
/// twin_mass_conserving -- --ignored onset_speed --nocapture`
#[test]
#[ignore = "a study: minutes a speed with the mass-conserving film"]
fn onset_speed_with_mass_conservation() {
    let speeds: Vec<f64> = std::env::var("MCAV_ONSET_SPEEDS")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![8300.0, 8500.0, 8700.0]);
    let revs: usize = std::env::var("MCAV_ONSET_REVS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40);
    let kick: f64 = std::env::var("MCAV_ONSET_KICK")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.05);
    // (cavitation, tabulated film)
    let films: Vec<(Cavitation, bool)> = match std::env::var("MCAV_ONSET_FILMS").as_deref() {
        Ok("reynolds") => vec![(Cavitation::Reynolds, false)],
        Ok("reynolds-table") => vec![(Cavitation::Reynolds, true)],
        Ok("mass-conserving") => vec![(Cavitation::MassConserving, false)],
        _ => vec![
            (Cavitation::Reynolds, true),
            (Cavitation::Reynolds, false),
            (Cavitation::MassConserving, false),
        ],
    };
    for film in films {
        let mut rates = Vec::new();
        for &rpm in &speeds {
            let (sigma, last, wall) = free_whirl_growth(rpm, film, kick, revs);
            println!(
                "ONSET {film:?} {rpm:.0} rpm: growth {sigma:+.3} 1/s, last peak {:.4} µm ({revs} rev in {wall:.0} s)",
                1e6 * last
            );
            rates.push((rpm, sigma));
        }
        let zero = rates
            .windows(2)
            .find(|p| p[0].1 < 0.0 && p[1].1 >= 0.0)
            .map(|p| p[0].0 + (p[1].0 - p[0].0) * (-p[0].1) / (p[1].1 - p[0].1));
        println!("ONSET {film:?}: growth rate zero at {zero:?} rpm");
        if !film.1 {
            // the linear threshold with this film's steady eight coefficients (the
            // mass-conserving film's: central differences of its force with ∂φ/∂t = 0, no memory)
            let mut rotor = onset_machine();
            rotor.set_cavitation(film.0).unwrap();
            let statics = rotor_twin::rotor::static_solution(&rotor).unwrap();
            let lo = speeds.iter().copied().fold(f64::INFINITY, f64::min) - 500.0;
            let hi = speeds.iter().copied().fold(0.0, f64::max) + 500.0;
            let t = rotor_twin::rotor::stability_threshold(&rotor, &statics, lo, hi, 200.0)
                .unwrap()
                .map(|t| t.speed_rpm);
            println!("ONSET {film:?}: linear threshold with the steady coefficients {t:?} rpm");
        }
    }
}
