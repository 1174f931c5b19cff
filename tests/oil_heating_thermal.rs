//! The films' own heating by the adiabatic thermal film in the live twin (issue 18):
//! `oil_heating: {model: thermal_film}` runs each film bearing at µ(T̄), T̄ the flow-weighted
//! mean temperature of its thermal film (E1–E3 of `src/film/thermal.rs`) under the static load
//! at the speed in force — the effective-temperature route of `modes --thermal`, now what the
//! node, the replay, `bearing --speeds` and `modes` run.

mod common;
use common::heating::*;
use common::*;
use rotor_twin::driver::{Driver, DriverSettings, Fed, ModelKind};
use rotor_twin::dynamics::FilmEvaluation;
use rotor_twin::film::{ThermalOil, ZERO_CELSIUS_K};
use rotor_twin::rotor::{
    stability_threshold, stability_threshold_thermal, static_solution, thermal_equilibria,
    BearingModel, MachineDescription, Rotor, DEFAULT_MACHINE_YAML,
};
use std::f64::consts::PI;

const THERMAL_YAML: &str = include_str!("../config/orc_microturbine_100kw_thermal.yaml");
/// MDM's c_p at 40–42 °C (J/(kg·K)), the shipped file's.
const MDM_CP: f64 = 1820.0;

fn thermal_rotor() -> Rotor {
    Rotor::from_description(&MachineDescription::from_yaml(THERMAL_YAML, "thermal").unwrap())
}

fn rad_s(rpm: f64) -> f64 {
    rpm * PI / 30.0
}

/// The oils of `stability_threshold_thermal` and `thermal_equilibria`: each film bearing's
/// law, MDM's c_p, supply `supply_c` (°C).
fn oils(rotor: &Rotor, supply_c: f64) -> Vec<ThermalOil> {
    (rotor.bearings.iter())
        .filter_map(|b| match &b.model {
            BearingModel::Film(f) => Some(ThermalOil {
                law: f.viscosity_law.unwrap(),
                specific_heat_j_per_kg_k: MDM_CP,
                supply_temperature_k: supply_c + ZERO_CELSIUS_K,
            }),
            _ => None,
        })
        .collect()
}

/// The shipped file is the built-in machine and the two `oil_heating` lines, nothing else:
/// every line that is not a comment is the default's, but for the name and those two.
#[test]
fn the_shipped_thermal_file_is_the_default_with_its_heating() {
    let lines = |s: &'static str| -> Vec<&'static str> {
        s.lines()
            .filter(|l| !l.trim_start().starts_with('#'))
            .filter(|l| !l.starts_with("name:") && !l.contains("oil_heating:"))
            .collect()
    };
    assert_eq!(lines(THERMAL_YAML), lines(DEFAULT_MACHINE_YAML));
    assert_eq!(THERMAL_YAML.matches("model: thermal_film").count(), 2);
}

/// Each film bearing of the built-in machine as its coupled thermal film (Newton on the film
/// and its field together, `thermal_equilibria`) at `rpm`, supply 40 °C: the reference.
fn coupled_thermal_films_at(rpm: f64) -> Vec<rotor_twin::rotor::ThermalBearing> {
    let default = Rotor::from_description(&MachineDescription::load(None).unwrap());
    let statics = static_solution(&default).unwrap();
    thermal_equilibria(&default, &statics, rpm, &oils(&default, 40.0)).unwrap()
}

/// The threshold with each film's full thermal field, its eight coefficients taken with the
/// field held (`stability_threshold_thermal`, 9,363.3 rpm on (B), README "Thermal film"), met
/// by the twin's route: the balance at the threshold speed, found as `modes` finds it (a fixed
/// point on the speed), leaves each finite film with the thermal film's viscosity field, and
/// `modes` takes their coefficients. The same frozen-field physics reached through the
/// balance, the machine and `modes`: it must agree within 0.01 % (measured 0.0000 %; the
/// field's mean alone, session 19, gave −0.035 %, and the effective-temperature route's
/// first-order bound is 0.42 %). And the heated threshold lies above the isothermal 9,291 rpm
/// (a thinner oil).
#[test]
fn thermal_heating_carries_the_thermal_films_threshold() {
    let default = Rotor::from_description(&MachineDescription::load(None).unwrap());
    let statics = static_solution(&default).unwrap();
    let range = [6000.0, 12000.0, 500.0];
    let full = stability_threshold_thermal(&default, &statics, range, &oils(&default, 40.0))
        .unwrap()
        .expect("a thermal threshold in range")
        .speed_rpm;
    let isothermal = stability_threshold(&default, &statics, range[0], range[1], range[2])
        .unwrap()
        .unwrap()
        .speed_rpm;
    let mut rotor = thermal_rotor();
    let mut rpm = 9000.0;
    let mut temps = Vec::new();
    for _ in 0..20 {
        temps = rotor.heat_films(None, rad_s(rpm), 1.0).unwrap();
        let next = stability_threshold(&rotor, &statics, range[0], range[1], range[2])
            .unwrap()
            .unwrap()
            .speed_rpm;
        if (next - rpm).abs() < 0.1 {
            rpm = next;
            break;
        }
        rpm = next;
    }
    for t in &temps {
        println!(
            "{} at {rpm:.1} rpm: T̄ {:.3} °C, peak rise {:.3} K, scale ×{:.5}, {} equilibria",
            t.name,
            t.effective.effective_temperature_k - ZERO_CELSIUS_K,
            t.effective.temperature_rise_k,
            t.viscosity_scale,
            t.effective.evaluations
        );
    }
    let off = rpm / full - 1.0;
    println!(
        "threshold: isothermal {isothermal:.1}, thermal film (field held) {full:.3}, twin's route {rpm:.3} rpm ({:+.4} %)",
        100.0 * off
    );
    // the films carry the thermal film's field (the mean alone gave −0.035 %, session 19)
    assert!(off.abs() < 1e-4, "{rpm} vs {full}");
    assert!(rpm > isothermal + 30.0, "{rpm} vs {isothermal}");
}

/// At 9,000 rpm: T̄ is the coupled thermal film's own flow-weighted mean (`thermal_equilibria`,
/// Newton on the coupled film: a second solution method, 1e-6 K), the heat carried equals its
/// dissipation (conservation, 1e-5), and the film the twin runs — at µ(T̄) with the thermal
/// film's viscosity field around it (session 20; the mean alone sat +0.5 % off) — sits at the
/// thermal film's own ε within 1e-4.
#[test]
fn the_heated_films_against_their_thermal_films_at_rated_speed() {
    let reference = coupled_thermal_films_at(9000.0);
    let mut rotor = thermal_rotor();
    let started = std::time::Instant::now();
    let temps = rotor.heat_films(None, rad_s(9000.0), 1.0).unwrap();
    println!(
        "heat balance (2 bearings, direct film): {:.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    assert_eq!(temps.len(), 2);
    for (t, r) in temps.iter().zip(&reference) {
        let e = &t.effective;
        let eps = e.equilibrium.eccentricity_ratio;
        println!(
            "{}: T̄ {:.4} °C (reference {:.4}), inlet {:.2}, peak {:.2} °C; heat {:.3} W, full-film friction {:.3} W; ε of the twin's film (µ(T̄), the field) {eps:.6}, thermal film's {:.6} ({:+.4} %)",
            t.name,
            e.effective_temperature_k - ZERO_CELSIUS_K,
            r.state.mean_temperature_k - ZERO_CELSIUS_K,
            r.state.inlet_temperature_k - ZERO_CELSIUS_K,
            r.state.max_temperature_k - ZERO_CELSIUS_K,
            e.heat_carried_w,
            e.friction_power_w,
            r.eccentricity_ratio,
            100.0 * (eps / r.eccentricity_ratio - 1.0)
        );
        assert!((e.effective_temperature_k - r.state.mean_temperature_k).abs() < 1e-6);
        assert!(e.effective_temperature_k > e.supply_temperature_k + 2.0);
        // the oil carries the thermal film's dissipation away (its own balance at its fixed
        // point, here against the coupled solve's), below the full-film friction reported
        assert!((e.heat_carried_w / r.state.dissipation_w - 1.0).abs() < 1e-5);
        assert!(e.friction_power_w == e.equilibrium.film.power_loss_w.abs());
        assert!(e.friction_power_w > e.heat_carried_w);
        assert!(
            rel(eps, r.eccentricity_ratio) < 1e-4,
            "{eps} vs {}",
            r.eccentricity_ratio
        );
        assert!((t.viscosity_scale - e.viscosity_pa_s / 0.0008).abs() < 1e-12);
    }
}

/// The direct film runs the thermal film's viscosity *field*, not only its mean (session 20):
/// after a balance at 9,000 rpm each finite film carries µ(T_i)/µ(T̄) per column
/// (`FilmBearing::viscosity_field`), and a twin on the direct film (no unbalance: it starts at
/// the static equilibrium) starts at the thermal film's own equilibrium (`thermal_equilibria`,
/// Newton on the coupled film) to 1e-4 in ε, where the mean's isoviscous film (the fields
/// cleared) sits +0.5 % off; the same machine on the table runs the mean.
#[test]
fn the_direct_twin_starts_at_the_thermal_films_equilibrium() {
    use rotor_twin::dynamics::{Coupling, Twin, TwinConfig};
    let reference = coupled_thermal_films_at(9000.0);
    let mut rotor = thermal_rotor();
    // no unbalance: the twin starts at the static equilibrium alone
    rotor.unbalance.clear();
    let w = rad_s(9000.0);
    let temps = rotor.heat_films(None, w, 1.0).unwrap();
    let fields = rotor.film_viscosity_fields();
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, 128);
    let twin = Twin::new(&rotor, config, w).unwrap();
    // the same machine with the fields cleared: the mean's isoviscous film
    let mut uniform = rotor.clone();
    for film in 0..2 {
        uniform.set_film_viscosity_field(film, &[]);
    }
    let uniform = Twin::new(&uniform, config, w).unwrap();
    let means = uniform.output().bearings.clone();
    let bearings = &twin.output().bearings;
    for ((((b, r), t), field), m) in (bearings.iter().zip(&reference))
        .zip(&temps)
        .zip(&fields)
        .zip(&means)
    {
        let (lo, hi) = field
            .iter()
            .fold((f64::MAX, 0.0_f64), |(l, h), &v| (l.min(v), h.max(v)));
        let mean_eps = m.eccentricity_ratio;
        println!(
            "{}: field µ/µ(T̄) {lo:.4}…{hi:.4} over {} columns; twin's start ε {:.6}, thermal film's {:.6} ({:+.4} %); the mean's isoviscous film {mean_eps:.6} ({:+.3} %)",
            r.bearing,
            field.len(),
            b.eccentricity_ratio,
            r.eccentricity_ratio,
            100.0 * (b.eccentricity_ratio / r.eccentricity_ratio - 1.0),
            100.0 * (mean_eps / r.eccentricity_ratio - 1.0)
        );
        assert_eq!(field.len(), 60, "one ratio a column of the 60 × 10 grid");
        // the oil heats along the film (µ down to −3 %) and re-forms cooler (+3 %)
        assert!(lo < 0.98 && hi > 1.02, "{lo}…{hi}");
        assert!(rel(b.eccentricity_ratio, r.eccentricity_ratio) < 1e-4);
        // the balance reports the film the twin runs
        let reported = t.effective.equilibrium.eccentricity_ratio;
        assert!(rel(reported, b.eccentricity_ratio) < 1e-6);
        assert!(
            rel(mean_eps, r.eccentricity_ratio) > 2e-3,
            "the mean alone is off"
        );
    }
    // on the table the same machine runs the mean (a table holds a uniform viscosity)
    use_test_table_cache();
    let table = TwinConfig {
        film: FilmEvaluation::Table,
        ..config
    };
    let twin = Twin::new(&rotor, table, w).unwrap();
    for (b, m) in twin.output().bearings.iter().zip(&means) {
        let mean_eps = m.eccentricity_ratio;
        assert!(
            rel(b.eccentricity_ratio, mean_eps) < 2e-3,
            "{} vs {mean_eps}",
            b.eccentricity_ratio
        );
    }
}

/// The live twin on the node's tabulated film: each balance's T̄ is the thermal film's (always
/// the finite solver) to 1e-9 K of `Rotor::heat_films` on a fresh machine, the running twin
/// runs at µ(T̄)/µ_ref, the balance is redone past 1 % of speed, and the twin steps on (its
/// cost per balance printed: it is taken on the model thread at a speed change).
#[test]
fn the_live_twin_on_the_table_heats_with_its_thermal_film() {
    use_test_table_cache();
    let rotor = thermal_rotor();
    let settings = DriverSettings::new(
        ModelKind::Nonlinear,
        FilmEvaluation::Table,
        rotor.rated_speed_rad_s,
    );
    let mut d = Driver::new(rotor, settings);
    let mut emit = |_: rotor_twin::session::Outgoing| {};
    let t0 = 1_767_225_600_000_000_000_i64;
    let ms = 1_000_000;
    assert!(matches!(
        d.feed(t0, speed_rpm(9000.0), &mut emit),
        Fed::Started { .. }
    ));
    assert_eq!(d.heat_balances(), (1, None));
    let check = |d: &Driver, rpm: f64| -> Vec<f64> {
        let temps = thermal_rotor().heat_films(None, rad_s(rpm), 1.0).unwrap();
        let live = d.film_oil();
        for (i, (l, t)) in live.iter().zip(&temps).enumerate() {
            let t_live = l.effective_temperature_k.expect("heated");
            let t_off = t.effective.effective_temperature_k;
            println!(
                "{rpm} rpm, {}: live T̄ {:.6} °C, offline {:.6} °C, scale ×{:.6}",
                l.name,
                t_live - ZERO_CELSIUS_K,
                t_off - ZERO_CELSIUS_K,
                l.viscosity_scale
            );
            assert!((t_live - t_off).abs() < 1e-9, "{}", l.name);
            let twin = d.session().unwrap().twin().film_viscosity_scale(i).unwrap();
            assert!((twin / t.viscosity_scale - 1.0).abs() < 1e-12);
        }
        temps
            .iter()
            .map(|t| t.effective.effective_temperature_k)
            .collect()
    };
    let hot = check(&d, 9000.0);
    let started = std::time::Instant::now();
    assert_eq!(d.feed(t0 + ms, speed_rpm(8000.0), &mut emit), Fed::Taken);
    println!(
        "speed 9,000 → 8,000 rpm with its heat balance: {:.1} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    assert_eq!(d.heat_balances().0, 2);
    let cooler = check(&d, 8000.0);
    for (h, c) in hot.iter().zip(&cooler) {
        assert!(h > c, "9,000 rpm {h} K vs 8,000 rpm {c} K");
    }
    assert_eq!(
        d.feed(t0 + 2 * ms, speed_rpm(8040.0), &mut emit),
        Fed::Taken
    );
    assert_eq!(d.heat_balances().0, 2);
    // the replay's report carries each film's temperature and scale in force
    let report = d.heat_balance_report().unwrap();
    assert_eq!(report.films.len(), 2);
    for (f, t) in report.films.iter().zip(&cooler) {
        assert!(
            (f.temperature_c - (t - ZERO_CELSIUS_K)).abs() < 1e-9,
            "{}",
            f.bearing
        );
    }
    assert_steps_on(&mut d, t0 + 20 * ms);
}

/// The node's heat balances run on a worker thread (`heat_balance_off_thread`): the twin
/// keeps stepping at the scales in force while a balance runs; three speeds fed while the first
/// balance runs are coalesced (the stale middle one is skipped or run, never queued behind the
/// newest); the scales taken at a later wake are those of the last speed, equal to 1e-12 of the
/// same speeds balanced on the driver's own thread.
#[test]
fn balances_off_the_model_thread_give_the_inline_scales() {
    use_test_table_cache();
    let settings = |off_thread: bool| DriverSettings {
        heat_balance_off_thread: off_thread,
        ..DriverSettings::new(
            ModelKind::Nonlinear,
            FilmEvaluation::Table,
            thermal_rotor().rated_speed_rad_s,
        )
    };
    let mut emit = |_: rotor_twin::session::Outgoing| {};
    let t0 = 1_767_225_600_000_000_000_i64;
    let ms = 1_000_000;
    let mut inline = Driver::new(thermal_rotor(), settings(false));
    let mut live = Driver::new(thermal_rotor(), settings(true));
    for (k, rpm) in [8000.0, 8500.0, 9000.0].into_iter().enumerate() {
        let t = t0 + k as i64 * ms;
        inline.feed(t, speed_rpm(rpm), &mut emit);
        live.feed(t, speed_rpm(rpm), &mut emit);
    }
    assert_eq!(inline.heat_balances(), (3, None));
    let mut t = t0 + 3 * ms;
    settle_heat(&mut live, &mut t);
    let (balances, failure) = live.heat_balances();
    println!("off the model thread: {balances} balances for 3 speeds");
    assert_eq!(failure, None);
    assert!((2..=3).contains(&balances), "{balances}");
    for (a, b) in live.film_oil().iter().zip(inline.film_oil()) {
        let (ta, tb) = (
            a.effective_temperature_k.unwrap(),
            b.effective_temperature_k.unwrap(),
        );
        println!(
            "{}: T̄ {:.6} vs inline {:.6} °C",
            a.name,
            ta - ZERO_CELSIUS_K,
            tb - ZERO_CELSIUS_K
        );
        assert!((ta / tb - 1.0).abs() < 1e-12, "{}", a.name);
        assert!((a.viscosity_scale / b.viscosity_scale - 1.0).abs() < 1e-12);
    }
    // the viscosity fields (the finite film runs them; here the table keeps the mean) too
    let (a, b) = (
        live.rotor().film_viscosity_fields(),
        inline.rotor().film_viscosity_fields(),
    );
    assert_eq!(a.iter().map(Vec::len).collect::<Vec<_>>(), [60, 60]);
    for (fa, fb) in a.iter().zip(&b) {
        assert!(fa.iter().zip(fb).all(|(x, y)| (x / y - 1.0).abs() < 1e-12));
    }
    let twin = live.session().unwrap().twin();
    let scale = twin.film_viscosity_scale(0).unwrap();
    assert!((scale / live.film_oil()[0].viscosity_scale - 1.0).abs() < 1e-12);
}

/// The thermal film is the finite laminar film of a plain bearing and mixes its own hot oil:
/// a `carry_over`, a turbulent or grooved bearing with it are refused, naming the field.
#[test]
fn thermal_heating_refuses_what_the_thermal_film_does_not_model() {
    let heat = "oil_heating: {model: thermal_film, specific_heat_j_per_kg_k: 1820.0}";
    let with_k = THERMAL_YAML.replacen(
        heat,
        "oil_heating: {model: thermal_film, specific_heat_j_per_kg_k: 1820.0, carry_over: 0.5}",
        1,
    );
    let grid = "    grid: 60x10\n";
    let turbulent = THERMAL_YAML.replacen(grid, &format!("{grid}    flow: auto\n"), 1);
    let grooved = THERMAL_YAML.replacen(grid, &format!("{grid}    grooves: two-axial\n"), 1);
    for (yaml, words) in [
        (with_k, ["oil_heating", "carry_over"]),
        (turbulent, ["oil_heating.model", "laminar"]),
        (grooved, ["oil_heating.model", "plain"]),
    ] {
        assert_ne!(yaml, THERMAL_YAML);
        let err = MachineDescription::from_yaml(&yaml, "bad")
            .unwrap_err()
            .to_string();
        println!("{err}");
        for w in words {
            assert!(err.contains(w), "{err}");
        }
    }
}

/// A run-up as the live twin balances it: every 1 % of speed from 1,000 to 12,000 rpm, the
/// thermal film settles under the static load (a failed balance would leave the last viscosity
/// in force with a warning: none may fail on the machine's own range), and T̄ rises with the
/// speed (more shear) but for a rupture flip's 0.1 K at most.
#[test]
fn every_balance_of_a_run_up_settles() {
    let mut rotor = thermal_rotor();
    let mut rpm: f64 = 1000.0;
    let (mut n, mut worst_ms, mut passes, mut failed) = (0, 0.0_f64, 0, Vec::new());
    let mut last_t = [0.0_f64; 2];
    let mut worst_fall = 0.0_f64;
    while rpm <= 12000.0 {
        let started = std::time::Instant::now();
        match rotor.heat_films(None, rad_s(rpm), 1.0) {
            Ok(temps) => {
                for (t, last) in temps.iter().zip(&mut last_t) {
                    let now = t.effective.effective_temperature_k;
                    worst_fall = worst_fall.max(*last - now);
                    *last = now;
                    passes = passes.max(t.effective.evaluations - 1);
                }
            }
            Err(e) => failed.push(format!("{rpm:.0} rpm: {e}")),
        }
        worst_ms = worst_ms.max(started.elapsed().as_secs_f64() * 1e3);
        n += 1;
        rpm *= 1.01;
    }
    println!(
        "{n} balances, slowest {worst_ms:.1} ms, at most {passes} passes, T̄ fell by at most {worst_fall:.4} K from one speed to the next; {} failed; at 12,000 rpm T̄ {:.2} / {:.2} °C",
        failed.len(),
        last_t[0] - ZERO_CELSIUS_K,
        last_t[1] - ZERO_CELSIUS_K
    );
    for f in &failed {
        println!("  {f}");
    }
    assert!(failed.is_empty());
    assert!(worst_fall < 0.1, "T̄ fell by {worst_fall} K");
}

/// `simulate` and `sweep` heat as the node does (`transient::HeatFollower`, the driver's rule):
/// at 9,000 rpm the heated machine runs its films thinner (µ × 0.944, README), so its journals
/// sit more eccentric than the unheated machine's; along a ramp 8,000 → 8,400 rpm the balance is
/// redone past each 1 % of speed: ln(1.05)/ln(1.01) → 4 times.
#[test]
fn offline_runs_heat_as_the_node_does() {
    use rotor_twin::dynamics::Coupling;
    use rotor_twin::transient::{run_driven, run_transient, Drive, SpeedHistory, TransientSpec};
    let spec = TransientSpec {
        speed_rpm: 9000.0,
        revolutions: 2,
        coupling: Coupling::Nonlinear,
        steps_per_rev: 64,
        grid: None,
        film: FilmEvaluation::Direct,
    };
    let heated = run_transient(&thermal_rotor(), &spec).unwrap();
    let default = Rotor::from_description(&MachineDescription::load(None).unwrap());
    let plain = run_transient(&default, &spec).unwrap();
    let eps =
        |r: &rotor_twin::transient::TransientResult| r.report.bearings[0].max_eccentricity_ratio;
    println!(
        "max ε at 9,000 rpm: heated {:.4}, plain {:.4}",
        eps(&heated),
        eps(&plain)
    );
    assert!(eps(&heated) > eps(&plain) + 0.005);
    assert_eq!((heated.heat_balances, plain.heat_balances), (0, 0));
    let drive = Drive {
        speed: Some(SpeedHistory::ramp(8000.0, 8400.0, 4000.0).unwrap()),
        kicks: Vec::new(),
    };
    let ramp = run_driven(&thermal_rotor(), &spec, None, &drive).unwrap();
    println!("ramp 8,000 → 8,400 rpm: {} balances", ramp.heat_balances);
    assert_eq!(ramp.heat_balances, 4);
}

/// A supply near the top of the law (115 °C on the 10–120 °C table; the file's viscosity the
/// law's there): the thermal film's hottest column passes 120 °C though its mean does not, and
/// the balance is refused naming the temperature in °C and the machine file's `valid_range_c`
/// (the live twin then keeps the last good viscosity with a warning: `driver::oil`).
/// `bearing --speeds` reports the speeds that balance (5,000–8,000 rpm here, peak rises
/// 4.1–4.8 K) and names the one that does not (9,000 rpm) with why, then exits with an error.
#[test]
fn a_film_hotter_than_the_law_is_refused_naming_the_range() {
    let yaml = THERMAL_YAML
        .replace(
            "design_supply_temperature_c: 40.0",
            "design_supply_temperature_c: 115.0",
        )
        .replace("viscosity_pa_s: 0.0008\n", "viscosity_pa_s: 0.000375\n");
    let mut rotor =
        Rotor::from_description(&MachineDescription::from_yaml(&yaml, "hot supply").unwrap());
    let err = rotor.heat_films(None, rad_s(9000.0), 1.0).unwrap_err();
    println!("{err}");
    assert!(
        err.contains("valid_range_c") && err.contains("°C") && err.contains("120.0"),
        "{err}"
    );
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("hot_supply");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("hot.yaml");
    std::fs::write(&path, &yaml).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rotor-twin"))
        .args(["bearing", "--config", path.to_str().unwrap()])
        .args(["--speeds", "5000:9000:1000", "--json"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stderr}");
    assert!(!out.status.success(), "a failed speed ends with an error");
    assert!(stderr.contains("1 of 5 speeds") && stderr.contains("9000 rpm"));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows: Vec<f64> = (v["speeds"].as_array().unwrap().iter())
        .map(|r| r["speed_rpm"].as_f64().unwrap())
        .collect();
    assert_eq!(rows, [5000.0, 6000.0, 7000.0, 8000.0]);
    assert_eq!(v["failed"][0]["speed_rpm"], 9000.0);
    assert!(v["failed"][0]["error"]
        .as_str()
        .unwrap()
        .contains("valid_range_c"));
}

/// `rotor-twin bench wakes` runs the node's wakes through a ramp with the balances on the model
/// thread and off it, and both do every balance (its times are figures for the README, not
/// asserted here).
#[test]
fn bench_wakes_runs_both_ways() {
    let cache = test_cache_dir();
    let config = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/config/orc_microturbine_100kw_thermal.yaml"
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rotor-twin"))
        .args([
            "--film-cache-dir",
            cache.to_str().unwrap(),
            "bench",
            "wakes",
        ])
        .args(["--config", config, "--seconds", "0.5", "--json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    println!("{v}");
    let runs = v.as_array().unwrap();
    assert_eq!(runs.len(), 2);
    for (run, place) in runs.iter().zip(["model thread", "worker thread"]) {
        assert_eq!(run["heat_balance"], place);
        assert_eq!(run["failures"], 0);
        // the first speed, then one a 1 % step of the 200 rpm ramp: at least 2
        assert!(run["balances"].as_u64().unwrap() >= 2, "{run}");
        assert_eq!(run["wakes"], 250);
    }
}
