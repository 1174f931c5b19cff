//! Calibration of the twin from what the plant measures (issue 12), I/O-free: the residual
//! unbalance from measured 1X vectors by the twin's own influence coefficients, and the oil's
//! effective viscosity (or temperature offset) from the measured mean journal positions by the
//! film's static equilibrium.
//!
//! **The 1X-vector convention** ([`OneXVector`]). The synchronous component of the displacement
//! of a probe station along a machine axis a (x or y) is
//!   a(t) = A cos(θ(t) − λ),
//! θ the shaft angle measured from the shaft's reference mark in the direction of rotation, A the
//! amplitude (m, zero to peak) and λ the **phase lag** (deg, 0–360): the rotation from the
//! reference mark's passing (θ = 0) to the next positive peak, as API 670 / Bently read it from
//! a keyphasor. In complex form a(t) = Re(X e^{iθ}), X = A e^{−iλ}: the convention of the
//! linear unbalance response (`rotor::unbalance_response`), so the measured X is compared with
//! the model's directly. Whoever provides θ decides the reference: today the twin's own shaft
//! angle (which is the synthetic plant's, both starting at 0), a keyphasor once one is wired in.
//!
//! Each estimate states its residual and its conditioning; the unbalance estimate also gives the
//! correction masses that would balance it.

mod linalg;
mod one_x;
mod unbalance;
mod viscosity;

pub use one_x::{fit_windows, AngleSample, WindowFit, WindowFits, MAX_WINDOW_SAMPLES};
pub use unbalance::{
    estimate_unbalance, CorrectionMass, PlaneEstimate, UnbalanceEstimate,
    DEFAULT_CORRECTION_RADIUS_M,
};
pub use viscosity::{estimate_viscosity, static_probe_positions, ViscosityEstimate};

use serde::Serialize;
use thiserror::Error;

/// A 1X vector of one probe station along one machine axis at one speed (module documentation
/// for the convention).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OneXVector {
    /// Probe station (index in the machine's `probes`).
    pub station: usize,
    /// Machine axis: 0 = x, 1 = y.
    pub axis: usize,
    /// Shaft speed (rad/s).
    pub speed_rad_s: f64,
    /// Amplitude A, zero to peak (m).
    pub amplitude_m: f64,
    /// Phase lag λ behind the shaft reference mark (deg, 0–360): a(t) = A cos(θ − λ).
    pub phase_lag_deg: f64,
}

impl OneXVector {
    /// The vector from its complex amplitude X (a = Re(X e^{iθ})).
    pub fn from_complex(station: usize, axis: usize, speed_rad_s: f64, x: [f64; 2]) -> Self {
        Self {
            station,
            axis,
            speed_rad_s,
            amplitude_m: x[0].hypot(x[1]),
            phase_lag_deg: (-x[1].atan2(x[0])).to_degrees().rem_euclid(360.0),
        }
    }

    /// Its complex amplitude X = A e^{−iλ} as [re, im] (m).
    pub fn complex(&self) -> [f64; 2] {
        let l = self.phase_lag_deg.to_radians();
        [self.amplitude_m * l.cos(), -self.amplitude_m * l.sin()]
    }
}

/// A measured mean journal position (DC-coupled probes: the shaft centreline) at a probe
/// station, in the machine frame relative to the bearing centre's axis, at one speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeanPosition {
    /// Probe station (index in the machine's `probes`).
    pub station: usize,
    /// Shaft speed (rad/s).
    pub speed_rad_s: f64,
    /// Mean displacement `[x, y]` (m).
    pub position_m: [f64; 2],
}

/// Why a calibration cannot be made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CalibrationError {
    /// Not enough (or no usable) measurements.
    #[error("not enough measurements: {0}")]
    TooFewMeasurements(String),
    /// A measurement is not finite or names a station or axis the machine lacks.
    #[error("bad measurement: {0}")]
    BadMeasurement(String),
    /// The machine has nothing to calibrate (no unbalance plane, no film bearing).
    #[error("nothing to calibrate: {0}")]
    NothingToCalibrate(String),
    /// The model could not be evaluated.
    #[error("model: {0}")]
    Model(String),
    /// The least-squares problem is singular (the planes cannot be told apart from these
    /// measurements).
    #[error("singular problem: {0}")]
    Singular(String),
}
