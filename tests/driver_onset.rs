//! The twin run through the driver against the same model run as a plain twin (issue 12,
//! README "The onset after a live calibration"): fed the plant's speed (every 10 ms) and its
//! keyphasor, a driver's nonlinear twin must follow the plain twin's motion, not start its
//! whirl from a larger seed because of how it is fed.
//!
//! The plant is the machine file's rotor as a plain nonlinear twin (direct film, 64 steps a
//! revolution at 8,000 rpm) started from its static equilibrium at 8,000 rpm, its keyphasor mark
//! at its angle zero; the driver runs the same model (nonlinear, direct film, the plant's step).
//! The driver's first speed comes after the plant's first step, before any keyphasor event (as a
//! live node hears the speed topic first), so its twin starts unlocked.

mod common;

use common::calibration::twin_rotor;
use rotor_twin::driver::{Driver, DriverSettings, Input, ModelKind};
use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use rotor_twin::monitor::{ClassifierSettings, Monitor};
use std::f64::consts::{PI, TAU};

const EPOCH_NS: i64 = 1_767_225_600_000_000_000;

/// Journal positions (m) of every bearing, x and y.
fn journals(twin: &Twin) -> Vec<f64> {
    twin.output()
        .bearings
        .iter()
        .flat_map(|b| b.position_m)
        .collect()
}

/// The largest sub-synchronous amplitude (m) of the bearings in a revolution's report.
fn subsync(monitor: &mut Monitor, twin: &Twin) -> Option<f64> {
    monitor.record(twin).map(|r| {
        r.bearings
            .iter()
            .map(|b| b.subsync_amplitude_m)
            .fold(0.0, f64::max)
    })
}

/// One twin's record since its (last) start: journal positions per step, sub-synchronous
/// amplitude per revolution.
#[derive(Default)]
struct Track {
    steps: Vec<Vec<f64>>,
    subsync: Vec<f64>,
    monitor: Option<Monitor>,
}

impl Track {
    fn record(&mut self, twin: &Twin) {
        // a restarted twin: its record starts again
        if self.steps.len() as f64 * twin.config().time_step_s > twin.time_s() + 1e-12 {
            *self = Track::default();
        }
        let m = self
            .monitor
            .get_or_insert_with(|| Monitor::new(twin, 128, ClassifierSettings::default()));
        if let Some(a) = subsync(m, twin) {
            self.subsync.push(a);
        }
        self.steps.push(journals(twin));
    }
}

/// The plant at 8,000 rpm for `revs` revolutions, fed to a driver (speed every 10 ms, keyphasor
/// events at the plant's mark, stamped by its angle); the driver's twin stepped one step at a
/// time and recorded. Returns (plant, driver) tracks and the driver's starts.
fn plant_and_driver(revs: f64) -> (Track, Track, u64) {
    let machine = twin_rotor();
    let w8 = 8000.0 * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w8, 64);
    let mut settings = DriverSettings::new(
        ModelKind::Nonlinear,
        FilmEvaluation::Direct,
        machine.rated_speed_rad_s,
    );
    settings.twin.time_step_s = config.time_step_s;
    let mut driver = Driver::new(machine.clone(), settings);
    let mut plant = Twin::new(&machine, config, w8).unwrap();
    let (mut p, mut d) = (Track::default(), Track::default());
    let (mut next_speed_ns, mut revolutions) = (0i64, 0i64);
    let input = StepInput {
        speed_rad_s: w8,
        accel_rad_s2: 0.0,
    };
    let mut emit = |_| {};
    while plant.time_s() < revs * TAU / w8 {
        plant.step(&input).unwrap();
        p.record(&plant);
        let t = EPOCH_NS + (plant.time_s() * 1e9).round() as i64;
        // the driver's twin up to the plant's time, one recorded step at a time
        while driver.advance_to(t, 1, &mut emit) == 1 {
            d.record(driver.session().unwrap().twin());
        }
        if t >= next_speed_ns {
            let speed = Input::Speed {
                speed_rad_s: w8,
                accel_rad_s2: 0.0,
                stamp_ns: t,
            };
            driver.feed(t, speed, &mut emit);
            next_speed_ns = t + 10_000_000;
        }
        let angle = plant.output().angle_rad;
        let rev = (angle / TAU).floor() as i64;
        if rev > revolutions {
            revolutions = rev;
            let past = (angle - rev as f64 * TAU) / w8;
            let stamp_ns = t - (past * 1e9).round() as i64;
            driver.feed(t, Input::Keyphasor { stamp_ns }, &mut emit);
        }
    }
    (p, d, driver.counts().starts)
}

/// Measured (session 13): before the fix the driver's twin was bitwise the plain twin's up to
/// step 64, then the first keyphasor event turned the running, unlocked twin's angle by the
/// plant's one step ahead (2π/64 = 0.098 rad): the unbalance force jumped in phase, an
/// impulse; from step 65 on the journals parted, by 0.56 µm within 41 revolutions, and the
/// sub-synchronous amplitude after 40 revolutions was × 8.2 the plain twin's. Now the twin
/// restarts at that event, angle zero there, as a twin that waited for it: over 40
/// revolutions it keeps to the plain twin within 3.6·10⁻¹² m (the later events turn its angle
/// by the stamps' nanosecond rounding, ~10⁻⁶ rad, ~6 µm/rad × 10⁻⁶ each: the 10⁻¹⁰ m
/// asserted is 5,000× below the kick's 0.56 µm), and its sub-synchronous amplitude is the
/// plain twin's to 10⁻⁴ (1 % asserted).
#[test]
fn a_twin_started_before_the_first_keyphasor_follows_a_plain_twin() {
    let (plant, driver, starts) = plant_and_driver(41.0);
    let n = driver.steps.len().min(plant.steps.len());
    let gaps: Vec<f64> = (0..n)
        .map(|k| {
            driver.steps[k]
                .iter()
                .zip(&plant.steps[k])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    let worst = gaps.iter().copied().fold(0.0, f64::max);
    // the first step where the two part by more than round-off (10⁻¹⁵ m)
    if let Some(k) = gaps.iter().position(|&g| g > 1e-15) {
        println!(
            "first divergence at step {} (revolution {:.3}): {:.3e} m",
            k + 1,
            (k + 1) as f64 / 64.0,
            gaps[k]
        );
    }
    let r = driver.subsync.len().min(plant.subsync.len()) - 1;
    let seed = driver.subsync[r] / plant.subsync[r];
    println!(
        "starts {starts}; over {n} steps the driver's journals within {worst:.3e} m of the plain twin's; sub-synchronous after {r} revolutions: driver {:.4e} m, plain {:.4e} m (× {seed:.2})",
        driver.subsync[r], plant.subsync[r]
    );
    assert!(n >= 36 * 64, "{n} steps compared");
    assert!(worst < 1e-10, "journals {worst:e} m apart");
    assert!((seed - 1.0).abs() < 0.01, "seed × {seed}");
}
