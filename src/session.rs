//! A twin session: the twin core and its monitor, turning each step into the messages the node
//! publishes and the replay records (journal and film states, orbits, warnings, residuals). It
//! knows no bus, no file and no wall clock: stamps come from the model time plus an epoch the
//! caller gives, and warning reminders are paced in model time, so a replay is deterministic.

use crate::dynamics::{StepInput, Twin, TwinConfig, TwinError};
use crate::messages::*;
use crate::monitor::{
    AlarmLevels, AlarmOverride, BearingRevolution, ClassifierSettings, Monitor, RotorState,
    PRESSURE_POINTS,
};
use crate::rotor::Rotor;

mod history;
use history::ProbeHistory;
pub use history::{PREDICTION_HISTORY_MAX_STEPS, PREDICTION_HISTORY_S};

/// Time a milder warning (state or level) must hold before the warning steps down to it (s of
/// model time). A worse one is announced at once: an alarm is never delayed. One second is
/// the time scale an operator reads a panel on and the order of the alarm delays of
/// machinery-protection systems (API 670); it spans 75 whirl periods of a 0.5X whirl at
/// 9,000 rpm and 14 at 1,700 rpm, so a whirl grazing a threshold cannot flip the warning more
/// than once a second, whatever the speed.
pub const DEFAULT_STATE_HOLD_S: f64 = 1.0;

/// Output rates and warning thresholds of a session (the node's parameters and the replay's
/// options of the same names default to these).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SessionSettings {
    /// Journal and film states per second of model time (Hz). Default 200 Hz: above 22 samples a
    /// revolution at 9,000 rpm would still not draw an orbit (the orbit message does that, once
    /// a revolution); 200 Hz follows the film's slow changes and keeps a bag small.
    pub state_rate_hz: f64,
    /// Film states that carry the mid-plane pressure profile, per second (Hz). Default 2 Hz: a
    /// profile is 64 values a bearing, for looking at, not for analysis.
    pub pressure_map_rate_hz: f64,
    /// Orbit radius over clearance above which a stable rotor still gets a warning (level WARN).
    /// Default 0.5.
    pub warning_amplitude_ratio: f64,
    /// While not stable, the warning is repeated this often (s of model time). Default 1 s.
    pub warning_repeat_s: f64,
    /// A milder warning must hold this long before it is announced (s of model time; default
    /// [`DEFAULT_STATE_HOLD_S`]).
    pub state_hold_s: f64,
    /// Alarm levels instead of the field-practice ones (e.g. the machine file's
    /// `alarm_levels`, through `AlarmOverride::from`); None: API 617 / ISO 20816-3.
    pub alarm_levels: Option<AlarmOverride>,
}

impl Default for SessionSettings {
    fn default() -> Self {
        Self {
            state_rate_hz: 200.0,
            pressure_map_rate_hz: 2.0,
            warning_amplitude_ratio: 0.5,
            warning_repeat_s: 1.0,
            state_hold_s: DEFAULT_STATE_HOLD_S,
            alarm_levels: None,
        }
    }
}

/// A message of the twin, for the bus and the recording.
#[derive(Debug, Clone)]
pub enum Outgoing {
    /// Journal state of one bearing.
    Journal(JournalState),
    /// Film state of one bearing.
    Film(FilmState),
    /// One revolution's orbit of one bearing.
    Orbit(Orbit),
    /// A warning.
    Warning(InstabilityWarning),
    /// Diagnostics.
    Diagnostics(DiagnosticArray),
    /// Predicted minus measured displacement at a probe station.
    Residual(OrbitResidual),
    /// Distance from the linear stability threshold.
    Margin(StabilityMargin),
    /// The twin's look-ahead ([`crate::forecast`]; boxed: it is the largest message).
    Forecast(Box<Forecast>),
}

/// A message header stamped `ns` (ns since the epoch) in frame `frame`.
pub fn header(ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time::from_nanos(ns),
        frame_id: frame.to_string(),
    }
}

/// Most revolutions an Orbit message holds (a whirl order down to 1/4.5 ≈ 0.22X is still a
/// whole loop within half a revolution); the monitor keeps 16.
pub const MAX_ORBIT_REVOLUTIONS: usize = 4;

/// Revolutions in an Orbit message: one, or, when the monitor reports a sub-synchronous
/// component of order `subsync_ratio` (0: none), the whole number of revolutions nearest one
/// sub-synchronous period, 1/`subsync_ratio` revolutions (2 from 0.4X to 2/3X, oil whirl and whip at ≈0.45–0.5X),
/// at most [`MAX_ORBIT_REVOLUTIONS`]: the orbit then closes on itself as the whirl loop does
/// (one revolution at 0.5X is half the loop).
pub fn orbit_revolutions(subsync_ratio: f64) -> usize {
    if subsync_ratio > 0.0 && subsync_ratio < 1.0 {
        ((1.0 / subsync_ratio).round() as usize).clamp(1, MAX_ORBIT_REVOLUTIONS)
    } else {
        1
    }
}

/// What a warning about the twin's inputs or its own running is about (the classification's
/// kinds, none | whirl | whip | contact, come from the monitor's state).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WarningKind {
    /// An input was refused (bad value, bad stamp, undecodable sample).
    BadInput,
    /// An input is overdue (no speed for longer than the timeout, or a gap without input).
    StaleInput,
    /// A step of the model failed; the twin restarts.
    ModelFailure,
    /// The model runs behind the clock.
    FallingBehind,
}

impl WarningKind {
    /// The `kind` field of the message.
    pub fn as_str(self) -> &'static str {
        match self {
            WarningKind::BadInput => "bad_input",
            WarningKind::StaleInput => "stale_input",
            WarningKind::ModelFailure => "model_failure",
            WarningKind::FallingBehind => "falling_behind",
        }
    }
}

/// A warning message of `level` and `kind`.
pub fn warning(ns: i64, level: u8, kind: WarningKind, bearing: &str, evidence: String) -> Outgoing {
    Outgoing::Warning(InstabilityWarning {
        header: header(ns, bearing),
        level,
        kind: kind.as_str().into(),
        bearing: bearing.into(),
        evidence,
        ..Default::default()
    })
}

/// A WARN-level warning about the inputs (bad or stale), of no bearing.
pub fn input_warning(ns: i64, kind: WarningKind, evidence: String) -> Outgoing {
    warning(ns, InstabilityWarning::WARN, kind, "", evidence)
}

/// The twin, its monitor and the message products.
pub struct Session {
    twin: Twin,
    monitor: Monitor,
    settings: SessionSettings,
    names: Vec<String>,
    stations: Vec<String>,
    clearances: Vec<f64>,
    angles: Vec<f64>,
    profile: Vec<f64>,
    epoch_ns: i64,
    step_index: u64,
    decimation: u64,
    map_decimation: u64,
    /// configured alarm levels (None: field practice)
    alarm_override: Option<AlarmOverride>,
    /// the (level, state) last announced by a warning
    announced: (u8, RotorState),
    /// since when (s of model time) the monitor has reported milder than the announced, and
    /// the worst it reported since
    milder_since_s: Option<f64>,
    milder_worst: (u8, RotorState),
    last_warning_s: f64,
    /// the last steps' probe displacements and angles, for a sample's prediction at its stamp
    history: ProbeHistory,
}

impl Session {
    /// Starts a twin of `rotor` at `speed_rad_s` (static equilibrium), its time zero stamped
    /// `epoch_ns` (ns since the epoch).
    pub fn new(
        rotor: &Rotor,
        config: TwinConfig,
        speed_rad_s: f64,
        settings: SessionSettings,
        epoch_ns: i64,
    ) -> Result<Self, TwinError> {
        let twin = Twin::new(rotor, config, speed_rad_s)?;
        let steps_per_rev =
            (std::f64::consts::TAU / rotor.rated_speed_rad_s.max(1e-9) / config.time_step_s)
                .round()
                .max(8.0) as usize;
        // the session's override, else the machine file's levels, else the monitor's defaults
        let classifier = ClassifierSettings {
            alarm_levels: settings
                .alarm_levels
                .or_else(|| rotor.alarm_levels.as_ref().map(Into::into)),
            ..ClassifierSettings::default()
        };
        let monitor = Monitor::new(&twin, 2 * steps_per_rev, classifier);
        let names = twin.bearing_names().map(str::to_string).collect();
        let clearances = twin.bearing_clearances_m();
        let o = twin.output();
        let mut history = ProbeHistory::new(o.probes.len(), config.time_step_s);
        history.push(
            o.time_s,
            o.angle_rad,
            o.probes.iter().map(|p| p.displacement_m),
        );
        let mut s = Self {
            twin,
            monitor,
            settings,
            names,
            stations: rotor.probes.iter().map(|p| p.name.clone()).collect(),
            clearances,
            angles: (0..PRESSURE_POINTS)
                .map(|k| std::f64::consts::TAU * k as f64 / PRESSURE_POINTS as f64)
                .collect(),
            profile: vec![0.0; PRESSURE_POINTS],
            epoch_ns,
            step_index: 0,
            decimation: 1,
            map_decimation: 1,
            alarm_override: classifier.alarm_levels,
            announced: (InstabilityWarning::OK, RotorState::Stable),
            milder_since_s: None,
            milder_worst: (InstabilityWarning::OK, RotorState::Stable),
            last_warning_s: f64::NEG_INFINITY,
            history,
        };
        s.set_settings(settings);
        Ok(s)
    }

    /// Changes the output rates and thresholds (at run time).
    pub fn set_settings(&mut self, settings: SessionSettings) {
        let h = self.twin.config().time_step_s;
        self.settings = settings;
        self.decimation = ((1.0 / settings.state_rate_hz) / h).round().max(1.0) as u64;
        self.map_decimation = ((1.0 / settings.pressure_map_rate_hz) / h).round().max(1.0) as u64;
    }

    /// The twin (read only).
    pub fn twin(&self) -> &Twin {
        &self.twin
    }

    /// The monitor (read only; the forecast continues a copy of it).
    pub fn monitor(&self) -> &Monitor {
        &self.monitor
    }

    /// The twin, to change its unbalance or forces.
    pub fn twin_mut(&mut self) -> &mut Twin {
        &mut self.twin
    }

    /// Model time zero, ns since the epoch.
    pub fn epoch_ns(&self) -> i64 {
        self.epoch_ns
    }

    /// Sets model time zero (ns since the epoch), e.g. to the first `/clock` time.
    pub fn set_epoch_ns(&mut self, epoch_ns: i64) {
        self.epoch_ns = epoch_ns;
    }

    /// The stamp (ns since the epoch) of the twin's present time.
    pub fn stamp_ns(&self) -> i64 {
        self.epoch_ns + (self.twin.time_s() * 1e9).round() as i64
    }

    /// Turns the twin's shaft angle by `delta_rad` (rad), also the angle its probe predictions
    /// are interpolated from (the keyphasor lock).
    pub fn shift_angle(&mut self, delta_rad: f64) {
        if delta_rad.is_finite() {
            self.twin.shift_angle(delta_rad);
            self.history.shift_angles(delta_rad);
        }
    }

    /// Re-references the twin's angle, and the angles its probe predictions are interpolated
    /// from, to a keyphasor mark turned by `delta_rad` (rad) against the shaft, its heavy spots
    /// by −`delta_rad`: the motion unchanged ([`crate::dynamics::Twin::turn_reference`]).
    pub fn turn_reference(&mut self, delta_rad: f64) {
        if delta_rad.is_finite() {
            self.twin.turn_reference(delta_rad);
            self.history.shift_angles(delta_rad);
        }
    }

    /// The twin's shaft angle (rad) at `stamp_ns` (ns since the epoch), extrapolated from its
    /// present time at its present speed.
    pub fn angle_at(&self, stamp_ns: i64) -> f64 {
        let o = self.twin.output();
        let t = (stamp_ns - self.epoch_ns) as f64 * 1e-9;
        o.angle_rad + o.speed_rad_s * (t - o.time_s)
    }

    /// Advances one step and hands its messages to `emit`. On an error the twin state is
    /// unchanged and nothing is emitted.
    pub fn step(
        &mut self,
        input: &StepInput,
        emit: &mut impl FnMut(Outgoing),
    ) -> Result<(), TwinError> {
        self.twin.step(input)?;
        {
            let o = self.twin.output();
            let probes = o.probes.iter().map(|p| p.displacement_m);
            self.history.push(o.time_s, o.angle_rad, probes);
        }
        self.step_index += 1;
        let stamp = self.stamp_ns();
        if self.step_index.is_multiple_of(self.decimation) {
            self.emit_states(stamp, emit);
        }
        if self.monitor.record(&self.twin).is_some() {
            self.emit_revolution(stamp, emit);
        }
        Ok(())
    }

    /// The predicted displacement (m) of probe station `station` at model time `time_s`, and
    /// the shaft angle (rad) there: linear between the two kept steps that bracket it (the last
    /// [`PREDICTION_HISTORY_S`]), clamped to the oldest and the newest, so a sample delivered
    /// late is compared with the twin at its own stamp.
    pub fn predicted_probe(&self, station: usize, time_s: f64) -> Option<([f64; 2], f64)> {
        self.history.at(station, time_s)
    }

    /// The residual message for a measured displacement (m) at station `station` stamped
    /// `stamp_ns`, against the prediction at that time (None for an unknown station).
    pub fn residual(
        &self,
        station: usize,
        measured: [f64; 2],
        stamp_ns: i64,
    ) -> Option<OrbitResidual> {
        let name = self.stations.get(station)?;
        let t = (stamp_ns - self.epoch_ns) as f64 * 1e-9;
        let ([px, py], _) = self.predicted_probe(station, t)?;
        Some(OrbitResidual {
            header: header(stamp_ns, name),
            station: name.clone(),
            predicted_x: px,
            predicted_y: py,
            measured_x: measured[0],
            measured_y: measured[1],
            residual_x: px - measured[0],
            residual_y: py - measured[1],
        })
    }

    fn emit_states(&mut self, stamp: i64, emit: &mut impl FnMut(Outgoing)) {
        let with_map = self.step_index.is_multiple_of(self.map_decimation);
        for k in 0..self.names.len() {
            let o = self.twin.output();
            let b = o.bearings[k];
            let speed = o.speed_rad_s;
            emit(Outgoing::Journal(JournalState {
                header: header(stamp, &self.names[k]),
                bearing: self.names[k].clone(),
                x: b.position_m[0],
                y: b.position_m[1],
                vx: b.velocity_m_s[0],
                vy: b.velocity_m_s[1],
                eccentricity_ratio: b.eccentricity_ratio,
                attitude: b.attitude_rad,
                speed,
                contact: b.contact,
            }));
            if with_map {
                self.twin.midplane_pressure(k, &mut self.profile);
            }
            emit(Outgoing::Film(FilmState {
                header: header(stamp, &self.names[k]),
                bearing: self.names[k].clone(),
                force_x: b.force_n[0],
                force_y: b.force_n[1],
                max_pressure: b.max_pressure_pa,
                max_pressure_angle: b.max_pressure_angle_rad,
                film_start: b.film_start_rad,
                film_end: b.film_end_rad,
                power_loss: b.power_loss_w,
                pressure_angles: if with_map {
                    self.angles.clone()
                } else {
                    Vec::new()
                },
                pressure: if with_map {
                    self.profile.clone()
                } else {
                    Vec::new()
                },
            }));
        }
    }

    /// Orbits of the revolution just completed, and a warning on a change of state (repeated
    /// every `warning_repeat_s` of model time while not stable).
    fn emit_revolution(&mut self, stamp: i64, emit: &mut impl FnMut(Outgoing)) {
        let rep = self.monitor.report();
        for (k, b) in rep.bearings.iter().enumerate() {
            let orbit = self
                .monitor
                .recent_orbit(k, orbit_revolutions(b.subsync_ratio));
            emit(Outgoing::Orbit(Orbit {
                header: header(stamp, &self.names[k]),
                bearing: self.names[k].clone(),
                revolution: rep.revolution,
                speed: rep.speed_rad_s,
                clearance: self.clearances[k],
                x: orbit.iter().map(|p| p[0]).collect(),
                y: orbit.iter().map(|p| p[1]).collect(),
                one_x_amplitude: b.one_x_amplitude_m,
                subsync_ratio: b.subsync_ratio,
                subsync_amplitude: b.subsync_amplitude_m,
            }));
        }
        let now = self.twin.time_s();
        let Some((k, b)) = rep
            .bearings
            .iter()
            .enumerate()
            .max_by(|a, b| {
                (warning_level(a.1), a.1.state)
                    .cmp(&(warning_level(b.1), b.1.state))
                    .then(a.1.amplitude_m.total_cmp(&b.1.amplitude_m))
            })
            .map(|(k, b)| (k, *b))
        else {
            return;
        };
        let (rep_state, speed_rad_s) = (rep.state, rep.speed_rad_s);
        let announce = self.hold((warning_level(&b), rep_state), now);
        let reminder = announce.1 != RotorState::Stable
            && now - self.last_warning_s >= self.settings.warning_repeat_s;
        if announce == self.announced && !reminder {
            return;
        }
        self.last_warning_s = now;
        self.announced = announce;
        let (level, state) = announce;
        let clearance = self.clearances.get(k).copied().unwrap_or(1.0);
        let amplitude_ratio = b.amplitude_m / clearance;
        let level = if state == RotorState::Stable
            && amplitude_ratio > self.settings.warning_amplitude_ratio
        {
            level.max(InstabilityWarning::WARN)
        } else {
            level
        };
        let speed_rpm = speed_rad_s * 30.0 / std::f64::consts::PI;
        let levels = AlarmLevels::new(clearance, speed_rpm, self.alarm_override);
        emit(Outgoing::Warning(InstabilityWarning {
            header: header(stamp, self.names.get(k).map_or("", String::as_str)),
            level,
            kind: state.warning_kind().into(),
            bearing: self.names.get(k).cloned().unwrap_or_default(),
            whirl_ratio: b.subsync_ratio,
            amplitude_over_clearance: amplitude_ratio,
            evidence: self.monitor.report().evidence(),
            growth_per_rev: b.subsync_growth_per_rev.unwrap_or(0.0),
            time_to_alert: b.time_to_alert_s.unwrap_or(-1.0),
            amplitude: b.amplitude_m,
            alert_level: levels.alert_m,
            danger_level: levels.danger_m,
            alarm_basis: levels.basis,
            contact: b.contact,
            contact_count: b.contact_events,
            max_penetration: b.max_penetration_m,
            beyond_clearance: b.beyond_clearance,
        }));
    }

    /// The hysteresis: a worse (level, state) than the announced one is announced at once; a
    /// milder one once the monitor has reported milder for `state_hold_s`, and then the worst
    /// it reported in that time.
    fn hold(&mut self, candidate: (u8, RotorState), now_s: f64) -> (u8, RotorState) {
        if candidate >= self.announced {
            self.milder_since_s = None;
            return candidate;
        }
        match self.milder_since_s {
            None => {
                self.milder_since_s = Some(now_s);
                self.milder_worst = candidate;
            }
            Some(_) => self.milder_worst = self.milder_worst.max(candidate),
        }
        let since = self.milder_since_s.unwrap_or(now_s);
        if now_s - since >= self.settings.state_hold_s {
            self.milder_since_s = None;
            self.milder_worst
        } else {
            self.announced
        }
    }
}

/// The warning level of one bearing's revolution: ERROR for whip, wall contact, a journal
/// beyond the clearance or an amplitude at the danger level; WARN for a growing or whirling
/// sub-synchronous component or an amplitude at the alert level; else OK.
pub fn warning_level(b: &BearingRevolution) -> u8 {
    if b.state == RotorState::Whip
        || b.contact
        || b.beyond_clearance
        || (b.danger_level_m > 0.0 && b.amplitude_m >= b.danger_level_m)
    {
        InstabilityWarning::ERROR
    } else if b.state != RotorState::Stable
        || (b.alert_level_m > 0.0 && b.amplitude_m >= b.alert_level_m)
    {
        InstabilityWarning::WARN
    } else {
        InstabilityWarning::OK
    }
}

/// The linear stability threshold of `rotor` from its damped eigenvalues at the static
/// equilibrium, searched from 10 % to 200 % of the rated speed: Some((speed rad/s, whirl
/// ratio)), or None if stable over that range or not computable.
pub fn linear_threshold(rotor: &Rotor) -> Option<(f64, f64)> {
    let rated_rpm = rotor.rated_speed_rad_s * 30.0 / std::f64::consts::PI;
    let st = crate::rotor::static_solution(rotor).ok()?;
    let found = crate::rotor::stability_threshold(
        rotor,
        &st,
        (0.1 * rated_rpm).max(100.0),
        2.0 * rated_rpm,
        rated_rpm / 20.0,
    )
    .ok()??;
    Some((
        found.speed_rpm * std::f64::consts::PI / 30.0,
        found.whirl_ratio,
    ))
}

/// The stability margin message at speed `speed_rad_s` against `threshold` (as from
/// [`linear_threshold`]), stamped `ns`.
pub fn margin(ns: i64, speed_rad_s: f64, threshold: Option<(f64, f64)>) -> StabilityMargin {
    let (threshold_found, threshold_speed, whirl_ratio) = match threshold {
        Some((s, r)) => (true, s, r),
        None => (false, 0.0, 0.0),
    };
    StabilityMargin {
        header: header(ns, ""),
        speed: speed_rad_s,
        threshold_found,
        threshold_speed,
        margin: if threshold_found {
            threshold_speed - speed_rad_s
        } else {
            0.0
        },
        whirl_ratio,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::Coupling;
    use crate::rotor::MachineDescription;

    /// The hysteresis in model time: a worse (level, state) at once; a milder one only after
    /// it has been reported for `state_hold_s` (1 s), and then the worst reported in that time;
    /// a flicker within the hold changes nothing.
    #[test]
    fn a_milder_warning_waits_for_the_hold_time() {
        let rotor = Rotor::from_description(&MachineDescription::builtin_default());
        let omega = rotor.rated_speed_rad_s;
        let config = TwinConfig::with_steps_per_rev(Coupling::Linear, omega, 64);
        let mut s = Session::new(&rotor, config, omega, SessionSettings::default(), 0).unwrap();
        let (ok, warn, err) = (
            InstabilityWarning::OK,
            InstabilityWarning::WARN,
            InstabilityWarning::ERROR,
        );
        let whip = (err, RotorState::Whip);
        let whirl = (warn, RotorState::Whirl);
        let stable = (ok, RotorState::Stable);
        assert_eq!(s.hold(whip, 0.0), whip);
        s.announced = whip;
        // whirl and stable alternate for 0.99 s: still whip
        for k in 1..100 {
            let c = if k % 2 == 0 { whirl } else { stable };
            assert_eq!(s.hold(c, 0.01 * k as f64), whip, "at {} s", 0.01 * k as f64);
        }
        // after 1 s of milder reports: the worst of them
        assert_eq!(s.hold(stable, 1.05), whirl);
        s.announced = whirl;
        // worse again: at once
        assert_eq!(s.hold(whip, 1.06), whip);
    }
}
