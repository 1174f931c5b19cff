//! The node's live calibration (issue 12): the fit of [`crate::driver::calibration`] on its own
//! thread (an influence-coefficient solve and a few static equilibria per speed: far more than a
//! time step), every `calibration_period_s` of the node's clock, its estimate published on
//! `/rotor_twin/calibration` and, while `calibration_apply` is true, applied to the running
//! twin (logged; false takes it back). And the linear stability threshold recomputed when the
//! viscosity in force (oil temperature or calibration) has moved by more than
//! [`THRESHOLD_RESCALE`].

use crate::calibrate::NonlinearRefinement;
use crate::driver::{LiveEstimate, MeasuredSet};
use crate::rotor::Rotor;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, SyncSender};
use std::sync::{Arc, Mutex};

/// Relative change of the viscosity in force after which the linear stability threshold is
/// recomputed: 0.5 %, the project's convergence bar (the threshold moves by less than the
/// viscosity: the seed's ∂ln ω_th/∂ln µ is below 1).
pub const THRESHOLD_RESCALE: f64 = 0.005;

/// What the fitting thread is asked: the machine, the measurements, the nonlinear refinement.
type Request = (Rotor, MeasuredSet, Option<NonlinearRefinement>);

/// The fitting thread: one request at a time; a request while it is busy is not made.
pub struct CalibrationWorker {
    tx: SyncSender<Request>,
    busy: Arc<AtomicBool>,
    done: Arc<Mutex<Option<LiveEstimate>>>,
}

impl CalibrationWorker {
    /// Starts the thread.
    pub fn spawn() -> std::io::Result<Self> {
        let (tx, rx) = mpsc::sync_channel::<Request>(1);
        let busy = Arc::new(AtomicBool::new(false));
        let done = Arc::new(Mutex::new(None));
        let (b, d) = (busy.clone(), done.clone());
        std::thread::Builder::new()
            .name("rotor_twin calibration".into())
            .spawn(move || {
                for (rotor, measured, refine) in rx {
                    let e = crate::driver::calibration::estimate(&rotor, &measured, refine);
                    *d.lock().unwrap_or_else(|e| e.into_inner()) = Some(e);
                    b.store(false, Ordering::Release);
                }
            })?;
        Ok(Self { tx, busy, done })
    }

    /// Asks for a fit of `measured` on `rotor` (refined as `refine` says) unless one is
    /// running; true if asked.
    pub fn request(
        &self,
        rotor: &Rotor,
        measured: MeasuredSet,
        refine: Option<NonlinearRefinement>,
    ) -> bool {
        if self.busy.swap(true, Ordering::AcqRel) {
            return false;
        }
        if self.tx.try_send((rotor.clone(), measured, refine)).is_err() {
            self.busy.store(false, Ordering::Release);
            return false;
        }
        true
    }

    /// The last finished fit, once.
    pub fn take(&self) -> Option<LiveEstimate> {
        self.done.lock().unwrap_or_else(|e| e.into_inner()).take()
    }
}
