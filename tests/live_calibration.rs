//! The node's live calibration (issue 12), through the driver and the 1X blocks the node uses
//! (`driver::OneXBlocks`, `driver::LiveCalibration`, `driver::calibration::estimate`,
//! `Driver::apply_calibration`), against a synthetic plant that differs from the twin as in
//! tests/calibrate.rs: unbalance doubled (280 instead of 140 g·mm) in another plane (stage 7,
//! node 21, instead of stage 4) at 120°, oil 10 % more viscous, films on 72 × 12 instead of
//! 60 × 10, the nonlinear transient with the direct film. The plant runs 5,000 → 6,500 → 8,000 rpm
//! in steps (24 revolutions each, the first 8 to settle), its keyphasor fires at its shaft angle
//! 0, and its probe pairs (DC: the static position included) get 0.3 µm of noise; the driver
//! (linear twin) is fed the speed, the keyphasor and the probes in time order, as the node feeds
//! it. Targets (the issue's): viscosity within 3 %, unbalance within 10 % and 10°; after the
//! estimate is applied the predicted 1X within 5 % and 5° of the measured at 8,000 rpm.

mod common;

use common::calibration::{plant_rotor, twin_rotor};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rotor_twin::driver::calibration::estimate;
use rotor_twin::driver::{
    Applied, Driver, DriverSettings, Fed, Input, LiveCalibration, ModelKind, OneXBlock, OneXBlocks,
    StationRef,
};
use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use rotor_twin::rotor::{MachineDescription, Rotor};
use std::f64::consts::TAU;

const EPOCH_NS: i64 = 1_767_225_600_000_000_000;

/// The plant and the driver side by side: the plant's time, keyphasor and probes fed to the
/// driver in time order; the blocks each station completes.
struct Rig {
    plant: Twin,
    driver: Driver,
    blocks: OneXBlocks,
    calibration: LiveCalibration,
    noise: Normal<f64>,
    rng: rand_chacha::ChaCha8Rng,
    next_speed_ns: i64,
    revolutions: i64,
}

impl Rig {
    fn now_ns(&self) -> i64 {
        EPOCH_NS + (self.plant.time_s() * 1e9).round() as i64
    }

    /// `revs` revolutions of the plant at `rpm`; probes fed when `measure`. Returns the blocks.
    fn run(&mut self, rpm: f64, revs: f64, measure: bool) -> Vec<OneXBlock> {
        let w = rpm * std::f64::consts::PI / 30.0;
        let input = StepInput {
            speed_rad_s: w,
            accel_rad_s2: 0.0,
        };
        let end = self.plant.output().angle_rad + revs * TAU;
        let mut out = Vec::new();
        let mut k = 0u64;
        while self.plant.output().angle_rad < end {
            self.plant.step(&input).unwrap();
            let t = self.now_ns();
            let feed = |d: &mut Driver, input: Input| d.feed(t, input, &mut |_| {});
            if t >= self.next_speed_ns {
                feed(
                    &mut self.driver,
                    Input::Speed {
                        speed_rad_s: w,
                        accel_rad_s2: 0.0,
                        stamp_ns: t,
                    },
                );
                self.next_speed_ns = t + 10_000_000;
            }
            let o = self.plant.output();
            let rev = (o.angle_rad / TAU).floor() as i64;
            if rev > self.revolutions {
                // the mark passed the keyphasor between the last two steps: its time by the
                // plant's speed from the angle past it
                let past = (o.angle_rad - rev as f64 * TAU) / w;
                let stamp_ns = t - (past * 1e9).round() as i64;
                self.revolutions = rev;
                feed(&mut self.driver, Input::Keyphasor { stamp_ns });
            }
            k += 1;
            if !measure || !k.is_multiple_of(2) {
                continue;
            }
            let probes: Vec<[f64; 2]> = o.probes.iter().map(|p| p.displacement_m).collect();
            for (station, p) in probes.iter().enumerate() {
                let (nx, ny) = (
                    self.noise.sample(&mut self.rng),
                    self.noise.sample(&mut self.rng),
                );
                let fed = self.driver.feed(
                    t,
                    Input::Probe {
                        station: StationRef::Index(station),
                        x_m: p[0] + nx,
                        y_m: p[1] + ny,
                        stamp_ns: t,
                    },
                    &mut |_| {},
                );
                if let Fed::Compared(c) = fed {
                    self.blocks.add(&c, self.driver.keyphasor_events());
                }
                // the node's route (ros/model.rs): blocks finished once their closing event came
                let newest = self.driver.newest_sample_ns().unwrap_or(i64::MIN);
                while let Some(b) = self
                    .blocks
                    .take_ready(self.driver.keyphasor_events(), newest)
                {
                    self.calibration.add(&b, true);
                    out.push(b);
                }
            }
        }
        out
    }
}

fn lag_gap(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

/// The largest amplitude ratio and lag difference, predicted against measured, over the probe
/// axes of the last block of each station.
fn prediction_error(blocks: &[OneXBlock]) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for station in 0..2 {
        let b = blocks.iter().rev().find(|b| b.station == station).unwrap();
        for j in 0..2 {
            let (p, m) = (b.predicted[j], b.measured[j]);
            let ratio = p.amplitude_m / m.amplitude_m - 1.0;
            let lag = lag_gap(p.phase_lag_deg, m.phase_lag_deg);
            println!(
                "station {station} axis {j}: predicted {:.3} µm at {:.1}°, measured {:.3} µm at {:.1}°",
                p.amplitude_m * 1e6,
                p.phase_lag_deg,
                m.amplitude_m * 1e6,
                m.phase_lag_deg
            );
            worst = (worst.0.max(ratio.abs()), worst.1.max(lag.abs()));
        }
    }
    worst
}

#[test]
fn the_live_estimate_recovers_the_plant_and_applying_it_moves_the_prediction_onto_it() {
    let twin = twin_rotor();
    let plant = plant_rotor(&twin);
    let w8 = 8000.0 * std::f64::consts::PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w8, 64);
    let w5 = 5000.0 * std::f64::consts::PI / 30.0;
    let settings = DriverSettings::new(
        ModelKind::Linear,
        FilmEvaluation::Direct,
        twin.rated_speed_rad_s,
    );
    let axes = vec![[0.0, std::f64::consts::FRAC_PI_2]; twin.probes.len()];
    let mut rig = Rig {
        plant: Twin::new(&plant, config, w5).unwrap(),
        driver: Driver::new(twin.clone(), settings),
        blocks: OneXBlocks::new(axes),
        calibration: LiveCalibration::default(),
        noise: Normal::new(0.0, 0.3e-6).unwrap(),
        rng: rand_chacha::ChaCha8Rng::seed_from_u64(12),
        next_speed_ns: 0,
        revolutions: 0,
    };
    let mut before = Vec::new();
    for rpm in [5000.0, 6500.0, 8000.0] {
        rig.run(rpm, 8.0, false);
        before = rig.run(rpm, 16.5, true);
    }
    assert!(before.iter().all(|b| b.null_reason.is_none()), "{before:?}");
    let (before_amp, before_lag) = prediction_error(&before);
    let measured = rig.calibration.measurements();
    println!(
        "{} 1X vectors, {} mean positions",
        measured.0.len(),
        measured.1.len()
    );
    let e = estimate(&twin, &measured);
    let v = e.viscosity.as_ref().unwrap();
    let u = e.unbalance.as_ref().unwrap();
    println!(
        "viscosity × {:.4} ± {:.4}; unbalance {:?}; condition {:.2}, relative 1X residual {:.3}",
        v.scale, v.scale_std, u.planes, u.condition_number, u.relative_residual
    );
    assert!((v.scale / 1.10 - 1.0).abs() < 0.03, "{v:?}");
    let p = u.planes[1];
    assert!((p.magnitude_g_mm / 280.0 - 1.0).abs() < 0.10, "{p:?}");
    assert!(lag_gap(p.phase_deg, 120.0).abs() < 10.0, "{p:?}");
    assert!(u.planes[0].magnitude_g_mm < 28.0, "{u:?}");
    let m = e.to_message(0, false);
    assert!(m.viscosity_valid && m.unbalance_valid && m.unbalance_magnitudes.len() == 2);

    // applied: the running twin takes the fitted viscosity and unbalance
    let (unbalance, viscosity_scale) = e.values();
    let said = rig
        .driver
        .apply_calibration(Applied {
            unbalance,
            viscosity_scale,
        })
        .unwrap();
    println!("applied: {said}");
    assert_eq!(rig.driver.viscosity_scale(), v.scale);
    rig.run(8000.0, 8.0, false);
    let after = rig.run(8000.0, 16.5, true);
    let (after_amp, after_lag) = prediction_error(&after);
    println!(
        "8,000 rpm, predicted against measured 1X: before {:.1} % and {:.1}°, after {:.1} % and {:.1}°",
        100.0 * before_amp,
        before_lag,
        100.0 * after_amp,
        after_lag
    );
    assert!(after_amp < 0.05 && after_lag < 5.0);
    // reversible: the machine file's values back
    rig.driver.revert_calibration().unwrap();
    assert_eq!(rig.driver.viscosity_scale(), 1.0);
    assert!(rig.driver.calibration().is_none());
}

/// The node's loop recomputes the linear stability threshold when the viscosity in force moves
/// (here an oil supply temperature of 60 °C against the built-in law's 40 °C design point): the
/// margin's threshold becomes the one computed independently for the machine at that viscosity
/// (`session::linear_threshold` on a copy with the scale set), which differs from the one at
/// start by more than 1 %.
#[test]
fn the_node_recomputes_the_stability_threshold_when_the_oil_temperature_changes() {
    use rotor_twin::messages::{Header, Temperature, Time};
    use rotor_twin::ros::model::{ModelLoop, Queued};
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let (mut model, inbox, clock) = common::model_loop::on_sim_time(rotor.clone());
    let mut t = EPOCH_NS;
    let mut wake_until = |model: &mut ModelLoop, done: &dyn Fn(&ModelLoop) -> bool| {
        for _ in 0..20_000 {
            t += 1_000_000;
            clock.sim_clock.lock().unwrap().offer(t);
            model.wake(&mut |_| {});
            if done(model) {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        panic!("not done in 100 s");
    };
    wake_until(&mut model, &|m| m.driver().threshold_known());
    let at_start = model.driver().linear_threshold().unwrap().0;
    let oil = Input::from(&Temperature {
        header: Header {
            stamp: Time::from_nanos(0),
            frame_id: String::new(),
        },
        temperature: 60.0,
        variance: 0.0,
    });
    inbox.lock().unwrap().push(Queued {
        received_ns: None,
        input: Ok(oil),
    });
    let moved = move |m: &ModelLoop| {
        m.driver()
            .linear_threshold()
            .is_some_and(|th| (th.0 - at_start).abs() > 1e-9)
    };
    wake_until(&mut model, &moved);
    let scale = model.driver().viscosity_scale();
    let mut hot = rotor.clone();
    hot.set_viscosity_scale(scale).unwrap();
    let want = rotor_twin::session::linear_threshold(&hot).unwrap().0;
    let now = model.driver().linear_threshold().unwrap().0;
    println!(
        "viscosity × {scale:.4} at 60 °C: threshold {:.1} rpm, was {:.1} rpm",
        now * 30.0 / std::f64::consts::PI,
        at_start * 30.0 / std::f64::consts::PI
    );
    assert_eq!(now, want);
    assert!((now / at_start - 1.0).abs() > 0.01);
}
