//! The heat balance off the model thread (issue 18): a live twin's heat balance takes 0.1–3 ms
//! (Raimondi–Boyd) or 3–17 ms (the thermal film), up to several hundred of the node's steps at
//! 9,000 rpm; done on the model thread it stalls the outputs for that long at every balance. The
//! node therefore hands each balance to a worker thread that owns a copy of the machine
//! (the bearings, their lubricants, laws and static loads: nothing a calibration changes), and
//! takes the scales it finds at the next wake after it finishes. Between them the scales of the
//! last balance stay in force, as they do between two balances anyway.
//!
//! Balances requested while one is running are coalesced: only the latest is run next (a fast
//! run-up does not queue stale speeds). The offline runs and the replay balance on their own
//! thread ([`super::DriverSettings::heat_balance_off_thread`] off), so that the same inputs give
//! the same outputs.

use crate::dynamics::FilmEvaluation;
use crate::rotor::Rotor;
use std::sync::mpsc::{channel, Receiver, Sender, TryRecvError};

/// One balance to do: the oil supply temperature (K; None: each law's design one) and the speed
/// (rad/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct HeatJob {
    pub supply_k: Option<f64>,
    pub speed_rad_s: f64,
}

/// One heated film bearing after a balance.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct FilmHeat {
    /// Its index among the film bearings.
    pub film: usize,
    /// T_eff (K).
    pub temperature_k: f64,
    /// µ(T_eff) / µ_reference.
    pub scale: f64,
    /// The thermal film's viscosity field relative to µ(T_eff) (empty for Raimondi–Boyd's).
    pub field: Vec<f64>,
}

/// Each heated film bearing's temperature, scale and viscosity field for `job` on `rotor`
/// (whose heated bearings' scales and fields it sets), the isoviscous film evaluated as `film` says: the balance the
/// driver does, on its thread or on the worker's.
pub(super) fn balance(
    rotor: &mut Rotor,
    job: HeatJob,
    film: FilmEvaluation,
) -> Result<Vec<FilmHeat>, String> {
    let temps = rotor.heat_films_with(job.supply_k, job.speed_rad_s, 1.0, film)?;
    Ok(temps
        .into_iter()
        .map(|t| {
            let i = rotor.bearings[..t.bearing]
                .iter()
                .filter(|b| matches!(b.model, crate::rotor::BearingModel::Film(_)))
                .count();
            FilmHeat {
                film: i,
                temperature_k: t.effective.effective_temperature_k,
                scale: t.viscosity_scale,
                field: t.effective.viscosity_field,
            }
        })
        .collect())
}

/// The worker thread and the balance it runs, if any.
#[derive(Debug)]
pub(super) struct HeatWorker {
    jobs: Sender<HeatJob>,
    done: Receiver<Result<Vec<FilmHeat>, String>>,
    running: bool,
    next: Option<HeatJob>,
}

impl HeatWorker {
    /// A worker with its own copy of `rotor`, evaluating the isoviscous film as `film` says.
    /// Err when the thread cannot be started.
    pub fn start(rotor: &Rotor, film: FilmEvaluation) -> Result<Self, String> {
        let (jobs, job_rx) = channel::<HeatJob>();
        let (done_tx, done) = channel();
        let mut own = rotor.clone();
        std::thread::Builder::new()
            .name("heat-balance".into())
            .spawn(move || {
                // ends when the driver (the sender) is dropped, or stops reading
                for job in job_rx {
                    if done_tx.send(balance(&mut own, job, film)).is_err() {
                        break;
                    }
                }
            })
            .map_err(|e| format!("cannot start the heat-balance thread: {e}"))?;
        Ok(Self {
            jobs,
            done,
            running: false,
            next: None,
        })
    }

    /// Asks for `job`: run now if the worker is idle, else run after the current one (replacing
    /// any job already waiting). Err if the worker has gone.
    pub fn request(&mut self, job: HeatJob) -> Result<(), String> {
        if self.running {
            self.next = Some(job);
            return Ok(());
        }
        self.send(job)
    }

    fn send(&mut self, job: HeatJob) -> Result<(), String> {
        self.jobs
            .send(job)
            .map_err(|_| "the heat-balance thread has stopped".to_string())?;
        self.running = true;
        Ok(())
    }

    /// The result of the balance that finished since the last call, if one did (the waiting
    /// job, if any, is then started). Does not block.
    pub fn finished(&mut self) -> Option<Result<Vec<FilmHeat>, String>> {
        if !self.running {
            return None;
        }
        let result = match self.done.try_recv() {
            Ok(r) => r,
            Err(TryRecvError::Empty) => return None,
            Err(TryRecvError::Disconnected) => Err("the heat-balance thread has stopped".into()),
        };
        self.running = false;
        if let Some(job) = self.next.take() {
            if let Err(why) = self.send(job) {
                return Some(Err(why));
            }
        }
        Some(result)
    }

    /// Whether a balance is running or waiting.
    pub fn busy(&self) -> bool {
        self.running || self.next.is_some()
    }
}
