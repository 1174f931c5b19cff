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
//! estimate is applied the predicted 1X within 5 % and 5° of the measured at 8,000 rpm (on the
//! built-in (B), the raw-probe test, a nonlinear twin with the unbalance refined on it). The twin is reading (A) (config/orc_microturbine_100kw_d55.yaml,
//! Ø55, the built-in machine until session 15) wherever an onset or a threshold is checked: those
//! figures are (A)'s threshold crossing; the raw-probe calibration runs on the built-in (B).

mod common;

use common::calibration::{plant_rotor, twin_rotor_d55, twin_rotor_with_raw_probes};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rotor_twin::calibrate::NonlinearRefinement;
use rotor_twin::driver::calibration::{estimate, CALIBRATION_BLEND_S};
use rotor_twin::driver::{
    Applied, Driver, DriverSettings, Fed, Input, LiveCalibration, LiveEstimate, ModelKind,
    ObserverGains, OneXBlock, OneXBlocks, ProbeRef, StationRef,
};
use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use rotor_twin::monitor::{ClassifierSettings, Monitor};
use rotor_twin::plant::plant_runout;
use rotor_twin::replay::compare::{Sample, StationComparison};
use rotor_twin::rotor::{BearingModel, MachineDescription, Rotor};
use rotor_twin::signals::probes::runout_at;
use std::f64::consts::PI;
use std::f64::consts::TAU;

const EPOCH_NS: i64 = 1_767_225_600_000_000_000;

/// What the plant's probes deliver.
#[derive(Debug, Clone, Copy)]
enum PlantProbes {
    /// Machine-frame pairs (`ProbeDisplacement`, m), the static position included.
    Pairs,
    /// One raw reading per probe along the twin's `proximity_probes` angles (±45° of vertical),
    /// in V at 7.87 V/mm, DC-coupled, 1 mm of gap with the shaft centred, with `runout_m` of
    /// slow-roll runout (high spot 30° from the mark, `plant::plant_runout`).
    Raw { runout_m: f64 },
}

/// The plant and the drivers side by side: the plant's time, keyphasor and probes fed to each
/// driver in time order (the first driver's compared samples go into the 1X blocks and the
/// live calibration).
struct Rig {
    plant: Twin,
    drivers: Vec<Driver>,
    blocks: OneXBlocks,
    calibration: LiveCalibration,
    noise: Normal<f64>,
    rng: rand_chacha::ChaCha8Rng,
    next_speed_ns: i64,
    /// the keyphasor mark's angle on the plant's shaft (rad), and the mark passes counted
    mark_rad: f64,
    revolutions: i64,
    probes: PlantProbes,
    /// keyphasor events refused by the first driver (intervals across a speed step)
    refused: usize,
    /// every driver's compared samples per station, as the replay collects them
    comparisons: Vec<Vec<StationComparison>>,
    /// the plant's own monitor (its bearings' sub-synchronous amplitude, the whirl's seed)
    plant_monitor: Monitor,
    /// the seeds printed every this many seconds of plant time in a ramp (0: never), and when next
    trace_s: f64,
    next_trace_s: f64,
}

impl Rig {
    fn new(plant: Twin, drivers: Vec<Driver>, mark_deg: f64, probes: PlantProbes) -> Self {
        let mark_rad = mark_deg.to_radians();
        let plant_monitor = Monitor::new(&plant, 256, ClassifierSettings::default());
        let mut rig = Rig {
            plant_monitor,
            // ONSET12_TRACE (s): the seeds along the whole history (studies)
            trace_s: std::env::var("ONSET12_TRACE")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(0.0),
            next_trace_s: 0.0,
            plant,
            blocks: OneXBlocks::new(Vec::new()),
            drivers: Vec::new(),
            calibration: LiveCalibration::default(),
            noise: Normal::new(0.0, 0.3e-6).unwrap(),
            rng: rand_chacha::ChaCha8Rng::seed_from_u64(12),
            next_speed_ns: 0,
            mark_rad,
            revolutions: (-mark_rad / TAU).floor() as i64,
            probes,
            refused: 0,
            comparisons: Vec::new(),
        };
        rig.set_drivers(drivers);
        rig
    }

    /// Feeds the plant to `drivers` from now on (fresh 1X blocks and calibration).
    fn set_drivers(&mut self, drivers: Vec<Driver>) {
        self.blocks = OneXBlocks::new(drivers[0].probe_axes());
        self.calibration = LiveCalibration::default();
        self.comparisons = drivers.iter().map(station_comparisons).collect();
        self.drivers = drivers;
    }

    /// Finishes every driver's comparison blocks against its own keyphasor events.
    fn finish_comparisons(&mut self) {
        for (comparisons, d) in self.comparisons.iter_mut().zip(&self.drivers) {
            for c in comparisons.iter_mut() {
                c.finish(Some(d.keyphasor_events()));
            }
        }
    }

    /// Driver `i`'s onset speed (rpm) by the replay's rule, the earlier station: predicted, or
    /// measured (the plant's).
    fn onset_rpm(&self, i: usize, predicted: bool) -> f64 {
        self.comparisons[i]
            .iter()
            .map(|c| c.onset(predicted).expect("an onset").1)
            .fold(f64::INFINITY, f64::min)
    }

    /// The largest sub-synchronous amplitude over the bearings (m, the monitor's 16-revolution
    /// spectrum at the last completed revolution): the plant's, then each driver's twin's.
    fn subsync_m(&self) -> Vec<f64> {
        let largest = |m: &Monitor| {
            m.report()
                .bearings
                .iter()
                .map(|b| b.subsync_amplitude_m)
                .fold(0.0, f64::max)
        };
        let mut out = vec![largest(&self.plant_monitor)];
        for d in &self.drivers {
            out.push(d.session().map_or(f64::NAN, |s| largest(s.monitor())));
        }
        out
    }

    /// Prints [`Self::subsync_m`] (µm) with the plant's speed.
    fn print_subsync(&self, what: &str) {
        let a: Vec<String> = self
            .subsync_m()
            .iter()
            .map(|a| format!("{:.4}", a * 1e6))
            .collect();
        println!(
            "sub-synchronous amplitude {what} ({:.0} rpm, µm): plant, twins {}",
            self.plant.output().speed_rad_s * 30.0 / PI,
            a.join(", ")
        );
    }

    fn now_ns(&self) -> i64 {
        EPOCH_NS + (self.plant.time_s() * 1e9).round() as i64
    }

    /// `revs` revolutions of the plant at `rpm`; probes fed when `measure`. Returns the blocks.
    fn run(&mut self, rpm: f64, revs: f64, measure: bool) -> Vec<OneXBlock> {
        self.ramp(rpm, rpm, revs * 60.0 / rpm, measure)
    }

    /// The plant from `from_rpm` to `to_rpm` at a constant rate over `seconds`; probes fed
    /// when `measure`. Returns the first driver's finished 1X blocks.
    fn ramp(&mut self, from_rpm: f64, to_rpm: f64, seconds: f64, measure: bool) -> Vec<OneXBlock> {
        let (w0, w1) = (from_rpm * PI / 30.0, to_rpm * PI / 30.0);
        let (t0, accel) = (self.plant.time_s(), (w1 - w0) / seconds);
        // the speed at once when it steps (the plant's speed steps between the calibration
        // speeds; the twin would otherwise turn at the old speed for up to 10 ms)
        self.next_speed_ns = 0;
        let mut out = Vec::new();
        let mut k = 0u64;
        while self.plant.time_s() < t0 + seconds {
            let h = self.plant.config().time_step_s;
            let t_mid = self.plant.time_s() + 0.5 * h - t0;
            let input = StepInput {
                speed_rad_s: w0 + accel * t_mid,
                accel_rad_s2: accel,
            };
            self.plant.step(&input).unwrap();
            self.plant_monitor.record(&self.plant);
            if self.trace_s > 0.0 && self.plant.time_s() >= self.next_trace_s {
                self.next_trace_s = self.plant.time_s() + self.trace_s;
                self.print_subsync("in the run-up");
            }
            let t = self.now_ns();
            let w = self.plant.output().speed_rad_s;
            if t >= self.next_speed_ns {
                let speed = Input::Speed {
                    speed_rad_s: w,
                    accel_rad_s2: accel,
                    stamp_ns: t,
                };
                self.feed(t, speed, &mut out);
                self.next_speed_ns = t + 10_000_000;
            }
            let o = self.plant.output();
            let (angle, rev) = (
                o.angle_rad,
                ((o.angle_rad - self.mark_rad) / TAU).floor() as i64,
            );
            if rev > self.revolutions {
                // the mark passed the keyphasor between the last two steps: its time by the
                // plant's speed from the angle past it
                let past = (angle - self.mark_rad - rev as f64 * TAU) / w;
                let stamp_ns = t - (past * 1e9).round() as i64;
                self.revolutions = rev;
                self.feed(t, Input::Keyphasor { stamp_ns }, &mut out);
            }
            k += 1;
            if measure && k.is_multiple_of(2) {
                self.measure(t, &mut out);
            }
        }
        out
    }

    /// The plant's probe samples at `t` (its present step), fed to every driver.
    fn measure(&mut self, t: i64, out: &mut Vec<OneXBlock>) {
        let o = self.plant.output();
        let probes: Vec<[f64; 2]> = o.probes.iter().map(|p| p.displacement_m).collect();
        let psi = o.angle_rad - self.mark_rad;
        for (station, p) in probes.iter().enumerate() {
            match self.probes {
                PlantProbes::Pairs => {
                    let (nx, ny) = (
                        self.noise.sample(&mut self.rng),
                        self.noise.sample(&mut self.rng),
                    );
                    let input = Input::Probe {
                        station: StationRef::Index(station),
                        x_m: p[0] + nx,
                        y_m: p[1] + ny,
                        stamp_ns: t,
                    };
                    self.feed(t, input, out);
                }
                PlantProbes::Raw { runout_m } => {
                    let name = self.drivers[0].rotor().probes[station].name.clone();
                    let axes = self.drivers[0].probe_axes()[station];
                    for (j, suffix) in ["x", "y"].iter().enumerate() {
                        let a = axes[j];
                        let runout = runout_at(&plant_runout(runout_m, a), psi);
                        let d = p[0] * a.cos()
                            + p[1] * a.sin()
                            + runout
                            + self.noise.sample(&mut self.rng);
                        let input = Input::ProbeSignal {
                            probe: ProbeRef::Name(format!("{name}_{suffix}")),
                            value: 7870.0 * (1e-3 - d),
                            stamp_ns: t,
                        };
                        self.feed(t, input, out);
                    }
                }
            }
        }
    }

    /// One input to every driver; the first driver's compared samples go into the 1X blocks
    /// (finished blocks into the live calibration, by the node's route, ros/model.rs).
    fn feed(&mut self, t: i64, input: Input, out: &mut Vec<OneXBlock>) {
        for (i, d) in self.drivers.iter_mut().enumerate() {
            let fed = d.feed(t, input.clone(), &mut |_| {});
            if let Fed::Refused(why) = &fed {
                // the plant's speed steps between the calibration speeds: the keyphasor
                // interval across a step contradicts the speed in force, and is refused
                assert!(why.starts_with("keyphasor"), "refused: {why}");
                self.refused += usize::from(i == 0);
            }
            let Fed::Compared(c) = fed else {
                continue;
            };
            // the measured 1X against the plant's keyphasor events, as the replay reads it
            self.comparisons[i][c.station].push(
                Sample::of(&c, (c.time_ns - EPOCH_NS) as f64 * 1e-9),
                Some(d.keyphasor_events()),
            );
            if i == 0 {
                self.blocks.add(&c, d.keyphasor_events());
            }
        }
        let d = &self.drivers[0];
        let newest = d.newest_sample_ns().unwrap_or(i64::MIN);
        while let Some(b) = self.blocks.take_ready(d.keyphasor_events(), newest) {
            self.calibration.add(&b, !d.station_is_ac(b.station));
            out.push(b);
        }
    }
}

/// The replay's comparisons of `driver`'s stations (its probe axes, the films' least clearance).
fn station_comparisons(driver: &Driver) -> Vec<StationComparison> {
    let rotor = driver.rotor();
    let clearance = rotor
        .bearings
        .iter()
        .filter_map(|b| match &b.model {
            BearingModel::Film(f) => Some(f.geometry.radial_clearance_m),
            _ => None,
        })
        .fold(f64::INFINITY, f64::min);
    rotor
        .probes
        .iter()
        .map(|p| StationComparison::new(&p.name, clearance).with_axes(p.angles_rad))
        .collect()
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

/// The plant at 5,000, 6,500 and 8,000 rpm (8 revolutions to settle, then 16.5 measured at
/// each), fed to a linear twin of `twin`; then the live estimate. Returns the rig, the last
/// blocks and the estimate.
fn calibrate(
    twin: &Rotor,
    mark_deg: f64,
    probes: PlantProbes,
) -> (Rig, Vec<OneXBlock>, LiveEstimate) {
    calibrate_with(twin, mark_deg, probes, Vec::new(), None, LINEAR)
}

/// The linear twin on the direct film.
const LINEAR: (ModelKind, FilmEvaluation) = (ModelKind::Linear, FilmEvaluation::Direct);

/// [`calibrate`] with `more` drivers fed the same plant alongside; the plant's speed steps from
/// one calibration speed to the next at once, or ramps at `ramp_rpm_s` (rpm/s).
fn calibrate_with(
    twin: &Rotor,
    mark_deg: f64,
    probes: PlantProbes,
    more: Vec<Driver>,
    ramp_rpm_s: Option<f64>,
    (kind, film): (ModelKind, FilmEvaluation),
) -> (Rig, Vec<OneXBlock>, LiveEstimate) {
    let plant = plant_rotor(twin);
    let w8 = 8000.0 * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w8, 64);
    let w5 = 5000.0 * PI / 30.0;
    let settings = DriverSettings::new(kind, film, twin.rated_speed_rad_s);
    let mut drivers = vec![Driver::new(twin.clone(), settings)];
    drivers.extend(more);
    let plant = Twin::new(&plant, config, w5).unwrap();
    let mut rig = Rig::new(plant, drivers, mark_deg, probes);
    let mut before = Vec::new();
    let mut last_rpm = 5000.0;
    for rpm in [5000.0, 6500.0, 8000.0] {
        if let (Some(rate), true) = (ramp_rpm_s, rpm > last_rpm) {
            rig.ramp(last_rpm, rpm, (rpm - last_rpm) / rate, false);
        }
        last_rpm = rpm;
        rig.run(rpm, 8.0, false);
        before = rig.run(rpm, 16.5, true);
    }
    assert!(before.iter().all(|b| b.null_reason.is_none()), "{before:?}");
    // at most one event refused at each of the two speed steps
    assert!(rig.refused <= 2, "{} keyphasor events refused", rig.refused);
    let measured = rig.calibration.measurements();
    println!(
        "{} 1X vectors, {} mean positions, {} whirl blocks",
        measured.0.len(),
        measured.1.len(),
        rig.calibration.whirl_blocks
    );
    let e = estimate(twin, &measured, rig.drivers[0].calibration_refinement());
    (rig, before, e)
}

/// The estimate against the plant (viscosity × 1.10 within 3 %, 280 g·mm within 10 % at
/// `phase_deg` within 10°, the twin's own plane under 10 % of it); then applied to the running
/// twin, the predicted 1X at 8,000 rpm against the measured (5 % and 5°). Returns the applied
/// values.
fn check_and_apply(
    rig: &mut Rig,
    before: &[OneXBlock],
    e: &LiveEstimate,
    phase_deg: f64,
) -> Applied {
    let (before_amp, before_lag) = prediction_error(before);
    let v = e.viscosity.as_ref().unwrap();
    let u = e.unbalance.as_ref().unwrap();
    println!(
        "viscosity × {:.4} ± {:.4}; unbalance {:?}; condition {:.2}, relative 1X residual {:.3}",
        v.scale, v.scale_std, u.planes, u.condition_number, u.relative_residual
    );
    assert!((v.scale / 1.10 - 1.0).abs() < 0.03, "{v:?}");
    // the reported σ covers the model error (README, issue 12): |s − 1.10| ≤ 2σ (k = 2); the
    // fit's own σ alone (the ± reported before, × 1.1042 ± 0.0016) left it 2.6σ off
    let err = v.scale - 1.10;
    println!(
        "viscosity error {err:+.4}: {:+.2} σ (σ {:.4}; fit alone {:.4}, {:+.1} of its σ)",
        err / v.scale_std,
        v.scale_std,
        v.fit_std,
        err / v.fit_std
    );
    assert!(err.abs() <= 2.0 * v.scale_std, "{v:?}");
    let p = u.planes[1];
    assert!((p.magnitude_g_mm / 280.0 - 1.0).abs() < 0.10, "{p:?}");
    assert!(lag_gap(p.phase_deg, phase_deg).abs() < 10.0, "{p:?}");
    assert!(u.planes[0].magnitude_g_mm < 28.0, "{u:?}");
    let m = e.to_message(0, false);
    assert!(m.viscosity_valid && m.unbalance_valid && m.unbalance_magnitudes.len() == 2);

    // applied: the running twin takes the fitted viscosity and unbalance
    let (unbalance, viscosity_scale) = e.values();
    let applied = Applied {
        unbalance,
        viscosity_scale,
    };
    let said = rig.drivers[0].apply_calibration(applied.clone()).unwrap();
    println!("applied: {said}");
    assert_eq!(rig.drivers[0].viscosity_scale(), v.scale);
    // a nonlinear twin takes the values over CALIBRATION_BLEND_S, then 8 revolutions to settle
    let blend_revs = match rig.drivers[0].settings().twin.coupling {
        Coupling::Linear => 0.0,
        _ => CALIBRATION_BLEND_S * 8000.0 / 60.0,
    };
    rig.run(8000.0, blend_revs + 8.0, false);
    let after = rig.run(8000.0, 16.5, true);
    let (after_amp, after_lag) = prediction_error(&after);
    println!(
        "8,000 rpm, predicted against measured 1X: before {:.1} % and {:.1}°, after {:.1} % and {:.1}°",
        100.0 * before_amp,
        before_lag,
        100.0 * after_amp,
        after_lag
    );
    // the 5 % and 5°. (A), linear twin: 3.0 % and 2.9°. (B), nonlinear twin with the
    // unbalance refined on it (`calibrate::refine_unbalance`, session 17): 0.7 % and 0.7°; the
    // linear fit alone left 7.7–8.9 % on (B) at 280 g·mm (linear or nonlinear twin), 2.9 % at
    // 140 g·mm and 2.5 % at 70: the films' nonlinearity, not the noise or the grids
    assert!(after_amp < 0.05 && after_lag < 5.0);
    applied
}

fn rpm(threshold: Option<(f64, f64)>) -> f64 {
    threshold.expect("a threshold in range").0 * 30.0 / PI
}

/// The predicted onset the node publishes, the linear stability threshold it recomputes when
/// the viscosity in force moves (`session::linear_threshold` of the driver's machine, ros/model.rs
/// `refresh_threshold`), before and after the live estimate, against the plant's own (its
/// machine: oil × 1.10, films 72 × 12; the reference is the same eigenvalue analysis of the
/// plant's machine). Also the twin's machine with the plant's true oil (× 1.10 on its 60 × 10
/// films), which splits the gap after calibration into the films' grid and the fit's error.
/// Measured: plant 8,279 rpm; twin 8,471 before (+192), **8,283 after (+4)**; with the true oil
/// 8,300 (+20, the grid alone). The fit models the plant's mean journal positions under the 1X
/// orbits of the fitted unbalance (`calibrate::estimate_viscosity_and_unbalance`): viscosity
/// × 1.1042 ± 0.0016 for × 1.10. With the static fit (main before session 11) it read × 1.126 and
/// the threshold 8,247 (−32), which fails the 30 rpm asserted here; more than 150 rpm
/// off before (the calibration's gain).
fn predicted_onset_after_calibration(twin: &Rotor, driver: &mut Driver) {
    let threshold = rotor_twin::session::linear_threshold;
    let plant = rpm(threshold(&plant_rotor(twin)));
    let before = rpm(threshold(twin));
    let mut true_oil = twin.clone();
    true_oil.set_viscosity_scale(1.10).unwrap();
    let grid_only = rpm(threshold(&true_oil));
    // as the node: the threshold of the driver's machine, the calibration applied
    driver.set_threshold(threshold(driver.rotor()));
    let after = rpm(driver.linear_threshold());
    println!(
        "linear threshold: plant {plant:.0} rpm; twin before {before:.0} ({:+.0}), after {after:.0} ({:+.0}); twin with the true oil {grid_only:.0} ({:+.0})",
        before - plant,
        after - plant,
        grid_only - plant
    );
    assert!((grid_only - plant).abs() < 30.0);
    assert!((after - plant).abs() < 30.0);
    assert!((before - plant).abs() > 150.0);
}

#[test]
fn the_live_estimate_recovers_the_plant_and_applying_it_moves_the_prediction_onto_it() {
    let twin = twin_rotor_d55();
    let (mut rig, before, e) = calibrate(&twin, 0.0, PlantProbes::Pairs);
    check_and_apply(&mut rig, &before, &e, 120.0);
    predicted_onset_after_calibration(&twin, &mut rig.drivers[0]);
    // reversible: the machine file's values back
    rig.drivers[0].revert_calibration().unwrap();
    assert_eq!(rig.drivers[0].viscosity_scale(), 1.0);
    assert!(rig.drivers[0].calibration().is_none());
}

/// Issue 12's checks with the plant's own signals as the live calibration's input: raw probes
/// at ±45° of vertical (API 670), in volts, DC-coupled, each with 5 µm of slow-roll runout (the
/// machine file gives the runout vectors, subtracted sample by sample) and 0.3 µm of noise, the
/// keyphasor mark 123° round the plant's shaft from its angle zero. The unbalance phase is then
/// read from the mark: 120° + 123° = 243° (the phase the plant publishes, `plant::write_bag`).
/// Same targets as above, on the built-in (B) with the node's default coupling (nonlinear; the
/// direct film here, where the node runs the table: the table gives the same figures, 281.3 g·mm
/// at 243.0°, 0.7 % and 0.7°, but is built afresh in a test process, 50 s), so the unbalance is
/// refined on the nonlinear twin: measured 281.3 g·mm at 243.0° (plant 280 at 243°), 0.7 g·mm
/// at stage 4, 1X residual 0.6 %.
#[test]
fn raw_probes_with_runout_calibrate_the_live_twin() {
    let twin = twin_rotor_with_raw_probes(5e-6);
    let raw = PlantProbes::Raw { runout_m: 5e-6 };
    let (mut rig, before, e) = calibrate_with(
        &twin,
        123.0,
        raw,
        Vec::new(),
        None,
        (ModelKind::Nonlinear, FilmEvaluation::Direct),
    );
    let u = e.unbalance.as_ref().unwrap();
    println!("{} update(s) on the nonlinear twin", u.nonlinear_updates);
    assert!(u.nonlinear_updates >= 1 && u.not_refined.is_none(), "{u:?}");
    // refined: within 1 % and 1° of the plant, under 3 g·mm at stage 4 (measured 281.3 g·mm at
    // 243.0°, 0.7 g·mm)
    assert!(
        (u.planes[1].magnitude_g_mm / 280.0 - 1.0).abs() < 0.01,
        "{u:?}"
    );
    assert!(lag_gap(u.planes[1].phase_deg, 243.0).abs() < 1.0, "{u:?}");
    assert!(u.planes[0].magnitude_g_mm < 3.0, "{u:?}");
    // a trial run that cannot be made (no steps a revolution) keeps the linear fit, saying why:
    // 274.7 g·mm at 239.9° and 12.7 g·mm at stage 4 (measured), outside the refined bounds above
    let no_trial = NonlinearRefinement {
        film: FilmEvaluation::Direct,
        steps_per_rev: 0,
    };
    let measured = rig.calibration.measurements();
    let lin = estimate(&twin, &measured, Some(no_trial))
        .unbalance
        .unwrap();
    println!("the linear fit: {:?}; {:?}", lin.planes, lin.not_refined);
    assert!(
        lin.not_refined.is_some() && lin.nonlinear_updates == 0,
        "{lin:?}"
    );
    assert!(lin.planes[0].magnitude_g_mm > 3.0, "{lin:?}");
    assert!(
        lag_gap(lin.planes[1].phase_deg, 243.0).abs() > 1.0,
        "{lin:?}"
    );
    check_and_apply(&mut rig, &before, &e, 243.0);
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

/// Issue 12's onset after a live calibration, the nonlinear twins through the plant's whole
/// history (not started at 8,000 rpm): three nonlinear twins (tabulated film, the node's default)
/// fed the plant from 5,000 rpm alongside the calibrating linear one: the machine file's; the
/// machine file's taking the live estimate the moment the fit yields it (after the 8,000 rpm
/// step); and the plant's own machine (oil × 1.10, 280 g·mm at stage 7, films 72 × 12). Then the
/// plant runs on from 8,000 to 9,400 rpm at 400 rpm/s into oil whip, the onset read by the
/// replay's rule (`StationComparison::onset`, the earlier station) from the measured (the plant,
/// direct film) and the predicted signals. The reference: the twin of the plant's own machine,
/// through the same driver, tabulated film and keyphasor lock, predicts the plant's onset within
/// the 30 rpm (measured +21 rpm). The calibrated twin takes the estimate over
/// `CALIBRATION_BLEND_S` (1 s): measured −107 rpm (before calibration −128), asserted within
/// 130 rpm; session 14 measured why (below, and README): the machine file's twins start the
/// run-up with × 1.9 the plant's whirl, the speed steps' kicks taken with the wrong unbalance. Taken at once, as before session 13, the
/// step kicked the rotor at 8,000 rpm, 280 rpm below its threshold where the whirl decays at
/// only ~0.02/rev, and the kick seeded the whip: −481 rpm, which fails here. The 30 rpm
/// is not met by the run-up onset (README, "The onset after a live calibration": it moves
/// 60–80 rpm per e-fold of the whirl's seed, +231 and +345 rpm per doubling of the run-up
/// rate); the linear threshold the node publishes meets it (+4 rpm,
/// `predicted_onset_after_calibration`).
#[test]
fn nonlinear_onset_after_live_calibration() {
    let ([plant, before, after, own], seed) = onset_after_live_calibration(None, 0.0, None, false);
    // the whirl's seed at the run-up's start (plant, linear twin, twins before, after, own):
    // measured 0.271, –, 0.520, 0.516, 0.253 µm. The twin of the plant's machine ran the
    // plant's history with the plant's values, so the speed steps kicked it as they kicked
    // the plant (× 0.93: its onset +21 rpm, one block of the rule); the machine file's twins
    // took the same steps with the machine file's unbalance (140 g·mm at stage 4, not 280 at
    // stage 7), so their free whirl started × 1.9 the plant's, and the calibration's blend did
    // not undo it: ln 1.9 = 0.64 e-fold, and the lead stays × 2.2–2.3 up the run-up (at 9,000 rpm
    // the plant's whirl grows 1.08 e-fold per 100 rpm): some 75–80 rpm of the −107.
    let ratio = |i: usize| seed[i] / seed[0];
    println!(
        "seed over the plant's at the run-up's start: before × {:.2}, after × {:.2}, own × {:.2}",
        ratio(2),
        ratio(3),
        ratio(4)
    );
    assert!((ratio(4) - 0.93).abs() < 0.1, "{seed:?}");
    assert!((ratio(3) - 1.90).abs() < 0.2, "{seed:?}");
    assert!((own - plant).abs() < 30.0);
    // measured −107 rpm (before calibration −128, stated): the seed's; asserted within 130 rpm
    // (the measured and one block of the rule, ≈ 21 rpm)
    assert!((after - plant).abs() < 130.0);
    let _ = before;
}

/// Study of [`nonlinear_onset_after_live_calibration`]'s history (ignored; set by environment
/// variables): ONSET12_RAMP (rpm/s of the plant between the calibration speeds, 0 = steps),
/// ONSET12_HOLD (s at 8,000 rpm after the calibration is applied, before the run-up);
/// ONSET12_OBS_C (N·s/m), ONSET12_OBS_K (N/m), ONSET12_OBS_FC (Hz): the nonlinear twins' nudging
/// observer from the start (none when both gains are 0), off at the run-up's start unless
/// ONSET12_OBS_KEEP is set.
#[test]
#[ignore]
fn nonlinear_onset_study() {
    let num = |name: &str, default: f64| {
        std::env::var(name).map_or(default, |v| v.parse().expect("a number"))
    };
    let ramp = num("ONSET12_RAMP", 0.0);
    let hold = num("ONSET12_HOLD", 0.0);
    let gains = ObserverGains {
        stiffness_n_m: num("ONSET12_OBS_K", 0.0),
        damping_n_s_m: num("ONSET12_OBS_C", 0.0),
        cutoff_hz: num("ONSET12_OBS_FC", 270.0),
    };
    let observer = (gains.stiffness_n_m > 0.0 || gains.damping_n_s_m > 0.0).then_some(gains);
    let keep = std::env::var("ONSET12_OBS_KEEP").is_ok();
    let (r, _) = onset_after_live_calibration((ramp > 0.0).then_some(ramp), hold, observer, keep);
    println!("RESULT ramp {ramp} hold {hold} observer {observer:?} keep {keep}: {r:?}");
}

/// The run of [`nonlinear_onset_after_live_calibration`]: the plant's history to 8,000 rpm
/// (steps, or ramps at `ramp_rpm_s`), the calibration, `hold_s` more at 8,000 rpm, then the
/// 400 rpm/s run-up to 9,400 rpm. Prints the whirl's seed (the bearings' largest
/// sub-synchronous amplitude) of the plant and each twin along the way. Returns the onsets
/// (rpm): the plant's, the twin's before and after calibration, the plant's own machine's.
/// `observer`: the nonlinear twins' nudging observer from the start, off at the run-up's start
/// (the onset an open-loop prediction from the assimilated state) unless `keep`.
fn onset_after_live_calibration(
    ramp_rpm_s: Option<f64>,
    hold_s: f64,
    observer: Option<ObserverGains>,
    keep: bool,
) -> ([f64; 4], Vec<f64>) {
    let twin = twin_rotor_d55();
    let nonlinear = |rotor: &Rotor| {
        let settings = DriverSettings::new(
            ModelKind::Nonlinear,
            FilmEvaluation::Table,
            twin.rated_speed_rad_s,
        );
        let mut d = Driver::new(rotor.clone(), settings);
        d.set_observer(observer).unwrap();
        d
    };
    let more = vec![
        nonlinear(&twin),
        nonlinear(&twin),
        nonlinear(&plant_rotor(&twin)),
    ];
    let (mut rig, before, e) =
        calibrate_with(&twin, 0.0, PlantProbes::Pairs, more, ramp_rpm_s, LINEAR);
    rig.print_subsync("at the estimate");
    let (unbalance, viscosity_scale) = e.values();
    let applied = Applied {
        unbalance,
        viscosity_scale,
    };
    rig.drivers[2].apply_calibration(applied).unwrap();
    check_and_apply(&mut rig, &before, &e, 120.0);
    if hold_s > 0.0 {
        rig.run(8000.0, hold_s * 8000.0 / 60.0, true);
    }
    rig.print_subsync("at the run-up's start");
    let seed = rig.subsync_m();
    if !keep {
        for d in &mut rig.drivers[1..] {
            d.set_observer(None).unwrap();
        }
    }
    if rig.trace_s == 0.0 {
        rig.trace_s = 0.25;
    }
    rig.ramp(8000.0, 9400.0, 3.5, true);
    rig.finish_comparisons();
    let onset = |i: usize, predicted: bool| rig.onset_rpm(i, predicted);
    let plant = onset(1, false);
    let [before, after, own] = [1, 2, 3].map(|i| onset(i, true));
    println!(
        "nonlinear onset: plant {plant:.0} rpm; twin before {before:.0} ({:+.0}), after {after:.0} ({:+.0}); twin of the plant's machine {own:.0} ({:+.0})",
        before - plant,
        after - plant,
        own - plant
    );
    // two starts each: at the first speed, and again at the first keyphasor event (a twin
    // running unlocked restarts there rather than being turned onto it); the twins ran the
    // plant's whole history from then on
    assert!(rig.drivers[1..].iter().all(|d| d.counts().starts == 2));
    ([plant, before, after, own], seed)
}

/// The twin's films on `n_theta × n_z`.
fn on_grid(rotor: &Rotor, n_theta: usize, n_z: usize) -> Rotor {
    let mut r = rotor.clone();
    for b in &mut r.bearings {
        if let BearingModel::Film(f) = &mut b.model {
            f.grid.n_theta = n_theta;
            f.grid.n_z = n_z;
        }
    }
    r
}

/// The study of the nonlinear onset against the twin's film grid (README, "The onset after a
/// live calibration"): the machine file's rotor (its oil and unbalance) as nonlinear twins on
/// the tabulated film of each grid (60 × 10, 72 × 12, 90 × 15, 120 × 20; a table built per
/// grid), fed one plant (the machine file's, direct film) from 8,000 rpm (16 revolutions) and
/// then the same 400 rpm/s run-up to 9,400 rpm as `nonlinear_onset_after_live_calibration`, the
/// onset by the replay's rule; and the linear threshold per grid. A study, not a check: ignored
/// (several minutes: the tables), run with `-- --ignored --nocapture`; it asserts only that every
/// twin finds an onset and a threshold.
#[test]
#[ignore]
fn onset_against_the_film_grid() {
    let machine = twin_rotor_d55();
    let grids = [(60, 10), (72, 12), (90, 15), (120, 20)];
    let drivers: Vec<Driver> = grids
        .iter()
        .map(|&(nt, nz)| {
            let settings = DriverSettings::new(
                ModelKind::Nonlinear,
                FilmEvaluation::Table,
                machine.rated_speed_rad_s,
            );
            Driver::new(on_grid(&machine, nt, nz), settings)
        })
        .collect();
    let w8 = 8000.0 * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w8, 64);
    let plant = Twin::new(&machine, config, w8).unwrap();
    let mut rig = Rig::new(plant, drivers, 0.0, PlantProbes::Pairs);
    rig.run(8000.0, 16.0, true);
    rig.ramp(8000.0, 9400.0, 3.5, true);
    rig.finish_comparisons();
    let onset = |i: usize, predicted: bool| rig.onset_rpm(i, predicted);
    println!(
        "plant (60 × 10, direct film): onset {:.0} rpm",
        onset(0, false)
    );
    for (i, &(nt, nz)) in grids.iter().enumerate() {
        let threshold = rpm(rotor_twin::session::linear_threshold(&on_grid(
            &machine, nt, nz,
        )));
        println!(
            "grid {nt} × {nz}: nonlinear onset {:.0} rpm, linear threshold {threshold:.1} rpm",
            onset(i, true)
        );
    }
}

/// Study (README, "The onset after a live calibration", the grid study's 212 rpm): the machine
/// file's plant (60 × 10, direct film, a plain twin) against twins of the same machine through
/// the driver: tabulated, direct, and direct with the plant's own time step; from 8,000 rpm (16
/// revolutions), the 400 rpm/s run-up. Before session 13's fix the driver's twins whipped
/// 212–277 rpm early (8,964 table, 8,899 direct against 9,176): the first keyphasor event turned
/// the running twin's angle by 0.098 rad, an unbalance impulse (tests/driver_onset.rs). Now the
/// direct twins (the plant's own model) whip within 30 rpm of the plant, the replay rule's
/// resolution (~21 rpm, one block of 8 revolutions at 400 rpm/s) plus its block phase; the
/// table's −21…−42 rpm against the direct film (README) is not asserted. Ignored (1.5 min).
#[test]
#[ignore]
fn onset_through_the_driver_against_a_plain_twin() {
    let machine = twin_rotor_d55();
    let w8 = 8000.0 * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w8, 64);
    let driver = |film: FilmEvaluation, same_step: bool| {
        let mut settings =
            DriverSettings::new(ModelKind::Nonlinear, film, machine.rated_speed_rad_s);
        if same_step {
            settings.twin.time_step_s = config.time_step_s;
        }
        Driver::new(machine.clone(), settings)
    };
    let drivers = vec![
        driver(FilmEvaluation::Table, false),
        driver(FilmEvaluation::Direct, false),
        driver(FilmEvaluation::Direct, true),
    ];
    let plant = Twin::new(&machine, config, w8).unwrap();
    let mut rig = Rig::new(plant, drivers, 0.0, PlantProbes::Pairs);
    rig.run(8000.0, 16.0, true);
    rig.ramp(8000.0, 9400.0, 3.5, true);
    rig.finish_comparisons();
    let onset = |i: usize, predicted: bool| rig.onset_rpm(i, predicted);
    println!(
        "plant (plain twin, direct): {:.0} rpm; through the driver: table {:.0}, direct {:.0}, direct at the plant's step {:.0}",
        onset(0, false),
        onset(0, true),
        onset(1, true),
        onset(2, true)
    );
    for i in [1, 2] {
        let gap = onset(i, true) - onset(0, false);
        assert!(gap.abs() < 30.0, "driver {i}: {gap:+.0} rpm from the plant");
    }
}
