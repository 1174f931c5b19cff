//! Per-revolution monitoring of the twin: orbits, rev-to-rev differences of orbit and pressure
//! field (the seed's Fig. 10/11 criterion), order spectrum (1X, dominant sub-synchronous
//! component, forward/backward), and a classification with its evidence. Fed one step at a time;
//! storage is reserved at construction and nothing is allocated per step.

pub mod spectrum;

pub use spectrum::{
    interpolate_peak, one_x_component, order_spectrum, subsynchronous_peak, OrderComponent,
};

use crate::dynamics::{StepOutput, Twin};
use serde::Serialize;
use std::f64::consts::TAU;

/// Revolutions in the spectrum window (order resolution 1/16).
pub const SPECTRUM_REVOLUTIONS: usize = 16;
/// Points of the mid-plane pressure profile kept per step.
pub const PRESSURE_POINTS: usize = 60;

/// Operating state of the rotor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum RotorState {
    /// Synchronous response only.
    #[default]
    Stable,
    /// A dominant sub-synchronous whirl of moderate amplitude.
    Whirl,
    /// A dominant sub-synchronous whirl with the orbit near the clearance.
    Whip,
    /// The journal touched the bearing wall.
    Contact,
}

/// Thresholds of the classification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClassifierSettings {
    /// Sub-synchronous semi-major axis that counts, as a share of the clearance.
    pub subsync_min_clearance_share: f64,
    /// ... and as a share of the 1X semi-major axis.
    pub subsync_min_one_x_share: f64,
    /// Largest eccentricity ratio in the revolution above which a whirl is a whip.
    pub whip_eccentricity_ratio: f64,
}

impl ClassifierSettings {
    /// A sub-synchronous semi-major axis `subsync_m` counts (is dominant) beside a 1X one of
    /// `one_x_m` in a bearing of radial clearance `clearance_m` (all m).
    pub fn subsync_counts(&self, subsync_m: f64, one_x_m: f64, clearance_m: f64) -> bool {
        subsync_m > self.subsync_min_clearance_share * clearance_m
            && subsync_m > self.subsync_min_one_x_share * one_x_m
    }
}

impl Default for ClassifierSettings {
    fn default() -> Self {
        Self {
            subsync_min_clearance_share: 0.02,
            subsync_min_one_x_share: 0.5,
            whip_eccentricity_ratio: 0.75,
        }
    }
}

/// One bearing over the last revolution (and the spectrum window).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct BearingRevolution {
    /// Peak-to-peak orbit in x (m) over the last revolution.
    pub orbit_pp_x_m: f64,
    /// Peak-to-peak orbit in y (m).
    pub orbit_pp_y_m: f64,
    /// Largest eccentricity ratio in the last revolution.
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
    /// Largest film pressure in the last revolution (Pa).
    pub max_pressure_pa: f64,
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
        match worst {
            Some((i, b)) => format!(
                "bearing {i}: sub-synchronous {:.2} µm at {:.3}X vs 1X {:.2} µm, max eccentricity {:.3}, rev-to-rev orbit diff {:.2e}, pressure diff {:.2e}{}",
                b.subsync_amplitude_m * 1e6,
                b.subsync_ratio,
                b.one_x_amplitude_m * 1e6,
                b.max_eccentricity_ratio,
                b.orbit_diff,
                b.pressure_diff,
                if b.contact { ", wall contact" } else { "" }
            ),
            None => "no bearings".into(),
        }
    }
}

/// Ring buffers of the recent samples of one bearing.
struct BearingHistory {
    clearance_m: f64,
    x: Vec<f64>,
    y: Vec<f64>,
    ecc: Vec<f64>,
    p_max: Vec<f64>,
    contact: Vec<bool>,
    /// mid-plane pressure profile per sample (PRESSURE_POINTS each)
    pressure: Vec<f64>,
}

/// The per-revolution monitor.
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
    spectrum: Vec<OrderComponent>,
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
                x: vec![0.0; capacity],
                y: vec![0.0; capacity],
                ecc: vec![0.0; capacity],
                p_max: vec![0.0; capacity],
                contact: vec![false; capacity],
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
            spectrum: vec![OrderComponent::default(); SPECTRUM_REVOLUTIONS],
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
                let i = (self.head + 2 * self.capacity - 1 - back) % self.capacity;
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
                let i = (self.head + 2 * self.capacity - 1 - back) % self.capacity;
                h.pressure[i * PRESSURE_POINTS..(i + 1) * PRESSURE_POINTS].to_vec()
            })
            .collect()
    }

    /// The order spectrum of bearing `bearing` over the window, orders 1/16 … 2 (allocates).
    pub fn full_spectrum(&self, bearing: usize) -> Vec<OrderComponent> {
        let window = self.recent_samples(SPECTRUM_REVOLUTIONS);
        let h = &self.bearings[bearing];
        let idx = |back: usize| (self.head + 2 * self.capacity - 1 - back) % self.capacity;
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
        let previous_angle = if self.len > 0 {
            self.angle[(self.head + self.capacity - 1) % self.capacity]
        } else {
            out.angle_rad
        };
        self.angle[slot] = out.angle_rad;
        for (k, (h, b)) in self.bearings.iter_mut().zip(&out.bearings).enumerate() {
            h.x[slot] = b.position_m[0];
            h.y[slot] = b.position_m[1];
            h.ecc[slot] = b.eccentricity_ratio;
            h.p_max[slot] = b.max_pressure_pa;
            h.contact[slot] = b.contact;
            twin.midplane_pressure(k, &mut self.profile);
            h.pressure[slot * PRESSURE_POINTS..(slot + 1) * PRESSURE_POINTS]
                .copy_from_slice(&self.profile);
        }
        self.head = (self.head + 1) % self.capacity;
        self.len = (self.len + 1).min(self.capacity);
        self.current_rev_len += 1;
        let completed = (out.angle_rad / TAU).floor() > (previous_angle / TAU).floor();
        if !completed || self.len < 2 {
            return None;
        }
        if self.rev_lengths.len() == SPECTRUM_REVOLUTIONS + 1 {
            self.rev_lengths.remove(0);
        }
        self.rev_lengths.push(self.current_rev_len);
        self.current_rev_len = 0;
        self.revolutions += 1;
        self.analyse(out.time_s, out.speed_rad_s);
        Some(&self.report)
    }

    fn analyse(&mut self, time_s: f64, speed_rad_s: f64) {
        let last = (*self.rev_lengths.last().unwrap_or(&0)).min(self.len);
        let window: usize = self
            .rev_lengths
            .iter()
            .rev()
            .take(SPECTRUM_REVOLUTIONS)
            .sum::<usize>()
            .min(self.len);
        let prev = if self.rev_lengths.len() >= 2 {
            self.rev_lengths[self.rev_lengths.len() - 2]
        } else {
            0
        };
        let s = self.settings;
        let mut state = RotorState::Stable;
        let (mut od, mut pd) = (0.0_f64, 0.0_f64);
        for (bi, h) in self.bearings.iter().enumerate() {
            let c = h.clearance_m;
            let idx = |back: usize| (self.head + 2 * self.capacity - 1 - back) % self.capacity;
            // the last revolution
            let (mut x0, mut x1, mut y0, mut y1, mut e, mut p, mut contact) = (
                f64::MAX,
                f64::MIN,
                f64::MAX,
                f64::MIN,
                0.0_f64,
                0.0_f64,
                false,
            );
            for back in 0..last {
                let i = idx(back);
                x0 = x0.min(h.x[i]);
                x1 = x1.max(h.x[i]);
                y0 = y0.min(h.y[i]);
                y1 = y1.max(h.y[i]);
                e = e.max(h.ecc[i]);
                p = p.max(h.p_max[i]);
                contact |= h.contact[i];
            }
            // rev-to-rev differences: each sample of the last revolution against the sample one
            // revolution earlier (offset = the last revolution's length; at constant speed the
            // lengths differ by at most one step from rounding)
            let (orbit_diff, pressure_diff);
            let count = last.min(prev);
            if count > 0 && last.abs_diff(prev) <= 1 && self.len >= last + count {
                let (mut d2, mut pd2, mut p2) = (0.0, 0.0, 0.0);
                for back in 0..count {
                    let (i, j) = (idx(back), idx(back + last));
                    d2 += (h.x[i] - h.x[j]).powi(2) + (h.y[i] - h.y[j]).powi(2);
                    let (a, b) = (
                        &h.pressure[i * PRESSURE_POINTS..(i + 1) * PRESSURE_POINTS],
                        &h.pressure[j * PRESSURE_POINTS..(j + 1) * PRESSURE_POINTS],
                    );
                    for (u, v) in a.iter().zip(b) {
                        pd2 += (u - v).powi(2);
                        p2 += u * u;
                    }
                }
                orbit_diff = (d2 / count as f64).sqrt() / c;
                pressure_diff = if p2 > 0.0 { (pd2 / p2).sqrt() } else { 0.0 };
            } else {
                orbit_diff = f64::NAN;
                pressure_diff = f64::NAN;
            }
            // path distance: each point of the last revolution to the polyline of the two before
            let mut path_diff = self.report.bearings[bi].orbit_path_diff;
            if last > 1 && self.len >= 3 * last {
                // every point against every segment costs O(n²) a revolution: up to 32 points of
                // the revolution, evenly spread, are compared (all segments are searched)
                let stride = last.div_ceil(32);
                let (mut sum, mut points) = (0.0, 0usize);
                for back in (0..last).step_by(stride) {
                    points += 1;
                    let p = idx(back);
                    let (px, py) = (h.x[p], h.y[p]);
                    let mut best = f64::MAX;
                    for seg in last..3 * last - 1 {
                        let (a, b) = (idx(seg), idx(seg + 1));
                        best = best.min(point_segment_distance2(
                            px, py, h.x[a], h.y[a], h.x[b], h.y[b],
                        ));
                    }
                    sum += best;
                }
                path_diff = (sum / points as f64).sqrt() / c;
            }
            // spectrum over the window (oldest first), from at most 32 samples a revolution: the
            // orders resolved go up to 2, far below that rate's Nyquist order of 16
            let start = window;
            let per_rev = window / self.rev_lengths.len().clamp(1, SPECTRUM_REVOLUTIONS);
            let stride = per_rev.div_ceil(32).max(1);
            let picks = window.div_ceil(stride);
            let xs = (0..picks).map(|k| h.x[idx(start - 1 - k * stride)]);
            let ys = (0..picks).map(|k| h.y[idx(start - 1 - k * stride)]);
            let angles = (0..picks).map(|k| self.angle[idx(start - 1 - k * stride)]);
            order_spectrum(
                xs,
                ys,
                angles,
                picks,
                SPECTRUM_REVOLUTIONS,
                &mut self.spectrum,
            );
            let one_x = one_x_component(&self.spectrum, SPECTRUM_REVOLUTIONS);
            let peak = subsynchronous_peak(&self.spectrum, SPECTRUM_REVOLUTIONS);
            let (abest, ratio) = (peak.semi_major_m(), peak.order);
            // a window shorter than its resolution cannot resolve orders: no verdict on
            // sub-synchronous motion until it holds SPECTRUM_REVOLUTIONS revolutions
            let full_window = self.rev_lengths.len() >= SPECTRUM_REVOLUTIONS;
            let dominant = full_window && s.subsync_counts(abest, one_x.semi_major_m(), c);
            let b_state = if contact {
                RotorState::Contact
            } else if dominant && e > s.whip_eccentricity_ratio {
                RotorState::Whip
            } else if dominant {
                RotorState::Whirl
            } else {
                RotorState::Stable
            };
            state = state.max(b_state);
            if orbit_diff.is_finite() {
                od = od.max(orbit_diff);
            }
            if pressure_diff.is_finite() {
                pd = pd.max(pressure_diff);
            }
            self.report.bearings[bi] = BearingRevolution {
                orbit_pp_x_m: (x1 - x0).max(0.0),
                orbit_pp_y_m: (y1 - y0).max(0.0),
                max_eccentricity_ratio: e,
                one_x_amplitude_m: one_x.semi_major_m(),
                one_x_phase_rad: one_x.forward_phase_rad,
                subsync_ratio: if dominant { ratio } else { 0.0 },
                subsync_amplitude_m: abest,
                subsync_forward: peak.forward_m >= peak.backward_m,
                max_pressure_pa: p,
                // not comparable (speed changed within a revolution): keep the last value
                orbit_path_diff: path_diff,
                orbit_diff: if orbit_diff.is_finite() {
                    orbit_diff
                } else {
                    self.report.bearings[bi].orbit_diff
                },
                pressure_diff: if pressure_diff.is_finite() {
                    pressure_diff
                } else {
                    self.report.bearings[bi].pressure_diff
                },
                contact,
                state: b_state,
            };
        }
        self.report.revolution = self.revolutions;
        self.report.time_s = time_s;
        self.report.speed_rad_s = speed_rad_s;
        self.report.state = state;
        self.report.rev_to_rev_orbit_diff = od;
        self.report.rev_to_rev_pressure_diff = pd;
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
