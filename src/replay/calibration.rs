//! `replay --calibrate` (issue 12): the bag's probe samples with the shaft angle, fitted to the
//! twin's viscosity and unbalance ([`crate::calibrate`]), and the twin of the machine with the
//! fitted values.
//!
//! The shaft angle is integrated from the speed messages (rotor_twin_msgs/RotorSpeed, with their
//! acceleration: exact on a linear ramp) from zero at the bag's first speed message. At each
//! keyphasor event (rotor_twin_msgs/Keyphasor, or std_msgs/Header, on the keyphasor topic) it is
//! set to the nearest whole revolution, so that angle 0 is the shaft's reference mark and the 1X
//! vectors are phase lags in the API 670 sense, like the replay's; the fitted unbalance phase is
//! then measured from the mark, as the twin reads `Unbalance.phase` with a keyphasor. Without a
//! keyphasor the phase is relative to the start (the synthetic plant's own angle starts there).

use crate::bag::Bag;
use crate::calibrate::{
    estimate_viscosity_and_unbalance, AngleSample, CalibrationError, MeanPosition, OneXVector,
    UnbalanceEstimate, ViscosityEstimate, WindowFits, DEFAULT_CORRECTION_RADIUS_M,
};
use crate::driver::PAIR_TOLERANCE_REVS;
use crate::messages::{self, from_cdr, RosMessage};
use crate::rotor::Rotor;
use crate::signals::probes::{check_reading, machine_from_probes, runout_at, ProbeCoupling};
use serde::Serialize;
use std::f64::consts::TAU;

/// Revolutions a fit window spans.
pub const CALIBRATION_WINDOW_REVS: f64 = 16.0;

/// A window whose fit leaves more than this share of its 1X semi-major axis (non-synchronous
/// motion: a whirl) is not used.
pub const MAX_WINDOW_RESIDUAL_SHARE: f64 = 0.3;

/// What `--calibrate` found.
#[derive(Debug, Clone, Serialize)]
pub struct BagCalibration {
    /// The bag time the fit used (s since the bag's first message).
    pub window_s: [f64; 2],
    /// Fit windows used (all stations), and left out for non-synchronous motion.
    pub windows_used: usize,
    /// Windows left out.
    pub windows_skipped: usize,
    /// The viscosity estimate.
    pub viscosity: ViscosityEstimate,
    /// The unbalance estimate, at the fitted viscosity.
    pub unbalance: UnbalanceEstimate,
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

/// [`angle_samples`] one at a time, in bag order, as (station index, sample): nothing is held.
/// Probe pairs (`ProbeDisplacement`) are taken as they are; raw probe readings (`ProbeSignal`,
/// or a std_msgs/Float64 topic per probe by `probe_signals`) are turned into the displacement
/// along their probe's axis (unit, sensitivity, reference gap: the machine file's), their
/// runout vector subtracted once a keyphasor has set the angle's zero on the mark, and the two
/// probes of a station paired into a machine-frame point, as the driver does
/// ([`RawPairs`]).
pub fn each_angle_sample(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    probe_signals: &[(String, String)],
    window_s: [f64; 2],
    take: &mut dyn FnMut(usize, AngleSample),
) {
    let name = |i: usize| {
        let n = &bag.topics[i].name;
        remaps
            .iter()
            .find(|(f, _)| f == n)
            .map_or(n.as_str(), |(_, t)| t.as_str())
    };
    let t0 = bag.time_span_ns().map_or(0, |(a, _)| a);
    let mut angle = ShaftAngle::default();
    let mut raw = RawPairs::new(rotor);
    for m in bag.messages() {
        let t = m.log_time_ns.saturating_sub(t0) as f64 * 1e-9;
        let topic = name(m.topic);
        let type_name = bag.topics[m.topic].type_name.as_str();
        let payload = m.payload();
        if angle.take(topic, type_name, payload, t) || !(window_s[0]..=window_s[1]).contains(&t) {
            continue;
        }
        let Some((a, w)) = angle.at(t) else {
            continue;
        };
        let point = match probe_reading(rotor, probe_signals, topic, type_name, payload) {
            Some(Reading::Pair(k, xy)) => Some((k, xy)),
            Some(Reading::Raw(k, value)) => {
                raw.take(rotor, k, value, t, angle.locked.then_some(a), w)
            }
            None => None,
        };
        if let Some((k, xy)) = point.filter(|(_, xy)| xy[0].is_finite() && xy[1].is_finite()) {
            let sample = AngleSample {
                angle_rad: a,
                speed_rad_s: w,
                displacement_m: xy,
            };
            take(k, sample);
        }
    }
}

/// The shaft angle integrated from the speed messages, set to whole revolutions at each
/// keyphasor event.
#[derive(Debug, Default)]
struct ShaftAngle {
    /// (time s, angle rad, speed rad/s, accel rad/s²) at the last speed message or event
    last: Option<(f64, f64, f64, f64)>,
    /// a keyphasor event has put the angle's zero on the mark
    locked: bool,
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
                }
            }
            return true;
        }
        if topic == crate::topics::KEYPHASOR && is_keyphasor_type(type_name) {
            // the reference mark passes: the angle is a whole number of revolutions
            if let (Some((.., acc)), Some((a, w))) = (self.last, self.at(t)) {
                self.last = Some((t, (a / TAU).round() * TAU, w, acc));
                self.locked = true;
            }
            return true;
        }
        false
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
/// `driver::PAIR_TOLERANCE_REVS`): the last reading of each probe of each station.
struct RawPairs {
    last: Vec<[Option<(f64, f64)>; 2]>,
    axes: Vec<[f64; 2]>,
}

impl RawPairs {
    fn new(rotor: &Rotor) -> Self {
        let mut axes = vec![[0.0, std::f64::consts::FRAC_PI_2]; rotor.probes.len()];
        for p in &rotor.proximity_probes {
            if let Some(a) = axes.get_mut(p.station) {
                a[p.axis] = p.angle_rad;
            }
        }
        Self {
            last: vec![[None; 2]; rotor.probes.len()],
            axes,
        }
    }

    /// Raw probe `k`'s reading `value` at `t` (s), the shaft at `psi` (rad from the mark, None
    /// without a keyphasor: no runout subtracted) turning at `w` (rad/s): the station's point
    /// once both its probes have read within the pairing tolerance. A refused reading (out of
    /// range, saturated) is left out.
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
        if let (Some(r), Some(psi)) = (p.runout, psi) {
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
}

/// A keyphasor event's type: ours, or a bare std_msgs/Header (the replay accepts both).
fn is_keyphasor_type(type_name: &str) -> bool {
    type_name == messages::Keyphasor::TYPE_NAME || type_name == messages::Header::TYPE_NAME
}

/// The measurements `--calibrate` fits, from the bag's samples in `window_s`: the mean
/// positions (DC-coupled stations), the keyphasor-referenced 1X vectors, and the windows left
/// out (never completed, or non-synchronous motion).
pub fn bag_measurements(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    probe_signals: &[(String, String)],
    window_s: [f64; 2],
) -> (Vec<MeanPosition>, Vec<OneXVector>, usize) {
    // the windows are fitted as the samples arrive: memory is bounded by one window a station
    // (issue 15), not by the length of `window_s`
    let mut fits = vec![WindowFits::new(CALIBRATION_WINDOW_REVS); rotor.probes.len()];
    each_angle_sample(bag, rotor, remaps, probe_signals, window_s, &mut |k, s| {
        fits[k].push(s)
    });
    // an AC-coupled station's mean is no position (its raw probes' DC gap is not kept)
    let ac = |k: usize| {
        rotor
            .proximity_probes
            .iter()
            .any(|p| p.station == k && p.coupling == ProbeCoupling::Ac)
    };
    let (mut means, mut vectors, mut skipped) = (Vec::new(), Vec::new(), 0);
    for (station, f) in fits.into_iter().enumerate() {
        // a window that never completed its revolutions (a shaft all but stopped) is left out
        skipped += f.overlong_windows;
        for w in f.finish() {
            if w.residual_rms_m > MAX_WINDOW_RESIDUAL_SHARE * w.one_x_major_m() {
                skipped += 1;
                continue;
            }
            if !ac(station) {
                means.push(w.mean_position(station));
            }
            vectors.extend(w.one_x(station));
        }
    }
    (means, vectors, skipped)
}

/// Fits the viscosity, then the unbalance at that viscosity, to the bag's samples in
/// `window_s` ([`bag_measurements`]) as the live calibration does (the viscosity refitted to the
/// mean positions under the journal orbits of the unbalance:
/// [`estimate_viscosity_and_unbalance`]); returns the estimates and the calibrated machine.
pub fn calibrate_bag(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    probe_signals: &[(String, String)],
    window_s: [f64; 2],
) -> Result<(BagCalibration, Rotor), CalibrationError> {
    let (means, vectors, skipped) = bag_measurements(bag, rotor, remaps, probe_signals, window_s);
    // the live calibration's fit: the viscosity under the journal orbits of the unbalance
    // fitted at the static fit's viscosity (`estimate_viscosity_and_unbalance`)
    let (viscosity, unbalance) =
        estimate_viscosity_and_unbalance(rotor, &means, &vectors, DEFAULT_CORRECTION_RADIUS_M);
    let (viscosity, unbalance) = (viscosity?, unbalance?);
    let mut calibrated = rotor.clone();
    calibrated
        .set_viscosity_scale(viscosity.scale)
        .map_err(|e| CalibrationError::Model(e.to_string()))?;
    for (u, p) in calibrated.unbalance.iter_mut().zip(&unbalance.planes) {
        u.magnitude_kg_m = (p.magnitude_g_mm * 1e-6).min(crate::driver::inputs::MAX_UNBALANCE_KG_M);
        u.phase_rad = p.phase_deg.to_radians();
    }
    Ok((
        BagCalibration {
            window_s,
            windows_used: means.len(),
            windows_skipped: skipped,
            viscosity,
            unbalance,
        },
        calibrated,
    ))
}
