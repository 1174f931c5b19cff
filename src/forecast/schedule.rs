//! When a forecast is due: the first at each start of the twin, then every period of the
//! driver's time (model time: bag time in a replay, the node's clock live). One home for the
//! rule, for the node's forecast thread and the replay.

use super::ForecastStart;
use crate::driver::Driver;

/// The forecast period and the next time one is due.
#[derive(Debug, Clone)]
pub struct Schedule {
    period_ns: i64,
    next_ns: Option<i64>,
    starts: u64,
}

impl Schedule {
    /// Every `period_s` seconds (> 0).
    pub fn new(period_s: f64) -> Self {
        Self {
            period_ns: ((period_s * 1e9).round() as i64).max(1),
            next_ns: None,
            starts: 0,
        }
    }

    /// True if a forecast is due at the driver's present state (a twin runs and the period has
    /// come, or the twin has just (re)started); the next is then one period on. Due times that
    /// passed while the caller was busy are skipped, not caught up.
    pub fn due(&mut self, driver: &Driver) -> bool {
        let (Some(session), Some(_)) = (driver.session(), driver.speed_input()) else {
            return false;
        };
        let now = session.stamp_ns();
        if driver.counts().starts != self.starts {
            self.starts = driver.counts().starts;
            self.next_ns = Some(now);
        }
        let next = self.next_ns.get_or_insert(now);
        if now < *next {
            return false;
        }
        while *next <= now {
            *next += self.period_ns;
        }
        true
    }

    /// The period (s).
    pub fn period_s(&self) -> f64 {
        self.period_ns as f64 * 1e-9
    }
}

/// The forecast's start from the driver's running twin: its checkpoint (allocates: a copy of
/// the state and the films), the speed and acceleration in force, the linear threshold.
pub fn start_of(driver: &Driver) -> Option<ForecastStart> {
    let session = driver.session()?;
    let (w, a) = driver.speed_input()?;
    Some(ForecastStart::of(session, w, a, driver.linear_threshold()))
}
