//! The driver: the one loop around a [`Session`] that the live node and the replay share. It
//! takes timed inputs (speed, unbalance, probe samples) in any time base — the wall clock or
//! `/clock` for the node, bag time for the replay — checks them against the running machine's
//! limits, starts, pauses and restarts the twin, keeps the unbalance across restarts, steps the
//! twin up to each input's time, compares probes with the prediction, and emits the warnings
//! (bad, stale or missing input; model failures) and the stability margin. It knows no bus, file
//! or clock: the same inputs at the same times give the same outputs, whoever feeds them.

pub mod calibration;
mod clock;
mod heat_worker;
pub mod inputs;
mod observer;
mod oil;
pub mod one_x;
mod plant_signals;
pub mod settings;

pub use calibration::{Applied, LiveCalibration, LiveEstimate, MeasuredSet};
pub use clock::{ClockSample, SimClock, CLOCK_CONFIRM, CLOCK_JUMP_S};
pub use inputs::{
    check_probe, check_unbalance, seconds_to_ns, Input, InputLimits, ProbeRef, SpeedGate,
    SpeedUnit, StationRef,
};
pub use observer::ObserverGains;
pub use oil::{
    speed_moved_past_balance, FilmOil, HeatBalanceReport, HeatedFilm, OilDiagnostics,
    HEAT_BALANCE_SPEED_STEP, HEAT_BALANCE_TEMPERATURE_STEP_K,
};
pub use one_x::{OneXBlock, OneXBlocks};
pub use plant_signals::{SignalState, StationSource, PAIR_TOLERANCE_REVS};
pub use settings::{film_name, parse_film, DriverSettings, ModelKind};

use crate::dynamics::StepInput;
use crate::messages::InstabilityWarning;
use crate::rotor::Rotor;
use crate::session::{
    input_warning, margin, warning, Outgoing, Session, SessionSettings, WarningKind,
};

/// Interval between stability-margin messages (s of driver time): 1 Hz, the diagnostics rate.
pub const MARGIN_INTERVAL_S: f64 = 1.0;

/// Shortest interval between two `bad_input` warnings (s of driver time); every refusal is
/// counted, and the next warning carries the count.
pub const REFUSAL_WARNING_INTERVAL_S: f64 = 1.0;

/// What became of one input.
#[derive(Debug, Clone, PartialEq)]
pub enum Fed {
    /// Taken (a speed or an unbalance), nothing else to tell.
    Taken,
    /// A speed that (re)started the twin from the static equilibrium.
    Started {
        /// The speed it started at (rad/s).
        speed_rad_s: f64,
    },
    /// A probe sample compared with the prediction.
    Compared(ProbeComparison),
    /// A probe sample that arrived while no twin was running.
    Unused,
    /// Refused, with the reason (counted, and warned about).
    Refused(String),
}

/// A measured probe sample beside the prediction at its time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeComparison {
    /// Probe station index.
    pub station: usize,
    /// The sample's time (ns, the driver's time base).
    pub time_ns: i64,
    /// Shaft angle of the twin there (rad).
    pub angle_rad: f64,
    /// Speed of the twin there (rad/s).
    pub speed_rad_s: f64,
    /// Measured displacement (m).
    pub measured_m: [f64; 2],
    /// Predicted displacement (m).
    pub predicted_m: [f64; 2],
    /// Whether the twin's angle (`angle_rad`) is locked to the plant's keyphasor here.
    pub phase_reference: crate::signals::PhaseReference,
}

/// What the driver counted since it was made.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DriverCounts {
    /// Inputs refused (bad value, bad stamp, undecodable).
    pub refused: u64,
    /// Starts of the twin from the static equilibrium.
    pub starts: u64,
    /// Steps that failed (each stops the twin until the next speed).
    pub step_failures: u64,
    /// Steps taken.
    pub steps: u64,
    /// Probe samples (pairs, or raw readings paired) that were valid but not compared: no
    /// twin ran at their time (before the first speed, below the minimum speed, after a
    /// failed step).
    pub probes_not_compared: u64,
    /// Raw probe readings never paired with their station's other probe (the next reading of
    /// the same probe came first: the other probe's reading was lost or stamped too far off).
    pub readings_unpaired: u64,
    /// Probe samples refused because another source feeds their station (raw probes and a
    /// `ProbeDisplacement` topic for one station: [`StationSource`]).
    pub second_source_refused: u64,
    /// Keyphasor relocks: the mark moved against the shaft and held (phases re-referenced).
    pub relocks: u64,
    /// Steady speed mismatches found between the keyphasor and the speed topic (each scales
    /// the speed topic: [`Driver::speed_scale`]).
    pub speed_mismatches: u64,
}

/// The latest accepted speed input.
#[derive(Debug, Clone, Copy)]
struct SpeedInput {
    /// shaft speed (rad/s)
    speed_rad_s: f64,
    /// its rate of change (rad/s²)
    accel_rad_s2: f64,
    /// when it came, on the driver's clock (ns)
    received_ns: i64,
}

/// An unbalance received for one plane.
#[derive(Debug, Clone, Copy)]
struct PlaneUnbalance {
    /// m·e (kg·m)
    magnitude_kg_m: f64,
    /// phase from the shaft's zero mark (rad)
    phase_rad: f64,
}

/// The twin of one machine, driven by timed inputs.
pub struct Driver {
    rotor: Rotor,
    settings: DriverSettings,
    limits: InputLimits,
    gate: SpeedGate,
    session: Option<Session>,
    /// the latest accepted speed
    speed: Option<SpeedInput>,
    /// the latest accepted unbalance per plane, applied at every start
    unbalance: Vec<Option<PlaneUnbalance>>,
    /// the linear stability threshold once known: Some((rad/s, whirl ratio)) or None
    threshold: Option<Option<(f64, f64)>>,
    last_input_ns: Option<i64>,
    next_margin_ns: i64,
    last_stale_warning_ns: Option<i64>,
    /// refusals not yet warned about, and when the last bad_input warning went out (ns)
    refused_unwarned: u64,
    last_refusal_warning_ns: Option<i64>,
    last_refusal: String,
    /// when the last "probe stamped off the clock" warning went out (ns)
    last_off_clock_warning_ns: Option<i64>,
    counts: DriverCounts,
    /// the last accepted oil supply temperature (K)
    oil_temperature_k: Option<f64>,
    /// keyphasor lock and raw-probe state (issue 12)
    signals: SignalState,
    /// the live calibration in force, if applied (issue 12)
    calibration: Option<Applied>,
    /// the viscosity scale of the last accepted oil temperature (kept while a calibrated
    /// viscosity is in force)
    oil_scale: Option<f64>,
    /// an applied calibrated viscosity as a factor on the law: the fitted scale over the oil
    /// temperature's scale when it was applied (1 without a temperature), so later temperatures
    /// still move the viscosity
    viscosity_correction: Option<f64>,
    /// each film bearing's oil: law and heated scales, effective temperatures (issue 12)
    oil: oil::OilState,
    /// an applied calibration on its way into the running nonlinear twin
    blend: Option<calibration::Blend>,
    /// the nudging observer, when on (issue 12, session 14)
    observer: Option<observer::Observer>,
}

impl Driver {
    /// A driver for `rotor`; no twin runs until the first speed at or above the minimum.
    pub fn new(rotor: Rotor, settings: DriverSettings) -> Self {
        let limits = InputLimits::of(&rotor);
        let gate = SpeedGate::new(limits.max_speed_rad_s, settings.input_timeout_s);
        let oil = oil::OilState::of(&rotor, &settings);
        Self {
            unbalance: vec![None; rotor.unbalance.len()],
            rotor,
            settings,
            limits,
            gate,
            session: None,
            speed: None,
            threshold: None,
            last_input_ns: None,
            next_margin_ns: i64::MIN,
            last_stale_warning_ns: None,
            refused_unwarned: 0,
            last_off_clock_warning_ns: None,
            last_refusal_warning_ns: None,
            last_refusal: String::new(),
            counts: DriverCounts::default(),
            oil_temperature_k: None,
            signals: SignalState::default(),
            calibration: None,
            oil_scale: None,
            viscosity_correction: None,
            oil,
            blend: None,
            observer: None,
        }
    }

    /// The machine the twin models.
    pub fn rotor(&self) -> &Rotor {
        &self.rotor
    }

    /// The settings in force.
    pub fn settings(&self) -> &DriverSettings {
        &self.settings
    }

    /// The limits inputs are checked against (from this machine).
    pub fn limits(&self) -> &InputLimits {
        &self.limits
    }

    /// The running session, if a twin runs.
    pub fn session(&self) -> Option<&Session> {
        self.session.as_ref()
    }

    /// The running session as an Option (for code that takes `&Option<Session>`).
    pub fn session_slot(&self) -> &Option<Session> {
        &self.session
    }

    /// What was counted so far.
    pub fn counts(&self) -> DriverCounts {
        self.counts
    }

    /// The latest accepted speed (rad/s).
    pub fn speed_rad_s(&self) -> Option<f64> {
        self.speed.map(|s| s.speed_rad_s)
    }

    /// The latest accepted speed and acceleration (rad/s, rad/s²): what the twin is stepped at
    /// (the forecast's starting point).
    pub fn speed_input(&self) -> Option<(f64, f64)> {
        self.speed.map(|s| (s.speed_rad_s, s.accel_rad_s2))
    }

    /// The linear stability threshold (rad/s, whirl ratio), if known and found.
    pub fn linear_threshold(&self) -> Option<(f64, f64)> {
        self.threshold.flatten()
    }

    /// Age (s) of the latest accepted speed at `now_ns`.
    pub fn speed_age_s(&self, now_ns: i64) -> Option<f64> {
        self.speed.map(|s| (now_ns - s.received_ns) as f64 * 1e-9)
    }

    /// The linear stability threshold (as [`crate::session::linear_threshold`] gives it), once
    /// known; the margin is published from then on.
    pub fn set_threshold(&mut self, threshold: Option<(f64, f64)>) {
        self.threshold = Some(threshold);
    }

    /// True once the linear threshold has been given.
    pub fn threshold_known(&self) -> bool {
        self.threshold.is_some()
    }

    /// Changes the settings that may change while running: output rates and thresholds, the
    /// minimum speed, the input timeout. The twin's configuration stays.
    pub fn set_runtime(&mut self, session: SessionSettings, min_speed_rad_s: f64, timeout_s: f64) {
        self.settings.session = session;
        self.settings.min_speed_rad_s = min_speed_rad_s;
        self.settings.input_timeout_s = timeout_s;
        self.gate.timeout_ns = seconds_to_ns(timeout_s);
        if let Some(s) = self.session.as_mut() {
            s.set_settings(session);
        }
    }

    /// One input received at `now_ns`: the twin is first stepped up to `now_ns`, then the input
    /// is checked and applied.
    pub fn feed(&mut self, now_ns: i64, input: Input, emit: &mut impl FnMut(Outgoing)) -> Fed {
        self.advance_to(now_ns, usize::MAX, emit);
        self.last_input_ns = Some(now_ns);
        let is_speed = matches!(input, Input::Speed { .. });
        let fed = match input {
            Input::Speed {
                speed_rad_s,
                accel_rad_s2,
                stamp_ns,
            } => self.take_speed(now_ns, speed_rad_s, accel_rad_s2, stamp_ns, false, emit),
            Input::Unbalance {
                plane,
                magnitude_kg_m,
                phase_rad,
            } => self.take_unbalance(plane, magnitude_kg_m, phase_rad),
            Input::Probe {
                station,
                x_m,
                y_m,
                stamp_ns,
            } => match self.claim_displacement(now_ns, &station) {
                Ok(()) => self.compare_probe(now_ns, &station, [x_m, y_m], stamp_ns, emit),
                Err(why) => Fed::Refused(why),
            },
            Input::OilTemperature { temperature_k, .. } => self.take_oil_temperature(temperature_k),
            Input::Keyphasor { stamp_ns } => self.take_keyphasor(now_ns, stamp_ns, emit),
            Input::ProbeSignal {
                probe,
                value,
                stamp_ns,
            } => self.take_probe_signal(now_ns, &probe, value, stamp_ns, emit),
        };
        if is_speed && matches!(fed, Fed::Taken | Fed::Started { .. }) {
            self.follow_speed_heating();
        }
        match &fed {
            Fed::Refused(why) => self.note_refused(now_ns, why, emit),
            Fed::Unused => self.counts.probes_not_compared += 1,
            _ => {}
        }
        self.emit_margin(now_ns, emit);
        fed
    }

    /// Counts an input refused before it became an [`Input`] (e.g. a sample that does not
    /// decode) and warns, as for any refused input.
    pub fn refuse(&mut self, now_ns: i64, why: &str, emit: &mut impl FnMut(Outgoing)) {
        self.last_input_ns = Some(now_ns);
        self.note_refused(now_ns, why, emit);
    }

    /// Steps the twin while its time is before `now_ns`, at most `max_steps` steps (the node
    /// bounds the work of one wake); stops it after a gap without input, warns of a stale speed
    /// and publishes the margin. Returns the steps taken.
    pub fn advance_to(
        &mut self,
        now_ns: i64,
        max_steps: usize,
        emit: &mut impl FnMut(Outgoing),
    ) -> usize {
        self.check_gap(now_ns, emit);
        self.check_stale(now_ns, emit);
        self.check_keyphasor_stop(now_ns, emit);
        self.warn_refusals(now_ns, emit);
        let mut taken = 0;
        self.take_finished_heat();
        self.blend_targets();
        while taken < max_steps && self.session.as_ref().is_some_and(|s| s.stamp_ns() < now_ns) {
            // an applied calibration moves the twin's values on before each step
            self.blend_step();
            match self.step_once(emit) {
                0 => break,
                n => taken += n,
            }
        }
        self.counts.steps += taken as u64;
        self.emit_margin(now_ns, emit);
        taken
    }

    /// One step of the running twin at the speed in force (1), or none (0: no twin or speed,
    /// or the step failed: warned, the twin stops).
    fn step_once(&mut self, emit: &mut impl FnMut(Outgoing)) -> usize {
        let (Some(s), Some(speed)) = (self.session.as_mut(), self.speed) else {
            return 0;
        };
        let input = StepInput {
            speed_rad_s: speed.speed_rad_s,
            accel_rad_s2: speed.accel_rad_s2,
        };
        if let Err(e) = s.step(&input, emit) {
            emit(warning(
                s.stamp_ns(),
                InstabilityWarning::ERROR,
                WarningKind::ModelFailure,
                "",
                format!("step failed: {e}; the twin restarts at the next speed"),
            ));
            self.session = None;
            self.counts.step_failures += 1;
            return 0;
        }
        1
    }

    fn take_speed(
        &mut self,
        now_ns: i64,
        w: f64,
        a: f64,
        stamp_ns: i64,
        from_keyphasor: bool,
        emit: &mut impl FnMut(Outgoing),
    ) -> Fed {
        let stamp_ns = if self.settings.check_speed_stamps {
            stamp_ns
        } else {
            0
        };
        let (mut w, mut a) = match self.gate.check(w, a, stamp_ns, now_ns) {
            Ok(v) => v,
            Err(why) => return Fed::Refused(why),
        };
        if let (false, Some(k)) = (from_keyphasor, self.signals.speed_scale) {
            // the keyphasor found the topic off by a steady factor: the shaft's speed
            (w, a) = (w * k, a * k);
        }
        self.speed = Some(SpeedInput {
            speed_rad_s: w,
            accel_rad_s2: a,
            received_ns: now_ns,
        });
        self.last_stale_warning_ns = None;
        self.signals.speed_from_keyphasor = from_keyphasor;
        if w < self.settings.min_speed_rad_s {
            // below the model's range: pause, and start afresh when the speed is back
            self.session = None;
            return Fed::Taken;
        }
        if self.session.is_some() || self.keyphasor_defers_start(now_ns) {
            return Fed::Taken;
        }
        self.start(now_ns, w, emit)
    }

    /// A twin from the static equilibrium at `w` (rad/s), its time zero at `now_ns`, with every
    /// unbalance received so far.
    fn start(&mut self, now_ns: i64, w: f64, emit: &mut impl FnMut(Outgoing)) -> Fed {
        let s = Session::new(
            &self.rotor,
            self.settings.twin,
            w,
            self.settings.session,
            now_ns,
        );
        let mut s = match s {
            Ok(s) => s,
            Err(e) => {
                emit(warning(
                    now_ns,
                    InstabilityWarning::ERROR,
                    WarningKind::BadInput,
                    "",
                    format!("cannot start the twin at {w:.1} rad/s: {e}"),
                ));
                return Fed::Taken;
            }
        };
        let calibrated = self
            .calibration
            .as_ref()
            .is_some_and(|c| c.unbalance.is_some());
        for plane in 0..self.unbalance.len() {
            if self.unbalance[plane].is_some() || calibrated {
                let (me, phase) = self.unbalance_in_force(plane);
                // checked when received or applied: the plane exists and the values are finite
                let _ = s.twin_mut().set_unbalance(plane, me, phase);
            }
        }
        self.session = Some(s);
        self.blend = None;
        if let Some(o) = self.observer.as_mut() {
            o.reset();
        }
        self.signals.keyphasor.unlock();
        self.counts.starts += 1;
        Fed::Started { speed_rad_s: w }
    }

    fn take_unbalance(&mut self, plane: u32, me: f64, phase: f64) -> Fed {
        match check_unbalance(plane, me, phase, self.limits.planes) {
            Ok((p, me, phase)) => {
                self.unbalance[p] = Some(PlaneUnbalance {
                    magnitude_kg_m: me,
                    phase_rad: phase,
                });
                if let Some(s) = self.session.as_mut() {
                    if let Err(e) = s.twin_mut().set_unbalance(p, me, phase) {
                        return Fed::Refused(format!("unbalance: {e}"));
                    }
                }
                Fed::Taken
            }
            Err(why) => Fed::Refused(why),
        }
    }

    /// Claims the station of a `ProbeDisplacement` pair for that source ([`StationSource`]).
    fn claim_displacement(&mut self, now_ns: i64, station: &StationRef) -> Result<(), String> {
        let k = self.limits.station(station)?;
        self.claim_station(k, StationSource::Displacement, now_ns)
    }

    fn compare_probe(
        &mut self,
        now_ns: i64,
        station: &StationRef,
        measured: [f64; 2],
        stamp_ns: i64,
        emit: &mut impl FnMut(Outgoing),
    ) -> Fed {
        let k = match self.limits.station(station) {
            Ok(k) => k,
            Err(why) => return Fed::Refused(why),
        };
        if let Err(why) = check_probe(measured[0], measured[1]) {
            return Fed::Refused(why);
        }
        // the sample's own stamp where it is on the driver's clock, else its receive time
        let tolerance = seconds_to_ns(self.settings.input_timeout_s);
        let off_ns = stamp_ns.saturating_sub(now_ns);
        let time_ns = if stamp_ns == 0 {
            now_ns
        } else if off_ns.abs() <= tolerance {
            stamp_ns
        } else {
            self.warn_off_clock(now_ns, k, off_ns, emit);
            now_ns
        };
        let newest = self
            .signals
            .newest_sample_ns
            .map_or(time_ns, |n| n.max(time_ns));
        self.signals.newest_sample_ns = Some(newest);
        let Some(s) = self.session.as_ref() else {
            return Fed::Unused;
        };
        let Some(r) = s.residual(k, measured, time_ns) else {
            return Fed::Unused;
        };
        let t = (time_ns - s.epoch_ns()) as f64 * 1e-9;
        let (_, angle_rad) = s.predicted_probe(k, t).unwrap_or_default();
        let comparison = ProbeComparison {
            station: k,
            time_ns,
            angle_rad,
            speed_rad_s: s.twin().output().speed_rad_s,
            measured_m: measured,
            predicted_m: [r.predicted_x, r.predicted_y],
            phase_reference: self.phase_reference(time_ns),
        };
        emit(Outgoing::Residual(r));
        let residual = [0, 1].map(|j| measured[j] - comparison.predicted_m[j]);
        self.observe(k, residual, t);
        Fed::Compared(comparison)
    }

    /// A probe sample stamped further than the input timeout from its receive time is compared
    /// at its receive time, and said so: at once, then at most once per
    /// [`REFUSAL_WARNING_INTERVAL_S`] (issue 15, item 13: ±1 h stamps were compared silently).
    fn warn_off_clock(
        &mut self,
        now_ns: i64,
        k: usize,
        off_ns: i64,
        emit: &mut impl FnMut(Outgoing),
    ) {
        let interval = seconds_to_ns(REFUSAL_WARNING_INTERVAL_S);
        if self
            .last_off_clock_warning_ns
            .is_some_and(|t| now_ns < t.saturating_add(interval))
        {
            return;
        }
        self.last_off_clock_warning_ns = Some(now_ns);
        let name = self.limits.stations.get(k).map_or("", String::as_str);
        emit(input_warning(
            now_ns,
            WarningKind::StaleInput,
            format!(
                "probe station '{name}' stamped {:+.3} s from its receive time (over {} s): compared at the receive time",
                off_ns as f64 * 1e-9,
                self.settings.input_timeout_s
            ),
        ));
    }

    /// Counts a refusal; the `bad_input` warning goes out at once, then at most once per
    /// [`REFUSAL_WARNING_INTERVAL_S`] with the count since the last one (a flood of bad samples
    /// must not flood the warning topic).
    fn note_refused(&mut self, now_ns: i64, why: &str, emit: &mut impl FnMut(Outgoing)) {
        self.counts.refused += 1;
        self.refused_unwarned += 1;
        self.last_refusal.clear();
        self.last_refusal.push_str(why);
        self.warn_refusals(now_ns, emit);
    }

    fn warn_refusals(&mut self, now_ns: i64, emit: &mut impl FnMut(Outgoing)) {
        let interval = seconds_to_ns(REFUSAL_WARNING_INTERVAL_S);
        let due = self
            .last_refusal_warning_ns
            .is_none_or(|t| now_ns >= t.saturating_add(interval));
        if self.refused_unwarned == 0 || !due {
            return;
        }
        emit(input_warning(
            now_ns,
            WarningKind::BadInput,
            format!(
                "{} input(s) rejected ({} in all); last: {}",
                self.refused_unwarned, self.counts.refused, self.last_refusal
            ),
        ));
        self.refused_unwarned = 0;
        self.last_refusal_warning_ns = Some(now_ns);
    }

    /// After `max_gap_s` without any input the twin stops (a recording that spans a pause is
    /// not modelled through it).
    fn check_gap(&mut self, now_ns: i64, emit: &mut impl FnMut(Outgoing)) {
        let Some(last) = self.last_input_ns else {
            return;
        };
        let gap = now_ns.saturating_sub(last);
        if self.session.is_some() && gap > seconds_to_ns(self.settings.max_gap_s) {
            self.session = None;
            emit(input_warning(
                now_ns,
                WarningKind::StaleInput,
                format!(
                    "no input for {:.3} s (over {} s): the twin stops and restarts at the next speed",
                    gap as f64 * 1e-9,
                    self.settings.max_gap_s
                ),
            ));
        }
    }

    /// A speed older than the timeout is warned about, once per timeout interval, and held.
    fn check_stale(&mut self, now_ns: i64, emit: &mut impl FnMut(Outgoing)) {
        let (Some(speed), true) = (self.speed, self.session.is_some()) else {
            return;
        };
        let (w, at) = (speed.speed_rad_s, speed.received_ns);
        let timeout = seconds_to_ns(self.settings.input_timeout_s);
        let due = self
            .last_stale_warning_ns
            .map_or(at.saturating_add(timeout), |t| t.saturating_add(timeout));
        if now_ns <= due {
            return;
        }
        self.last_stale_warning_ns = Some(now_ns);
        emit(input_warning(
            now_ns,
            WarningKind::StaleInput,
            format!(
                "no speed for {:.2} s; holding {w:.1} rad/s",
                (now_ns - at) as f64 * 1e-9
            ),
        ));
    }

    fn emit_margin(&mut self, now_ns: i64, emit: &mut impl FnMut(Outgoing)) {
        let (Some(threshold), Some(w)) = (self.threshold, self.speed_rad_s()) else {
            return;
        };
        if now_ns < self.next_margin_ns {
            return;
        }
        emit(Outgoing::Margin(margin(now_ns, w, threshold)));
        self.next_margin_ns = now_ns.saturating_add(seconds_to_ns(MARGIN_INTERVAL_S));
    }
}
