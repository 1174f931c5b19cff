//! The monitor's verdicts agree with the dynamics (issue 14): a growing non-synchronous motion
//! is never called stable, a decaying one is, and a model that knows no wall says when its
//! journal has left the bearing.

mod common;
use common::run_cli;

use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use rotor_twin::monitor::{ClassifierSettings, Monitor, RevolutionReport, RotorState};
use rotor_twin::rotor::{MachineDescription, Rotor};
use rotor_twin::transient::{self, Drive, SpeedHistory, TransientSpec};
use rotor_twin::units::rpm_to_rad_s;
use serde_json::Value;

/// Reading (A) of the seed (Ø55; the default until session 15): its linear model is unstable at
/// 9,000 rpm (threshold 8,471 rpm), which the checks of a growing linear run need; the default,
/// reading (B), is linear-stable there (threshold 9,291 rpm).
const D55: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/config/orc_microturbine_100kw_d55.yaml"
);

fn d55() -> Rotor {
    Rotor::from_description(&MachineDescription::load(Some(std::path::Path::new(D55))).unwrap())
}

/// Reading (A)'s linear model at 9,000 rpm, 300 revolutions (the run of issue 14, formerly "stable"):
/// its least-damped mode is unstable (threshold 8,635 rpm; the eigenvalue gives a growth of
/// 0.0219/rev, tests/transient_orc.rs), so the verdict is "growing" (or a whirl once the
/// component counts), with the growth rate of the eigenvalue within 10 % and a predicted time to
/// the alert level.
#[test]
fn the_growing_linear_run_at_9000_rpm_is_not_stable() {
    let (ok, out, err) = run_cli(&[
        "simulate",
        "--config",
        D55,
        "--speed-rpm",
        "9000",
        "--revs",
        "300",
        "--model",
        "linear",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_ne!(v["state"], "stable", "{}", v["evidence"]);
    assert!(
        v["state"] == "growing" || v["state"] == "whirl",
        "{}",
        v["state"]
    );
    let worst = v["bearings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["state"] == v["state"])
        .unwrap();
    let g = worst["subsync_growth_per_rev"].as_f64().unwrap();
    assert!((g / 0.0219 - 1.0).abs() < 0.1, "growth {g}/rev");
    let t = worst["time_to_alert_s"].as_f64().unwrap();
    // from the sub-synchronous amplitude at that rate, at 150 rev/s
    let a = worst["subsync_amplitude_m"].as_f64().unwrap();
    let alert = worst["alert_level_m"].as_f64().unwrap();
    let expected = (alert / a).ln() / g / 150.0;
    assert!(
        t > 0.0 && (t / expected - 1.0).abs() < 1e-6,
        "{t} s vs {expected} s"
    );
}

/// The revolution's verdict is `stable` (else the revolution, its speed and its evidence).
fn assert_stable(r: &RevolutionReport) {
    assert_eq!(
        r.state,
        RotorState::Stable,
        "rev {} at {:.0} rpm: {}",
        r.revolution,
        r.speed_rad_s * 30.0 / std::f64::consts::PI,
        r.evidence()
    );
}

/// Runs `rotor` at `speed_rpm` for `revs` revolutions (64 steps a revolution, tabulated film),
/// calling `at_rev` after each revolution; returns every revolution's report.
fn run(
    rotor: &Rotor,
    coupling: Coupling,
    speed_rpm: f64,
    revs: usize,
    mut at_rev: impl FnMut(usize, &mut Twin),
) -> Vec<RevolutionReport> {
    let omega = rpm_to_rad_s(speed_rpm);
    let config = TwinConfig {
        film: FilmEvaluation::Table,
        ..TwinConfig::with_steps_per_rev(coupling, omega, 64)
    };
    let mut twin = Twin::new(rotor, config, omega).unwrap();
    let mut monitor = Monitor::new(&twin, 66, ClassifierSettings::default());
    let input = StepInput {
        speed_rad_s: omega,
        accel_rad_s2: 0.0,
    };
    let mut history = Vec::new();
    while history.len() < revs {
        twin.step(&input).unwrap();
        if let Some(r) = monitor.record(&twin) {
            history.push(r.clone());
            at_rev(history.len(), &mut twin);
        }
    }
    history
}

/// 8,000 rpm, nonlinear film (stable: the transients decay, tests/transient_orc.rs), the twin
/// started without unbalance and the machine's unbalance applied suddenly after 20 revolutions
/// (as a plant's start-up does): the free vibration it excites (a sub-synchronous component of
/// 1.6 µm, far above the floor: checked) decays, and no revolution is classified anything but
/// stable, the window spectrum's rise over the window after the step included. (With the
/// unbalance doubled the motion is not stable at 8,000 rpm: the sub-synchronous component then
/// grows slowly, 2 → 3.8 µm over 200 revolutions.)
#[test]
fn a_sudden_unbalance_at_8000_rpm_decays_and_stays_stable() {
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let mut unbalanced_later = rotor.clone();
    for p in &mut unbalanced_later.unbalance {
        p.magnitude_kg_m = 0.0;
    }
    let history = run(
        &unbalanced_later,
        Coupling::Nonlinear,
        8000.0,
        260,
        |rev, twin| {
            if rev == 20 {
                for (k, p) in rotor.unbalance.iter().enumerate() {
                    twin.set_unbalance(k, p.magnitude_kg_m, p.phase_rad)
                        .unwrap();
                }
            }
        },
    );
    let peak = history[20..]
        .iter()
        .flat_map(|r| r.bearings.iter().map(|b| b.subsync_amplitude_m))
        .fold(0.0, f64::max);
    println!("largest sub-synchronous amplitude after the step {peak:.3e} m");
    assert!(peak > 10.0 * 1e-3 * 40e-6, "a transient was excited");
    for r in &history {
        assert_stable(r);
    }
    let last = &history[history.len() - 1];
    for b in &last.bearings {
        let g = b.subsync_growth_per_rev.unwrap();
        assert!(g < -0.002, "growth {g}");
    }
}

/// The linear model at 9,000 rpm run on until its orbit passes the clearance circle (the
/// eigenvalue's growth takes the orbit from ε ≈ 0.6 beyond 1 in some 450 revolutions): the
/// journal is flagged beyond the clearance (the linear model knows no wall), the warning level
/// is ERROR, and the state is a whirl or whip, not stable; the bearing beyond the clearance is a
/// whirl (without a wall, no whip on that alone).
#[test]
fn a_linear_orbit_beyond_the_clearance_is_flagged() {
    let rotor = d55();
    let history = run(&rotor, Coupling::Linear, 9000.0, 480, |_, _| {});
    let first = history
        .iter()
        .position(|r| r.bearings.iter().any(|b| b.beyond_clearance))
        .expect("a revolution beyond the clearance");
    let r = &history[first];
    let b = r.bearings.iter().find(|b| b.beyond_clearance).unwrap();
    println!(
        "beyond the clearance at revolution {first}: {}",
        r.evidence()
    );
    assert!(b.max_eccentricity_ratio > 1.0 && !b.contact);
    assert!(r.evidence().contains("BEYOND THE CLEARANCE"));
    assert_eq!(
        rotor_twin::session::warning_level(b),
        rotor_twin::messages::InstabilityWarning::ERROR
    );
    assert!(matches!(r.state, RotorState::Whirl | RotorState::Whip));
    // the linear model has no wall: the bearing beyond the clearance is a whirl, never a whip
    // on that eccentricity alone (it used to read "whip" at ε = 970)
    assert_eq!(b.state, RotorState::Whirl, "{}", r.evidence());
    // before it, every revolution with a known growth rate and a sub-synchronous component
    // above the floor (10⁻³ of the clearance) was growing or worse, never stable
    let mut judged = 0;
    for r in &history[..first] {
        let b = &r.bearings[1];
        if b.subsync_growth_per_rev.is_some() && b.subsync_amplitude_m > 1e-3 * 40e-6 {
            judged += 1;
            assert_ne!(
                r.state,
                RotorState::Stable,
                "rev {}: {}",
                r.revolution,
                r.evidence()
            );
        }
    }
    assert!(judged > 100, "{judged} revolutions judged");
}

/// The machine file's optional `alarm_levels`: read when given, refused with the field and the
/// rule when the danger level lies below the alert one.
#[test]
fn alarm_levels_in_the_machine_file_are_checked() {
    use rotor_twin::rotor::DEFAULT_MACHINE_YAML;
    let given = format!(
        "{DEFAULT_MACHINE_YAML}\nalarm_levels: {{alert_amplitude_m: 25.0e-6, danger_amplitude_m: 35.0e-6}}\n"
    );
    let d = MachineDescription::from_yaml(&given, "machine.yaml").unwrap();
    let a = d.alarm_levels.unwrap();
    assert_eq!(
        (a.alert_amplitude_m, a.danger_amplitude_m),
        (25.0e-6, 35.0e-6)
    );
    assert!(MachineDescription::builtin_default().alarm_levels.is_none());
    let bad = format!(
        "{DEFAULT_MACHINE_YAML}\nalarm_levels: {{alert_amplitude_m: 50.0e-6, danger_amplitude_m: 30.0e-6}}\n"
    );
    let e = MachineDescription::from_yaml(&bad, "machine.yaml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("alarm_levels.danger_amplitude_m") && e.contains("at least"),
        "{e}"
    );
}

/// A transient of reading (A)'s rotor ([`d55`], where these figures were measured; nonlinear,
/// tabulated film, 64 steps a revolution, the film tables cached in the build's temporary
/// directory) under `drive`; every revolution's report.
fn run_driven(speed_rpm: f64, revolutions: usize, drive: &Drive) -> Vec<RevolutionReport> {
    rotor_twin::film::set_disk_cache(Some(rotor_twin::film::TableCache::new(
        common::test_cache_dir(),
    )));
    let rotor = d55();
    let spec = TransientSpec {
        speed_rpm,
        revolutions,
        coupling: Coupling::Nonlinear,
        steps_per_rev: 64,
        grid: None,
        film: FilmEvaluation::Table,
    };
    transient::run_driven(&rotor, &spec, None, drive)
        .unwrap()
        .history
}

/// Near the stability threshold (8,450 rpm, the nonlinear model's sub-synchronous component of
/// 0.06 µm grows at +0.0013/rev: measured over 700 revolutions, below the 0.002/rev threshold)
/// the growth estimate scatters by ±0.005/rev about its true value. Without the dead band
/// (`ClassifierSettings::growth_dead_band_per_rev`) the monitor called it `growing` from
/// revolution 66 on, one to three revolutions in every twelve; with it every revolution is
/// `stable`, while the component is present (above the floor of 10⁻³ c) with a known growth rate
/// on at least 150 of them (so the band, not the floor, decides).
#[test]
fn near_the_threshold_the_verdict_does_not_flip() {
    let history = run_driven(8450.0, 260, &Drive::default());
    let mut judged = 0;
    for r in &history {
        assert_stable(r);
        judged += r
            .bearings
            .iter()
            .all(|b| b.subsync_growth_per_rev.is_some() && b.subsync_amplitude_m > 1e-3 * 40e-6)
            as usize;
    }
    println!("revolutions judged on their growth: {judged}");
    assert!(judged >= 150, "{judged}");
}

/// A run-up at 1,000 rpm/s from 2,000 to 6,000 rpm through the first critical speed (3,662 rpm,
/// README "The microturbine") and 20 revolutions at 6,000: the 1X response peaks inside the ramp
/// (the critical is crossed) and every revolution is `stable`. Before, revolutions 131–152
/// (4,440–4,716 rpm) read `growing` at up to 0.066/rev: the spectrum's largest in-band bin was
/// bin 2, the flank of the slow drift of the journal's mean position (bin 1 4× larger), read
/// as a 0.04–0.11 µm component at 0.094X.
#[test]
fn a_run_up_through_the_first_critical_is_quiet() {
    let drive = Drive {
        speed: Some(SpeedHistory::ramp(2000.0, 6000.0, 1000.0).unwrap()),
        kicks: vec![],
    };
    let history = run_driven(2000.0, 20, &drive);
    let rpm = |r: &RevolutionReport| r.speed_rad_s * 30.0 / std::f64::consts::PI;
    let peak = history
        .iter()
        .max_by(|a, b| {
            a.bearings[0]
                .one_x_amplitude_m
                .total_cmp(&b.bearings[0].one_x_amplitude_m)
        })
        .unwrap();
    println!("1X peak at {:.0} rpm", rpm(peak));
    assert!(rpm(peak) > 3000.0 && rpm(peak) < 5900.0, "{}", rpm(peak));
    history.iter().for_each(assert_stable);
}
