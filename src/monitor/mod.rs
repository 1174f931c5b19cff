//! Per-revolution monitoring of the twin: orbits, rev-to-rev differences of orbit and pressure
//! field (the seed's Fig. 10/11 criterion), order spectrum (1X, dominant sub-synchronous
//! component, forward/backward), and a classification with its evidence. Fed one step at a time;
//! storage is reserved at construction and nothing is allocated per step.

pub mod classify;
mod pressure;
pub mod spectrum;

pub use pressure::PRESSURE_SAMPLES_PER_REV;

pub use classify::{
    AlarmLevels, AlarmOverride, ClassifierSettings, Evidence, RotorState, API_617_CLEARANCE_SHARE,
};

pub use spectrum::{
    interpolate_peak, one_x_component, order_spectrum, subsynchronous_peak, OrderComponent,
};

use crate::dynamics::{StepOutput, Twin};
use pressure::PressureRing;
use serde::Serialize;
use std::f64::consts::TAU;

/// Revolutions in the spectrum window (order resolution 1/16).
pub const SPECTRUM_REVOLUTIONS: usize = 16;
/// Revolutions (of spectrum windows, one a revolution) the growth rate is fitted over.
pub const GROWTH_REVOLUTIONS: usize = 16;
/// Points of the mid-plane pressure profile kept per sampled step ([`PRESSURE_SAMPLES_PER_REV`]).
pub const PRESSURE_POINTS: usize = 60;

/// One bearing over the last revolution (and the spectrum window).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct BearingRevolution {
    /// Peak-to-peak orbit in x (m) over the last whole whirl period ([`span_revolutions`]
    /// revolutions).
    ///
    /// [`span_revolutions`]: Self::span_revolutions
    pub orbit_pp_x_m: f64,
    /// Peak-to-peak orbit in y (m), over the same span.
    pub orbit_pp_y_m: f64,
    /// Revolutions the peak-to-peak values, the largest eccentricity ratio and pressure span:
    /// 1, or ⌈1/r⌉ when a sub-synchronous component of order r is present (above the floor of
    /// [`ClassifierSettings::subsync_floor_clearance_share`]), so that a whole whirl period is
    /// covered (2 for a half-speed whirl).
    pub span_revolutions: usize,
    /// Largest eccentricity ratio over the span.
    pub max_eccentricity_ratio: f64,
    /// 1X semi-major axis (m) over the spectrum window.
    pub one_x_amplitude_m: f64,
    /// Phase of the forward 1X component against the rotor angle (rad).
    pub one_x_phase_rad: f64,
    /// Order of the dominant sub-synchronous component (0 if none).
    pub subsync_ratio: f64,
    /// Its semi-major axis (m).
    pub subsync_amplitude_m: f64,
    /// True if the dominant sub-synchronous component whirls forward.
    pub subsync_forward: bool,
    /// Largest film pressure over the span (Pa).
    pub max_pressure_pa: f64,
    /// Smallest film thickness over the span, c (1 − ε_max) (m; at the contact onset in contact,
    /// where the film is evaluated).
    pub min_film_thickness_m: f64,
    /// The film pressures are within the model's validity: the smallest film thickness is at
    /// least [`crate::dynamics::ContactModel::full_film_min_thickness_m`] (full-film lubrication,
    /// Λ = h_min/σ ≥ 3). False at grazing, where the isoviscous rigid-surface Reynolds pressure
    /// (p ∝ h⁻³ towards the wall) is not a physical figure.
    pub pressure_valid: bool,
    /// RMS distance between the last two revolutions' orbits, sample by sample, over the
    /// clearance.
    pub orbit_diff: f64,
    /// RMS distance from the points of the last revolution's orbit (up to 32, evenly spread) to
    /// the path traced in the two revolutions before it, over the clearance: small when the
    /// journal repeats a closed path (a limit cycle, even one that takes two revolutions),
    /// whatever the timing.
    pub orbit_path_diff: f64,
    /// Relative L2 difference between the last two revolutions' mid-plane pressure fields.
    pub pressure_diff: f64,
    /// The journal touched the wall in the last revolution.
    pub contact: bool,
    /// Contacts begun in the last revolution (steps entering contact; a contact under way at
    /// its start counts once).
    pub contact_events: u32,
    /// Largest penetration beyond the contact onset in the last revolution (m).
    pub max_penetration_m: f64,
    /// The wall spring held the journal inside the bore: the penetration beyond the contact
    /// onset stayed within the film left there, (1 − onset) c, so that ε ≤ 1. False: the journal
    /// centre passed the real wall (the penalty spring is too soft for the load), outside the
    /// wall model's validity.
    pub wall_valid: bool,
    /// Largest rubbing power of the wall contact in the last revolution (W): the Coulomb
    /// friction force times the sliding speed of the surfaces, μ N |ωR + v_t|.
    pub max_rub_power_w: f64,
    /// Rubbing power averaged over the last revolution's steps (W).
    pub mean_rub_power_w: f64,
    /// The journal centre went beyond the clearance circle (ε > 1) without wall contact: a
    /// model without a wall (the linear one) outside its validity.
    pub beyond_clearance: bool,
    /// Orbit amplitude: half the larger peak-to-peak displacement of the last revolution (m).
    pub amplitude_m: f64,
    /// Alert amplitude (m) at this speed ([`AlarmLevels`]).
    pub alert_level_m: f64,
    /// Danger amplitude (m).
    pub danger_level_m: f64,
    /// Growth rate of the non-synchronous motion (1/rev, per shaft revolution): the smaller of
    /// the median revolution-to-revolution increments of the logarithms of the sub-synchronous
    /// semi-major axis and of the rev-to-rev orbit difference over the last [`GROWTH_REVOLUTIONS`] revolutions; None
    /// until that many full spectrum windows are in.
    pub subsync_growth_per_rev: Option<f64>,
    /// At that rate, the time until the sub-synchronous semi-major axis reaches the alert level
    /// (s of model time, at the present speed); None unless it grows (beyond the classifier's
    /// rate), zero once there.
    pub time_to_alert_s: Option<f64>,
    /// This bearing's state.
    pub state: RotorState,
}

/// The report after each completed revolution.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct RevolutionReport {
    /// Completed revolutions.
    pub revolution: u64,
    /// Time at its end (s).
    pub time_s: f64,
    /// Speed (rad/s).
    pub speed_rad_s: f64,
    /// Worst bearing state.
    pub state: RotorState,
    /// Largest orbit difference of the bearings.
    pub rev_to_rev_orbit_diff: f64,
    /// Largest pressure-field difference of the bearings.
    pub rev_to_rev_pressure_diff: f64,
    /// Per bearing.
    pub bearings: Vec<BearingRevolution>,
}

impl RevolutionReport {
    /// A sentence with the evidence for the state (allocates: not for the hot path).
    pub fn evidence(&self) -> String {
        let worst = self.bearings.iter().enumerate().max_by(|a, b| {
            a.1.state.cmp(&b.1.state).then(
                a.1.max_eccentricity_ratio
                    .total_cmp(&b.1.max_eccentricity_ratio),
            )
        });
        // a journal beyond the clearance is named even when another bearing is worse
        let beyond: String = self
            .bearings
            .iter()
            .enumerate()
            .filter(|(k, b)| b.beyond_clearance && Some(*k) != worst.map(|w| w.0))
            .map(|(k, b)| {
                format!(
                    "; bearing {k}: JOURNAL BEYOND THE CLEARANCE at ε = {:.3} (the model knows no wall: outside its validity)",
                    b.max_eccentricity_ratio
                )
            })
            .collect();
        let text = match worst {
            Some((i, b)) => format!(
                "bearing {i}: sub-synchronous {} vs 1X {:.2} µm, max eccentricity {:.3}, rev-to-rev orbit diff {:.2e}, pressure diff {:.2e}{}",
                subsync_words(b.subsync_ratio, b.subsync_amplitude_m),
                b.one_x_amplitude_m * 1e6,
                b.max_eccentricity_ratio,
                b.orbit_diff,
                b.pressure_diff,
                growth_words(b),
            ),
            None => "no bearings".into(),
        };
        text + &beyond
    }
}

/// The sub-synchronous component as reports show it: its size (µm) and order, or "none" when
/// no component stands above the monitor's floor (`subsync_ratio` 0: "at 0.000X" said before).
/// The one wording for `simulate`, `sweep` and the evidence.
pub fn subsync_words(subsync_ratio: f64, subsync_amplitude_m: f64) -> String {
    if subsync_ratio > 0.0 {
        format!("{:.2} µm at {subsync_ratio:.3}X", subsync_amplitude_m * 1e6)
    } else {
        "none".into()
    }
}

/// A growth rate of the sub-synchronous amplitude as reports show it, with its unit: the slope
/// of its logarithm per revolution, or "not yet known" before the monitor has the revolutions.
pub fn growth_words_per_rev(growth_per_rev: Option<f64>) -> String {
    match growth_per_rev {
        Some(g) => format!("{g:+.4} /rev"),
        None => "not yet known".into(),
    }
}

/// The growth, contact and validity clauses of the evidence (allocates).
fn growth_words(b: &BearingRevolution) -> String {
    let mut s = match b.subsync_growth_per_rev {
        Some(g) => format!(", sub-synchronous growth {g:+.4} /rev"),
        None => String::new(),
    };
    if let Some(t) = b.time_to_alert_s {
        s += &format!(", alert level {:.1} µm in {t:.2} s", b.alert_level_m * 1e6);
    }
    s += &format!(
        ", amplitude {:.2} µm (alert {:.1}, danger {:.1} µm)",
        b.amplitude_m * 1e6,
        b.alert_level_m * 1e6,
        b.danger_level_m * 1e6
    );
    if b.contact {
        s += &format!(
            ", wall contact ({} in the revolution, penetration up to {:.2} µm)",
            b.contact_events,
            b.max_penetration_m * 1e6
        );
    }
    if b.beyond_clearance {
        s += ", JOURNAL BEYOND THE CLEARANCE (the model knows no wall: outside its validity)";
    }
    s
}

/// Ring buffers of the recent samples of one bearing.
#[derive(Clone)]
struct BearingHistory {
    clearance_m: f64,
    /// sub-synchronous semi-major axes (m) of the last GROWTH_REVOLUTIONS full windows,
    /// oldest first
    subsync_history: Vec<f64>,
    /// rev-to-rev orbit differences of the last GROWTH_REVOLUTIONS comparable revolutions
    diff_history: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    ecc: Vec<f64>,
    p_max: Vec<f64>,
    contact: Vec<bool>,
    rub_power: Vec<f64>,
}

/// The per-revolution monitor (Clone: the forecast continues a copy of the live one).
#[derive(Clone)]
pub struct Monitor {
    settings: ClassifierSettings,
    capacity: usize,
    /// samples stored (≤ capacity) and the next write position
    len: usize,
    head: usize,
    angle: Vec<f64>,
    bearings: Vec<BearingHistory>,
    /// sample counts of the recent revolutions (newest last)
    rev_lengths: Vec<usize>,
    current_rev_len: usize,
    revolutions: u64,
    /// eccentricity ratio at which the wall takes over
    contact_onset_ratio: f64,
    /// smallest film thickness of full-film lubrication (m), for `pressure_valid`
    full_film_min_thickness_m: f64,
    spectrum: Vec<OrderComponent>,
    /// the spectra's samples (angle, then x and y of each bearing), gathered from the ring
    /// (capacity reserved)
    picked: Vec<f64>,
    /// the path distance's segments (capacity reserved)
    segments: Vec<[f64; 8]>,
    /// the window spectrum's per-revolution sums ([`spectrum::WindowSums`])
    sums: spectrum::WindowSums,
    /// one revolution's picked samples for `sums` (the angle, the weight, then x and y of each
    /// bearing; capacity reserved)
    rev_picked: Vec<f64>,
    /// samples recorded
    samples_total: u64,
    /// the mid-plane pressure profiles, at about PRESSURE_SAMPLES_PER_REV steps a revolution
    pressure: PressureRing,
    report: RevolutionReport,
}

impl Monitor {
    /// A monitor for `twin`, keeping up to `max_steps_per_rev` samples per revolution.
    pub fn new(twin: &Twin, max_steps_per_rev: usize, settings: ClassifierSettings) -> Self {
        let contact = &twin.config().contact;
        Self::with_clearances(
            &twin.bearing_clearances_m(),
            [
                contact.onset_eccentricity_ratio,
                contact.full_film_min_thickness_m,
            ],
            max_steps_per_rev,
            settings,
        )
    }

    /// A monitor of bearings of clearances `clearances` (m), with the wall's `[onset
    /// eccentricity ratio, full-film thickness (m)]`.
    fn with_clearances(
        clearances: &[f64],
        [onset, full_film_m]: [f64; 2],
        max_steps_per_rev: usize,
        settings: ClassifierSettings,
    ) -> Self {
        let capacity = SPECTRUM_REVOLUTIONS * max_steps_per_rev.max(8);
        let bearings = clearances
            .iter()
            .map(|&c| BearingHistory {
                clearance_m: c,
                subsync_history: Vec::with_capacity(GROWTH_REVOLUTIONS),
                diff_history: Vec::with_capacity(GROWTH_REVOLUTIONS),
                x: vec![0.0; capacity],
                y: vec![0.0; capacity],
                ecc: vec![0.0; capacity],
                p_max: vec![0.0; capacity],
                contact: vec![false; capacity],
                rub_power: vec![0.0; capacity],
            })
            .collect::<Vec<_>>();
        let n = bearings.len();
        Self {
            settings,
            capacity,
            len: 0,
            head: 0,
            angle: vec![0.0; capacity],
            bearings,
            rev_lengths: Vec::with_capacity(SPECTRUM_REVOLUTIONS + 1),
            current_rev_len: 0,
            revolutions: 0,
            contact_onset_ratio: onset,
            full_film_min_thickness_m: full_film_m,
            spectrum: vec![OrderComponent::default(); n * SPECTRUM_REVOLUTIONS],
            picked: Vec::with_capacity(capacity * (1 + 2 * n)),
            segments: Vec::with_capacity(capacity),
            sums: spectrum::WindowSums::new(n, SPECTRUM_REVOLUTIONS),
            rev_picked: Vec::with_capacity(capacity * (2 + 2 * n)),
            samples_total: 0,
            pressure: PressureRing::new(n, max_steps_per_rev),
            report: RevolutionReport {
                bearings: vec![BearingRevolution::default(); n],
                ..RevolutionReport::default()
            },
        }
    }

    /// The last revolution's report.
    pub fn report(&self) -> &RevolutionReport {
        &self.report
    }

    /// Sample counts of the last `revs` completed revolutions, summed (capped by what is stored).
    fn recent_samples(&self, revs: usize) -> usize {
        self.rev_lengths
            .iter()
            .rev()
            .take(revs)
            .sum::<usize>()
            .min(self.len)
    }

    /// The orbit `[x, y]` (m) of bearing `bearing` over the last `revs` revolutions, oldest
    /// first (allocates: for reports and plots).
    pub fn recent_orbit(&self, bearing: usize, revs: usize) -> Vec<[f64; 2]> {
        let n = self.recent_samples(revs);
        let h = &self.bearings[bearing];
        (0..n)
            .rev()
            .map(|back| {
                let i = self.idx(back);
                [h.x[i], h.y[i]]
            })
            .collect()
    }

    /// The mid-plane pressure profiles (Pa, PRESSURE_POINTS angles each) of bearing `bearing`
    /// over the last `revs` revolutions, oldest first, about [`PRESSURE_SAMPLES_PER_REV`] a
    /// revolution (allocates).
    pub fn recent_pressure(&self, bearing: usize, revs: usize) -> Vec<Vec<f64>> {
        self.pressure.recent(bearing, revs)
    }

    /// The order spectrum of bearing `bearing` over the window, orders 1/16 … 2 (allocates).
    pub fn full_spectrum(&self, bearing: usize) -> Vec<OrderComponent> {
        let window = self.recent_samples(SPECTRUM_REVOLUTIONS);
        let h = &self.bearings[bearing];
        let idx = |back: usize| ring_index(self.head, self.capacity, back);
        let mut out = vec![OrderComponent::default(); 2 * SPECTRUM_REVOLUTIONS];
        if window > 0 {
            order_spectrum(
                (0..window).map(|k| h.x[idx(window - 1 - k)]),
                (0..window).map(|k| h.y[idx(window - 1 - k)]),
                (0..window).map(|k| self.angle[idx(window - 1 - k)]),
                window,
                SPECTRUM_REVOLUTIONS,
                &mut out,
            );
        }
        out
    }

    /// Records the twin's last step; returns the new report when a revolution was completed.
    pub fn record(&mut self, twin: &Twin) -> Option<&RevolutionReport> {
        let out: &StepOutput = twin.output();
        let slot = self.head;
        let previous_angle = self.previous_angle(out.angle_rad);
        self.angle[slot] = out.angle_rad;
        for (h, b) in self.bearings.iter_mut().zip(&out.bearings) {
            h.x[slot] = b.position_m[0];
            h.y[slot] = b.position_m[1];
            h.ecc[slot] = b.eccentricity_ratio;
            h.p_max[slot] = b.max_pressure_pa;
            h.contact[slot] = b.contact;
            h.rub_power[slot] = b.rub_power_w;
        }
        if self.pressure.due() {
            for k in 0..out.bearings.len().min(self.bearings.len()) {
                twin.midplane_pressure(k, self.pressure.slot_mut(k));
            }
        }
        self.close_sample(previous_angle, out.angle_rad, out.time_s, out.speed_rad_s)
    }

    /// Records a sample of given journal positions `positions_m` (m, one `[x, y]` a bearing, as
    /// the twin's `position_m`) at rotor angle `angle_rad`, with no film pressure, no wall
    /// contact and the eccentricity ratio |position|/c: an orbit of known content (a synthetic
    /// whirl) through the same analysis as [`record`](Self::record). Returns the new report when
    /// a revolution was completed. Bearings beyond `positions_m` keep their old samples.
    pub fn record_orbit(
        &mut self,
        time_s: f64,
        speed_rad_s: f64,
        angle_rad: f64,
        positions_m: &[[f64; 2]],
    ) -> Option<&RevolutionReport> {
        let slot = self.head;
        let previous_angle = self.previous_angle(angle_rad);
        self.angle[slot] = angle_rad;
        for (h, p) in self.bearings.iter_mut().zip(positions_m) {
            h.x[slot] = p[0];
            h.y[slot] = p[1];
            h.ecc[slot] = p[0].hypot(p[1]) / h.clearance_m;
            h.p_max[slot] = 0.0;
            h.contact[slot] = false;
            h.rub_power[slot] = 0.0;
        }
        if self.pressure.due() {
            for k in 0..positions_m.len().min(self.bearings.len()) {
                self.pressure.slot_mut(k).fill(0.0);
            }
        }
        self.close_sample(previous_angle, angle_rad, time_s, speed_rad_s)
    }

    /// The newest stored sample's rotor angle (rad), or `angle_rad` when none is stored.
    fn previous_angle(&self, angle_rad: f64) -> f64 {
        if self.len > 0 {
            self.angle[self.idx(0)]
        } else {
            angle_rad
        }
    }

    /// Advances the ring past the sample just written at `head` (rotor angle `angle_rad`, the
    /// previous sample's `previous_angle`) and analyses the revolution if one was completed.
    fn close_sample(
        &mut self,
        previous_angle: f64,
        angle_rad: f64,
        time_s: f64,
        speed_rad_s: f64,
    ) -> Option<&RevolutionReport> {
        self.head = if self.head + 1 == self.capacity {
            0
        } else {
            self.head + 1
        };
        self.len = (self.len + 1).min(self.capacity);
        self.current_rev_len += 1;
        self.samples_total += 1;
        self.pressure.close_step(angle_rad);
        let completed = (angle_rad / TAU).floor() > (previous_angle / TAU).floor();
        if !completed || self.len < 2 {
            return None;
        }
        if self.rev_lengths.len() == SPECTRUM_REVOLUTIONS + 1 {
            self.rev_lengths.remove(0);
        }
        self.rev_lengths.push(self.current_rev_len);
        self.pressure.close_revolution(self.current_rev_len);
        self.current_rev_len = 0;
        self.revolutions += 1;
        self.analyse(time_s, speed_rad_s);
        Some(&self.report)
    }

    /// Ring index of the sample `back` steps before the newest.
    fn idx(&self, back: usize) -> usize {
        ring_index(self.head, self.capacity, back)
    }

    /// Extremes of the last `last` samples of bearing `bi`: x and y ranges (m), largest
    /// eccentricity ratio and pressure (Pa), contacts begun, largest penetration (m).
    fn last_revolution(&self, bi: usize, last: usize) -> LastRevolution {
        let h = &self.bearings[bi];
        let mut r = LastRevolution {
            x: [f64::MAX, f64::MIN],
            y: [f64::MAX, f64::MIN],
            ..LastRevolution::default()
        };
        for back in 0..last {
            let i = self.idx(back);
            r.x = [r.x[0].min(h.x[i]), r.x[1].max(h.x[i])];
            r.y = [r.y[0].min(h.y[i]), r.y[1].max(h.y[i])];
            r.ecc = r.ecc.max(h.ecc[i]);
            r.p_max = r.p_max.max(h.p_max[i]);
            r.rub_max_w = r.rub_max_w.max(h.rub_power[i]);
            r.rub_sum_w += h.rub_power[i];
            if h.contact[i] {
                r.contact = true;
                let before = back + 1 < last && h.contact[self.idx(back + 1)];
                if !before {
                    r.contact_events += 1;
                }
                r.penetration = r
                    .penetration
                    .max((h.ecc[i] - self.contact_onset_ratio).max(0.0) * h.clearance_m);
            }
        }
        r
    }

    /// Rev-to-rev orbit difference of bearing `bi` (over the clearance): each sample of the
    /// last revolution (`last` samples) against the position at the same shaft angle one
    /// revolution earlier, interpolated by the cubic through the four samples of that
    /// revolution around it (Lagrange, in the angle: a time step that is not a whole fraction
    /// of the revolution, or a speed that changes, leaves no offset, and the interpolation error
    /// is O(Δψ⁴)); NaN when not enough is stored. The pressure difference is the same
    /// comparison on the sampled profiles ([`PressureRing::rev_to_rev`]).
    fn rev_to_rev(&self, bi: usize, last: usize) -> f64 {
        let h = &self.bearings[bi];
        let mut d2 = 0.0;
        let angle = |back: usize| self.angle[self.idx(back)];
        let complete = one_revolution_back(self.len, last, angle, |back, nodes, w| {
            let i = self.idx(back);
            let slots = nodes.map(|n| self.idx(n));
            let at = |v: &[f64]| slots.iter().zip(&w).map(|(&n, w)| w * v[n]).sum::<f64>();
            d2 += (h.x[i] - at(&h.x)).powi(2) + (h.y[i] - at(&h.y)).powi(2);
        });
        match complete {
            true => (d2 / last as f64).sqrt() / h.clearance_m,
            false => f64::NAN,
        }
    }

    /// Path distance of bearing `bi`: each point of the last revolution to the polyline of the
    /// two before, over the clearance; None if not enough is stored.
    fn path_diff(&mut self, bi: usize, last: usize) -> Option<f64> {
        if last <= 1 || self.len < 3 * last {
            return None;
        }
        let h = &self.bearings[bi];
        // the segments from `last` back to 3 last − 1 samples before the newest, gathered once
        // with their bounding boxes: [a, b, x range, y range]
        let segments = &mut self.segments;
        segments.clear();
        segments.extend((last..3 * last - 1).map(|j| {
            let (a, b) = (
                ring_index(self.head, self.capacity, j),
                ring_index(self.head, self.capacity, j + 1),
            );
            let (xa, ya, xb, yb) = (h.x[a], h.y[a], h.x[b], h.y[b]);
            let (x0, x1) = if xa < xb { (xa, xb) } else { (xb, xa) };
            let (y0, y1) = if ya < yb { (ya, yb) } else { (yb, ya) };
            [xa, ya, xb, yb, x0, x1, y0, y1]
        }));
        let distance2 = |px: f64, py: f64, s: &[f64; 8]| {
            point_segment_distance2(px, py, s[0], s[1], s[2], s[3])
        };
        // every point against every segment costs O(n²) a revolution: up to 32 points of the
        // revolution, evenly spread, are compared (all segments are searched)
        let stride = last.div_ceil(32);
        let (mut sum, mut points) = (0.0, 0usize);
        for back in (0..last).step_by(stride) {
            points += 1;
            let p = ring_index(self.head, self.capacity, back);
            let (px, py) = (h.x[p], h.y[p]);
            // the minimum does not depend on the order: first the segments one and two
            // revolutions back (near the point when the path repeats), so that the bounding-box
            // test below skips most of the others
            let mut best = distance2(px, py, &segments[back]).min(distance2(
                px,
                py,
                &segments[(back + last).min(2 * last - 2)],
            ));
            for s in segments.iter() {
                // the squared distance to the segment's bounding box is a lower bound of the
                // distance to the segment: a segment whose box lies beyond the best (with a
                // margin far above the rounding of either) cannot lower the minimum
                let ox = larger(larger(s[4] - px, px - s[5]), 0.0);
                let oy = larger(larger(s[6] - py, py - s[7]), 0.0);
                if ox * ox + oy * oy <= best * (1.0 + 1e-9) {
                    best = best.min(distance2(px, py, s));
                }
            }
            sum += best;
        }
        Some((sum / points as f64).sqrt() / h.clearance_m)
    }

    /// The order spectra of all bearings over the last `window` samples (oldest first) into
    /// `self.spectrum` (SPECTRUM_REVOLUTIONS components a bearing), from at most about 32
    /// samples a revolution: the orders resolved go up to 2, far below that rate's Nyquist order
    /// of 16. From the per-revolution sums ([`spectrum::WindowSums`]: the revolution just
    /// completed summed once) when the window holds SPECTRUM_REVOLUTIONS complete revolutions;
    /// otherwise (the first revolutions, a revolution longer than the ring) from the samples,
    /// one pass for all bearings ([`spectrum::order_spectra`]; each bearing's figures are those
    /// of [`order_spectrum`] on its own orbit, to the last bit).
    fn window_spectra(&mut self, window: usize) {
        let stride = self.spectrum_stride(window);
        self.push_revolution_sums(stride);
        if !self.sums.spectra(&mut self.spectrum) {
            self.samples_spectra(window, stride);
        }
    }

    /// The stride of the spectrum's picks for a window of `window` samples: about 32 a
    /// revolution.
    fn spectrum_stride(&self, window: usize) -> usize {
        let per_rev = window / self.rev_lengths.len().clamp(1, SPECTRUM_REVOLUTIONS);
        per_rev.div_ceil(32).max(1)
    }

    /// The window spectra from the last `window` samples, every `stride`-th from the oldest.
    fn samples_spectra(&mut self, window: usize, stride: usize) {
        let idx = |back: usize| ring_index(self.head, self.capacity, back);
        let picks = window.div_ceil(stride);
        // the picked samples gathered once, oldest first: the angle, then x and y of each
        // bearing
        let picked = &mut self.picked;
        picked.clear();
        for k in 0..picks {
            let i = idx(window - 1 - k * stride);
            picked.push(self.angle[i]);
            for h in &self.bearings {
                picked.extend([h.x[i], h.y[i]]);
            }
        }
        spectrum::order_spectra(
            picked,
            self.bearings.len(),
            SPECTRUM_REVOLUTIONS,
            SPECTRUM_REVOLUTIONS,
            &mut self.spectrum,
        );
    }

    /// Sums the revolution just completed into `self.sums`: its samples whose count since the
    /// start is a multiple of `stride` (the picks continue evenly across revolutions), each
    /// weighted by the angle of its `stride` steps (an angle quadrature: revolutions of
    /// different lengths, or picked at different strides, weigh by their angle). Complete
    /// unless it is the first (partial) revolution, not all of it is stored, or a pick's angle
    /// is not within a factor 2 of the revolution's mean (a shifted rotor angle, e.g. a
    /// keyphasor lock's correction, or a jump: the window then comes from the samples).
    fn push_revolution_sums(&mut self, stride: usize) {
        let last = *self.rev_lengths.last().unwrap_or(&0);
        let stored = last.min(self.len.saturating_sub(stride));
        let mean = TAU * stride as f64 / last.max(1) as f64;
        let mut regular = true;
        let (head, capacity) = (self.head, self.capacity);
        let picked = &mut self.rev_picked;
        picked.clear();
        for back in (0..stored).rev() {
            if !(self.samples_total - 1 - back as u64).is_multiple_of(stride as u64) {
                continue;
            }
            let i = ring_index(head, capacity, back);
            let before = ring_index(head, capacity, back + stride);
            let weight = self.angle[i] - self.angle[before];
            regular &= weight > 0.5 * mean && weight < 2.0 * mean;
            picked.extend([self.angle[i], weight]);
            for h in &self.bearings {
                picked.extend([h.x[i], h.y[i]]);
            }
        }
        let complete = self.revolutions > 1 && stored == last && regular;
        self.sums.push(picked, complete);
    }

    /// Appends a full window's sub-synchronous amplitude and the revolution's orbit difference
    /// (if comparable) to bearing `bi`'s histories and estimates the growth rate: the smaller
    /// of the two median increments of their logarithms (None until GROWTH_REVOLUTIONS amplitudes and half as many
    /// differences are in). Both grow at the rate of an unstable mode; the window spectrum
    /// alone also rises for one window length after a sudden change (a step of unbalance, the
    /// start) while the free vibration it excites already decays, which the orbit difference,
    /// with two revolutions of memory, shows at once. At whip size (`whip_size`: dominant, the
    /// orbit beyond the whip eccentricity) the spectral rate alone: the rev-to-rev difference of
    /// a half-speed whirl compares opposite sides of its orbit (≈ 2 c) and its scatter carries
    /// no growth, while its median increment wandered about −0.002/rev and flipped a steady
    /// 33 µm whip to "stable" and back, revolution by revolution, in a slow run-down.
    fn growth(
        &mut self,
        bi: usize,
        subsync_m: f64,
        orbit_diff: f64,
        whip_size: bool,
    ) -> Option<f64> {
        let h = &mut self.bearings[bi];
        if h.subsync_history.len() == GROWTH_REVOLUTIONS {
            h.subsync_history.remove(0);
        }
        h.subsync_history.push(subsync_m.max(1e-300));
        if orbit_diff.is_finite() {
            if h.diff_history.len() == GROWTH_REVOLUTIONS {
                h.diff_history.remove(0);
            }
            h.diff_history.push(orbit_diff.max(1e-300));
        }
        if h.subsync_history.len() < GROWTH_REVOLUTIONS
            || h.diff_history.len() < GROWTH_REVOLUTIONS / 2
        {
            return None;
        }
        let spectral = classify::log_growth_per_rev(h.subsync_history.iter().copied())?;
        if whip_size {
            return Some(spectral);
        }
        let diff = classify::log_growth_per_rev(h.diff_history.iter().copied())?;
        Some(spectral.min(diff))
    }

    fn analyse(&mut self, time_s: f64, speed_rad_s: f64) {
        let mut state = RotorState::Stable;
        let (mut od, mut pd) = (0.0_f64, 0.0_f64);
        self.window_spectra(self.recent_samples(SPECTRUM_REVOLUTIONS));
        for bi in 0..self.bearings.len() {
            let (b, orbit_diff, pressure_diff) = self.analyse_bearing(bi, speed_rad_s);
            state = state.max(b.state);
            if orbit_diff.is_finite() {
                od = od.max(orbit_diff);
            }
            if pressure_diff.is_finite() {
                pd = pd.max(pressure_diff);
            }
            self.report.bearings[bi] = b;
        }
        self.report.revolution = self.revolutions;
        self.report.time_s = time_s;
        self.report.speed_rad_s = speed_rad_s;
        self.report.state = state;
        self.report.rev_to_rev_orbit_diff = od;
        self.report.rev_to_rev_pressure_diff = pd;
    }

    /// Revolutions of whole whirl periods ending now: one, or for a sub-synchronous component
    /// above the floor at order r < 1, the ⌈1/r⌉ revolutions that hold a whole whirl period
    /// (a half-speed whirl turns once in two revolutions: one revolution sees half of it).
    fn whirl_span(&self, peak: &OrderComponent, clearance_m: f64) -> usize {
        let present =
            peak.semi_major_m() > self.settings.subsync_floor_clearance_share * clearance_m;
        if !(present && peak.order > 0.0 && peak.order < 1.0) {
            return 1;
        }
        ((1.0 / peak.order - 1e-6).ceil() as usize).clamp(1, self.rev_lengths.len().max(1))
    }

    /// Alert and danger amplitudes (m) at this speed, and the time to the alert level at the
    /// growth rate (s of model time), if the component grows beyond the threshold.
    fn alarms(
        &self,
        clearance_m: f64,
        speed_rad_s: f64,
        subsync_m: f64,
        growth: Option<f64>,
    ) -> (f64, f64, Option<f64>) {
        let s = &self.settings;
        let (alert, danger) =
            s.alarm_amplitudes_m(clearance_m, speed_rad_s * 30.0 / std::f64::consts::PI);
        let time_to_alert_s = growth
            .filter(|&g| g > s.growth_threshold_per_rev && speed_rad_s > 0.0)
            .map(|g| (alert / subsync_m).ln().max(0.0) / g * TAU / speed_rad_s);
        (alert, danger, time_to_alert_s)
    }

    /// The report of bearing `bi` for the revolution just completed, with its orbit and
    /// pressure differences (NaN when not comparable).
    fn analyse_bearing(&mut self, bi: usize, speed_rad_s: f64) -> (BearingRevolution, f64, f64) {
        let last = (*self.rev_lengths.last().unwrap_or(&0)).min(self.len);
        // a window shorter than its resolution cannot resolve orders: no verdict on
        // sub-synchronous motion until it holds SPECTRUM_REVOLUTIONS revolutions
        let full_window = self.rev_lengths.len() >= SPECTRUM_REVOLUTIONS;
        let c = self.bearings[bi].clearance_m;
        let spectrum = &self.spectrum[bi * SPECTRUM_REVOLUTIONS..(bi + 1) * SPECTRUM_REVOLUTIONS];
        let one_x = one_x_component(spectrum, SPECTRUM_REVOLUTIONS);
        let peak = subsynchronous_peak(spectrum, SPECTRUM_REVOLUTIONS);
        let subsync_m = peak.semi_major_m();
        let span = self.whirl_span(&peak, c);
        let r = self.last_revolution(bi, self.recent_samples(span));
        let rub = self.last_revolution(bi, last);
        let orbit_diff = self.rev_to_rev(bi, last);
        let pressure_diff = self.pressure.rev_to_rev(bi);
        let old = self.report.bearings[bi];
        let path_diff = self.path_diff(bi, last).unwrap_or(old.orbit_path_diff);
        let s = self.settings;
        // a journal beyond the clearance without a wall (the linear model) is outside the
        // model's validity: flagged, and never called a whip on its eccentricity alone
        let beyond_clearance = r.ecc > 1.0 && !rub.contact;
        let dominant = full_window && s.subsync_counts(subsync_m, one_x.semi_major_m(), c);
        let whip_size = dominant && !beyond_clearance && r.ecc > s.whip_eccentricity_ratio;
        let growth = full_window
            .then(|| self.growth(bi, subsync_m, orbit_diff, whip_size))
            .flatten();
        let b_state = s.classify(&Evidence {
            clearance_m: c,
            subsync_m,
            one_x_m: one_x.semi_major_m(),
            max_eccentricity_ratio: if beyond_clearance { 0.0 } else { r.ecc },
            full_window,
            growth_per_rev: growth,
            previous: old.state,
        });
        let (alert, danger, time_to_alert_s) = self.alarms(c, speed_rad_s, subsync_m, growth);
        let (pp_x, pp_y) = ((r.x[1] - r.x[0]).max(0.0), (r.y[1] - r.y[0]).max(0.0));
        let min_film = (1.0 - r.ecc.min(self.contact_onset_ratio)).max(0.0) * c;
        let b = BearingRevolution {
            orbit_pp_x_m: pp_x,
            orbit_pp_y_m: pp_y,
            span_revolutions: span,
            max_eccentricity_ratio: r.ecc,
            one_x_amplitude_m: one_x.semi_major_m(),
            one_x_phase_rad: one_x.forward_phase_rad,
            subsync_ratio: if dominant { peak.order } else { 0.0 },
            subsync_amplitude_m: subsync_m,
            subsync_forward: peak.forward_m >= peak.backward_m,
            max_pressure_pa: r.p_max,
            min_film_thickness_m: min_film,
            pressure_valid: min_film >= self.full_film_min_thickness_m,
            orbit_path_diff: path_diff,
            // not comparable (too little stored): keep the last value
            orbit_diff: if orbit_diff.is_finite() {
                orbit_diff
            } else {
                old.orbit_diff
            },
            pressure_diff: if pressure_diff.is_finite() {
                pressure_diff
            } else {
                old.pressure_diff
            },
            contact: rub.contact,
            contact_events: rub.contact_events,
            max_penetration_m: rub.penetration,
            // the film the onset leaves: deeper, the journal centre is past the real wall
            wall_valid: rub.penetration <= (1.0 - self.contact_onset_ratio) * c,
            max_rub_power_w: rub.rub_max_w,
            mean_rub_power_w: rub.rub_sum_w / last.max(1) as f64,
            beyond_clearance,
            amplitude_m: 0.5 * pp_x.max(pp_y),
            alert_level_m: alert,
            danger_level_m: danger,
            subsync_growth_per_rev: growth,
            time_to_alert_s,
            state: b_state,
        };
        (b, orbit_diff, pressure_diff)
    }
}

/// The extremes of one bearing's last revolution.
#[derive(Debug, Clone, Copy, Default)]
struct LastRevolution {
    x: [f64; 2],
    y: [f64; 2],
    ecc: f64,
    p_max: f64,
    contact: bool,
    contact_events: u32,
    penetration: f64,
    rub_max_w: f64,
    rub_sum_w: f64,
}

/// Ring position of the sample `back` (< 2 `capacity`) steps before the newest, the newest at
/// `head` − 1: (head + 2 capacity − 1 − back) mod capacity, by subtraction (the value lies in
/// [0, 3 capacity)): the monitor indexes its ring tens of thousands of times a revolution, and
/// an integer division costs tens of cycles.
fn ring_index(head: usize, capacity: usize, back: usize) -> usize {
    debug_assert!(head < capacity && back < 2 * capacity);
    let v = head + 2 * capacity - 1 - back;
    if v >= 2 * capacity {
        v - 2 * capacity
    } else if v >= capacity {
        v - capacity
    } else {
        v
    }
}

/// Walks the last revolution of a ring of `len` samples (`last` of them, newest first, by
/// look-back) against the same shaft angle one revolution earlier: for each, `visit(back,
/// nodes, weights)` with the four look-backs of the earlier revolution around that angle and
/// their cubic Lagrange weights in the angle (`angle(back)`, rad). False (and the walk stopped)
/// when not enough is stored.
fn one_revolution_back(
    len: usize,
    last: usize,
    angle: impl Fn(usize) -> f64,
    mut visit: impl FnMut(usize, [usize; 4], [f64; 4]),
) -> bool {
    if last == 0 || len < last + 4 {
        return false;
    }
    // k: the newer of the two samples of the earlier revolution that bracket the target
    let mut k = last.saturating_sub(1).max(1);
    for back in 0..last {
        let target = angle(back) - TAU;
        while k + 2 < len && angle(k + 1) > target {
            k += 1;
        }
        if k + 2 >= len || angle(k) < target {
            return false;
        }
        let nodes = [k - 1, k, k + 1, k + 2];
        visit(back, nodes, lagrange_weights(nodes.map(&angle), target));
    }
    true
}

/// Weights of the cubic Lagrange interpolant through nodes `x` (distinct) at `t`.
fn lagrange_weights(x: [f64; 4], t: f64) -> [f64; 4] {
    let mut w = [1.0; 4];
    for (i, wi) in w.iter_mut().enumerate() {
        for (j, xj) in x.iter().enumerate() {
            if i != j {
                *wi *= (t - xj) / (x[i] - xj);
            }
        }
    }
    w
}

/// The larger of `a` and `b` (either when equal; for finite values: no NaN handling).
fn larger(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// Squared distance from point (px, py) to the segment (ax, ay)–(bx, by).
fn point_segment_distance2(px: f64, py: f64, ax: f64, ay: f64, bx: f64, by: f64) -> f64 {
    let (dx, dy) = (bx - ax, by - ay);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((px - ax) * dx + (py - ay) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (cx, cy) = (ax + t * dx - px, ay + t * dy - py);
    cx * cx + cy * cy
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A monitor of two bearings of 60 µm clearance fed `revs` revolutions of a synthetic
    /// orbit at `per_rev` samples a revolution (a step a little off a whole fraction of the
    /// revolution): a 1X ellipse, a half-speed forward whirl and a slow drift, different in
    /// the two bearings; `check` is called after each completed revolution.
    fn feed(per_rev: usize, revs: usize, mut check: impl FnMut(&Monitor)) {
        let c = 60e-6;
        let mut m = Monitor::with_clearances(
            &[c, c],
            [0.95, 1e-6],
            2 * per_rev,
            ClassifierSettings::default(),
        );
        let dpsi = TAU / (per_rev as f64 + 0.37);
        for i in 0..(revs as f64 * (per_rev as f64 + 0.37)) as usize {
            let psi = i as f64 * dpsi;
            let orbit = |k: f64| {
                let (one, half, drift) = (3e-6 * k, 12e-6 / k, 1.0 + 1e-3 * psi);
                [
                    one * psi.cos() + half * drift * (0.48 * psi).cos(),
                    0.6 * one * psi.sin() + half * drift * (0.48 * psi).sin(),
                ]
            };
            if m.record_orbit(psi / 942.5, 942.5, psi, &[orbit(1.0), orbit(1.7)])
                .is_some()
            {
                check(&m);
            }
        }
    }

    /// Path distance of bearing `bi`, every point against every segment (the monitor's
    /// computation before the bounding-box test).
    fn path_diff_all_segments(m: &Monitor, bi: usize, last: usize) -> Option<f64> {
        let h = &m.bearings[bi];
        if last <= 1 || m.len < 3 * last {
            return None;
        }
        let stride = last.div_ceil(32);
        let (mut sum, mut points) = (0.0, 0usize);
        for back in (0..last).step_by(stride) {
            points += 1;
            let p = m.idx(back);
            let mut best = f64::MAX;
            for j in last..3 * last - 1 {
                let (a, b) = (m.idx(j), m.idx(j + 1));
                best = best.min(point_segment_distance2(
                    h.x[p], h.y[p], h.x[a], h.y[a], h.x[b], h.y[b],
                ));
            }
            sum += best;
        }
        Some((sum / points as f64).sqrt() / h.clearance_m)
    }

    /// The path distance with the segments' bounding boxes skipped is the minimum over all
    /// segments to the last bit (a minimum does not depend on the order, and the test skips
    /// only segments that cannot lower it), for every revolution of a whirling orbit at 64 and
    /// 128 samples a revolution, both bearings; and it is not trivially zero (the drift).
    #[test]
    fn path_distance_with_bounding_boxes_is_the_full_minimum() {
        for per_rev in [64, 128] {
            let mut compared = 0;
            feed(per_rev, 40, |m| {
                let last = *m.rev_lengths.last().unwrap_or(&0);
                for bi in 0..2 {
                    let all = path_diff_all_segments(m, bi, last);
                    let pruned = m.clone().path_diff(bi, last);
                    assert_eq!(pruned, all, "{per_rev} a revolution, bearing {bi}");
                    if let Some(d) = all {
                        assert!(d > 1e-6, "path distance {d}");
                        compared += 1;
                    }
                }
            });
            // 40 revolutions, the first few without three stored
            assert!(compared >= 2 * 36, "{compared} comparisons");
        }
    }

    /// The joint spectra of the bearings from the samples equal each bearing's own
    /// [`order_spectrum`] to the last bit (the same sums in the same order), over a full window
    /// of the synthetic orbit; the monitor's spectra from the per-revolution sums (from the
    /// 17th revolution on) agree with them within 2e-3 of the largest component (measured
    /// 7.4e-4 at 64.37 samples a revolution; the picks differ: those of the sums continue
    /// evenly across revolutions, the samples' start at the window's first sample, and the
    /// window is in angle instead of pick index over a window of 514–515 picks, not 512).
    #[test]
    fn joint_spectra_equal_each_bearings_spectrum() {
        let mut from_sums = 0;
        feed(64, 24, |m| {
            let window = m.recent_samples(SPECTRUM_REVOLUTIONS);
            let mut old = m.clone();
            old.samples_spectra(window, m.spectrum_stride(window));
            for bi in 0..2 {
                let own = m.full_spectrum(bi);
                let picked = &old.picked;
                let mut single = vec![OrderComponent::default(); SPECTRUM_REVOLUTIONS];
                let rows = picked.len() / 5;
                order_spectrum(
                    (0..rows).map(|r| picked[5 * r + 1 + 2 * bi]),
                    (0..rows).map(|r| picked[5 * r + 2 + 2 * bi]),
                    (0..rows).map(|r| picked[5 * r]),
                    rows,
                    SPECTRUM_REVOLUTIONS,
                    &mut single,
                );
                let range = bi * SPECTRUM_REVOLUTIONS..(bi + 1) * SPECTRUM_REVOLUTIONS;
                assert_eq!(&old.spectrum[range.clone()], &single[..], "bearing {bi}");
                let largest = single.iter().map(|c| c.forward_m.max(c.backward_m));
                let largest = largest.fold(0.0, f64::max);
                let worst = m.spectrum[range]
                    .iter()
                    .zip(&single)
                    .map(|(a, b)| {
                        let d = (a.forward_m - b.forward_m).abs();
                        d.max((a.backward_m - b.backward_m).abs()) / largest
                    })
                    .fold(0.0, f64::max);
                if m.revolutions > SPECTRUM_REVOLUTIONS as u64 {
                    from_sums += 1;
                    eprintln!(
                        "rev {} bearing {bi}: sums against samples {worst:.2e}",
                        m.revolutions
                    );
                    assert!(worst < 2e-3, "bearing {bi}: {worst:e} of the largest");
                } else {
                    assert_eq!(worst, 0.0, "the first revolutions come from the samples");
                }
                // and the 1X of the whole window is the 3 µm (× 1, 1.7) ellipse's, within 5 %
                let one_x = one_x_component(&own, SPECTRUM_REVOLUTIONS).semi_major_m();
                let expected = 3e-6 * [1.0, 1.7][bi];
                if window >= SPECTRUM_REVOLUTIONS * 64 {
                    assert!((one_x / expected - 1.0).abs() < 0.05, "1X {one_x}");
                }
            }
        });
        assert!(from_sums >= 2 * 6, "{from_sums} windows from the sums");
    }

    /// (b) at the monitor: a run-up at a fixed time step, 80 samples a revolution falling to
    /// 48 over 40 revolutions, then a step to 40 held for 30, of a forward 1X circle of 3 µm and
    /// a forward 0.47X one of 5 µm (both bearings). From the 17th revolution on (the sums) the
    /// 1X semi-major axis and the sub-synchronous one are within 1 % of the orbit's in every
    /// revolution (measured 0.57 % and 0.37 %); the old path on the same samples is off by up to
    /// 1.6 % and 1.6 % (its window in pick index, uneven in angle in a ramp).
    #[test]
    fn the_window_sums_follow_a_run_up_and_a_speed_step() {
        let c = 60e-6;
        let mut m =
            Monitor::with_clearances(&[c, c], [0.95, 1e-6], 96, ClassifierSettings::default());
        let (mut psi, mut new, mut old) = (0.1, [0.0_f64; 2], [0.0_f64; 2]);
        let errors = |s: &[OrderComponent]| {
            let one = one_x_component(s, SPECTRUM_REVOLUTIONS).semi_major_m() / 3e-6 - 1.0;
            let sub = subsynchronous_peak(s, SPECTRUM_REVOLUTIONS).semi_major_m() / 5e-6 - 1.0;
            [one.abs(), sub.abs()]
        };
        while psi < 70.0 * TAU {
            let revs = psi / TAU;
            psi += TAU
                / if revs < 40.0 {
                    80.0 - 32.0 * revs / 40.0
                } else {
                    40.0
                };
            let orbit = [
                3e-6 * psi.cos() + 5e-6 * (0.47 * psi).cos(),
                3e-6 * psi.sin() + 5e-6 * (0.47 * psi).sin(),
            ];
            if m.record_orbit(psi / 900.0, 900.0, psi, &[orbit, orbit])
                .is_none()
                || m.revolutions <= SPECTRUM_REVOLUTIONS as u64
            {
                continue;
            }
            let window = m.recent_samples(SPECTRUM_REVOLUTIONS);
            let mut samples = m.clone();
            samples.samples_spectra(window, m.spectrum_stride(window));
            let range = 0..SPECTRUM_REVOLUTIONS;
            for (t, e) in new.iter_mut().zip(errors(&m.spectrum[range.clone()])) {
                *t = t.max(e);
            }
            for (t, e) in old.iter_mut().zip(errors(&samples.spectrum[range])) {
                *t = t.max(e);
            }
        }
        eprintln!("run-up and step, 1X and sub-synchronous: sums {new:?}, samples {old:?}");
        assert!(new.iter().all(|&e| e < 0.01), "{new:?}");
    }

    /// A rotor angle shifted by −1 rad at the end of revolution 30 (a keyphasor correction):
    /// the windows holding the revolution of the shift come from the samples (equal to the
    /// samples' path to the bit), the ones after it from the sums again (within 2e-3 of the
    /// largest radius of the samples' path, as in `joint_spectra_equal_each_bearings_spectrum`;
    /// measured up to 1.04e-3 on this orbit).
    #[test]
    fn after_an_angle_shift_the_window_comes_from_the_samples() {
        let c = 60e-6;
        let mut m =
            Monitor::with_clearances(&[c, c], [0.95, 1e-6], 128, ClassifierSettings::default());
        let (dpsi, mut shift, mut checked) = (TAU / 64.37, 0.0, [0, 0]);
        for i in 0..60 * 64 {
            let psi = i as f64 * dpsi;
            let orbit = [
                3e-6 * psi.cos() + 5e-6 * (0.47 * psi).cos(),
                3e-6 * psi.sin(),
            ];
            if m.record_orbit(psi / 900.0, 900.0, psi + shift, &[orbit, orbit])
                .is_none()
            {
                continue;
            }
            if m.revolutions == 30 {
                shift = -1.0;
            }
            let window = m.recent_samples(SPECTRUM_REVOLUTIONS);
            let mut samples = m.clone();
            samples.samples_spectra(window, m.spectrum_stride(window));
            let largest = samples.spectrum.iter().map(OrderComponent::semi_major_m);
            let largest = largest.fold(0.0, f64::max);
            let apart = m.spectrum.iter().zip(&samples.spectrum).map(|(a, b)| {
                (a.forward_m - b.forward_m)
                    .abs()
                    .max((a.backward_m - b.backward_m).abs())
            });
            let apart = apart.fold(0.0, f64::max) / largest;
            let r = m.revolutions;
            if (31..=46).contains(&r) {
                assert_eq!(apart, 0.0, "revolution {r}: from the samples");
                checked[0] += 1;
            } else if r >= 47 {
                assert!(apart > 0.0 && apart < 2e-3, "revolution {r}: {apart:e}");
                checked[1] += 1;
            }
        }
        assert!(checked[0] >= 16 && checked[1] >= 5, "{checked:?}");
    }

    /// The profiles kept: 32 a revolution at 64 and 128 steps a revolution (every second or
    /// fourth step), 31–33 at 100 (every third: 100.37/3), over the two revolutions a pressure
    /// map shows.
    #[test]
    fn pressure_profiles_are_kept_32_a_revolution() {
        for (per_rev, lo, hi) in [(64, 64, 66), (128, 64, 66), (100, 64, 68)] {
            let mut last = 0;
            feed(per_rev, 10, |m| last = m.recent_pressure(0, 2).len());
            assert!(
                (lo..=hi).contains(&last),
                "{per_rev}: {last} profiles in two revolutions"
            );
        }
    }

    /// The ring position by subtraction is the remainder the monitor took before, (head + 2
    /// capacity − 1 − back) mod capacity, for every head and every look-back it uses (under
    /// two capacities), for rings of one to 40 slots.
    #[test]
    fn ring_index_is_the_remainder() {
        for capacity in 1..=40 {
            for head in 0..capacity {
                for back in 0..2 * capacity {
                    assert_eq!(
                        ring_index(head, capacity, back),
                        (head + 2 * capacity - 1 - back) % capacity,
                        "head {head}, back {back}, capacity {capacity}"
                    );
                }
            }
        }
    }
}
