//! `rotor-twin bench wakes`: the node's model thread through a speed ramp, paced in real time,
//! with the machine's heat balances (`oil_heating`) on that thread and off it (issue 18,
//! `driver::heat_worker`). A [`Driver`] with the node's settings is fed a speed every 50 ms
//! ([`SPEED_PERIOD_NS`]) along the ramp and woken every 2 ms ([`WAKE_PERIOD_NS`]) as the node's
//! model thread is; each wake's wall time (the feed of any speed due, with the balance it may
//! start, and the steps up to the wake) is a sample. A balance done on the model thread shows
//! as the slowest wakes.

use super::node::{node_settings, SPEED_PERIOD_NS, WAKE_PERIOD_NS};
use crate::driver::{Driver, Input};
use crate::rotor::Rotor;
use crate::units::rpm_to_rad_s;
use serde::Serialize;
use std::time::{Duration, Instant};

/// Seconds run at the ramp's first speed before measuring (the first balance, the tables).
pub const SETTLE_S: f64 = 1.0;

/// The figures of one run.
#[derive(Debug, Serialize)]
pub struct WakeFigures {
    /// Where the heat balances ran: "model thread" or "worker thread".
    pub heat_balance: &'static str,
    /// Wakes measured.
    pub wakes: usize,
    /// Wall time of a wake (µs): median, 99th percentile and slowest.
    pub median_us: f64,
    pub p99_us: f64,
    pub max_us: f64,
    /// Wakes that took longer than the wake period (the model thread late for the next).
    pub late_wakes: usize,
    /// Heat balances done over the run (settling included), and those that failed.
    pub balances: u64,
    pub failures: u64,
    /// Why the last failed balance failed (None without one).
    pub last_failure: Option<String>,
}

/// The ramp: from `from_rpm` at `rpm_per_s` for `seconds` (after [`SETTLE_S`] at `from_rpm`).
#[derive(Debug, Clone, Copy)]
pub struct Ramp {
    pub from_rpm: f64,
    pub rpm_per_s: f64,
    pub seconds: f64,
}

/// The shortest ramp measured (s): five wakes.
pub const MIN_SECONDS: f64 = 5.0 * WAKE_PERIOD_NS as f64 * 1e-9;

/// Err naming the option and the value when `ramp` cannot run on `rotor`: too short, a rate
/// that is not a positive finite number, or an end past the machine's top speed.
pub fn check(rotor: &Rotor, ramp: Ramp) -> anyhow::Result<()> {
    anyhow::ensure!(
        ramp.seconds >= MIN_SECONDS,
        "--seconds {}: bench wakes measures at least {MIN_SECONDS} s (five wakes of 2 ms)",
        ramp.seconds
    );
    anyhow::ensure!(
        ramp.rpm_per_s.is_finite() && ramp.rpm_per_s > 0.0,
        "--ramp-rpm-s {}: the ramp's rate must be a positive number of rpm/s",
        ramp.rpm_per_s
    );
    let top_rpm = crate::units::rad_s_to_rpm(crate::driver::InputLimits::of(rotor).max_speed_rad_s);
    let end_rpm = ramp.from_rpm + ramp.rpm_per_s * ramp.seconds;
    anyhow::ensure!(
        end_rpm <= top_rpm,
        "--ramp-rpm-s {} for --seconds {} ends at {end_rpm:.0} rpm, past the machine's top speed \
         {top_rpm:.0} rpm (the node refuses faster speeds)",
        ramp.rpm_per_s,
        ramp.seconds
    );
    Ok(())
}

/// Runs `ramp` on a twin of `rotor` with the balances off the model thread or on it.
pub fn run(rotor: &Rotor, ramp: Ramp, off_thread: bool) -> anyhow::Result<WakeFigures> {
    let mut settings = node_settings(rotor);
    settings.heat_balance_off_thread = off_thread;
    let mut driver = Driver::new(rotor.clone(), settings);
    let total_s = SETTLE_S + ramp.seconds;
    let wakes = (total_s * 1e9 / WAKE_PERIOD_NS as f64).round() as usize;
    let settle = (SETTLE_S * 1e9 / WAKE_PERIOD_NS as f64).round() as usize;
    let mut samples = Vec::with_capacity(wakes);
    let (t0, start) = (1_767_225_600_000_000_000_i64, Instant::now());
    let mut next_speed_ns = 0;
    for k in 0..wakes {
        let since_ns = k as i64 * WAKE_PERIOD_NS;
        let due = start + Duration::from_nanos(since_ns as u64);
        std::thread::sleep(due.saturating_duration_since(Instant::now()));
        let woke = Instant::now();
        if since_ns >= next_speed_ns {
            let ramp_s = (since_ns as f64 * 1e-9 - SETTLE_S).max(0.0);
            let input = Input::Speed {
                speed_rad_s: rpm_to_rad_s(ramp.from_rpm + ramp.rpm_per_s * ramp_s),
                accel_rad_s2: rpm_to_rad_s(ramp.rpm_per_s) * f64::from(ramp_s > 0.0),
                stamp_ns: t0 + since_ns,
            };
            driver.feed(t0 + since_ns, input, &mut |_| {});
            next_speed_ns += SPEED_PERIOD_NS;
        }
        driver.advance_to(t0 + since_ns, usize::MAX, &mut |_| {});
        if k >= settle {
            samples.push(woke.elapsed().as_secs_f64() * 1e6);
        }
    }
    anyhow::ensure!(driver.session().is_some(), "the twin did not run");
    anyhow::ensure!(!samples.is_empty(), "no wake measured");
    samples.sort_by(f64::total_cmp);
    let at = |q: f64| samples[((samples.len() - 1) as f64 * q).round() as usize];
    let period_us = WAKE_PERIOD_NS as f64 * 1e-3;
    Ok(WakeFigures {
        heat_balance: if off_thread {
            "worker thread"
        } else {
            "model thread"
        },
        wakes: samples.len(),
        median_us: at(0.5),
        p99_us: at(0.99),
        max_us: at(1.0),
        late_wakes: samples.iter().filter(|&&s| s > period_us).count(),
        balances: driver.heat_balances().0,
        failures: driver.heat_balance_failures(),
        last_failure: driver.heat_balance_report().and_then(|r| r.last_failure),
    })
}
