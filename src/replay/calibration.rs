//! `replay --calibrate` (issue 12): the bag's probe samples with the shaft angle, fitted to the
//! twin's viscosity and unbalance ([`crate::calibrate`]), and the twin of the machine with the
//! fitted values.
//!
//! The shaft angle is integrated from the speed messages (rotor_twin_msgs/RotorSpeed, with their
//! acceleration: exact on a linear ramp) from zero at the bag's first speed message; where the
//! bag has no speed topic (a rig with only the once-per-revolution mark), from the keyphasor's
//! intervals ([`MAX_KEYPHASOR_SPEED_STEP`]). At each keyphasor event (rotor_twin_msgs/Keyphasor,
//! or std_msgs/Header, on the keyphasor topic) it is set to the nearest whole revolution, so
//! that angle 0 is the shaft's reference mark and the 1X vectors are phase lags in the API 670
//! sense, like the replay's; the fitted unbalance phase is then measured from the mark, as the
//! twin reads `Unbalance.phase` with a keyphasor. Without a keyphasor the phase would be
//! relative to the start: it is reported null with the reason, the amplitude still given.
//! Raw probes' runout: the machine file's, else measured in the bag at slow roll (below the
//! machine file's `slow_roll_speed_rpm`), as the driver does; AC-coupled probes give no mean
//! position, so the unbalance alone is fitted.

use crate::bag::Bag;
use crate::calibrate::{
    estimate_viscosity_and_unbalance, AngleSample, CalibrationError, MeanPosition,
    NonlinearRefinement, OneXVector, UnbalanceEstimate, ViscosityEstimate, WindowFits,
    DEFAULT_CORRECTION_RADIUS_M,
};
use crate::driver::PAIR_TOLERANCE_REVS;
use crate::messages::{self, from_cdr, RosMessage};
use crate::rotor::Rotor;
use crate::signals::probes::{
    check_reading, machine_from_probes, runout_at, ProbeCoupling, SlowRoll,
};
use serde::Serialize;
use std::f64::consts::TAU;

/// Revolutions a fit window spans.
pub const CALIBRATION_WINDOW_REVS: f64 = 16.0;

pub use crate::calibrate::MAX_WINDOW_RESIDUAL_SHARE;

/// What `--calibrate` found. Serialized with the unbalance phases (and the correction
/// angles) null when `phase_null_reason` says why.
#[derive(Debug, Clone)]
pub struct BagCalibration {
    /// The bag time the fit used (s since the bag's first message).
    pub window_s: [f64; 2],
    /// Fit windows used (all stations), and left out for non-synchronous motion.
    pub windows_used: usize,
    /// Windows left out.
    pub windows_skipped: usize,
    /// No speed topic: the speed came from the keyphasor's intervals.
    pub speed_from_keyphasor: bool,
    /// Keyphasor intervals refused as a missed or extra pulse.
    pub keyphasor_intervals_refused: usize,
    /// The viscosity estimate; None when not fitted (`viscosity_not_fitted` says why).
    pub viscosity: Option<ViscosityEstimate>,
    /// Why the viscosity was not fitted.
    pub viscosity_not_fitted: Option<String>,
    /// The unbalance estimate, at the fitted viscosity (or the machine file's). Its phases are
    /// from the keyphasor's mark, or from the bag's start without one (then null in the JSON).
    pub unbalance: UnbalanceEstimate,
    /// Why the unbalance phases are null (no keyphasor); None when they are from the mark.
    pub phase_null_reason: Option<String>,
    /// Each raw probe's runout: the machine file's, measured at slow roll, or none.
    pub runouts: Vec<RunoutUse>,
}

impl Serialize for BagCalibration {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeStruct};
        let mut unbalance = serde_json::to_value(&self.unbalance).map_err(S::Error::custom)?;
        if self.phase_null_reason.is_some() {
            let planes = unbalance.get_mut("planes").and_then(|p| p.as_array_mut());
            for p in planes.into_iter().flatten() {
                p["phase_deg"] = serde_json::Value::Null;
                p["correction"]["angle_deg"] = serde_json::Value::Null;
            }
        }
        let mut s = serializer.serialize_struct("BagCalibration", 10)?;
        s.serialize_field("window_s", &self.window_s)?;
        s.serialize_field("windows_used", &self.windows_used)?;
        s.serialize_field("windows_skipped", &self.windows_skipped)?;
        s.serialize_field("speed_from_keyphasor", &self.speed_from_keyphasor)?;
        s.serialize_field(
            "keyphasor_intervals_refused",
            &self.keyphasor_intervals_refused,
        )?;
        s.serialize_field("viscosity", &self.viscosity)?;
        s.serialize_field("viscosity_not_fitted", &self.viscosity_not_fitted)?;
        s.serialize_field("unbalance", &unbalance)?;
        s.serialize_field("phase_null_reason", &self.phase_null_reason)?;
        s.serialize_field("runouts", &self.runouts)?;
        s.end()
    }
}

/// The probe samples of each station of `rotor` between `window_s` (s since the bag's first
/// message), with the shaft angle and speed; `remaps` and `probe_signals` (std_msgs/Float64
/// topics → raw probe names) as the replay's.
pub fn angle_samples(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    probe_signals: &[(String, String)],
    window_s: [f64; 2],
) -> Vec<Vec<AngleSample>> {
    let mut out = vec![Vec::new(); rotor.probes.len()];
    each_angle_sample(bag, rotor, remaps, probe_signals, window_s, &mut |k, s| {
        out[k].push(s)
    });
    out
}

/// How the runout of one raw probe was taken (`calibration.json`'s `runouts`).
#[derive(Debug, Clone, Serialize)]
pub struct RunoutUse {
    /// The raw probe (the machine file's name).
    pub probe: String,
    /// "machine file", "measured at slow roll" (in this bag, below the machine file's
    /// `slow_roll_speed_rpm`), or "none: " and why.
    pub source: String,
    /// The runout vector subtracted (amplitude m, phase lag deg from the keyphasor).
    pub vector: Option<crate::signals::OneXVector>,
    /// Bag time (s) of the slow-roll samples it was measured on, and their revolutions.
    pub slow_roll_s: Option<[f64; 2]>,
    /// Revolutions of slow roll measured.
    pub slow_roll_revolutions: Option<f64>,
}

/// What the samples of [`each_angle_sample`] were referenced to.
#[derive(Debug, Clone, Default)]
pub struct SampleReference {
    /// Keyphasor events set the angle's zero on the mark (the 1X phases are phase lags).
    pub keyphasor: bool,
    /// No speed topic spoke: the speed came from the keyphasor's intervals.
    pub speed_from_keyphasor: bool,
    /// Keyphasor intervals refused as a missed or extra pulse.
    pub keyphasor_refused: usize,
    /// Per raw probe of the machine file: its runout.
    pub runouts: Vec<RunoutUse>,
}

/// [`angle_samples`] one at a time, in bag order, as (station index, sample): nothing is held.
/// Probe pairs (`ProbeDisplacement`) are taken as they are; raw probe readings (`ProbeSignal`,
/// or a std_msgs/Float64 topic per probe by `probe_signals`) are turned into the displacement
/// along their probe's axis (unit, sensitivity, reference gap: the machine file's), their
/// runout vector subtracted once a keyphasor has set the angle's zero on the mark, and the two
/// probes of a station paired into a machine-frame point, as the driver does
/// ([`RawPairs`]). The shaft speed is the speed topic's, or the keyphasor's where no speed
/// topic speaks; with keyphasor events in the bag, no sample is taken before the first has set
/// the angle's zero. Below the machine file's `slow_roll_speed_rpm` (with a keyphasor) raw
/// readings measure each probe's runout and are not taken; the bag is read from its start for
/// that, whatever `window_s`.
pub fn each_angle_sample(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    probe_signals: &[(String, String)],
    window_s: [f64; 2],
    take: &mut dyn FnMut(usize, AngleSample),
) -> SampleReference {
    let name = |i: usize| {
        let n = &bag.topics[i].name;
        remaps
            .iter()
            .find(|(f, _)| f == n)
            .map_or(n.as_str(), |(_, t)| t.as_str())
    };
    let has_keyphasor = (0..bag.topics.len()).any(|i| {
        name(i) == crate::topics::KEYPHASOR
            && is_keyphasor_type(&bag.topics[i].type_name)
            && bag.topic_message_count(i) > 0
    });
    let t0 = bag.time_span_ns().map_or(0, |(a, _)| a);
    let mut angle = ShaftAngle::default();
    let mut raw = RawPairs::new(rotor);
    for m in bag.messages() {
        let t = m.log_time_ns.saturating_sub(t0) as f64 * 1e-9;
        let topic = name(m.topic);
        let type_name = bag.topics[m.topic].type_name.as_str();
        let payload = m.payload();
        if angle.take(topic, type_name, payload, t) || t > window_s[1] {
            continue;
        }
        let Some((a, w)) = angle.at(t).filter(|_| angle.locked || !has_keyphasor) else {
            continue;
        };
        let point = match probe_reading(rotor, probe_signals, topic, type_name, payload) {
            Some(Reading::Pair(k, xy)) => Some((k, xy)),
            Some(Reading::Raw(k, value)) => {
                raw.take(rotor, k, value, t, angle.locked.then_some(a), w)
            }
            None => None,
        };
        let point = point.filter(|(_, xy)| xy[0].is_finite() && xy[1].is_finite());
        if let Some((k, xy)) = point.filter(|_| t >= window_s[0]) {
            let sample = AngleSample {
                angle_rad: a,
                speed_rad_s: w,
                displacement_m: xy,
            };
            take(k, sample);
        }
    }
    SampleReference {
        keyphasor: angle.locked,
        speed_from_keyphasor: angle.from_keyphasor,
        keyphasor_refused: angle.refused,
        runouts: raw.runouts(rotor, angle.locked),
    }
}

/// Largest change of the keyphasor's speed from one interval to the next (share) taken as a
/// speed: 0.3. A missed pulse halves the speed, an extra one at least nearly doubles it in
/// one of its two intervals; a ramp changes it by a few per cent a revolution (7,000 rpm/s at
/// 8,000 rpm: 1 %).
pub const MAX_KEYPHASOR_SPEED_STEP: f64 = 0.3;

/// The shaft angle integrated from the speed messages, set to whole revolutions at each
/// keyphasor event; where no speed message comes, the speed from the keyphasor's intervals.
#[derive(Debug, Default)]
struct ShaftAngle {
    /// (time s, angle rad, speed rad/s, accel rad/s²) at the last speed message or event
    last: Option<(f64, f64, f64, f64)>,
    /// a keyphasor event has put the angle's zero on the mark
    locked: bool,
    /// a speed message has come: the keyphasor corrects the angle only
    speed_topic: bool,
    /// the last keyphasor event (s)
    last_event_s: Option<f64>,
    /// the last accepted interval: its midpoint (s) and mean speed (rad/s)
    interval: Option<(f64, f64)>,
    /// the speed in force came from the keyphasor
    from_keyphasor: bool,
    /// intervals refused (a missed or extra pulse)
    refused: usize,
}

impl ShaftAngle {
    /// The angle (rad) and speed (rad/s) at `t` (s), once a speed has come.
    fn at(&self, t: f64) -> Option<(f64, f64)> {
        self.last.map(|(t1, a1, w1, acc)| {
            let dt = t - t1;
            (a1 + w1 * dt + 0.5 * acc * dt * dt, w1 + acc * dt)
        })
    }

    /// Takes a speed message or a keyphasor event; false for any other message.
    fn take(&mut self, topic: &str, type_name: &str, payload: &[u8], t: f64) -> bool {
        if topic == crate::topics::SPEED && type_name == messages::RotorSpeed::TYPE_NAME {
            if let Ok(s) = from_cdr::<messages::RotorSpeed>(payload) {
                if s.speed.is_finite() && s.acceleration.is_finite() {
                    let angle = self.at(t).map_or(0.0, |(a, _)| a);
                    self.last = Some((t, angle, s.speed, s.acceleration));
                    self.speed_topic = true;
                    self.from_keyphasor = false;
                }
            }
            return true;
        }
        if topic == crate::topics::KEYPHASOR && is_keyphasor_type(type_name) {
            let accepted = self.speed_topic || self.keyphasor_speed(t);
            self.last_event_s = Some(t);
            // the reference mark passes: the angle is a whole number of revolutions
            if let (true, Some((.., acc)), Some((a, w))) = (accepted, self.last, self.at(t)) {
                self.last = Some((t, (a / TAU).round() * TAU, w, acc));
                self.locked = true;
            }
            return true;
        }
        false
    }

    /// Without a speed topic, the speed at the event at `t` (s) from the keyphasor: one
    /// revolution over the interval from the last event is the mean speed at the interval's
    /// midpoint, the acceleration is the change of that mean between two intervals over the
    /// time between their midpoints (both exact on a linear ramp), and the speed at `t` is the
    /// mean carried half an interval on. False if there is no speed yet or the interval is
    /// refused ([`MAX_KEYPHASOR_SPEED_STEP`]: the speed in force runs on).
    fn keyphasor_speed(&mut self, t: f64) -> bool {
        let Some(dt) = self.last_event_s.map(|t0| t - t0).filter(|dt| *dt > 0.0) else {
            return false;
        };
        let (tm, wm) = (t - 0.5 * dt, TAU / dt);
        if let Some((_, wp)) = self.interval {
            if (wm / wp - 1.0).abs() > MAX_KEYPHASOR_SPEED_STEP {
                self.refused += 1;
                return false;
            }
        }
        let acc = self
            .interval
            .map_or(0.0, |(tp, wp)| (wm - wp) / (tm - tp).max(1e-9))
            .clamp(
                -crate::driver::inputs::MAX_ACCEL_RAD_S2,
                crate::driver::inputs::MAX_ACCEL_RAD_S2,
            );
        self.interval = Some((tm, wm));
        // the angle so far (0 at the second event: the first speed)
        let angle = self.at(t).map_or(0.0, |(a, _)| a);
        self.last = Some((t, angle, wm + acc * (t - tm), acc));
        self.from_keyphasor = true;
        true
    }
}

/// A probe message: a machine-frame pair of station k (m), or raw probe k's reading.
enum Reading {
    Pair(usize, [f64; 2]),
    Raw(usize, f64),
}

/// The probe reading in a message on `topic`, if it is one.
fn probe_reading(
    rotor: &Rotor,
    probe_signals: &[(String, String)],
    topic: &str,
    type_name: &str,
    payload: &[u8],
) -> Option<Reading> {
    let raw_index = |name: &str| rotor.proximity_probes.iter().position(|p| p.name == name);
    if topic == crate::topics::PROBE && type_name == messages::ProbeDisplacement::TYPE_NAME {
        let p = from_cdr::<messages::ProbeDisplacement>(payload).ok()?;
        let k = rotor.probes.iter().position(|s| s.name == p.station)?;
        return Some(Reading::Pair(k, [p.x, p.y]));
    }
    if topic == crate::topics::PROBE_SIGNAL && type_name == messages::ProbeSignal::TYPE_NAME {
        let p = from_cdr::<messages::ProbeSignal>(payload).ok()?;
        return Some(Reading::Raw(raw_index(&p.probe)?, p.value));
    }
    let (_, probe) = probe_signals.iter().find(|(tp, _)| tp == topic)?;
    if type_name != messages::Float64::TYPE_NAME {
        return None;
    }
    let v = from_cdr::<messages::Float64>(payload).ok()?;
    Some(Reading::Raw(raw_index(probe)?, v.data))
}

/// Raw probe readings paired into machine-frame points (the driver's rule,
/// `driver::PAIR_TOLERANCE_REVS`): the last reading of each probe of each station; and each
/// raw probe's runout measured at slow roll (the driver's rule: below the machine file's
/// `slow_roll_speed_rpm`, with a keyphasor; a runout the machine file gives wins).
struct RawPairs {
    last: Vec<[Option<(f64, f64)>; 2]>,
    axes: Vec<[f64; 2]>,
    slow_roll: Vec<SlowRoll>,
    /// bag time (s) of the first and last slow-roll reading of each raw probe
    slow_roll_s: Vec<Option<[f64; 2]>>,
    measured: Vec<Option<crate::signals::OneXVector>>,
}

impl RawPairs {
    fn new(rotor: &Rotor) -> Self {
        let mut axes = vec![[0.0, std::f64::consts::FRAC_PI_2]; rotor.probes.len()];
        for p in &rotor.proximity_probes {
            if let Some(a) = axes.get_mut(p.station) {
                a[p.axis] = p.angle_rad;
            }
        }
        let n = rotor.proximity_probes.len();
        Self {
            last: vec![[None; 2]; rotor.probes.len()],
            axes,
            slow_roll: vec![SlowRoll::default(); n],
            slow_roll_s: vec![None; n],
            measured: vec![None; n],
        }
    }

    /// Raw probe `k`'s reading `value` at `t` (s), the shaft at `psi` (rad from the mark, None
    /// without a keyphasor: no runout subtracted) turning at `w` (rad/s): the station's point
    /// once both its probes have read within the pairing tolerance. A refused reading (out of
    /// range, saturated) is left out; so is a slow-roll reading, which measures the runout.
    fn take(
        &mut self,
        rotor: &Rotor,
        k: usize,
        value: f64,
        t: f64,
        psi: Option<f64>,
        w: f64,
    ) -> Option<(usize, [f64; 2])> {
        let p = rotor.proximity_probes.get(k)?;
        let mut d = check_reading(p, value).ok()?;
        if let (Some(limit), Some(psi)) = (rotor.slow_roll_speed_rad_s, psi) {
            if w > 0.0 && w < limit {
                self.slow_roll[k].add(psi, d);
                let span = self.slow_roll_s[k].get_or_insert([t, t]);
                span[1] = t;
                if let Some(v) = self.slow_roll[k].vector() {
                    self.measured[k] = Some(v);
                }
                return None;
            }
        }
        if let (Some(r), Some(psi)) = (p.runout.or(self.measured[k]), psi) {
            d -= runout_at(&r, psi);
        }
        let slot = self.last.get_mut(p.station)?;
        slot[p.axis] = Some((t, d));
        let (Some((t0, d0)), Some((t1, d1))) = (slot[0], slot[1]) else {
            return None;
        };
        if (t0 - t1).abs() > PAIR_TOLERANCE_REVS * TAU / w.max(1e-3) {
            return None;
        }
        *slot = [None, None];
        Some((
            p.station,
            machine_from_probes([d0, d1], self.axes[p.station]),
        ))
    }

    /// Each raw probe's runout as used (`locked`: a keyphasor referenced the angle).
    fn runouts(&self, rotor: &Rotor, locked: bool) -> Vec<RunoutUse> {
        rotor
            .proximity_probes
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let revs = self.slow_roll[k].revolutions();
                let (source, vector) = match (p.runout, self.measured[k]) {
                    (Some(r), _) => ("machine file".to_string(), Some(r)),
                    (None, Some(m)) => ("measured at slow roll".to_string(), Some(m)),
                    (None, None) if !locked => (
                        "none: no keyphasor (a runout vector needs the mark)".into(),
                        None,
                    ),
                    (None, None) if rotor.slow_roll_speed_rad_s.is_none() => (
                        "none: the machine file gives neither a runout nor slow_roll_speed_rpm"
                            .into(),
                        None,
                    ),
                    (None, None) => (
                        format!("none: {revs:.1} revolutions of slow roll in the bag (2 needed)"),
                        None,
                    ),
                };
                RunoutUse {
                    probe: p.name.clone(),
                    source,
                    vector,
                    slow_roll_s: self.slow_roll_s[k],
                    slow_roll_revolutions: self.slow_roll_s[k].map(|_| revs),
                }
            })
            .collect()
    }
}

/// A keyphasor event's type: ours, or a bare std_msgs/Header (the replay accepts both).
fn is_keyphasor_type(type_name: &str) -> bool {
    type_name == messages::Keyphasor::TYPE_NAME || type_name == messages::Header::TYPE_NAME
}

/// The measurements `--calibrate` fits ([`bag_measurements`]).
#[derive(Debug, Clone, Default)]
pub struct BagMeasurements {
    /// Mean positions (DC-coupled stations).
    pub means: Vec<MeanPosition>,
    /// 1X vectors (phase lags from the mark with a keyphasor, else from the bag's start).
    pub vectors: Vec<OneXVector>,
    /// Windows left out (never completed, or non-synchronous motion).
    pub skipped: usize,
    /// What the samples were referenced to, and the runouts.
    pub reference: SampleReference,
}

/// The measurements `--calibrate` fits, from the bag's samples in `window_s`: the mean
/// positions (DC-coupled stations), the 1X vectors, and the windows left out (never
/// completed, or non-synchronous motion).
pub fn bag_measurements(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    probe_signals: &[(String, String)],
    window_s: [f64; 2],
) -> BagMeasurements {
    // the windows are fitted as the samples arrive: memory is bounded by one window a station
    // (issue 15), not by the length of `window_s`
    let mut fits = vec![WindowFits::new(CALIBRATION_WINDOW_REVS); rotor.probes.len()];
    let reference = each_angle_sample(bag, rotor, remaps, probe_signals, window_s, &mut |k, s| {
        fits[k].push(s)
    });
    let mut m = BagMeasurements {
        reference,
        ..BagMeasurements::default()
    };
    for (station, f) in fits.into_iter().enumerate() {
        // a window that never completed its revolutions (a shaft all but stopped) is left out
        m.skipped += f.overlong_windows;
        for w in f.finish() {
            if w.residual_rms_m > MAX_WINDOW_RESIDUAL_SHARE * w.one_x_major_m() {
                m.skipped += 1;
                continue;
            }
            // an AC-coupled station's mean is no position (its raw probes' DC gap is not kept)
            if !station_is_ac(rotor, station) {
                m.means.push(w.mean_position(station));
            }
            m.vectors.extend(w.one_x(station));
        }
    }
    m
}

/// True if a raw probe of probe station `k` is AC-coupled.
fn station_is_ac(rotor: &Rotor, k: usize) -> bool {
    rotor
        .proximity_probes
        .iter()
        .any(|p| p.station == k && p.coupling == ProbeCoupling::Ac)
}

/// Why the viscosity is not fitted when every probe station is AC-coupled.
pub const VISCOSITY_NOT_FITTED_AC: &str =
    "not fitted: no mean positions (AC-coupled): the machine file's viscosity (or the oil temperature's) kept";

/// Why the phases are null without a keyphasor.
pub const PHASE_NULL_NO_KEYPHASOR: &str = "no keyphasor in the bag: a phase would be relative to an arbitrary start (the bag's first speed message), not to the shaft's mark";

/// Fits the viscosity, then the unbalance at that viscosity, to the bag's samples in
/// `window_s` ([`bag_measurements`]) as the live calibration does (the viscosity refitted to the
/// mean positions under the journal orbits of the unbalance:
/// [`estimate_viscosity_and_unbalance`]); returns the estimates and the calibrated machine.
/// With AC-coupled probes only (no mean position) the unbalance alone is fitted, at the
/// machine file's viscosity. Without a keyphasor the unbalance's phase is fitted from the bag's
/// start (the calibrated machine carries it, for the replay after, which starts there too) but
/// reported null ([`BagCalibration::phase_null_reason`]). With `refine` the unbalance is refined
/// on the nonlinear twin that replays the bag after (`calibrate::refine_unbalance`).
pub fn calibrate_bag(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    probe_signals: &[(String, String)],
    window_s: [f64; 2],
    refine: Option<NonlinearRefinement>,
) -> Result<(BagCalibration, Rotor), CalibrationError> {
    let m = bag_measurements(bag, rotor, remaps, probe_signals, window_s);
    let all_ac =
        !rotor.probes.is_empty() && (0..rotor.probes.len()).all(|k| station_is_ac(rotor, k));
    // the live calibration's fit: the viscosity under the journal orbits of the unbalance
    // fitted at the static fit's viscosity (`estimate_viscosity_and_unbalance`); with no mean
    // position it gives the unbalance at the machine file's viscosity
    let (viscosity, unbalance) = estimate_viscosity_and_unbalance(
        rotor,
        &m.means,
        &m.vectors,
        DEFAULT_CORRECTION_RADIUS_M,
        refine,
    );
    let unbalance = unbalance?;
    let (viscosity, viscosity_not_fitted) = match viscosity {
        Ok(v) => (Some(v), None),
        Err(_) if all_ac && m.means.is_empty() => (None, Some(VISCOSITY_NOT_FITTED_AC.to_string())),
        Err(e) => return Err(e),
    };
    let mut calibrated = rotor.clone();
    if let Some(v) = &viscosity {
        calibrated
            .set_viscosity_scale(v.scale)
            .map_err(|e| CalibrationError::Model(e.to_string()))?;
    }
    for (u, p) in calibrated.unbalance.iter_mut().zip(&unbalance.planes) {
        u.magnitude_kg_m = (p.magnitude_g_mm * 1e-6).min(crate::driver::inputs::MAX_UNBALANCE_KG_M);
        u.phase_rad = p.phase_deg.to_radians();
    }
    let r = &m.reference;
    Ok((
        BagCalibration {
            window_s,
            windows_used: m.vectors.len() / 2,
            windows_skipped: m.skipped,
            speed_from_keyphasor: r.speed_from_keyphasor,
            keyphasor_intervals_refused: r.keyphasor_refused,
            viscosity,
            viscosity_not_fitted,
            unbalance,
            phase_null_reason: (!r.keyphasor).then(|| PHASE_NULL_NO_KEYPHASOR.to_string()),
            runouts: m.reference.runouts,
        },
        calibrated,
    ))
}

/// The 1X comparison of one probe station before and after calibration (`calibration.json`'s
/// `comparison`): over the fitted window, the mean over the replay's 8-revolution blocks of the
/// relative amplitude error |predicted − measured| / measured and of the absolute phase lag
/// error |predicted − measured| per probe axis (deg, wrapped to ±180°, API 670 lags from the
/// keyphasor); over the bag's last 32 revolutions, the report's signed errors.
#[derive(Debug, Clone, Serialize)]
pub struct StationComparison {
    /// The probe station.
    pub station: String,
    /// Blocks of the replay within the fitted window.
    pub blocks_in_window: usize,
    /// Mean relative 1X amplitude error over the window, before and after.
    pub amplitude_error_window: [Option<f64>; 2],
    /// Mean absolute 1X phase lag error per probe axis over the window (deg), before and after;
    /// null without a keyphasor lock.
    pub phase_lag_error_window_deg: [Option<[f64; 2]>; 2],
    /// Relative 1X amplitude error over the bag's last 32 revolutions, before and after.
    pub amplitude_error_last: [Option<f64>; 2],
    /// Phase lag error per probe axis over the bag's last 32 revolutions (deg), before and
    /// after.
    pub phase_lag_error_last_deg: [Option<[f64; 2]>; 2],
    /// Why the phases are null (the replay's reason), if they are.
    pub phase_null_reason: Option<String>,
}

/// Before and after calibration: per station and the onset.
#[derive(Debug, Clone, Serialize)]
pub struct CalibrationComparison {
    /// Per probe station.
    pub stations: Vec<StationComparison>,
    /// The onset observed in the bag (rpm).
    pub onset_observed_rpm: Option<f64>,
    /// The onset the twin predicts, before and after (rpm).
    pub onset_predicted_rpm: [Option<f64>; 2],
}

/// The comparison of the `before` and `after` replays over the fitted `window_s`.
pub fn compare_before_after(
    before: &super::ReplayReport,
    after: &super::ReplayReport,
    window_s: [f64; 2],
) -> CalibrationComparison {
    let stations = before
        .stations
        .iter()
        .zip(&after.stations)
        .map(|(b, a)| {
            let (wb, wa) = (window_errors(b, window_s), window_errors(a, window_s));
            let last = |r: &super::StationReport| {
                r.one_x_amplitude_error_m
                    .zip(r.one_x_amplitude_measured_m)
                    .map(|(e, m)| e / m)
            };
            StationComparison {
                station: b.station.clone(),
                blocks_in_window: wb.0,
                amplitude_error_window: [wb.1, wa.1],
                phase_lag_error_window_deg: [wb.2, wa.2],
                amplitude_error_last: [last(b), last(a)],
                phase_lag_error_last_deg: [
                    b.one_x_phase_lag_error_deg,
                    a.one_x_phase_lag_error_deg,
                ],
                phase_null_reason: b.phase_null_reason.clone(),
            }
        })
        .collect();
    CalibrationComparison {
        stations,
        onset_observed_rpm: before.onset.observed_speed_rpm,
        onset_predicted_rpm: [
            before.onset.predicted_speed_rpm,
            after.onset.predicted_speed_rpm,
        ],
    }
}

/// Over the blocks of `r` within `window_s`: their number, the mean relative 1X amplitude
/// error and the mean absolute phase lag error per probe axis (deg; None unless every such
/// block has its lags).
fn window_errors(
    r: &super::StationReport,
    window_s: [f64; 2],
) -> (usize, Option<f64>, Option<[f64; 2]>) {
    let blocks: Vec<_> = r
        .blocks
        .iter()
        .filter(|b| b.start_s >= window_s[0] && b.end_s <= window_s[1])
        .collect();
    let amp: Vec<f64> = blocks
        .iter()
        .filter(|b| b.measured.one_x_amplitude_m > 0.0)
        .map(|b| {
            (b.predicted.one_x_amplitude_m - b.measured.one_x_amplitude_m).abs()
                / b.measured.one_x_amplitude_m
        })
        .collect();
    let lags: Option<Vec<[f64; 2]>> = blocks
        .iter()
        .map(|b| {
            let (m, p) = (b.measured.one_x_probe_axes?, b.predicted.one_x_probe_axes?);
            let gap = |i: usize| {
                ((p[i].phase_lag_deg - m[i].phase_lag_deg + 180.0).rem_euclid(360.0) - 180.0).abs()
            };
            Some([gap(0), gap(1)])
        })
        .collect();
    let mean = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    let lag = lags.filter(|l| !l.is_empty()).map(|l| {
        let n = l.len() as f64;
        [0, 1].map(|i| l.iter().map(|x| x[i]).sum::<f64>() / n)
    });
    (blocks.len(), mean(&amp), lag)
}
