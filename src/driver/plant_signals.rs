//! The driver's part of the plant's own signals (issue 12): the keyphasor lock of the twin's
//! shaft angle (and the speed from the keyphasor where no speed topic speaks), and raw
//! proximity-probe readings turned into machine-frame displacements, AC mean removed, slow-roll
//! runout subtracted, before they are compared like any probe pair.

use super::{seconds_to_ns, Driver, Fed, ProbeRef, StationRef};
use crate::session::{input_warning, Outgoing, WarningKind};
use crate::signals::probes::{check_reading, machine_from_probes, runout_at, SlowRoll};
use crate::signals::{
    KeyphasorEvents, KeyphasorLock, KeyphasorSettings, OneXVector, PhaseReference,
    KEYPHASOR_JITTER_S, KEYPHASOR_STOP_REVS,
};
use std::f64::consts::TAU;

/// Time constant of the running mean removed from AC-coupled probes (revolutions): 8, the
/// replay's block. The mean is an exponential average of whole-revolution means (each the
/// average of the samples of one revolution of the shaft angle), so it carries none of the 1X
/// or its harmonics (a running average sample by sample would carry 2 % of the 1X at 16
/// samples a revolution and shift its phase by 1°); the twin's predicted mean, averaged the
/// same way, takes its place, so AC probes compare the motion about the mean.
pub const AC_MEAN_REVS: f64 = 8.0;

/// Largest difference between the stamps of the two readings of a station that are paired into
/// one orbit point (share of a revolution): 1/50 (7.2° of rotation). A DAQ stamps the channels of
/// one scan alike.
pub const PAIR_TOLERANCE_REVS: f64 = 0.02;

/// State of one raw-probe station: the last reading of each axis (its time, ns, and its
/// displacement along the axis, m), and the revolution means of the measured and predicted
/// orbit points.
#[derive(Debug, Clone, Copy, Default)]
struct RawStation {
    last: [Option<(i64, f64)>; 2],
    measured: RevolutionMean,
    predicted: RevolutionMean,
}

/// An exponential average, over [`AC_MEAN_REVS`] revolutions, of whole-revolution means of a
/// point (m); until a revolution is complete, the mean of the samples so far.
#[derive(Debug, Clone, Copy, Default)]
struct RevolutionMean {
    revolution: Option<i64>,
    sum: [f64; 2],
    n: usize,
    mean: Option<[f64; 2]>,
}

impl RevolutionMean {
    /// Adds point `xy` at shaft angle `angle_rad`; returns the mean in force.
    fn add(&mut self, angle_rad: f64, xy: [f64; 2]) -> [f64; 2] {
        let rev = (angle_rad / TAU).floor() as i64;
        if self.revolution.is_some_and(|r| r != rev) && self.n > 0 {
            let done = [self.sum[0] / self.n as f64, self.sum[1] / self.n as f64];
            let a = 1.0 / AC_MEAN_REVS;
            self.mean = Some(self.mean.map_or(done, |m| {
                [m[0] + a * (done[0] - m[0]), m[1] + a * (done[1] - m[1])]
            }));
            self.sum = [0.0; 2];
            self.n = 0;
        }
        self.revolution = Some(rev);
        self.sum = [self.sum[0] + xy[0], self.sum[1] + xy[1]];
        self.n += 1;
        self.mean
            .unwrap_or([self.sum[0] / self.n as f64, self.sum[1] / self.n as f64])
    }
}

/// The keyphasor and raw-probe state the driver keeps.
#[derive(Debug, Clone, Default)]
pub struct SignalState {
    /// The lock.
    pub(super) keyphasor: KeyphasorLock,
    /// The accepted events since the last refused one: the plant's own angle.
    events: KeyphasorEvents,
    /// The newest probe sample's time (ns): the stamp time the keyphasor stop is judged at.
    pub(super) newest_sample_ns: Option<i64>,
    /// Any event was received.
    seen: bool,
    /// Keyphasor events are known to come (a replayed bag has them): the twin waits for the
    /// first to start.
    expected: bool,
    /// The stop was warned about (reset by the next event).
    stop_warned: bool,
    /// The speed in force came from keyphasor intervals (no speed topic speaks).
    pub(super) speed_from_keyphasor: bool,
    /// The factor a steady speed mismatch found between the shaft's speed (the keyphasor's)
    /// and the speed topic's: every topic speed is scaled by it (None: none found).
    pub(super) speed_scale: Option<f64>,
    /// The last keyphasor speed (rad/s) and when (ns), for its acceleration.
    last_kp_speed: Option<(f64, i64)>,
    stations: Vec<RawStation>,
    /// Runout per raw probe: measured below the slow-roll speed (or the file's).
    slow_roll: Vec<SlowRoll>,
    measured_runout: Vec<Option<OneXVector>>,
    /// The source that feeds each probe station, and when it last spoke (receive time, ns).
    sources: Vec<Option<(StationSource, i64)>>,
}

/// What feeds a probe station: its raw probes (`ProbeSignal` or `std_msgs/Float64`, one
/// reading per probe) or `ProbeDisplacement` pairs. One source a station: mixed in one 1X block
/// the two are two different signals (an AC raw station's mean is the twin's own, the
/// displacement's its own), so every block reads as a whirl and calibrates nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StationSource {
    /// Raw probe readings, paired into orbit points.
    Raw,
    /// `ProbeDisplacement` pairs.
    Displacement,
}

impl StationSource {
    fn describe(self) -> &'static str {
        match self {
            StationSource::Raw => "raw probe signals (ProbeSignal on /rotor_twin/probe_signal, or std_msgs/Float64 by remap)",
            StationSource::Displacement => "ProbeDisplacement (/rotor_twin/probe)",
        }
    }
}

impl SignalState {
    /// Fresh state for a keyphasor lock with `settings`.
    pub fn new(settings: KeyphasorSettings) -> Self {
        Self {
            keyphasor: KeyphasorLock::new(settings),
            ..Self::default()
        }
    }

    /// The slow-roll runout measured for raw probe `probe`, if any.
    pub fn measured_runout(&self, probe: usize) -> Option<OneXVector> {
        self.measured_runout.get(probe).copied().flatten()
    }
}

impl Driver {
    /// One source a probe station ([`StationSource`]): the first to feed station `station`
    /// keeps it while it speaks (within `input_timeout_s` of receive time); a sample of the
    /// other source meanwhile is refused with the station and both sources named, and counted
    /// ([`super::DriverCounts::second_source_refused`]). After that silence the other may take
    /// the station over.
    pub(super) fn claim_station(
        &mut self,
        station: usize,
        source: StationSource,
        now_ns: i64,
    ) -> Result<(), String> {
        let n = self.rotor.probes.len();
        if self.signals.sources.len() < n {
            self.signals.sources = vec![None; n];
        }
        let timeout = seconds_to_ns(self.settings.input_timeout_s);
        let slot = &mut self.signals.sources[station];
        if let Some((owner, last)) = *slot {
            if owner != source && now_ns.saturating_sub(last) <= timeout {
                self.counts.second_source_refused += 1;
                let name = self
                    .rotor
                    .probes
                    .get(station)
                    .map_or("", |p| p.name.as_str());
                return Err(format!(
                    "probe station '{name}' takes {}; a sample of {} refused: one source a station (mixed, every 1X block reads as a whirl); give the second source a station of its own",
                    owner.describe(),
                    source.describe()
                ));
            }
        }
        *slot = Some((source, now_ns));
        Ok(())
    }

    /// Whether 1X phases at `t_ns` are referenced to the keyphasor, and if not why.
    pub fn phase_reference(&self, t_ns: i64) -> PhaseReference {
        let s = &self.signals;
        if !s.seen {
            return PhaseReference::NoKeyphasor;
        }
        if self.keyphasor_stopped(t_ns) {
            return PhaseReference::Stopped;
        }
        if s.keyphasor.is_locked() && self.session.is_some() && !self.lock_lapsed(t_ns) {
            PhaseReference::Locked
        } else {
            PhaseReference::NotLocked
        }
    }

    /// The slow-roll runout vector of each raw probe: the machine file's, else measured.
    pub fn runouts(&self) -> Vec<Option<OneXVector>> {
        (0..self.rotor.proximity_probes.len())
            .map(|k| self.runout(k))
            .collect()
    }

    fn runout(&self, k: usize) -> Option<OneXVector> {
        self.rotor
            .proximity_probes
            .get(k)
            .and_then(|p| p.runout)
            .or_else(|| self.signals.measured_runout(k))
    }

    /// The accepted keyphasor events since the last refused one (the plant's own angle, for
    /// the measured 1X vectors: [`crate::signals::keyphasor_one_x`]).
    pub fn keyphasor_events(&self) -> &KeyphasorEvents {
        &self.signals.events
    }

    /// The newest probe sample's time (ns, its stamp where it is on the driver's clock).
    pub fn newest_sample_ns(&self) -> Option<i64> {
        self.signals.newest_sample_ns
    }

    /// True if no event is stamped within [`KEYPHASOR_STOP_REVS`] revolutions at the speed in
    /// force plus [`KEYPHASOR_JITTER_S`] before `t_ns` (a stamp time).
    fn keyphasor_stopped(&self, t_ns: i64) -> bool {
        self.beyond_stop_limit(self.signals.keyphasor.last_event_ns(), t_ns)
    }

    /// Events come but none has been accepted whole for as long as a stop takes, or one
    /// steadily contradicted the speed topic within that time (a keyphasor at a whole multiple
    /// of the topic's speed has every n-th event accepted): the twin's angle is not held to
    /// the mark.
    fn lock_lapsed(&self, t_ns: i64) -> bool {
        let lock = &self.signals.keyphasor;
        let contradicted = lock.last_contradiction_ns().is_some();
        self.beyond_stop_limit(lock.last_accepted_ns(), t_ns)
            || (contradicted && !self.beyond_stop_limit(lock.last_contradiction_ns(), t_ns))
    }

    /// Whether `t_ns` is more than [`KEYPHASOR_STOP_REVS`] revolutions (at the speed in force)
    /// plus [`KEYPHASOR_JITTER_S`] after `since_ns`.
    fn beyond_stop_limit(&self, since_ns: Option<i64>, t_ns: i64) -> bool {
        let (Some(last), Some(w)) = (since_ns, self.speed_rad_s()) else {
            return false;
        };
        let limit_s = KEYPHASOR_STOP_REVS * TAU / w.max(1e-3) + KEYPHASOR_JITTER_S;
        (t_ns - last) as f64 * 1e-9 > limit_s
    }

    /// The stamp time the keyphasor stop is judged at, at receive time `now_ns`: the newest
    /// probe sample's, but no earlier than `now_ns` (so a keyphasor that stops while no sample
    /// comes is seen too; the limit of [`Self::keyphasor_stopped`] already allows
    /// [`KEYPHASOR_JITTER_S`] of delivery delay, once). An event delivered up to that jitter
    /// plus `KEYPHASOR_STOP_REVS` − 1 revolutions late never counts as a stop.
    fn stop_judged_at(&self, now_ns: i64) -> i64 {
        self.signals
            .newest_sample_ns
            .map_or(now_ns, |s| s.max(now_ns))
    }

    /// A keyphasor event stamped `stamp_ns`, received at `now_ns`: checked against the speed,
    /// then the twin's angle is corrected (a twin not yet locked restarts at the event);
    /// without a speed topic, its interval is the speed.
    pub(super) fn take_keyphasor(
        &mut self,
        now_ns: i64,
        stamp_ns: i64,
        emit: &mut impl FnMut(Outgoing),
    ) -> Fed {
        let tolerance = seconds_to_ns(self.settings.input_timeout_s);
        let t = if stamp_ns != 0 && (stamp_ns - now_ns).abs() <= tolerance {
            stamp_ns
        } else {
            now_ns
        };
        self.signals.seen = true;
        self.signals.stop_warned = false;
        let topic_speed = self
            .speed
            .filter(|_| !self.signals.speed_from_keyphasor)
            .filter(|s| (now_ns - s.received_ns) <= tolerance)
            .map(|s| s.speed_rad_s);
        // a twin running unlocked (started by a speed before the first event) restarts at the
        // event, angle 0 there, instead of being turned onto it: turning a running twin jumps
        // its unbalance force's phase, an impulse that seeds its whirl (README, "The onset
        // after a live calibration": 0.098 rad, the run-up onset 200 rpm early)
        let restart = self.session.is_some() && !self.signals.keyphasor.is_locked();
        let angle = match (&self.session, restart) {
            (Some(s), false) => Some(s.angle_at(t)),
            _ => None,
        };
        let after = self.signals.events.newest_ns().is_none_or(|n| t > n);
        let ev = match self.signals.keyphasor.event(t, angle, topic_speed) {
            Ok(ev) => ev,
            Err(r) => {
                if after && r.breaks_history {
                    // a missed or moved pulse: the plant's angle counts afresh from it (an
                    // extra pulse is ignored: the events around it still count)
                    self.signals.events.restart_at(t);
                }
                return Fed::Refused(r.why);
            }
        };
        self.signals.events.push(t);
        if restart {
            self.session = None;
        }
        if let Some(rho) = ev.speed_ratio {
            self.scale_speed_topic(rho, now_ns, emit);
        }
        match (ev.correction_rad, ev.relocked) {
            (Some(c), true) => {
                self.counts.relocks += 1;
                self.move_mark(c, now_ns, emit);
            }
            (Some(c), false) => {
                if let Some(s) = self.session.as_mut() {
                    s.shift_angle(c);
                }
            }
            (None, _) => {}
        }
        let fed = match (ev.interval_speed_rad_s, topic_speed) {
            (Some(w), None) => self.speed_from_interval(now_ns, w, emit),
            _ => Fed::Taken,
        };
        self.start_at_event(t, fed, emit)
    }

    /// The factor found between the shaft's speed (from the keyphasor) and the speed topic's
    /// by a steady speed mismatch (None: none found); every speed topic value is scaled by it.
    pub fn speed_scale(&self) -> Option<f64> {
        self.signals.speed_scale
    }

    /// A steady speed mismatch: over the last revolutions the plant turned `rho` times as fast
    /// as the twin. The speed topic is wrong (a tachometer's scale, a wrong pulses-per-turn
    /// count), not the mark: from now on every topic speed is scaled so that the twin turns at
    /// the keyphasor's speed, the speed in force at once; counted and warned about, with the
    /// ratio. A later mismatch refines the factor (one near 1 says the topic agrees again).
    fn scale_speed_topic(&mut self, rho: f64, now_ns: i64, emit: &mut impl FnMut(Outgoing)) {
        let scale = self.signals.speed_scale.unwrap_or(1.0) * rho;
        self.signals.speed_scale = Some(scale);
        if let Some(s) = self.speed.as_mut() {
            s.speed_rad_s *= rho;
            s.accel_rad_s2 *= rho;
        }
        self.counts.speed_mismatches += 1;
        let settings = self.signals.keyphasor.settings();
        emit(input_warning(
            now_ns,
            WarningKind::BadInput,
            format!(
                "speed mismatch: over the last {} revolutions the keyphasor's shaft turned {rho:.5} times as fast as the twin at the speed topic (its phase drifting {:+.2}° a revolution, steadily: the speed is wrong, the mark did not move); the speed topic now scaled by {scale:.5}{}",
                settings.mismatch_revs,
                360.0 * (1.0 - 1.0 / rho),
                if (scale - 1.0).abs() <= settings.speed_mismatch {
                    " (it agrees with the keyphasor again)"
                } else {
                    ""
                }
            ),
        ));
    }

    /// A relock (the lock moved to a new offset `c`, rad, after consecutive agreeing events):
    /// the keyphasor's mark, or its probe, moved against the shaft; the plant's shaft did not
    /// jump, so neither does the twin's motion. Everything fixed to the shaft is restated from
    /// the new mark: the twin's angle turns by c and each heavy spot by −c (the unbalance force
    /// at angle + phase, hence the motion, unchanged: no impulse), as do the unbalance the
    /// driver keeps (the machine file's, received, calibrated, a blend's ends: −c) and the
    /// slow-roll runouts (lag +c). The phase lags after it are read from the new mark. (Turning
    /// the twin's angle alone, as the lock did before session 14, jumps the unbalance force's
    /// phase: an impulse that seeds the whirl near the threshold.)
    fn move_mark(&mut self, c: f64, now_ns: i64, emit: &mut impl FnMut(Outgoing)) {
        if let Some(s) = self.session.as_mut() {
            s.turn_reference(c);
        }
        for u in &mut self.rotor.unbalance {
            u.phase_rad -= c;
        }
        for u in self.unbalance.iter_mut().flatten() {
            u.phase_rad -= c;
        }
        let calibrated = self.calibration.as_mut().and_then(|a| a.unbalance.as_mut());
        for u in calibrated.into_iter().flatten() {
            u.1 -= c;
        }
        if let Some(b) = self.blend.as_mut() {
            b.turn_unbalance(-c);
        }
        let lag = |r: &mut OneXVector| {
            r.phase_lag_deg = (r.phase_lag_deg + c.to_degrees()).rem_euclid(360.0);
        };
        let file = self.rotor.proximity_probes.iter_mut();
        file.filter_map(|p| p.runout.as_mut()).for_each(lag);
        self.signals
            .measured_runout
            .iter_mut()
            .flatten()
            .for_each(lag);
        emit(input_warning(
            now_ns,
            WarningKind::BadInput,
            format!(
                "keyphasor: the mark moved by {:.1}° against the shaft and held; phases re-referenced to the new mark (the twin's motion unchanged: its angle and heavy spots restated, no impulse)",
                -c.to_degrees()
            ),
        ));
    }

    /// With a keyphasor the twin starts at an event, its angle 0 there: locked from its first
    /// step (a lock that turned a running twin by a large angle would set off a transient).
    pub(super) fn keyphasor_defers_start(&self, now_ns: i64) -> bool {
        (self.signals.seen || self.signals.expected) && !self.keyphasor_stopped(now_ns)
    }

    /// Keyphasor events will come (a bag with keyphasor messages): the twin waits for the
    /// first event to start, so that it is locked from its first step.
    pub fn expect_keyphasor(&mut self) {
        self.signals.expected = true;
    }

    /// Whether a keyphasor is expected (a keyphasor topic with messages, or one seen).
    pub fn expects_keyphasor(&self) -> bool {
        self.signals.expected || self.signals.seen
    }

    /// Starts the twin at the event at `t_ns` if the speed in force allows and none runs.
    fn start_at_event(&mut self, t_ns: i64, fed: Fed, emit: &mut impl FnMut(Outgoing)) -> Fed {
        let Some(w) = self.speed_rad_s() else {
            return fed;
        };
        if self.session.is_some() || w < self.settings.min_speed_rad_s {
            return fed;
        }
        let started = self.start(t_ns, w, emit);
        if matches!(started, Fed::Started { .. }) {
            self.signals.keyphasor.lock_at_event();
        }
        started
    }

    /// The speed from a keyphasor interval (rad/s), with the acceleration from the last one.
    fn speed_from_interval(&mut self, now_ns: i64, w: f64, emit: &mut impl FnMut(Outgoing)) -> Fed {
        let a = self.signals.last_kp_speed.map_or(0.0, |(w0, t0)| {
            let dt = (now_ns - t0) as f64 * 1e-9;
            if dt > 0.0 {
                ((w - w0) / dt).clamp(
                    -super::inputs::MAX_ACCEL_RAD_S2,
                    super::inputs::MAX_ACCEL_RAD_S2,
                )
            } else {
                0.0
            }
        });
        self.signals.last_kp_speed = Some((w, now_ns));
        self.take_speed(now_ns, w, a, 0, true, emit)
    }

    /// Warns once when the keyphasor stops while the shaft turns; phases are null meanwhile.
    pub(super) fn check_keyphasor_stop(&mut self, now_ns: i64, emit: &mut impl FnMut(Outgoing)) {
        let judged_at = self.stop_judged_at(now_ns);
        if self.signals.stop_warned || self.session.is_none() || !self.keyphasor_stopped(judged_at)
        {
            return;
        }
        self.signals.stop_warned = true;
        emit(input_warning(
            now_ns,
            WarningKind::StaleInput,
            format!(
                "keyphasor stopped: no event stamped within {KEYPHASOR_STOP_REVS} revolutions + {KEYPHASOR_JITTER_S} s of the samples; 1X phases are null until it is back, the twin carries on with the speed"
            ),
        ));
    }

    /// One raw probe reading: checked, turned into the displacement along the probe's axis,
    /// runout subtracted; paired with the other probe of its station into an orbit point.
    pub(super) fn take_probe_signal(
        &mut self,
        now_ns: i64,
        probe: &ProbeRef,
        value: f64,
        stamp_ns: i64,
        emit: &mut impl FnMut(Outgoing),
    ) -> Fed {
        let probes = &self.rotor.proximity_probes;
        let k = match probe {
            ProbeRef::Index(k) if *k < probes.len() => *k,
            ProbeRef::Name(n) => match probes.iter().position(|p| &p.name == n) {
                Some(k) => k,
                None => {
                    return Fed::Refused(format!(
                        "probe '{}' is not in the machine's proximity_probes",
                        n.chars().take(64).collect::<String>()
                    ))
                }
            },
            ProbeRef::Index(k) => return Fed::Refused(format!("raw probe {k} does not exist")),
        };
        let p = &probes[k];
        let (station, axis) = (p.station, p.axis);
        let d = match check_reading(p, value) {
            Ok(d) => d,
            Err(why) => return Fed::Refused(why),
        };
        if let Err(why) = self.claim_station(station, StationSource::Raw, now_ns) {
            return Fed::Refused(why);
        }
        let tolerance = seconds_to_ns(self.settings.input_timeout_s);
        let t = if stamp_ns != 0 && (stamp_ns - now_ns).abs() <= tolerance {
            stamp_ns
        } else {
            now_ns
        };
        let newest = self.signals.newest_sample_ns.map_or(t, |n| n.max(t));
        self.signals.newest_sample_ns = Some(newest);
        let d = self.compensate_runout(k, t, d);
        if self.signals.stations.len() < self.rotor.probes.len() {
            self.signals.stations = vec![RawStation::default(); self.rotor.probes.len()];
        }
        if self.signals.stations[station].last[axis].is_some() {
            self.counts.readings_unpaired += 1;
        }
        self.signals.stations[station].last[axis] = Some((t, d));
        self.pair_station(now_ns, station, axis, emit)
    }

    /// The displacement `d` (m) of raw probe `k` at `t_ns` with its runout subtracted (when
    /// the phase is referenced); below the slow-roll speed, the runout is measured instead.
    fn compensate_runout(&mut self, k: usize, t_ns: i64, d: f64) -> f64 {
        let n = self.rotor.proximity_probes.len();
        if self.signals.slow_roll.len() < n {
            self.signals.slow_roll = vec![SlowRoll::default(); n];
            self.signals.measured_runout = vec![None; n];
        }
        let slow = self.rotor.slow_roll_speed_rad_s;
        let w = self.speed_rad_s();
        if let (Some(limit), Some(w), Some(psi)) = (slow, w, self.keyphasor_angle(t_ns)) {
            if w > 0.0 && w < limit {
                self.signals.slow_roll[k].add(psi, d);
                if let Some(v) = self.signals.slow_roll[k].vector() {
                    self.signals.measured_runout[k] = Some(v);
                }
                return d;
            }
        }
        match (self.runout(k), self.phase_reference(t_ns)) {
            (Some(r), PhaseReference::Locked) => {
                let psi = self.session.as_ref().map_or(0.0, |s| s.angle_at(t_ns));
                d - runout_at(&r, psi)
            }
            _ => d,
        }
    }

    /// The plant's shaft angle at `t_ns` from the keyphasor alone (rad, 0 at the last event,
    /// growing at the speed in force), for slow roll where no twin runs.
    fn keyphasor_angle(&self, t_ns: i64) -> Option<f64> {
        let last = self.signals.keyphasor.last_event_ns()?;
        let w = self.speed_rad_s()?;
        let dt = (t_ns - last) as f64 * 1e-9;
        (dt >= 0.0 && self.signals.seen && !self.keyphasor_stopped(t_ns)).then_some(w * dt)
    }

    /// Pairs the reading just stored on `axis` of `station` with the other axis' if their
    /// stamps agree within [`PAIR_TOLERANCE_REVS`]; the pair becomes an orbit point.
    fn pair_station(
        &mut self,
        now_ns: i64,
        station: usize,
        axis: usize,
        emit: &mut impl FnMut(Outgoing),
    ) -> Fed {
        let st = self.signals.stations[station];
        let (Some((t0, d0)), Some((t1, d1))) = (st.last[axis], st.last[1 - axis]) else {
            return Fed::Taken;
        };
        let w = self.speed_rad_s().unwrap_or(0.0).max(1e-3);
        if ((t0 - t1).abs() as f64 * 1e-9) > PAIR_TOLERANCE_REVS * TAU / w {
            return Fed::Taken;
        }
        self.signals.stations[station].last = [None, None];
        let mut d = [0.0; 2];
        d[axis] = d0;
        d[1 - axis] = d1;
        let angles = self.station_axes(station);
        let mut xy = machine_from_probes(d, angles);
        if self.station_is_ac(station) {
            xy = self.remove_ac_mean(station, t0, xy);
        }
        self.compare_probe(now_ns, &StationRef::Index(station), xy, t0, emit)
    }

    /// The probe axis angles (rad) of every probe station, in axis order: the machine file's
    /// raw probes where it lists them, else x and y.
    pub fn probe_axes(&self) -> Vec<[f64; 2]> {
        (0..self.rotor.probes.len())
            .map(|k| self.station_axes(k))
            .collect()
    }

    /// The two axis angles (rad) of a raw-probe station, in axis order.
    fn station_axes(&self, station: usize) -> [f64; 2] {
        let mut a = [0.0, std::f64::consts::FRAC_PI_2];
        for p in self
            .rotor
            .proximity_probes
            .iter()
            .filter(|p| p.station == station)
        {
            a[p.axis] = p.angle_rad;
        }
        a
    }

    /// True if a probe of raw-probe station `station` is AC-coupled (its mean is the twin's).
    pub fn station_is_ac(&self, station: usize) -> bool {
        self.rotor.proximity_probes.iter().any(|p| {
            p.station == station && p.coupling == crate::signals::probes::ProbeCoupling::Ac
        })
    }

    /// An AC-coupled station's point `xy` (m) at `t_ns`: its running mean removed and the
    /// twin's running mean of the prediction put in its place ([`AC_MEAN_REVS`]), so the
    /// comparison is of the motion about the mean. Unchanged while no twin runs (nothing is
    /// compared then).
    fn remove_ac_mean(&mut self, station: usize, t_ns: i64, xy: [f64; 2]) -> [f64; 2] {
        let Some(s) = self.session.as_ref() else {
            return xy;
        };
        let angle = s.angle_at(t_ns);
        let t = (t_ns - s.epoch_ns()) as f64 * 1e-9;
        let Some((p, _)) = s.predicted_probe(station, t) else {
            return xy;
        };
        let st = &mut self.signals.stations[station];
        let m = st.measured.add(angle, xy);
        let pm = st.predicted.add(angle, p);
        [xy[0] - m[0] + pm[0], xy[1] - m[1] + pm[1]]
    }
}
