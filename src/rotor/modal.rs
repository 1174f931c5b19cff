//! Natural frequencies, damped eigenvalues with the bearings' speed-dependent coefficients
//! (the seed's "classical" linear description), the Campbell diagram with its modes followed by
//! shape, the critical speeds and the linear stability threshold.

use super::mode_tracking::{
    assign_tracks, normalise, rotate_to_whirl_senses, sense, tilt_weight_m2, Shape,
};
use super::{BearingModel, Rotor, RotorError, StaticSolution};
use crate::film::{FilmCoefficients, FilmModel, JournalKinematics};
use crate::units::rad_s_to_rpm;
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use serde::Serialize;
use std::f64::consts::PI;

/// Supports for the non-rotating natural frequencies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Constraint {
    /// No supports at all (the 2 rigid-body modes of each bending plane are dropped).
    FreeFree,
    /// x and y held at every bearing node.
    Pinned,
}

/// A shaft lighter than this fraction of the rotor is a massless-shaft idealisation (a textbook
/// Jeffcott or Stodola–Green rotor): the modes that its own, negligible mass carries are set apart.
const MASSLESS_SHAFT_FRACTION: f64 = 1e-3;

/// Natural frequencies of the non-rotating shaft, each once, rigid-body modes dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct NaturalFrequencies {
    /// The rotor's natural frequencies (Hz), ascending.
    pub hz: Vec<f64>,
    /// Modes of a massless-shaft idealisation's own, negligible mass (Hz): more than half their
    /// kinetic energy is in a shaft lighter than 0.1 % of the rotor. They come from the density
    /// that stands for "massless" (hundreds of kHz for the textbook rotor) and are not modes of
    /// the modelled machine. Empty for a real shaft.
    pub massless_shaft_hz: Vec<f64>,
}

/// True if the shaft is a massless idealisation (below 0.1 % of the rotor's mass).
pub(crate) fn massless_shaft(rotor: &Rotor) -> bool {
    let shaft: f64 = rotor.elements.iter().map(|e| e.mass_kg()).sum();
    shaft < MASSLESS_SHAFT_FRACTION * rotor.rotor_mass_kg()
}

/// Natural frequencies of the non-rotating shaft and discs (Hz). The isotropic shaft's two
/// bending planes have the same frequencies, so one plane, x–z (x, θy), is solved. K φ = ω² M φ
/// is solved as the shifted, inverted problem M φ = μ (K + σM) φ, μ = 1/(ω² + σ), by the
/// Cholesky reduction L⁻¹ M L⁻ᵀ with L Lᵀ = K + σM: the low modes are its largest eigenvalues and
/// come out to round-off of them even when massless nodes make M nearly singular (the direct
/// reduction L_M⁻¹ K L_M⁻ᵀ loses 1e-3 of them there); σ = (2π · 0.1 Hz)² keeps K + σM
/// positive definite with rigid-body modes.
pub fn natural_frequencies(
    rotor: &Rotor,
    constraint: Constraint,
) -> Result<NaturalFrequencies, RotorError> {
    let held: Vec<usize> = match constraint {
        Constraint::FreeFree => Vec::new(),
        Constraint::Pinned => rotor.bearings.iter().map(|b| b.journal_dofs[0]).collect(),
    };
    let dofs: Vec<usize> = (0..rotor.n_nodes())
        .flat_map(|n| [4 * n, 4 * n + 3])
        .filter(|d| !held.contains(d))
        .collect();
    let n = dofs.len();
    let fail = |why: String| RotorError::LinearAlgebra {
        what: "natural frequencies",
        why,
    };
    let sigma = (2.0 * PI * 0.1_f64).powi(2);
    let m = Mat::<f64>::from_fn(n, n, |i, j| rotor.mass[(dofs[i], dofs[j])]);
    let a = Mat::<f64>::from_fn(n, n, |i, j| {
        rotor.stiffness[(dofs[i], dofs[j])] + sigma * m[(i, j)]
    });
    let llt = a.llt(Side::Lower).map_err(|_| {
        fail("K + σM is not positive definite (a shaft element of zero density?)".into())
    })?;
    let l = llt.L();
    // S = L⁻¹ M L⁻ᵀ
    let mut x = m.clone();
    l.solve_lower_triangular_in_place(&mut x);
    let mut s = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(&mut s);
    let s = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (s[(i, j)] + s[(j, i)]));
    let eig = s
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| {
            fail(format!(
                "the symmetric eigenvalue solver failed ({e:?}) on the {n} × {n} mass and stiffness matrices of the free shaft (machine {})",
                rotor.name
            ))
        })?;
    // φ = L⁻ᵀ u, the mode shape (its kinetic energy in the shaft elements tells a massless
    // shaft's own modes)
    let mut phi = eig.U().to_owned();
    l.transpose().solve_upper_triangular_in_place(&mut phi);
    let bearing_nodes = {
        let mut nodes: Vec<usize> = rotor.bearings.iter().map(|b| b.node).collect();
        nodes.sort_unstable();
        nodes.dedup();
        nodes.len()
    };
    // rigid-body modes of one plane: translation and tilt when free, 2 − pinned nodes when pinned
    let rigid = match constraint {
        Constraint::FreeFree => 2,
        Constraint::Pinned => 2usize.saturating_sub(bearing_nodes),
    };
    let massless = massless_shaft(rotor);
    let mut out = NaturalFrequencies {
        hz: Vec::new(),
        massless_shaft_hz: Vec::new(),
    };
    let values = eig.S().column_vector();
    // ascending μ is descending ω: the rigid-body modes are the last `rigid`
    for col in (0..n.saturating_sub(rigid)).rev() {
        let mu = values[col];
        if mu <= 0.0 {
            continue;
        }
        let hz = (1.0 / mu - sigma).max(0.0).sqrt() / (2.0 * PI);
        let mut full = vec![faer::c64::new(0.0, 0.0); rotor.n_dof()];
        for (r, &d) in dofs.iter().enumerate() {
            full[d] = faer::c64::new(phi[(r, col)], 0.0);
        }
        if massless && shaft_energy_fraction(rotor, &full) > 0.5 {
            out.massless_shaft_hz.push(hz);
        } else {
            out.hz.push(hz);
        }
    }
    Ok(out)
}

/// Natural frequencies of the non-rotating shaft (Hz), each once, rigid-body modes and the
/// modes of a massless shaft's own mass (see [`NaturalFrequencies`]) left out.
pub fn undamped_frequencies_hz(
    rotor: &Rotor,
    constraint: Constraint,
) -> Result<Vec<f64>, RotorError> {
    Ok(natural_frequencies(rotor, constraint)?.hz)
}

/// Share of a mode's kinetic energy carried by the shaft elements, φᴴ M_shaft φ / φᴴ M φ (the
/// rest is in the discs and pedestals).
pub(crate) fn shaft_energy_fraction(rotor: &Rotor, shape: &[faer::c64]) -> f64 {
    let quad = |m: &dyn Fn(usize, usize) -> f64, dofs: &mut dyn Iterator<Item = usize>| {
        let d: Vec<usize> = dofs.collect();
        let mut s = 0.0;
        for (a, &i) in d.iter().enumerate() {
            for (b, &j) in d.iter().enumerate() {
                s += m(a, b) * (shape[i].conj() * shape[j]).re;
            }
        }
        s
    };
    let total = quad(&|a, b| rotor.mass[(a, b)], &mut (0..rotor.n_dof()));
    let mut shaft = 0.0;
    for (e, el) in rotor.elements.iter().enumerate() {
        let me = el.mass();
        shaft += quad(&|a, b| me[a][b], &mut (4 * e..4 * e + 8));
    }
    if total > 0.0 {
        shaft / total
    } else {
        0.0
    }
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

/// A damped mode with its shape.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeShape {
    /// Frequency, damping and whirl sense.
    pub mode: Mode,
    /// Complex amplitude of every global DOF (rigid bearings' journals zero), unit norm in the
    /// inner product of [`mode_tracking`](super::mode_tracking) (tilts weighted by ℓ²).
    pub shape: Shape,
}

/// Coefficients of every bearing at one speed (rigid bearings carry zeros: they are constraints).
pub type BearingCoefficientSet = Vec<FilmCoefficients>;

/// Two eigenvalues closer than this (relative to |λ|) are one repeated eigenvalue: the solver's
/// round-off on the stiff massless-shaft models is a few 1e-6 of ω.
const REPEATED_EIGENVALUE_REL: f64 = 1e-5;

/// Damped modes at spin `speed_rad_s` (rad/s) with bearing coefficients `coefficients` (one per
/// bearing), sorted by frequency; overdamped (real) eigenvalues and the modes of a massless
/// shaft's own mass (see [`NaturalFrequencies`]) are left out.
pub fn damped_modes(
    rotor: &Rotor,
    speed_rad_s: f64,
    coefficients: &[FilmCoefficients],
) -> Result<Vec<Mode>, RotorError> {
    Ok(damped_mode_shapes(rotor, speed_rad_s, coefficients)?
        .into_iter()
        .map(|m| m.mode)
        .collect())
}

/// [`damped_modes`] with their shapes. A repeated eigenvalue's eigenvectors are rotated into
/// the modes of extreme whirl sense (circular forward and backward for an isotropic rotor), so
/// that their labels and shapes are defined.
pub fn damped_mode_shapes(
    rotor: &Rotor,
    speed_rad_s: f64,
    coefficients: &[FilmCoefficients],
) -> Result<Vec<ModeShape>, RotorError> {
    let (values, mut shapes) = state_eigen(rotor, speed_rad_s, coefficients)?;
    let (n_nodes, ell2) = (rotor.n_nodes(), tilt_weight_m2(rotor));
    let mut start = 0;
    while start < values.len() {
        let mut end = start + 1;
        while end < values.len()
            && (values[end] - values[start]).norm()
                <= REPEATED_EIGENVALUE_REL * values[start].norm()
        {
            end += 1;
        }
        rotate_to_whirl_senses(&mut shapes[start..end], n_nodes, ell2);
        start = end;
    }
    let massless = massless_shaft(rotor);
    let mut out = Vec::new();
    for (lam, mut shape) in values.into_iter().zip(shapes) {
        if massless && shaft_energy_fraction(rotor, &shape) > 0.5 {
            continue;
        }
        normalise(&mut shape, n_nodes, ell2);
        let s = sense(&shape, &shape, n_nodes, ell2).re;
        out.push(ModeShape {
            mode: Mode {
                frequency_hz: lam.im / (2.0 * PI),
                log_dec: -2.0 * PI * lam.re / lam.im,
                damping_ratio: -lam.re / lam.re.hypot(lam.im),
                direction: if s <= 0.0 {
                    WhirlDirection::Forward
                } else {
                    WhirlDirection::Backward
                },
            },
            shape,
        });
    }
    Ok(out)
}

/// The linear system at spin `speed_rad_s` with bearing coefficients `coefficients`.
pub(crate) struct Assembled {
    /// M + M_bearings (the films' added mass, weightless).
    pub m: Mat<f64>,
    /// K + K_bearings.
    pub k: Mat<f64>,
    /// C + ΩG + C_bearings.
    pub c: Mat<f64>,
    /// The DOFs left free (all but the rigid bearings' journals).
    pub free: Vec<usize>,
}

/// The full mass, stiffness and damping of the rotor on its linearised bearings at spin
/// `speed_rad_s`, and the DOFs left free.
pub(crate) fn assembled_matrices(
    rotor: &Rotor,
    speed_rad_s: f64,
    coefficients: &[FilmCoefficients],
) -> Assembled {
    let n_all = rotor.n_dof();
    let mut m = rotor.mass.clone();
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
        let sides: Vec<([usize; 2], f64)> = match b.pedestal_dofs {
            Some(p) => vec![(b.journal_dofs, 1.0), (p, -1.0)],
            None => vec![(b.journal_dofs, 1.0)],
        };
        for &(di, si) in &sides {
            for &(dj, sj) in &sides {
                for i in 0..2 {
                    for j in 0..2 {
                        k[(di[i], dj[j])] += si * sj * coef.stiffness_n_per_m[(i, j)];
                        c[(di[i], dj[j])] += si * sj * coef.damping_n_s_per_m[(i, j)];
                        m[(di[i], dj[j])] += si * sj * coef.added_mass_kg[(i, j)];
                    }
                }
            }
        }
    }
    let free = (0..n_all).filter(|d| !held.contains(d)).collect();
    Assembled { m, k, c, free }
}

/// Eigenvalues λ (Im λ > 0, ascending) of the state-space form ż = A z,
/// A = [[0, I], [−M⁻¹K, −M⁻¹(C + ΩG)]], and the displacement half of each eigenvector on the
/// global DOFs (held DOFs zero).
/// What to say when the eigenvalue solver of the damped modes fails (`what`: the solver's
/// own word, e.g. NoConvergence): the speed, and the bearing coefficient that is not a finite
/// number or, failing that, the largest one (issue 15, item 21: "NoConvergence" named nothing).
fn eigen_failure(
    what: &str,
    rotor: &Rotor,
    speed_rad_s: f64,
    coefficients: &[FilmCoefficients],
) -> String {
    const NAMES: [[&str; 2]; 2] = [["xx", "xy"], ["yx", "yy"]];
    let mut entries = Vec::new();
    for (b, c) in rotor.bearings.iter().zip(coefficients) {
        for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            let n = NAMES[i][j];
            entries.push((
                b.name.as_str(),
                format!("k_{n}"),
                c.stiffness_n_per_m[(i, j)],
                "N/m",
            ));
            entries.push((
                b.name.as_str(),
                format!("c_{n}"),
                c.damping_n_s_per_m[(i, j)],
                "N·s/m",
            ));
        }
    }
    let bad = entries.iter().find(|e| !e.2.is_finite());
    let largest = entries
        .iter()
        .max_by(|a, b| a.2.abs().total_cmp(&b.2.abs()));
    let cause = match (bad, largest) {
        (Some((b, f, v, u)), _) => format!("bearing {b}: {f} = {v} {u} is not a finite number"),
        (None, Some((b, f, v, u))) => format!(
            "every bearing coefficient is finite; the largest is bearing {b}'s {f} = {v:.3e} {u}"
        ),
        (None, None) => "the machine has no film bearing".into(),
    };
    format!(
        "the eigenvalue solver failed ({what}) at {:.1} rpm (speed_rad_s = {speed_rad_s}): {cause}",
        crate::units::rad_s_to_rpm(speed_rad_s)
    )
}

fn state_eigen(
    rotor: &Rotor,
    speed_rad_s: f64,
    coefficients: &[FilmCoefficients],
) -> Result<(Vec<faer::c64>, Vec<Shape>), RotorError> {
    let n_all = rotor.n_dof();
    let Assembled {
        m: m_all,
        k,
        c,
        free: dofs,
    } = assembled_matrices(rotor, speed_rad_s, coefficients);
    let n = dofs.len();
    let fail = |why: String| RotorError::LinearAlgebra {
        what: "damped modes",
        why,
    };
    let m = Mat::<f64>::from_fn(n, n, |i, j| m_all[(dofs[i], dofs[j])]);
    let llt = m
        .llt(Side::Lower)
        .map_err(|_| fail("the mass matrix is not positive definite".into()))?;
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
    let eig = a.eigen().map_err(|e| {
        fail(eigen_failure(
            &format!("{e:?}"),
            rotor,
            speed_rad_s,
            coefficients,
        ))
    })?;
    let values = eig.S().column_vector();
    // eigenvectors of the balanced matrix D⁻¹AD are D⁻¹ times those of A
    let u = eig.U();
    let mut modes: Vec<(faer::c64, Shape)> = Vec::new();
    for (col, lam) in values.iter().enumerate() {
        if lam.im <= 1e-6 * lam.re.abs().max(1.0) || !lam.im.is_finite() {
            continue;
        }
        let mut shape = vec![faer::c64::new(0.0, 0.0); n_all];
        for (r, &d) in dofs.iter().enumerate() {
            shape[d] = u[(r, col)] * scale[r];
        }
        modes.push((*lam, shape));
    }
    modes.sort_by(|a, b| a.0.im.total_cmp(&b.0.im));
    Ok(modes.into_iter().unzip())
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
    /// Track id of each mode: the same id at two speeds is the same mode, followed by its shape
    /// (MAC ≥ 0.5 with the speed before); ids are numbered as the modes first appear.
    pub tracks: Vec<usize>,
    /// Eccentricity ratio of each film bearing at its static equilibrium (0 for others).
    pub eccentricity_ratios: Vec<f64>,
    /// The bearing coefficients used.
    #[serde(skip)]
    pub coefficients: BearingCoefficientSet,
}

/// The film solvers of a rotor's bearings, reused from speed to speed (warm starts).
/// With a step (share of the clearance), the convective inertia's slopes are taken with the
/// pressure zone following the state ([`super::zone_following`]).
pub(crate) struct BearingSolvers(Vec<Option<Box<dyn FilmModel + Send>>>, Option<f64>);

impl BearingSolvers {
    pub(crate) fn new(rotor: &Rotor) -> Self {
        Self(
            rotor
                .bearings
                .iter()
                .map(|b| match &b.model {
                    BearingModel::Film(f) => Some(f.solver()),
                    _ => None,
                })
                .collect(),
            None,
        )
    }

    /// These film solvers, one per bearing in the rotor's order (None for a bearing without a
    /// film): e.g. the thermal films of [`super::stability_threshold_thermal`].
    pub(crate) fn from_films(films: Vec<Option<Box<dyn FilmModel + Send>>>) -> Self {
        Self(films, None)
    }

    /// These solvers, the convective inertia's slopes taken with the zone following the state
    /// (central differences, steps `step` × c and × c ω).
    pub(crate) fn following_zone(self, step: f64) -> Self {
        Self(self.0, Some(step))
    }

    /// The tabulated film of every film bearing (plain bearings on the finite model; others an
    /// error naming the bearing).
    pub(crate) fn tabulated(rotor: &Rotor) -> Result<Self, RotorError> {
        let solvers = rotor.bearings.iter().map(|b| match &b.model {
            BearingModel::Film(f) => {
                f.tabulated_solver()
                    .map(Some)
                    .map_err(|cause| RotorError::Film {
                        bearing: b.name.clone(),
                        speed_rpm: 0.0,
                        cause,
                    })
            }
            _ => Ok(None),
        });
        Ok(Self(solvers.collect::<Result<_, _>>()?, None))
    }

    /// Coefficients and eccentricity ratios of every bearing at its static equilibrium under
    /// `loads` (N) at `speed_rad_s` (rad/s).
    pub(crate) fn at_speed(
        &mut self,
        rotor: &Rotor,
        loads: &[[f64; 2]],
        speed_rad_s: f64,
    ) -> Result<(BearingCoefficientSet, Vec<f64>), RotorError> {
        let mut coefs = Vec::new();
        let mut eps = Vec::new();
        let follow = self.1;
        for ((b, solver), load) in rotor.bearings.iter().zip(&mut self.0).zip(loads) {
            let (coef, e) = match (&b.model, solver) {
                (BearingModel::Film(f), Some(s)) => {
                    let fail = |cause| RotorError::Film {
                        bearing: b.name.clone(),
                        speed_rpm: rad_s_to_rpm(speed_rad_s),
                        cause,
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
                        let eq = f
                            .equilibrium(s.as_mut(), *load, speed_rad_s)
                            .map_err(fail)?;
                        let mut c = f.with_added_mass(
                            eq.coefficients,
                            eq.position_m,
                            &eq.film,
                            speed_rad_s,
                        );
                        if let Some(step) = follow {
                            let [dk, dc] = super::zone_following::following_minus_held(
                                f,
                                s.as_mut(),
                                &eq,
                                speed_rad_s,
                                step,
                            )
                            .map_err(fail)?;
                            c.stiffness_n_per_m += dk;
                            c.damping_n_s_per_m += dc;
                        }
                        (c, eq.eccentricity_ratio)
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
/// film bearings linearised at their static equilibrium under the loads of `statics`; each mode
/// carries a track id that follows its shape from speed to speed (MAC, see
/// [`mode_tracking`](super::mode_tracking)).
pub fn campbell(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: &[f64],
    n_modes: usize,
) -> Result<Vec<CampbellPoint>, RotorError> {
    campbell_with(
        rotor,
        statics,
        speeds_rpm,
        n_modes,
        BearingSolvers::new(rotor),
    )
}

/// [`campbell`] on every film bearing's tabulated film with the convective inertia's slopes of
/// `fluid_inertia: full` taken with the pressure zone and κ following the state
/// ([`super::zone_following`], steps `step` × c and × c ω): the eigenvalues whose threshold is
/// [`stability_threshold_zone_following`]'s (one linearisation for the diagram and the
/// threshold). Without the convective inertia the tabulated film's held diagram.
pub fn campbell_zone_following(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: &[f64],
    n_modes: usize,
    step: f64,
) -> Result<Vec<CampbellPoint>, RotorError> {
    let solvers = BearingSolvers::tabulated(rotor)?.following_zone(step);
    campbell_with(rotor, statics, speeds_rpm, n_modes, solvers)
}

/// The Campbell diagram with these film solvers.
fn campbell_with(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: &[f64],
    n_modes: usize,
    mut solvers: BearingSolvers,
) -> Result<Vec<CampbellPoint>, RotorError> {
    let (n_nodes, ell2) = (rotor.n_nodes(), tilt_weight_m2(rotor));
    // a few modes more than shown are followed, so that a mode entering from above keeps its id
    let followed = n_modes + 4;
    let mut previous: Vec<(usize, Shape)> = Vec::new();
    let mut next_id = 0;
    let mut out = Vec::with_capacity(speeds_rpm.len());
    for &rpm in speeds_rpm {
        let omega = crate::units::rpm_to_rad_s(rpm);
        let (coefs, eps) = solvers.at_speed(rotor, &statics.bearing_loads_n, omega)?;
        let mut shapes = damped_mode_shapes(rotor, omega, &coefs)?;
        shapes.truncate(followed);
        let current: Vec<Shape> = shapes.iter().map(|m| m.shape.clone()).collect();
        let tracks = assign_tracks(&previous, &current, n_nodes, ell2, &mut next_id);
        previous = tracks.iter().copied().zip(current).collect();
        out.push(CampbellPoint {
            speed_rpm: rpm,
            modes: shapes.iter().take(n_modes).map(|m| m.mode).collect(),
            tracks: tracks.into_iter().take(n_modes).collect(),
            eccentricity_ratios: eps,
            coefficients: coefs,
        });
    }
    Ok(out)
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
    let solvers = BearingSolvers::new(rotor);
    threshold_with(rotor, statics, [from_rpm, to_rpm, step_rpm], solvers)
}

/// [`stability_threshold`] over `[from, to, step]` (rpm) with every film bearing's tabulated
/// film (equilibria and coefficients from the table's interpolant,
/// [`crate::film::TabulatedFilm`]): the threshold the twin's table implies (README "The film
/// table's resolution").
pub fn stability_threshold_tabulated(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: [f64; 3],
) -> Result<Option<Threshold>, RotorError> {
    threshold_with(
        rotor,
        statics,
        speeds_rpm,
        BearingSolvers::tabulated(rotor)?,
    )
}

/// [`stability_threshold_tabulated`] with the convective inertia's slopes of `fluid_inertia:
/// full` taken with the pressure zone and κ following the state, as the transient has them
/// ([`super::zone_following`], steps `step` × c and × c ω; [`ZONE_FOLLOWING_STEP`] in the
/// plateau): the linearisation of the transient, whose threshold the held slopes of
/// [`stability_threshold`] miss by 180 rpm on the seed machine (README "The transient's own
/// threshold with `full`"). Without the convective inertia the same as
/// [`stability_threshold_tabulated`].
///
/// [`ZONE_FOLLOWING_STEP`]: super::ZONE_FOLLOWING_STEP
pub fn stability_threshold_zone_following(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: [f64; 3],
    step: f64,
) -> Result<Option<Threshold>, RotorError> {
    threshold_with(
        rotor,
        statics,
        speeds_rpm,
        BearingSolvers::tabulated(rotor)?.following_zone(step),
    )
}

/// The threshold search over `[from, to, step]` (rpm) with these film solvers.
pub(super) fn threshold_with(
    rotor: &Rotor,
    statics: &StaticSolution,
    [from_rpm, to_rpm, step_rpm]: [f64; 3],
    mut solvers: BearingSolvers,
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

#[cfg(test)]
mod eigen_failure_tests {
    use super::*;

    /// The damped modes with a NaN film coefficient: an error, or at least no panic; the error
    /// text names the bearing and the coefficient (issue 15, item 21).
    #[test]
    fn an_eigen_failure_names_the_bearing_and_the_coefficient() {
        let rotor = Rotor::from_description(&crate::rotor::MachineDescription::builtin_default());
        let mut coefficients = vec![
            FilmCoefficients {
                stiffness_n_per_m: nalgebra::Matrix2::new(1e8, 2e7, -3e7, 9e7),
                damping_n_s_per_m: nalgebra::Matrix2::from_diagonal_element(1e5),
                ..FilmCoefficients::default()
            };
            rotor.bearings.len()
        ];
        coefficients[0].stiffness_n_per_m[(0, 0)] = 2e8;
        let ok = eigen_failure("NoConvergence", &rotor, 900.0, &coefficients);
        let first = &rotor.bearings[0].name;
        assert!(
            ok.contains("NoConvergence") && ok.contains("8594.4 rpm"),
            "{ok}"
        );
        assert!(
            ok.contains(&format!("bearing {first}'s k_xx = 2.000e8 N/m")),
            "{ok}"
        );
        let last = rotor.bearings.len() - 1;
        coefficients[last].damping_n_s_per_m[(1, 0)] = f64::NAN;
        let bad = eigen_failure("NoConvergence", &rotor, 900.0, &coefficients);
        let name = &rotor.bearings[last].name;
        assert!(
            bad.contains(&format!(
                "bearing {name}: c_yx = NaN N·s/m is not a finite number"
            )),
            "{bad}"
        );
        if let Err(e) = damped_modes(&rotor, 900.0, &coefficients) {
            assert!(e.to_string().contains("c_yx = NaN"), "{e}");
        }
    }
}

#[cfg(test)]
mod balance_tests {
    use super::*;

    /// A state-like matrix B (random, order 1) disguised as A = S B S⁻¹ with S spanning 10⁻⁶…10⁶
    /// (the spread of the rotor's state matrix between its order-1 and order-ω² blocks).
    /// Balancing is a similarity by powers of two: D⁻¹ A D is reproduced exactly from the D it
    /// returns, and faer's eigenvalues of the balanced A equal faer's eigenvalues of B (a second
    /// route to the same spectrum) to 1e-9 of the spectral radius.
    #[test]
    fn balancing_keeps_the_spectrum_faer_finds_unscaled() {
        use rand::{Rng, SeedableRng};
        let n = 12;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
        let mut rnd = || rng.random_range(-0.5..0.5);
        let b = Mat::<f64>::from_fn(n, n, |_, _| rnd());
        let s: Vec<f64> = (0..n)
            .map(|i| 10f64.powf(-6.0 + 12.0 * i as f64 / (n - 1) as f64))
            .collect();
        let a = Mat::<f64>::from_fn(n, n, |i, j| s[i] * b[(i, j)] / s[j]);
        let (balanced, d) = balance(a.clone());
        for i in 0..n {
            assert!(
                d[i].log2().fract() == 0.0,
                "D[{i}] = {} is not a power of two",
                d[i]
            );
            for j in 0..n {
                assert_eq!(balanced[(i, j)], a[(i, j)] / d[i] * d[j], "({i}, {j})");
            }
        }
        let spectrum = |m: &Mat<f64>| {
            let mut v: Vec<faer::c64> = m.eigenvalues().expect("eigenvalues").into_iter().collect();
            v.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
            v
        };
        let (got, want) = (spectrum(&balanced), spectrum(&b));
        let radius = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
        for (g, w) in got.iter().zip(&want) {
            assert!((*g - *w).norm() < 1e-9 * radius, "{g:?} vs {w:?}");
        }
    }
}
