//! Static equilibrium of a journal in its film: where the film force balances the load.

use super::coefficients::FilmCoefficients;
use super::error::{positive, FilmError};
use super::{FilmModel, FilmResult, JournalKinematics, MAX_ECCENTRICITY_RATIO};
use nalgebra::Vector2;
use serde::Serialize;
use std::f64::consts::PI;

/// Newton iterations allowed for an equilibrium.
const MAX_ITERATIONS: usize = 60;
/// Largest eccentricity ratio the static equilibrium is sought at (a margin below the film
/// models' [`MAX_ECCENTRICITY_RATIO`]): a load the film cannot carry there has no equilibrium.
pub const MAX_EQUILIBRIUM_ECCENTRICITY: f64 = 0.995 * MAX_ECCENTRICITY_RATIO;

/// A static equilibrium and the film there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Equilibrium {
    /// Journal centre position `[x, y]` relative to the bearing centre (m).
    pub position_m: [f64; 2],
    /// Eccentricity ratio ε = e/c (dimensionless).
    pub eccentricity_ratio: f64,
    /// Attitude angle φ: from the load line to the line of centres, in the direction of
    /// rotation (rad).
    pub attitude_angle_rad: f64,
    /// Load carried by the film `[W_x, W_y]` (N): the external load on the journal.
    pub load_n: [f64; 2],
    /// Sommerfeld number S = (µ N L D / W)(R/c)², N in rev/s (dimensionless).
    pub sommerfeld_number: f64,
    /// The film solution at equilibrium.
    #[serde(skip)]
    pub film: FilmResult,
    /// The eight coefficients at equilibrium, for a linearised analysis
    /// ([`FilmModel::linearised_coefficients`]).
    pub coefficients: FilmCoefficients,
    /// Newton iterations used.
    pub iterations: usize,
}

/// Sommerfeld number S = (µ N L D / W)(R/c)² with N = |ω|/2π (rev/s).
pub fn sommerfeld_number(
    model: &dyn FilmModel,
    viscosity_pa_s: f64,
    speed_rad_s: f64,
    load_n: f64,
) -> f64 {
    let g = model.geometry();
    let n_rev_s = speed_rad_s.abs() / (2.0 * PI);
    viscosity_pa_s * n_rev_s * g.length_m * g.diameter_m / load_n
        * (g.radius_m() / g.radial_clearance_m).powi(2)
}

/// Eccentricity ratio of a short bearing (Ocvirk) carrying Sommerfeld number `s` at slenderness
/// `l_over_d`: inverts S (L/D)² = (1−ε²)² / (π ε √(16ε² + π²(1−ε²))) by bisection. Used as the
/// first guess of the equilibrium search.
pub fn short_bearing_eccentricity(s: f64, l_over_d: f64) -> f64 {
    let target = s * l_over_d * l_over_d;
    let f = |e: f64| {
        let q = 1.0 - e * e;
        q * q / (PI * e * (16.0 * e * e + PI * PI * q).sqrt())
    };
    let (mut lo, mut hi) = (1e-6, 0.999);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Attitude angle of a short bearing at eccentricity ratio `e`: tan φ = π√(1−ε²)/(4ε).
fn short_bearing_attitude(e: f64) -> f64 {
    (PI * (1.0 - e * e).sqrt()).atan2(4.0 * e)
}

/// Finds where the film carries the static load `load_n` (N, on the journal, fixed frame) at
/// speed `speed_rad_s` (rad/s), by Newton's method with the film stiffness as Jacobian.
pub fn equilibrium_under_load(
    model: &mut dyn FilmModel,
    viscosity_pa_s: f64,
    load_n: [f64; 2],
    speed_rad_s: f64,
) -> Result<Equilibrium, FilmError> {
    let w = load_n[0].hypot(load_n[1]);
    positive("static load (N)", w)?;
    check_speed(speed_rad_s)?;
    let c = model.geometry().radial_clearance_m;
    let s = sommerfeld_number(model, viscosity_pa_s, speed_rad_s, w);
    let load_angle = load_n[1].atan2(load_n[0]);
    let turn = speed_rad_s.signum();
    let start = short_bearing_start(model, viscosity_pa_s, load_n, speed_rad_s);
    let (q, film, it) = newton_position(model, load_n, speed_rad_s, start)?;
    let kin = JournalKinematics::at_position(q, speed_rad_s);
    let coef = model.linearised_coefficients(&kin)?;
    let mut phi = turn * (q[1].atan2(q[0]) - load_angle);
    phi = (phi + PI).rem_euclid(2.0 * PI) - PI;
    Ok(Equilibrium {
        position_m: q,
        eccentricity_ratio: kin.eccentricity_ratio(c),
        attitude_angle_rad: phi,
        load_n,
        sommerfeld_number: s,
        film,
        coefficients: coef,
        iterations: it,
    })
}

/// The journal position of the short-bearing (Ocvirk) solution at the film's Sommerfeld
/// number, ε kept within 0.05–0.9: where [`equilibrium_under_load`] starts.
fn short_bearing_start(
    model: &dyn FilmModel,
    viscosity_pa_s: f64,
    load_n: [f64; 2],
    speed_rad_s: f64,
) -> [f64; 2] {
    let c = model.geometry().radial_clearance_m;
    let s = sommerfeld_number(
        model,
        viscosity_pa_s,
        speed_rad_s,
        load_n[0].hypot(load_n[1]),
    );
    let e0 = short_bearing_eccentricity(s, model.geometry().slenderness()).clamp(0.05, 0.9);
    let psi = load_n[1].atan2(load_n[0]) + speed_rad_s.signum() * short_bearing_attitude(e0);
    [e0 * c * psi.cos(), e0 * c * psi.sin()]
}

/// The position (m) where the film carries `load_n` (N) at `speed_rad_s`, and the film there,
/// by the Newton iteration of [`equilibrium_under_load`] started at `start` (m; a warm start,
/// e.g. the last position of a slowly changing film) or, without one, where it starts; without
/// the equilibrium's linearised coefficients.
pub fn equilibrium_position(
    model: &mut dyn FilmModel,
    viscosity_pa_s: f64,
    load_n: [f64; 2],
    speed_rad_s: f64,
    start: Option<[f64; 2]>,
) -> Result<([f64; 2], FilmResult), FilmError> {
    positive("static load (N)", load_n[0].hypot(load_n[1]))?;
    check_speed(speed_rad_s)?;
    let start =
        start.unwrap_or_else(|| short_bearing_start(model, viscosity_pa_s, load_n, speed_rad_s));
    let (q, film, _) = newton_position(model, load_n, speed_rad_s, start)?;
    Ok((q, film))
}

fn check_speed(speed_rad_s: f64) -> Result<(), FilmError> {
    if !(speed_rad_s.is_finite() && speed_rad_s != 0.0) {
        return Err(FilmError::InvalidParameter {
            name: "journal speed (rad/s)",
            value: speed_rad_s,
            rule: "must be finite and not zero: a film at rest carries no static load",
        });
    }
    Ok(())
}

/// Newton's method on the film force − load from `start`, the film stiffness as Jacobian and
/// a halving line search on the residual; to 1e-9 of the load. The position, the film there
/// and the iterations taken.
fn newton_position(
    model: &mut dyn FilmModel,
    load_n: [f64; 2],
    speed_rad_s: f64,
    start: [f64; 2],
) -> Result<([f64; 2], FilmResult, usize), FilmError> {
    let w = load_n[0].hypot(load_n[1]);
    let c = model.geometry().radial_clearance_m;
    let residual = |f: &FilmResult| [f.force_n[0] + load_n[0], f.force_n[1] + load_n[1]];
    let norm = |r: [f64; 2]| r[0].hypot(r[1]);
    let mut q = start;
    let kin = JournalKinematics::at_position(q, speed_rad_s);
    let (mut film, mut coef) = model.solve_with_coefficients(&kin)?;
    let mut r = residual(&film);
    for it in 0..MAX_ITERATIONS {
        if norm(r) <= 1e-9 * w {
            return Ok((q, film, it));
        }
        // −K Δq = −r  →  Δq = K⁻¹ r
        let newton = coef
            .stiffness_n_per_m
            .try_inverse()
            .map(|k_inv| k_inv * Vector2::from(r));
        let mut dq = match newton {
            Some(d) if d.iter().all(|v| v.is_finite()) => [d.x, d.y],
            _ => [0.01 * c * r[0] / norm(r), 0.01 * c * r[1] / norm(r)],
        };
        let mut accepted = false;
        for _ in 0..30 {
            let trial = [q[0] + dq[0], q[1] + dq[1]];
            if trial[0].hypot(trial[1]) < MAX_EQUILIBRIUM_ECCENTRICITY * c {
                let tk = JournalKinematics::at_position(trial, speed_rad_s);
                if let Ok((f, cf)) = model.solve_with_coefficients(&tk) {
                    let tr = residual(&f);
                    if norm(tr) < norm(r) {
                        (q, film, coef, r) = (trial, f, cf, tr);
                        accepted = true;
                        break;
                    }
                }
            }
            dq = [0.5 * dq[0], 0.5 * dq[1]];
        }
        if !accepted {
            break;
        }
    }
    Err(FilmError::EquilibriumNotFound {
        iterations: MAX_ITERATIONS,
        residual_n: norm(r),
    })
}

/// Finds the equilibrium at a given eccentricity ratio `eccentricity_ratio` with the load along
/// `+x`: the attitude angle where the film force has no `y` component, and the load it carries.
pub fn equilibrium_at_eccentricity(
    model: &mut dyn FilmModel,
    viscosity_pa_s: f64,
    eccentricity_ratio: f64,
    speed_rad_s: f64,
) -> Result<Equilibrium, FilmError> {
    if !(eccentricity_ratio.is_finite() && eccentricity_ratio > 0.0 && eccentricity_ratio < 0.99) {
        return Err(FilmError::InvalidParameter {
            name: "eccentricity ratio",
            value: eccentricity_ratio,
            rule: "must be greater than 0 and less than 0.99",
        });
    }
    if !(speed_rad_s.is_finite() && speed_rad_s != 0.0) {
        return Err(FilmError::InvalidParameter {
            name: "journal speed (rad/s)",
            value: speed_rad_s,
            rule: "must be finite and not zero: a film at rest carries no static load",
        });
    }
    let c = model.geometry().radial_clearance_m;
    let e = eccentricity_ratio * c;
    let turn = speed_rad_s.signum();
    let mut phi = short_bearing_attitude(eccentricity_ratio);
    let mut imbalance_n = 0.0;
    for it in 0..MAX_ITERATIONS {
        let psi = turn * phi;
        let q = [e * psi.cos(), e * psi.sin()];
        let kin = JournalKinematics::at_position(q, speed_rad_s);
        let (film, coef) = model.solve_with_coefficients(&kin)?;
        let fy = film.force_n[1];
        let w = -film.force_n[0];
        imbalance_n = fy.abs();
        if fy.abs() <= 1e-10 * w.abs().max(f64::MIN_POSITIVE) {
            positive("load carried at this eccentricity (N)", w)?;
            let coef = model.linearised_coefficients(&kin)?;
            return Ok(Equilibrium {
                position_m: q,
                eccentricity_ratio,
                attitude_angle_rad: phi,
                load_n: [w, 0.0],
                sommerfeld_number: sommerfeld_number(model, viscosity_pa_s, speed_rad_s, w),
                film,
                coefficients: coef,
                iterations: it,
            });
        }
        // dF_y/dφ = −(k_yx ∂x/∂φ + k_yy ∂y/∂φ), ∂q/∂φ = turn·e(−sin ψ, cos ψ)
        let k = coef.stiffness_n_per_m;
        let dfy = -turn * e * (-k[(1, 0)] * psi.sin() + k[(1, 1)] * psi.cos());
        let step = if dfy != 0.0 && dfy.is_finite() {
            -fy / dfy
        } else {
            0.0
        };
        phi = (phi + step.clamp(-0.3, 0.3)).clamp(1e-4, PI - 1e-4);
    }
    Err(FilmError::EquilibriumNotFound {
        iterations: MAX_ITERATIONS,
        residual_n: imbalance_n,
    })
}
