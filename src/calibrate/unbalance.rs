//! The residual unbalance from measured 1X vectors, by influence coefficients (the balancing
//! method of field practice, e.g. ISO 20806 / Bently's "Fundamentals of Rotating Machinery
//! Diagnostics" ch. 13), the coefficients computed from the twin's own linear model at each
//! speed (`rotor::influence_coefficients`): X_k = Σ_p H_kp(Ω) u_p, u_p = m e e^{iφ_p}, solved
//! for u in the least-squares sense over every station, axis and speed.

use super::linalg::complex_least_squares;
use super::{CalibrationError, OneXVector};
use crate::rotor::{influence_coefficients, static_solution, Rotor};
use serde::Serialize;

/// Correction radius used when the machine file states none (m): 0.1 m.
pub const DEFAULT_CORRECTION_RADIUS_M: f64 = 0.1;

/// The balancing weight that cancels a plane's estimated unbalance: the same m·e at the
/// opposite angle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CorrectionMass {
    /// Mass to add (g).
    pub mass_g: f64,
    /// At this radius (m).
    pub radius_m: f64,
    /// At this angle from the reference mark, in the direction of rotation (deg, 0–360).
    pub angle_deg: f64,
}

/// The estimate in one unbalance plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlaneEstimate {
    /// Shaft node of the plane.
    pub node: usize,
    /// m·e (g·mm).
    pub magnitude_g_mm: f64,
    /// Heavy-spot angle from the reference mark (deg, 0–360), as the machine file's `phase_deg`.
    pub phase_deg: f64,
    /// The balancing weight.
    pub correction: CorrectionMass,
}

/// The unbalance estimate with its quality.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnbalanceEstimate {
    /// Per plane of the machine file, in its order.
    pub planes: Vec<PlaneEstimate>,
    /// RMS of measured minus modelled 1X over the vectors used (m).
    pub residual_rms_m: f64,
    /// The residual over the RMS measured amplitude.
    pub relative_residual: f64,
    /// 2-norm condition number of the influence-coefficient matrix (columns scaled to unit
    /// length): near 1, the planes are told apart well; above ~100, hardly.
    pub condition_number: f64,
    /// 1X vectors used.
    pub vectors: usize,
    /// Distinct speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Updates made on the nonlinear twin (`calibrate::refine_unbalance`; 0: the linear fit).
    pub nonlinear_updates: usize,
    /// Why a refinement asked for was not made (a trial run failed or whirled): the linear fit
    /// stands.
    pub not_refined: Option<String>,
}

/// Estimates the unbalance in `rotor`'s planes from `measured` 1X vectors (any stations, axes
/// and speeds; the phase reference is the shaft's angle-0 mark). Speeds within 0.5 rpm share
/// one set of influence coefficients.
pub fn estimate_unbalance(
    rotor: &Rotor,
    measured: &[OneXVector],
    correction_radius_m: f64,
) -> Result<UnbalanceEstimate, CalibrationError> {
    let planes = rotor.unbalance.len();
    if planes == 0 {
        return Err(CalibrationError::NothingToCalibrate(
            "the machine file names no unbalance plane".into(),
        ));
    }
    check_vectors(rotor, measured)?;
    if 2 * measured.len() < 2 * planes {
        return Err(CalibrationError::TooFewMeasurements(format!(
            "{} 1X vector(s) for {planes} plane(s)",
            measured.len()
        )));
    }
    let statics = static_solution(rotor).map_err(|e| CalibrationError::Model(e.to_string()))?;
    let speeds_rpm = distinct_speeds_rpm(measured);
    let mut rows = Vec::with_capacity(measured.len());
    let mut b = Vec::with_capacity(measured.len());
    for &rpm in &speeds_rpm {
        let h = influence_coefficients(rotor, &statics, rpm)
            .map_err(|e| CalibrationError::Model(e.to_string()))?;
        for v in measured.iter().filter(|v| (rpm_of(v) - rpm).abs() <= 0.5) {
            let row: Vec<[f64; 2]> = (0..planes)
                .map(|p| {
                    let c = h[p][v.station][v.axis];
                    [c.re, c.im]
                })
                .collect();
            rows.push(row);
            b.push(v.complex());
        }
    }
    solve(&rows, &b, rotor, correction_radius_m, speeds_rpm)
}

fn rpm_of(v: &OneXVector) -> f64 {
    crate::units::rad_s_to_rpm(v.speed_rad_s)
}

fn check_vectors(rotor: &Rotor, measured: &[OneXVector]) -> Result<(), CalibrationError> {
    for v in measured {
        let fine = v.station < rotor.probes.len()
            && v.axis < 2
            && v.speed_rad_s.is_finite()
            && v.speed_rad_s > 0.0
            && v.amplitude_m.is_finite()
            && v.amplitude_m.abs() < crate::driver::inputs::MAX_PROBE_DISPLACEMENT_M
            && v.phase_lag_deg.is_finite();
        if !fine {
            return Err(CalibrationError::BadMeasurement(format!("{v:?}")));
        }
    }
    Ok(())
}

/// The distinct speeds (rpm) of `measured`, 0.5 rpm apart at least, ascending.
fn distinct_speeds_rpm(measured: &[OneXVector]) -> Vec<f64> {
    let mut s: Vec<f64> = measured.iter().map(rpm_of).collect();
    s.sort_by(f64::total_cmp);
    let mut out: Vec<f64> = Vec::new();
    for v in s {
        if out.last().is_none_or(|l| v - l > 0.5) {
            out.push(v);
        }
    }
    out
}

/// Least squares on column-scaled coefficients (so the condition number compares the planes'
/// shapes, not their units), then the plane estimates and correction masses.
fn solve(
    rows: &[Vec<[f64; 2]>],
    b: &[[f64; 2]],
    rotor: &Rotor,
    radius_m: f64,
    speeds_rpm: Vec<f64>,
) -> Result<UnbalanceEstimate, CalibrationError> {
    let planes = rotor.unbalance.len();
    let norms: Vec<f64> = (0..planes)
        .map(|p| {
            rows.iter()
                .map(|r| r[p][0].powi(2) + r[p][1].powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    if norms.iter().any(|n| n.is_nan() || *n <= 0.0) {
        return Err(CalibrationError::Singular(
            "a plane moves no probe at these speeds".into(),
        ));
    }
    let scaled: Vec<Vec<[f64; 2]>> = rows
        .iter()
        .map(|r| {
            r.iter()
                .zip(&norms)
                .map(|(a, n)| [a[0] / n, a[1] / n])
                .collect()
        })
        .collect();
    let (u, residual, cond) = complex_least_squares(&scaled, b).ok_or_else(|| {
        CalibrationError::Singular("the planes cannot be told apart from these vectors".into())
    })?;
    let m = b.len() as f64;
    let measured_rms = (b.iter().map(|v| v[0] * v[0] + v[1] * v[1]).sum::<f64>() / m).sqrt();
    let residual_rms = residual / m.sqrt();
    let planes = u
        .iter()
        .zip(&norms)
        .zip(&rotor.unbalance)
        .map(|((u, n), plane)| {
            let r = plane.correction_radius_m.unwrap_or(radius_m);
            plane_estimate(plane.node, [u[0] / n, u[1] / n], r)
        })
        .collect();
    Ok(UnbalanceEstimate {
        planes,
        residual_rms_m: residual_rms,
        relative_residual: residual_rms / measured_rms.max(f64::MIN_POSITIVE),
        condition_number: cond,
        vectors: b.len(),
        speeds_rpm,
        nonlinear_updates: 0,
        not_refined: None,
    })
}

/// A plane's estimate from its complex m·e `u` (kg·m) and the correction at `radius_m` (m).
pub(super) fn plane_estimate(node: usize, u: [f64; 2], radius_m: f64) -> PlaneEstimate {
    let me_g_mm = u[0].hypot(u[1]) * 1e6;
    let phase_deg = u[1].atan2(u[0]).to_degrees().rem_euclid(360.0);
    PlaneEstimate {
        node,
        magnitude_g_mm: me_g_mm,
        phase_deg,
        correction: CorrectionMass {
            mass_g: me_g_mm / (radius_m * 1e3),
            radius_m,
            angle_deg: (phase_deg + 180.0).rem_euclid(360.0),
        },
    }
}
