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
use crate::topics::{KEYPHASOR, PROBE, PROBE_SIGNAL, SPEED, UNBALANCE};
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
    /// Plant signals (issue 12): keyphasor, raw probes and their runout.
    pub signals: PlantSignals,
}

// --- plant signals (issue 12) ---

/// What the plant delivers besides the speed: a keyphasor at an arbitrary shaft angle, and raw
/// proximity-probe readings with runout instead of machine-frame probe pairs.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlantSignals {
    /// The plant's shaft angle (deg) at which its reference mark passes the keyphasor probe;
    /// None: no keyphasor topic. The unbalance is then published with its heavy-spot angle
    /// measured from the mark (what a balancer reads), φ + θ_k.
    pub keyphasor_angle_deg: Option<f64>,
    /// Raw probe readings (ProbeSignal, in V at [`RAW_SENSITIVITY_V_PER_M`], DC-coupled, gap
    /// [`RAW_REFERENCE_GAP_M`] at the centre) along each station's two probe axes, named
    /// `<station>_x` (first angle) and `<station>_y` (second), instead of ProbeDisplacement pairs.
    pub raw_probes: bool,
    /// Slow-roll runout of each raw probe (m, zero to peak): a 1X pattern of the shaft surface
    /// whose high spot is [`RUNOUT_HIGH_SPOT_DEG`] from the mark, so the probe at angle α reads
    /// it with the lag α − 30°.
    pub runout_m: f64,
    /// Write no speed topic (a rig with only the keyphasor: the speed is the keyphasor's).
    pub no_speed_topic: bool,
    /// The raw probes are AC-coupled: their readings carry no DC gap (the reference gap and
    /// the journal's static position taken out by a high pass, [`RAW_AC_TIME_CONSTANT_S`]),
    /// only the motion about it.
    pub ac_coupled: bool,
    /// Relative error of the speed topic: it reports (1 + e) times the shaft's speed and
    /// acceleration (a tachometer's scale, a wrong pulses-per-turn count; 0: true). The
    /// keyphasor, the probes and the plant itself keep the true speed.
    pub speed_topic_error: f64,
}

/// Time constant of the plant's AC coupling (s): 0.1, a first-order high pass (an exponential
/// mean of the displacement, taken out) with its corner at 1.6 Hz; at 1X of 8,000 rpm (133 Hz)
/// it leads the phase by 0.7° and leaves the amplitude within 0.01 %.
pub const RAW_AC_TIME_CONSTANT_S: f64 = 0.1;

/// Sensitivity of the plant's raw probes (V/m): 7.87 V/mm.
pub const RAW_SENSITIVITY_V_PER_M: f64 = 7870.0;
/// Gap of the plant's raw probes with the shaft centred (m): 1.0 mm (7.87 V, mid-range).
pub const RAW_REFERENCE_GAP_M: f64 = 1.0e-3;
/// Angle of the runout's high spot from the keyphasor mark (deg).
pub const RUNOUT_HIGH_SPOT_DEG: f64 = 30.0;

/// The plant's runout vector seen by a probe at `angle_rad`: `runout_m` at lag α − 30°.
pub fn plant_runout(runout_m: f64, angle_rad: f64) -> crate::signals::OneXVector {
    crate::signals::OneXVector {
        amplitude_m: runout_m,
        phase_lag_deg: (angle_rad.to_degrees() - RUNOUT_HIGH_SPOT_DEG).rem_euclid(360.0),
    }
}

/// The plant's true 1X vectors over the last [`TRUTH_REVS`] revolutions: at each probe station,
/// along its two probe axes, from its own (noise- and runout-free) orbit against its own shaft
/// angle counted from the keyphasor mark.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlantTruth {
    /// Per station (machine order): the two axes' 1X vectors; None without a keyphasor.
    pub one_x_probe_axes: Vec<Option<[crate::signals::OneXVector; 2]>>,
}

/// Revolutions at the end of the run over which the truth is computed: 32 (the replay's
/// summary window).
pub const TRUTH_REVS: usize = 32;

/// Samples of the plant's own orbit for the truth: per station, (ψ from the mark, d along axis
/// 0, d along axis 1).
#[derive(Debug, Default)]
struct TruthSamples {
    stations: Vec<Vec<(f64, [f64; 2])>>,
}

impl TruthSamples {
    fn truth(&self, keyphasor: bool) -> PlantTruth {
        let vector = |v: &Vec<(f64, [f64; 2])>, j: usize| {
            crate::signals::one_x_vector(v.iter().map(|(psi, d)| (*psi, d[j])), v.len())
                .unwrap_or_default()
        };
        PlantTruth {
            one_x_probe_axes: self
                .stations
                .iter()
                .map(|v| keyphasor.then(|| [vector(v, 0), vector(v, 1)]))
                .collect(),
        }
    }
}
// --- end plant signals ---

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

/// What [`write_bag`] wrote: the bag directory, the messages per topic, the plant's truth.
pub type WrittenBag = (PathBuf, Vec<(String, u64)>, PlantTruth);

/// Runs the plant of `rotor` through `spec` and writes the bag to `out`; `progress` gets the
/// plant time (s) now and then. Returns the bag directory, the messages per topic and the
/// plant's true 1X vectors (issue 12).
pub fn write_bag(
    rotor: &Rotor,
    spec: &PlantSpec,
    out: &Path,
    progress: &mut dyn FnMut(f64),
) -> Result<WrittenBag, PlantError> {
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
    bag.write_unbalance(&plant, spec)?;
    let noise = Normal::new(0.0, spec.noise_m).map_err(|_| PlantError::Noise(spec.noise_m))?;
    let mut sampler = Sampler {
        noise,
        rng: rand_chacha::ChaCha8Rng::seed_from_u64(spec.seed),
        next_speed: 0.0,
        next_probe: 0.0,
        truth_from_s: spec.profile.duration_s()
            - TRUTH_REVS as f64 * TAU / spec.profile.speed_rad_s(spec.profile.duration_s()),
        truth: TruthSamples {
            stations: vec![Vec::new(); plant.probes.len()],
        },
        ac_mean: vec![[None; 2]; plant.probes.len()],
    };
    let mut last_progress = std::time::Instant::now();
    let profile = spec.profile;
    while session.twin().time_s() < profile.duration_s() {
        sampler.write_due(&mut bag, &session, &plant, spec)?;
        let (now, a0) = (session.twin().time_s(), session.twin().output().angle_rad);
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
        let o = session.twin().output();
        bag.write_keyphasor_crossing(spec, (now, a0), (o.time_s, o.angle_rad))?;
        if last_progress.elapsed().as_secs() >= 5 {
            last_progress = std::time::Instant::now();
            progress(session.twin().time_s());
        }
    }
    let counts = bag.rec.counts();
    let truth = sampler
        .truth
        .truth(spec.signals.keyphasor_angle_deg.is_some());
    Ok((bag.rec.finish()?, counts, truth))
}

/// When the next speed message and probe sample are due, the noise, and the truth gathered.
struct Sampler {
    noise: Normal<f64>,
    rng: rand_chacha::ChaCha8Rng,
    next_speed: f64,
    next_probe: f64,
    truth_from_s: f64,
    truth: TruthSamples,
    /// AC coupling: per raw probe, the exponential mean of its displacement and its time (m, s)
    ac_mean: Vec<[Option<(f64, f64)>; 2]>,
}

impl Sampler {
    /// Speed messages at 100 Hz and probe samples every 1/samples_per_rev revolution up to the
    /// plant's present time, each at its own time, from the plant's state interpolated within
    /// the step just taken.
    fn write_due(
        &mut self,
        bag: &mut PlantBag,
        session: &Session,
        plant: &Rotor,
        spec: &PlantSpec,
    ) -> Result<(), RecordError> {
        let now = session.twin().time_s();
        while self.next_speed <= now {
            bag.write_speed(self.next_speed, &spec.profile)?;
            self.next_speed += 1.0 / SPEED_RATE_HZ;
        }
        while self.next_probe <= now {
            let t = self.next_probe;
            for (k, station) in plant.probes.iter().enumerate() {
                if let Some(([x, y], angle)) = session.predicted_probe(k, t) {
                    self.sample_station(bag, spec, station, k, t, [x, y], angle)?;
                }
            }
            self.next_probe += TAU / spec.profile.speed_rad_s(t) / spec.samples_per_rev as f64;
        }
        Ok(())
    }

    /// One sample of station `k` at plant time `t` (s): the pair, or the two raw readings
    /// with runout and noise; the clean axis displacements go to the truth.
    #[allow(clippy::too_many_arguments)]
    fn sample_station(
        &mut self,
        bag: &mut PlantBag,
        spec: &PlantSpec,
        station: &crate::rotor::ProbeStation,
        k: usize,
        t: f64,
        xy: [f64; 2],
        angle_rad: f64,
    ) -> Result<(), RecordError> {
        let sig = spec.signals;
        let psi = angle_rad - sig.keyphasor_angle_deg.unwrap_or(0.0).to_radians();
        let clean = station
            .angles_rad
            .map(|a| xy[0] * a.cos() + xy[1] * a.sin());
        if t >= self.truth_from_s {
            self.truth.stations[k].push((psi, clean));
        }
        if !sig.raw_probes {
            let noisy = [
                xy[0] + self.noise.sample(&mut self.rng),
                xy[1] + self.noise.sample(&mut self.rng),
            ];
            return bag.write_probe(t, &station.name, noisy);
        }
        for (j, suffix) in ["x", "y"].iter().enumerate() {
            let runout = crate::signals::probes::runout_at(
                &plant_runout(sig.runout_m, station.angles_rad[j]),
                psi,
            );
            let d = clean[j] + runout + self.noise.sample(&mut self.rng);
            let volts = match sig.ac_coupled {
                false => RAW_SENSITIVITY_V_PER_M * (RAW_REFERENCE_GAP_M - d),
                true => -RAW_SENSITIVITY_V_PER_M * (d - self.ac_mean(k, j, t, d)),
            };
            bag.write_probe_signal(t, &format!("{}_{suffix}", station.name), volts)?;
        }
        Ok(())
    }
}

impl Sampler {
    /// The AC coupling's mean of raw probe `j` of station `k` after displacement `d` (m) at
    /// `t` (s): a first-order high pass ([`RAW_AC_TIME_CONSTANT_S`]) started at the first one.
    fn ac_mean(&mut self, k: usize, j: usize, t: f64, d: f64) -> f64 {
        let slot = &mut self.ac_mean[k][j];
        let mean = slot.map_or(d, |(m, t0)| {
            m + (d - m) * (1.0 - (-(t - t0) / RAW_AC_TIME_CONSTANT_S).exp())
        });
        *slot = Some((mean, t));
        mean
    }
}

/// The bag being written: the recorder and its topics.
struct PlantBag {
    rec: Recorder,
    /// the speed topic (absent when the rig has only the keyphasor)
    speed: Option<usize>,
    unbalance: usize,
    /// probe pairs (absent with raw probes)
    probe: Option<usize>,
    /// keyphasor and raw probe signals (issue 12)
    keyphasor: Option<usize>,
    probe_signal: Option<usize>,
    /// what the speed topic reports over the true speed: 1 + `speed_topic_error`
    speed_topic_factor: f64,
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
        let sig = spec.signals;
        rec.set_custom_data(
            "plant_signals",
            &format!(
                "keyphasor {}; speed topic {}; probes {}",
                sig.keyphasor_angle_deg
                    .map_or("none".into(), |a| format!("at plant shaft angle {a}° (unbalance phases published from the mark)")),
                if sig.no_speed_topic { "none (the speed is the keyphasor's)".into() } else if sig.speed_topic_error != 0.0 { format!("/rotor_twin/speed, off by {:+} %", sig.speed_topic_error * 100.0) } else { "/rotor_twin/speed".to_string() },
                if sig.raw_probes && sig.ac_coupled {
                    format!("raw (ProbeSignal in V, {RAW_SENSITIVITY_V_PER_M} V/m, AC: high pass of {RAW_AC_TIME_CONSTANT_S} s; runout {:.2} µm, high spot {RUNOUT_HIGH_SPOT_DEG}° from the mark)", sig.runout_m * 1e6)
                } else if sig.raw_probes {
                    format!("raw (ProbeSignal in V, {RAW_SENSITIVITY_V_PER_M} V/m, DC, gap {} mm at the centre; runout {:.2} µm, high spot {RUNOUT_HIGH_SPOT_DEG}° from the mark)", RAW_REFERENCE_GAP_M * 1e3, sig.runout_m * 1e6)
                } else {
                    "pairs (ProbeDisplacement, m)".into()
                }
            ),
        );
        // as a rig publishes: the speed and the unbalance reliable, the probes and keyphasor
        // best effort
        let sensor = TopicQos::sensor(1000);
        Ok(Self {
            speed: match sig.no_speed_topic {
                false => {
                    Some(rec.add_topic::<messages::RotorSpeed>(SPEED, TopicQos::reliable(100))?)
                }
                true => None,
            },
            unbalance: rec.add_topic::<messages::Unbalance>(UNBALANCE, TopicQos::reliable(10))?,
            probe: match sig.raw_probes {
                false => Some(rec.add_topic::<messages::ProbeDisplacement>(PROBE, sensor)?),
                true => None,
            },
            keyphasor: match sig.keyphasor_angle_deg {
                Some(_) => Some(rec.add_topic::<messages::Keyphasor>(KEYPHASOR, sensor)?),
                None => None,
            },
            probe_signal: match sig.raw_probes {
                true => Some(rec.add_topic::<messages::ProbeSignal>(PROBE_SIGNAL, sensor)?),
                false => None,
            },
            rec,
            speed_topic_factor: 1.0 + sig.speed_topic_error,
        })
    }

    /// A keyphasor event if the plant's angle passed the mark θ_k (mod 2π) within the step
    /// from (t0, a0) to (t1, a1) (s, rad), at the instant interpolated within the step.
    fn write_keyphasor_crossing(
        &mut self,
        spec: &PlantSpec,
        (t0, a0): (f64, f64),
        (t1, a1): (f64, f64),
    ) -> Result<(), RecordError> {
        let (Some(h), Some(mark_deg)) = (self.keyphasor, spec.signals.keyphasor_angle_deg) else {
            return Ok(());
        };
        let mark = mark_deg.to_radians();
        let target = mark + TAU * ((a1 - mark) / TAU).floor();
        // the first step also takes an event exactly at its start (a mark at angle 0)
        let at_start = t0 == 0.0 && (target - a0).abs() < 1e-12;
        if (target <= a0 && !at_start) || a1 <= a0 {
            return Ok(());
        }
        let t = t0 + (target - a0) / (a1 - a0) * (t1 - t0);
        let ns = stamp(t);
        let m = messages::Keyphasor {
            header: header(ns, "keyphasor"),
            revolution: (target / TAU).floor().max(0.0) as u32,
        };
        self.rec.write(h, &m, ns as u64, ns as u64)
    }

    fn write_probe_signal(&mut self, t: f64, probe: &str, value: f64) -> Result<(), RecordError> {
        let Some(h) = self.probe_signal else {
            return Ok(());
        };
        let ns = stamp(t);
        let m = messages::ProbeSignal {
            header: header(ns, probe),
            probe: probe.into(),
            value,
        };
        self.rec.write(h, &m, ns as u64, ns as u64)
    }

    /// The unbalance as the machine description gives it, once at the start; with a
    /// keyphasor, its heavy-spot angle from the mark (φ + θ_k).
    fn write_unbalance(&mut self, plant: &Rotor, spec: &PlantSpec) -> Result<(), RecordError> {
        let mark = spec.signals.keyphasor_angle_deg.unwrap_or(0.0).to_radians();
        for (plane, u) in plant.unbalance.iter().enumerate() {
            let m = messages::Unbalance {
                header: header(EPOCH_NS, "rotor"),
                plane: plane as u32,
                magnitude: u.magnitude_kg_m,
                phase: crate::signals::keyphasor::wrap_pi(u.phase_rad + mark),
            };
            self.rec
                .write(self.unbalance, &m, EPOCH_NS as u64, EPOCH_NS as u64)?;
        }
        Ok(())
    }

    fn write_speed(&mut self, t: f64, profile: &SpeedProfile) -> Result<(), RecordError> {
        let Some(h) = self.speed else {
            return Ok(());
        };
        let ns = stamp(t);
        let m = messages::RotorSpeed {
            header: header(ns, "rotor"),
            speed: profile.speed_rad_s(t) * self.speed_topic_factor,
            acceleration: profile.accel_rad_s2(t) * self.speed_topic_factor,
        };
        self.rec.write(h, &m, ns as u64, ns as u64)
    }

    fn write_probe(&mut self, t: f64, station: &str, xy: [f64; 2]) -> Result<(), RecordError> {
        let Some(h) = self.probe else {
            return Ok(());
        };
        let ns = stamp(t);
        let m = messages::ProbeDisplacement {
            header: header(ns, station),
            station: station.into(),
            x: xy[0],
            y: xy[1],
        };
        self.rec.write(h, &m, ns as u64, ns as u64)
    }
}
