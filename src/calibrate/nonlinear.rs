//! The unbalance refined on the nonlinear twin. The influence coefficients H(Ω) are the linear
//! model's (the film's eight coefficients at the static equilibrium); where the 1X orbit is a
//! sizeable share of the clearance the films' response is no longer linear in the unbalance,
//! and the linear fit carries that into its estimate. On the built-in machine (B) with 280 g·mm
//! at stage 7 the nonlinear twin run with the linear fit's values missed the plant's 1X at
//! 8,000 rpm by 8.6–8.9 % (the linear twin 7.7–8.6 %); at 140 and 70 g·mm by 2.9 and 2.5 %
//! (tests/live_calibration.rs).
//!
//! Field balancing meets the same with trial runs: the next correction is the influence
//! coefficients applied to what is left. Here the trial run is the twin's own nonlinear
//! transient at each measured speed, started on the linear synchronous orbit of the current
//! estimate ([`crate::dynamics::Twin::new`]), so that only the nonlinear part settles:
//!
//!   u_{k+1} = u_k + H⁺ (X_measured − X_nonlinear(u_k)),
//!
//! a quasi-Newton iteration with the linear H as its Jacobian; it contracts by about the share of
//! the response that is nonlinear (≈ 0.1 above), and stops when an update moves the unbalance by
//! less than [`REFINEMENT_TOLERANCE`] of it.

use super::unbalance::{estimate_unbalance, plane_estimate};
use super::{CalibrationError, OneXVector, UnbalanceEstimate};
use crate::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use crate::rotor::Rotor;

/// Revolutions run before the 1X is taken, from the linear orbit: 24. Against 192 settled and
/// 32 measured, the estimate of tests/live_calibration.rs (the built-in (B), 280 g·mm at stage 7)
/// moves by 2·10⁻⁶ of its stage-7 plane and 0.005 g·mm at stage 4 (README, "Oil temperature and
/// calibration from measurements").
pub const SETTLE_REVOLUTIONS: usize = 24;

/// Revolutions the 1X is taken over (a DFT at the shaft angle over whole revolutions): 16, the
/// replay's window.
pub const MEASURED_REVOLUTIONS: usize = 16;

/// The iteration stops when an update moves the unbalance by less than this share of it: 0.5 %,
/// the project's convergence bar.
pub const REFINEMENT_TOLERANCE: f64 = 0.005;

/// Updates at most: 4 (the update contracts tenfold each time on (B) at 280 g·mm).
pub const MAX_REFINEMENTS: usize = 4;

/// How the nonlinear trial runs are made: the film evaluation and the steps a revolution of the
/// twin whose estimate it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NonlinearRefinement {
    /// Film evaluation of the trial runs.
    pub film: FilmEvaluation,
    /// Time steps a revolution.
    pub steps_per_rev: usize,
}

/// The steady 1X of every probe station of `rotor` (its own unbalance and viscosity) on the
/// nonlinear twin at `speed_rad_s`: per station the complex amplitudes [x, y] as [re, im] (m),
/// a = Re(X e^{iθ}), θ the twin's shaft angle (the unbalance's phase reference).
pub fn nonlinear_one_x(
    rotor: &Rotor,
    speed_rad_s: f64,
    how: NonlinearRefinement,
) -> Result<Vec<[[f64; 2]; 2]>, CalibrationError> {
    let model = |e: crate::dynamics::TwinError| CalibrationError::Model(e.to_string());
    let config = TwinConfig {
        film: how.film,
        ..TwinConfig::with_steps_per_rev(Coupling::Nonlinear, speed_rad_s, how.steps_per_rev)
    };
    let mut twin = Twin::new(rotor, config, speed_rad_s).map_err(model)?;
    let input = StepInput {
        speed_rad_s,
        accel_rad_s2: 0.0,
    };
    for _ in 0..SETTLE_REVOLUTIONS * how.steps_per_rev {
        twin.step(&input).map_err(model)?;
    }
    let n = MEASURED_REVOLUTIONS * how.steps_per_rev;
    let mut sums = vec![[[0.0; 2]; 2]; rotor.probes.len()];
    for _ in 0..n {
        let out = twin.step(&input).map_err(model)?;
        let (s, c) = out.angle_rad.sin_cos();
        for (sum, p) in sums.iter_mut().zip(&out.probes) {
            for (axis, a) in sum.iter_mut().zip(p.displacement_m) {
                // X = (2/N) Σ a e^{−iθ}
                axis[0] += a * c;
                axis[1] -= a * s;
            }
        }
    }
    let k = 2.0 / n as f64;
    Ok(sums
        .into_iter()
        .map(|s| s.map(|a| [a[0] * k, a[1] * k]))
        .collect())
}

/// The unbalance of `linear` (the influence-coefficient fit of `measured` on `rotor`, at the
/// fitted viscosity) refined on the nonlinear twin (module documentation); its residual and
/// relative residual are then the nonlinear twin's against `measured`, its condition number the
/// linear problem's.
pub fn refine_unbalance(
    rotor: &Rotor,
    measured: &[OneXVector],
    linear: UnbalanceEstimate,
    how: NonlinearRefinement,
    correction_radius_m: f64,
) -> Result<UnbalanceEstimate, CalibrationError> {
    let mut u: Vec<[f64; 2]> = linear.planes.iter().map(plane_complex).collect();
    let mut predicted = predict(rotor, &u, measured, how)?;
    let mut updates = 0;
    for _ in 0..MAX_REFINEMENTS {
        updates += 1;
        let left: Vec<OneXVector> = measured
            .iter()
            .zip(&predicted)
            .map(|(v, p)| {
                let (m, p) = (v.complex(), p.complex());
                OneXVector::from_complex(
                    v.station,
                    v.axis,
                    v.speed_rad_s,
                    [m[0] - p[0], m[1] - p[1]],
                )
            })
            .collect();
        let step = estimate_unbalance(rotor, &left, correction_radius_m)?;
        let (mut moved, mut size) = (0.0f64, 0.0f64);
        for (ui, d) in u.iter_mut().zip(step.planes.iter().map(plane_complex)) {
            *ui = [ui[0] + d[0], ui[1] + d[1]];
            moved += d[0] * d[0] + d[1] * d[1];
            size += ui[0] * ui[0] + ui[1] * ui[1];
        }
        predicted = predict(rotor, &u, measured, how)?;
        if moved.sqrt() <= REFINEMENT_TOLERANCE * size.sqrt() {
            break;
        }
    }
    let mut e = refined_estimate(rotor, measured, &predicted, &u, linear, correction_radius_m);
    e.nonlinear_updates = updates;
    Ok(e)
}

/// A plane's complex m·e (kg·m) as [re, im].
fn plane_complex(p: &super::PlaneEstimate) -> [f64; 2] {
    let (s, c) = p.phase_deg.to_radians().sin_cos();
    let me = p.magnitude_g_mm * 1e-6;
    [me * c, me * s]
}

/// The nonlinear twin's 1X for each of `measured` (its station, axis and speed) with the
/// unbalance `u` (kg·m per plane of `rotor`, [re, im]); one trial run a distinct speed.
fn predict(
    rotor: &Rotor,
    u: &[[f64; 2]],
    measured: &[OneXVector],
    how: NonlinearRefinement,
) -> Result<Vec<OneXVector>, CalibrationError> {
    let mut trial = rotor.clone();
    for (plane, ui) in trial.unbalance.iter_mut().zip(u) {
        plane.magnitude_kg_m = ui[0].hypot(ui[1]);
        plane.phase_rad = ui[1].atan2(ui[0]);
    }
    let mut runs: Vec<(f64, Vec<[[f64; 2]; 2]>)> = Vec::new();
    let mut out = Vec::with_capacity(measured.len());
    for v in measured {
        let i = match runs.iter().position(|(w, _)| same_speed(*w, v.speed_rad_s)) {
            Some(i) => i,
            None => {
                runs.push((v.speed_rad_s, nonlinear_one_x(&trial, v.speed_rad_s, how)?));
                runs.len() - 1
            }
        };
        let x = runs[i].1[v.station][v.axis];
        out.push(OneXVector::from_complex(
            v.station,
            v.axis,
            v.speed_rad_s,
            x,
        ));
    }
    Ok(out)
}

/// Within 0.5 rpm: one set of influence coefficients (`unbalance::estimate_unbalance`).
fn same_speed(a_rad_s: f64, b_rad_s: f64) -> bool {
    (crate::units::rad_s_to_rpm(a_rad_s) - crate::units::rad_s_to_rpm(b_rad_s)).abs() <= 0.5
}

/// The estimate at `u` with the nonlinear twin's residual.
fn refined_estimate(
    rotor: &Rotor,
    measured: &[OneXVector],
    predicted: &[OneXVector],
    u: &[[f64; 2]],
    linear: UnbalanceEstimate,
    radius_m: f64,
) -> UnbalanceEstimate {
    let (mut left, mut size) = (0.0, 0.0);
    for (m, p) in measured.iter().zip(predicted) {
        let (m, p) = (m.complex(), p.complex());
        left += (m[0] - p[0]).powi(2) + (m[1] - p[1]).powi(2);
        size += m[0] * m[0] + m[1] * m[1];
    }
    let n = measured.len().max(1) as f64;
    let planes = rotor
        .unbalance
        .iter()
        .zip(u)
        .map(|(plane, ui)| {
            let r = plane.correction_radius_m.unwrap_or(radius_m);
            plane_estimate(plane.node, *ui, r)
        })
        .collect();
    UnbalanceEstimate {
        planes,
        residual_rms_m: (left / n).sqrt(),
        relative_residual: (left / size.max(f64::MIN_POSITIVE)).sqrt(),
        ..linear
    }
}
