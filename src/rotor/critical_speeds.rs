//! Critical speeds: where a forward mode's damped natural frequency equals the running frequency,
//! so that a 1X excitation (unbalance) meets the mode. The Campbell diagram's grid only brackets
//! each crossing; the speed is then located by root-finding on that mode, followed by its shape
//! (MAC) between the bracket's ends, so that it is a property of the machine, not of the grid.
//! Each crossing is classed by API 684's rule (API 684, 2nd ed. 2005, §2.8 and Figure 2-1): a
//! resonance whose amplification factor is below 2.5 is "critically damped" and needs no
//! separation margin; it is reported, but not as a critical speed. The modal amplification
//! factor is the single-degree-of-freedom one, AF = 1/(2ζ) (the half-power estimate
//! N_c/(N₂ − N₁) of a lightly damped resonance): AF ≥ 2.5 ⇔ ζ ≤ 0.2 ⇔ log dec ≤ 1.28.

use super::modal::{damped_mode_shapes, BearingSolvers, CampbellPoint, ModeShape, WhirlDirection};
use super::mode_tracking::{mac, tilt_weight_m2, Shape, MIN_TRACK_MAC};
use super::{Rotor, RotorError, StaticSolution};
use serde::Serialize;

/// API 684's least amplification factor of a critical speed: below it a resonance is critically
/// damped (no separation margin required).
pub const API_684_MIN_AMPLIFICATION_FACTOR: f64 = 2.5;

/// The crossing speed is located to this (rpm).
const SPEED_TOLERANCE_RPM: f64 = 0.01;

/// Two located crossings closer than this (rpm) with the same frequency are one (the same mode
/// found from two tracks, or twice from one).
const SAME_CROSSING_RPM: f64 = 0.5;

/// Crossings of one critically damped mode closer than this fraction of the speed are one: its
/// frequency, nearly parallel to 1X, carries the film coefficients' scatter (≈ 0.05 Hz).
const DAMPED_CLUSTER: f64 = 0.03;

/// A crossing of a forward mode with 1X.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CriticalSpeed {
    /// Speed (rpm), located to 0.01 rpm on the mode followed by shape.
    pub speed_rpm: f64,
    /// Track id of the mode (see [`CampbellPoint::tracks`]).
    pub track: usize,
    /// The mode's log decrement there.
    pub log_dec: f64,
    /// The mode's damping ratio there.
    pub damping_ratio: f64,
    /// The modal amplification factor 1/(2ζ) there.
    pub amplification_factor: f64,
    /// True if API 684 calls it a critical speed (AF ≥ 2.5); false for a critically damped mode.
    pub critical: bool,
}

/// Every forward mode's crossing with 1X in the range of the Campbell diagram `points` (computed
/// with `rotor` and `statics`), located by root-finding and classed by API 684's amplification
/// factor (see the module's notes); ascending in speed. A crossing the grid brackets is found
/// whatever the step; two crossings of one mode inside one step are not bracketed and not found.
pub fn critical_speeds(
    rotor: &Rotor,
    statics: &StaticSolution,
    points: &[CampbellPoint],
) -> Result<Vec<CriticalSpeed>, RotorError> {
    critical_speeds_with(rotor, statics, points, BearingSolvers::new(rotor))
}

/// [`critical_speeds`] of a diagram of [`super::campbell_zone_following`]: located with the same
/// tabulated film and zone-following slopes (steps `step` × c and × c ω).
pub fn critical_speeds_zone_following(
    rotor: &Rotor,
    statics: &StaticSolution,
    points: &[CampbellPoint],
    step: f64,
) -> Result<Vec<CriticalSpeed>, RotorError> {
    let solvers = BearingSolvers::tabulated(rotor)?.following_zone(step);
    critical_speeds_with(rotor, statics, points, solvers)
}

/// The crossings located with these film solvers.
fn critical_speeds_with(
    rotor: &Rotor,
    statics: &StaticSolution,
    points: &[CampbellPoint],
    solvers: BearingSolvers,
) -> Result<Vec<CriticalSpeed>, RotorError> {
    let mut follower = Follower::new(rotor, statics, solvers);
    let mut out: Vec<(CriticalSpeed, f64)> = Vec::new();
    for (w, id) in brackets(points) {
        if let Some(found) = follower.locate(&w, id)? {
            out.push(found);
        }
    }
    out.sort_by(|a, b| a.0.speed_rpm.total_cmp(&b.0.speed_rpm));
    out.dedup_by(|b, a| {
        (b.0.speed_rpm - a.0.speed_rpm).abs() < SAME_CROSSING_RPM
            && (b.1 - a.1).abs() < 1e-3 * a.1.abs().max(1.0)
    });
    // a critically damped mode running close to 1X crosses it back and forth within the
    // scatter of its frequency: one crossing, at the mean speed
    out.dedup_by(|b, a| {
        let near = (b.0.speed_rpm - a.0.speed_rpm).abs() < DAMPED_CLUSTER * a.0.speed_rpm;
        if near && b.0.track == a.0.track && !a.0.critical && !b.0.critical {
            a.0.speed_rpm = 0.5 * (a.0.speed_rpm + b.0.speed_rpm);
            true
        } else {
            false
        }
    });
    Ok(out.into_iter().map(|(c, _)| c).collect())
}

/// The grid's brackets of a forward mode's crossing: the two neighbouring points (speed rpm,
/// frequency Hz at each end) and the track id, where f − N/60 changes sign along one track.
fn brackets(points: &[CampbellPoint]) -> Vec<([(f64, f64); 2], usize)> {
    let mut out = Vec::new();
    for w in points.windows(2) {
        for (m0, id) in w[0].modes.iter().zip(&w[0].tracks) {
            let Some(j) = w[1].tracks.iter().position(|t| t == id) else {
                continue;
            };
            let m1 = w[1].modes[j];
            if m0.direction != WhirlDirection::Forward || m1.direction != WhirlDirection::Forward {
                continue;
            }
            let ga = m0.frequency_hz - w[0].speed_rpm / 60.0;
            let gb = m1.frequency_hz - w[1].speed_rpm / 60.0;
            if (ga > 0.0 && gb <= 0.0) || (ga < 0.0 && gb >= 0.0) {
                out.push((
                    [
                        (w[0].speed_rpm, m0.frequency_hz),
                        (w[1].speed_rpm, m1.frequency_hz),
                    ],
                    *id,
                ));
            }
        }
    }
    out
}

/// The damped modes at any speed, and one mode followed by its shape.
struct Follower<'a> {
    rotor: &'a Rotor,
    statics: &'a StaticSolution,
    solvers: BearingSolvers,
    n_nodes: usize,
    ell2: f64,
}

/// One evaluation of the followed mode: speed (rpm), f − N/60 (Hz), the mode.
type Sample = (f64, f64, ModeShape);

impl<'a> Follower<'a> {
    fn new(rotor: &'a Rotor, statics: &'a StaticSolution, solvers: BearingSolvers) -> Self {
        Self {
            rotor,
            statics,
            solvers,
            n_nodes: rotor.n_nodes(),
            ell2: tilt_weight_m2(rotor),
        }
    }

    fn modes(&mut self, rpm: f64) -> Result<Vec<ModeShape>, RotorError> {
        let omega = crate::units::rpm_to_rad_s(rpm);
        let (coefs, _) = self
            .solvers
            .at_speed(self.rotor, &self.statics.bearing_loads_n, omega)?;
        damped_mode_shapes(self.rotor, omega, &coefs)
    }

    /// The forward mode at `rpm` whose frequency is nearest `hz` (a bracket's end, recomputed).
    fn by_frequency(&mut self, rpm: f64, hz: f64) -> Result<Option<Sample>, RotorError> {
        let best = self
            .modes(rpm)?
            .into_iter()
            .filter(|m| m.mode.direction == WhirlDirection::Forward)
            .min_by(|a, b| {
                (a.mode.frequency_hz - hz)
                    .abs()
                    .total_cmp(&(b.mode.frequency_hz - hz).abs())
            });
        Ok(best.map(|m| (rpm, m.mode.frequency_hz - rpm / 60.0, m)))
    }

    /// The mode at `rpm` most like `shape` (MAC ≥ 0.5), if any.
    fn by_shape(&mut self, rpm: f64, shape: &Shape) -> Result<Option<Sample>, RotorError> {
        let (n, l) = (self.n_nodes, self.ell2);
        let best = self
            .modes(rpm)?
            .into_iter()
            .map(|m| (mac(&m.shape, shape, n, l), m))
            .filter(|(q, _)| *q >= MIN_TRACK_MAC)
            .max_by(|a, b| a.0.total_cmp(&b.0));
        Ok(best.map(|(_, m)| (rpm, m.mode.frequency_hz - rpm / 60.0, m)))
    }

    /// The crossing inside one bracket by the Illinois variant of regula falsi, each new speed's
    /// mode the one most like the mode at the nearer end; with its frequency (Hz). None if the
    /// mode cannot be followed or is not forward at the crossing.
    fn locate(
        &mut self,
        ends: &[(f64, f64); 2],
        track: usize,
    ) -> Result<Option<(CriticalSpeed, f64)>, RotorError> {
        let (Some(mut a), Some(mut b)) = (
            self.by_frequency(ends[0].0, ends[0].1)?,
            self.by_frequency(ends[1].0, ends[1].1)?,
        ) else {
            return Ok(None);
        };
        if a.1 * b.1 > 0.0 {
            return Ok(None);
        }
        // Illinois: the stale end's value is halved each time the new point falls on its side
        let mut stale = 1.0;
        for _ in 0..60 {
            if (b.0 - a.0).abs() < SPEED_TOLERANCE_RPM || b.1 == 0.0 {
                break;
            }
            let (ga, gb) = (a.1 * stale, b.1);
            let s = (a.0 * gb - b.0 * ga) / (gb - ga);
            let nearer = if (s - a.0).abs() < (s - b.0).abs() {
                &a.2.shape
            } else {
                &b.2.shape
            };
            let shape = nearer.clone();
            let Some(c) = self.by_shape(s, &shape)? else {
                return Ok(None);
            };
            if c.1 * b.1 < 0.0 {
                a = std::mem::replace(&mut b, c);
                stale = 1.0;
            } else {
                b = c;
                stale *= 0.5;
            }
        }
        let m = b.2.mode;
        if m.direction != WhirlDirection::Forward {
            return Ok(None);
        }
        let af = 0.5 / m.damping_ratio.max(1e-12);
        Ok(Some((
            CriticalSpeed {
                speed_rpm: b.0,
                track,
                log_dec: m.log_dec,
                damping_ratio: m.damping_ratio,
                amplification_factor: af,
                critical: af >= API_684_MIN_AMPLIFICATION_FACTOR,
            },
            m.frequency_hz,
        )))
    }
}
