//! The model thread: the shared [`Driver`] at real-time pace, fed in order by the inputs the
//! subscriptions queue with their receive time on the node's clock (the wall clock, or `/clock`
//! under use_sim_time). It never runs on the async executor, never waits for the bus, and when it
//! falls behind it says so.

use super::params::NodeParams;
use crate::driver::{
    Applied, Driver, DriverSettings, Fed, Input, LiveCalibration, LiveEstimate, OneXBlocks,
};
use crate::messages::*;
use crate::rotor::Rotor;
pub use crate::session::Outgoing;
use crate::session::{warning, SessionSettings, WarningKind};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::SyncSender;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// What the model thread hands to the publishing thread: the twin's messages (those of the
/// driver, shared with the replay) and the node's own (issue 12: the live 1X vectors and the
/// calibration estimates).
#[derive(Debug, Clone)]
pub enum Published {
    /// A message of the twin.
    Twin(Outgoing),
    /// The 1X vectors of one station over a block.
    OneX(OneXVectors),
    /// The live calibration estimate (boxed: the largest message).
    Calibration(Box<CalibrationEstimate>),
}

/// Inputs waiting for the model thread beyond this many are dropped, oldest first, and counted.
pub const INBOX_CAPACITY: usize = 65_536;

/// Steps one wake of the model thread may take before it looks at its inputs again (at 9,000 rpm
/// and 64 steps a revolution, 256 steps are 27 ms of model time).
pub const MAX_STEPS_PER_WAKE: usize = 256;

/// How often the model thread wakes at most when nothing else wakes it (issue 17): each wake runs
/// every step then due, so a twin at 9,000 rpm and 64 steps a revolution takes about 19 steps a
/// wake instead of waking once or twice a step. A speed or unbalance input wakes it at once
/// (the subscription unparks the model thread), so the latency from a speed to the first output that reflects it stays
/// within this period plus the state interval.
pub const WAKE_PERIOD: Duration = Duration::from_millis(2);

/// An input waiting for the model thread.
#[derive(Debug)]
pub struct Queued {
    /// Its receive time on the node's clock (ns; None: under use_sim_time before the first
    /// `/clock`, fed at the model's present time).
    pub received_ns: Option<i64>,
    /// The input, or why it could not be decoded (refused, counted and warned about).
    pub input: Result<Input, String>,
}

/// What the subscriptions hand to the model thread.
#[derive(Debug, Default)]
pub struct Inbox {
    /// Inputs in order of arrival.
    pub queue: VecDeque<Queued>,
    /// Inputs dropped because the queue was full.
    pub dropped: u64,
}

impl Inbox {
    /// Queues one input; a full queue drops its oldest and counts it.
    pub fn push(&mut self, item: Queued) {
        if self.queue.len() >= INBOX_CAPACITY {
            self.queue.pop_front();
            self.dropped += 1;
        }
        self.queue.push_back(item);
    }
}

/// Counts kept outside the model thread, reported in its diagnostics.
#[derive(Debug, Default)]
pub struct NodeCounters {
    /// Messages the recorder could not take (its queue was full): lost from the recording.
    pub recording_dropped: AtomicU64,
    /// Messages the bus refused to take (a full send window).
    pub publish_failed: AtomicU64,
    /// The recording stopped before the node (e.g. a full disk): what follows is not recorded.
    pub recording_failed: AtomicBool,
    /// Input samples lost before the node read them, per input topic (gaps in each writer's
    /// sequence numbers, [`super::loss`]): (topic, count).
    pub lost_inputs: Mutex<Vec<(String, u64)>>,
    /// `lost_inputs` in all at the last diagnostics.
    pub lost_reported: AtomicU64,
    /// Which high-rate outputs have a reader on the bus.
    pub audience: Audience,
}

/// Which of the twin's high-rate outputs (journal and film states, orbits, residuals) have a
/// matched reader on the bus (issue 17: a twin nobody watches publishes its diagnostics,
/// warnings, margin and the node's own messages, not its states). Until [`Audience::watch`]
/// (tests, a node that records) every output is wanted.
#[derive(Debug, Default)]
pub struct Audience {
    /// the node follows its writers' matched readers
    watched: AtomicBool,
    /// bit k: [`Gated`] output k has at least one matched reader
    matched: AtomicU64,
    /// outputs not made because no reader wanted them
    pub skipped: AtomicU64,
}

/// The outputs published only to a reader (each a bit of [`Audience`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Gated {
    /// Journal states.
    Journal,
    /// Film states.
    Film,
    /// Orbits.
    Orbit,
    /// Residuals.
    Residual,
}

impl Audience {
    /// From now on only the outputs with a matched reader are wanted.
    pub fn watch(&self) {
        self.watched.store(true, Ordering::Relaxed);
    }

    /// Which gated output `o` is; None for the outputs that are always published (the latched
    /// warning and margin, the diagnostics, the forecast).
    pub fn gated(o: &Outgoing) -> Option<Gated> {
        match o {
            Outgoing::Journal(_) => Some(Gated::Journal),
            Outgoing::Film(_) => Some(Gated::Film),
            Outgoing::Orbit(_) => Some(Gated::Orbit),
            Outgoing::Residual(_) => Some(Gated::Residual),
            _ => None,
        }
    }

    /// Says whether output `g` has a matched reader now.
    pub fn set(&self, g: Gated, has_reader: bool) {
        let bit = 1u64 << (g as u32);
        if has_reader {
            self.matched.fetch_or(bit, Ordering::Relaxed);
        } else {
            self.matched.fetch_and(!bit, Ordering::Relaxed);
        }
    }

    /// True if `o` is to be published (and counts it when not).
    pub fn wants(&self, o: &Outgoing) -> bool {
        if !self.watched.load(Ordering::Relaxed) {
            return true;
        }
        let matched = self.matched.load(Ordering::Relaxed);
        let wanted = Self::gated(o).is_none_or(|g| matched & (1 << (g as u32)) != 0);
        if !wanted {
            self.skipped.fetch_add(1, Ordering::Relaxed);
        }
        wanted
    }
}

impl NodeCounters {
    /// Registers an input topic for the loss counts; returns its index.
    pub fn add_topic(&self, topic: &str) -> usize {
        let mut t = self.lost_inputs.lock().unwrap_or_else(|e| e.into_inner());
        t.push((topic.to_string(), 0));
        t.len() - 1
    }

    /// Counts `n` input samples of topic `index` lost before the node read them.
    pub fn lost(&self, index: usize, n: u64) {
        if n == 0 {
            return;
        }
        let mut t = self.lost_inputs.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(e) = t.get_mut(index) {
            e.1 += n;
        }
    }

    /// Input samples lost before the node read them, all topics.
    pub fn lost_total(&self) -> u64 {
        let t = self.lost_inputs.lock().unwrap_or_else(|e| e.into_inner());
        t.iter().map(|e| e.1).sum()
    }

    /// Hands `item` to the recorder; a full queue loses it, counted.
    pub fn record<T>(&self, rec: &std::sync::mpsc::SyncSender<T>, item: T) {
        if rec.try_send(item).is_err() {
            self.recording_dropped.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// The node's clock: the wall clock, or `/clock` under use_sim_time as
/// [`crate::driver::SimClock`] follows it (one bad sample refused, a reset followed).
#[derive(Debug, Default)]
pub struct NodeClock {
    /// Follow `/clock`.
    pub sim: bool,
    /// The simulation clock `/clock` drives.
    pub sim_clock: Mutex<crate::driver::SimClock>,
}

impl NodeClock {
    /// Now on this clock (ns since the epoch); None before the first `/clock` in sim time.
    pub fn now_ns(&self) -> Option<i64> {
        if self.sim {
            self.sim_clock
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .now_ns()
        } else {
            Some(now_ns())
        }
    }
}

/// Wall-clock time (ns since the epoch).
pub fn now_ns() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as i64)
}

/// The session's output settings from the node's parameters.
fn session_settings(p: &NodeParams) -> SessionSettings {
    SessionSettings {
        state_rate_hz: p.state_rate_hz,
        pressure_map_rate_hz: p.pressure_map_rate_hz,
        warning_amplitude_ratio: p.warning_amplitude_ratio,
        ..SessionSettings::default()
    }
}

/// The driver's settings from the node's parameters.
pub fn driver_settings(p: &NodeParams, rotor: &Rotor) -> DriverSettings {
    let mut s = DriverSettings::new(p.model, p.film, rotor.rated_speed_rad_s);
    s.twin = crate::dynamics::TwinConfig {
        film: p.film,
        ..crate::dynamics::TwinConfig::with_steps_per_rev(
            p.model.coupling(p.delta),
            rotor.rated_speed_rad_s,
            p.steps_per_rev,
        )
    };
    s.session = session_settings(p);
    s.min_speed_rad_s = crate::units::rpm_to_rad_s(p.min_speed_rpm);
    s.input_timeout_s = p.input_timeout_s;
    // a heat balance (up to 17 ms with the thermal film) must not stall the model thread
    s.heat_balance_off_thread = true;
    s
}

/// The linear threshold once computed: Some(Some((speed rad/s, whirl ratio))), Some(None) if
/// stable over the range, None while computing.
type ThresholdSlot = Option<Option<(f64, f64)>>;

/// Parameters changed at run time, as the parameter services share them.
pub type LiveParams = (Arc<Mutex<NodeParams>>, Arc<AtomicU64>);

/// Timing of the model thread over the current diagnostics interval.
#[derive(Debug, Clone, Copy)]
struct Timing {
    since: Instant,
    steps: u64,
    overruns: u64,
    worst_step_us: f64,
    lag_s: f64,
    last_behind_warning: Option<Instant>,
    wakes: u64,
    /// the last wake stopped at [`MAX_STEPS_PER_WAKE`] with steps still due
    behind: bool,
}

impl Timing {
    fn new() -> Self {
        Self {
            since: Instant::now(),
            wakes: 0,
            behind: false,
            steps: 0,
            overruns: 0,
            worst_step_us: 0.0,
            lag_s: 0.0,
            last_behind_warning: None,
        }
    }
}

/// The model loop of the node: owns the driver, reads the inbox, paces the twin by the clock.
pub struct ModelLoop {
    driver: Driver,
    params: NodeParams,
    live: LiveParams,
    seen_version: u64,
    inbox: Arc<Mutex<Inbox>>,
    clock: Arc<NodeClock>,
    threshold: Arc<Mutex<ThresholdSlot>>,
    timing: Timing,
    dropped_out: u64,
    last_fed_ns: i64,
    /// the node's name, for the diagnostic status names (`<name>: model`)
    node_name: String,
    counters: Arc<NodeCounters>,
    /// counts at the last diagnostics, to tell what happened in the interval
    counts_before: crate::driver::DriverCounts,
    /// the forecast thread's link, when `forecast_period_s` > 0 (issue 14)
    forecast: Option<super::forecast::ForecastLink>,
    /// the live 1X blocks per probe station (issue 12)
    one_x: OneXBlocks,
    /// the node's own messages of this wake, sent after the twin's
    pending: Vec<Published>,
    /// the live calibration's measurements, fitting thread and last estimate (issue 12)
    calibration: LiveCalibration,
    calibration_worker: Option<super::calibration::CalibrationWorker>,
    next_calibration_ns: i64,
    last_estimate: Option<LiveEstimate>,
    /// `calibration_apply` as last acted upon
    apply_seen: bool,
    /// the viscosity scale the threshold was computed at, and whether a computation runs
    threshold_scale: f64,
    threshold_busy: Arc<AtomicBool>,
}

impl ModelLoop {
    /// A loop for a twin of `rotor` with the node's parameters `params`. The linear stability
    /// threshold is computed on a helper thread (it takes a while) and the margin follows once
    /// it is known.
    pub fn new(
        rotor: Rotor,
        params: NodeParams,
        live: LiveParams,
        inbox: Arc<Mutex<Inbox>>,
        clock: Arc<NodeClock>,
    ) -> Self {
        let threshold = Arc::new(Mutex::new(None));
        let threshold_busy = Arc::new(AtomicBool::new(false));
        spawn_threshold(&rotor, &threshold, &threshold_busy);
        let driver = Driver::new(rotor.clone(), driver_settings(&params, &rotor));
        let calibration_worker = (params.calibration_period_s > 0.0)
            .then(super::calibration::CalibrationWorker::spawn)
            .and_then(|w| {
                w.map_err(|e| {
                    super::log::error(&format!("the calibration thread did not start: {e}"))
                })
                .ok()
            });
        Self {
            calibration: LiveCalibration::default(),
            calibration_worker,
            next_calibration_ns: i64::MIN,
            last_estimate: None,
            apply_seen: false,
            threshold_scale: rotor.viscosity_scale(),
            threshold_busy,
            one_x: OneXBlocks::new(driver.probe_axes()),
            pending: Vec::with_capacity(64),
            driver,
            params,
            live,
            seen_version: 0,
            inbox,
            clock,
            threshold,
            timing: Timing::new(),
            dropped_out: 0,
            last_fed_ns: i64::MIN,
            node_name: "rotor_twin".into(),
            counters: Arc::default(),
            counts_before: Default::default(),
            forecast: None,
        }
    }

    /// Runs until `stop` is set. Messages go to `out`; when `out` is full a message is dropped
    /// and counted (the model never waits for the bus).
    ///
    /// It wakes every [`WAKE_PERIOD`] (or at once when the thread is unparked: a speed or
    /// unbalance input), runs every step due, and wakes again at once only while it is
    /// behind by more than [`MAX_STEPS_PER_WAKE`] steps. Outputs without a reader are not
    /// published ([`Audience`]).
    pub fn run(mut self, out: SyncSender<Published>, stop: Arc<AtomicBool>) {
        self.start_forecast(&out);
        let mut dropped = 0u64;
        let counters = self.counters.clone();
        let mut next = Instant::now();
        while !stop.load(Ordering::Relaxed) {
            let mut emit = |m: Outgoing| {
                if counters.audience.wants(&m) && out.try_send(Published::Twin(m)).is_err() {
                    dropped += 1;
                }
            };
            self.wake(&mut emit);
            for m in self.pending.drain(..) {
                if out.try_send(m).is_err() {
                    dropped += 1;
                }
            }
            self.dropped_out = dropped;
            let now = Instant::now();
            next = (next + WAKE_PERIOD).max(now);
            if !self.timing.behind {
                std::thread::park_timeout(next - now);
            }
        }
    }

    /// The node's own messages of the last wakes (the live 1X vectors, the calibration), for a
    /// caller that drives [`ModelLoop::wake`] itself (tests).
    pub fn take_published(&mut self) -> Vec<Published> {
        std::mem::take(&mut self.pending)
    }

    /// One wake: parameter changes, the queued inputs, the steps now due, the reports. False
    /// when there was nothing to do (the caller sleeps).
    pub fn wake(&mut self, emit: &mut impl FnMut(Outgoing)) -> bool {
        self.timing.wakes += 1;
        self.take_parameters();
        if let Some(found) = *self.threshold.lock().unwrap_or_else(|e| e.into_inner()) {
            self.driver.set_threshold(found);
        }
        let Some(now) = self.clock.now_ns() else {
            return false;
        };
        let fed = self.feed_inputs(now, emit);
        let steps = self.step_until(now, emit);
        self.calibrate(now);
        self.refresh_threshold();
        if let Some(f) = self.forecast.as_mut() {
            f.after_wake(&self.driver);
        }
        self.report(now, emit);
        fed || steps > 0
    }

    /// Starts the forecast thread when `forecast_period_s` > 0; its messages go to `out`.
    fn start_forecast(&mut self, out: &SyncSender<Published>) {
        let p = &self.params;
        if p.forecast_period_s <= 0.0 {
            return;
        }
        let settings = crate::forecast::ForecastSettings {
            horizon_s: p.forecast_horizon_s,
            offsets_rpm: p.forecast_offsets_rpm.clone(),
            ..Default::default()
        };
        let s = self.driver.settings();
        match super::forecast::ForecastLink::spawn(
            self.driver.rotor(),
            s.twin,
            settings,
            p.forecast_period_s,
            out.clone(),
        ) {
            Ok(link) => self.forecast = Some(link),
            Err(e) => super::log::error(&format!("the forecast thread did not start: {e}")),
        }
    }

    /// The node's name as the diagnostics show it (default `rotor_twin`).
    pub fn set_node_name(&mut self, name: &str) {
        self.node_name = name.trim_start_matches('/').to_string();
    }

    /// The counters the node's other threads keep, for the diagnostics.
    pub fn set_counters(&mut self, counters: Arc<NodeCounters>) {
        self.counters = counters;
    }

    /// The driver (read only), e.g. for tests.
    pub fn driver(&self) -> &Driver {
        &self.driver
    }

    fn take_parameters(&mut self) {
        let version = self.live.1.load(Ordering::Relaxed);
        if version == self.seen_version {
            return;
        }
        self.seen_version = version;
        let p = self
            .live
            .0
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        self.params = p;
        self.driver.set_runtime(
            session_settings(&self.params),
            crate::units::rpm_to_rad_s(self.params.min_speed_rpm),
            self.params.input_timeout_s,
        );
    }

    /// Feeds the queued inputs in order, each at its receive time (never before the one fed
    /// last, nor after now).
    fn feed_inputs(&mut self, now: i64, emit: &mut impl FnMut(Outgoing)) -> bool {
        let batch = std::mem::take(&mut self.inbox.lock().unwrap_or_else(|e| e.into_inner()).queue);
        let any = !batch.is_empty();
        for Queued { received_ns, input } in batch {
            let t = received_ns.unwrap_or(now).clamp(self.last_fed_ns, now);
            self.last_fed_ns = t;
            // the steps up to the input's time count in the real-time factor too (they were
            // left out: a node woken late by a busy machine reported 0.01–0.3 while keeping up)
            let steps = self.driver.advance_to(t, usize::MAX, emit);
            self.timing.steps += steps as u64;
            match input {
                Ok(input) => {
                    let fed = self.driver.feed(t, input, emit);
                    self.after_feed(&fed);
                }
                Err(why) => self.driver.refuse(t, &why, emit),
            }
        }
        any
    }

    /// What the node makes of a fed input beyond the driver's messages: a compared probe sample
    /// goes into its station's 1X block, and the blocks now finished (their closing keyphasor
    /// event come, or their wait over) are published.
    fn after_feed(&mut self, fed: &Fed) {
        let events = self.driver.keyphasor_events();
        if let Fed::Compared(c) = fed {
            self.one_x.add(c, events);
        }
        let newest = self.driver.newest_sample_ns().unwrap_or(i64::MIN);
        while let Some(block) = self
            .one_x
            .take_ready(self.driver.keyphasor_events(), newest)
        {
            let name = self
                .driver
                .rotor()
                .probes
                .get(block.station)
                .map_or("", |p| p.name.as_str());
            self.pending.push(Published::OneX(block.to_message(name)));
            let dc = !self.driver.station_is_ac(block.station);
            self.calibration.add(&block, dc);
        }
    }

    /// The live calibration (issue 12): a change of `calibration_apply` acted upon, a finished
    /// fit published (and applied while `calibration_apply` is true), the next fit asked for
    /// every `calibration_period_s`.
    fn calibrate(&mut self, now: i64) {
        self.follow_apply(now);
        let Some(finished) = self.calibration_worker.as_ref().map(|w| w.take()) else {
            return;
        };
        if let Some(e) = finished {
            if self.params.calibration_apply {
                self.apply(&e);
            }
            let applied = self.driver.calibration().is_some();
            self.pending
                .push(Published::Calibration(Box::new(e.to_message(now, applied))));
            self.last_estimate = Some(e);
        }
        if now < self.next_calibration_ns {
            return;
        }
        let measured = self.calibration.measurements();
        if measured.0.is_empty() && measured.1.len() < 2 {
            return;
        }
        let asked = self.calibration_worker.as_ref().is_some_and(|w| {
            w.request(
                self.driver.rotor(),
                measured,
                self.driver.calibration_refinement(),
            )
        });
        if asked {
            let period = crate::driver::seconds_to_ns(self.params.calibration_period_s);
            self.next_calibration_ns = now.saturating_add(period);
        }
    }

    /// Applies an estimate's fitted values to the twin, logged.
    fn apply(&mut self, e: &LiveEstimate) {
        let (unbalance, viscosity_scale) = e.values();
        if unbalance.is_none() && viscosity_scale.is_none() {
            return;
        }
        let applied = Applied {
            unbalance,
            viscosity_scale,
        };
        match self.driver.apply_calibration(applied) {
            Ok(said) => super::log::info(&format!("calibration applied to the twin: {said}")),
            Err(why) => super::log::warn(&format!("calibration not applied: {why}")),
        }
    }

    /// `calibration_apply` changed: true applies the last estimate, false takes the calibration
    /// back (the machine file's and the received values in force again); logged, and the
    /// estimate published again with what is in force.
    fn follow_apply(&mut self, now: i64) {
        let want = self.params.calibration_apply;
        if want == self.apply_seen {
            return;
        }
        self.apply_seen = want;
        let Some(e) = self.last_estimate.take() else {
            if !want && self.driver.calibration().is_some() {
                self.revert_calibration();
            }
            return;
        };
        if want {
            self.apply(&e);
        } else {
            self.revert_calibration();
        }
        let applied = self.driver.calibration().is_some();
        self.pending
            .push(Published::Calibration(Box::new(e.to_message(now, applied))));
        self.last_estimate = Some(e);
    }

    /// Takes the calibration back, saying so or why it could not.
    fn revert_calibration(&mut self) {
        match self.driver.revert_calibration() {
            Ok(()) => super::log::info("calibration taken back: the machine file's and the received unbalance and viscosity are in force again"),
            Err(why) => super::log::warn(&format!("calibration not taken back: {why}")),
        }
    }

    /// The linear stability threshold recomputed, off the model thread, when the viscosity in
    /// force has moved by more than [`super::calibration::THRESHOLD_RESCALE`] since it was
    /// computed (an oil temperature, or a calibration); the old one is published meanwhile.
    fn refresh_threshold(&mut self) {
        let s = self.driver.viscosity_scale();
        let moved = (s / self.threshold_scale - 1.0).abs() > super::calibration::THRESHOLD_RESCALE;
        if !moved || self.threshold_busy.load(Ordering::Acquire) {
            return;
        }
        self.threshold_scale = s;
        super::log::info(&format!(
            "viscosity × {s:.4} in force: the stability threshold is recomputed"
        ));
        spawn_threshold(self.driver.rotor(), &self.threshold, &self.threshold_busy);
    }

    /// Steps up to `now`, one at a time to time each, at most [`MAX_STEPS_PER_WAKE`].
    fn step_until(&mut self, now: i64, emit: &mut impl FnMut(Outgoing)) -> usize {
        let h_us = self.driver.settings().twin.time_step_s * 1e6;
        let mut steps = 0;
        while steps < MAX_STEPS_PER_WAKE {
            let started = Instant::now();
            if self.driver.advance_to(now, 1, emit) == 0 {
                break;
            }
            let cost = started.elapsed().as_secs_f64() * 1e6;
            self.timing.worst_step_us = self.timing.worst_step_us.max(cost);
            self.timing.overruns += u64::from(cost > h_us);
            steps += 1;
        }
        self.timing.steps += steps as u64;
        self.timing.behind = steps == MAX_STEPS_PER_WAKE;
        if let Some(s) = self.driver.session() {
            self.timing.lag_s = ((now - s.stamp_ns()) as f64 * 1e-9).max(0.0);
        }
        steps
    }

    /// Falling-behind warnings and, every second of wall time, the diagnostics.
    fn report(&mut self, now: i64, emit: &mut impl FnMut(Outgoing)) {
        let lag = self.timing.lag_s;
        let warned = self.timing.last_behind_warning;
        if lag > 0.1 && warned.is_none_or(|t| t.elapsed() > Duration::from_secs(1)) {
            self.timing.last_behind_warning = Some(Instant::now());
            emit(warning(
                now,
                InstabilityWarning::WARN,
                WarningKind::FallingBehind,
                "",
                format!("the model runs {lag:.3} s behind the clock"),
            ));
        }
        if self.timing.since.elapsed() < Duration::from_secs(1) {
            return;
        }
        emit(Outgoing::Diagnostics(self.diagnostics(now)));
        self.timing = Timing {
            last_behind_warning: self.timing.last_behind_warning,
            lag_s: self.timing.lag_s,
            ..Timing::new()
        };
    }

    /// The diagnostics as diagnostic_updater publishes them: one status per concern (the model's
    /// timing, the inputs), named `<node>: …`, hardware_id the machine's name, levels OK / WARN /
    /// ERROR / STALE.
    fn diagnostics(&mut self, now: i64) -> DiagnosticArray {
        let counts = self.driver.counts();
        let before = std::mem::replace(&mut self.counts_before, counts);
        let mut status = vec![
            self.model_status(counts.step_failures - before.step_failures),
            self.input_status(now, counts.refused - before.refused),
        ];
        if let Some(f) = self.forecast_status() {
            status.push(f);
        }
        DiagnosticArray {
            header: crate::session::header(now, ""),
            status,
        }
    }

    fn status(
        &self,
        concern: &str,
        level: u8,
        message: String,
        values: Vec<KeyValue>,
    ) -> DiagnosticStatus {
        DiagnosticStatus {
            level,
            name: format!("{}: {concern}", self.node_name),
            message,
            hardware_id: self.driver.rotor().name.clone(),
            values,
        }
    }

    fn model_status(&self, failures: u64) -> DiagnosticStatus {
        let t = &self.timing;
        let h = self.driver.settings().twin.time_step_s;
        let rtf = t.steps as f64 * h / t.since.elapsed().as_secs_f64();
        let mut values = vec![
            kv("real_time_factor", format!("{rtf:.3}")),
            kv("lag_s", format!("{:.4}", t.lag_s)),
            kv("step_overruns", t.overruns.to_string()),
            kv("worst_step_us", format!("{:.1}", t.worst_step_us)),
            kv("dropped_messages", self.dropped_out.to_string()),
            kv(
                "publish_failed",
                self.counters
                    .publish_failed
                    .load(Ordering::Relaxed)
                    .to_string(),
            ),
            kv(
                "recording_dropped",
                self.counters
                    .recording_dropped
                    .load(Ordering::Relaxed)
                    .to_string(),
            ),
            kv(
                "step_failures",
                self.driver.counts().step_failures.to_string(),
            ),
            kv("time_step_us", format!("{:.2}", h * 1e6)),
            kv("wakes", t.wakes.to_string()),
            kv(
                "outputs_without_reader",
                self.counters
                    .audience
                    .skipped
                    .load(Ordering::Relaxed)
                    .to_string(),
            ),
        ];
        let oil = self.driver.oil_diagnostics();
        values.extend(oil.values.iter().map(|(k, v)| kv(k, v.clone())));
        let (level, message) = if self.counters.recording_failed.load(Ordering::Relaxed) {
            (
                DiagnosticStatus::ERROR,
                "the recording stopped (see the node's log): outputs are no longer recorded".into(),
            )
        } else if failures > 0 {
            (
                DiagnosticStatus::ERROR,
                format!("{failures} step(s) failed; the twin restarts"),
            )
        } else if t.lag_s > 0.1 {
            (
                DiagnosticStatus::WARN,
                format!("{:.3} s behind real time", t.lag_s),
            )
        } else if let Some(why) = oil.warning {
            (DiagnosticStatus::WARN, why)
        } else if self.driver.session().is_none() {
            (
                DiagnosticStatus::OK,
                "waiting for a speed at or above the minimum".into(),
            )
        } else {
            (DiagnosticStatus::OK, "keeping up".into())
        };
        self.status("model", level, message, values)
    }

    /// `<node>: forecast`: the last and longest forecast duration, forecasts done, cycles skipped
    /// because one was still running, the checkpoint's cost in the model thread; WARN when a
    /// cycle was skipped in the interval (a forecast took longer than the period), ERROR when it
    /// cannot run.
    fn forecast_status(&self) -> Option<DiagnosticStatus> {
        let f = self.forecast.as_ref()?;
        let st = &f.stats;
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        let skipped = get(&st.skipped);
        let skipped_now = skipped - st.skipped_reported.swap(skipped, Ordering::Relaxed);
        let values = vec![
            kv("period_s", format!("{:.3}", self.params.forecast_period_s)),
            kv(
                "horizon_s",
                format!("{:.3}", self.params.forecast_horizon_s),
            ),
            kv("completed", get(&st.completed).to_string()),
            kv("skipped_cycles", skipped.to_string()),
            kv(
                "last_duration_s",
                format!("{:.3}", get(&st.last_duration_us) as f64 * 1e-6),
            ),
            kv(
                "worst_duration_s",
                format!("{:.3}", get(&st.worst_duration_us) as f64 * 1e-6),
            ),
            kv("checkpoint_us", get(&st.checkpoint_us).to_string()),
            kv("dropped", get(&st.dropped).to_string()),
            kv(
                "lower_priority",
                st.niced.load(Ordering::Relaxed).to_string(),
            ),
            kv("model_lag_s", format!("{:.4}", self.timing.lag_s)),
        ];
        let (level, message) = if st.failed.load(Ordering::Relaxed) {
            (
                DiagnosticStatus::ERROR,
                "the forecast cannot run (see the node's log)".into(),
            )
        } else if skipped_now > 0 {
            (
                DiagnosticStatus::WARN,
                format!("{skipped_now} cycle(s) skipped: a forecast took longer than the period"),
            )
        } else {
            (DiagnosticStatus::OK, "forecasting".into())
        };
        Some(self.status("forecast", level, message, values))
    }

    fn input_status(&self, now: i64, refused: u64) -> DiagnosticStatus {
        let counts = self.driver.counts();
        let dropped_in = self.inbox.lock().unwrap_or_else(|e| e.into_inner()).dropped;
        let age = self.driver.speed_age_s(now);
        let values = vec![
            kv(
                "speed_input_age_s",
                age.map_or("none".into(), |a| format!("{a:.3}")),
            ),
            kv("refused_inputs", counts.refused.to_string()),
            kv("dropped_inputs", dropped_in.to_string()),
            kv(
                "keyphasor",
                keyphasor_state(self.driver.phase_reference(now)).into(),
            ),
            kv("keyphasor_relocks", counts.relocks.to_string()),
            kv("speed_mismatches", counts.speed_mismatches.to_string()),
            kv(
                "speed_topic_scale",
                self.driver
                    .speed_scale()
                    .map_or("none".into(), |s| format!("{s:.6}")),
            ),
        ];
        let (values, lost_now) = self.loss_values(values);
        let timeout = self.driver.settings().input_timeout_s;
        let (level, message) = match age {
            None => (DiagnosticStatus::STALE, "no speed received yet".into()),
            Some(a) if a > timeout => (DiagnosticStatus::STALE, format!("no speed for {a:.2} s")),
            Some(_) if lost_now > 0 => (
                DiagnosticStatus::WARN,
                format!("{lost_now} input sample(s) lost before the node in the last second"),
            ),
            Some(_) if refused > 0 => (
                DiagnosticStatus::WARN,
                format!("{refused} input(s) refused in the last second"),
            ),
            Some(_) => (DiagnosticStatus::OK, "speed fresh".into()),
        };
        self.status("inputs", level, message, values)
    }

    /// Every count of input samples lost or not used, where it happened (issue 15, item 8):
    /// lost before the node (`lost_samples`, in all and per topic: sequence gaps), queued
    /// beyond the inbox (`dropped_inputs`, already in `values`), valid probes not compared
    /// (no twin at their time), raw readings never paired, 1X blocks given up; and the losses
    /// since the last diagnostics.
    fn loss_values(&self, mut values: Vec<KeyValue>) -> (Vec<KeyValue>, u64) {
        let counts = self.driver.counts();
        let total = self.counters.lost_total();
        let before = self
            .counters
            .lost_reported
            .swap(total, std::sync::atomic::Ordering::Relaxed);
        values.push(kv("lost_samples", total.to_string()));
        for (topic, n) in self
            .counters
            .lost_inputs
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
            .filter(|e| e.1 > 0)
        {
            values.push(kv(&format!("lost_samples {topic}"), n.to_string()));
        }
        values.push(kv(
            "probes_not_compared",
            counts.probes_not_compared.to_string(),
        ));
        values.push(kv(
            "raw_readings_unpaired",
            counts.readings_unpaired.to_string(),
        ));
        values.push(kv(
            "one_x_blocks_overflowed",
            self.one_x.overflowed.to_string(),
        ));
        (values, total.saturating_sub(before))
    }
}

/// The keyphasor's state as `<node>: inputs` reports it: locked, not_locked (events come, the
/// running twin is not locked yet), stopped (no event for 3 revolutions: phases null), none.
fn keyphasor_state(r: crate::signals::PhaseReference) -> &'static str {
    use crate::signals::PhaseReference::*;
    match r {
        Locked => "locked",
        NotLocked => "not_locked",
        Stopped => "stopped",
        NoKeyphasor => "none",
    }
}

/// Computes the linear stability threshold of `rotor` on a helper thread into `slot`
/// (`busy` while it runs).
fn spawn_threshold(rotor: &Rotor, slot: &Arc<Mutex<ThresholdSlot>>, busy: &Arc<AtomicBool>) {
    let (rotor, slot, busy) = (rotor.clone(), slot.clone(), busy.clone());
    busy.store(true, Ordering::Release);
    std::thread::spawn(move || {
        let value = crate::session::linear_threshold(&rotor);
        *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(value);
        busy.store(false, Ordering::Release);
    });
}

fn kv(key: &str, value: String) -> KeyValue {
    KeyValue {
        key: key.into(),
        value,
    }
}
