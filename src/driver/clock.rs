//! Following `/clock` (use_sim_time) without being thrown by one bad sample (issue 15, item 10).
//!
//! The node's clock under use_sim_time is the latest `/clock` time. Taken as it came, one sample
//! stamped an hour ahead would move the clock there, every later (correct) sample would be
//! "backwards" and the node would stay an hour ahead until restarted. Here a sample is taken when
//! it moves the clock forward by at most [`CLOCK_JUMP_S`]; any other sample (a larger step
//! ahead, or a step back) is refused, counted, and held as the start of a possible new timeline:
//! when [`CLOCK_CONFIRM`] samples in a row agree with each other (each at most [`CLOCK_JUMP_S`]
//! after the one before) but not with the clock, the clock jumps to them — a simulator reset or
//! a bag played again in a loop is followed after those samples, and a clock that was itself
//! started by a bad sample recovers the same way.

/// Largest forward step of `/clock` taken as it comes (s of simulated time). A simulator or
/// `ros2 bag play --clock` publishes `/clock` at 40 Hz or more; a step of 10 s would be a
/// simulation 400 times faster than real time.
pub const CLOCK_JUMP_S: f64 = 10.0;

/// Consecutive samples that agree with each other, and not with the clock, that make the clock
/// jump to them (1/8 s of a `/clock` at 40 Hz).
pub const CLOCK_CONFIRM: u32 = 5;

/// What became of one `/clock` sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClockSample {
    /// The clock moved to it (or stayed: a repeated time).
    Taken,
    /// Refused: too far from the clock; the clock stays.
    Refused {
        /// The clock when it was refused (ns).
        clock_ns: i64,
    },
    /// The last of [`CLOCK_CONFIRM`] samples that agree: the clock jumped to it.
    Jumped {
        /// The clock before the jump (ns).
        from_ns: i64,
    },
}

/// The simulation clock, fed every `/clock` sample in arrival order.
#[derive(Debug, Default, Clone)]
pub struct SimClock {
    now_ns: Option<i64>,
    /// The newest refused sample and how many refused samples in a row agree up to it.
    candidate: Option<(i64, u32)>,
    refused: u64,
}

impl SimClock {
    /// The clock (ns), None before the first sample.
    pub fn now_ns(&self) -> Option<i64> {
        self.now_ns
    }

    /// Samples refused so far.
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// Offers one `/clock` sample (ns).
    pub fn offer(&mut self, ns: i64) -> ClockSample {
        let jump = super::seconds_to_ns(CLOCK_JUMP_S);
        let follows = |from: i64| ns >= from && ns - from <= jump;
        let Some(now) = self.now_ns else {
            self.now_ns = Some(ns);
            return ClockSample::Taken;
        };
        if follows(now) {
            self.now_ns = Some(ns);
            self.candidate = None;
            return ClockSample::Taken;
        }
        let agreeing = match self.candidate {
            Some((last, n)) if follows(last) => n + 1,
            _ => 1,
        };
        if agreeing >= CLOCK_CONFIRM {
            self.now_ns = Some(ns);
            self.candidate = None;
            return ClockSample::Jumped { from_ns: now };
        }
        self.candidate = Some((ns, agreeing));
        self.refused += 1;
        ClockSample::Refused { clock_ns: now }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: i64 = 1_000_000_000;
    const HOUR: i64 = 3600 * S;

    /// /clock at 100 Hz from 1,000 s.
    fn tick(k: i64) -> i64 {
        1000 * S + k * S / 100
    }

    #[test]
    fn one_sample_an_hour_ahead_is_refused_and_the_clock_goes_on() {
        let mut c = SimClock::default();
        for k in 0..10 {
            assert_eq!(c.offer(tick(k)), ClockSample::Taken);
        }
        assert_eq!(
            c.offer(tick(10) + HOUR),
            ClockSample::Refused { clock_ns: tick(9) }
        );
        for k in 11..100 {
            assert_eq!(c.offer(tick(k)), ClockSample::Taken, "sample {k}");
        }
        assert_eq!(c.now_ns(), Some(tick(99)));
        assert_eq!(c.refused(), 1);
    }

    #[test]
    fn a_clock_started_by_a_bad_sample_recovers() {
        let mut c = SimClock::default();
        assert_eq!(c.offer(tick(0) + HOUR), ClockSample::Taken);
        for k in 1..CLOCK_CONFIRM as i64 {
            assert!(matches!(c.offer(tick(k)), ClockSample::Refused { .. }));
        }
        assert_eq!(
            c.offer(tick(CLOCK_CONFIRM as i64)),
            ClockSample::Jumped {
                from_ns: tick(0) + HOUR
            }
        );
        assert_eq!(c.offer(tick(6)), ClockSample::Taken);
        assert_eq!(c.now_ns(), Some(tick(6)));
        assert_eq!(c.refused(), u64::from(CLOCK_CONFIRM) - 1);
    }

    #[test]
    fn a_reset_is_followed_after_agreeing_samples_and_scattered_ones_never() {
        let mut c = SimClock::default();
        c.offer(tick(500));
        // a bag played again from its start: back to 1,000 s
        for k in 0..CLOCK_CONFIRM as i64 - 1 {
            assert!(matches!(c.offer(tick(k)), ClockSample::Refused { .. }));
        }
        assert!(matches!(
            c.offer(tick(CLOCK_CONFIRM as i64 - 1)),
            ClockSample::Jumped { .. }
        ));
        // samples scattered an hour apart never agree: every one refused, the clock stays
        let at = c.now_ns();
        for k in 1..20 {
            assert!(matches!(
                c.offer(tick(0) + (k % 2) * 2 * HOUR - HOUR),
                ClockSample::Refused { .. }
            ));
        }
        assert_eq!(c.now_ns(), at);
    }
}
