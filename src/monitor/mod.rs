//! Per-revolution monitoring of the twin: orbits, rev-to-rev differences of orbit and pressure
//! field (the seed's Fig. 10/11 criterion), order spectrum (1X, dominant sub-synchronous
//! component, forward/backward), and a classification with its evidence. Fed one step at a time;
//! storage is reserved at construction and nothing is allocated per step.

pub mod classify;
pub mod spectrum;

pub use classify::{
    AlarmLevels, AlarmOverride, ClassifierSettings, Evidence, RotorState, API_617_CLEARANCE_SHARE,
};

pub use spectrum::{
    interpolate_peak, one_x_component, order_spectrum, subsynchronous_peak, OrderComponent,
};

use crate::dynamics::{StepOutput, Twin};
use serde::Serialize;
use std::f64::consts::TAU;

/// Revolutions in the spectrum window (order resolution 1/16).
pub const SPECTRUM_REVOLUTIONS: usize = 16;
/// Revolutions (of spectrum windows, one a revolution) the growth rate is fitted over.
pub const GROWTH_REVOLUTIONS: usize = 16;
/// Points of the mid-plane pressure profile kept per step.
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
    /// mid-plane pressure profile per sample (PRESSURE_POINTS each)
    pressure: Vec<f64>,
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
    /// the spectrum's samples (x, y, angle), gathered from the ring (capacity reserved)
    picked: Vec<[f64; 3]>,
    profile: Vec<f64>,
    report: RevolutionReport,
}

impl Monitor {
    /// A monitor for `twin`, keeping up to `max_steps_per_rev` samples per revolution.
    pub fn new(twin: &Twin, max_steps_per_rev: usize, settings: ClassifierSettings) -> Self {
        let capacity = SPECTRUM_REVOLUTIONS * max_steps_per_rev.max(8);
        let clearances = twin.bearing_clearances_m();
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
                pressure: vec![0.0; capacity * PRESSURE_POINTS],
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
            contact_onset_ratio: twin.config().contact.onset_eccentricity_ratio,
            full_film_min_thickness_m: twin.config().contact.full_film_min_thickness_m,
            spectrum: vec![OrderComponent::default(); SPECTRUM_REVOLUTIONS],
            picked: Vec::with_capacity(capacity),
            profile: vec![0.0; PRESSURE_POINTS],
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
    /// over the last `revs` revolutions, oldest first (allocates).
    pub fn recent_pressure(&self, bearing: usize, revs: usize) -> Vec<Vec<f64>> {
        let n = self.recent_samples(revs);
        let h = &self.bearings[bearing];
        (0..n)
            .rev()
            .map(|back| {
                let i = self.idx(back);
                h.pressure[i * PRESSURE_POINTS..(i + 1) * PRESSURE_POINTS].to_vec()
            })
            .collect()
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
        for (k, (h, b)) in self.bearings.iter_mut().zip(&out.bearings).enumerate() {
            h.x[slot] = b.position_m[0];
            h.y[slot] = b.position_m[1];
            h.ecc[slot] = b.eccentricity_ratio;
            h.p_max[slot] = b.max_pressure_pa;
            h.contact[slot] = b.contact;
            h.rub_power[slot] = b.rub_power_w;
            twin.midplane_pressure(k, &mut self.profile);
            h.pressure[slot * PRESSURE_POINTS..(slot + 1) * PRESSURE_POINTS]
                .copy_from_slice(&self.profile);
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
            h.pressure[slot * PRESSURE_POINTS..(slot + 1) * PRESSURE_POINTS].fill(0.0);
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
        let completed = (angle_rad / TAU).floor() > (previous_angle / TAU).floor();
        if !completed || self.len < 2 {
            return None;
        }
        if self.rev_lengths.len() == SPECTRUM_REVOLUTIONS + 1 {
            self.rev_lengths.remove(0);
        }
        self.rev_lengths.push(self.current_rev_len);
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

    /// Rev-to-rev differences of bearing `bi` (orbit over the clearance, pressure relative):
    /// each sample of the last revolution (`last` samples) against the state at the same shaft
    /// angle one revolution earlier, interpolated by the cubic through the four samples of that
    /// revolution around it (Lagrange, in the angle: a time step that is not a whole fraction of
    /// the revolution, or a speed that changes, leaves no offset, and the interpolation error is
    /// O(Δψ⁴)); NaN when not enough is stored.
    fn rev_to_rev(&self, bi: usize, last: usize) -> (f64, f64) {
        let h = &self.bearings[bi];
        if last == 0 || self.len < last + 4 {
            return (f64::NAN, f64::NAN);
        }
        let angle = |back: usize| self.angle[self.idx(back)];
        let (mut d2, mut pd2, mut p2) = (0.0, 0.0, 0.0);
        // k: the newer of the two samples of the earlier revolution that bracket the target
        let mut k = last.saturating_sub(1).max(1);
        for back in 0..last {
            let target = angle(back) - TAU;
            while k + 2 < self.len && angle(k + 1) > target {
                k += 1;
            }
            if k + 2 >= self.len || angle(k) < target {
                return (f64::NAN, f64::NAN);
            }
            let nodes = [k - 1, k, k + 1, k + 2];
            let w = lagrange_weights(nodes.map(angle), target);
            let i = self.idx(back);
            // the nodes' ring positions once (not once per pressure point: the same sums)
            let slots = nodes.map(|n| self.idx(n));
            let at = |v: &[f64]| slots.iter().zip(&w).map(|(&n, w)| w * v[n]).sum::<f64>();
            d2 += (h.x[i] - at(&h.x)).powi(2) + (h.y[i] - at(&h.y)).powi(2);
            let a = &h.pressure[i * PRESSURE_POINTS..(i + 1) * PRESSURE_POINTS];
            let profiles =
                slots.map(|n| &h.pressure[n * PRESSURE_POINTS..(n + 1) * PRESSURE_POINTS]);
            for (m, u) in a.iter().enumerate() {
                let v: f64 = profiles.iter().zip(&w).map(|(p, w)| w * p[m]).sum();
                pd2 += (u - v).powi(2);
                p2 += u * u;
            }
        }
        let pressure = if p2 > 0.0 { (pd2 / p2).sqrt() } else { 0.0 };
        ((d2 / last as f64).sqrt() / h.clearance_m, pressure)
    }

    /// Path distance of bearing `bi`: each point of the last revolution to the polyline of the
    /// two before, over the clearance; None if not enough is stored.
    fn path_diff(&self, bi: usize, last: usize) -> Option<f64> {
        let h = &self.bearings[bi];
        if last <= 1 || self.len < 3 * last {
            return None;
        }
        // every point against every segment costs O(n²) a revolution: up to 32 points of the
        // revolution, evenly spread, are compared (all segments are searched)
        let stride = last.div_ceil(32);
        let (mut sum, mut points) = (0.0, 0usize);
        for back in (0..last).step_by(stride) {
            points += 1;
            let p = self.idx(back);
            let (px, py) = (h.x[p], h.y[p]);
            let mut best = f64::MAX;
            // the segments from `last` back to 3 last − 1 samples before the newest: the ring
            // position one sample further back is one slot lower (wrapping)
            let mut a = self.idx(last);
            for _ in last..3 * last - 1 {
                let b = if a == 0 { self.capacity - 1 } else { a - 1 };
                best = best.min(point_segment_distance2(
                    px, py, h.x[a], h.y[a], h.x[b], h.y[b],
                ));
                a = b;
            }
            sum += best;
        }
        Some((sum / points as f64).sqrt() / h.clearance_m)
    }

    /// The order spectrum of bearing `bi` over the last `window` samples (oldest first) into
    /// `self.spectrum`, from at most 32 samples a revolution: the orders resolved go up to 2,
    /// far below that rate's Nyquist order of 16.
    fn window_spectrum(&mut self, bi: usize, window: usize) {
        let h = &self.bearings[bi];
        let idx = |back: usize| ring_index(self.head, self.capacity, back);
        let per_rev = window / self.rev_lengths.len().clamp(1, SPECTRUM_REVOLUTIONS);
        let stride = per_rev.div_ceil(32).max(1);
        let picks = window.div_ceil(stride);
        // the picked samples gathered once, oldest first (the spectrum reads each twice)
        let picked = &mut self.picked;
        picked.clear();
        picked.extend((0..picks).map(|k| {
            let i = idx(window - 1 - k * stride);
            [h.x[i], h.y[i], self.angle[i]]
        }));
        order_spectrum(
            picked.iter().map(|p| p[0]),
            picked.iter().map(|p| p[1]),
            picked.iter().map(|p| p[2]),
            picks,
            SPECTRUM_REVOLUTIONS,
            &mut self.spectrum,
        );
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
        self.window_spectrum(bi, self.recent_samples(SPECTRUM_REVOLUTIONS));
        let one_x = one_x_component(&self.spectrum, SPECTRUM_REVOLUTIONS);
        let peak = subsynchronous_peak(&self.spectrum, SPECTRUM_REVOLUTIONS);
        let subsync_m = peak.semi_major_m();
        let span = self.whirl_span(&peak, c);
        let r = self.last_revolution(bi, self.recent_samples(span));
        let rub = self.last_revolution(bi, last);
        let (orbit_diff, pressure_diff) = self.rev_to_rev(bi, last);
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
