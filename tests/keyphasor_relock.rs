//! A keyphasor whose mark moves, misses pulses, gives extra ones or stops (issue 12, "Bad
//! input: a keyphasor that jumps, stops or contradicts the speed → reported, the twin carries
//! on with the speed").
//!
//! The plant turns at a constant speed; its keyphasor fires when its angle passes 2πk (the
//! mark), so its events are stamped t₀ + k·T exactly (T = 2π/Ω). Two drivers run the machine
//! file's rotor (nonlinear, direct film, 64 steps a revolution): one fed the true events, one
//! fed events whose mark moved by 90° from revolution 12 on (the mark, not the shaft: the
//! plant's motion is the same). Both start at the first event (`expect_keyphasor`).

mod common;

use common::calibration::twin_rotor;
use rotor_twin::driver::{Driver, DriverSettings, Fed, Input, ModelKind};
use rotor_twin::dynamics::{Coupling, FilmEvaluation, Twin, TwinConfig};
use rotor_twin::monitor::{ClassifierSettings, Monitor};
use rotor_twin::session::Outgoing;
use rotor_twin::signals::{one_x_vector, PhaseReference};
use std::f64::consts::{PI, TAU};

const T0_NS: i64 = 1_000_000_000;

/// One driver's record: journal positions per step, the twin's angle and probe station 0's x
/// per step, the largest sub-synchronous amplitude per revolution, and its warnings.
#[derive(Default)]
struct Track {
    steps: Vec<Vec<f64>>,
    angle_x: Vec<(f64, f64)>,
    subsync: Vec<f64>,
    monitor: Option<Monitor>,
    warnings: Vec<String>,
    refused: Vec<String>,
}

impl Track {
    fn record(&mut self, twin: &Twin) {
        let m = self
            .monitor
            .get_or_insert_with(|| Monitor::new(twin, 128, ClassifierSettings::default()));
        if let Some(r) = m.record(twin) {
            let a = r.bearings.iter().map(|b| b.subsync_amplitude_m);
            self.subsync.push(a.fold(0.0, f64::max));
        }
        let o = twin.output();
        self.steps
            .push(o.bearings.iter().flat_map(|b| b.position_m).collect());
        self.angle_x
            .push((o.angle_rad, o.probes[0].displacement_m[0]));
    }
}

fn driver_at(w: f64, steps_per_rev: usize) -> Driver {
    let machine = twin_rotor();
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, steps_per_rev);
    let mut settings = DriverSettings::new(
        ModelKind::Nonlinear,
        FilmEvaluation::Direct,
        machine.rated_speed_rad_s,
    );
    settings.twin.time_step_s = config.time_step_s;
    Driver::new(machine, settings)
}

/// A driver at `rpm` fed the speed every 10 ms and keyphasor events for `revs` revolutions,
/// the event of revolution k stamped at the plant's angle 2πk + `mark_rad(k)`; each twin step
/// recorded.
fn run(rpm: f64, revs: usize, mark_rad: impl Fn(usize) -> f64) -> Track {
    let w = rpm * PI / 30.0;
    let mut driver = driver_at(w, 64);
    driver.expect_keyphasor();
    let mut track = Track::default();
    let mut warnings = Vec::new();
    let mut emit = |o: Outgoing| {
        if let Outgoing::Warning(x) = o {
            warnings.push(x.evidence);
        }
    };
    let at = |psi: f64| T0_NS + (psi / w * 1e9).round() as i64;
    let mut next_speed_ns = T0_NS - 5_000_000;
    for k in 0..revs {
        let event = at(TAU * k as f64 + mark_rad(k));
        while next_speed_ns <= event {
            let speed = Input::Speed {
                speed_rad_s: w,
                accel_rad_s2: 0.0,
                stamp_ns: next_speed_ns,
            };
            while driver.advance_to(next_speed_ns, 1, &mut emit) == 1 {
                track.record(driver.session().unwrap().twin());
            }
            driver.feed(next_speed_ns, speed, &mut emit);
            next_speed_ns += 10_000_000;
        }
        while driver.advance_to(event, 1, &mut emit) == 1 {
            track.record(driver.session().unwrap().twin());
        }
        let fed = driver.feed(event, Input::Keyphasor { stamp_ns: event }, &mut emit);
        if let Fed::Refused(why) = fed {
            track.refused.push(why);
        }
    }
    assert_eq!(driver.counts().starts, 1, "one start, at the first event");
    track.warnings = warnings;
    track
}

/// The 1X phase lag (deg) of probe station 0's x over the last 8 revolutions of `t`, against
/// the twin's angle (the keyphasor-referenced angle of a locked twin).
fn lag_of_last_revs(t: &Track) -> f64 {
    let n = 8 * 64;
    let s = &t.angle_x[t.angle_x.len() - n..];
    one_x_vector(s.iter().copied(), n).unwrap().phase_lag_deg
}

/// Measured on main (session 14, before the fix): at 8,500 rpm, 350 rpm below the whip
/// threshold, the driver whose keyphasor mark moved by 90° at revolution 12 turned its running
/// twin's angle by −90° at the third agreeing event (revolution 15): its unbalance force jumped
/// in phase (a rotating force of 2·sin 45° = 1.41 times it added at once, printed), and its
/// journals left the undisturbed twin's by up to 8.8 µm within 40 revolutions, its
/// sub-synchronous amplitude after 37 revolutions 5.39 µm against 0.065 µm (× 83; the monitor
/// warned of a 0.46X whirl). Now the relock re-references the twin (its angle turned by the
/// correction and every heavy spot by minus it: the force, hence the motion, unchanged, as the
/// plant's; only the phase reference moves): the journals stay within 10⁻⁹ m of the
/// undisturbed twin's (8,800 times below the kick's; the printout gives the figure: the lock's
/// later corrections differ by the stamps' nanosecond rounding, ~10⁻⁶ rad), the
/// sub-synchronous amplitude the same within 1 %, and the 1X phase lag read after the relock
/// is the old one − 90° (the mark passes the probe a quarter turn later, so the next positive
/// peak comes a quarter turn sooner) within 0.5° (on main −1.0°: the kicked twin's force
/// turned with its angle).
#[test]
fn a_relock_re_references_the_phase_without_kicking_the_twin() {
    let (revs, moved_from) = (40, 12);
    let quarter = 90f64.to_radians();
    let plain = run(8500.0, revs, |_| 0.0);
    let moved = run(
        8500.0,
        revs,
        |k| if k >= moved_from { quarter } else { 0.0 },
    );
    let n = plain.steps.len().min(moved.steps.len());
    let worst = (0..n)
        .map(|k| {
            plain.steps[k]
                .iter()
                .zip(&moved.steps[k])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    let r = plain.subsync.len().min(moved.subsync.len()) - 1;
    let seed = moved.subsync[r] / plain.subsync[r];
    let (lag_plain, lag_moved) = (lag_of_last_revs(&plain), lag_of_last_revs(&moved));
    let shift = (lag_moved - lag_plain + 540.0).rem_euclid(360.0) - 180.0;
    // the size of the kick a turn of the twin's angle by 90° would be: the unbalance force
    // Σ m·e·Ω² turned by 90° at once, a rotating force of 2·sin 45° times it added in a step
    let w = 8500.0 * PI / 30.0;
    let f: f64 = twin_rotor()
        .unbalance
        .iter()
        .map(|u| u.magnitude_kg_m * w * w)
        .sum();
    println!(
        "unbalance force {f:.2} N: a 90° turn adds a rotating {:.2} N in a step",
        2.0 * 45f64.to_radians().sin() * f
    );
    println!(
        "{n} steps: journals within {worst:.3e} m; sub-synchronous after {r} revolutions: moved {:.4e} m, plain {:.4e} m (× {seed:.3}); 1X lag plain {lag_plain:.2}°, moved {lag_moved:.2}° ({shift:+.2}°); refused {:?}",
        moved.subsync[r], plain.subsync[r], moved.refused
    );
    // the moved mark's first event comes 1.25 T after the last (refused: a missed pulse or a
    // stop), the next two are 90° off (refused), the third agreeing one relocks, with a warning
    assert_eq!(moved.refused.len(), 3, "{:?}", moved.refused);
    assert!(moved.refused[0].contains("contradicts the speed"));
    assert!(moved.refused[1..]
        .iter()
        .all(|w| w.contains("jumped by -90.0°")));
    assert!(
        moved.warnings.iter().any(|w| w.contains("re-referenced")),
        "{:?}",
        moved.warnings
    );
    assert!(plain.refused.is_empty(), "{:?}", plain.refused);
    assert!(n >= 38 * 64, "{n} steps compared");
    assert!(worst < 1e-9, "journals {worst:e} m apart");
    // the monitor's revolutions start at the mark, so a 90° move shifts its windows by a quarter
    // revolution: on the default (B) at 8,500 rpm, whose 0.49X motion decays, that is × 0.986
    // with the journals 3e-12 m apart (session 15; (A)'s growing motion read within 1 %); the
    // kick this guards against read × 83
    assert!((seed - 1.0).abs() < 0.03, "sub-synchronous × {seed}");
    assert!((shift + 90.0).abs() < 0.5, "lag moved by {shift}°");
}

/// Keyphasor only (no speed topic), 8,000 rpm: pulse k is lost for every k ≡ 5 (mod 10) and a
/// glitch comes 0.37 T after pulse k for every k ≡ 8 (mod 10), 10 ≤ k < 80: 7 missed and 7
/// extra. Each bad event is refused once, with its reason (a missed pulse or a stop: the
/// interval is 2T; an extra pulse: 0.37 T), counted (14) and warned about, and costs nothing
/// else: every other event is accepted (on main a missed pulse cost 2 refusals and a glitch 3,
/// 35 in all: the refused interval became the reference the next true one was judged by). The
/// speed is 2π/T within 10⁻⁶ throughout (the stamps' 1 ns in T = 7.5 ms is 1.3·10⁻⁷), the
/// twin runs on from its one start, locked. Then the keyphasor stops: after 0.3 s (> 3
/// revolutions + 0.1 s) the stop is warned about once, the phases read Stopped, the twin has
/// carried on at the last speed (its steps: 0.3 s at 64 a revolution, within 2); a speed topic
/// then drives it.
#[test]
fn keyphasor_only_speed_survives_missed_and_extra_pulses_and_a_stop() {
    let w = 8000.0 * PI / 30.0;
    let mut driver = driver_at(w, 64);
    let warnings = std::cell::RefCell::new(Vec::<String>::new());
    let mut emit = |o: Outgoing| {
        if let Outgoing::Warning(x) = o {
            warnings.borrow_mut().push(x.evidence);
        }
    };
    let at = |revs: f64| T0_NS + (revs * TAU / w * 1e9).round() as i64;
    let (mut refused, mut worst_speed) = (Vec::new(), 0.0f64);
    for k in 0..80usize {
        let mut events = vec![k as f64];
        if k >= 10 && k % 10 == 5 {
            events.clear();
        }
        if k >= 10 && k % 10 == 8 {
            events.push(k as f64 + 0.37);
        }
        for e in events {
            let t = at(e);
            driver.advance_to(t, usize::MAX, &mut emit);
            if let Fed::Refused(why) = driver.feed(t, Input::Keyphasor { stamp_ns: t }, &mut emit) {
                refused.push(why);
            }
            if k >= 2 {
                let s = driver.speed_rad_s().unwrap();
                worst_speed = worst_speed.max((s / w - 1.0).abs());
            }
        }
    }
    let last = at(79.0);
    println!(
        "refused {}: {refused:?}; speed within {worst_speed:.2e}",
        refused.len()
    );
    assert_eq!(driver.counts().refused, 14, "{refused:?}");
    assert_eq!(
        refused
            .iter()
            .filter(|r| r.contains("missed pulse"))
            .count(),
        7
    );
    assert_eq!(
        refused.iter().filter(|r| r.contains("extra pulse")).count(),
        7
    );
    assert!(worst_speed < 1e-6, "speed off by {worst_speed}");
    assert_eq!(driver.counts().starts, 1);
    assert_eq!(driver.phase_reference(last), PhaseReference::Locked);
    assert!(
        warnings
            .borrow()
            .iter()
            .any(|x| x.contains("input(s) rejected")),
        "{warnings:?}"
    );
    // the keyphasor stops
    let steps_before = driver.counts().steps;
    let end = last + 300_000_000;
    driver.advance_to(end, usize::MAX, &mut emit);
    let dt = driver.session().unwrap().twin().config().time_step_s;
    let steps = (driver.counts().steps - steps_before) as f64;
    assert!((steps - 0.3 / dt).abs() <= 2.0, "{steps} steps in 0.3 s");
    assert_eq!(driver.phase_reference(end), PhaseReference::Stopped);
    let stops = warnings
        .borrow()
        .iter()
        .filter(|x| x.contains("keyphasor stopped"))
        .count();
    assert_eq!(stops, 1, "{warnings:?}");
    let held = driver.speed_rad_s().unwrap();
    assert!((held / w - 1.0).abs() < 1e-6, "held {held}");
    // a speed topic drives it on
    let w2 = 8100.0 * PI / 30.0;
    let speed = Input::Speed {
        speed_rad_s: w2,
        accel_rad_s2: 0.0,
        stamp_ns: end,
    };
    assert!(matches!(driver.feed(end, speed, &mut emit), Fed::Taken));
    assert_eq!(driver.speed_rad_s(), Some(w2));
    assert!(driver.advance_to(end + 10_000_000, usize::MAX, &mut emit) > 0);
    assert_eq!(driver.counts().starts, 1);
}
