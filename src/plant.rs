//! A SYNTHETIC plant for trying the replay: the machine with a finer film grid and another
//! lubricant viscosity (a model that is not the twin), run through a speed profile with the
//! nonlinear film; its probe displacements, with Gaussian noise, are recorded as a rig would
//! record them, with the speed and the unbalance. The bag says in its metadata that it is
//! synthetic and how it was made.

use crate::dynamics::{Coupling, FilmEvaluation, StepInput, TwinConfig};
use crate::messages::{self, Header, Time};
use crate::record::{RecordError, Recorder, TopicQos};
use crate::rotor::{BearingModel, Rotor};
use crate::session::{Session, SessionSettings};
use crate::topics::{PROBE, SPEED, UNBALANCE};
use crate::units::rpm_to_rad_s;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The bag's time zero: 2026-01-01T00:00:00Z (ns since the epoch), fixed so the bag is
/// reproducible.
pub const EPOCH_NS: i64 = 1_767_225_600_000_000_000;

/// Speed messages per second in the bag (Hz).
pub const SPEED_RATE_HZ: f64 = 100.0;

/// Time steps a revolution of the plant at rated speed: 128, the seed summary's converged
/// figure (orbit amplitudes within 0.2 % of 512).
pub const PLANT_STEPS_PER_REV: usize = 128;

/// A speed profile: hold, linear ramp, hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedProfile {
    /// Speed at the start (rpm).
    pub from_rpm: f64,
    /// Speed at the end of the ramp (rpm).
    pub to_rpm: f64,
    /// Seconds at the start speed.
    pub hold_start_s: f64,
    /// Seconds of the ramp.
    pub ramp_s: f64,
    /// Seconds at the end speed.
    pub hold_end_s: f64,
}

impl SpeedProfile {
    /// Speed (rad/s) at time `t` (s).
    pub fn speed_rad_s(&self, t: f64) -> f64 {
        let rpm = if t <= self.hold_start_s {
            self.from_rpm
        } else if t <= self.hold_start_s + self.ramp_s {
            self.from_rpm + (self.to_rpm - self.from_rpm) * (t - self.hold_start_s) / self.ramp_s
        } else {
            self.to_rpm
        };
        rpm_to_rad_s(rpm)
    }

    /// Angular acceleration (rad/s²) at time `t` (s).
    pub fn accel_rad_s2(&self, t: f64) -> f64 {
        let ramping = t > self.hold_start_s && t <= self.hold_start_s + self.ramp_s;
        if ramping && self.ramp_s > 0.0 {
            rpm_to_rad_s(self.to_rpm - self.from_rpm) / self.ramp_s
        } else {
            0.0
        }
    }

    /// Length of the profile (s).
    pub fn duration_s(&self) -> f64 {
        self.hold_start_s + self.ramp_s + self.hold_end_s
    }
}

/// How the plant differs from the machine description, and how it is sampled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantSpec {
    /// The speed profile.
    pub profile: SpeedProfile,
    /// Probe samples per revolution.
    pub samples_per_rev: usize,
    /// Standard deviation of the probe noise (m).
    pub noise_m: f64,
    /// The plant's lubricant viscosity over the machine description's.
    pub viscosity_factor: f64,
    /// The plant's film grid over the machine description's, in each direction.
    pub grid_factor: f64,
    /// The plant's film evaluation.
    pub film: FilmEvaluation,
    /// Seed of the noise.
    pub seed: u64,
}

/// Why a synthetic bag could not be written.
#[derive(Debug, Error)]
pub enum PlantError {
    /// The plant model failed to start or to step.
    #[error("the plant model failed at t = {time_s:.4} s: {source}")]
    Model {
        /// Plant time (s).
        time_s: f64,
        /// The twin core's error.
        source: crate::dynamics::TwinError,
    },
    /// The bag could not be written.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// The noise level is not a standard deviation.
    #[error("probe noise {0} m is not a standard deviation")]
    Noise(f64),
}

/// The plant: `rotor` with the spec's film grid and viscosity.
pub fn plant_of(rotor: &Rotor, spec: &PlantSpec) -> Rotor {
    let mut plant = rotor.clone();
    for b in &mut plant.bearings {
        if let BearingModel::Film(f) = &mut b.model {
            f.grid.n_theta = (f.grid.n_theta as f64 * spec.grid_factor).round() as usize;
            f.grid.n_z = (f.grid.n_z as f64 * spec.grid_factor).round() as usize;
            f.lubricant.viscosity_pa_s *= spec.viscosity_factor;
        }
    }
    plant
}

/// Runs the plant of `rotor` through `spec` and writes the bag to `out`; `progress` gets the
/// plant time (s) now and then. Returns the bag directory and the messages per topic.
pub fn write_bag(
    rotor: &Rotor,
    spec: &PlantSpec,
    out: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<(PathBuf, Vec<(String, u64)>), PlantError> {
    let plant = plant_of(rotor, spec);
    let config = TwinConfig {
        film: spec.film,
        ..TwinConfig::with_steps_per_rev(
            Coupling::Nonlinear,
            plant.rated_speed_rad_s,
            PLANT_STEPS_PER_REV,
        )
    };
    let w0 = spec.profile.speed_rad_s(0.0);
    let mut session = Session::new(&plant, config, w0, SessionSettings::default(), EPOCH_NS)
        .map_err(|source| PlantError::Model {
            time_s: 0.0,
            source,
        })?;
    let mut bag = PlantBag::create(out, rotor, spec)?;
    bag.write_unbalance(&plant)?;
    let noise = Normal::new(0.0, spec.noise_m).map_err(|_| PlantError::Noise(spec.noise_m))?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(spec.seed);
    let (mut next_speed, mut next_probe) = (0.0, 0.0);
    let mut last_progress = std::time::Instant::now();
    let profile = spec.profile;
    while session.twin().time_s() < profile.duration_s() {
        // speed messages at 100 Hz and probe samples every 1/samples_per_rev revolution, each at
        // its own time, from the plant's state interpolated within the step just taken
        let now = session.twin().time_s();
        while next_speed <= now {
            bag.write_speed(next_speed, &profile)?;
            next_speed += 1.0 / SPEED_RATE_HZ;
        }
        while next_probe <= now {
            for (k, station) in plant.probes.iter().enumerate() {
                if let Some(([x, y], _)) = session.predicted_probe(k, next_probe) {
                    let noisy = [x + noise.sample(&mut rng), y + noise.sample(&mut rng)];
                    bag.write_probe(next_probe, &station.name, noisy)?;
                }
            }
            next_probe += TAU / profile.speed_rad_s(next_probe) / spec.samples_per_rev as f64;
        }
        let t_mid = now + 0.5 * config.time_step_s;
        let input = StepInput {
            speed_rad_s: profile.speed_rad_s(t_mid),
            accel_rad_s2: profile.accel_rad_s2(t_mid),
        };
        session
            .step(&input, &mut |_| {})
            .map_err(|source| PlantError::Model {
                time_s: now,
                source,
            })?;
        if last_progress.elapsed().as_secs() >= 5 {
            last_progress = std::time::Instant::now();
            progress(session.twin().time_s());
        }
    }
    let counts = bag.rec.counts();
    Ok((bag.rec.finish()?, counts))
}

/// The bag being written: the recorder and its three topics.
struct PlantBag {
    rec: Recorder,
    speed: usize,
    unbalance: usize,
    probe: usize,
}

fn header(ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time::from_nanos(ns),
        frame_id: frame.into(),
    }
}

fn stamp(t: f64) -> i64 {
    EPOCH_NS + (t * 1e9).round() as i64
}

impl PlantBag {
    fn create(out: &Path, rotor: &Rotor, spec: &PlantSpec) -> Result<Self, RecordError> {
        let mut rec = Recorder::create(out)?;
        rec.set_custom_data("synthetic", "true");
        rec.set_custom_data(
            "made_by",
            &format!(
                "rotor-twin synth-bag {} (nonlinear film, {:?} evaluation, plant = machine '{}' with film grid ×{} and viscosity ×{}; {} samples/rev; noise {:.3} µm RMS; seed {})",
                env!("CARGO_PKG_VERSION"),
                spec.film,
                rotor.name,
                spec.grid_factor,
                spec.viscosity_factor,
                spec.samples_per_rev,
                spec.noise_m * 1e6,
                spec.seed
            ),
        );
        let p = &spec.profile;
        rec.set_custom_data(
            "speed_profile",
            &format!(
                "{} rpm for {} s, ramp to {} rpm over {} s, hold {} s",
                p.from_rpm, p.hold_start_s, p.to_rpm, p.ramp_s, p.hold_end_s
            ),
        );
        // as a rig publishes: the speed and the unbalance reliable, the probes best effort
        Ok(Self {
            speed: rec.add_topic::<messages::RotorSpeed>(SPEED, TopicQos::reliable(100))?,
            unbalance: rec.add_topic::<messages::Unbalance>(UNBALANCE, TopicQos::reliable(10))?,
            probe: rec.add_topic::<messages::ProbeDisplacement>(PROBE, TopicQos::sensor(1000))?,
            rec,
        })
    }

    /// The unbalance as the machine description gives it, once at the start.
    fn write_unbalance(&mut self, plant: &Rotor) -> Result<(), RecordError> {
        for (plane, u) in plant.unbalance.iter().enumerate() {
            let m = messages::Unbalance {
                header: header(EPOCH_NS, "rotor"),
                plane: plane as u32,
                magnitude: u.magnitude_kg_m,
                phase: u.phase_rad,
            };
            self.rec
                .write(self.unbalance, &m, EPOCH_NS as u64, EPOCH_NS as u64)?;
        }
        Ok(())
    }

    fn write_speed(&mut self, t: f64, profile: &SpeedProfile) -> Result<(), RecordError> {
        let ns = stamp(t);
        let m = messages::RotorSpeed {
            header: header(ns, "rotor"),
            speed: profile.speed_rad_s(t),
            acceleration: profile.accel_rad_s2(t),
        };
        self.rec.write(self.speed, &m, ns as u64, ns as u64)
    }

    fn write_probe(&mut self, t: f64, station: &str, xy: [f64; 2]) -> Result<(), RecordError> {
        let ns = stamp(t);
        let m = messages::ProbeDisplacement {
            header: header(ns, station),
            station: station.into(),
            x: xy[0],
            y: xy[1],
        };
        self.rec.write(self.probe, &m, ns as u64, ns as u64)
    }
}
