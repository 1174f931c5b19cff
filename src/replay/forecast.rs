//! `replay --forecast`: the forecast ([`crate::forecast`]) run offline at bag time, every
//! period, from a checkpoint of the replay's twin, and scored against the plant's observed onset.

use super::compare::StationComparison;
use super::ReplayError;
use crate::driver::Driver;
use crate::forecast::schedule::{start_of, Schedule};
use crate::forecast::score::{ForecastRecord, ForecastScore};
use crate::forecast::{ForecastSettings, Forecaster};
use crate::rotor::Rotor;
use crate::session::Outgoing;
use std::time::{Duration, Instant};

/// Default forecast period of a replay (s of bag time): 0.5 s, so that an onset is announced at
/// most half a second later than the first state from which the twin can see it coming.
pub const DEFAULT_REPLAY_FORECAST_PERIOD_S: f64 = 0.5;

/// What to forecast in a replay, and how often.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayForecast {
    /// Bag time between forecasts (s).
    pub period_s: f64,
    /// What each forecast runs.
    pub settings: ForecastSettings,
}

impl Default for ReplayForecast {
    fn default() -> Self {
        Self {
            period_s: DEFAULT_REPLAY_FORECAST_PERIOD_S,
            settings: ForecastSettings::default(),
        }
    }
}

/// The forecasting of a replay under way.
pub(super) struct Forecasting {
    forecaster: Forecaster,
    schedule: Schedule,
    t0_ns: i64,
    records: Vec<ForecastRecord>,
    wall: Duration,
}

impl Forecasting {
    /// The forecasting `options` ask for (None without `--forecast`), on a twin of `rotor`
    /// with the replay's twin settings; bag time zero `t0_ns`.
    pub(super) fn for_options(
        rotor: &Rotor,
        options: &super::ReplayOptions,
        t0_ns: i64,
    ) -> Result<Option<Self>, ReplayError> {
        let Some(f) = &options.forecast else {
            return Ok(None);
        };
        if !(f.period_s.is_finite() && f.period_s > 0.0) {
            return Err(ReplayError::Forecast(format!(
                "forecast period (s): {} must be a finite number greater than 0",
                f.period_s
            )));
        }
        let twin = options.driver_settings(rotor).twin;
        let forecaster = Forecaster::new(rotor, twin, f.settings.clone())
            .map_err(|e| ReplayError::Forecast(e.to_string()))?;
        Ok(Some(Self {
            forecaster,
            schedule: Schedule::new(f.period_s),
            t0_ns,
            records: Vec::new(),
            wall: Duration::ZERO,
        }))
    }

    /// After a bag message: a forecast from the twin's present state when one is due. Its
    /// message goes to `emit` with `compute_duration` 0, so that a replay's output bag is the
    /// same at every run (the report has the wall time).
    pub(super) fn after_message(&mut self, driver: &Driver, emit: &mut impl FnMut(Outgoing)) {
        if !self.schedule.due(driver) {
            return;
        }
        let Some(start) = start_of(driver) else {
            return;
        };
        let wall = Instant::now();
        let f = self.forecaster.forecast(&start);
        self.wall += wall.elapsed();
        let time_s = (start.stamp_ns - self.t0_ns) as f64 * 1e-9;
        self.records.push(ForecastRecord::of(&f, time_s));
        emit(Outgoing::Forecast(Box::new(f.to_message(0.0))));
    }

    /// The score against the plant's observed onset (bag time, s) and its whip as the
    /// measured blocks of `comparisons` show it ([`observed_whip_s`]).
    pub(super) fn finish(
        self,
        observed_onset_s: Option<f64>,
        comparisons: &[StationComparison],
    ) -> ForecastScore {
        ForecastScore::new(
            self.records,
            self.forecaster.settings(),
            self.schedule.period_s(),
            (observed_onset_s, observed_whip_s(comparisons)),
            self.wall.as_secs_f64(),
        )
    }
}

/// The plant's whip as its probes show it: the start of the first 8-revolution block from
/// which the measured sub-synchronous semi-major axis stays at or above the monitor's whip
/// eccentricity (0.75) times the clearance over [`ONSET_BLOCKS`](super::compare::ONSET_BLOCKS) consecutive blocks, at any
/// station (bag time, s). The probes stand for the journals: a 0.5X whip is a near-rigid
/// conical or cylindrical whirl whose amplitude at the probes is of the journals' size (on the
/// sample bag 39.6 µm at both stations in a 40 µm clearance).
pub fn observed_whip_s(comparisons: &[StationComparison]) -> Option<f64> {
    comparisons
        .iter()
        .filter_map(StationComparison::observed_whip_start_s)
        .min_by(f64::total_cmp)
}
