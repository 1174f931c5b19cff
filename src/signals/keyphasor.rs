//! The keyphasor lock: each once-per-revolution event is shaft angle 0 of the plant (its
//! reference mark under the keyphasor probe, the API 670 / Bently convention). The twin keeps
//! integrating its angle from the speed; at each event the lock measures the twin's angle there,
//! e = wrap(0 − θ_twin(t_event)), and turns the twin's angle by g·e (a first-order phase-locked
//! loop of gain g a revolution; the first event locks at once, g = 1). With the speed known to
//! δω/ω, the angle error left between two events is 2π·δω/ω (0.36° at 0.1 %).
//!
//! Checks (each refusal is the driver's `bad_input`, and the twin carries on with the speed):
//! an event not after the previous one; an interval that contradicts the reference speed (the
//! speed topic's, else the last accepted interval's) by more than
//! [`KeyphasorSettings::interval_tolerance`]: too short, an extra pulse (ignored: the next
//! event's interval runs from the one before it), too long, a missed pulse or a stop (the
//! intervals run on from it); an angle error beyond [`KeyphasorSettings::max_jump_deg`] once
//! locked (the mark or the sensor moved, or a glitch): refused, and only after
//! [`KeyphasorSettings::relock_events`] consecutive events agreeing on a new offset does the
//! lock move to it (a relock: the driver re-references the twin to the new mark without
//! turning its unbalance force, `Driver::move_mark`). Without a speed topic, as many
//! consecutive interval refusals mean the speed itself changed (a stop and a restart): the
//! next interval is taken as the new speed.
//!
//! A speed that is wrong is told from a mark that moved by the trend of the phase error (issue
//! 12): between two events the twin's own angle advances by Δθ = ∫ω_twin dt (the lock's
//! corrections left out) while the plant's advances by 2π, so ρ = 2π/Δθ is the plant's speed
//! over the twin's for that revolution, and the phase error grows by 2π(1 − 1/ρ) a revolution.
//! A moved mark is one odd interval, then steady ones (the error jumps once and stays: a
//! relock); a speed error is the same ρ ≠ 1 revolution after revolution (the error grows in
//! proportion to time). When the last [`KeyphasorSettings::mismatch_revs`] revolutions all give
//! ρ beyond 1 ± [`KeyphasorSettings::speed_mismatch`], agreeing within it, the event reports the
//! mean ρ ([`KeyphasorEvent::speed_ratio`]: the driver scales the speed topic by it) and
//! corrects the whole error, without a relock. Only with a speed topic: a speed from the
//! keyphasor's own intervals has nothing to disagree with. Beyond the interval tolerance the
//! keyphasor contradicts the speed (issue 12: reported, the twin carries on with the speed):
//! every such event is refused; when the events' own intervals, taken whatever the check said
//! ([`RawIntervals`]), agree over the last `mismatch_revs` revolutions while the topic stayed
//! steady, the refusal says so with both speeds and their ratio (a speed topic or a keyphasor
//! set up wrong: a pulses-per-turn count, a mark on another shaft, two notches), since which
//! of the two is right cannot be told from them.

use std::f64::consts::{PI, TAU};

/// Revolutions without a keyphasor event, judged by the stamps, after which the keyphasor
/// counts as stopped (and phases are null): 3, plus [`KEYPHASOR_JITTER_S`].
pub const KEYPHASOR_STOP_REVS: f64 = 3.0;

/// Delivery jitter the keyphasor rules tolerate (s): 0.1 s. An event stamped right but received
/// up to this much (plus `KEYPHASOR_STOP_REVS` − 1 revolutions) after the probe samples of its
/// time neither stops the keyphasor nor leaves a 1X block without its closing event. The rclpy
/// peer on this loaded machine delivered in bursts of up to 41 ms (6 revolutions at 9,000 rpm).
pub const KEYPHASOR_JITTER_S: f64 = 0.1;

/// Keyphasor events kept for the plant's angle: 256 (a block of 8 revolutions, the wait for
/// its closing event and the jitter at 12,000 rpm are 8 + 3 + 20 revolutions).
pub const KEYPHASOR_EVENTS_KEPT: usize = 256;

/// Why a sample has no plant angle (yet).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unbracketed {
    /// No event after the sample has arrived yet: wait for it.
    Pending,
    /// No kept event at or before the sample (none yet, or the history broke after it).
    Missing,
}

/// The last accepted keyphasor events (stamps, ns, increasing) since the last break: the
/// plant's own shaft angle. Each event is angle 0 of a revolution; between two events the angle
/// is interpolated in time, quadratically through a third event (exact at constant
/// acceleration, where linear interpolation reads up to α·T²/8 off: 0.56° in a run-up that
/// gains 10 % of its speed in 8 revolutions) (the API 670 / ADRE keyphasor reference: the angle of a
/// sample does not depend on when it, or the event, was delivered). A refused event breaks the
/// history (a missed or extra pulse would count a revolution wrongly). Allocates nothing.
#[derive(Debug, Clone)]
pub struct KeyphasorEvents {
    stamps: [i64; KEYPHASOR_EVENTS_KEPT],
    /// index of the oldest kept event in `stamps`
    head: usize,
    len: usize,
    /// events pushed since the last break (the newest is revolution `count − 1`)
    count: u64,
}

impl Default for KeyphasorEvents {
    fn default() -> Self {
        Self {
            stamps: [0; KEYPHASOR_EVENTS_KEPT],
            head: 0,
            len: 0,
            count: 0,
        }
    }
}

impl KeyphasorEvents {
    /// The newest event's stamp (ns).
    pub fn newest_ns(&self) -> Option<i64> {
        (self.len > 0).then(|| self.stamp(self.len - 1))
    }

    fn stamp(&self, j: usize) -> i64 {
        self.stamps[(self.head + j) % KEYPHASOR_EVENTS_KEPT]
    }

    /// Adds an event at `t_ns`; one not after the newest is ignored (false).
    pub fn push(&mut self, t_ns: i64) -> bool {
        if self.newest_ns().is_some_and(|n| t_ns <= n) {
            return false;
        }
        if self.len == KEYPHASOR_EVENTS_KEPT {
            self.head = (self.head + 1) % KEYPHASOR_EVENTS_KEPT;
            self.len -= 1;
        }
        self.stamps[(self.head + self.len) % KEYPHASOR_EVENTS_KEPT] = t_ns;
        self.len += 1;
        self.count += 1;
        true
    }

    /// Breaks the history (a refused event) and starts it again at `t_ns`.
    pub fn restart_at(&mut self, t_ns: i64) {
        *self = Self::default();
        self.push(t_ns);
    }

    /// The plant's shaft angle at `t_ns` (rad, 2π a revolution, continuous since the last
    /// break) between the events k and k + 1 that bracket it: the parabola through them and
    /// event k + 2 (or k − 1 while k + 2 has not come), 2π·(k + (t − t_k)/(t_{k+1} − t_k)) when
    /// only two are kept.
    pub fn angle_at(&self, t_ns: i64) -> Result<f64, Unbracketed> {
        // first kept event after t_ns, by bisection
        let (mut lo, mut hi) = (0, self.len);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.stamp(mid) > t_ns {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        if lo == self.len {
            return Err(Unbracketed::Pending);
        }
        if lo == 0 {
            return Err(Unbracketed::Missing);
        }
        let (a, b) = (self.stamp(lo - 1), self.stamp(lo));
        let k = (self.count - self.len as u64 + lo as u64 - 1) as f64;
        // a third event, the next one or else the one before, makes the angle quadratic in time
        let third = if lo + 1 < self.len {
            Some((self.stamp(lo + 1), 2.0))
        } else if lo >= 2 {
            Some((self.stamp(lo - 2), -1.0))
        } else {
            None
        };
        let (x, xb) = ((t_ns - a) as f64, (b - a) as f64);
        let u = match third {
            Some((c, kc)) => through_three(x, xb, (c - a) as f64, kc),
            None => x / xb,
        };
        Ok(TAU * (k + u))
    }

    /// As [`KeyphasorEvents::angle_at`], and less than one interval past the newest event,
    /// extrapolated at the last interval's speed (a block finished without its closing event,
    /// its last revolution at the last speed, as the lock extrapolates the twin's angle).
    pub fn angle_at_or_after(&self, t_ns: i64) -> Result<f64, Unbracketed> {
        match self.angle_at(t_ns) {
            Err(Unbracketed::Pending) if self.len >= 2 => {
                let (a, b) = (self.stamp(self.len - 2), self.stamp(self.len - 1));
                let u = (t_ns - b) as f64 / (b - a) as f64;
                let k = (self.count - 1) as f64;
                (u < 1.0)
                    .then_some(TAU * (k + u))
                    .ok_or(Unbracketed::Pending)
            }
            r => r,
        }
    }
}

/// The revolution fraction at time x of the parabola through (0, 0), (xb, 1) and (xc, kc)
/// (Lagrange form; times relative to the first event).
/// Linear between the first two when the parabola would not rise monotonically between them
/// (intervals so unequal that the speed is not smooth: no acceleration to follow).
fn through_three(x: f64, xb: f64, xc: f64, kc: f64) -> f64 {
    let (db, dc) = (xb * (xb - xc), xc * (xc - xb));
    let slope = |x: f64| (2.0 * x - xc) / db + kc * (2.0 * x - xb) / dc;
    if slope(0.0) > 0.0 && slope(xb) > 0.0 {
        x * (x - xc) / db + kc * x * (x - xb) / dc
    } else {
        x / xb
    }
}

/// How the lock follows and checks the events.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyphasorSettings {
    /// Share of the angle error corrected at each event (after the first). Default 0.5: the
    /// error halves every revolution, and one noisy event moves the angle by half its noise.
    pub gain: f64,
    /// Largest accepted relative difference between the keyphasor's speed 2π/Δt and the
    /// reference speed (the speed topic's, else the last accepted interval's). Default 0.1: a
    /// missed pulse doubles the interval, an extra one shortens it; a run-up changes the speed
    /// by far less than 10 % a revolution (the sample bag: 0.02 %).
    pub interval_tolerance: f64,
    /// Largest accepted angle error once locked (degrees). Default 20°: 50 times the drift of
    /// a 0.1 %-accurate speed over a revolution.
    pub max_jump_deg: f64,
    /// Consecutive events agreeing (within `max_jump_deg`) on a new offset before the lock
    /// moves to it; also, without a speed topic, the interval refusals in a row after which
    /// the speed is judged afresh. Default 3.
    pub relock_events: u32,
    /// Largest steady relative difference between the plant's speed and the twin's (the speed
    /// topic's) that the lock follows as an angle error; beyond it, over `mismatch_revs`
    /// revolutions, the speed topic is reported inconsistent and scaled. Default 0.005: the
    /// lock's steady error under it, 2π·0.005/gain = 3.6° at gain 0.5, stays within the 5° a
    /// 1X phase is compared to (issue 12); 25 times the ratio's noise from a 10 µs stamp jitter
    /// at 12,000 rpm (√2·10 µs / 5 ms = 0.03 %).
    pub speed_mismatch: f64,
    /// Consecutive revolutions that must agree on a speed ratio beyond `speed_mismatch`
    /// (2 ..= [`MISMATCH_REVS_MAX`]). Default 3: fewer than a relock needs (a drift of up to
    /// 10 % a revolution reaches the third agreeing refusal no sooner than the fourth
    /// revolution), more than the one odd interval a moved mark gives.
    pub mismatch_revs: u32,
}

/// Most revolutions [`KeyphasorSettings::mismatch_revs`] can look back over: 16.
pub const MISMATCH_REVS_MAX: usize = 16;

impl Default for KeyphasorSettings {
    fn default() -> Self {
        Self {
            gain: 0.5,
            interval_tolerance: 0.1,
            max_jump_deg: 20.0,
            relock_events: 3,
            speed_mismatch: 0.005,
            mismatch_revs: 3,
        }
    }
}

/// Whether 1X phases at an instant are referenced to a keyphasor, and if not, why.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PhaseReference {
    /// The twin's angle is locked to the plant's keyphasor.
    Locked,
    /// No keyphasor event has been received.
    #[default]
    NoKeyphasor,
    /// Keyphasor events came, but the twin running now has not been locked yet.
    NotLocked,
    /// The keyphasor stopped: no event for longer than the timeout.
    Stopped,
}

impl PhaseReference {
    /// Why a phase is null here (None when locked).
    pub fn null_reason(self) -> Option<&'static str> {
        match self {
            PhaseReference::Locked => None,
            PhaseReference::NoKeyphasor => Some(
                "no keyphasor: a 1X phase needs the plant's once-per-revolution reference (map it to /rotor_twin/keyphasor)",
            ),
            PhaseReference::NotLocked => {
                Some("the twin was not locked to the keyphasor over the whole window")
            }
            PhaseReference::Stopped => Some("the keyphasor stopped within the window"),
        }
    }
}

/// Why an event is refused, and whether the plant's angle counts afresh from it.
#[derive(Debug, Clone, PartialEq)]
pub struct KeyphasorRefusal {
    /// The reason, for the `bad_input` warning.
    pub why: String,
    /// False for an extra pulse (ignored: the events around it still count the revolutions)
    /// and an event not after the previous one; true otherwise (a missed pulse, a stop, a jump).
    pub breaks_history: bool,
}

impl KeyphasorRefusal {
    fn breaking(why: String) -> Self {
        Self {
            why,
            breaks_history: true,
        }
    }
}

/// What one accepted event gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyphasorEvent {
    /// Turn the twin's angle by this much (rad); None when no twin angle was given.
    pub correction_rad: Option<f64>,
    /// The speed from the interval since the previous event, 2π/Δt (rad/s), if there was one.
    pub interval_speed_rad_s: Option<f64>,
    /// The lock moved to a new offset after consecutive agreeing jumps (to be reported; the
    /// correction is then the mark's move, not the shaft's: re-reference, do not turn the twin).
    pub relocked: bool,
    /// A steady speed mismatch found at this event: the plant's speed over the twin's (the
    /// mean of the last [`KeyphasorSettings::mismatch_revs`] revolutions' ratios). The
    /// correction is then the twin's whole angle error (its angle drifted: turn it).
    pub speed_ratio: Option<f64>,
}

/// The trend of the twin's angle error: the twin's angle just after the last event's
/// correction, and the plant-over-twin speed ratio of each revolution since (a ring).
#[derive(Debug, Clone, Copy, Default)]
struct DriftTrack {
    /// the twin's angle after the last event's correction (rad), while the chain holds
    after_rad: Option<f64>,
    ratios: [f64; MISMATCH_REVS_MAX],
    /// ratios recorded (at most `MISMATCH_REVS_MAX`) and where the next goes
    len: usize,
    next: usize,
}

impl DriftTrack {
    /// Forgets everything (the twin restarted, or an event was missed).
    fn reset(&mut self, after_rad: Option<f64>) {
        *self = Self {
            after_rad,
            ..Self::default()
        };
    }

    /// Records the revolution that ends with the twin at `theta` (rad, before any correction).
    fn record(&mut self, theta: f64) {
        let Some(after) = self.after_rad else {
            return;
        };
        // the twin's advance since the last event, taken near one revolution (a drift of less
        // than half a revolution a revolution)
        let advance = TAU + wrap_pi(theta - after - TAU);
        if advance <= 0.0 {
            return;
        }
        self.ratios[self.next] = TAU / advance;
        self.next = (self.next + 1) % MISMATCH_REVS_MAX;
        self.len = (self.len + 1).min(MISMATCH_REVS_MAX);
    }

    /// The mean ratio of the last `n` revolutions if they all lie beyond 1 ± `tol` on one side
    /// and agree within `tol`: a steady speed mismatch.
    fn mismatch(&self, n: usize, tol: f64) -> Option<f64> {
        let n = n.clamp(2, MISMATCH_REVS_MAX);
        if self.len < n {
            return None;
        }
        let (mut lo, mut hi, mut sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
        for j in 1..=n {
            let r = self.ratios[(self.next + MISMATCH_REVS_MAX - j) % MISMATCH_REVS_MAX];
            (lo, hi, sum) = (lo.min(r), hi.max(r), sum + r);
        }
        let beyond = lo > 1.0 + tol || hi < 1.0 - tol;
        (beyond && hi - lo <= tol).then_some(sum / n as f64)
    }
}

/// The lock's state between events.
#[derive(Debug, Clone, Default)]
pub struct KeyphasorLock {
    settings: KeyphasorSettings,
    last_event_ns: Option<i64>,
    /// the last accepted interval's speed (rad/s)
    last_interval_speed: Option<f64>,
    /// consecutive events refused by the interval check
    interval_refusals: u32,
    locked: bool,
    /// a jump being confirmed: its angle error (rad) and how many events agreed
    pending: Option<(f64, u32)>,
    /// the twin's speed against the plant's, revolution by revolution
    drift: DriftTrack,
    /// the events' own intervals, accepted or not
    raw: RawIntervals,
    /// time of the last event accepted whole (interval and angle) (ns)
    last_accepted_ns: Option<i64>,
    /// time of the last event that steadily contradicted the speed topic (ns)
    last_contradiction_ns: Option<i64>,
}

/// The times of the last events, each after the one before, whatever the checks said, with
/// the speed topic's value at each (0: none): their intervals are the shaft's own revolutions
/// when the speed topic is far off.
#[derive(Debug, Clone, Copy, Default)]
struct RawIntervals {
    times_ns: [i64; MISMATCH_REVS_MAX + 1],
    topic_rad_s: [f64; MISMATCH_REVS_MAX + 1],
    /// events recorded (at most `MISMATCH_REVS_MAX + 1`) and where the next goes
    len: usize,
    next: usize,
}

impl RawIntervals {
    /// Records an event at `t_ns` (the speed topic then `topic`, rad/s) if it is after the
    /// newest.
    fn push(&mut self, t_ns: i64, topic: Option<f64>) {
        let n = self.times_ns.len();
        if self.len > 0 && t_ns <= self.times_ns[(self.next + n - 1) % n] {
            return;
        }
        self.times_ns[self.next] = t_ns;
        self.topic_rad_s[self.next] = topic.unwrap_or(0.0);
        self.next = (self.next + 1) % n;
        self.len = (self.len + 1).min(n);
    }

    /// The mean speed (rad/s) of the last `k` intervals if they agree within `tol` (relative
    /// spread), the speed topic at each interval's end agreed with its value now (`topic`,
    /// rad/s) within `tol` (a step of the topic is no mismatch: the intervals before it were
    /// at the old speed), and each interval contradicts it by more than `interval_tol`.
    fn steady_beyond(&self, k: usize, tol: f64, topic: f64, interval_tol: f64) -> Option<f64> {
        let n = self.times_ns.len();
        let k = k.clamp(2, MISMATCH_REVS_MAX);
        if self.len < k + 1 {
            return None;
        }
        let slot = |back: usize| (self.next + 2 * n - 1 - back) % n;
        let at = |back: usize| self.times_ns[slot(back)];
        let (mut lo, mut hi, mut sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
        for j in 0..k {
            if (self.topic_rad_s[slot(j)] / topic - 1.0).abs() > tol {
                return None;
            }
            let w = TAU / ((at(j) - at(j + 1)) as f64 * 1e-9);
            (lo, hi, sum) = (lo.min(w), hi.max(w), sum + w);
        }
        let mean = sum / k as f64;
        let beyond = lo > topic * (1.0 + interval_tol) || hi < topic * (1.0 - interval_tol);
        (beyond && hi - lo <= tol * mean).then_some(mean)
    }
}

/// `a` wrapped into (−π, π].
pub fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI {
        w - TAU
    } else {
        w
    }
}

impl KeyphasorLock {
    /// A lock with `settings`, not locked.
    pub fn new(settings: KeyphasorSettings) -> Self {
        Self {
            settings,
            ..Self::default()
        }
    }

    /// The settings it follows.
    pub fn settings(&self) -> KeyphasorSettings {
        self.settings
    }

    /// True once an event has locked the twin running now.
    pub fn is_locked(&self) -> bool {
        self.locked
    }

    /// Time of the last event accepted whole, interval and angle (ns): a lock whose events are
    /// all refused for revolutions no longer holds the twin's angle to the mark.
    pub fn last_accepted_ns(&self) -> Option<i64> {
        self.last_accepted_ns
    }

    /// Time of the last event that steadily contradicted the speed topic (ns): a keyphasor at
    /// a whole multiple of the topic's speed has every n-th event accepted, on a twin turning
    /// at the wrong speed, so no lock holds while they come.
    pub fn last_contradiction_ns(&self) -> Option<i64> {
        self.last_contradiction_ns
    }

    /// Whether, at `t_ns` and speed `w` (rad/s), no event has been accepted whole for as long
    /// as a stop takes ([`KEYPHASOR_STOP_REVS`] revolutions and [`KEYPHASOR_JITTER_S`]).
    fn lapsed(&self, t_ns: i64, w: Option<f64>) -> bool {
        match (self.last_accepted_ns, w) {
            (Some(a), Some(w)) if w > 0.0 => {
                (t_ns - a) as f64 * 1e-9 > KEYPHASOR_STOP_REVS * TAU / w + KEYPHASOR_JITTER_S
            }
            _ => false,
        }
    }

    /// Time of the last accepted (or interval-checked) event (ns).
    pub fn last_event_ns(&self) -> Option<i64> {
        self.last_event_ns
    }

    /// A twin started at the instant of the last event, angle 0 there: locked by construction.
    pub fn lock_at_event(&mut self) {
        self.locked = true;
        self.pending = None;
        self.drift.reset(Some(0.0));
    }

    /// The twin (re)started: its angle is no longer locked.
    pub fn unlock(&mut self) {
        self.locked = false;
        self.pending = None;
        self.drift.reset(None);
    }

    /// One event at `t_ns`. `twin_angle_rad`: the twin's shaft angle at that instant (None when
    /// no twin runs); `speed_rad_s`: the speed topic's value, if one is in force. Ok with the
    /// correction, or the reason it is refused.
    pub fn event(
        &mut self,
        t_ns: i64,
        twin_angle_rad: Option<f64>,
        speed_rad_s: Option<f64>,
    ) -> Result<KeyphasorEvent, KeyphasorRefusal> {
        let interval_speed = match self.check_interval(t_ns, speed_rad_s) {
            Ok(w) => w,
            Err(r) => {
                if r.breaks_history {
                    // the revolution is not known to be one: the trend starts afresh
                    self.drift.reset(None);
                }
                return Err(r);
            }
        };
        let w = speed_rad_s.filter(|s| *s > 0.0).or(interval_speed);
        if self.locked && self.lapsed(t_ns, w) {
            // every event refused for a stop's length (a keyphasor that contradicted the speed,
            // or stopped): the angle is no longer held, so this event locks afresh (its whole
            // error, as the first event did) rather than counting as a jump of the mark
            self.locked = false;
            self.pending = None;
            self.drift.reset(None);
        }
        let out = self.angle_event(interval_speed, twin_angle_rad, speed_rad_s);
        if out.is_ok() {
            self.last_accepted_ns = Some(t_ns);
        }
        out
    }

    /// The angle part of an event whose interval was accepted (`interval_speed`, rad/s): the
    /// twin's angle `twin_angle_rad` there against the mark, the speed topic `speed_rad_s`.
    fn angle_event(
        &mut self,
        interval_speed: Option<f64>,
        twin_angle_rad: Option<f64>,
        speed_rad_s: Option<f64>,
    ) -> Result<KeyphasorEvent, KeyphasorRefusal> {
        let mut ev = KeyphasorEvent {
            correction_rad: None,
            interval_speed_rad_s: interval_speed,
            relocked: false,
            speed_ratio: None,
        };
        let Some(theta) = twin_angle_rad else {
            self.drift.reset(None);
            return Ok(ev);
        };
        let e = wrap_pi(-theta);
        if speed_rad_s.is_some_and(|s| s > 0.0) && self.locked {
            self.drift.record(theta);
        } else {
            // a speed from the keyphasor's own intervals: nothing to disagree with
            self.drift.reset(None);
        }
        let n = self.settings.mismatch_revs as usize;
        if let Some(rho) = self.drift.mismatch(n, self.settings.speed_mismatch) {
            // a steady drift, not a moved mark: the twin's angle is wrong by all of e
            self.pending = None;
            self.drift.reset(Some(theta + e));
            ev.correction_rad = Some(e);
            ev.speed_ratio = Some(rho);
            return Ok(ev);
        }
        let result = self.correction(e);
        let c = result.as_ref().map_or(0.0, |(c, _)| *c);
        self.drift.after_rad = Some(theta + c);
        let (correction, relocked) = result.map_err(KeyphasorRefusal::breaking)?;
        ev.correction_rad = Some(correction);
        ev.relocked = relocked;
        Ok(ev)
    }

    /// Checks the interval since the last event against the reference speed (the speed topic's,
    /// else the last accepted interval's); records the event time, also when refused as a missed
    /// pulse or a stop (one bad pulse costs one interval), not for an extra pulse.
    fn check_interval(
        &mut self,
        t_ns: i64,
        speed: Option<f64>,
    ) -> Result<Option<f64>, KeyphasorRefusal> {
        self.raw.push(t_ns, speed.filter(|s| *s > 0.0));
        let Some(last) = self.last_event_ns else {
            self.last_event_ns = Some(t_ns);
            return Ok(None);
        };
        if t_ns <= last {
            return Err(KeyphasorRefusal {
                why: format!(
                    "keyphasor event at {:.6} s is not after the previous one ({:.6} s)",
                    t_ns as f64 * 1e-9,
                    last as f64 * 1e-9
                ),
                breaks_history: false,
            });
        }
        let dt = (t_ns - last) as f64 * 1e-9;
        let w = TAU / dt;
        let topic = speed.filter(|s| *s > 0.0);
        let tol = self.settings.interval_tolerance;
        match topic.or(self.last_interval_speed) {
            Some(r) if (w / r - 1.0).abs() > tol => {
                let steady = topic.and_then(|t| self.steady_contradiction(t));
                let mut refusal = self.refuse_interval(t_ns, dt, w, r, topic);
                if let Some((w_raw, rho)) = steady {
                    self.last_contradiction_ns = Some(t_ns);
                    refusal.why = format!(
                        "keyphasor contradicts the speed topic steadily: its last {} revolutions all turned at {:.1} rpm, {rho:.4} times the topic's {:.1} rpm (a speed topic or a keyphasor set up wrong: pulses per turn, a mark on another shaft, two notches); events refused, the twin carries on with the speed topic",
                        self.settings.mismatch_revs,
                        w_raw * 30.0 / PI,
                        r * 30.0 / PI
                    );
                }
                Err(refusal)
            }
            _ => {
                self.last_event_ns = Some(t_ns);
                self.last_interval_speed = Some(w);
                self.interval_refusals = 0;
                Ok(Some(w))
            }
        }
    }

    /// The keyphasor contradicting a steady speed topic `topic` (rad/s) steadily: the last
    /// `mismatch_revs` intervals of the events themselves agree within `speed_mismatch` and
    /// all contradict it by more than the interval tolerance. Their speed (rad/s) and its ratio
    /// to the topic's, or None.
    fn steady_contradiction(&self, topic: f64) -> Option<(f64, f64)> {
        let s = &self.settings;
        let k = s.mismatch_revs as usize;
        self.raw
            .steady_beyond(k, s.speed_mismatch, topic, s.interval_tolerance)
            .map(|w| (w, w / topic))
    }

    /// Refuses an event whose interval `dt` (s, speed `w`) contradicts the reference `r`: too
    /// short, an extra pulse, ignored; too long, a missed pulse or a stop, recorded. Without a
    /// speed topic, after [`KeyphasorSettings::relock_events`] such refusals in a row the
    /// intervals are judged afresh from this event (the speed changed).
    fn refuse_interval(
        &mut self,
        t_ns: i64,
        dt: f64,
        w: f64,
        r: f64,
        topic: Option<f64>,
    ) -> KeyphasorRefusal {
        let extra = w > r;
        if !extra {
            self.last_event_ns = Some(t_ns);
        }
        self.interval_refusals += 1;
        let afresh = topic.is_none() && self.interval_refusals >= self.settings.relock_events;
        if afresh {
            self.last_event_ns = Some(t_ns);
            self.last_interval_speed = None;
            self.interval_refusals = 0;
        }
        let what = match (extra, afresh) {
            (_, true) => "the speed changed: judged afresh from this event",
            (true, false) => "an extra pulse: ignored",
            (false, false) => "a missed pulse or a stop",
        };
        KeyphasorRefusal {
            why: format!(
                "keyphasor interval {:.6} s ({:.1} rpm) contradicts the speed {:.1} rpm by more than {:.0} % ({what})",
                dt,
                w * 30.0 / PI,
                r * 30.0 / PI,
                self.settings.interval_tolerance * 100.0
            ),
            breaks_history: !extra || afresh,
        }
    }

    /// The angle correction for an error `e` (rad) at an event.
    fn correction(&mut self, e: f64) -> Result<(f64, bool), String> {
        if !self.locked {
            self.locked = true;
            self.pending = None;
            return Ok((e, false));
        }
        let max = self.settings.max_jump_deg.to_radians();
        if e.abs() <= max {
            self.pending = None;
            return Ok((self.settings.gain * e, false));
        }
        let count = match self.pending {
            Some((p, n)) if wrap_pi(e - p).abs() <= max => n + 1,
            _ => 1,
        };
        if count >= self.settings.relock_events {
            self.pending = None;
            return Ok((e, true));
        }
        self.pending = Some((e, count));
        Err(format!(
            "keyphasor phase jumped by {:.1}° against the locked shaft angle (more than {:.0}°): refused ({count} of {} agreeing events move the lock)",
            e.to_degrees(),
            self.settings.max_jump_deg,
            self.settings.relock_events
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: f64 = 942.477_796_076_938; // 9,000 rpm (rad/s)

    fn rev_ns(k: i64) -> i64 {
        (k as f64 * TAU / W * 1e9).round() as i64
    }

    /// A twin 100° behind: the first event corrects it all. Then a twin running 1 % slow loses
    /// 2π·0.01 = 3.6° a revolution; with gain g the error before each correction obeys
    /// e(k+1) = (1 − g)·e(k) + 3.6°, whose fixed point is 3.6°/g = 7.2° (closed form). (The
    /// speed-mismatch check off, the loop alone: by default 1 % is reported and scaled away,
    /// `a_steady_speed_error_is_reported_not_relocked`.)
    #[test]
    fn locks_at_once_then_follows_a_speed_error() {
        let mut lock = KeyphasorLock::new(KeyphasorSettings {
            speed_mismatch: 1.0,
            ..KeyphasorSettings::default()
        });
        let mut offset = -100f64.to_radians();
        let ev = lock.event(0, Some(offset), Some(W)).unwrap();
        offset += ev.correction_rad.unwrap();
        assert!(offset.abs() < 1e-12 && lock.is_locked());
        // the twin runs 1 % slow: each revolution it loses 2π·0.01
        let mut errors = Vec::new();
        for k in 1..40 {
            let theta = TAU * k as f64 * 0.99 + offset;
            let ev = lock.event(rev_ns(k), Some(theta), Some(W)).unwrap();
            let e = wrap_pi(-theta);
            errors.push(e.to_degrees());
            offset += ev.correction_rad.unwrap();
            let speed = ev.interval_speed_rad_s.unwrap();
            assert!((speed / W - 1.0).abs() < 1e-6, "interval speed {speed}");
        }
        // steady state of e_{k+1} = (1 − g) e_k + 3.6°: e = 3.6°/g = 7.2°
        let last = *errors.last().unwrap();
        assert!((last - 7.2).abs() < 0.01, "steady error {last}°");
    }

    /// Events at a speed changing by 10 % a revolution, pushed in any delivery order of
    /// whole bursts: the angle at an event is 2πk, half-way between two events π more, the
    /// angle after the newest waits (Pending), before the oldest kept is Missing; a break
    /// forgets the past; the ring keeps the last 256.
    #[test]
    fn the_plant_angle_is_interpolated_between_the_bracketing_events() {
        let mut ev = KeyphasorEvents::default();
        let mut t = 1_000_000i64;
        let mut stamps = Vec::new();
        for k in 0..300 {
            stamps.push(t);
            t += (6_000_000.0 / (1.0 + 0.1 * (k % 7) as f64)) as i64;
        }
        for &s in &stamps {
            assert!(ev.push(s));
        }
        assert!(!ev.push(stamps[10]), "an old event is ignored");
        assert_eq!(ev.angle_at(stamps[299] + 1), Err(Unbracketed::Pending));
        assert_eq!(ev.angle_at(stamps[43]), Err(Unbracketed::Missing));
        for k in [44usize, 100, 298] {
            let a = ev.angle_at(stamps[k]).unwrap();
            assert!((a - TAU * k as f64).abs() < 1e-9, "{k}: {a}");
            // between the events the angle rises from 2πk to 2π(k + 1)
            let mut last = a;
            for j in 1..20 {
                let t = stamps[k] + (stamps[k + 1] - stamps[k]) * j / 20;
                let m = ev.angle_at(t).unwrap();
                assert!(m > last && m < TAU * (k + 1) as f64, "{k}, {j}: {m}");
                last = m;
            }
        }
        // at constant acceleration (speed +10 % in 8 revolutions) the parabola through three
        // events is the angle itself: within 1e-6 rad (the stamps are rounded to 1 ns), where
        // linear interpolation is up to α·T²/8 = 0.0098 rad off
        let (w0, acc) = (900.0, 0.1 * 900.0 * 900.0 / (8.0 * TAU));
        let time_of = |psi: f64| (-w0 + (w0 * w0 + 2.0 * acc * psi).sqrt()) / acc;
        let mut run = KeyphasorEvents::default();
        for k in 0..10 {
            run.push((time_of(TAU * k as f64) * 1e9).round() as i64);
        }
        for j in 1..90 {
            let psi = TAU * j as f64 / 10.0;
            let t = (time_of(psi) * 1e9).round() as i64;
            let got = run.angle_at(t).unwrap();
            let exact = w0 * t as f64 * 1e-9 + 0.5 * acc * (t as f64 * 1e-9).powi(2);
            assert!((got - exact).abs() < 1e-6, "ψ {psi}: {got} vs {exact}");
        }
        // past the newest by a quarter of the last interval: Pending, or extrapolated
        let q = stamps[299] + (stamps[299] - stamps[298]) / 4;
        assert_eq!(ev.angle_at(q), Err(Unbracketed::Pending));
        let e = ev.angle_at_or_after(q).unwrap();
        assert!((e - TAU * 299.25).abs() < 1e-6, "{e}");
        let beyond = stamps[299] + (stamps[299] - stamps[298]) + 1;
        assert_eq!(ev.angle_at_or_after(beyond), Err(Unbracketed::Pending));
        ev.restart_at(stamps[299] + 5_000_000);
        assert_eq!(ev.angle_at(stamps[299]), Err(Unbracketed::Missing));
        assert_eq!(ev.newest_ns(), Some(stamps[299] + 5_000_000));
    }

    #[test]
    fn refuses_missed_pulses_jumps_and_backwards_events_then_relocks() {
        let mut lock = KeyphasorLock::new(KeyphasorSettings::default());
        lock.event(0, Some(0.0), Some(W)).unwrap();
        lock.event(rev_ns(1), Some(TAU), Some(W)).unwrap();
        // a missed pulse: the interval is two revolutions
        let why = lock
            .event(rev_ns(3), Some(3.0 * TAU), Some(W))
            .unwrap_err()
            .why;
        assert!(why.contains("contradicts the speed"), "{why}");
        // the next one is fine again
        lock.event(rev_ns(4), Some(4.0 * TAU), Some(W)).unwrap();
        // backwards
        assert!(lock
            .event(rev_ns(4), Some(4.0 * TAU), Some(W))
            .unwrap_err()
            .why
            .contains("not after"));
        // the mark moved by 90°: refused twice, the third agreeing event relocks
        for k in 5..7 {
            let why = lock
                .event(
                    rev_ns(k),
                    Some(k as f64 * TAU - 90f64.to_radians()),
                    Some(W),
                )
                .unwrap_err()
                .why;
            assert!(why.contains("jumped by 90.0°"), "{why}");
        }
        let ev = lock
            .event(rev_ns(7), Some(7.0 * TAU - 90f64.to_radians()), Some(W))
            .unwrap();
        assert!(ev.relocked);
        assert!((ev.correction_rad.unwrap() - 90f64.to_radians()).abs() < 1e-9);
    }

    /// What a lock makes of a plant turning `ratio` times as fast as the twin's speed W, its
    /// mark moved by `mark_deg` from revolution 12 on, over `revs` revolutions: the twin's
    /// angle turned by each correction and its speed scaled by each reported ratio, as the
    /// driver does. (Reported ratios, relocks, refusals, the twin's angle error at the last
    /// event in degrees.)
    /// A plant at 1.15 × the told speed for 20 revolutions (every event refused: it contradicts
    /// the speed), then at the told speed again: the lock lapsed, so the first event accepted
    /// after locks afresh with the twin's whole angle error (no relock, which would restate
    /// every heavy spot as if the mark had moved), and the next events find the angle right.
    /// Before session 16 the lapse was not seen: that event's error (the drift of 20
    /// revolutions at 15 %) was refused as a jump and the third agreeing one relocked.
    #[test]
    fn after_a_lapse_the_next_accepted_event_locks_afresh_without_a_relock() {
        let mut lock = KeyphasorLock::new(KeyphasorSettings::default());
        let (mut theta, mut t, mut t_prev) = (0.0, 0.0f64, 0.0);
        let (mut relocks, mut refusals, mut errors) = (0, 0, Vec::new());
        for k in 0..40 {
            let wp = if k < 20 { 1.15 * W } else { W };
            t += if k == 0 { 0.0 } else { TAU / wp };
            theta += W * (t - t_prev);
            t_prev = t;
            match lock.event((t * 1e9).round() as i64, Some(theta), Some(W)) {
                Ok(ev) => {
                    theta += ev.correction_rad.unwrap();
                    relocks += u32::from(ev.relocked);
                    // event 21 locks afresh with its whole error (3.0 rad here); after it
                    if k > 21 {
                        errors.push(wrap_pi(-(theta - ev.correction_rad.unwrap())).abs());
                    }
                }
                Err(_) => refusals += 1,
            }
        }
        assert_eq!(relocks, 0);
        // events 1–19 contradict the speed; event 20 is the first at the told speed after a
        // 15 % faster revolution's interval (refused too), 21 on are accepted
        assert_eq!(refusals, 20, "{refusals}");
        assert!(errors.iter().all(|e| *e < 1e-6), "{errors:?}");
        assert!(lock.is_locked());
    }

    fn follow(ratio: f64, mark_deg: f64, revs: usize) -> (Vec<f64>, u32, u32, f64) {
        let mut lock = KeyphasorLock::new(KeyphasorSettings::default());
        let (wp, mut w) = (W * ratio, W);
        let (mut theta, mut t_prev, mut last_error) = (0.0, 0.0, 0.0);
        let (mut ratios, mut relocks, mut refusals) = (Vec::new(), 0, 0);
        for k in 0..revs {
            let mark = if k >= 12 { mark_deg.to_radians() } else { 0.0 };
            let t = (TAU * k as f64 + mark) / wp;
            theta += w * (t - t_prev);
            t_prev = t;
            last_error = wrap_pi(-theta).to_degrees();
            match lock.event((t * 1e9).round() as i64, Some(theta), Some(w)) {
                Ok(ev) => {
                    theta += ev.correction_rad.unwrap();
                    relocks += u32::from(ev.relocked);
                    if let Some(r) = ev.speed_ratio {
                        ratios.push(r);
                        w *= r;
                    }
                }
                Err(_) => refusals += 1,
            }
        }
        (ratios, relocks, refusals, last_error)
    }

    /// A plant 3, 5 or 8 % faster or 3 or 5 % slower than the speed the twin is told: its
    /// phase error grows by 2π(1 − 1/ρ) a revolution (10.5° at 1.03, 26.7° at 1.08). The
    /// lock reports the ratio once, at the fourth event (the first locks; three revolutions
    /// agree), to 10⁻⁶ (the stamps are rounded to 1 ns in T = 6.7 ms), never relocks, refuses
    /// at most the two events whose error passed 20° before it (before session 15 a drift
    /// beyond 2.8 % relocked as a moved mark, again and again), and once the twin's speed is
    /// scaled its angle error is nil (< 10⁻⁶ °). Within the tolerance (0.4 %) nothing is
    /// reported: the lock follows with its steady error 360°·(1 − 1/1.004)/g = 2.869°.
    #[test]
    fn a_steady_speed_error_is_reported_not_relocked() {
        for ratio in [1.03, 1.05, 1.08, 0.97, 0.95] {
            let (ratios, relocks, refusals, error) = follow(ratio, 0.0, 40);
            assert_eq!(ratios.len(), 1, "{ratio}: {ratios:?}");
            assert!(
                (ratios[0] / ratio - 1.0).abs() < 1e-6,
                "{ratio}: {ratios:?}"
            );
            assert_eq!(relocks, 0, "{ratio}");
            assert!(refusals <= 2, "{ratio}: {refusals} refused");
            assert!(error.abs() < 1e-6, "{ratio}: {error}°");
        }
        let (ratios, relocks, refusals, error) = follow(1.004, 0.0, 40);
        assert!(ratios.is_empty() && relocks == 0 && refusals == 0);
        let steady = 360.0 * (1.0 - 1.0 / 1.004) / 0.5;
        assert!((error - steady).abs() < 0.01, "{error}° against {steady}°");
    }

    /// A mark moved by ±40° at the right speed: one odd revolution (its interval 1 ± 1/9 T),
    /// then steady ones: one relock, no speed mismatch, the error nil after it (the relock
    /// takes the whole offset). +40°: the odd interval (ρ = 0.9) is refused as a missed pulse
    /// or taken, the next two jumps refused; −40°: the early event is an extra pulse, the next
    /// a missed one, then two jumps refused.
    #[test]
    fn a_moved_mark_relocks_once_and_is_no_speed_error() {
        for (mark, refused) in [(40.0, 3), (-40.0, 4)] {
            let (ratios, relocks, refusals, error) = follow(1.0, mark, 40);
            assert!(ratios.is_empty(), "{mark}: {ratios:?}");
            assert_eq!(relocks, 1, "{mark}");
            assert!(refusals <= refused, "{mark}: {refusals}");
            assert!(error.abs() < 1e-6, "{mark}: {error}°");
        }
    }

    /// Keyphasor only (no speed topic) at 9,000 rpm: an extra pulse at 0.4 T is refused and
    /// keeps the history (the next true event's interval, T, is accepted); a missed pulse is
    /// refused once (2T, breaks the history; the next T is judged by the last accepted speed,
    /// not by the refused 4,500 rpm). Then a stop of 10 T and a restart at 8,000 rpm (−11 %):
    /// 3 refusals in a row, after which the intervals are judged afresh and the next gives
    /// 8,000 rpm to 10⁻⁶ (the stamps' 1 ns in 7.5 ms).
    #[test]
    fn extra_and_missed_pulses_cost_one_refusal_and_a_new_speed_is_learnt() {
        let mut lock = KeyphasorLock::new(KeyphasorSettings::default());
        for k in 0..4 {
            lock.event(rev_ns(k), None, None).unwrap();
        }
        let t = rev_ns(3) + (rev_ns(4) - rev_ns(3)) * 2 / 5;
        let extra = lock.event(t, None, None).unwrap_err();
        assert!(extra.why.contains("extra pulse") && !extra.breaks_history);
        let w = lock.event(rev_ns(4), None, None).unwrap();
        assert!((w.interval_speed_rad_s.unwrap() / W - 1.0).abs() < 1e-6);
        let missed = lock.event(rev_ns(6), None, None).unwrap_err();
        assert!(missed.why.contains("missed pulse") && missed.breaks_history);
        lock.event(rev_ns(7), None, None).unwrap();
        // a stop, then 8,000 rpm
        let w2 = W * 8.0 / 9.0;
        let at = |k: i64| rev_ns(17) + (k as f64 * TAU / w2 * 1e9).round() as i64;
        for k in 0..3 {
            let r = lock.event(at(k), None, None).unwrap_err();
            assert!(r.breaks_history, "{}", r.why);
        }
        let ev = lock.event(at(3), None, None).unwrap();
        let got = ev.interval_speed_rad_s.unwrap();
        assert!((got / w2 - 1.0).abs() < 1e-6, "{got} rad/s");
        lock.event(at(4), None, None).unwrap();
    }
}
