//! Natural frequencies, damped eigenvalues with the bearings' speed-dependent coefficients
//! (the seed's "classical" linear description), the Campbell diagram and the linear stability
//! threshold.

use super::{BearingModel, Rotor, RotorError, StaticSolution};
use crate::film::{equilibrium_under_load, FilmCoefficients, FilmModel, JournalKinematics};
use crate::units::rad_s_to_rpm;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use serde::Serialize;
use std::f64::consts::PI;

/// Supports for the non-rotating natural frequencies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Constraint {
    /// No supports at all (4 rigid-body modes are dropped).
    FreeFree,
    /// x and y held at every bearing node.
    Pinned,
}

/// Natural frequencies of the non-rotating shaft (Hz), each once (the two bending planes give
/// every frequency twice), rigid-body modes dropped. Solves K φ = ω² M φ on the shaft DOFs by
/// the Cholesky reduction L⁻¹ K L⁻ᵀ.
pub fn undamped_frequencies_hz(
    rotor: &Rotor,
    constraint: Constraint,
) -> Result<Vec<f64>, RotorError> {
    let n_shaft = 4 * rotor.n_nodes();
    let held: Vec<usize> = match constraint {
        Constraint::FreeFree => Vec::new(),
        Constraint::Pinned => rotor.bearings.iter().flat_map(|b| b.journal_dofs).collect(),
    };
    let dofs: Vec<usize> = (0..n_shaft).filter(|d| !held.contains(d)).collect();
    let n = dofs.len();
    let m = Mat::<f64>::from_fn(n, n, |i, j| rotor.mass[(dofs[i], dofs[j])]);
    let k = Mat::<f64>::from_fn(n, n, |i, j| rotor.stiffness[(dofs[i], dofs[j])]);
    let llt = m.llt(Side::Lower).map_err(|_| RotorError::LinearAlgebra {
        what: "natural frequencies",
        why: "the mass matrix is not positive definite (a shaft element of zero density?)".into(),
    })?;
    let l = llt.L();
    // S = L⁻¹ K L⁻ᵀ
    let mut x = k.clone();
    l.solve_lower_triangular_in_place(&mut x);
    let mut s = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut s);
    let s = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (s[(i, j)] + s[(j, i)]));
    let values =
        s.self_adjoint_eigenvalues(Side::Lower)
            .map_err(|e| RotorError::LinearAlgebra {
                what: "natural frequencies",
                why: format!("{e:?}"),
            })?;
    // rigid-body modes: 2 per bending plane when free, 1 per plane when pinned at one node only
    let pinned_nodes = {
        let mut nodes: Vec<usize> = rotor.bearings.iter().map(|b| b.node).collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes.len()
    };
    let rigid = match constraint {
        Constraint::FreeFree => 4,
        Constraint::Pinned => 2 * 2usize.saturating_sub(pinned_nodes),
    };
    let mut hz: Vec<f64> = values
        .into_iter()
        .skip(rigid)
        .map(|v| v.max(0.0).sqrt() / (2.0 * PI))
        .collect();
    hz.sort_by(f64::total_cmp);
    hz.dedup_by(|a, b| (*a - *b).abs() <= 1e-6 * b.abs());
    Ok(hz)
}

/// Sense of whirl of a mode relative to the rotation (from +x towards +y).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum WhirlDirection {
    /// With the rotation.
    Forward,
    /// Against the rotation.
    Backward,
}

/// One damped mode at one speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Mode {
    /// Damped natural frequency (Hz).
    pub frequency_hz: f64,
    /// Logarithmic decrement δ = −2π Re λ / Im λ (negative: unstable).
    pub log_dec: f64,
    /// Damping ratio ζ = −Re λ / |λ|.
    pub damping_ratio: f64,
    /// Whirl sense.
    pub direction: WhirlDirection,
}

/// Coefficients of every bearing at one speed (rigid bearings carry zeros: they are constraints).
pub type BearingCoefficientSet = Vec<FilmCoefficients>;

/// Damped modes at spin `speed_rad_s` (rad/s) with bearing coefficients `coefficients` (one per
/// bearing), sorted by frequency; overdamped (real) eigenvalues are left out. State-space form
/// ż = A z, A = [[0, I], [−M⁻¹K, −M⁻¹(C + ΩG)]], on all DOFs but the rigid bearings' journals.
pub fn damped_modes(
    rotor: &Rotor,
    speed_rad_s: f64,
    coefficients: &[FilmCoefficients],
) -> Result<Vec<Mode>, RotorError> {
    let n_all = rotor.n_dof();
    let mut k = rotor.stiffness.clone();
    let mut c = Mat::<f64>::from_fn(n_all, n_all, |i, j| {
        rotor.damping[(i, j)] + speed_rad_s * rotor.gyroscopic[(i, j)]
    });
    let mut held = Vec::new();
    for (b, coef) in rotor.bearings.iter().zip(coefficients) {
        if matches!(b.model, BearingModel::Rigid) {
            held.extend(b.journal_dofs);
            continue;
        }
        // the film acts on the relative motion journal − pedestal
        let pairs: &[(usize, f64)] = if b.pedestal_dofs.is_some() {
            &[(0, 1.0), (1, -1.0)]
        } else {
            &[(0, 1.0)]
        };
        let dofs = |side: usize| {
            if side == 0 {
                b.journal_dofs
            } else {
                b.pedestal_dofs.unwrap_or(b.journal_dofs)
            }
        };
        for &(si, ssi) in pairs {
            for &(sj, ssj) in pairs {
                for i in 0..2 {
                    for j in 0..2 {
                        k[(dofs(si)[i], dofs(sj)[j])] += ssi * ssj * coef.stiffness_n_per_m[i][j];
                        c[(dofs(si)[i], dofs(sj)[j])] += ssi * ssj * coef.damping_n_s_per_m[i][j];
                    }
                }
            }
        }
    }
    let dofs: Vec<usize> = (0..n_all).filter(|d| !held.contains(d)).collect();
    let n = dofs.len();
    let m = Mat::<f64>::from_fn(n, n, |i, j| rotor.mass[(dofs[i], dofs[j])]);
    let llt = m.llt(Side::Lower).map_err(|_| RotorError::LinearAlgebra {
        what: "damped modes",
        why: "the mass matrix is not positive definite".into(),
    })?;
    let mut mk = Mat::<f64>::from_fn(n, n, |i, j| k[(dofs[i], dofs[j])]);
    let mut mc = Mat::<f64>::from_fn(n, n, |i, j| c[(dofs[i], dofs[j])]);
    llt.solve_in_place(&mut mk);
    llt.solve_in_place(&mut mc);
    let a = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(j - n == i)),
        (false, true) => -mk[(i - n, j)],
        (false, false) => -mc[(i - n, j - n)],
    });
    let (a, scale) = balance(a);
    let eig = a.eigen().map_err(|e| RotorError::LinearAlgebra {
        what: "damped modes",
        why: format!("{e:?}"),
    })?;
    let values = eig.S().column_vector();
    // eigenvectors of the balanced matrix D⁻¹AD are D⁻¹ times those of A
    let u = eig.U();
    let vectors = Mat::<faer::c64>::from_fn(u.nrows(), u.ncols(), |i, j| u[(i, j)] * scale[i]);
    let span = rotor.node_z_m.last().copied().unwrap_or(1.0) - rotor.node_z_m[0];
    let ell2 = (0.1 * span).powi(2);
    let mut full_index = vec![usize::MAX; n_all];
    for (r, &d) in dofs.iter().enumerate() {
        full_index[d] = r;
    }
    let mut modes = Vec::new();
    for (col, lam) in values.iter().enumerate() {
        if lam.im <= 1e-6 * lam.re.abs().max(1.0) || !lam.im.is_finite() {
            continue;
        }
        // whirl sense: Σ Im(conj(X)·Y) over nodes, with the cross-section axis (θy, −θx) weighted
        // by ℓ² (ℓ = a tenth of the rotor); negative = forward for the e^{+iωt} convention
        let mut sense = 0.0;
        let comp = |d: usize| {
            let r = full_index[d];
            if r == usize::MAX {
                faer::c64::new(0.0, 0.0)
            } else {
                vectors[(r, col)]
            }
        };
        for node in 0..rotor.n_nodes() {
            let (x, y) = (comp(4 * node), comp(4 * node + 1));
            let (tx, ty) = (comp(4 * node + 2), comp(4 * node + 3));
            sense += (x.conj() * y).im + ell2 * (ty.conj() * (-tx)).im;
        }
        modes.push(Mode {
            frequency_hz: lam.im / (2.0 * PI),
            log_dec: -2.0 * PI * lam.re / lam.im,
            damping_ratio: -lam.re / lam.re.hypot(lam.im),
            direction: if sense <= 0.0 {
                WhirlDirection::Forward
            } else {
                WhirlDirection::Backward
            },
        });
    }
    modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    Ok(modes)
}

/// Balances a square matrix by a diagonal similarity D⁻¹ A D with D a power of two per row
/// (Parlett & Reinsch 1969, as in LAPACK's dgebal), so that each row and column have comparable
/// norms: the state matrix mixes blocks of order 1 and of order ω² of the stiffest element, and
/// unbalanced its small eigenvalues (the ones that matter) lose their accuracy. Returns the
/// balanced matrix and D.
fn balance(mut a: Mat<f64>) -> (Mat<f64>, Vec<f64>) {
    let n = a.nrows();
    let mut d = vec![1.0; n];
    loop {
        let mut converged = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += a[(j, i)].abs();
                    r += a[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / 2.0 {
                cc *= 2.0;
                rr /= 2.0;
                f *= 2.0;
            }
            while cc >= rr * 2.0 {
                cc /= 2.0;
                rr *= 2.0;
                f /= 2.0;
            }
            if (cc + rr) < 0.95 * s {
                converged = false;
                d[i] *= f;
                for j in 0..n {
                    a[(i, j)] /= f;
                    a[(j, i)] *= f;
                }
            }
        }
        if converged {
            return (a, d);
        }
    }
}

/// One speed of a Campbell diagram.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CampbellPoint {
    /// Speed (rpm).
    pub speed_rpm: f64,
    /// The lowest modes, by frequency.
    pub modes: Vec<Mode>,
    /// Eccentricity ratio of each film bearing at its static equilibrium (0 for others).
    pub eccentricity_ratios: Vec<f64>,
    /// The bearing coefficients used.
    #[serde(skip)]
    pub coefficients: BearingCoefficientSet,
}

/// The film solvers of a rotor's bearings, reused from speed to speed (warm starts).
struct BearingSolvers(Vec<Option<Box<dyn FilmModel + Send>>>);

impl BearingSolvers {
    fn new(rotor: &Rotor) -> Self {
        Self(
            rotor
                .bearings
                .iter()
                .map(|b| match &b.model {
                    BearingModel::Film(f) => Some(f.solver()),
                    _ => None,
                })
                .collect(),
        )
    }

    /// Coefficients and eccentricity ratios of every bearing at its static equilibrium under
    /// `loads` (N) at `speed_rad_s` (rad/s).
    fn at_speed(
        &mut self,
        rotor: &Rotor,
        loads: &[[f64; 2]],
        speed_rad_s: f64,
    ) -> Result<(BearingCoefficientSet, Vec<f64>), RotorError> {
        let mut coefs = Vec::new();
        let mut eps = Vec::new();
        for ((b, solver), load) in rotor.bearings.iter().zip(&mut self.0).zip(loads) {
            let (coef, e) = match (&b.model, solver) {
                (BearingModel::Film(f), Some(s)) => {
                    let fail = |source| RotorError::Film {
                        bearing: b.name.clone(),
                        speed_rpm: rad_s_to_rpm(speed_rad_s),
                        source,
                    };
                    if load[0].hypot(load[1]) < 1e-9 {
                        // unloaded: the journal runs centred
                        let (_, c) = s
                            .solve_with_coefficients(&JournalKinematics::at_position(
                                [0.0, 0.0],
                                speed_rad_s,
                            ))
                            .map_err(fail)?;
                        (c, 0.0)
                    } else {
                        let eq = equilibrium_under_load(
                            s.as_mut(),
                            f.lubricant.viscosity_pa_s,
                            *load,
                            speed_rad_s,
                        )
                        .map_err(fail)?;
                        (eq.coefficients, eq.eccentricity_ratio)
                    }
                }
                (BearingModel::Linear(c), _) => (*c, 0.0),
                _ => (FilmCoefficients::default(), 0.0),
            };
            coefs.push(coef);
            eps.push(e);
        }
        Ok((coefs, eps))
    }
}

/// The Campbell diagram: the `n_modes` lowest damped modes at each speed of `speeds_rpm`, the
/// film bearings linearised at their static equilibrium under the loads of `statics`.
pub fn campbell(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: &[f64],
    n_modes: usize,
) -> Result<Vec<CampbellPoint>, RotorError> {
    let mut solvers = BearingSolvers::new(rotor);
    speeds_rpm
        .iter()
        .map(|&rpm| {
            let omega = crate::units::rpm_to_rad_s(rpm);
            let (coefs, eps) = solvers.at_speed(rotor, &statics.bearing_loads_n, omega)?;
            let mut modes = damped_modes(rotor, omega, &coefs)?;
            modes.truncate(n_modes);
            Ok(CampbellPoint {
                speed_rpm: rpm,
                modes,
                eccentricity_ratios: eps,
                coefficients: coefs,
            })
        })
        .collect()
}

/// The linear stability threshold.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Threshold {
    /// Lowest speed at which a mode loses its damping (rpm).
    pub speed_rpm: f64,
    /// That mode's frequency there (Hz).
    pub frequency_hz: f64,
    /// Whirl frequency ratio there: mode frequency / running frequency.
    pub whirl_ratio: f64,
}

/// Log decrement below which a mode counts as unstable: below round-off of undamped shaft modes.
const UNSTABLE_LOG_DEC: f64 = -1e-6;

/// Least log decrement among the modes whose frequency is below twice the running frequency
/// (fluid-film instability is sub-synchronous), and that mode's frequency (Hz).
fn least_damped(modes: &[Mode], speed_rpm: f64) -> Option<(f64, f64)> {
    modes
        .iter()
        .filter(|m| m.frequency_hz < 2.0 * speed_rpm / 60.0)
        .map(|m| (m.log_dec, m.frequency_hz))
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// Lowest speed in [`from_rpm`, `to_rpm`] where a mode below twice the running frequency turns
/// unstable (log decrement below −1e-6): scanned every `step_rpm`, then located by bisection to 0.5 rpm. None if stable over
/// the whole range.
pub fn stability_threshold(
    rotor: &Rotor,
    statics: &StaticSolution,
    from_rpm: f64,
    to_rpm: f64,
    step_rpm: f64,
) -> Result<Option<Threshold>, RotorError> {
    if !(from_rpm > 0.0
        && to_rpm > from_rpm
        && step_rpm > 0.0
        && (to_rpm - from_rpm) / step_rpm <= 10_000.0)
    {
        return Err(RotorError::InvalidInput {
            name: "speed range (rpm)",
            value: to_rpm - from_rpm,
            rule: "needs 0 < from < to and at most 10,000 steps",
        });
    }
    let mut solvers = BearingSolvers::new(rotor);
    let mut probe = |rpm: f64| -> Result<Option<(f64, f64)>, RotorError> {
        let omega = crate::units::rpm_to_rad_s(rpm);
        let (coefs, _) = solvers.at_speed(rotor, &statics.bearing_loads_n, omega)?;
        Ok(least_damped(&damped_modes(rotor, omega, &coefs)?, rpm))
    };
    let unstable = |v: Option<(f64, f64)>| v.is_some_and(|(d, _)| d < UNSTABLE_LOG_DEC);
    let mut last_stable = from_rpm;
    if unstable(probe(from_rpm)?) {
        let (_, f) = probe(from_rpm)?.unwrap_or((0.0, 0.0));
        return Ok(Some(Threshold {
            speed_rpm: from_rpm,
            frequency_hz: f,
            whirl_ratio: f * 60.0 / from_rpm,
        }));
    }
    let mut rpm = from_rpm;
    while rpm < to_rpm {
        rpm = (rpm + step_rpm).min(to_rpm);
        if unstable(probe(rpm)?) {
            let (mut lo, mut hi) = (last_stable, rpm);
            while hi - lo > 0.5 {
                let mid = 0.5 * (lo + hi);
                if unstable(probe(mid)?) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            // interpolate the log decrement's zero between lo and hi
            let (dl, fl) = probe(lo)?.unwrap_or((0.0, 0.0));
            let (dh, fh) = probe(hi)?.unwrap_or((0.0, 0.0));
            let t = if dl != dh {
                (dl / (dl - dh)).clamp(0.0, 1.0)
            } else {
                0.5
            };
            let speed = lo + t * (hi - lo);
            let f = fl + t * (fh - fl);
            return Ok(Some(Threshold {
                speed_rpm: speed,
                frequency_hz: f,
                whirl_ratio: f * 60.0 / speed,
            }));
        }
        last_stable = rpm;
    }
    Ok(None)
}

/// Forward critical speeds (rpm) read off a Campbell diagram: where the k-th forward mode's
/// frequency crosses the running frequency, by linear interpolation between grid speeds.
pub fn critical_speeds_rpm(points: &[CampbellPoint]) -> Vec<f64> {
    let forward = |p: &CampbellPoint| -> Vec<f64> {
        p.modes
            .iter()
            .filter(|m| m.direction == WhirlDirection::Forward)
            .map(|m| m.frequency_hz)
            .collect()
    };
    let mut out = Vec::new();
    for w in points.windows(2) {
        let (fa, fb) = (forward(&w[0]), forward(&w[1]));
        for k in 0..fa.len().min(fb.len()) {
            let ga = fa[k] - w[0].speed_rpm / 60.0;
            let gb = fb[k] - w[1].speed_rpm / 60.0;
            if ga > 0.0 && gb <= 0.0 {
                let t = ga / (ga - gb);
                out.push(w[0].speed_rpm + t * (w[1].speed_rpm - w[0].speed_rpm));
            }
        }
    }
    out.sort_by(f64::total_cmp);
    out
}
