//! Scoring forecasts against what the plant did: how long before the plant's observed onset the
//! forecast first announced it (lead time), and how often it announced an onset that did not
//! come within its horizon (false announcements). I/O-free; the replay fills it at bag time.

use super::Forecast;
use crate::units::rad_s_to_rpm;
use serde::Serialize;

/// One forecast as the report lists it (bag time).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForecastRecord {
    /// Bag time of the checkpoint (s).
    pub time_s: f64,
    /// Speed there (rpm).
    pub speed_rpm: f64,
    /// Acceleration there (rpm/s).
    pub accel_rpm_s: f64,
    /// Expected state at the end of the expected path (none, growing, whirl, whip).
    pub expected_state: String,
    /// Time to a persisting whirl or whip on the expected path (s from the checkpoint).
    pub onset_in_s: Option<f64>,
    /// Time to a persisting whip on the expected path (s).
    pub whip_in_s: Option<f64>,
    /// Largest orbit amplitude on the expected path (m).
    pub amplitude_m: f64,
    /// Nonlinear threshold (rpm): the lowest probed speed going into whip within the horizon.
    pub nonlinear_threshold_rpm: Option<f64>,
    /// Width of its bracket (rpm).
    pub nonlinear_threshold_resolution_rpm: Option<f64>,
    /// The linear threshold beside it (rpm).
    pub linear_threshold_rpm: Option<f64>,
    /// Twin steps the forecast took (all runs).
    pub steps: u64,
}

impl ForecastRecord {
    /// The record of `f`, its checkpoint at bag time `time_s`.
    pub fn of(f: &Forecast, time_s: f64) -> Self {
        Self {
            time_s,
            speed_rpm: rad_s_to_rpm(f.speed_rad_s),
            accel_rpm_s: rad_s_to_rpm(f.accel_rad_s2),
            expected_state: f.expected.state.warning_kind().into(),
            onset_in_s: f.expected.onset_after_s,
            whip_in_s: f.expected.whip_after_s,
            amplitude_m: f.expected.amplitude_m,
            nonlinear_threshold_rpm: f.nonlinear_threshold.map(|t| rad_s_to_rpm(t.0)),
            nonlinear_threshold_resolution_rpm: f.nonlinear_threshold.map(|t| rad_s_to_rpm(t.1)),
            linear_threshold_rpm: f.linear_threshold.map(|t| rad_s_to_rpm(t.0)),
            steps: f.steps,
        }
    }
}

/// How announcements of one kind (onset, or whip) fared against the plant's observed onset.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AnnouncementScore {
    /// Forecasts that announced it (within their horizon).
    pub announcements: usize,
    /// Bag time of the first announcement that came true: the observed onset fell within its
    /// horizon (s).
    pub first_true_s: Option<f64>,
    /// Observed onset minus that announcement's checkpoint time (s): how long before it happened
    /// the forecast announced it.
    pub lead_time_s: Option<f64>,
    /// The time it announced (checkpoint + predicted time) minus the observed onset (s).
    pub predicted_minus_observed_s: Option<f64>,
    /// Announcements before the observed onset whose horizon ended before it (or with no
    /// observed onset at all): announced onsets that did not come.
    pub false_announcements: usize,
    /// Bag times of those (s).
    pub false_times_s: Vec<f64>,
    /// Forecasts before the onset whose horizon covered it that did not announce it.
    pub missed: usize,
    /// Announcements at or after the observed onset (the instability is there: neither lead nor
    /// false).
    pub after_onset: usize,
}

/// The forecast's score in a replay.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForecastScore {
    /// Forecast period (s of bag time).
    pub period_s: f64,
    /// Horizon (s).
    pub horizon_s: f64,
    /// Speeds probed above the present one (rpm).
    pub offsets_rpm: Vec<f64>,
    /// Bisection resolution (rpm).
    pub margin_resolution_rpm: f64,
    /// The plant's observed onset the onset announcements are scored against (the replay's
    /// onset detector on the measured orbits; bag time, s).
    pub observed_onset_s: Option<f64>,
    /// The plant's observed whip the whip announcements are scored against (bag time, s; see
    /// `replay::observed_whip_s`).
    pub observed_whip_s: Option<f64>,
    /// Announcements of a persisting whirl or whip on the expected path, against the observed
    /// onset.
    pub onset: AnnouncementScore,
    /// Announcements of a persisting whip on the expected path, against the observed whip.
    pub whip: AnnouncementScore,
    /// Every forecast.
    pub forecasts: Vec<ForecastRecord>,
    /// Wall time spent forecasting (s).
    pub wall_time_s: f64,
}

impl ForecastScore {
    /// Scores `forecasts` against the observed (onset, whip) times (bag time, s).
    pub fn new(
        forecasts: Vec<ForecastRecord>,
        settings: &super::ForecastSettings,
        period_s: f64,
        (observed_onset_s, observed_whip_s): (Option<f64>, Option<f64>),
        wall_time_s: f64,
    ) -> Self {
        let h = settings.horizon_s;
        Self {
            period_s,
            horizon_s: h,
            offsets_rpm: settings.offsets_rpm.clone(),
            margin_resolution_rpm: settings.margin_resolution_rpm,
            observed_onset_s,
            observed_whip_s,
            onset: score(&forecasts, h, observed_onset_s, |f| f.onset_in_s),
            whip: score(&forecasts, h, observed_whip_s, |f| f.whip_in_s),
            forecasts,
            wall_time_s,
        }
    }

    /// Lines for the replay's summary.
    pub fn summary(&self) -> String {
        let line = |what: &str, a: &AnnouncementScore| {
            let lead = match (a.first_true_s, a.lead_time_s) {
                (Some(t), Some(l)) => format!("first at {t:.2} s, {l:.2} s before it"),
                _ => "never before it".into(),
            };
            format!(
                "  {what}: {} announcement(s), {lead}; {} false, {} missed\n",
                a.announcements, a.false_announcements, a.missed
            )
        };
        let at = |t: Option<f64>| t.map_or("none".to_string(), |t| format!("{t:.2} s"));
        let observed = format!(
            "observed onset {}, whip {}",
            at(self.observed_onset_s),
            at(self.observed_whip_s)
        );
        format!(
            "forecast: {} look-aheads of {:.1} s every {:.2} s ({:.1} s of wall time); {observed}\n{}{}",
            self.forecasts.len(),
            self.horizon_s,
            self.period_s,
            self.wall_time_s,
            line("onset (whirl or whip) before the observed onset", &self.onset),
            line("whip before the observed whip", &self.whip),
        )
    }
}

/// Scores the announcements `announced` gives (time from the checkpoint) against `observed`.
fn score(
    forecasts: &[ForecastRecord],
    horizon_s: f64,
    observed: Option<f64>,
    announced: impl Fn(&ForecastRecord) -> Option<f64>,
) -> AnnouncementScore {
    let mut s = AnnouncementScore::default();
    for f in forecasts {
        let covers = observed.is_some_and(|o| f.time_s < o && o <= f.time_s + horizon_s);
        let after = observed.is_some_and(|o| f.time_s >= o);
        match announced(f) {
            Some(_) if after => s.after_onset += 1,
            Some(dt) => {
                s.announcements += 1;
                if covers {
                    if s.first_true_s.is_none() {
                        s.first_true_s = Some(f.time_s);
                        s.lead_time_s = observed.map(|o| o - f.time_s);
                        s.predicted_minus_observed_s = observed.map(|o| f.time_s + dt - o);
                    }
                } else {
                    s.false_announcements += 1;
                    s.false_times_s.push(f.time_s);
                }
            }
            None if covers => s.missed += 1,
            None => {}
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(time_s: f64, onset_in_s: Option<f64>) -> ForecastRecord {
        ForecastRecord {
            time_s,
            speed_rpm: 8000.0,
            accel_rpm_s: 0.0,
            expected_state: "none".into(),
            onset_in_s,
            whip_in_s: None,
            amplitude_m: 0.0,
            nonlinear_threshold_rpm: None,
            nonlinear_threshold_resolution_rpm: None,
            linear_threshold_rpm: None,
            steps: 0,
        }
    }

    /// Onset observed at 5 s, horizon 3 s: an announcement at 1 s is false (its horizon ends at
    /// 4 s), one at 2.5 s is the first true one (lead 2.5 s, announced for 2.5 + 2 = 4.5 s:
    /// 0.5 s early), a silent forecast at 3 s is a miss, announcements from 5 s are after it.
    #[test]
    fn lead_false_and_missed_by_hand() {
        let f = vec![
            rec(0.0, None),
            rec(1.0, Some(2.0)),
            rec(2.5, Some(2.0)),
            rec(3.0, None),
            rec(4.0, Some(0.5)),
            rec(5.0, Some(0.1)),
        ];
        let s = score(&f, 3.0, Some(5.0), |r| r.onset_in_s);
        assert_eq!(s.announcements, 3);
        assert_eq!(s.false_announcements, 1);
        assert_eq!(s.false_times_s, vec![1.0]);
        assert_eq!(s.first_true_s, Some(2.5));
        assert_eq!(s.lead_time_s, Some(2.5));
        assert_eq!(s.predicted_minus_observed_s, Some(-0.5));
        assert_eq!(s.missed, 1);
        assert_eq!(s.after_onset, 1);
        // no observed onset: every announcement is false
        let s = score(&f, 3.0, None, |r| r.onset_in_s);
        assert_eq!(s.false_announcements, 4);
        assert_eq!(s.lead_time_s, None);
    }
}
