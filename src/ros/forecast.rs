//! The node's forecast thread (issue 14): the model thread hands it a checkpoint of the twin
//! every `forecast_period_s` of model time, and it runs the forecast ([`crate::forecast`]) on a
//! twin of its own at a lower scheduling priority (nice +10 on Linux), yielding every 1,024
//! steps, and publishes a `Forecast`. The model thread never waits for it: a checkpoint due
//! while the last forecast still runs is skipped and counted, and the diagnostics report the
//! forecast's duration and the skipped cycles beside the model loop's lag.

use super::model::Outgoing;
use crate::driver::Driver;
use crate::dynamics::TwinConfig;
use crate::forecast::schedule::{start_of, Schedule};
use crate::forecast::{ForecastSettings, ForecastStart, Forecaster};
use crate::rotor::Rotor;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, SyncSender};
use std::sync::Arc;
use std::time::Instant;

/// How much nicer than the node the forecast thread runs (Linux nice levels; 19 the lowest).
pub const FORECAST_NICE: i32 = 10;

/// What the forecast thread counted (shared with the model thread's diagnostics).
#[derive(Debug, Default)]
pub struct ForecastStats {
    /// A forecast is running.
    pub busy: AtomicBool,
    /// Forecasts published.
    pub completed: AtomicU64,
    /// Due checkpoints skipped because the last forecast was still running.
    pub skipped: AtomicU64,
    /// `skipped` at the last diagnostics (the status warns of skips in its interval).
    pub skipped_reported: AtomicU64,
    /// Wall time of the last forecast (µs).
    pub last_duration_us: AtomicU64,
    /// Longest wall time of a forecast (µs).
    pub worst_duration_us: AtomicU64,
    /// Wall time of the model thread's last checkpoint (µs).
    pub checkpoint_us: AtomicU64,
    /// Forecasts the outgoing queue could not take.
    pub dropped: AtomicU64,
    /// Whether the thread could lower its priority (false: it runs at the model's).
    pub niced: AtomicBool,
    /// Why the forecaster could not be built (the thread then ends), if it could not.
    pub failed: AtomicBool,
}

/// The model thread's side: the schedule and the hand-over to the forecast thread.
pub struct ForecastLink {
    schedule: Schedule,
    tx: SyncSender<ForecastStart>,
    /// The counts, for the diagnostics.
    pub stats: Arc<ForecastStats>,
}

impl ForecastLink {
    /// Starts the forecast thread for twins of `rotor` (`config`: the live twin's),
    /// every `period_s` of model time; its messages go to `out`.
    pub fn spawn(
        rotor: &Rotor,
        config: TwinConfig,
        settings: ForecastSettings,
        period_s: f64,
        out: SyncSender<super::model::Published>,
    ) -> std::io::Result<Self> {
        let (tx, rx) = mpsc::sync_channel::<ForecastStart>(1);
        let stats = Arc::new(ForecastStats::default());
        let (rotor, thread_stats) = (rotor.clone(), stats.clone());
        std::thread::Builder::new()
            .name("rotor_twin forecast".into())
            .spawn(move || {
                thread_stats
                    .niced
                    .store(lower_priority(), Ordering::Relaxed);
                let mut forecaster = match Forecaster::new(&rotor, config, settings) {
                    Ok(f) => f,
                    Err(e) => {
                        super::log::error(&format!("the forecast cannot run: {e}"));
                        thread_stats.failed.store(true, Ordering::Relaxed);
                        return;
                    }
                };
                for start in rx {
                    let t = Instant::now();
                    let f = forecaster.forecast(&start);
                    let took = t.elapsed();
                    let us = took.as_micros() as u64;
                    thread_stats.last_duration_us.store(us, Ordering::Relaxed);
                    thread_stats
                        .worst_duration_us
                        .fetch_max(us, Ordering::Relaxed);
                    if out
                        .try_send(super::model::Published::Twin(Outgoing::Forecast(Box::new(
                            f.to_message(took.as_secs_f64()),
                        ))))
                        .is_err()
                    {
                        thread_stats.dropped.fetch_add(1, Ordering::Relaxed);
                    }
                    thread_stats.completed.fetch_add(1, Ordering::Relaxed);
                    thread_stats.busy.store(false, Ordering::Release);
                }
            })?;
        Ok(Self {
            schedule: Schedule::new(period_s),
            tx,
            stats,
        })
    }

    /// After a wake of the model thread: when a forecast is due, a checkpoint for the forecast
    /// thread, or, while it is busy, a skipped cycle (counted). Never waits.
    pub fn after_wake(&mut self, driver: &Driver) {
        if !self.schedule.due(driver) {
            return;
        }
        if self.stats.failed.load(Ordering::Relaxed) || self.stats.busy.load(Ordering::Acquire) {
            self.stats.skipped.fetch_add(1, Ordering::Relaxed);
            return;
        }
        let t = Instant::now();
        let Some(start) = start_of(driver) else {
            return;
        };
        self.stats
            .checkpoint_us
            .store(t.elapsed().as_micros() as u64, Ordering::Relaxed);
        self.stats.busy.store(true, Ordering::Release);
        if self.tx.try_send(start).is_err() {
            self.stats.busy.store(false, Ordering::Release);
            self.stats.skipped.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// Lowers the calling thread's scheduling priority by [`FORECAST_NICE`] below the process's
/// (nice capped at 19) with `renice` on its thread id (no unsafe system call); false where
/// that is not possible.
fn lower_priority() -> bool {
    let Ok(link) = std::fs::read_link("/proc/thread-self") else {
        return false;
    };
    let Some(tid) = link.file_name().map(|t| t.to_string_lossy().to_string()) else {
        return false;
    };
    // field 19 of /proc/<tid>/stat is the nice value (after the parenthesised name)
    let nice = std::fs::read_to_string("/proc/thread-self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1.to_string();
            rest.split_whitespace().nth(16)?.parse::<i32>().ok()
        })
        .unwrap_or(0);
    std::process::Command::new("renice")
        .args([
            "-n",
            &(nice + FORECAST_NICE).min(19).to_string(),
            "-p",
            &tid,
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}
