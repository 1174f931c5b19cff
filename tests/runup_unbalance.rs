//! The unbalance from a plant that ramps (issue 12, README "Next steps" 2: "the unbalance ...
//! from a plant that ramps"), through the driver and the node's live-calibration route
//! (`driver::OneXBlocks` → `driver::LiveCalibration` → `driver::calibration::estimate`), in
//! simulated time (no bus: tests/node_bus_unbalance.rs takes a stepped plant through DDS).
//!
//! The plant is the one of tests/live_calibration.rs (`common::calibration::plant_rotor` of the
//! built-in machine, reading (B), the default: the twin's own machine plus an empty plane at
//! stage 7): 280 g·mm at stage 7 (node 21) at 120° of its shaft angle instead of 140 g·mm at
//! stage 4, oil × 1.10, films 72 × 12 instead of 60 × 10; nonlinear, direct film, 64 steps a
//! revolution of 6,000 rpm. Its keyphasor mark is 123° round the shaft from its angle 0, so the
//! heavy spot read from the mark is at 120° + 123° = 243°. Its raw probes (±45° of vertical,
//! V at 7.87 V/mm, DC-coupled about a 1 mm gap, 5 µm of slow-roll runout, 0.3 µm of noise) are
//! sampled every second step, the speed (with its acceleration) every 10 ms, the keyphasor at
//! each mark pass, all fed to a linear twin in time order as the node feeds it. The plant runs
//! up at a constant rate from 3,000 to 6,000 rpm (after 8 revolutions at 3,000 to settle): the
//! 1X blocks of 8 revolutions each carry their own mean speed; the influence coefficients are
//! the twin's at each speed bin (10 rpm) of the blocks kept (the latest 16 × 4 bins).

mod common;

use common::calibration::{plant_rotor, twin_rotor_with_raw_probes};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rotor_twin::driver::calibration::estimate;
use rotor_twin::driver::{
    Driver, DriverSettings, Fed, Input, LiveCalibration, ModelKind, OneXBlocks, ProbeRef,
};
use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use rotor_twin::plant::plant_runout;
use rotor_twin::signals::probes::runout_at;
use std::f64::consts::{PI, TAU};

const EPOCH_NS: i64 = 1_767_225_600_000_000_000;
const MARK_DEG: f64 = 123.0;
const RUNOUT_M: f64 = 5e-6;

/// The plant, the driver and the live calibration side by side.
struct Rig {
    plant: Twin,
    driver: Driver,
    blocks: OneXBlocks,
    calibration: LiveCalibration,
    noise: Normal<f64>,
    rng: rand_chacha::ChaCha8Rng,
    next_speed_ns: i64,
    mark_rad: f64,
    revolutions: i64,
    refused: Vec<String>,
    block_count: usize,
}

impl Rig {
    fn now_ns(&self) -> i64 {
        EPOCH_NS + (self.plant.time_s() * 1e9).round() as i64
    }

    /// The plant from `from_rpm` to `to_rpm` at a constant rate over `seconds`; probes fed
    /// when `measure`.
    fn ramp(&mut self, from_rpm: f64, to_rpm: f64, seconds: f64, measure: bool) {
        let (w0, w1) = (from_rpm * PI / 30.0, to_rpm * PI / 30.0);
        let (t0, accel) = (self.plant.time_s(), (w1 - w0) / seconds);
        let mut k = 0u64;
        while self.plant.time_s() < t0 + seconds {
            let h = self.plant.config().time_step_s;
            let t_mid = self.plant.time_s() + 0.5 * h - t0;
            let input = StepInput {
                speed_rad_s: w0 + accel * t_mid,
                accel_rad_s2: accel,
            };
            self.plant.step(&input).unwrap();
            let t = self.now_ns();
            let (angle, w) = (
                self.plant.output().angle_rad,
                self.plant.output().speed_rad_s,
            );
            if t >= self.next_speed_ns {
                let speed = Input::Speed {
                    speed_rad_s: w,
                    accel_rad_s2: accel,
                    stamp_ns: t,
                };
                self.feed(t, speed);
                self.next_speed_ns = t + 10_000_000;
            }
            let rev = ((angle - self.mark_rad) / TAU).floor() as i64;
            if rev > self.revolutions {
                // the mark passed between the last two steps: its time by the speed
                let past = (angle - self.mark_rad - rev as f64 * TAU) / w;
                self.revolutions = rev;
                let stamp_ns = t - (past * 1e9).round() as i64;
                self.feed(t, Input::Keyphasor { stamp_ns });
            }
            k += 1;
            if measure && k.is_multiple_of(2) {
                self.measure(t);
            }
        }
    }

    /// The plant's raw probe readings at `t` (its present step).
    fn measure(&mut self, t: i64) {
        let o = self.plant.output();
        let probes: Vec<[f64; 2]> = o.probes.iter().map(|p| p.displacement_m).collect();
        let psi = o.angle_rad - self.mark_rad;
        for (station, p) in probes.iter().enumerate() {
            let name = self.driver.rotor().probes[station].name.clone();
            let axes = self.driver.probe_axes()[station];
            for (j, suffix) in ["x", "y"].iter().enumerate() {
                let a = axes[j];
                let runout = runout_at(&plant_runout(RUNOUT_M, a), psi);
                let d = p[0] * a.cos() + p[1] * a.sin() + runout + self.noise.sample(&mut self.rng);
                let input = Input::ProbeSignal {
                    probe: ProbeRef::Name(format!("{name}_{suffix}")),
                    value: 7870.0 * (1e-3 - d),
                    stamp_ns: t,
                };
                self.feed(t, input);
            }
        }
    }

    /// One input to the driver; its compared samples into the 1X blocks, finished blocks into
    /// the live calibration (the node's route, ros/model.rs).
    fn feed(&mut self, t: i64, input: Input) {
        let fed = self.driver.feed(t, input, &mut |_| {});
        if let Fed::Refused(why) = &fed {
            self.refused.push(why.clone());
        }
        if let Fed::Compared(c) = fed {
            self.blocks.add(&c, self.driver.keyphasor_events());
        }
        let d = &self.driver;
        let newest = d.newest_sample_ns().unwrap_or(i64::MIN);
        while let Some(b) = self.blocks.take_ready(d.keyphasor_events(), newest) {
            self.calibration.add(&b, !d.station_is_ac(b.station));
            self.block_count += 1;
        }
    }
}

fn lag_gap(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

/// A run-up at `rate_rpm_s` from 3,000 to 6,000 rpm: the live estimate of the unbalance (and
/// the viscosity) from the blocks the calibration keeps at its end.
fn run_up(rate_rpm_s: f64) {
    let twin = twin_rotor_with_raw_probes(RUNOUT_M);
    let plant = plant_rotor(&twin);
    let w6 = 6000.0 * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w6, 64);
    let settings = DriverSettings::new(
        ModelKind::Linear,
        FilmEvaluation::Direct,
        twin.rated_speed_rad_s,
    );
    let driver = Driver::new(twin.clone(), settings);
    let mark_rad = MARK_DEG.to_radians();
    let mut rig = Rig {
        plant: Twin::new(&plant, config, 3000.0 * PI / 30.0).unwrap(),
        blocks: OneXBlocks::new(driver.probe_axes()),
        driver,
        calibration: LiveCalibration::default(),
        noise: Normal::new(0.0, 0.3e-6).unwrap(),
        rng: rand_chacha::ChaCha8Rng::seed_from_u64(12),
        next_speed_ns: 0,
        mark_rad,
        revolutions: (-mark_rad / TAU).floor() as i64,
        refused: Vec::new(),
        block_count: 0,
    };
    rig.ramp(3000.0, 3000.0, 8.0 * 60.0 / 3000.0, false);
    let started = std::time::Instant::now();
    rig.ramp(3000.0, 6000.0, 3000.0 / rate_rpm_s, true);
    let measured = rig.calibration.measurements();
    let e = estimate(&twin, &measured, rig.driver.calibration_refinement());
    let c = rig.driver.counts();
    println!(
        "run-up at {rate_rpm_s} rpm/s: {:.1} s of wall time; {} blocks, {} 1X vectors and {} mean positions kept ({} whirl blocks); refused {:?}; speed mismatches {}, relocks {}",
        started.elapsed().as_secs_f64(),
        rig.block_count,
        measured.0.len(),
        measured.1.len(),
        rig.calibration.whirl_blocks,
        rig.refused,
        c.speed_mismatches,
        c.relocks
    );
    let v = e.viscosity.as_ref().unwrap();
    let u = e.unbalance.as_ref().unwrap();
    println!(
        "viscosity × {:.4} ± {:.4}; unbalance {:?}; condition {:.2}, relative 1X residual {:.4} (rms {:.3} µm), speeds {:.0?} rpm",
        v.scale,
        v.scale_std,
        u.planes,
        u.condition_number,
        u.relative_residual,
        u.residual_rms_m * 1e6,
        u.speeds_rpm
    );
    let p = u.planes[1];
    assert!((p.magnitude_g_mm / 280.0 - 1.0).abs() < 0.10, "{p:?}");
    assert!(lag_gap(p.phase_deg, 120.0 + MARK_DEG).abs() < 10.0, "{p:?}");
    assert!(u.planes[0].magnitude_g_mm < 28.0, "{u:?}");
    assert!((v.scale / 1.10 - 1.0).abs() < 0.03, "{v:?}");
    assert_eq!(c.speed_mismatches, 0);
    assert_eq!(c.relocks, 0);
}

/// A 100 rpm/s run-up, 3,000 → 6,000 rpm in 30 s (560 blocks): the targets, the
/// unbalance within 10 % and 10° of the plant's (280 g·mm at 243° from the mark), the twin's
/// own plane under 10 % of it, the viscosity within 3 % of × 1.10; no speed mismatch, no relock
/// (the keyphasor and the speed topic agree; the lock's drift check sees no trend in a ramp).
/// Measured (session 15): 282.6 g·mm at 239.1° (+0.9 %, −3.9°), stage 4 19.2 g·mm,
/// × 1.1028 ± 0.0058, condition 7.25, relative 1X residual 6.9 % (0.44 µm rms), 32 speeds a
/// station spread over 3,007–5,989 rpm. Before session 15 the live calibration kept the last 64
/// speed bins, 5,680–5,990 rpm, and read 324 g·mm at 233° (+16 %, −10°), stage 4 39 g·mm,
/// × 1.088: this fails there. 61 s of wall time on the loaded machine (load ≈ 12 on 2 cores).
#[test]
fn the_unbalance_from_a_100_rpm_s_run_up() {
    run_up(100.0);
}

/// Study (ignored): the run-up at RUNUP12_RATE rpm/s (default 1,000: 54 blocks, no bin dropped;
/// 284 g·mm at 239°, × 1.103, condition 7.2, relative residual 7.1 %).
#[test]
#[ignore]
fn run_up_at_a_given_rate() {
    let rate = std::env::var("RUNUP12_RATE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1000.0);
    run_up(rate);
}
