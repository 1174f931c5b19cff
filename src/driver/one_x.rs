//! Live 1X vectors (issue 12): the probe comparisons of one station gathered over blocks of
//! [`ONE_X_BLOCK_REVS`] whole revolutions of the twin's shaft angle (the replay's block,
//! `replay::compare::BLOCK_REVS`), and at each block's end the 1X vector of the measured and
//! of the predicted signal along each of the station's two probe axes, by the one 1X rule of
//! [`crate::signals::one_x_vector`] (Hann-windowed DFT at order 1, phase lag in the API 670 /
//! Bently convention). The measured vectors are read against the plant's own angle, interpolated
//! between the keyphasor events that bracket each sample's stamp ([`OneXBlocks`]), the
//! predicted ones against the twin's. The phase lags are null, with the reason, unless every
//! sample of the block was referenced to a locked keyphasor
//! ([`crate::signals::PhaseReference::null_reason`]) and the events bracket the whole block; the
//! amplitudes do not depend on the phase reference.
//!
//! A block also gives, per machine axis, the measured 1X vector and mean position that the live
//! calibration uses ([`crate::calibrate`]'s convention: a = Re(X e^{iθ})), and how much of the
//! measured motion the 1X and the mean leave (a whirl makes that large).

use super::{seconds_to_ns, ProbeComparison};
use crate::signals::{
    keyphasor_one_x, one_x_vector, KeyphasorEvents, OneXVector, Unbracketed, KEYPHASOR_JITTER_S,
    KEYPHASOR_STOP_REVS,
};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Revolutions of one block: 8, the replay's (`replay::compare::BLOCK_REVS`).
pub const ONE_X_BLOCK_REVS: usize = crate::replay::compare::BLOCK_REVS;

/// Samples a block holds at most: 32,768 (8 revolutions at 1,000 rpm, the default minimum
/// speed, are 0.48 s: room for 68 kHz of probe samples). A block that fills before its
/// revolutions are complete is given up and counted ([`OneXBlocks::overflowed`]).
pub const ONE_X_BLOCK_CAPACITY: usize = 32_768;

/// One sample of a block.
#[derive(Debug, Clone, Copy, Default)]
struct BlockSample {
    time_ns: i64,
    angle_rad: f64,
    speed_rad_s: f64,
    measured_m: [f64; 2],
    predicted_m: [f64; 2],
}

/// What a finished block gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneXBlock {
    /// Probe station index.
    pub station: usize,
    /// Time of the block's last sample (ns, the driver's time base).
    pub end_ns: i64,
    /// Mean speed over the block (rad/s).
    pub speed_rad_s: f64,
    /// Whole revolutions in the block.
    pub revolutions: usize,
    /// Samples in the block.
    pub samples: usize,
    /// The station's probe axis angles (rad, from +x towards +y).
    pub axes_rad: [f64; 2],
    /// Measured 1X vector along each probe axis (its phase lag valid only without a reason).
    pub measured: [OneXVector; 2],
    /// Predicted 1X vector along each probe axis.
    pub predicted: [OneXVector; 2],
    /// Measured 1X vector along the machine axes x, y (for the calibration).
    pub measured_xy: [OneXVector; 2],
    /// Measured mean position `[x, y]` (m).
    pub measured_mean_m: [f64; 2],
    /// RMS of the measured motion less its mean and 1X (m, both axes).
    pub residual_rms_m: f64,
    /// Why the phase lags are null (None: keyphasor-referenced over the whole block).
    pub null_reason: Option<&'static str>,
}

impl OneXBlock {
    /// The measured 1X semi-major axis (m) from the machine-axis vectors.
    pub fn measured_major_m(&self) -> f64 {
        let (x, y) = (
            self.measured_xy[0].phasor_m(),
            self.measured_xy[1].phasor_m(),
        );
        let f = ((x[0] - y[1]).powi(2) + (x[1] + y[0]).powi(2)).sqrt() / 2.0;
        let b = ((x[0] + y[1]).powi(2) + (x[1] - y[0]).powi(2)).sqrt() / 2.0;
        f + b
    }
}

impl OneXBlock {
    /// The message of this block at station `name`: phase lags empty, with the reason, unless
    /// keyphasor-referenced; amplitudes always.
    pub fn to_message(&self, name: &str) -> crate::messages::OneXVectors {
        let lags = |v: &[OneXVector; 2]| match self.null_reason {
            None => v.iter().map(|a| a.phase_lag_deg).collect(),
            Some(_) => Vec::new(),
        };
        let errors = match self.null_reason {
            None => (0..2)
                .map(|j| {
                    let d = self.predicted[j].phase_lag_deg - self.measured[j].phase_lag_deg;
                    (d + 180.0).rem_euclid(360.0) - 180.0
                })
                .collect(),
            Some(_) => Vec::new(),
        };
        crate::messages::OneXVectors {
            header: crate::session::header(self.end_ns, name),
            station: name.to_string(),
            speed: self.speed_rad_s,
            revolutions: self.revolutions as u32,
            samples: self.samples as u32,
            axis_angles: self.axes_rad.to_vec(),
            measured_amplitudes: self.measured.iter().map(|a| a.amplitude_m).collect(),
            measured_phase_lags_deg: lags(&self.measured),
            predicted_amplitudes: self.predicted.iter().map(|a| a.amplitude_m).collect(),
            predicted_phase_lags_deg: lags(&self.predicted),
            phase_lag_errors_deg: errors,
            phase_null_reason: self.null_reason.unwrap_or_default().to_string(),
        }
    }
}

/// Why the measured phase lags of a block are null although the twin was locked: the
/// keyphasor event after its last sample did not come within the wait.
pub const NO_CLOSING_EVENT: &str = "the keyphasor stopped: no event within a revolution of the block's end (waited 3 revolutions + 0.1 s of sample stamps)";

/// Why the measured phase lags of a block are null: no kept keyphasor event before its first
/// sample (the events started, or broke at a refused one, within the block).
pub const NO_OPENING_EVENT: &str =
    "no keyphasor event before the block's first sample (none yet, or a refused event broke the reference)";

/// The block being gathered at one station, and the one gathered before it while it waits for
/// the keyphasor event after its last sample.
#[derive(Debug, Clone)]
struct Gathering {
    samples: Vec<BlockSample>,
    start_angle_rad: f64,
    reason: Option<&'static str>,
    waiting: Vec<BlockSample>,
    waiting_reason: Option<&'static str>,
    /// the stamp time after which the waiting block is finished without its closing event
    deadline_ns: i64,
    /// a block finished without its closing event because the next one was complete
    done: Option<OneXBlock>,
}

/// The blocks of every probe station. Samples are gathered by the twin's angle into blocks of
/// [`ONE_X_BLOCK_REVS`] revolutions; a gathered block waits for the keyphasor event after its
/// last sample (at most [`KEYPHASOR_STOP_REVS`] revolutions + [`KEYPHASOR_JITTER_S`] of sample
/// stamps after it), and its measured 1X vectors are then read against the plant's own angle,
/// interpolated between the events that bracket each sample's stamp
/// ([`crate::signals::keyphasor_one_x`]): what a sample's angle is does not depend on when it or
/// the events were delivered. The predicted vectors stay on the twin's angle (its own phase).
#[derive(Debug, Clone)]
pub struct OneXBlocks {
    stations: Vec<Gathering>,
    axes: Vec<[f64; 2]>,
    /// Blocks given up because they filled before their revolutions were complete.
    pub overflowed: u64,
}

impl OneXBlocks {
    /// Blocks for stations whose probe axes are `axes` (rad); the buffers are allocated here.
    pub fn new(axes: Vec<[f64; 2]>) -> Self {
        let stations = axes
            .iter()
            .map(|_| Gathering {
                samples: Vec::with_capacity(ONE_X_BLOCK_CAPACITY),
                start_angle_rad: 0.0,
                reason: None,
                waiting: Vec::with_capacity(ONE_X_BLOCK_CAPACITY),
                waiting_reason: None,
                deadline_ns: 0,
                done: None,
            })
            .collect();
        Self {
            stations,
            axes,
            overflowed: 0,
        }
    }

    /// Adds a comparison, in stamp order within its block. A twin that restarted (its angle
    /// went back by more than half a revolution) or a revolution without a sample starts a new
    /// block; a complete block goes to wait for its closing event ([`OneXBlocks::take_ready`]).
    pub fn add(&mut self, c: &ProbeComparison, events: &KeyphasorEvents) {
        let axes = self.axes.get(c.station).copied().unwrap_or_default();
        let Some(g) = self.stations.get_mut(c.station) else {
            return;
        };
        // a gap by the stamps (a burst delivered late jumps the twin's angle, not the stamps)
        let rev_ns = TAU / c.speed_rad_s.max(1e-3) * 1e9;
        let last = g.samples.last().map(|s| (s.angle_rad, s.time_ns));
        if last.is_some_and(|(a, t)| c.angle_rad < a - PI || (c.time_ns - t) as f64 > rev_ns) {
            g.samples.clear();
        }
        if g.samples.len() >= ONE_X_BLOCK_CAPACITY {
            g.samples.clear();
            self.overflowed += 1;
        }
        if g.samples.is_empty() {
            g.start_angle_rad = c.angle_rad;
            g.reason = None;
        }
        g.reason = g.reason.or(c.phase_reference.null_reason());
        let sample = BlockSample {
            time_ns: c.time_ns,
            angle_rad: c.angle_rad,
            speed_rad_s: c.speed_rad_s,
            measured_m: c.measured_m,
            predicted_m: c.predicted_m,
        };
        // a sample delivered out of stamp order goes to its place (rare: one search from the end)
        let at = g.samples.len()
            - g.samples
                .iter()
                .rev()
                .take_while(|q| q.time_ns > c.time_ns)
                .count();
        g.samples.insert(at, sample);
        if c.angle_rad - g.start_angle_rad < ONE_X_BLOCK_REVS as f64 * TAU {
            return;
        }
        if !g.waiting.is_empty() {
            g.done = finish(c.station, axes, &g.waiting, g.waiting_reason, events, true);
        }
        // the sample that closed this block opens the next one
        std::mem::swap(&mut g.samples, &mut g.waiting);
        g.waiting_reason = g.reason;
        let closing = g.waiting.pop().unwrap_or(sample);
        let end = g.waiting.last().map_or(closing, |q| *q);
        let w = end.speed_rad_s.max(1e-3);
        g.deadline_ns =
            end.time_ns + seconds_to_ns(KEYPHASOR_STOP_REVS * TAU / w + KEYPHASOR_JITTER_S);
        g.samples.clear();
        g.samples.push(closing);
        g.start_angle_rad = closing.angle_rad;
        g.reason = c.phase_reference.null_reason();
    }

    /// A finished block, if one is ready: one whose closing keyphasor event has come (in
    /// `events`), or whose wait ended (the newest sample stamped `newest_ns` is past its
    /// deadline). Call until None after each input.
    pub fn take_ready(&mut self, events: &KeyphasorEvents, newest_ns: i64) -> Option<OneXBlock> {
        for (k, g) in self.stations.iter_mut().enumerate() {
            if let Some(b) = g.done.take() {
                return Some(b);
            }
            if g.waiting.is_empty() {
                continue;
            }
            let give_up = newest_ns > g.deadline_ns;
            let b = finish(
                k,
                self.axes[k],
                &g.waiting,
                g.waiting_reason,
                events,
                give_up,
            );
            if b.is_some() || give_up {
                g.waiting.clear();
            }
            if b.is_some() {
                return b;
            }
        }
        None
    }
}

/// Each sample of `s` with its point `pick` projected on the axis at angle `a` (rad).
fn along_axis(
    s: &[BlockSample],
    pick: fn(&BlockSample) -> [f64; 2],
    a: f64,
) -> impl Iterator<Item = (&BlockSample, f64)> + Clone {
    let (sn, cs) = a.sin_cos();
    s.iter().map(move |q| {
        let p = pick(q);
        (q, p[0] * cs + p[1] * sn)
    })
}

/// The 1X vectors of a gathered block `s` (whole revolutions of the twin's angle): measured
/// against the plant's angle from `events`, predicted against the twin's. None while its
/// closing event is pending (unless `give_up`: then its measured phases are null).
fn finish(
    station: usize,
    axes: [f64; 2],
    s: &[BlockSample],
    twin_reason: Option<&'static str>,
    events: &KeyphasorEvents,
    give_up: bool,
) -> Option<OneXBlock> {
    let n = s.len();
    let end = s.last()?;
    let plant = |pick: fn(&BlockSample) -> [f64; 2], a: f64| {
        let along = along_axis(s, pick, a).map(|(q, v)| (q.time_ns, v));
        keyphasor_one_x(along, n, events, give_up)
    };
    let twin = |pick: fn(&BlockSample) -> [f64; 2], a: f64| {
        one_x_vector(along_axis(s, pick, a).map(|(q, v)| (q.angle_rad, v)), n)
    };
    let measured = |q: &BlockSample| q.measured_m;
    let predicted = |q: &BlockSample| q.predicted_m;
    let (plant_ok, measured_reason) = match plant(measured, axes[0]) {
        Ok(_) => (true, None),
        Err(Unbracketed::Pending) if !give_up => return None,
        Err(Unbracketed::Pending) => (false, Some(NO_CLOSING_EVENT)),
        Err(Unbracketed::Missing) => (false, Some(NO_OPENING_EVENT)),
    };
    // the plant's angle where every sample is bracketed; the twin's (amplitudes only) where not
    let vector = |pick: fn(&BlockSample) -> [f64; 2], a: f64| match plant_ok {
        true => plant(pick, a).ok().flatten(),
        false => twin(pick, a),
    };
    let m = [vector(measured, axes[0])?, vector(measured, axes[1])?];
    let p = [twin(predicted, axes[0])?, twin(predicted, axes[1])?];
    let xy = [vector(measured, 0.0)?, vector(measured, FRAC_PI_2)?];
    let psi = |q: &BlockSample| match plant_ok {
        true => events.angle_at_or_after(q.time_ns).unwrap_or(q.angle_rad),
        false => q.angle_rad,
    };
    let mean = [0, 1].map(|j| s.iter().map(|q| q.measured_m[j]).sum::<f64>() / n as f64);
    let rss: f64 = s
        .iter()
        .map(|q| {
            (0..2)
                .map(|j| {
                    let fit = mean[j] + crate::signals::probes::runout_at(&xy[j], psi(q));
                    (q.measured_m[j] - fit).powi(2)
                })
                .sum::<f64>()
        })
        .sum();
    Some(OneXBlock {
        station,
        end_ns: end.time_ns,
        speed_rad_s: s.iter().map(|q| q.speed_rad_s).sum::<f64>() / n as f64,
        revolutions: ONE_X_BLOCK_REVS,
        samples: n,
        axes_rad: axes,
        measured: m,
        predicted: p,
        measured_xy: xy,
        measured_mean_m: mean,
        residual_rms_m: (rss / (2 * n) as f64).sqrt(),
        null_reason: twin_reason.or(measured_reason),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signals::PhaseReference;

    /// Keyphasor events where the angle `psi` of [`comparison`] is 2πm, m in 0..revs, at `w`.
    fn events(w: f64, revs: usize) -> KeyphasorEvents {
        let mut e = KeyphasorEvents::default();
        for m in 0..revs {
            e.push((TAU * m as f64 / w * 1e9) as i64);
        }
        e
    }

    /// Adds `c` and takes the blocks that are ready.
    fn add(blocks: &mut OneXBlocks, c: &ProbeComparison, ev: &KeyphasorEvents) -> Vec<OneXBlock> {
        blocks.add(c, ev);
        std::iter::from_fn(|| blocks.take_ready(ev, c.time_ns)).collect()
    }

    fn comparison(k: usize, psi: f64, w: f64, lag: f64, r: PhaseReference) -> ProbeComparison {
        // a forward 1X circle of 3 µm lagging the mark by `lag`, about a mean of (5, −20) µm;
        // the prediction: 1 µm lagging by lag + 40°
        let a = 3e-6;
        let q = lag + 40f64.to_radians();
        ProbeComparison {
            station: 0,
            time_ns: (psi / w * 1e9) as i64 + k as i64,
            angle_rad: psi,
            speed_rad_s: w,
            measured_m: [5e-6 + a * (psi - lag).cos(), -20e-6 + a * (psi - lag).sin()],
            predicted_m: [1e-6 * (psi - q).cos(), 1e-6 * (psi - q).sin()],
            phase_reference: r,
        }
    }

    /// A forward circle x = A cos(ψ − β), y = A sin(ψ − β) read by probes at α: d = A cos(ψ −
    /// β − α), so each probe's lag is β + α (the plant-signal tests' closed form), here with
    /// probes at 45° and 135° and β = 50°: 95° and 185°, within 0.5°, 3 µm within 1 %; the
    /// machine axes read β and β + 90°, the mean (5, −20) µm, the residual nothing.
    #[test]
    fn a_block_gives_the_lag_of_each_probe_axis() {
        let axes = [45f64.to_radians(), 135f64.to_radians()];
        let mut blocks = OneXBlocks::new(vec![axes]);
        let (w, lag) = (800.0, 50f64.to_radians());
        let per_rev = 37; // not a divisor of anything in particular
        let ev = events(w, 12);
        let mut out = None;
        for k in 0..(9 * per_rev) {
            let psi = TAU * k as f64 / per_rev as f64 + 0.3;
            let c = comparison(k, psi, w, lag, PhaseReference::Locked);
            if let Some(b) = add(&mut blocks, &c, &ev).pop() {
                out.get_or_insert(b);
            }
        }
        let b = out.expect("a block after 8 revolutions");
        assert_eq!(b.null_reason, None);
        assert_eq!(b.samples, 8 * per_rev);
        for (j, want) in [95.0, 185.0].iter().enumerate() {
            let d = (b.measured[j].phase_lag_deg - want + 180.0).rem_euclid(360.0) - 180.0;
            assert!(d.abs() < 0.5, "axis {j}: {:?}", b.measured[j]);
            assert!((b.measured[j].amplitude_m / 3e-6 - 1.0).abs() < 0.01);
            let dp = (b.predicted[j].phase_lag_deg - want - 40.0 + 180.0).rem_euclid(360.0) - 180.0;
            assert!(dp.abs() < 0.5, "predicted axis {j}: {:?}", b.predicted[j]);
        }
        assert!((b.measured_xy[0].phase_lag_deg - 50.0).abs() < 0.5, "{b:?}");
        assert!(
            (b.measured_xy[1].phase_lag_deg - 140.0).abs() < 0.5,
            "{b:?}"
        );
        assert!((b.measured_mean_m[0] - 5e-6).abs() < 0.05e-6);
        assert!((b.measured_mean_m[1] + 20e-6).abs() < 0.05e-6);
        assert!(b.residual_rms_m < 0.05e-6, "{b:?}");
        assert!((b.measured_major_m() / 3e-6 - 1.0).abs() < 0.01);
        let m = b.to_message("probe_outboard");
        assert_eq!(m.measured_phase_lags_deg.len(), 2);
        assert!((m.phase_lag_errors_deg[0] - 40.0).abs() < 0.5, "{m:?}");
        assert!(m.phase_null_reason.is_empty());
    }

    /// One sample without the lock in a block makes its phases null with that reason; a twin
    /// that restarts (angle back to 0) starts a new block.
    #[test]
    fn a_block_not_locked_throughout_has_null_phases_with_the_reason() {
        let mut blocks = OneXBlocks::new(vec![[0.0, FRAC_PI_2]]);
        let lag = 0.2;
        let ev = events(900.0, 40);
        let mut got = Vec::new();
        for k in 0..(20 * 16) {
            let psi = TAU * k as f64 / 16.0;
            let r = if k == 30 {
                PhaseReference::Stopped
            } else {
                PhaseReference::Locked
            };
            got.extend(add(&mut blocks, &comparison(k, psi, 900.0, lag, r), &ev));
        }
        assert_eq!(got.len(), 2, "{got:?}");
        assert_eq!(
            got[0].null_reason,
            PhaseReference::Stopped.null_reason(),
            "{:?}",
            got[0]
        );
        assert_eq!(got[1].null_reason, None);
        let m = got[0].to_message("s");
        assert!(m.measured_phase_lags_deg.is_empty() && m.phase_lag_errors_deg.is_empty());
        assert_eq!(m.measured_amplitudes.len(), 2);
        assert!(m.phase_null_reason.contains("stopped"), "{m:?}");
        // a restart: back to angle 0 half-way through a block
        let mut blocks = OneXBlocks::new(vec![[0.0, FRAC_PI_2]]);
        let mut n = 0;
        for k in (0..(6 * 16)).chain(0..(6 * 16)) {
            let psi = TAU * k as f64 / 16.0;
            let c = comparison(k, psi, 900.0, lag, PhaseReference::Locked);
            n += add(&mut blocks, &c, &ev).len();
        }
        assert_eq!(
            n, 0,
            "two halves of a block across a restart are not one block"
        );
        // a revolution and a half without a sample: the block starts again after the gap
        let mut blocks = OneXBlocks::new(vec![[0.0, FRAC_PI_2]]);
        let mut got = Vec::new();
        for k in (0..(4 * 16)).chain((4 * 16 + 24)..(14 * 16)) {
            let psi = TAU * k as f64 / 16.0;
            let c = comparison(k, psi, 900.0, lag, PhaseReference::Locked);
            got.extend(add(&mut blocks, &c, &ev));
        }
        assert_eq!(got.len(), 1, "{got:?}");
        assert_eq!(got[0].samples, 8 * 16);
    }
}
