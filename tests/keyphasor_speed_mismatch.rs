//! A speed topic that is steadily wrong, told from a keyphasor mark that moved (issue 12,
//! README "Next steps" 2: "a twin whose speed is off by more than 2.8 % relocks as if the mark
//! moved").
//!
//! The plant turns at a constant speed ρ·Ω while its speed topic says Ω (a tachometer off by a
//! factor, as a wrong pulses-per-turn count or scale gives); its keyphasor fires when its angle
//! passes 2πk + mark, so the events are stamped t₀ + (2πk + mark)/(ρΩ) exactly. A driver runs
//! the built-in machine (reading (B), the default: nothing here depends on the reading, only
//! on the angle; 6,000 rpm is below both readings' thresholds, so the rotor is quiet and its
//! 1X response steady), nonlinear, direct film, 64 steps a revolution, started at the first
//! event (`expect_keyphasor`), the speed topic every 10 ms.
//!
//! Between two events the twin's angle advances ∫Ω_twin dt, the plant's 2π: the phase error
//! grows by 2π(1 − 1/ρ) a revolution (10.5° at 1.03, 17.1° at 1.05). On main (before session
//! 15) the lock followed it with a steady error 2π(1 − 1/ρ)/g (g = 0.5) that passes its 20°
//! jump limit beyond ρ = 1.028, then took three agreeing jumps for a moved mark and relocked,
//! again and again: in 40 revolutions at 9,000 rpm (the lock alone, the old rules compiled
//! from main's `src/signals/keyphasor.rs`) 5 relocks and 10 refusals at 1.03, 9 and 20 at
//! 1.05, the twin's angle up to 41° and 60° off, each relock turning every heavy spot.

use rotor_twin::driver::{Driver, DriverSettings, Fed, Input, ModelKind};
use rotor_twin::dynamics::{Coupling, FilmEvaluation, TwinConfig};
use rotor_twin::rotor::{MachineDescription, Rotor};
use rotor_twin::session::Outgoing;
use rotor_twin::signals::{one_x_vector, OneXVector, PhaseReference};
use std::f64::consts::{PI, TAU};

const T0_NS: i64 = 1_000_000_000;
/// The speed the twin is told (rpm), and its step: 64 a revolution there, in every run (so
/// that a run told the plant's true speed steps alike).
const TOLD_RPM: f64 = 6000.0;
const STEPS_PER_REV: usize = 64;

/// What one run gives.
struct Run {
    /// the twin's angle error at each event, before the event corrects it (deg)
    errors_deg: Vec<f64>,
    /// the twin's angle and probe station 0's x at every step (for the 1X phase lag)
    angle_x: Vec<(f64, f64)>,
    warnings: Vec<String>,
    refused: Vec<String>,
    driver: Driver,
    end_ns: i64,
}

fn rotor() -> Rotor {
    Rotor::from_description(&MachineDescription::builtin_default())
}

/// The plant at `plant_rpm` for `revs` revolutions, its mark moved by `mark_deg` from
/// revolution 12 on; the speed topic says `told_rpm`.
fn run(told_rpm: f64, plant_rpm: f64, mark_deg: f64, revs: usize) -> Run {
    let told = told_rpm * PI / 30.0;
    let plant = plant_rpm * PI / 30.0;
    let machine = rotor();
    let w_step = TOLD_RPM * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w_step, STEPS_PER_REV);
    let mut settings = DriverSettings::new(
        ModelKind::Nonlinear,
        FilmEvaluation::Direct,
        machine.rated_speed_rad_s,
    );
    settings.twin.time_step_s = config.time_step_s;
    let mut driver = Driver::new(machine, settings);
    driver.expect_keyphasor();
    let mut warnings = Vec::new();
    let mut emit = |o: Outgoing| {
        if let Outgoing::Warning(x) = o {
            warnings.push(x.evidence);
        }
    };
    let (mut errors_deg, mut angle_x, mut refused) = (Vec::new(), Vec::new(), Vec::new());
    let mut record = |d: &Driver| {
        let o = d.session().unwrap().twin().output();
        angle_x.push((o.angle_rad, o.probes[0].displacement_m[0]));
    };
    let mut next_speed_ns = T0_NS - 5_000_000;
    let mut event = T0_NS;
    for k in 0..revs {
        let mark = if k >= 12 { mark_deg.to_radians() } else { 0.0 };
        event = T0_NS + ((TAU * k as f64 + mark) / plant * 1e9).round() as i64;
        while next_speed_ns <= event {
            while driver.advance_to(next_speed_ns, 1, &mut emit) == 1 {
                record(&driver);
            }
            let speed = Input::Speed {
                speed_rad_s: told,
                accel_rad_s2: 0.0,
                stamp_ns: next_speed_ns,
            };
            driver.feed(next_speed_ns, speed, &mut emit);
            next_speed_ns += 10_000_000;
        }
        while driver.advance_to(event, 1, &mut emit) == 1 {
            record(&driver);
        }
        if let Some(s) = driver.session() {
            errors_deg.push((-s.angle_at(event)).rem_euclid(TAU).to_degrees());
        }
        let fed = driver.feed(event, Input::Keyphasor { stamp_ns: event }, &mut emit);
        if let Fed::Refused(why) = fed {
            refused.push(why);
        }
    }
    Run {
        errors_deg: errors_deg
            .into_iter()
            .map(|e| if e > 180.0 { e - 360.0 } else { e })
            .collect(),
        angle_x,
        warnings,
        refused,
        driver,
        end_ns: event,
    }
}

/// The 1X vector of probe station 0's x over the last 8 revolutions of the twin's angle.
fn one_x_of_last_revs(r: &Run) -> OneXVector {
    let end = r.angle_x.last().unwrap().0;
    let from = r
        .angle_x
        .iter()
        .position(|(a, _)| *a >= end - 8.0 * TAU)
        .unwrap();
    let s = &r.angle_x[from..];
    one_x_vector(s.iter().copied(), s.len()).unwrap()
}

/// A speed topic 3 % and 5 % below the plant's: the keyphasor's phase drifts steadily, three
/// revolutions agree on it, and the mismatch is reported once (counted, warned with the
/// ratio), the speed topic scaled by the measured ratio (within 10⁻⁵ of the truth: the stamps'
/// 1 ns in 9.7 ms, averaged over three revolutions; the brief asks 0.1 %), never relocked (≤ 1
/// asked; 0 here), at most one event refused (at 1.05 the second event's error, 25.7°, passes
/// the 20° jump limit before the third revolution confirms the drift). Then the twin turns at
/// the plant's speed: its angle error at every event from the 10th under 0.01° (measured
/// 1.4·10⁻³°: 0.18° left at the next event, the part of the step straddling the event taken at
/// the old speed, then halved each revolution by the lock), its phases locked at the end, and
/// the 1X vector of its probe over the last 8 of 32 revolutions the one of a twin told the true
/// speed from the start, within 1 % and 1° (measured: the same to 10⁻⁴ µm and 0.01°; the
/// once-only correction of its angle, 18° at 1.03 and 43° at 1.05, is a step in the unbalance
/// force's phase: its transient has died out in 28 revolutions at this speed, well below the
/// threshold).
#[test]
fn a_speed_topic_off_by_3_and_5_percent_is_a_speed_mismatch_not_a_moved_mark() {
    for ratio in [1.03, 1.05] {
        let plant_rpm = TOLD_RPM * ratio;
        let r = run(TOLD_RPM, plant_rpm, 0.0, 32);
        let truth = run(plant_rpm, plant_rpm, 0.0, 32);
        let c = r.driver.counts();
        let scale = r.driver.speed_scale();
        let (x, x0) = (one_x_of_last_revs(&r), one_x_of_last_revs(&truth));
        let late = r.errors_deg[10..]
            .iter()
            .fold(0.0f64, |m, e| m.max(e.abs()));
        println!(
            "ρ {ratio}: mismatches {}, relocks {}, refused {:?}, scale {scale:?}, speed {:.3} rpm; errors (deg) {:.3?}; worst from event 10 {late:.2e}°; 1X {:.4} µm at {:.2}° against {:.4} µm at {:.2}° (told the truth); warnings {:?}",
            c.speed_mismatches,
            c.relocks,
            r.refused,
            r.driver.speed_rad_s().unwrap() * 30.0 / PI,
            &r.errors_deg[..8],
            x.amplitude_m * 1e6,
            x.phase_lag_deg,
            x0.amplitude_m * 1e6,
            x0.phase_lag_deg,
            r.warnings,
        );
        assert_eq!(c.speed_mismatches, 1, "ρ {ratio}");
        let scale = scale.unwrap();
        assert!(
            (scale / ratio - 1.0).abs() < 1e-5,
            "ρ {ratio}: scale {scale}"
        );
        let speed = r.driver.speed_rad_s().unwrap() * 30.0 / PI;
        assert!((speed / plant_rpm - 1.0).abs() < 1e-5, "{speed} rpm");
        assert_eq!(c.relocks, 0, "ρ {ratio}: {:?}", r.warnings);
        assert!(r.refused.len() <= 1, "ρ {ratio}: {:?}", r.refused);
        let said = format!("{ratio:.5} times as fast");
        assert!(
            r.warnings
                .iter()
                .any(|w| w.contains("speed mismatch") && w.contains(&said)),
            "{:?}",
            r.warnings
        );
        assert!(late < 0.01, "ρ {ratio}: {late}° from event 10 on");
        assert_eq!(r.driver.phase_reference(r.end_ns), PhaseReference::Locked);
        assert_eq!(truth.driver.counts().speed_mismatches, 0);
        assert!((x.amplitude_m / x0.amplitude_m - 1.0).abs() < 0.01);
        let dphi = (x.phase_lag_deg - x0.phase_lag_deg + 540.0).rem_euclid(360.0) - 180.0;
        assert!(dphi.abs() < 1.0, "ρ {ratio}: 1X lag {dphi}° off");
    }
}

/// A speed topic off by more than the keyphasor's 10 % interval tolerance (+15 %, −20 %, the
/// topic at twice the keyphasor's speed, and at half of it, as two notches give): beyond it the keyphasor contradicts the speed,
/// and the rule holds — reported, the twin carries on with the speed — since a wrong
/// tachometer and a keyphasor set up wrong (two notches, a mark on another shaft) cannot be
/// told apart from the two signals. Every event after the first is refused (31 of 32; at 2×
/// every other one, 16, the others' intervals being one of the topic's revolutions), none
/// scales the topic or relocks, the twin keeps the told speed, and once the events' own
/// intervals have agreed over 3 revolutions (by the 3rd refusal) each refusal says so with
/// both speeds and their ratio (to 4 digits), instead of naming an extra or a missed pulse;
/// the phases read not locked at the end (null with the reason, never a number from a mark
/// the twin does not follow; before session 16 they read locked, also at 2×).
#[test]
fn a_keyphasor_steadily_contradicting_the_speed_is_refused_with_the_diagnosis() {
    for ratio in [1.15, 0.8, 0.5, 2.0] {
        let plant_rpm = TOLD_RPM * ratio;
        let r = run(TOLD_RPM, plant_rpm, 0.0, 32);
        let c = r.driver.counts();
        println!(
            "ρ {ratio}: mismatches {}, relocks {}, refused {}, scale {:?}; refusals 2–4: {:?}",
            c.speed_mismatches,
            c.relocks,
            r.refused.len(),
            r.driver.speed_scale(),
            &r.refused[1..4],
        );
        assert_eq!((c.speed_mismatches, c.relocks), (0, 0), "ρ {ratio}");
        assert!(r.driver.speed_scale().is_none());
        let speed = r.driver.speed_rad_s().unwrap() * 30.0 / PI;
        assert!((speed / TOLD_RPM - 1.0).abs() < 1e-9, "{speed} rpm");
        // at 2× every other event's interval is one of the topic's revolutions: accepted, on a
        // twin at half the shaft's speed; the others are refused as extra pulses
        let refusals = if ratio == 2.0 { 16 } else { 31 };
        assert_eq!(r.refused.len(), refusals, "ρ {ratio}");
        let said = format!("{:.4} times the topic's", ratio);
        let first = r.refused.iter().position(|w| w.contains("steadily"));
        assert!(
            first.is_some_and(|k| k <= 2),
            "ρ {ratio}: {:?}",
            &r.refused[..4]
        );
        for (k, why) in r.refused.iter().enumerate().skip(first.unwrap()) {
            assert!(
                why.contains("steadily") && why.contains(&said),
                "refusal {k}: {why}"
            );
        }
        let reference = r.driver.phase_reference(r.end_ns);
        assert_eq!(reference, PhaseReference::NotLocked, "ρ {ratio}");
    }
}

/// The mark moved by 40° at revolution 12, the speed right: one relock (warned
/// "re-referenced", counted), no speed mismatch, as before session 15 (the odd revolution's
/// interval, 1 + 1/9 T, is one revolution, not a trend); the lock's error nil again after it.
#[test]
fn a_mark_moved_by_40_degrees_at_the_right_speed_relocks_once() {
    let r = run(TOLD_RPM, TOLD_RPM, 40.0, 24);
    let c = r.driver.counts();
    println!(
        "relocks {}, mismatches {}, refused {:?}, errors (deg) {:.3?}",
        c.relocks, c.speed_mismatches, r.refused, r.errors_deg
    );
    assert_eq!(c.relocks, 1);
    assert_eq!(c.speed_mismatches, 0);
    assert!(r.driver.speed_scale().is_none());
    assert!(r.warnings.iter().any(|w| w.contains("re-referenced")));
    assert!(r.refused.len() <= 3, "{:?}", r.refused);
    let late = r.errors_deg[18..]
        .iter()
        .fold(0.0f64, |m, e| m.max(e.abs()));
    assert!(late < 0.01, "{late}°");
}
