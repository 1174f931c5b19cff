//! The replay's report: what was read, what came out, predicted against measured per probe
//! station, and when the instability set in. Serialized as the `--json` report.

use super::compare::{
    phase_difference_deg, BlockSpectra, StationComparison, TransientSpan, WindowComparison,
    ONSET_BLOCKS,
};
use super::orbit_shape::{OrbitEllipse, ShapeDifference};
use crate::bag::Bag;
use crate::session::{Outgoing, Session};
use crate::signals::OneXVector;
use serde::Serialize;

/// Predicted against measured at one probe station, over the summary window (the last 32
/// revolutions of the bag, or as many as there are).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct StationReport {
    /// Probe station name.
    pub station: String,
    /// Measured samples compared.
    pub samples: usize,
    /// The summary window (bag time, s) and its mean speed (rpm).
    pub window_start_s: Option<f64>,
    /// End of the summary window (s).
    pub window_end_s: Option<f64>,
    /// Mean speed over the window (rpm).
    pub window_speed_rpm: Option<f64>,
    /// Measured 1X semi-major axis (m).
    pub one_x_amplitude_measured_m: Option<f64>,
    /// Predicted 1X semi-major axis (m).
    pub one_x_amplitude_predicted_m: Option<f64>,
    /// Predicted minus measured 1X semi-major axis (m).
    pub one_x_amplitude_error_m: Option<f64>,
    /// Predicted minus measured phase of the forward 1X component, in (−180, 180] (degrees);
    /// null without a keyphasor lock over the window (see `phase_null_reason`).
    pub one_x_phase_error_deg: Option<f64>,
    // --- plant signals (issue 12) ---
    /// Measured 1X vector along each of the station's two probe axes: amplitude (m) and phase
    /// lag from the keyphasor event to the next positive peak (deg, 0–360, API 670 / Bently);
    /// null without a keyphasor lock over the window.
    pub one_x_probe_axes_measured: Option<[OneXVector; 2]>,
    /// Predicted 1X vector along each probe axis (same convention).
    pub one_x_probe_axes_predicted: Option<[OneXVector; 2]>,
    /// Predicted minus measured phase lag per probe axis, in (−180, 180] (deg).
    pub one_x_phase_lag_error_deg: Option<[f64; 2]>,
    /// Why the phases are null (null when they are keyphasor-referenced).
    pub phase_null_reason: Option<String>,
    // --- end plant signals ---
    /// Largest predicted sub-synchronous semi-major axis (m).
    pub subsync_amplitude_predicted_m: Option<f64>,
    /// Largest measured sub-synchronous semi-major axis (m).
    pub subsync_amplitude_measured_m: Option<f64>,
    /// Its order (frequency / running frequency), null unless it counts (the monitor's rule).
    pub subsync_ratio_predicted: Option<f64>,
    /// Measured sub-synchronous order, null unless it counts.
    pub subsync_ratio_measured: Option<f64>,
    /// RMS distance between the predicted and measured orbits, means removed, sample by sample
    /// at equal times (m): phase and shape differences together, not a shape measure.
    pub orbit_rms_distance_m: Option<f64>,
    /// Distance between the mean positions (m).
    pub mean_position_distance_m: Option<f64>,
    // --- orbit shape, phase-free (issue 16) ---
    /// The measured 1X orbit's ellipse: semi-major and semi-minor axes (m), inclination of the
    /// major axis (deg from +x towards +y), precession (forward/backward).
    pub one_x_ellipse_measured: Option<OrbitEllipse>,
    /// The predicted 1X orbit's ellipse.
    pub one_x_ellipse_predicted: Option<OrbitEllipse>,
    /// Predicted minus measured 1X ellipse, and their RMS distance minimised over a phase
    /// shift (`shape_distance_m`: the shape difference alone).
    pub one_x_shape: Option<ShapeDifference>,
    /// The measured largest sub-synchronous component's ellipse (null unless it counts).
    pub subsync_ellipse_measured: Option<OrbitEllipse>,
    /// The predicted one (null unless it counts).
    pub subsync_ellipse_predicted: Option<OrbitEllipse>,
    /// Predicted against measured sub-synchronous ellipse (null unless both count).
    pub subsync_shape: Option<ShapeDifference>,
    /// Blocks of 8 revolutions over the whole bag (amplitude against speed).
    pub blocks: Vec<WindowComparison>,
    // --- views (issue 16) ---
    /// Each block's order spectra at orders k/8, k = 1 … 16: semi-major axes (`measured_m`,
    /// `predicted_m`) and the full spectrum of x + iy (`measured_full_m`, `predicted_full_m`:
    /// `[forward radii, backward (reverse) radii]`, m), the cascade plot's numbers.
    pub block_spectra: Vec<BlockSpectra>,
    /// Why the blocks' measured `mean_m` is not the plant's mean position (null: it is, the
    /// measured shaft centerline).
    pub mean_position_null_reason: Option<String>,
    /// The predicted static-equilibrium position of the station over the bag's speeds (the
    /// centerline plot's locus; filled by `rotor-twin replay`, empty from the library call).
    pub centerline_static_predicted: Vec<CenterlineStatic>,
}

/// The station's predicted static-equilibrium position at one speed.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct CenterlineStatic {
    /// Speed (rpm).
    pub speed_rpm: f64,
    /// Position `[x, y]` (m), machine frame, relative to the bearing centres' line.
    pub position_m: [f64; 2],
}

/// When the instability set in, predicted and observed (null where there is none).
#[derive(Debug, Clone, Default, Serialize, PartialEq)]
pub struct OnsetReport {
    /// First 8-revolution block of the predicted probe orbit from which a sub-synchronous
    /// component that counts persists or grows over 3 consecutive blocks (bag time, s).
    pub predicted_time_s: Option<f64>,
    /// The same detector on the measured orbit (s).
    pub observed_time_s: Option<f64>,
    /// Speed at the predicted onset (rpm).
    pub predicted_speed_rpm: Option<f64>,
    /// Speed at the observed onset (rpm).
    pub observed_speed_rpm: Option<f64>,
    /// The twin's first warning of a growing, whirling or whipping rotor (bag time, s): the
    /// early warning.
    pub twin_warning_time_s: Option<f64>,
    /// Speed at that warning (rpm).
    pub twin_warning_speed_rpm: Option<f64>,
    /// The twin's first whip warning (bag time, s).
    pub twin_whip_time_s: Option<f64>,
    /// How onset is detected.
    pub detector: String,
    /// Sub-synchronous components that counted but decayed before the predicted onset (at
    /// any station): transients, not onsets.
    pub predicted_transients: Vec<TransientSpan>,
    /// The same on the measured orbits.
    pub observed_transients: Vec<TransientSpan>,
}

/// A change of the twin's classification.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct StateChange {
    /// Bag time (s).
    pub time_s: f64,
    /// Speed (rpm).
    pub speed_rpm: f64,
    /// start (the twin (re)started, from the static equilibrium) | none (stable) | growing
    /// (unstable, growing: the early warning) | whirl | whip.
    pub state: String,
    /// Warning level: 0 OK, 1 WARN, 2 ERROR.
    pub level: u8,
}

/// Inputs refused on one topic.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Rejections {
    /// Topic (as in the bag).
    pub topic: String,
    /// How many.
    pub count: u64,
    /// The last reason.
    pub last_reason: String,
}

/// The whole report.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ReplayReport {
    /// Bag time replayed, first to last message (s).
    pub bag_duration_s: f64,
    /// Wall time of the replay (s).
    pub wall_time_s: f64,
    /// Bag time over wall time.
    pub real_time_factor: f64,
    /// Messages read from the bag and processed.
    pub messages_in: u64,
    /// Messages written to the output bag.
    pub messages_out: u64,
    /// Damage found in the bag (each damaged range named; every intact message is replayed).
    pub damage: Vec<String>,
    /// What the bag's metadata got wrong, and receive-time outliers left out of the span.
    pub notes: Vec<String>,
    /// Inputs refused, per topic.
    pub rejected: Vec<Rejections>,
    /// Predicted against measured, per probe station with measurements.
    pub stations: Vec<StationReport>,
    /// Onset of instability.
    pub onset: OnsetReport,
    /// The twin's classification over time (its changes).
    pub states: Vec<StateChange>,
    /// The forecast's score (`--forecast`; absent without).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub forecast: Option<crate::forecast::score::ForecastScore>,
    /// The bearings' heat balances (issue 12; absent without `oil_heating`): a failure left the
    /// last good viscosity in force.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heat_balance: Option<crate::driver::HeatBalanceReport>,
    /// The oil in force at the end (issue 12; absent when no oil supply temperature was
    /// accepted): the last supply temperature and each film bearing's viscosity scale.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oil: Option<OilReport>,
    /// What the keyphasor lock did (issue 12; absent without a keyphasor topic).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub keyphasor: Option<KeyphasorReport>,
}

/// What the keyphasor lock did over a replay (issue 12): relocks (the mark moved against the
/// shaft and held) and steady speed mismatches (the speed topic scaled to the keyphasor's).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct KeyphasorReport {
    /// Relocks: phases re-referenced to a moved mark.
    pub relocks: u64,
    /// Steady speed mismatches found between the keyphasor and the speed topic.
    pub speed_mismatches: u64,
    /// The factor every speed topic value was scaled by at the end (null: none found).
    pub speed_topic_scale: Option<f64>,
}

/// The oil in force at the end of a replay (issue 12).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct OilReport {
    /// The last oil supply temperature accepted (°C).
    pub supply_temperature_c: f64,
    /// Per film bearing: its name and viscosity scale in force (µ / µ of the machine file).
    pub viscosity_scales: Vec<(String, f64)>,
}

impl ReplayReport {
    /// An empty report of `bag`.
    pub fn empty(bag: &Bag, wall_time_s: f64) -> Self {
        Self {
            bag_duration_s: 0.0,
            wall_time_s,
            real_time_factor: 0.0,
            messages_in: 0,
            messages_out: 0,
            damage: bag.damage.iter().map(|d| d.to_string()).collect(),
            notes: bag.notes.clone(),
            rejected: Vec::new(),
            stations: Vec::new(),
            onset: OnsetReport::default(),
            states: Vec::new(),
            forecast: None,
            heat_balance: None,
            oil: None,
            keyphasor: None,
        }
    }

    /// Counts a refused input.
    pub(super) fn note_rejection(&mut self, topic: &str, why: &str) {
        match self.rejected.iter_mut().find(|r| r.topic == topic) {
            Some(r) => {
                r.count += 1;
                r.last_reason = why.into();
            }
            None => self.rejected.push(Rejections {
                topic: topic.into(),
                count: 1,
                last_reason: why.into(),
            }),
        }
    }

    /// Notes a (re)start of the twin at bag time `time_s` and `speed_rpm`: stable, from the
    /// static equilibrium.
    pub(super) fn note_start(&mut self, time_s: f64, speed_rpm: f64) {
        self.states.push(StateChange {
            time_s,
            speed_rpm,
            state: "start".into(),
            level: 0,
        });
    }

    /// Notes the twin's warnings (state changes, first onset).
    pub(super) fn note_output(&mut self, o: &Outgoing, t0_ns: u64, session: &Option<Session>) {
        let Outgoing::Warning(w) = o else {
            return;
        };
        if !matches!(w.kind.as_str(), "none" | "growing" | "whirl" | "whip") {
            return;
        }
        let time_s = (w.header.stamp.as_nanos() - t0_ns as i64) as f64 * 1e-9;
        let speed_rpm = session.as_ref().map_or(0.0, |s| {
            s.twin().output().speed_rad_s * 30.0 / std::f64::consts::PI
        });
        if w.kind == "whip" && self.onset.twin_whip_time_s.is_none() {
            self.onset.twin_whip_time_s = Some(time_s);
        }
        if w.kind != "none" && self.onset.twin_warning_time_s.is_none() {
            self.onset.twin_warning_time_s = Some(time_s);
            self.onset.twin_warning_speed_rpm = Some(speed_rpm);
        }
        if self.states.last().is_none_or(|s| s.state != w.kind) {
            self.states.push(StateChange {
                time_s,
                speed_rpm,
                state: w.kind.clone(),
                level: w.level,
            });
        }
    }

    /// Fills the comparison and timing.
    pub(super) fn finish(&mut self, comparisons: &[StationComparison], wall_time_s: f64) {
        self.wall_time_s = wall_time_s;
        self.real_time_factor = if wall_time_s > 0.0 {
            self.bag_duration_s / wall_time_s
        } else {
            0.0
        };
        self.onset.detector = format!(
            "first block of {} revolutions at any probe station from which the largest sub-synchronous component is ≥ 2 % of the clearance and ≥ half the 1X amplitude over {ONSET_BLOCKS} consecutive blocks, decaying by less than 0.002/rev (persisting or growing); counting blocks that decay are transients",
            super::compare::BLOCK_REVS
        );
        self.onset.predicted_transients = comparisons
            .iter()
            .flat_map(|c| c.transients(true))
            .collect();
        self.onset.observed_transients = comparisons
            .iter()
            .flat_map(|c| c.transients(false))
            .collect();
        let earliest = |found: Vec<(f64, f64)>| {
            found
                .into_iter()
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map_or((None, None), |(t, w)| (Some(t), Some(w)))
        };
        (self.onset.predicted_time_s, self.onset.predicted_speed_rpm) =
            earliest(comparisons.iter().filter_map(|c| c.onset(true)).collect());
        (self.onset.observed_time_s, self.onset.observed_speed_rpm) =
            earliest(comparisons.iter().filter_map(|c| c.onset(false)).collect());
        self.stations = comparisons
            .iter()
            .filter(|c| c.samples > 0)
            .map(station_report)
            .collect();
        self.notes
            .extend(comparisons.iter().filter_map(decimation_note));
    }

    /// The oil heating's lines of the summary: a failed balance's warning, the balances and each
    /// film's temperature and scale.
    fn heat_lines(&self) -> String {
        let mut s = String::new();
        if let Some(h) = self.heat_balance.as_ref().filter(|h| h.failures > 0) {
            s += &format!(
                "WARNING: {} of {} heat balance(s) failed, the last good viscosity kept; last: {}\n",
                h.failures,
                h.balances,
                h.last_failure.as_deref().unwrap_or("")
            );
        }
        if let Some(h) = &self.heat_balance {
            s += &format!("oil heating: {} heat balance(s);", h.balances);
            for f in &h.films {
                s += &format!(
                    " {} {:.2} degC x{:.5}",
                    f.bearing, f.temperature_c, f.viscosity_scale
                );
            }
            s += "\n";
        }
        s
    }

    /// A few lines for the terminal.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "replayed {:.2} s of bag in {:.2} s ({:.2}× real time): {} messages in, {} out\n",
            self.bag_duration_s,
            self.wall_time_s,
            self.real_time_factor,
            self.messages_in,
            self.messages_out
        );
        for d in &self.damage {
            s += &format!("DAMAGED BAG: {d}; every intact message replayed\n");
        }
        for r in &self.rejected {
            s += &format!(
                "rejected {} input(s) on {}; last: {}\n",
                r.count, r.topic, r.last_reason
            );
        }
        s += &self.heat_lines();
        if let Some(oil) = &self.oil {
            s += &format!("oil supply {:.2} degC: viscosity", oil.supply_temperature_c);
            for (name, k) in &oil.viscosity_scales {
                s += &format!(" x{k:.5} ({name})");
            }
            s += "\n";
        }
        for st in &self.stations {
            s += &station_lines(st);
        }
        let at = |t: Option<f64>, w: Option<f64>| match (t, w) {
            (Some(t), Some(w)) => format!("{t:.2} s ({w:.0} rpm)"),
            _ => "none".into(),
        };
        s += &format!(
            "instability onset: predicted {}, observed {}; twin's first warning {}\n",
            at(self.onset.predicted_time_s, self.onset.predicted_speed_rpm),
            at(self.onset.observed_time_s, self.onset.observed_speed_rpm),
            at(
                self.onset.twin_warning_time_s,
                self.onset.twin_warning_speed_rpm
            ),
        );
        for (who, list) in [
            ("predicted", &self.onset.predicted_transients),
            ("observed", &self.onset.observed_transients),
        ] {
            for t in list {
                s += &format!(
                    "{who} transient (decaying, no onset): {:.2}–{:.2} s, sub-synchronous up to {:.2} µm\n",
                    t.start_s,
                    t.end_s,
                    t.largest_subsync_m * 1e6
                );
            }
        }
        let states: Vec<String> = self
            .states
            .iter()
            .map(|c| format!("{} at {:.2} s", c.state, c.time_s))
            .collect();
        s += &format!("states: {}\n", states.join(" → "));
        if let Some(f) = &self.forecast {
            s += &f.summary();
        }
        s
    }
}

/// The terminal lines of one station: amplitudes, phases, sub-synchronous, distances, shape.
fn station_lines(st: &StationReport) -> String {
    let um = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{:.2} µm", v * 1e6));
    // A sub-synchronous component is "amplitude at order", or "none" when the block has none.
    let subsync = |a: Option<f64>, r: Option<f64>| match (a, r) {
        (Some(a), Some(r)) => format!("{:.2} µm at {r:.3}X", a * 1e6),
        (Some(a), None) => format!("{:.2} µm", a * 1e6),
        _ => "none".to_string(),
    };
    let s = format!(
        "{}: 1X {} predicted vs {} measured ({}), sub-synchronous {} predicted vs {} measured, orbit RMS distance at equal times {}\n",
        st.station,
        um(st.one_x_amplitude_predicted_m),
        um(st.one_x_amplitude_measured_m),
        match (&st.one_x_probe_axes_measured, &st.one_x_probe_axes_predicted) {
            (Some(m), Some(p)) => format!(
                "phase lag {:.1}°/{:.1}° predicted vs {:.1}°/{:.1}° measured",
                p[0].phase_lag_deg, p[1].phase_lag_deg, m[0].phase_lag_deg, m[1].phase_lag_deg
            ),
            _ => format!(
                "phase null: {}",
                st.phase_null_reason.as_deref().unwrap_or("—")
            ),
        },
        subsync(st.subsync_amplitude_predicted_m, st.subsync_ratio_predicted),
        subsync(st.subsync_amplitude_measured_m, st.subsync_ratio_measured),
        um(st.orbit_rms_distance_m),
    );
    s + &shape_line(st)
}

/// Minor over major semi-axis above which an ellipse is read as a circle: its inclination is
/// then printed as "—" (a rounding of the axes turns it anywhere).
const NEAR_CIRCLE: f64 = 0.98;

/// The phase-free shape line of a station: the 1X (and sub-synchronous) ellipses, predicted
/// against measured, and their shape distance.
fn shape_line(st: &StationReport) -> String {
    let ell = |e: &OrbitEllipse| {
        // a near-circle (minor/major above NEAR_CIRCLE) has no meaningful inclination
        let inclination = if e.semi_minor_m > NEAR_CIRCLE * e.semi_major_m {
            "—".to_string()
        } else {
            format!("{:.0}°", e.inclination_deg)
        };
        format!(
            "{:.2} × {:.2} µm at {inclination}, {:?}",
            e.semi_major_m * 1e6,
            e.semi_minor_m * 1e6,
            e.precession
        )
        .to_lowercase()
    };
    let one = |label: &str,
               p: &Option<OrbitEllipse>,
               m: &Option<OrbitEllipse>,
               d: &Option<ShapeDifference>| match (p, m, d) {
        (Some(p), Some(m), Some(d)) => format!(
            "{label} ellipse {} predicted vs {} measured, shape distance {:.2} µm",
            ell(p),
            ell(m),
            d.shape_distance_m * 1e6
        ),
        _ => format!("{label}: no ellipse to compare (none counts)"),
    };
    format!(
        "  orbit shape (phase-free): {}; {}\n",
        one(
            "1X",
            &st.one_x_ellipse_predicted,
            &st.one_x_ellipse_measured,
            &st.one_x_shape
        ),
        one(
            "sub-synchronous",
            &st.subsync_ellipse_predicted,
            &st.subsync_ellipse_measured,
            &st.subsync_shape
        ),
    )
}

/// The report of one station's comparison, over its summary window.
fn station_report(c: &StationComparison) -> StationReport {
    let w = c.summary();
    let get = |f: fn(&WindowComparison) -> f64| w.as_ref().map(f);
    StationReport {
        station: c.station.clone(),
        samples: c.samples,
        window_start_s: get(|w| w.start_s),
        window_end_s: get(|w| w.end_s),
        window_speed_rpm: get(|w| w.speed_rpm),
        one_x_amplitude_measured_m: get(|w| w.measured.one_x_amplitude_m),
        one_x_amplitude_predicted_m: get(|w| w.predicted.one_x_amplitude_m),
        one_x_amplitude_error_m: get(|w| {
            w.predicted.one_x_amplitude_m - w.measured.one_x_amplitude_m
        }),
        one_x_phase_error_deg: w
            .as_ref()
            .filter(|w| w.phase_null_reason.is_none())
            .map(|w| {
                phase_difference_deg(
                    w.predicted.one_x_forward_phase_deg,
                    w.measured.one_x_forward_phase_deg,
                )
            }),
        one_x_probe_axes_measured: w.as_ref().and_then(|w| w.measured.one_x_probe_axes),
        one_x_probe_axes_predicted: w.as_ref().and_then(|w| w.predicted.one_x_probe_axes),
        one_x_phase_lag_error_deg: w.as_ref().and_then(|w| {
            let (p, m) = (w.predicted.one_x_probe_axes?, w.measured.one_x_probe_axes?);
            Some([0, 1].map(|j| phase_difference_deg(p[j].phase_lag_deg, m[j].phase_lag_deg)))
        }),
        phase_null_reason: match &w {
            Some(w) => w.phase_null_reason.map(str::to_string),
            None => Some("no summary window (fewer than 2 revolutions compared)".into()),
        },
        subsync_amplitude_predicted_m: get(|w| w.predicted.subsync_amplitude_m),
        subsync_amplitude_measured_m: get(|w| w.measured.subsync_amplitude_m),
        subsync_ratio_predicted: w.as_ref().and_then(|w| w.predicted.subsync_ratio),
        subsync_ratio_measured: w.as_ref().and_then(|w| w.measured.subsync_ratio),
        orbit_rms_distance_m: get(|w| w.orbit_rms_distance_m),
        mean_position_distance_m: get(|w| w.mean_position_distance_m),
        one_x_ellipse_measured: w.as_ref().map(|w| w.measured.one_x_ellipse),
        one_x_ellipse_predicted: w.as_ref().map(|w| w.predicted.one_x_ellipse),
        one_x_shape: w.as_ref().map(|w| w.one_x_shape),
        subsync_ellipse_measured: w.as_ref().and_then(|w| w.measured.subsync_ellipse),
        subsync_ellipse_predicted: w.as_ref().and_then(|w| w.predicted.subsync_ellipse),
        subsync_shape: w.as_ref().and_then(|w| w.subsync_shape),
        blocks: c.blocks.clone(),
        block_spectra: c.block_spectra.clone(),
        mean_position_null_reason: c.mean_not_measured.clone(),
        centerline_static_predicted: Vec::new(),
    }
}

/// What the memory bound left out at station `c` (issue 17): blocks decimated in the report
/// and plots, transients beyond the first ones; None when nothing was.
fn decimation_note(c: &StationComparison) -> Option<String> {
    let (p, m) = c.transients_dropped();
    if c.block_stride == 1 && p + m == 0 {
        return None;
    }
    Some(format!(
        "{}: {} blocks of {} revolutions; the report and plots keep every {}{} ({} kept, at most {}); the onset, transients and whip are read over every block{}",
        c.station,
        c.blocks_seen,
        super::compare::BLOCK_REVS,
        c.block_stride,
        match c.block_stride { 1 => "", 2 => "nd", _ => "th" },
        c.blocks.len(),
        super::compare::MAX_KEPT_BLOCKS,
        if p + m > 0 {
            format!("; transients beyond the first {} not listed: {p} predicted, {m} measured", super::compare::MAX_TRANSIENTS)
        } else {
            String::new()
        }
    ))
}

/// Speeds of the static-equilibrium locus of the centerline plot over a bag's speed range.
const CENTERLINE_SPEEDS: usize = 12;

impl ReplayReport {
    /// Fills each station's `centerline_static_predicted`: its static-equilibrium position
    /// (films at their equilibrium under the static loads, the shaft statically deflected, as
    /// the twin starts) at 12 speeds over the range of its blocks (one speed for a constant
    /// one). Returns the loci per station of `self.stations`.
    pub fn add_static_centerline(&mut self, rotor: &crate::rotor::Rotor) -> anyhow::Result<()> {
        for st in &mut self.stations {
            let Some(k) = rotor.probes.iter().position(|p| p.name == st.station) else {
                continue;
            };
            let (lo, hi) = st
                .blocks
                .iter()
                .map(|b| b.speed_rpm)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| {
                    (a.0.min(v), a.1.max(v))
                });
            if !lo.is_finite() {
                continue;
            }
            let n = if hi - lo > 1.0 { CENTERLINE_SPEEDS } else { 1 };
            st.centerline_static_predicted = (0..n)
                .map(|i| {
                    let rpm = lo + (hi - lo) * i as f64 / (n.max(2) - 1) as f64;
                    let p = crate::calibrate::static_probe_positions(
                        rotor,
                        1.0,
                        crate::units::rpm_to_rad_s(rpm),
                    )?;
                    Ok(CenterlineStatic {
                        speed_rpm: rpm,
                        position_m: p[k],
                    })
                })
                .collect::<anyhow::Result<_>>()?;
        }
        Ok(())
    }
}
