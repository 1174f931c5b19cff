//! The bearing's own heating by an effective temperature (issue 12; `film::effective_temperature`,
//! Raimondi & Boyd's adiabatic heat balance P_f = ρ c_p ΔT (Q − Q_s/2), T_eff = T_s + k ΔT,
//! iterated through the machine file's viscosity–temperature law).

mod common;
use common::heating::*;
use common::*;
use rotor_twin::film::{
    equilibrium_at_eccentricity, equilibrium_under_load, FilmGrid, FiniteFilm, FlowRegime,
    Lubricant, ZERO_CELSIUS_K,
};
use rotor_twin::rotor::{
    static_solution, BearingModel, MachineDescription, Rotor, DEFAULT_MACHINE_YAML,
};

/// The built-in microturbine with `oil_heating` on both film bearings (specific heat c_p,
/// carry-over k).
fn heated_yaml(cp: f64, k: f64) -> String {
    let law_end = "        valid_range_c: [10.0, 120.0]\n";
    assert_eq!(DEFAULT_MACHINE_YAML.matches(law_end).count(), 2);
    DEFAULT_MACHINE_YAML.replace(
        law_end,
        &format!(
            "{law_end}      oil_heating: {{model: effective_temperature, specific_heat_j_per_kg_k: {cp}, carry_over: {k}}}\n"
        ),
    )
}

/// The machine file's name of a flow regime.
fn flow_name(flow: FlowRegime) -> &'static str {
    match flow {
        FlowRegime::Laminar => "laminar",
        FlowRegime::Turbulent => "turbulent",
        FlowRegime::Auto => "auto",
    }
}

/// ASSUMED c_p of the seed's MDM (octamethyltrisiloxane) liquid, about 1.9 kJ/(kg·K) near 40 °C
/// (the order of silicone oils'); not a measured figure of the plant's oil.
const MDM_CP: f64 = 1900.0;

fn heated_rotor(cp: f64, k: f64) -> Rotor {
    let desc = MachineDescription::from_yaml(&heated_yaml(cp, k), "heated microturbine").unwrap();
    Rotor::from_description(&desc)
}

/// Reference: the energy balance itself. At the fixed point the friction power equals the heat
/// the flows carry, ρ c_p ((T_eff − T_s)/k)(Q − Q_s/2), to 1e-6 — checked on a film solved anew,
/// directly at µ(T_eff) (not the scaled solver the fixed point used). Laminar, and `flow: auto`
/// at 9,000 rpm (session 20): past Taylor's onset the turbulent film's Re follows µ, its friction
/// rises as the oil thins, and the bracket of the fixed point must widen upward (before, the
/// balance failed there as "beyond the law's range"; the fresh film takes Re at µ(T_eff)).
#[test]
fn friction_power_equals_the_heat_carried_at_the_effective_temperature() {
    let cases = [
        (FlowRegime::Laminar, 0.5, 8000.0),
        (FlowRegime::Laminar, 0.5, 9000.0),
        (FlowRegime::Laminar, 1.0, 8000.0),
        (FlowRegime::Laminar, 1.0, 9000.0),
        (FlowRegime::Auto, 0.5, 9000.0),
    ];
    for (flow, k, rpm) in cases {
        let desc = heated_yaml(MDM_CP, k).replace(
            "    grid: 60x10\n",
            &format!("    grid: 60x10\n    flow: {}\n", flow_name(flow)),
        );
        let desc = MachineDescription::from_yaml(&desc, "heated microturbine").unwrap();
        let mut rotor = Rotor::from_description(&desc);
        let loads = static_solution(&rotor).unwrap().bearing_loads_n;
        let omega = rpm * std::f64::consts::PI / 30.0;
        let temps = rotor.heat_films(None, omega, 1.0).unwrap();
        assert_eq!(temps.len(), 2, "both film bearings are heated");
        for t in &temps {
            let e = &t.effective;
            let BearingModel::Film(f) = &rotor.bearings[t.bearing].model else {
                panic!("not a film bearing");
            };
            assert_eq!(f.flow, flow);
            let mut direct = FiniteFilm::new(
                f.geometry.clone(),
                Lubricant::new(900.0, e.viscosity_pa_s).unwrap(),
                f.grid,
            )
            .unwrap()
            .with_flow(flow);
            let eq = equilibrium_under_load(&mut direct, e.viscosity_pa_s, loads[t.bearing], omega)
                .unwrap();
            let carried = 900.0 * MDM_CP * (e.effective_temperature_k - e.supply_temperature_k) / k
                * (eq.film.inflow_m3_s - 0.5 * eq.film.side_flow_m3_s);
            let p = eq.film.power_loss_w.abs();
            println!(
                "{flow:?} k {k} {rpm} rpm {}: T_eff {:.3} °C (ΔT {:.3} K), µ_eff {:.4} mPa·s (×{:.4}), ε {:.4}, P_f {:.2} W, carried {:.2} W, {} equilibria",
                t.name,
                e.effective_temperature_k - ZERO_CELSIUS_K,
                e.temperature_rise_k,
                e.viscosity_pa_s * 1e3,
                t.viscosity_scale,
                eq.eccentricity_ratio,
                p,
                carried,
                e.evaluations
            );
            assert!(e.effective_temperature_k > e.supply_temperature_k + 1.0);
            assert!((carried / p - 1.0).abs() < 1e-6, "{carried} W vs {p} W");
            assert!((e.heat_carried_w / e.friction_power_w - 1.0).abs() < 1e-6);
            // the bearing was left at µ(T_eff)
            assert!((f.viscosity_pa_s() / e.viscosity_pa_s - 1.0).abs() < 1e-12);
        }
    }
}

/// Reference: Raimondi & Boyd (1958) as tabulated in tests/reference/raimondi_boyd.csv. Their
/// temperature-rise variable ρ c_p ΔT / P (P = W/(L D)) follows from the table's friction and
/// flow variables: 4π (R/c)f / ((Q/(R c N L))(1 − ½ Q_s/Q)) (the energy balance above with
/// P_f = f W ωR). The film's own friction and flows must give it within 8 %: the file's notes
/// say its flows are reproduced by converged solutions only within about 6 %.
#[test]
fn temperature_rise_variable_against_raimondi_and_boyd() {
    let grid = FilmGrid::new(72, 12).unwrap();
    let mut worst: f64 = 0.0;
    for row in reference_table("raimondi_boyd.csv") {
        let (ld, eps) = (row["LD"], row["eps"]);
        if !(ld > 0.4 && (0.4..=0.9).contains(&eps)) {
            continue;
        }
        let mut film = FiniteFilm::new(seed_bearing(ld), mdm(), grid).unwrap();
        let e = equilibrium_at_eccentricity(&mut film, 0.0008, eps, OMEGA_9000_RPM).unwrap();
        let w = e.load_n[0].hypot(e.load_n[1]);
        let p_unit = w / (0.06 * ld * 0.06);
        let ours = e.film.power_loss_w.abs()
            / ((e.film.inflow_m3_s - 0.5 * e.film.side_flow_m3_s) * p_unit);
        let table =
            4.0 * std::f64::consts::PI * row["Rcf"] / (row["Q"] * (1.0 - 0.5 * row["Qs_over_Q"]));
        println!(
            "L/D {ld} ε {eps}: ρc_pΔT/P {ours:.3} vs {table:.3} ({:+.2} %)",
            100.0 * (ours / table - 1.0)
        );
        worst = worst.max(rel(ours, table));
    }
    assert!(worst < 0.08, "worst {:.2} %", 100.0 * worst);
}

/// The built-in machine has no `oil_heating`: nothing is heated, no figure moves.
#[test]
fn without_oil_heating_nothing_changes() {
    let mut rotor = Rotor::from_description(&MachineDescription::load(None).unwrap());
    assert!(!rotor.has_oil_heating());
    assert!(rotor.heat_films(None, 900.0, 1.0).unwrap().is_empty());
    assert_eq!(rotor.viscosity_scale(), 1.0);
}

#[test]
fn bad_oil_heating_is_refused_naming_the_field() {
    for (cp, k, word) in [(1900.0, 1.5, "carry_over"), (0.0, 0.5, "specific_heat")] {
        let err = MachineDescription::from_yaml(&heated_yaml(cp, k), "bad")
            .unwrap_err()
            .to_string();
        assert!(err.contains("oil_heating") && err.contains(word), "{err}");
    }
}

/// The seed case's effective temperature at 8,000 and 9,000 rpm and what it moves: ε and the
/// linear threshold (at the viscosities of the threshold speed, as `modes` finds it). The
/// oil thins as it heats, and a thinner oil raises this rotor's threshold (60 °C supply:
/// 8,471 → 9,006 rpm, tests/live_calibration.rs), so the heated threshold must be higher.
#[test]
fn the_seed_case_heated_raises_the_threshold() {
    let cold = Rotor::from_description(&MachineDescription::load(None).unwrap());
    let (t_cold, _) = rotor_twin::session::linear_threshold(&cold).unwrap();
    let mut rotor = heated_rotor(MDM_CP, 0.5);
    let mut rpm = 9000.0;
    for _ in 0..20 {
        rotor
            .heat_films(None, rpm * std::f64::consts::PI / 30.0, 1.0)
            .unwrap();
        let (t, _) = rotor_twin::session::linear_threshold(&rotor).unwrap();
        let next = t * 30.0 / std::f64::consts::PI;
        if (next - rpm).abs() < 1.0 {
            break;
        }
        rpm = next;
    }
    let cold_rpm = t_cold * 30.0 / std::f64::consts::PI;
    println!(
        "linear threshold: {cold_rpm:.0} rpm at the supply temperature, {rpm:.0} rpm at the effective temperatures (scale ×{:.4})",
        rotor.viscosity_scale()
    );
    assert!(rpm > cold_rpm + 20.0, "{rpm} vs {cold_rpm}");
}

/// The live twin's films (the driver the node and the replay run) against `Rotor::heat_films`
/// on a fresh machine, the computation `bearing --speeds` and `modes` print: per bearing, T_eff
/// within `tol_k` and the running twin's scale µ(T_eff)/µ_ref equal to the machine's.
fn assert_live_equals_offline(
    d: &rotor_twin::driver::Driver,
    supply_c: Option<f64>,
    rpm: f64,
    tol_k: f64,
) {
    let mut offline = heated_rotor(MDM_CP, 0.5);
    let w = rpm * std::f64::consts::PI / 30.0;
    let temps = offline
        .heat_films(supply_c.map(|c| c + ZERO_CELSIUS_K), w, 1.0)
        .unwrap();
    let live = d.film_oil();
    assert_eq!(live.len(), temps.len());
    for (i, (l, t)) in live.iter().zip(&temps).enumerate() {
        let t_live = l.effective_temperature_k.expect("heated");
        let t_off = t.effective.effective_temperature_k;
        println!(
            "supply {supply_c:?} °C, {rpm} rpm, {}: live T_eff {:.6} °C, offline {:.6} °C (Δ {:.1e} K), scale {:.6}",
            l.name,
            t_live - ZERO_CELSIUS_K,
            t_off - ZERO_CELSIUS_K,
            t_live - t_off,
            l.viscosity_scale
        );
        assert!(
            (t_live - t_off).abs() < tol_k,
            "{}: {t_live} vs {t_off}",
            l.name
        );
        let twin = d.session().unwrap().twin().film_viscosity_scale(i).unwrap();
        assert!((twin / l.viscosity_scale - 1.0).abs() < 1e-12);
        if tol_k < 1e-5 {
            assert!((l.viscosity_scale / t.viscosity_scale - 1.0).abs() < 1e-9);
        }
    }
}

/// Reference: `Rotor::heat_films` (what `bearing --speeds` and `modes` print, checked above
/// against the energy balance and Raimondi–Boyd). The live twin (direct film) heats each film
/// bearing at the speed and supply temperature in force to 1e-6 K of it; a supply temperature
/// step moves T_eff (40 → 50 °C: about +10 K), a speed step past 1 % redoes the balance, a
/// smaller one or a 0.01 K temperature change does not (the balance is not per step).
#[test]
fn the_live_twin_heats_each_film_as_bearing_speeds_does() {
    use rotor_twin::driver::{Driver, DriverSettings, Fed, ModelKind};
    use rotor_twin::dynamics::FilmEvaluation;
    let rotor = heated_rotor(MDM_CP, 0.5);
    let rated = rotor.rated_speed_rad_s;
    let settings = DriverSettings::new(ModelKind::Nonlinear, FilmEvaluation::Direct, rated);
    let mut d = Driver::new(rotor, settings);
    let mut emit = |_: rotor_twin::session::Outgoing| {};
    let t0 = 1_767_225_600_000_000_000_i64;
    let ms = 1_000_000;
    assert!(matches!(
        d.feed(t0, speed_rpm(9000.0), &mut emit),
        Fed::Started { .. }
    ));
    assert_eq!(d.heat_balances(), (1, None));
    assert_live_equals_offline(&d, None, 9000.0, 1e-6);
    assert_eq!(d.feed(t0 + ms, speed_rpm(8000.0), &mut emit), Fed::Taken);
    assert_eq!(d.heat_balances().0, 2);
    assert_live_equals_offline(&d, None, 8000.0, 1e-6);
    // 0.5 % faster: within the step, no new balance, the 8,000 rpm temperatures stay
    assert_eq!(
        d.feed(t0 + 2 * ms, speed_rpm(8040.0), &mut emit),
        Fed::Taken
    );
    assert_eq!(d.heat_balances().0, 2);
    assert_live_equals_offline(&d, None, 8000.0, 1e-6);
    // a supply temperature step: 40 °C (the design's) → 50 °C
    let before: Vec<f64> = (d.film_oil().iter())
        .map(|f| f.effective_temperature_k.unwrap())
        .collect();
    assert_eq!(d.feed(t0 + 3 * ms, supply(50.0), &mut emit), Fed::Taken);
    assert_eq!(d.heat_balances().0, 3);
    assert_live_equals_offline(&d, Some(50.0), 8040.0, 1e-6);
    for (f, b) in d.film_oil().iter().zip(&before) {
        let moved = f.effective_temperature_k.unwrap() - b;
        assert!((9.0..10.0).contains(&moved), "{}: moved {moved} K", f.name);
    }
    assert_eq!(d.feed(t0 + 4 * ms, supply(50.01), &mut emit), Fed::Taken);
    assert_eq!(d.heat_balances().0, 3);
    // the twin steps on at the heated viscosities
    assert_steps_on(&mut d, t0 + 20 * ms);
}

/// The node runs the tabulated film: its heat balance takes the table (0.4 ms here against the
/// direct solver's 29 ms: printed), and its T_eff stays within 0.03 K of the direct one
/// (measured −0.020 K at 9,000 rpm, 1 % of the 1.96 K rise: the table's friction and flows,
/// interpolated, are that close to the solver's; the scale differs by 0.02 %).
#[test]
fn the_live_twin_on_the_table_heats_within_three_hundredths_of_a_kelvin() {
    use rotor_twin::driver::{Driver, DriverSettings, Fed, ModelKind};
    use rotor_twin::dynamics::FilmEvaluation;
    use_test_table_cache();
    let mut rotor = heated_rotor(MDM_CP, 0.5);
    let w = 9000.0 * std::f64::consts::PI / 30.0;
    for film in [
        FilmEvaluation::Table,
        FilmEvaluation::Direct,
        FilmEvaluation::Table,
    ] {
        let started = std::time::Instant::now();
        rotor.heat_films_with(None, w, 1.0, film).unwrap();
        println!(
            "heat balance, {film:?} film: {:.1} ms",
            started.elapsed().as_secs_f64() * 1e3
        );
    }
    let settings = DriverSettings::new(
        ModelKind::Nonlinear,
        FilmEvaluation::Table,
        rotor.rated_speed_rad_s,
    );
    let mut d = Driver::new(rotor, settings);
    let mut emit = |_: rotor_twin::session::Outgoing| {};
    let t0 = 1_767_225_600_000_000_000_i64;
    assert!(matches!(
        d.feed(t0, speed_rpm(9000.0), &mut emit),
        Fed::Started { .. }
    ));
    assert_eq!(d.heat_balances(), (1, None));
    assert_live_equals_offline(&d, None, 9000.0, 0.03);
}

/// A heat balance that fails reaches the bus (issue 12): a supply at 119.8 °C, inside the
/// built-in law's 10–120 °C, with a bearing heating past the law's top (k = 1: T_eff − T_s is
/// the whole rise, ~2 K at 40 °C). Reference: `Rotor::heat_films` on a fresh machine fails there
/// too (and succeeds at 40 °C). The driver counts the failure, keeps the last good viscosity
/// (the 40 °C balance's scales, to 1e-12, on the machine and in the running twin), its model
/// status warns with the reason (`heat_balance_error`, `heat_balance_failures` 1) and the twin
/// steps on; back at 40 °C the balance succeeds, the warning goes, the count stays and the
/// replay's report keeps the last failure.
#[test]
fn a_failed_heat_balance_warns_and_the_last_good_viscosity_stays() {
    use rotor_twin::driver::{Driver, DriverSettings, Fed, ModelKind};
    use rotor_twin::dynamics::FilmEvaluation;
    let rotor = heated_rotor(MDM_CP, 1.0);
    let w = 9000.0 * std::f64::consts::PI / 30.0;
    let hot_c = 119.8;
    let mut offline = rotor.clone();
    let why_offline = offline
        .heat_films(Some(hot_c + ZERO_CELSIUS_K), w, 1.0)
        .expect_err("the reference balance fails at 119.8 °C");
    println!("reference at {hot_c} °C: {why_offline}");
    assert!(why_offline.contains("beyond the viscosity law's range"));
    let settings = DriverSettings::new(ModelKind::Nonlinear, FilmEvaluation::Direct, w);
    let mut d = Driver::new(rotor, settings);
    let mut emit = |_: rotor_twin::session::Outgoing| {};
    let (t0, ms) = (1_767_225_600_000_000_000_i64, 1_000_000);
    assert!(matches!(
        d.feed(t0, speed_rpm(9000.0), &mut emit),
        Fed::Started { .. }
    ));
    let value = |d: &Driver, key: &str| {
        let diag = d.oil_diagnostics();
        (diag.values.iter())
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.clone())
    };
    assert_eq!(d.heat_balances(), (1, None));
    assert_eq!(d.oil_diagnostics().warning, None);
    assert_eq!(value(&d, "heat_balance_failures").as_deref(), Some("0"));
    let scales = |d: &Driver| -> Vec<f64> {
        let twin = d.session().unwrap().twin();
        (0..d.film_oil().len())
            .map(|i| twin.film_viscosity_scale(i).unwrap())
            .collect()
    };
    let good = scales(&d);
    let good_oil = d.film_oil();
    // the law takes 119.8 °C; the balance fails
    assert_eq!(d.feed(t0 + ms, supply(hot_c), &mut emit), Fed::Taken);
    let (balances, why) = d.heat_balances();
    println!("driver at {hot_c} °C: {balances} balances, {why:?}");
    assert_eq!(balances, 2);
    assert!(why.unwrap().contains("beyond the viscosity law's range"));
    assert_eq!(d.heat_balance_failures(), 1);
    for (now, before) in scales(&d).iter().zip(&good) {
        assert!((now / before - 1.0).abs() < 1e-12, "{now} vs {before}");
    }
    for (now, before) in d.film_oil().iter().zip(&good_oil) {
        assert!((now.viscosity_scale / before.viscosity_scale - 1.0).abs() < 1e-12);
    }
    let diag = d.oil_diagnostics();
    println!("diagnostics: {diag:?}");
    assert!(diag.warning.unwrap().contains("heat balance failed"));
    assert_eq!(value(&d, "heat_balance_failures").as_deref(), Some("1"));
    assert!(value(&d, "heat_balance_error").is_some_and(|v| v.contains("law's range")));
    // the twin steps on
    assert_steps_on(&mut d, t0 + 20 * ms);
    // back to 40 °C: a good balance, no warning, the count kept
    assert_eq!(d.feed(t0 + 21 * ms, supply(40.0), &mut emit), Fed::Taken);
    assert_eq!(d.heat_balances(), (3, None));
    assert_eq!(d.oil_diagnostics().warning, None);
    assert!(value(&d, "heat_balance_error").is_none());
    let report = d.heat_balance_report().unwrap();
    assert_eq!((report.balances, report.failures), (3, 1));
    assert!(report.last_failure.unwrap().contains("law's range"));
}

/// The node's balances run on a worker thread: a failed one there is counted and warned of as
/// on the driver's own thread, and the last good viscosity stays in force (to 1e-12) in the
/// running twin.
#[test]
fn a_failed_heat_balance_off_the_model_thread_keeps_the_last_good_viscosity() {
    use rotor_twin::driver::{Driver, DriverSettings, ModelKind};
    use rotor_twin::dynamics::FilmEvaluation;
    let w = 9000.0 * std::f64::consts::PI / 30.0;
    let settings = DriverSettings {
        heat_balance_off_thread: true,
        ..DriverSettings::new(ModelKind::Nonlinear, FilmEvaluation::Direct, w)
    };
    let mut d = Driver::new(heated_rotor(MDM_CP, 1.0), settings);
    let mut t = 1_767_225_600_000_000_000_i64;
    d.feed(t, speed_rpm(9000.0), &mut |_| {});
    settle_heat(&mut d, &mut t);
    assert_eq!(d.heat_balances(), (1, None));
    let twin_scale = |d: &Driver| d.session().unwrap().twin().film_viscosity_scale(0).unwrap();
    let good = twin_scale(&d);
    assert!((good / d.film_oil()[0].viscosity_scale - 1.0).abs() < 1e-12);
    d.feed(t, supply(119.8), &mut |_| {});
    settle_heat(&mut d, &mut t);
    let (balances, why) = d.heat_balances();
    println!("off the model thread at 119.8 °C: {balances} balances, {why:?}");
    assert_eq!(balances, 2);
    assert!(why.unwrap().contains("beyond the viscosity law's range"));
    assert_eq!(d.heat_balance_failures(), 1);
    assert!(d
        .oil_diagnostics()
        .warning
        .unwrap()
        .contains("heat balance failed"));
    assert!((twin_scale(&d) / good - 1.0).abs() < 1e-12);
}
