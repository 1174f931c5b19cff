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
mod nonlinear;
mod one_x;
mod unbalance;
mod viscosity;

pub use nonlinear::{
    nonlinear_one_x, refine_unbalance, NonlinearRefinement, MAX_REFINEMENTS, MEASURED_REVOLUTIONS,
    REFINEMENT_TOLERANCE, SETTLE_REVOLUTIONS,
};
pub use one_x::{fit_windows, AngleSample, WindowFit, WindowFits, MAX_WINDOW_SAMPLES};
pub use unbalance::{
    estimate_unbalance, CorrectionMass, PlaneEstimate, UnbalanceEstimate,
    DEFAULT_CORRECTION_RADIUS_M,
};
pub use viscosity::{
    estimate_viscosity, estimate_viscosity_under_orbits, static_probe_positions, JournalOrbits,
    ViscosityEstimate, ORBIT_POINTS, VISCOSITY_MODEL_FLOOR,
};

use serde::Serialize;
use thiserror::Error;

/// A fit window (or a trial run) whose mean and 1X leave more than this share of its 1X
/// semi-major axis, RMS (non-synchronous motion: a whirl), is not used.
pub const MAX_WINDOW_RESIDUAL_SHARE: f64 = 0.3;

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

/// The journals' 1X orbits of `rotor`'s linear model (at its viscosity) under the estimated
/// `unbalance`, at each speed of `speeds_rad_s` (the viscosity fit's orbits,
/// [`estimate_viscosity_under_orbits`]).
pub fn journal_orbits(
    rotor: &crate::rotor::Rotor,
    unbalance: &UnbalanceEstimate,
    speeds_rad_s: &[f64],
) -> Result<Vec<JournalOrbits>, CalibrationError> {
    let model = |e: crate::rotor::RotorError| CalibrationError::Model(e.to_string());
    let statics = crate::rotor::static_solution(rotor).map_err(model)?;
    let planes: Vec<crate::rotor::Unbalance> = rotor
        .unbalance
        .iter()
        .zip(&unbalance.planes)
        .map(|(u, p)| crate::rotor::Unbalance {
            magnitude_kg_m: p.magnitude_g_mm * 1e-6,
            phase_rad: p.phase_deg.to_radians(),
            ..*u
        })
        .collect();
    speeds_rad_s
        .iter()
        .map(|&w| {
            let rpm = crate::units::rad_s_to_rpm(w);
            let journals =
                crate::rotor::journal_orbits(rotor, &statics, rpm, &planes).map_err(model)?;
            Ok(JournalOrbits {
                speed_rad_s: w,
                journals,
            })
        })
        .collect()
}

/// The viscosity scale (from `means`) and the unbalance at it (from `vectors`), as the live
/// calibration fits them: the static fit of [`estimate_viscosity`] and the unbalance at it, then
/// the viscosity again with the mean positions under the journal orbits that unbalance gives
/// ([`journal_orbits`], [`estimate_viscosity_under_orbits`]) and the unbalance at that. Without
/// an unbalance (no 1X vector) the static fit stands. `rotor` at the machine file's viscosity.
/// With `refine`, the last unbalance is refined on the nonlinear twin ([`refine_unbalance`]);
/// where that cannot be done the linear fit stands, saying why (`not_refined`).
pub fn estimate_viscosity_and_unbalance(
    rotor: &crate::rotor::Rotor,
    means: &[MeanPosition],
    vectors: &[OneXVector],
    correction_radius_m: f64,
    refine: Option<NonlinearRefinement>,
) -> (
    Result<ViscosityEstimate, CalibrationError>,
    Result<UnbalanceEstimate, CalibrationError>,
) {
    let unbalance_at = |v: &Result<ViscosityEstimate, CalibrationError>| {
        let mut at = rotor.clone();
        if let Ok(v) = v {
            at.set_viscosity_scale(v.scale)
                .map_err(|e| CalibrationError::Model(format!("fitted scale {}: {e}", v.scale)))?;
        }
        if vectors.is_empty() {
            return Err(CalibrationError::TooFewMeasurements(
                "no keyphasor-referenced 1X vector yet (a 1X phase needs the keyphasor)".into(),
            ));
        }
        Ok((estimate_unbalance(&at, vectors, correction_radius_m)?, at))
    };
    let finish = |fit: Result<(UnbalanceEstimate, crate::rotor::Rotor), CalibrationError>| {
        fit.map(|(u, at)| match refine {
            // a trial run that fails or whirls keeps the linear fit, with the reason
            Some(how) => refine_unbalance(&at, vectors, u.clone(), how, correction_radius_m)
                .unwrap_or_else(|e| UnbalanceEstimate {
                    not_refined: Some(e.to_string()),
                    ..u
                }),
            None => u,
        })
    };
    let viscosity = estimate_viscosity(rotor, means);
    let (unbalance, at) = match (&viscosity, unbalance_at(&viscosity)) {
        (Ok(_), Ok(u)) => u,
        (_, u) => return (viscosity, finish(u)),
    };
    let mut speeds: Vec<f64> = means.iter().map(|m| m.speed_rad_s).collect();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    let refined = journal_orbits(&at, &unbalance, &speeds)
        .and_then(|orbits| estimate_viscosity_under_orbits(rotor, means, &orbits));
    let unbalance = finish(unbalance_at(&refined));
    (refined, unbalance)
}
