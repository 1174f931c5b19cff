//! The oil's effective viscosity from measured mean journal positions (DC-coupled probes: the
//! shaft centreline against speed), fitted to the film's static equilibrium: the journal finds
//! the eccentricity and attitude where the film carries the static load, and at fixed geometry
//! that position depends on µΩ only (the Sommerfeld number, seed eq. 2 isoviscous), so the
//! positions over a speed range fix µ. The scale s = µ / µ_reference is fitted by Gauss–Newton
//! in ln s. Its standard uncertainty combines the fit's own, σ_r / |∂d/∂s| from the residual
//! σ_r and the slope (the usual linearised least-squares covariance, which shrinks as 1/√N
//! with the number of mean positions whatever their common model error), with a stated model
//! floor [`VISCOSITY_MODEL_FLOOR`] in quadrature (GUM's root sum of squares of independent
//! components). The probe's zero is taken to be the
//! bearing centre's axis (probes referenced to the bearing; the synthetic plant's are).
//!
//! Under a 1X orbit the mean journal position is not the static equilibrium: the film force is
//! nonlinear in the position, so its mean over the orbit differs from the force at the mean
//! position, and the journal moves until the mean force carries the load (the shaft is linear,
//! so over a periodic motion the mean bearing forces still equal the static loads). The plant of
//! tests/live_calibration.rs (280 g·mm at stage 7) sits 0.1–1.0 µm off its static equilibrium at
//! 5,000–8,000 rpm, which the static fit reads as 2.3 % more viscosity. Given the journals' 1X
//! orbits ([`JournalOrbits`], from the fitted unbalance through the linear model:
//! [`journal_orbits`]) the model's mean position is the orbit-averaged equilibrium instead:
//! (1/N) Σ_k F(x̄ + Re(X e^{iθ_k}), Re(iΩX e^{iθ_k})) = −W over N points of the orbit.

use super::linalg::solve_spd;
use super::{CalibrationError, MeanPosition};
use crate::film::{
    equilibrium_under_load, solve2, FilmModel, JournalKinematics, ViscosityScaledFilm,
    ZERO_CELSIUS_K,
};
use crate::rotor::{static_solution, BearingModel, Rotor, StaticSolution};
use faer::c64;
use serde::Serialize;

/// The model's own relative standard uncertainty of the viscosity scale (a Type B component,
/// GUM 4.3): 0.5 %. What the data's residual cannot show because every mean position shares it:
/// the films' grid (the plant's static equilibrium on 72 × 12, 90 × 15 and 120 × 20 films fitted
/// by the twin on 60 × 10: +0.08, +0.15 and +0.21 %, README "Why the live viscosity fit was
/// 2.4 % high") and the orbit-averaged model (the linear model's orbits of the fitted
/// unbalance; the fit on the plant of tests/live_calibration.rs reads +0.38 %, of which the grid
/// +0.08 %). Before, the reported ± was the fit's alone: × 1.0514 ± 0.0002 for a plant's 1.05
/// (7σ off), × 1.1042 ± 0.0016 for 1.10 (2.6σ off).
pub const VISCOSITY_MODEL_FLOOR: f64 = 0.005;

/// Points per orbit of the orbit-averaged equilibrium: 16 (the mean force of a 1X orbit of
/// 0.5 c at ε 0.55 changes by under 1e-6 of the load from 16 to 32 points, the integrand being
/// smooth and periodic).
pub const ORBIT_POINTS: usize = 16;

/// The journals' 1X orbits at one speed: per bearing of the machine (its order) the complex
/// amplitudes `[X, Y]` (m) relative to the pedestal, x = Re(X e^{iΩt}).
#[derive(Debug, Clone, PartialEq)]
pub struct JournalOrbits {
    /// Shaft speed (rad/s).
    pub speed_rad_s: f64,
    /// Per bearing.
    pub journals: Vec<[c64; 2]>,
}

/// The viscosity estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ViscosityEstimate {
    /// µ / µ_reference (the machine file's viscosity_pa_s).
    pub scale: f64,
    /// Its standard uncertainty (1σ): the fit's own ([`Self::fit_std`]) and the model floor
    /// [`VISCOSITY_MODEL_FLOOR`] × scale in quadrature.
    pub scale_std: f64,
    /// The fit's own standard uncertainty (1σ, from the residual and the slope): noise and the
    /// part of the model error that differs from one mean position to the next.
    pub fit_std: f64,
    /// The effective viscosity µ (Pa·s) of the first film bearing.
    pub viscosity_pa_s: f64,
    /// The oil temperature the law gives for it (°C), if the machine file has a law and the
    /// viscosity lies in its range.
    pub temperature_c: Option<f64>,
    /// Its standard uncertainty (K).
    pub temperature_std_k: Option<f64>,
    /// The offset from the law's design supply temperature (K).
    pub temperature_offset_k: Option<f64>,
    /// RMS of measured minus modelled position, per coordinate (m).
    pub residual_rms_m: f64,
    /// Mean positions used.
    pub points: usize,
    /// Gauss–Newton iterations.
    pub iterations: usize,
}

/// The film solvers reused from evaluation to evaluation (warm starts).
struct Films(Vec<Option<ViscosityScaledFilm>>);

impl Films {
    fn of(rotor: &Rotor) -> Self {
        Self(
            rotor
                .bearings
                .iter()
                .map(|b| match &b.model {
                    BearingModel::Film(f) => Some(f.scaled(f.reference_solver())),
                    _ => None,
                })
                .collect(),
        )
    }
}

/// The static position `[x, y]` (m) of every probe station of `rotor` at `speed_rad_s` with the
/// films at `scale` × their reference viscosity: each journal at its film's equilibrium under
/// its static load, the shaft statically deflected and moved rigidly onto the journals (as the
/// twin starts, `Twin::new`).
pub fn static_probe_positions(
    rotor: &Rotor,
    scale: f64,
    speed_rad_s: f64,
) -> Result<Vec<[f64; 2]>, CalibrationError> {
    let statics = static_solution(rotor).map_err(|e| CalibrationError::Model(e.to_string()))?;
    positions(
        rotor,
        &statics,
        &mut Films::of(rotor),
        scale,
        speed_rad_s,
        None,
    )
}

/// The model's mean probe positions (module documentation), under `orbits` when given.
fn positions(
    rotor: &Rotor,
    statics: &StaticSolution,
    films: &mut Films,
    scale: f64,
    speed: f64,
    orbits: Option<&JournalOrbits>,
) -> Result<Vec<[f64; 2]>, CalibrationError> {
    let mut journals = Vec::new();
    for (i, ((b, load), film)) in rotor
        .bearings
        .iter()
        .zip(&statics.bearing_loads_n)
        .zip(&mut films.0)
        .enumerate()
    {
        let d = match (&b.model, film) {
            (BearingModel::Film(f), Some(film)) => {
                film.set_scale(scale)
                    .map_err(|e| CalibrationError::Model(e.to_string()))?;
                let mu = f.lubricant.viscosity_pa_s * scale;
                let model = film as &mut dyn FilmModel;
                let named =
                    |e: String| CalibrationError::Model(format!("bearing '{}': {e}", b.name));
                let eq = equilibrium_under_load(model, mu, *load, speed)
                    .map_err(|e| named(e.to_string()))?;
                match orbits.and_then(|o| o.journals.get(i)) {
                    Some(orbit) => orbit_equilibrium(model, eq.position_m, *load, speed, orbit)
                        .map_err(named)?,
                    None => eq.position_m,
                }
            }
            (BearingModel::Linear(c), _) => solve2(&c.stiffness_n_per_m, *load),
            _ => continue,
        };
        journals.push((rotor.node_z_m[b.node], d));
    }
    let line = straight_lines(&journals);
    Ok(rotor
        .probes
        .iter()
        .map(|p| {
            let z = rotor.node_z_m[p.node];
            [0, 1].map(|a| statics.displacement[4 * p.node + a] + line[a][0] + line[a][1] * z)
        })
        .collect())
}

/// The mean journal position under the 1X `orbit` (module documentation): Newton from the
/// static equilibrium `start` on the orbit-averaged film force against the load, the Jacobian
/// the orbit-averaged stiffness, to 1e-9 of the load.
fn orbit_equilibrium(
    film: &mut dyn FilmModel,
    start: [f64; 2],
    load: [f64; 2],
    speed: f64,
    orbit: &[c64; 2],
) -> Result<[f64; 2], String> {
    let w = load[0].hypot(load[1]);
    let mut q = start;
    for _ in 0..30 {
        let (mut force, mut k) = ([0.0; 2], [[0.0; 2]; 2]);
        for j in 0..ORBIT_POINTS {
            let e = c64::cis(std::f64::consts::TAU * j as f64 / ORBIT_POINTS as f64);
            let (d, v) = (
                orbit.map(|a| (a * e).re),
                orbit.map(|a| (a * e * c64::new(0.0, speed)).re),
            );
            let kin = JournalKinematics {
                position_m: [q[0] + d[0], q[1] + d[1]],
                velocity_m_s: v,
                speed_rad_s: speed,
            };
            let (f, c) = film
                .solve_with_coefficients(&kin)
                .map_err(|e| e.to_string())?;
            let n = ORBIT_POINTS as f64;
            for a in 0..2 {
                force[a] += f.force_n[a] / n;
                for b in 0..2 {
                    k[a][b] += c.stiffness_n_per_m[(a, b)] / n;
                }
            }
        }
        let r = [force[0] + load[0], force[1] + load[1]];
        if r[0].hypot(r[1]) <= 1e-9 * w {
            return Ok(q);
        }
        // F(q + Δ) ≈ F(q) − K Δ (K = −∂F/∂q): Δ = K⁻¹ r
        let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
        if !(det.is_finite() && det != 0.0) {
            return Err("the orbit-averaged stiffness is singular".into());
        }
        q[0] += (k[1][1] * r[0] - k[0][1] * r[1]) / det;
        q[1] += (k[0][0] * r[1] - k[1][0] * r[0]) / det;
    }
    Err("the orbit-averaged equilibrium did not converge in 30 Newton steps".into())
}

/// Least-squares lines v(z) = a + b z through the journal positions, per axis: [[a, b]; 2].
fn straight_lines(points: &[(f64, [f64; 2])]) -> [[f64; 2]; 2] {
    let n = points.len() as f64;
    if points.is_empty() {
        return [[0.0; 2]; 2];
    }
    let zm = points.iter().map(|p| p.0).sum::<f64>() / n;
    let szz: f64 = points.iter().map(|p| (p.0 - zm).powi(2)).sum();
    [0, 1].map(|a| {
        let vm = points.iter().map(|p| p.1[a]).sum::<f64>() / n;
        let slope = if szz > 0.0 {
            points
                .iter()
                .map(|p| (p.0 - zm) * (p.1[a] - vm))
                .sum::<f64>()
                / szz
        } else {
            0.0
        };
        [vm - slope * zm, slope]
    })
}

/// Estimates the viscosity scale from `measured` mean positions (module documentation), each
/// modelled as the static equilibrium.
pub fn estimate_viscosity(
    rotor: &Rotor,
    measured: &[MeanPosition],
) -> Result<ViscosityEstimate, CalibrationError> {
    estimate_viscosity_under_orbits(rotor, measured, &[])
}

/// [`estimate_viscosity`] with the mean positions at the speeds of `orbits` modelled as the
/// equilibrium under those journal orbits (module documentation).
pub fn estimate_viscosity_under_orbits(
    rotor: &Rotor,
    measured: &[MeanPosition],
    orbits: &[JournalOrbits],
) -> Result<ViscosityEstimate, CalibrationError> {
    let Some(reference) = rotor.bearings.iter().find_map(|b| match &b.model {
        BearingModel::Film(f) => Some(f),
        _ => None,
    }) else {
        return Err(CalibrationError::NothingToCalibrate(
            "the machine has no film bearing".into(),
        ));
    };
    if measured.len() < 2 {
        return Err(CalibrationError::TooFewMeasurements(format!(
            "{} mean position(s); at least 2",
            measured.len()
        )));
    }
    for m in measured {
        let ok = m.station < rotor.probes.len()
            && m.speed_rad_s.is_finite()
            && m.speed_rad_s > 0.0
            && m.position_m.iter().all(|v| v.is_finite() && v.abs() < 0.01);
        if !ok {
            return Err(CalibrationError::BadMeasurement(format!("{m:?}")));
        }
    }
    let statics = static_solution(rotor).map_err(|e| CalibrationError::Model(e.to_string()))?;
    let mut films = Films::of(rotor);
    let model = Model {
        rotor,
        statics: &statics,
        orbits,
    };
    let (x, slope, rss, iterations) = gauss_newton(&model, &mut films, measured)?;
    let scale = x.exp();
    let dof = (2 * measured.len()).saturating_sub(1).max(1) as f64;
    let sigma_r = (rss / dof).sqrt();
    // d(model)/d(ln s) = s d(model)/ds: σ_s = s σ_ln s
    let fit_std = scale * sigma_r / slope.sqrt().max(f64::MIN_POSITIVE);
    let scale_std = fit_std.hypot(VISCOSITY_MODEL_FLOOR * scale);
    let mu = reference.lubricant.viscosity_pa_s * scale;
    let (temperature_c, temperature_std_k, temperature_offset_k) =
        temperature_of(reference, mu, scale_std / scale);
    Ok(ViscosityEstimate {
        scale,
        scale_std,
        fit_std,
        viscosity_pa_s: mu,
        temperature_c,
        temperature_std_k,
        temperature_offset_k,
        residual_rms_m: (rss / (2 * measured.len()) as f64).sqrt(),
        points: measured.len(),
        iterations,
    })
}

/// What the fit's model of the mean positions needs.
struct Model<'a> {
    rotor: &'a Rotor,
    statics: &'a StaticSolution,
    orbits: &'a [JournalOrbits],
}

/// Residuals measured − model at ln s = `x`, in the order of `measured`, both axes.
fn residuals(
    model: &Model,
    films: &mut Films,
    measured: &[MeanPosition],
    x: f64,
) -> Result<Vec<f64>, CalibrationError> {
    let mut out = Vec::with_capacity(2 * measured.len());
    let mut cache: Vec<(f64, Vec<[f64; 2]>)> = Vec::new();
    for m in measured {
        let at = match cache
            .iter()
            .position(|(w, _)| (w - m.speed_rad_s).abs() < 1e-6)
        {
            Some(i) => i,
            None => {
                let orbits = model
                    .orbits
                    .iter()
                    .find(|o| (o.speed_rad_s - m.speed_rad_s).abs() < 1e-6);
                let (rotor, statics) = (model.rotor, model.statics);
                let p = positions(rotor, statics, films, x.exp(), m.speed_rad_s, orbits)?;
                cache.push((m.speed_rad_s, p));
                cache.len() - 1
            }
        };
        let model = cache[at].1[m.station];
        out.extend([m.position_m[0] - model[0], m.position_m[1] - model[1]]);
    }
    Ok(out)
}

/// Gauss–Newton in x = ln s from s = 1: (x, Σ(∂r/∂x)², residual sum of squares, iterations).
fn gauss_newton(
    model: &Model,
    films: &mut Films,
    measured: &[MeanPosition],
) -> Result<(f64, f64, f64, usize), CalibrationError> {
    let ln_max = crate::film::MAX_VISCOSITY_SCALE.ln();
    let (mut x, h) = (0.0_f64, 0.01);
    for it in 1..=30 {
        let r = residuals(model, films, measured, x)?;
        let rp = residuals(model, films, measured, x + h)?;
        let rm = residuals(model, films, measured, x - h)?;
        let g: Vec<f64> = rp
            .iter()
            .zip(&rm)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let gg: f64 = g.iter().map(|v| v * v).sum();
        let gr: f64 = g.iter().zip(&r).map(|(a, b)| a * b).sum();
        let step = solve_spd(&[gg], &[-gr]).ok_or_else(|| {
            CalibrationError::Singular("the positions do not depend on the viscosity".into())
        })?[0]
            .clamp(-0.5, 0.5);
        x = (x + step).clamp(-ln_max, ln_max);
        if step.abs() < 1e-6 {
            let r = residuals(model, films, measured, x)?;
            return Ok((x, gg, r.iter().map(|v| v * v).sum(), it));
        }
    }
    Err(CalibrationError::Model(
        "the viscosity fit did not converge in 30 iterations".into(),
    ))
}

/// The temperature (°C), its uncertainty (K) and offset from the design point (K) that give µ
/// (Pa·s) through the bearing's law, with relative uncertainty `rel_std` of µ.
fn temperature_of(
    f: &crate::rotor::FilmBearing,
    mu: f64,
    rel_std: f64,
) -> (Option<f64>, Option<f64>, Option<f64>) {
    let Some(law) = f.viscosity_law else {
        return (None, None, None);
    };
    let [mut lo, mut hi] = law.range_k();
    if !(law.viscosity_pa_s(lo) >= mu && law.viscosity_pa_s(hi) <= mu) {
        return (None, None, None);
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if law.viscosity_pa_s(mid) > mu {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    // d ln µ / dT by central difference over ±0.5 K
    let dlnmu = (law.viscosity_pa_s(t + 0.5).ln() - law.viscosity_pa_s(t - 0.5).ln()).abs();
    let design = law_design_k(f, &law);
    (
        Some(t - ZERO_CELSIUS_K),
        Some(rel_std / dlnmu.max(f64::MIN_POSITIVE)),
        design.map(|d| t - d),
    )
}

/// The design supply temperature (K): where the law gives the reference viscosity.
fn law_design_k(f: &crate::rotor::FilmBearing, law: &crate::film::ViscosityLaw) -> Option<f64> {
    let target = f.lubricant.viscosity_pa_s;
    let [mut lo, mut hi] = law.range_k();
    if !(law.viscosity_pa_s(lo) >= target && law.viscosity_pa_s(hi) <= target) {
        return None;
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if law.viscosity_pa_s(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}
