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
//! the response that is nonlinear (≈ 0.06 above), and stops when an update moves the unbalance by
//! less than [`REFINEMENT_TOLERANCE`] of it. The iterate with the least misfit on the nonlinear
//! twin is kept; no convergence in [`MAX_REFINEMENTS`] updates, or none better than the linear
//! fit, is an error (the caller keeps the linear fit, saying why).

use super::unbalance::{estimate_unbalance, plane_estimate};
use super::{CalibrationError, OneXVector, UnbalanceEstimate, MAX_WINDOW_RESIDUAL_SHARE};
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

/// Updates at most: 4 (on (B) at 280 g·mm the first moves the unbalance by 7.0 %, the second by
/// 0.44 %: the update contracts about sixteenfold).
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
/// a = Re(X e^{iθ}), θ the twin's shaft angle (the unbalance's phase reference). Refused
/// (an error) when the twin's motion there is not synchronous: what is left after the mean and
/// the 1X, RMS, above [`MAX_WINDOW_RESIDUAL_SHARE`] of the station's larger 1X amplitude (the
/// replay's rule for a whirl): a twin that whirls where the plant did not has no 1X to fit to.
pub fn nonlinear_one_x(
    rotor: &Rotor,
    speed_rad_s: f64,
    how: NonlinearRefinement,
) -> Result<Vec<[[f64; 2]; 2]>, CalibrationError> {
    let rpm = crate::units::rad_s_to_rpm(speed_rad_s);
    let model = |e: crate::dynamics::TwinError| {
        CalibrationError::Model(format!("the nonlinear trial run at {rpm:.0} rpm: {e}"))
    };
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
    let mut sums = vec![[AxisSums::default(); 2]; rotor.probes.len()];
    for k in 0..n {
        let out = twin.step(&input).map_err(model)?;
        let (s, c) = out.angle_rad.sin_cos();
        // the periodic Hann window over the whole revolutions: exact for the 1X and the mean,
        // a whirl's leakage into the 1X falling as 1/f³ (a rectangular window leaks ≈ 4 % of a
        // 0.47X component)
        let w = 0.5 * (1.0 - (std::f64::consts::TAU * k as f64 / n as f64).cos());
        for (sum, p) in sums.iter_mut().zip(&out.probes) {
            for (axis, a) in sum.iter_mut().zip(p.displacement_m) {
                axis.add(a, w, c, s);
            }
        }
    }
    sums.iter()
        .map(|station| synchronous(station, n, speed_rad_s))
        .collect()
}

/// Running sums of one probe axis over the measured revolutions.
#[derive(Debug, Clone, Copy, Default)]
struct AxisSums {
    /// Σa, Σa², Σa e^{−iθ} ([re, im]), the same Hann-weighted, Σw
    a: f64,
    a2: f64,
    plain: [f64; 2],
    weighted: [f64; 2],
    w: f64,
}

impl AxisSums {
    fn add(&mut self, a: f64, w: f64, cos: f64, sin: f64) {
        self.a += a;
        self.a2 += a * a;
        self.plain = [self.plain[0] + a * cos, self.plain[1] - a * sin];
        self.weighted = [
            self.weighted[0] + w * a * cos,
            self.weighted[1] - w * a * sin,
        ];
        self.w += w;
    }

    /// X = (2/Σw) Σ w a e^{−iθ}, and the RMS of what the mean and the plain 1X leave
    /// (Σa²/N − mean² − |X₀|²/2, X₀ = (2/N) Σ a e^{−iθ}; uniform samples over whole revolutions).
    fn one_x(&self, n: usize) -> ([f64; 2], f64) {
        let k = 2.0 / self.w;
        let x = [self.weighted[0] * k, self.weighted[1] * k];
        let k0 = 2.0 / n as f64;
        let x0 = [self.plain[0] * k0, self.plain[1] * k0];
        let mean = self.a / n as f64;
        let left = self.a2 / n as f64 - mean * mean - 0.5 * (x0[0] * x0[0] + x0[1] * x0[1]);
        (x, left.max(0.0).sqrt())
    }
}

/// A station's two 1X vectors, or the refusal when its motion is not synchronous.
fn synchronous(
    station: &[AxisSums; 2],
    n: usize,
    speed_rad_s: f64,
) -> Result<[[f64; 2]; 2], CalibrationError> {
    let [(x, lx), (y, ly)] = station.map(|a| a.one_x(n));
    let amplitude = x[0].hypot(x[1]).max(y[0].hypot(y[1]));
    if lx.max(ly) > MAX_WINDOW_RESIDUAL_SHARE * amplitude {
        return Err(CalibrationError::Model(format!(
            "the nonlinear twin's motion at {:.0} rpm is not synchronous (RMS {:.3} µm besides a \
             1X of {:.3} µm): it whirls where the plant did not",
            crate::units::rad_s_to_rpm(speed_rad_s),
            lx.max(ly) * 1e6,
            amplitude * 1e6
        )));
    }
    Ok([x, y])
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
    let linear_left = misfit(measured, &predicted);
    let mut best = (linear_left, u.clone(), 0);
    for update in 1..=MAX_REFINEMENTS {
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
        let now = misfit(measured, &predicted);
        if now < best.0 {
            best = (now, u.clone(), update);
        }
        if moved.sqrt() <= REFINEMENT_TOLERANCE * size.sqrt() {
            break;
        }
        if update == MAX_REFINEMENTS {
            return Err(CalibrationError::Model(format!(
                "no convergence on the nonlinear twin in {MAX_REFINEMENTS} updates (the last moved \
                 the unbalance by {:.1} %)",
                100.0 * moved.sqrt() / size.sqrt().max(f64::MIN_POSITIVE)
            )));
        }
    }
    let (left, u, updates) = best;
    if updates == 0 {
        return Err(CalibrationError::Model(
            "no update improved on the linear fit's misfit on the nonlinear twin".into(),
        ));
    }
    let mut e = refined_estimate(rotor, measured, left, &u, linear, correction_radius_m);
    e.nonlinear_updates = updates;
    Ok(e)
}

/// Σ|X_measured − X_predicted|² (m²).
fn misfit(measured: &[OneXVector], predicted: &[OneXVector]) -> f64 {
    measured
        .iter()
        .zip(predicted)
        .map(|(m, p)| {
            let (m, p) = (m.complex(), p.complex());
            (m[0] - p[0]).powi(2) + (m[1] - p[1]).powi(2)
        })
        .sum()
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
        let x = *runs[i]
            .1
            .get(v.station)
            .and_then(|st| st.get(v.axis))
            .ok_or_else(|| CalibrationError::BadMeasurement(format!("{v:?}")))?;
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

/// The estimate at `u` with the nonlinear twin's residual, `left` its [`misfit`].
fn refined_estimate(
    rotor: &Rotor,
    measured: &[OneXVector],
    left: f64,
    u: &[[f64; 2]],
    linear: UnbalanceEstimate,
    radius_m: f64,
) -> UnbalanceEstimate {
    let size: f64 = measured
        .iter()
        .map(|m| {
            let m = m.complex();
            m[0] * m[0] + m[1] * m[1]
        })
        .sum();
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
