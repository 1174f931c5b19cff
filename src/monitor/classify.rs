//! The classification of one bearing's motion from the evidence of the monitor: the
//! sub-synchronous component's size and its growth rate, and the alarm levels an orbit is judged
//! against.
//!
//! The verdict follows the dynamics, not the size alone: a sub-synchronous component that grows
//! faster than [`ClassifierSettings::growth_threshold_per_rev`] is unstable whatever its size
//! (the linearised system has an eigenvalue in the right half-plane, or the orbit has not yet
//! reached its limit cycle); "stable" means it decays or is absent.

use serde::Serialize;

/// Operating state of a bearing (and, the worst of them, of the rotor). Ordered by severity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum RotorState {
    /// Synchronous response only: the sub-synchronous component is absent (below
    /// [`ClassifierSettings::subsync_floor_clearance_share`] of the clearance), decays, or is
    /// small (not dominant) and neither grows nor decays beyond the threshold rate.
    #[default]
    Stable,
    /// Unstable (growing): the early warning of a whirl onset. A sub-synchronous component
    /// grows faster than the stated rate while still too small to be dominant.
    Growing,
    /// A dominant sub-synchronous whirl that does not decay (growing, or on its limit cycle).
    Whirl,
    /// A dominant sub-synchronous whirl with the orbit near the clearance (ε above
    /// [`ClassifierSettings::whip_eccentricity_ratio`]). Wall contact is a flag carried with it
    /// (see [`crate::monitor::BearingRevolution::contact_events`]), not a state of its own.
    Whip,
}

impl RotorState {
    /// The state's name as in the JSON output and the warnings' `kind` ("none" for stable).
    pub fn warning_kind(self) -> &'static str {
        match self {
            Self::Stable => "none",
            Self::Growing => "growing",
            Self::Whirl => "whirl",
            Self::Whip => "whip",
        }
    }
}

/// Thresholds of the classification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClassifierSettings {
    /// Sub-synchronous semi-major axis that counts (is dominant), as a share of the clearance.
    pub subsync_min_clearance_share: f64,
    /// ... and as a share of the 1X semi-major axis.
    pub subsync_min_one_x_share: f64,
    /// Largest eccentricity ratio in the revolution above which a whirl is a whip.
    pub whip_eccentricity_ratio: f64,
    /// Below this share of the clearance the sub-synchronous component is absent (default
    /// 10⁻³: 40 nm in the microturbine's 40 µm bearings, far above round-off and far below the
    /// 2 % that counts, so that a growth is announced some 6 e-folds before it counts).
    pub subsync_floor_clearance_share: f64,
    /// Growth rate of the sub-synchronous amplitude (1/rev, per shaft revolution) beyond which
    /// the motion is unstable (growing), and below whose negative it decays (default 0.002: an
    /// e-fold in 500 revolutions, 3.3 s at 9,000 rpm; the onset measured by transients lies
    /// between −0.0023/rev at 8,200 rpm and +0.0029/rev at 8,500 rpm).
    pub growth_threshold_per_rev: f64,
    /// Half-width of the dead band about [`Self::growth_threshold_per_rev`] (1/rev): the growth
    /// estimate's own scatter. A small component starts `growing` only when its estimate exceeds
    /// the threshold by more than this, and a growing one stays growing until its estimate falls
    /// below the threshold by more than this or it decays (below −threshold, which with the
    /// defaults comes first: −0.002/rev); in between the previous verdict holds. Default
    /// 0.005/rev: near the stability threshold (Ø55 shipped rotor, nonlinear, tabulated film,
    /// 64 steps a revolution, 8,450 and 8,500 rpm, 700 revolutions each, both bearings) the
    /// estimate ([`log_growth_per_rev`] of the 16-revolution histories) differs from the local
    /// slope of ln(amplitude) over 64 revolutions by 0.0012–0.0025/rev RMS and at most
    /// 0.0045–0.0051/rev (a swing with a period of 12–13 revolutions), which without the band
    /// flipped a +0.0013/rev component between `growing` and `stable` every ~12 revolutions.
    pub growth_dead_band_per_rev: f64,
    /// Alarm levels set by the machine's owner instead of the field-practice ones
    /// ([`AlarmLevels`]); None: API 617 / ISO 20816-3.
    pub alarm_levels: Option<AlarmOverride>,
}

impl ClassifierSettings {
    /// The alert and danger amplitudes (m, zero to peak) for radial clearance `clearance_m`
    /// at `speed_rpm` (allocates nothing).
    pub fn alarm_amplitudes_m(&self, clearance_m: f64, speed_rpm: f64) -> (f64, f64) {
        match self.alarm_levels {
            Some(o) => (o.alert_m.min(clearance_m), o.danger_m.min(clearance_m)),
            None => alarm_amplitudes(clearance_m, speed_rpm),
        }
    }

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
            subsync_floor_clearance_share: 1e-3,
            growth_threshold_per_rev: 0.002,
            growth_dead_band_per_rev: 0.005,
            alarm_levels: None,
        }
    }
}

/// The evidence the classification of one bearing rests on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Evidence {
    /// Radial clearance (m).
    pub clearance_m: f64,
    /// Sub-synchronous semi-major axis (m).
    pub subsync_m: f64,
    /// 1X semi-major axis (m).
    pub one_x_m: f64,
    /// Largest eccentricity ratio in the last revolution.
    pub max_eccentricity_ratio: f64,
    /// The spectrum window holds its full number of revolutions.
    pub full_window: bool,
    /// Growth rate of the sub-synchronous amplitude (1/rev), once known.
    pub growth_per_rev: Option<f64>,
    /// The bearing's state in the revolution before (what a growth inside the dead band keeps).
    pub previous: RotorState,
}

impl ClassifierSettings {
    /// The state of one bearing. Until the growth rate is known (the first
    /// 2 × [`crate::monitor::SPECTRUM_REVOLUTIONS`] revolutions) by size alone, and only a
    /// whip (dominant, beyond the eccentricity ratio): a decaying start-up transient must not
    /// be taken for a whirl.
    pub fn classify(&self, e: &Evidence) -> RotorState {
        if !e.full_window {
            return RotorState::Stable;
        }
        let dominant = self.subsync_counts(e.subsync_m, e.one_x_m, e.clearance_m);
        let size_state = if e.max_eccentricity_ratio > self.whip_eccentricity_ratio {
            RotorState::Whip
        } else {
            RotorState::Whirl
        };
        let Some(g) = e.growth_per_rev else {
            // no verdict on the dynamics yet: only a whip is announced on its size
            return if dominant && size_state == RotorState::Whip {
                size_state
            } else {
                RotorState::Stable
            };
        };
        let present = e.subsync_m > self.subsync_floor_clearance_share * e.clearance_m;
        // a whip's amplitude is modulated (±3 % over ~30 revolutions at 7,500 rpm on the shipped
        // rotor) and its median increment over 16 revolutions swings by ±0.004/rev: at whip size
        // it is called stable only when it collapses, decaying faster than
        // WHIP_COLLAPSE_FACTOR × the threshold (0.02/rev, an e-fold in 50 revolutions)
        let decay = if dominant && size_state == RotorState::Whip {
            WHIP_COLLAPSE_FACTOR * self.growth_threshold_per_rev
        } else {
            self.growth_threshold_per_rev
        };
        if !present || g < -decay {
            RotorState::Stable
        } else if dominant {
            size_state
        } else if g > self.growth_threshold_per_rev + self.growth_dead_band_per_rev
            || (e.previous != RotorState::Stable
                && g > self.growth_threshold_per_rev - self.growth_dead_band_per_rev)
        {
            // beyond the threshold by more than the estimate's scatter, or already unstable
            // and not yet clearly below it
            RotorState::Growing
        } else {
            // present and small, its rate not clearly beyond the threshold: a transient not yet
            // decided (right after a sudden change the estimate passes through this band)
            RotorState::Stable
        }
    }
}

/// A dominant component at whip size counts as decaying (stable) only beyond this multiple of
/// [`ClassifierSettings::growth_threshold_per_rev`] (see [`ClassifierSettings::classify`]).
pub const WHIP_COLLAPSE_FACTOR: f64 = 10.0;

/// Most values [`log_growth_per_rev`] takes.
pub const MAX_GROWTH_VALUES: usize = 32;

/// Growth rate per revolution of amplitudes `a` (oldest first, one a revolution): the median of
/// the increments ln a[n+1] − ln a[n]. For an amplitude a ∝ e^{σ n} every increment is σ (and
/// for a window spectrum of an exponentially growing component the window shape is the same
/// each revolution, so successive amplitudes have the ratio e^σ exactly). The median, unlike a
/// least-squares slope, is not carried by the one large increment of a sudden change (a step of
/// unbalance): a step followed by a decay reads as the decay. None with fewer than 4 values
/// or any that is not positive; at most [`MAX_GROWTH_VALUES`] are used (allocates nothing).
pub fn log_growth_per_rev(a: impl Iterator<Item = f64> + Clone) -> Option<f64> {
    let mut inc = [0.0_f64; MAX_GROWTH_VALUES];
    let mut n = 0;
    let mut previous: Option<f64> = None;
    for v in a.take(MAX_GROWTH_VALUES + 1) {
        if !(v > 0.0 && v.is_finite()) {
            return None;
        }
        if let Some(p) = previous {
            inc[n] = v.ln() - p.ln();
            n += 1;
        }
        previous = Some(v);
    }
    if n < 3 {
        return None;
    }
    let inc = &mut inc[..n];
    inc.sort_unstable_by(f64::total_cmp);
    Some(if n % 2 == 1 {
        inc[n / 2]
    } else {
        0.5 * (inc[n / 2 - 1] + inc[n / 2])
    })
}

/// Alert and danger levels of the orbit amplitude (half the peak-to-peak displacement, m) with
/// their basis, as field practice sets them:
/// - alert: the smaller of API 617's limit on the unbalance response at close clearances
///   (peak-to-peak below 75 % of the diametral clearance: an amplitude of 0.75 c) and the
///   ISO 20816-3 (ISO 7919-3, annex A) zone B/C boundary of shaft vibration relative to the
///   bearing, S_pp = 9000/√n µm (n in r/min);
/// - danger: the smaller of the clearance itself (the journal reaches the wall) and the zone C/D
///   boundary, S_pp = 13200/√n µm.
///
/// The ISO boundaries are evaluated at the running speed (the standard takes the machine's
/// speed; at the microturbine's 8,000–9,000 rpm they lie above the clearance limits, which
/// govern).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlarmLevels {
    /// Alert (WARN) amplitude (m, zero to peak).
    pub alert_m: f64,
    /// Danger (ERROR) amplitude (m, zero to peak).
    pub danger_m: f64,
    /// Where the two come from, in words.
    pub basis: String,
}

/// Share of the radial clearance of API 617's close-clearance limit.
pub const API_617_CLEARANCE_SHARE: f64 = 0.75;

/// A configured override of the alarm levels (m, zero to peak), e.g. from the machine file.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AlarmOverride {
    /// Alert amplitude (m).
    pub alert_m: f64,
    /// Danger amplitude (m).
    pub danger_m: f64,
}

impl From<&crate::rotor::AlarmLevelsSpec> for AlarmOverride {
    fn from(a: &crate::rotor::AlarmLevelsSpec) -> Self {
        Self {
            alert_m: a.alert_amplitude_m,
            danger_m: a.danger_amplitude_m,
        }
    }
}

/// The alert and danger amplitudes (m) for a bearing of radial clearance `clearance_m` at
/// `speed_rpm`, without the words (allocates nothing: for every revolution).
pub fn alarm_amplitudes(clearance_m: f64, speed_rpm: f64) -> (f64, f64) {
    let (bc, cd) = iso_20816_boundaries_m(speed_rpm);
    (
        (API_617_CLEARANCE_SHARE * clearance_m).min(bc),
        clearance_m.min(cd),
    )
}

/// ISO 20816-3 (ISO 7919-3 annex A) zone boundaries B/C and C/D of relative shaft vibration as
/// amplitudes (half the peak-to-peak limits, m) at `speed_rpm`.
pub fn iso_20816_boundaries_m(speed_rpm: f64) -> (f64, f64) {
    let root = speed_rpm.max(1.0).sqrt();
    (0.5 * 9000e-6 / root, 0.5 * 13200e-6 / root)
}

impl AlarmLevels {
    /// The field-practice levels for radial clearance `clearance_m` at `speed_rpm`, or the
    /// configured `levels` (each capped by the clearance).
    pub fn new(clearance_m: f64, speed_rpm: f64, levels: Option<AlarmOverride>) -> Self {
        let (bc, cd) = iso_20816_boundaries_m(speed_rpm);
        if let Some(o) = levels {
            let (alert, danger) = (o.alert_m.min(clearance_m), o.danger_m.min(clearance_m));
            return Self {
                alert_m: alert,
                danger_m: danger,
                basis: format!(
                    "configured: alert {:.1} µm, danger {:.1} µm (capped by the clearance {:.1} µm)",
                    alert * 1e6,
                    danger * 1e6,
                    clearance_m * 1e6
                ),
            };
        }
        let (alert, danger) = alarm_amplitudes(clearance_m, speed_rpm);
        let alert_basis = if alert < bc {
            "API 617: 75 % of the clearance"
        } else {
            "ISO 20816-3 zone B/C"
        };
        let danger_basis = if danger < cd {
            "the clearance"
        } else {
            "ISO 20816-3 zone C/D"
        };
        Self {
            alert_m: alert,
            danger_m: danger,
            basis: format!(
                "amplitudes (half peak-to-peak) at {speed_rpm:.0} rpm: alert {:.1} µm ({alert_basis}; ISO B/C {:.1} µm), danger {:.1} µm ({danger_basis}; ISO C/D {:.1} µm)",
                alert * 1e6,
                bc * 1e6,
                danger * 1e6,
                cd * 1e6
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The growth of a pure exponential is its exponent (to round-off); a step up by 100×
    /// followed by a decay at 0.013/rev reads as the decay; with a zero amplitude there is none.
    #[test]
    fn growth_of_an_exponential_is_its_rate_and_a_step_is_not_growth() {
        let a = (0..16).map(|n| 3e-7 * (0.0218 * n as f64).exp());
        assert!((log_growth_per_rev(a).unwrap() - 0.0218).abs() < 1e-12);
        let step = (0..16).map(|n| {
            let jump = if n >= 12 { 100.0 } else { 1.0 };
            jump * 3e-7 * (-0.013 * n as f64).exp()
        });
        assert!((log_growth_per_rev(step).unwrap() + 0.013).abs() < 1e-12);
        assert!(log_growth_per_rev([1.0, 0.0, 1.0, 1.0].into_iter()).is_none());
    }

    /// Stable only when absent or decaying; growing whatever the size; dominant whirl or whip.
    #[test]
    fn verdicts_follow_size_and_growth() {
        let s = ClassifierSettings::default();
        let c = 40e-6;
        let ev = |subsync_m: f64, g: Option<f64>, ecc: f64| Evidence {
            clearance_m: c,
            subsync_m,
            one_x_m: 1e-6,
            max_eccentricity_ratio: ecc,
            full_window: true,
            growth_per_rev: g,
            previous: RotorState::Stable,
        };
        assert_eq!(s.classify(&ev(1e-9, Some(0.05), 0.6)), RotorState::Stable);
        assert_eq!(
            s.classify(&ev(0.3e-6, Some(0.02), 0.6)),
            RotorState::Growing
        );
        assert_eq!(
            s.classify(&ev(0.3e-6, Some(-0.01), 0.6)),
            RotorState::Stable
        );
        // a large decaying transient is stable
        assert_eq!(s.classify(&ev(5e-6, Some(-0.01), 0.6)), RotorState::Stable);
        assert_eq!(s.classify(&ev(5e-6, Some(0.02), 0.6)), RotorState::Whirl);
        assert_eq!(s.classify(&ev(30e-6, Some(0.0), 0.95)), RotorState::Whip);
        // a modulated whip on its way down is still a whip; a collapsing one is not
        assert_eq!(s.classify(&ev(30e-6, Some(-0.004), 0.86)), RotorState::Whip);
        assert_eq!(
            s.classify(&ev(30e-6, Some(-0.03), 0.86)),
            RotorState::Stable
        );
        assert_eq!(s.classify(&ev(0.3e-6, Some(0.0), 0.6)), RotorState::Stable);
        assert_eq!(s.classify(&ev(5e-6, Some(0.0), 0.6)), RotorState::Whirl);
        assert_eq!(s.classify(&ev(5e-6, None, 0.6)), RotorState::Stable);
        assert_eq!(s.classify(&ev(30e-6, None, 0.95)), RotorState::Whip);
        // the dead band (0.002 ± 0.005/rev): a small component starts growing only beyond
        // 0.007/rev, and a growing one stays growing until it decays (below −0.002/rev, which
        // comes before 0.002 − 0.005)
        assert_eq!(
            s.classify(&ev(0.3e-6, Some(0.0065), 0.6)),
            RotorState::Stable
        );
        assert_eq!(
            s.classify(&ev(0.3e-6, Some(0.0075), 0.6)),
            RotorState::Growing
        );
        let was_growing = |g: f64| Evidence {
            previous: RotorState::Growing,
            ..ev(0.3e-6, Some(g), 0.6)
        };
        assert_eq!(s.classify(&was_growing(0.0015)), RotorState::Growing);
        assert_eq!(s.classify(&was_growing(-0.0015)), RotorState::Growing);
        assert_eq!(s.classify(&was_growing(-0.0025)), RotorState::Stable);
    }

    /// The microturbine at 9,000 rpm, c = 40 µm: ISO B/C 9000/√9000 = 94.87 µm p-p (47.4 µm
    /// amplitude) and C/D 139.1 µm p-p lie above the clearance limits: alert 30 µm (API 617),
    /// danger 40 µm (the clearance). At 300 rpm with a 1 mm clearance ISO governs both.
    #[test]
    fn alarm_levels_take_the_governing_limit() {
        let a = AlarmLevels::new(40e-6, 9000.0, None);
        assert!((a.alert_m - 30e-6).abs() < 1e-12 && (a.danger_m - 40e-6).abs() < 1e-12);
        assert!(
            a.basis.contains("API 617") && a.basis.contains("47.4"),
            "{}",
            a.basis
        );
        let b = AlarmLevels::new(1e-3, 300.0, None);
        assert!((b.alert_m - 0.5 * 9000e-6 / 300f64.sqrt()).abs() < 1e-12);
        assert!((b.danger_m - 0.5 * 13200e-6 / 300f64.sqrt()).abs() < 1e-12);
        let o = AlarmOverride {
            alert_m: 20e-6,
            danger_m: 60e-6,
        };
        let c = AlarmLevels::new(40e-6, 9000.0, Some(o));
        assert!((c.alert_m - 20e-6).abs() < 1e-12 && (c.danger_m - 40e-6).abs() < 1e-12);
    }
}
