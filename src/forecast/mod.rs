//! The forecast (look-ahead): from a checkpoint of the live twin's state, the same twin core
//! ([`Twin`]) is run ahead of real time for a horizon of T seconds — on the **expected path**
//! (the present speed continued at the present acceleration) and at **constant speeds** from the
//! present one up — and each run is classified revolution by revolution by a copy of the live
//! session's monitor, continued from the revolutions before the checkpoint. From the constant-speed runs comes the
//! **nonlinear stability margin**: the lowest speed at which the nonlinear twin, from its present
//! state, goes into whip within the horizon, bracketed by bisection between the probed speeds.
//! I/O-free and clock-free: the node runs it on a thread of its own, the replay at bag time.

pub mod schedule;
pub mod score;

use crate::dynamics::{Checkpoint, StepInput, Twin, TwinConfig, TwinError};
use crate::messages::{self, Header, Time};
use crate::monitor::{Monitor, RotorState};
use crate::rotor::Rotor;
use crate::session::Session;
use crate::units::{rad_s_to_rpm, rpm_to_rad_s};
use serde::Serialize;

/// Default look-ahead horizon (s). Three seconds is 450 revolutions at 9,000 rpm: long enough
/// for a whirl growing at the classifier's threshold rate plus half again (0.003/rev) to grow
/// e-fold 1.35 times, for the twin's whirl on the shipped run-up to develop into whip (whirl at
/// 6.10 s, whip at 6.83 s), and short enough that a forecast of the default four runs costs
/// about a second of one core at 8,000 rpm (measured in the node: 1.0–1.3 s median).
pub const DEFAULT_HORIZON_S: f64 = 3.0;

/// Default constant speeds probed, above the present speed (rpm): 0 (the present speed), +100,
/// +250, +500 rpm — 1 %, 3 % and 6 % of the microturbine's rated 9,000 rpm, the range of an
/// operator's next set-point change.
pub const DEFAULT_OFFSETS_RPM: [f64; 4] = [0.0, 100.0, 250.0, 500.0];

/// Default resolution of the nonlinear threshold (rpm): the bisection stops when the bracket is
/// this narrow (two or three extra runs between the default probes).
pub const DEFAULT_MARGIN_RESOLUTION_RPM: f64 = 50.0;

/// Shortest forecast period (s): a forecast of the default runs costs about a second of one
/// core, so periods below a tenth of a second only queue skipped cycles (node) or multiply a
/// replay's cost (a period of 1e-9 s would ask for 8·10⁹ forecasts of the sample bag).
pub const MIN_PERIOD_S: f64 = 0.1;

/// Largest speed offset probed (rpm): a forecast looks at the operator's next set-point changes,
/// not at speeds the machine file's limits would refuse anyway.
pub const MAX_OFFSET_RPM: f64 = 10_000.0;

/// Revolutions a whirl (or whip) must hold in a run to count as its onset: 24, the replay's
/// onset rule (3 consecutive blocks of 8 revolutions), so that a forecast onset and an observed
/// one mean the same. A run ending before that counts a state held to its end.
pub const PERSIST_REVOLUTIONS: u32 = 24;

/// An acceleration whose effect over the horizon is below this (rad/s) makes the expected path
/// the present-speed run (1 rpm).
const STEADY_SPEED_CHANGE_RAD_S: f64 = std::f64::consts::PI / 30.0;

/// Steps between two `yield_now` of a run (the node's forecast thread lets the model thread go
/// first; at 64 steps a revolution, 1,024 steps are 16 revolutions, ~40 ms of wall time).
const YIELD_EVERY_STEPS: usize = 1024;

/// What to forecast.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForecastSettings {
    /// Look-ahead horizon (s of model time).
    pub horizon_s: f64,
    /// Constant-speed runs at the present speed plus these (rpm, ascending; empty: no margin).
    pub offsets_rpm: Vec<f64>,
    /// Bisection stops at a bracket this narrow (rpm); 0 or more than the probes' spacing: no
    /// bisection, the bracket is the probes'.
    pub margin_resolution_rpm: f64,
}

impl Default for ForecastSettings {
    fn default() -> Self {
        Self {
            horizon_s: DEFAULT_HORIZON_S,
            offsets_rpm: DEFAULT_OFFSETS_RPM.to_vec(),
            margin_resolution_rpm: DEFAULT_MARGIN_RESOLUTION_RPM,
        }
    }
}

impl ForecastSettings {
    /// Refuses a horizon that is not a positive finite number (up to 60 s) and offsets that are
    /// not finite, non-negative and ascending, naming the field and the value.
    pub fn check(&self) -> Result<(), String> {
        if !(self.horizon_s.is_finite() && self.horizon_s > 0.0 && self.horizon_s <= 60.0) {
            return Err(format!(
                "forecast horizon (s): {} must be greater than 0 and at most 60",
                self.horizon_s
            ));
        }
        if let Some(bad) = self
            .offsets_rpm
            .iter()
            .find(|o| !(o.is_finite() && (0.0..=MAX_OFFSET_RPM).contains(*o)))
        {
            return Err(format!(
                "forecast speed offset (rpm): {bad} must be a finite number from 0 to {MAX_OFFSET_RPM}"
            ));
        }
        if self.offsets_rpm.windows(2).any(|w| w[1] <= w[0]) {
            return Err(format!(
                "forecast speed offsets (rpm): {:?} must be ascending",
                self.offsets_rpm
            ));
        }
        if !(self.margin_resolution_rpm.is_finite() && self.margin_resolution_rpm >= 0.0) {
            return Err(format!(
                "forecast margin resolution (rpm): {} must be a finite number ≥ 0",
                self.margin_resolution_rpm
            ));
        }
        Ok(())
    }
}

/// Where a forecast starts: the twin's checkpoint and the inputs in force.
pub struct ForecastStart {
    /// The live twin's state.
    pub checkpoint: Checkpoint,
    /// The live session's monitor, so that each run classifies on from the revolutions before
    /// the checkpoint (a whirl under way is seen at once, the growth rate is known).
    pub monitor: Monitor,
    /// Model time of the checkpoint (s).
    pub time_s: f64,
    /// Stamp of the checkpoint (ns since the epoch).
    pub stamp_ns: i64,
    /// Speed in force (rad/s).
    pub speed_rad_s: f64,
    /// Acceleration in force (rad/s²).
    pub accel_rad_s2: f64,
    /// The linear threshold as the driver knows it (rad/s, whirl ratio), if found.
    pub linear_threshold: Option<(f64, f64)>,
}

impl ForecastStart {
    /// The start from `session`'s twin and monitor now, with speed `speed_rad_s` and
    /// acceleration `accel_rad_s2` (allocates: a copy of the state, the films and the monitor).
    pub fn of(
        session: &Session,
        speed_rad_s: f64,
        accel_rad_s2: f64,
        linear_threshold: Option<(f64, f64)>,
    ) -> Self {
        Self {
            checkpoint: session.twin().checkpoint(),
            monitor: session.monitor().clone(),
            time_s: session.twin().time_s(),
            stamp_ns: session.stamp_ns(),
            speed_rad_s,
            accel_rad_s2,
            linear_threshold,
        }
    }
}

/// One run ahead.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RunForecast {
    /// Speed at the start of the run (rad/s).
    pub speed_rad_s: f64,
    /// Acceleration along the run (rad/s²; 0 for a constant-speed run).
    pub accel_rad_s2: f64,
    /// The worst bearing's state at the last revolution of the run.
    pub state: RotorState,
    /// Time from the start to a persisting whirl or whip (s).
    pub onset_after_s: Option<f64>,
    /// Time from the start to a persisting whip (s).
    pub whip_after_s: Option<f64>,
    /// Largest orbit amplitude (half peak-to-peak) of any bearing in any revolution (m).
    pub amplitude_m: f64,
    /// Model time run (s): the horizon, or less when the run stopped at a persisting whip or a
    /// failed step.
    pub ran_s: f64,
    /// A step failed (the run stopped there).
    pub failed: bool,
}

/// A forecast.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Forecast {
    /// Model time of the checkpoint (s).
    pub time_s: f64,
    /// Its stamp (ns since the epoch).
    pub stamp_ns: i64,
    /// Horizon (s).
    pub horizon_s: f64,
    /// Speed at the checkpoint (rad/s).
    pub speed_rad_s: f64,
    /// Acceleration at the checkpoint (rad/s²).
    pub accel_rad_s2: f64,
    /// The expected path (the present speed at the present acceleration).
    pub expected: RunForecast,
    /// The constant-speed runs, the probes and the bisection's, ascending in speed.
    pub runs: Vec<RunForecast>,
    /// Lowest speed whose run went into whip (rad/s), with the bracket's width (rad/s): the
    /// threshold lies in (speed − width, speed]; a width equal to the speed means "at or below
    /// it" (the lowest speed probed whips already); None if no run whipped.
    pub nonlinear_threshold: Option<(f64, f64)>,
    /// The linear threshold (rad/s, whirl ratio), as given.
    pub linear_threshold: Option<(f64, f64)>,
    /// Steps taken by all the runs.
    pub steps: u64,
}

/// Runs forecasts on a twin of its own (built once; each forecast restores the checkpoint).
pub struct Forecaster {
    twin: Twin,
    settings: ForecastSettings,
    max_speed_rad_s: f64,
    steps: u64,
}

impl Forecaster {
    /// A forecaster for twins of `rotor` with `config` (the live twin's; the monitor and its
    /// alarm settings come with each start).
    pub fn new(
        rotor: &Rotor,
        config: TwinConfig,
        settings: ForecastSettings,
    ) -> Result<Self, TwinError> {
        settings.check().map_err(TwinError::Setup)?;
        Ok(Self {
            twin: Twin::new(rotor, config, rotor.rated_speed_rad_s)?,
            settings,
            max_speed_rad_s: crate::driver::InputLimits::of(rotor).max_speed_rad_s,
            steps: 0,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &ForecastSettings {
        &self.settings
    }

    /// The forecast from `start`.
    pub fn forecast(&mut self, start: &ForecastStart) -> Forecast {
        self.steps = 0;
        let w0 = start.speed_rad_s;
        let mut runs: Vec<RunForecast> = Vec::new();
        for off in self.settings.offsets_rpm.clone() {
            let run = self.run(start, w0 + rpm_to_rad_s(off), 0.0);
            runs.push(run);
        }
        let nonlinear_threshold = self.bisect(start, &mut runs);
        let steady =
            (start.accel_rad_s2 * self.settings.horizon_s).abs() < STEADY_SPEED_CHANGE_RAD_S;
        let expected = match runs.first() {
            Some(r) if steady && self.settings.offsets_rpm.first() == Some(&0.0) => *r,
            _ => self.run(start, w0, if steady { 0.0 } else { start.accel_rad_s2 }),
        };
        Forecast {
            time_s: start.time_s,
            stamp_ns: start.stamp_ns,
            horizon_s: self.settings.horizon_s,
            speed_rad_s: w0,
            accel_rad_s2: start.accel_rad_s2,
            expected,
            runs,
            nonlinear_threshold,
            linear_threshold: start.linear_threshold,
            steps: self.steps,
        }
    }

    /// The lowest whipping speed among `runs` (ascending), the bracket below it narrowed by
    /// bisection to the resolution (the runs it takes are added to `runs`, kept ascending).
    fn bisect(&mut self, start: &ForecastStart, runs: &mut Vec<RunForecast>) -> Option<(f64, f64)> {
        let k = runs.iter().position(|r| r.whip_after_s.is_some())?;
        let mut hi = runs[k].speed_rad_s;
        let w0 = start.speed_rad_s;
        let mut lo = match k.checked_sub(1) {
            Some(j) => runs[j].speed_rad_s,
            // the lowest probe whips, above the present speed: bracket from the present speed
            None if hi > w0 => {
                let run = self.run(start, w0, 0.0);
                let whips = run.whip_after_s.is_some();
                runs.insert(0, run);
                if whips {
                    // at or below the present speed: nothing below it was probed
                    return Some((w0, w0));
                }
                w0
            }
            // the present speed whips already: at or below it (nothing below was probed)
            None => return Some((hi, hi)),
        };
        let resolution = rpm_to_rad_s(self.settings.margin_resolution_rpm);
        while resolution > 0.0 && hi - lo > resolution {
            let mid = 0.5 * (lo + hi);
            let run = self.run(start, mid, 0.0);
            if run.whip_after_s.is_some() {
                hi = mid;
            } else {
                lo = mid;
            }
            let at = runs.partition_point(|r| r.speed_rad_s < mid);
            runs.insert(at, run);
        }
        Some((hi, hi - lo))
    }

    /// One run from `start` at `speed_rad_s` changing at `accel_rad_s2`, for the horizon (or
    /// until a whip has persisted).
    fn run(&mut self, start: &ForecastStart, speed_rad_s: f64, accel_rad_s2: f64) -> RunForecast {
        self.twin.restore(&start.checkpoint);
        let mut monitor = start.monitor.clone();
        let h = self.twin.config().time_step_s;
        let steps = (self.settings.horizon_s / h).round().max(1.0) as usize;
        let mut track = Track::default();
        let mut run = RunForecast {
            speed_rad_s,
            accel_rad_s2,
            state: RotorState::Stable,
            onset_after_s: None,
            whip_after_s: None,
            amplitude_m: 0.0,
            ran_s: 0.0,
            failed: false,
        };
        for k in 1..=steps {
            let w = (speed_rad_s + accel_rad_s2 * k as f64 * h).clamp(0.0, self.max_speed_rad_s);
            let a = if w > 0.0 && w < self.max_speed_rad_s {
                accel_rad_s2
            } else {
                0.0
            };
            if self
                .twin
                .step(&StepInput {
                    speed_rad_s: w,
                    accel_rad_s2: a,
                })
                .is_err()
            {
                run.failed = true;
                break;
            }
            self.steps += 1;
            run.ran_s = k as f64 * h;
            if k % YIELD_EVERY_STEPS == 0 {
                std::thread::yield_now();
            }
            if let Some(rep) = monitor.record(&self.twin) {
                let amplitude = rep
                    .bearings
                    .iter()
                    .map(|b| b.amplitude_m)
                    .fold(0.0, f64::max);
                run.amplitude_m = run.amplitude_m.max(amplitude);
                run.state = rep.state;
                track.revolution(rep.state, run.ran_s);
                if track.whip_at.is_some() {
                    break;
                }
            }
        }
        (run.onset_after_s, run.whip_after_s) = track.finish();
        run
    }
}

/// Onset bookkeeping of a run: the start of the current stretch of whirl-or-whip and of whip
/// revolutions, and the first of each that persisted [`PERSIST_REVOLUTIONS`].
#[derive(Debug, Default)]
struct Track {
    unstable: Option<(f64, u32)>,
    whip: Option<(f64, u32)>,
    onset_at: Option<f64>,
    whip_at: Option<f64>,
}

impl Track {
    /// A revolution ending at `t_s` (s from the run's start) in state `state`. The stretch
    /// starts at the end of its first revolution.
    fn revolution(&mut self, state: RotorState, t_s: f64) {
        let step = |stretch: &mut Option<(f64, u32)>, on: bool, first: &mut Option<f64>| {
            *stretch = if on {
                let (t0, n) = stretch.unwrap_or((t_s, 0));
                Some((t0, n + 1))
            } else {
                None
            };
            if let Some((t0, n)) = *stretch {
                if n >= PERSIST_REVOLUTIONS && first.is_none() {
                    *first = Some(t0);
                }
            }
        };
        step(
            &mut self.unstable,
            state >= RotorState::Whirl,
            &mut self.onset_at,
        );
        step(&mut self.whip, state == RotorState::Whip, &mut self.whip_at);
    }

    /// (onset, whip) times: the persisting ones, else a stretch held to the end of the run for
    /// at least 3 revolutions.
    fn finish(&self) -> (Option<f64>, Option<f64>) {
        let held = |s: Option<(f64, u32)>| s.filter(|s| s.1 >= 3).map(|s| s.0);
        (
            self.onset_at.or(held(self.unstable)),
            self.whip_at.or(held(self.whip)),
        )
    }
}

impl Forecast {
    /// The message, with the wall time it took (s).
    pub fn to_message(&self, compute_duration_s: f64) -> messages::Forecast {
        let t = |v: Option<f64>| v.unwrap_or(-1.0);
        let (nl_found, nl_speed, nl_res) = match self.nonlinear_threshold {
            Some((s, r)) => (true, s, r),
            None => (false, 0.0, 0.0),
        };
        let (lin_found, lin_speed) = match self.linear_threshold {
            Some((s, _)) => (true, s),
            None => (false, 0.0),
        };
        let margin = |found: bool, s: f64| if found { s - self.speed_rad_s } else { 0.0 };
        messages::Forecast {
            header: Header {
                stamp: Time::from_nanos(self.stamp_ns),
                frame_id: String::new(),
            },
            horizon: self.horizon_s,
            speed: self.speed_rad_s,
            acceleration: self.accel_rad_s2,
            expected_state: self.expected.state.warning_kind().into(),
            time_to_onset: t(self.expected.onset_after_s),
            time_to_whip: t(self.expected.whip_after_s),
            amplitude: self.expected.amplitude_m,
            speeds: self.runs.iter().map(|r| r.speed_rad_s).collect(),
            states: self
                .runs
                .iter()
                .map(|r| r.state.warning_kind().into())
                .collect(),
            onset_times: self.runs.iter().map(|r| t(r.onset_after_s)).collect(),
            whip_times: self.runs.iter().map(|r| t(r.whip_after_s)).collect(),
            amplitudes: self.runs.iter().map(|r| r.amplitude_m).collect(),
            nonlinear_threshold_found: nl_found,
            nonlinear_threshold_speed: nl_speed,
            nonlinear_threshold_resolution: nl_res,
            nonlinear_margin: margin(nl_found, nl_speed),
            linear_threshold_found: lin_found,
            linear_threshold_speed: lin_speed,
            linear_margin: margin(lin_found, lin_speed),
            compute_duration: compute_duration_s,
        }
    }

    /// One line for a log (allocates).
    pub fn describe(&self) -> String {
        let when = |v: Option<f64>| v.map_or("none".to_string(), |t| format!("{t:.2} s"));
        let nl = match self.nonlinear_threshold {
            Some((s, r)) if r >= s => format!("at or below {:.0} rpm", rad_s_to_rpm(s)),
            Some((s, r)) => format!("{:.0} rpm (−{:.0})", rad_s_to_rpm(s), rad_s_to_rpm(r)),
            None => "not within the probes".into(),
        };
        format!(
            "at {:.0} rpm: expected {} (onset {}, whip {}, amplitude {:.1} µm); nonlinear threshold {nl}",
            rad_s_to_rpm(self.speed_rad_s),
            self.expected.state.warning_kind(),
            when(self.expected.onset_after_s),
            when(self.expected.whip_after_s),
            self.expected.amplitude_m * 1e6,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The persistence rule by hand: a whirl stretch interrupted after 23 revolutions is no
    /// onset; one held 24 revolutions is, from its first revolution; a whip likewise; a stretch
    /// held to the end of a run counts from 3 revolutions on.
    #[test]
    fn an_onset_must_persist_24_revolutions() {
        let mut t = Track::default();
        for k in 0..23 {
            t.revolution(RotorState::Whirl, k as f64);
        }
        t.revolution(RotorState::Growing, 23.0);
        assert_eq!(t.finish(), (None, None));
        for k in 24..48 {
            t.revolution(RotorState::Whirl, k as f64);
        }
        assert_eq!(t.onset_at, Some(24.0));
        for k in 48..60 {
            t.revolution(RotorState::Whip, k as f64);
        }
        // the whip has held 12 revolutions to the end of the run: counted, from 48
        assert_eq!(t.finish(), (Some(24.0), Some(48.0)));
        let mut short = Track::default();
        short.revolution(RotorState::Whip, 0.0);
        short.revolution(RotorState::Whip, 1.0);
        assert_eq!(
            short.finish(),
            (None, None),
            "two revolutions are not enough"
        );
    }

    /// Settings refused with the field and the value.
    #[test]
    fn bad_settings_are_refused() {
        let bad = |s: ForecastSettings| s.check().unwrap_err();
        let d = ForecastSettings::default;
        assert!(bad(ForecastSettings {
            horizon_s: 0.0,
            ..d()
        })
        .contains("horizon"));
        assert!(bad(ForecastSettings {
            horizon_s: f64::NAN,
            ..d()
        })
        .contains("NaN"));
        assert!(bad(ForecastSettings {
            offsets_rpm: vec![0.0, 0.0],
            ..d()
        })
        .contains("ascending"));
        assert!(bad(ForecastSettings {
            offsets_rpm: vec![-1.0],
            ..d()
        })
        .contains("-1"));
        assert!(d().check().is_ok());
    }
}
