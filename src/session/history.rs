//! The twin's recent probe-station outputs (issue 12): a fixed ring of the last steps' predicted
//! displacements and shaft angles, so that a probe sample delivered late (in a burst, after the
//! twin has stepped on) is compared with the prediction at its own stamp, linear between the two
//! steps that bracket it, not with the newest step's. Allocated once when the session starts;
//! a step writes in place (the time step allocates nothing).

/// How far back (s of model time) the outputs are kept: 0.1 s, the delivery jitter the keyphasor
/// stop allows (`signals::KEYPHASOR_JITTER_S`) and over twice the 41 ms bursts measured with the
/// rclpy peer. A sample older than that is compared with the oldest kept step.
pub const PREDICTION_HISTORY_S: f64 = 0.1;

/// Most steps kept whatever the step (8,192: 0.1 s down to 12 µs steps).
pub const PREDICTION_HISTORY_MAX_STEPS: usize = 8192;

/// The ring: per step its model time (s), shaft angle (rad) and each station's displacement (m).
#[derive(Debug, Clone)]
pub(super) struct ProbeHistory {
    stations: usize,
    times: Vec<f64>,
    angles: Vec<f64>,
    probes: Vec<[f64; 2]>,
    /// physical index of the oldest entry, and the number held
    oldest: usize,
    len: usize,
}

impl ProbeHistory {
    /// A ring for `stations` stations and steps of `time_step_s`.
    pub(super) fn new(stations: usize, time_step_s: f64) -> Self {
        let steps = (PREDICTION_HISTORY_S / time_step_s.max(1e-12)).ceil() as usize + 2;
        let cap = steps.clamp(2, PREDICTION_HISTORY_MAX_STEPS);
        Self {
            stations,
            times: vec![0.0; cap],
            angles: vec![0.0; cap],
            probes: vec![[0.0; 2]; cap * stations],
            oldest: 0,
            len: 0,
        }
    }

    /// Physical index of the `i`-th entry (i < len), wrapped by subtraction (no division).
    fn slot(&self, i: usize) -> usize {
        let (v, cap) = (self.oldest + i, self.times.len());
        if v >= cap {
            v - cap
        } else {
            v
        }
    }

    /// Appends one step's outputs (the oldest is overwritten when full).
    pub(super) fn push(
        &mut self,
        time_s: f64,
        angle_rad: f64,
        probes: impl Iterator<Item = [f64; 2]>,
    ) {
        let cap = self.times.len();
        let at = if self.len < cap {
            self.len += 1;
            self.slot(self.len - 1)
        } else {
            let at = self.oldest;
            self.oldest = if self.oldest + 1 == cap {
                0
            } else {
                self.oldest + 1
            };
            at
        };
        self.times[at] = time_s;
        self.angles[at] = angle_rad;
        let row = &mut self.probes[at * self.stations..(at + 1) * self.stations];
        for (r, p) in row.iter_mut().zip(probes) {
            *r = p;
        }
    }

    /// Turns every kept angle by `delta_rad` (the keyphasor lock turns the twin's frame).
    pub(super) fn shift_angles(&mut self, delta_rad: f64) {
        for a in &mut self.angles {
            *a += delta_rad;
        }
    }

    /// Station `station`'s displacement (m) and the shaft angle (rad) at model time `time_s`:
    /// linear between the kept steps that bracket it, clamped to the oldest and the newest.
    pub(super) fn at(&self, station: usize, time_s: f64) -> Option<([f64; 2], f64)> {
        if station >= self.stations || self.len == 0 {
            return None;
        }
        // the first logical index whose time is after time_s
        let (mut lo, mut hi) = (0, self.len);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.times[self.slot(mid)] <= time_s {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let (i0, i1) = match lo {
            0 => (0, 0),
            n if n == self.len => (n - 1, n - 1),
            n => (n - 1, n),
        };
        let (a, b) = (self.slot(i0), self.slot(i1));
        let span = self.times[b] - self.times[a];
        let u = if span > 0.0 {
            ((time_s - self.times[a]) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let lerp = |p: f64, q: f64| p + u * (q - p);
        let (pa, pb) = (
            self.probes[a * self.stations + station],
            self.probes[b * self.stations + station],
        );
        Some((
            [lerp(pa[0], pb[0]), lerp(pa[1], pb[1])],
            lerp(self.angles[a], self.angles[b]),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ring of 0.1 s at 10 ms steps (12 kept) holding x = t, angle = 2t: any time within
    /// the kept span reads back exactly (linear data, linear interpolation), before it the
    /// oldest kept, after it the newest; the ring wraps without losing order.
    #[test]
    fn reads_any_kept_time_and_clamps_outside() {
        let mut h = ProbeHistory::new(2, 0.01);
        for k in 0..40 {
            let t = 0.01 * k as f64;
            h.push(t, 2.0 * t, [[t, -t], [3.0 * t, 0.0]].into_iter());
        }
        assert_eq!(h.len, 12);
        let newest = 0.39;
        let oldest = newest - 0.01 * 11.0;
        for t in [oldest, 0.3051, 0.33333, newest - 0.004, newest] {
            let (p, a) = h.at(0, t).unwrap();
            assert!(
                (p[0] - t).abs() < 1e-12 && (p[1] + t).abs() < 1e-12,
                "{t}: {p:?}"
            );
            assert!((a - 2.0 * t).abs() < 1e-12);
            assert!((h.at(1, t).unwrap().0[0] - 3.0 * t).abs() < 1e-12);
        }
        assert!((h.at(0, 0.1).unwrap().0[0] - oldest).abs() < 1e-12);
        assert!((h.at(0, 5.0).unwrap().0[0] - newest).abs() < 1e-12);
        assert!(h.at(2, 0.3).is_none());
        h.shift_angles(1.0);
        assert!((h.at(0, 0.35).unwrap().1 - 1.7).abs() < 1e-12);
    }
}
