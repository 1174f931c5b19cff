//! The mid-plane pressure profiles the monitor keeps: at most about
//! [`PRESSURE_SAMPLES_PER_REV`] a revolution (every `stride`-th step, the stride set at each
//! revolution from the last one's steps), in a ring of a few revolutions. The profile is the
//! dearest thing the monitor took at every step (the tabulated film's blend of four nodes'
//! profiles, 10,000 instructions a bearing, twice the rest of the monitor's step), and it
//! serves only the revolution-to-revolution pressure difference (a published figure, not
//! evidence of the classifier) and the pressure maps of the last two revolutions.

use super::{one_revolution_back, ring_index, PRESSURE_POINTS};

/// Pressure profiles kept a revolution (about: the stride is the nearest whole number of steps).
pub const PRESSURE_SAMPLES_PER_REV: usize = 32;

/// Revolutions of profiles the ring holds (the difference reads the last two and four more).
const RING_REVOLUTIONS: usize = 3;

/// The profiles of every bearing at the sampled steps, with their rotor angles.
#[derive(Clone)]
pub(super) struct PressureRing {
    capacity: usize,
    len: usize,
    head: usize,
    angle: Vec<f64>,
    /// per bearing: PRESSURE_POINTS values a slot
    profiles: Vec<Vec<f64>>,
    /// profiles taken in the recent completed revolutions (newest last)
    rev_counts: Vec<usize>,
    current: usize,
    stride: usize,
    /// steps to pass before the next profile
    countdown: usize,
}

impl PressureRing {
    /// A ring for `bearings` bearings; `max_steps_per_rev` (the monitor's hint, twice the
    /// expected steps in the node) sets the first revolution's stride.
    pub(super) fn new(bearings: usize, max_steps_per_rev: usize) -> Self {
        // a stride rounded to the nearest step gives at most 1.5 × 32 profiles a revolution
        let capacity = RING_REVOLUTIONS * (3 * PRESSURE_SAMPLES_PER_REV).div_ceil(2) + 8;
        Self {
            capacity,
            len: 0,
            head: 0,
            angle: vec![0.0; capacity],
            profiles: vec![vec![0.0; capacity * PRESSURE_POINTS]; bearings],
            rev_counts: Vec::with_capacity(RING_REVOLUTIONS + 1),
            current: 0,
            stride: max_steps_per_rev
                .div_ceil(2 * PRESSURE_SAMPLES_PER_REV)
                .max(1),
            countdown: 0,
        }
    }

    /// Whether this step's profile is to be taken.
    pub(super) fn due(&self) -> bool {
        self.countdown == 0
    }

    /// The slot of bearing `bearing`'s profile for this step (when [`due`](Self::due)).
    pub(super) fn slot_mut(&mut self, bearing: usize) -> &mut [f64] {
        let s = self.head * PRESSURE_POINTS;
        &mut self.profiles[bearing][s..s + PRESSURE_POINTS]
    }

    /// Closes a step at rotor angle `angle_rad`: keeps the profiles written if it was due.
    pub(super) fn close_step(&mut self, angle_rad: f64) {
        if self.countdown > 0 {
            self.countdown -= 1;
            return;
        }
        self.angle[self.head] = angle_rad;
        self.head = if self.head + 1 == self.capacity {
            0
        } else {
            self.head + 1
        };
        self.len = (self.len + 1).min(self.capacity);
        self.current += 1;
        self.countdown = self.stride - 1;
    }

    /// Closes a revolution of `steps` steps: its profile count is kept and the stride set to
    /// the nearest whole number of steps giving PRESSURE_SAMPLES_PER_REV a revolution.
    pub(super) fn close_revolution(&mut self, steps: usize) {
        if self.rev_counts.len() == RING_REVOLUTIONS {
            self.rev_counts.remove(0);
        }
        self.rev_counts.push(self.current);
        self.current = 0;
        self.stride = ((steps + PRESSURE_SAMPLES_PER_REV / 2) / PRESSURE_SAMPLES_PER_REV).max(1);
        self.countdown = self.countdown.min(self.stride - 1);
    }

    fn idx(&self, back: usize) -> usize {
        ring_index(self.head, self.capacity, back)
    }

    /// Profiles of the last `revs` completed revolutions, capped by what is stored.
    fn recent_count(&self, revs: usize) -> usize {
        self.rev_counts
            .iter()
            .rev()
            .take(revs)
            .sum::<usize>()
            .min(self.len)
    }

    /// Bearing `bearing`'s profiles of the last `revs` revolutions, oldest first (allocates).
    pub(super) fn recent(&self, bearing: usize, revs: usize) -> Vec<Vec<f64>> {
        let p = &self.profiles[bearing];
        (0..self.recent_count(revs))
            .rev()
            .map(|back| {
                let i = self.idx(back);
                p[i * PRESSURE_POINTS..(i + 1) * PRESSURE_POINTS].to_vec()
            })
            .collect()
    }

    /// Relative L2 difference of bearing `bearing`'s last revolution of profiles against the
    /// one before: each profile against the profile at the same shaft angle one revolution
    /// earlier, interpolated by the cubic through the four profiles of that revolution around
    /// it (Lagrange, in the angle, as the orbit difference); NaN when not enough is stored.
    pub(super) fn rev_to_rev(&self, bearing: usize) -> f64 {
        let last = self.rev_counts.last().map_or(0, |&n| n.min(self.len));
        let h = &self.profiles[bearing];
        let angle = |back: usize| self.angle[self.idx(back)];
        let (mut pd2, mut p2) = (0.0, 0.0);
        let complete = one_revolution_back(self.len, last, angle, |back, nodes, w| {
            let i = self.idx(back);
            let a = &h[i * PRESSURE_POINTS..(i + 1) * PRESSURE_POINTS];
            let profiles = nodes.map(|n| {
                let s = self.idx(n) * PRESSURE_POINTS;
                &h[s..s + PRESSURE_POINTS]
            });
            for (m, u) in a.iter().enumerate() {
                let v: f64 = profiles.iter().zip(&w).map(|(p, w)| w * p[m]).sum();
                pd2 += (u - v).powi(2);
                p2 += u * u;
            }
        });
        if !complete {
            return f64::NAN;
        }
        if p2 > 0.0 {
            (pd2 / p2).sqrt()
        } else {
            0.0
        }
    }
}
