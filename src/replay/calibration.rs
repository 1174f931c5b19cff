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
    estimate_unbalance, estimate_viscosity, AngleSample, CalibrationError, UnbalanceEstimate,
    ViscosityEstimate, WindowFits, DEFAULT_CORRECTION_RADIUS_M,
};
use crate::messages::{self, from_cdr, RosMessage};
use crate::rotor::Rotor;
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
/// message), with the shaft angle and speed; `remaps` as the replay's.
pub fn angle_samples(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    window_s: [f64; 2],
) -> Vec<Vec<AngleSample>> {
    let mut out = vec![Vec::new(); rotor.probes.len()];
    each_angle_sample(bag, rotor, remaps, window_s, &mut |k, s| out[k].push(s));
    out
}

/// [`angle_samples`] one at a time, in bag order, as (station index, sample): nothing is held.
pub fn each_angle_sample(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
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
    // (time s, angle rad, speed rad/s, accel rad/s²) at the last speed message
    let mut last: Option<(f64, f64, f64, f64)> = None;
    for m in bag.messages() {
        let t = m.log_time_ns.saturating_sub(t0) as f64 * 1e-9;
        let topic = name(m.topic);
        let type_name = bag.topics[m.topic].type_name.as_str();
        let angle_at = |t: f64| {
            last.map(|(t1, a1, w1, acc)| {
                let dt = t - t1;
                (a1 + w1 * dt + 0.5 * acc * dt * dt, w1 + acc * dt)
            })
        };
        if topic == crate::topics::SPEED && type_name == messages::RotorSpeed::TYPE_NAME {
            let Ok(s) = from_cdr::<messages::RotorSpeed>(m.payload()) else {
                continue;
            };
            if !(s.speed.is_finite() && s.acceleration.is_finite()) {
                continue;
            }
            let angle = angle_at(t).map_or(0.0, |(a, _)| a);
            last = Some((t, angle, s.speed, s.acceleration));
        } else if topic == crate::topics::KEYPHASOR && is_keyphasor_type(type_name) {
            // the reference mark passes: the angle is a whole number of revolutions
            if let (Some((.., acc)), Some((a, w))) = (last, angle_at(t)) {
                last = Some((t, (a / TAU).round() * TAU, w, acc));
            }
        } else if topic == crate::topics::PROBE
            && type_name == messages::ProbeDisplacement::TYPE_NAME
            && (window_s[0]..=window_s[1]).contains(&t)
        {
            let Ok(p) = from_cdr::<messages::ProbeDisplacement>(m.payload()) else {
                continue;
            };
            let (Some(k), Some((angle, w))) = (
                rotor.probes.iter().position(|s| s.name == p.station),
                angle_at(t),
            ) else {
                continue;
            };
            if p.x.is_finite() && p.y.is_finite() {
                take(
                    k,
                    AngleSample {
                        angle_rad: angle,
                        speed_rad_s: w,
                        displacement_m: [p.x, p.y],
                    },
                );
            }
        }
    }
}

/// A keyphasor event's type: ours, or a bare std_msgs/Header (the replay accepts both).
fn is_keyphasor_type(type_name: &str) -> bool {
    type_name == messages::Keyphasor::TYPE_NAME || type_name == messages::Header::TYPE_NAME
}

/// Fits the viscosity, then the unbalance at that viscosity, to the bag's samples in
/// `window_s`; returns the estimates and the calibrated machine.
pub fn calibrate_bag(
    bag: &Bag,
    rotor: &Rotor,
    remaps: &[(String, String)],
    window_s: [f64; 2],
) -> Result<(BagCalibration, Rotor), CalibrationError> {
    // the windows are fitted as the samples arrive: memory is bounded by one window a station
    // (issue 15), not by the length of `window_s`
    let mut fits = vec![WindowFits::new(CALIBRATION_WINDOW_REVS); rotor.probes.len()];
    each_angle_sample(bag, rotor, remaps, window_s, &mut |k, s| fits[k].push(s));
    let (mut means, mut vectors, mut skipped) = (Vec::new(), Vec::new(), 0);
    for (station, f) in fits.into_iter().enumerate() {
        // a window that never completed its revolutions (a shaft all but stopped) is left out
        skipped += f.overlong_windows;
        for w in f.finish() {
            if w.residual_rms_m > MAX_WINDOW_RESIDUAL_SHARE * w.one_x_major_m() {
                skipped += 1;
                continue;
            }
            means.push(w.mean_position(station));
            vectors.extend(w.one_x(station));
        }
    }
    let viscosity = estimate_viscosity(rotor, &means)?;
    let mut calibrated = rotor.clone();
    calibrated
        .set_viscosity_scale(viscosity.scale)
        .map_err(|e| CalibrationError::Model(e.to_string()))?;
    let unbalance = estimate_unbalance(&calibrated, &vectors, DEFAULT_CORRECTION_RADIUS_M)?;
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
