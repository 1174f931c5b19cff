//! Steady unbalance response of the linear model (the analysis of API 684 §2.5 and ROSS's
//! `run_unbalance_response`): at each speed Ω the film bearings are linearised at their static
//! equilibrium and the harmonic equations
//!   [K(Ω) − Ω² M + iΩ (C(Ω) + Ω G)] Q = F,   F = m e Ω² e^{iφ} (1, −i) at each unbalance node
//! are solved for the complex 1X amplitudes Q (x(t) = Re(X e^{iΩt})). Then per station the peaks,
//! their amplification factors by the half-power method and the separation margins that API 684
//! (after API 617) requires of them.

use super::modal::{assembled_matrices, BearingSolvers};
use super::{BearingModel, Rotor, RotorError, StaticSolution};
use crate::units::rpm_to_rad_s;
use faer::linalg::solvers::Solve;
use faer::{c64, Mat};
use serde::Serialize;

/// Where the response is read.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Station {
    /// Name of the bearing or probe station.
    pub name: String,
    /// "bearing" (journal relative to its pedestal) or "probe" (shaft at the probe node).
    pub kind: &'static str,
    /// Shaft node.
    pub node: usize,
}

/// The 1X response of one station at one speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StationResponse {
    /// Amplitude of x (m).
    pub x_amplitude_m: f64,
    /// Phase lag of x behind the rotor's angle-0 mark (the keyphasor), x = A cos(Ωt − lag) (deg,
    /// 0–360).
    pub x_phase_lag_deg: f64,
    /// Amplitude of y (m).
    pub y_amplitude_m: f64,
    /// Phase lag of y (deg, 0–360), y = A cos(Ωt − lag).
    pub y_phase_lag_deg: f64,
    /// Semi-major axis of the 1X orbit ellipse (m): forward + backward radius.
    pub major_semi_axis_m: f64,
}

/// A response peak of one station and what API 684 asks of it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResponsePeak {
    /// Peak speed N_c (rpm), by a parabola through the three grid points about the maximum.
    pub speed_rpm: f64,
    /// Semi-major axis there (m).
    pub amplitude_m: f64,
    /// Speeds N₁ < N_c < N₂ where the amplitude is the peak's / √2 (rpm), if both are in range.
    pub half_power_rpm: Option<[f64; 2]>,
    /// Amplification factor AF = N_c / (N₂ − N₁) (half-power method, API 684 §2.5.1).
    pub amplification_factor: Option<f64>,
    /// Separation margin from the operating speed range (%): below it (N_min − N_c)/N_min,
    /// above it (N_c − N_max)/N_max; negative inside the range.
    pub separation_margin_pct: f64,
    /// Margin API 684 / API 617 requires: none (0) for AF < 2.5 (critically damped); below the
    /// range min(16, 17(1 − 1/(AF − 1.5))) %, above it min(26, 10 + 17(1 − 1/(AF − 1.5))) %.
    pub required_margin_pct: f64,
    /// Whether the separation margin meets the required one.
    pub meets_api_684: bool,
}

/// The unbalance response over a speed range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnbalanceResponse {
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// The stations: the film (and linear) bearings first, then the probe stations.
    pub stations: Vec<Station>,
    /// `response[s][k]`: station s at speed k.
    pub response: Vec<Vec<StationResponse>>,
}

/// The stations of a rotor: every non-rigid bearing and every probe station.
pub fn response_stations(rotor: &Rotor) -> Vec<Station> {
    let bearings = rotor
        .bearings
        .iter()
        .filter(|b| !matches!(b.model, BearingModel::Rigid))
        .map(|b| Station {
            name: b.name.clone(),
            kind: "bearing",
            node: b.node,
        });
    let probes = rotor.probes.iter().map(|p| Station {
        name: p.name.clone(),
        kind: "probe",
        node: p.node,
    });
    bearings.chain(probes).collect()
}

/// The 1X unbalance response at each speed of `speeds_rpm` (rpm, > 0) to the machine's
/// unbalances, the film bearings linearised at their static equilibrium under `statics`.
pub fn unbalance_response(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: &[f64],
) -> Result<UnbalanceResponse, RotorError> {
    response_with(rotor, statics, speeds_rpm, BearingSolvers::new(rotor))
}

/// [`unbalance_response`] on every film bearing's tabulated film with the convective inertia's
/// slopes of `fluid_inertia: full` taken with the pressure zone and κ following the state
/// (steps `step` × c and × c ω; [`super::ZONE_FOLLOWING_STEP`]), as
/// [`super::stability_threshold_zone_following`] takes them: the linearisation of the
/// transient on the table. The added mass is the same as [`unbalance_response`]'s.
pub fn unbalance_response_zone_following(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: &[f64],
    step: f64,
) -> Result<UnbalanceResponse, RotorError> {
    let solvers = BearingSolvers::tabulated(rotor)?.following_zone(step);
    response_with(rotor, statics, speeds_rpm, solvers)
}

/// The unbalance response with these film solvers.
fn response_with(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: &[f64],
    mut solvers: BearingSolvers,
) -> Result<UnbalanceResponse, RotorError> {
    if let Some(&bad) = speeds_rpm.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(RotorError::InvalidInput {
            name: "unbalance-response speed (rpm)",
            value: bad,
            rule: "must be finite and above zero",
        });
    }
    let stations = response_stations(rotor);
    let mut response = vec![Vec::with_capacity(speeds_rpm.len()); stations.len()];
    for &rpm in speeds_rpm {
        let omega = rpm_to_rad_s(rpm);
        let (coefs, _) = solvers.at_speed(rotor, &statics.bearing_loads_n, omega)?;
        let q = harmonic_solution(rotor, omega, &coefs)?;
        for (s, st) in stations.iter().enumerate() {
            let (x, y) = station_motion(rotor, st, &q);
            response[s].push(station_response(x, y));
        }
    }
    Ok(UnbalanceResponse {
        speeds_rpm: speeds_rpm.to_vec(),
        stations,
        response,
    })
}

// --- calibration from measurements (issue 12) ---
/// Influence coefficients of the linear model at `speed_rpm` (rpm): `h[plane][station]` is the
/// complex 1X displacement `[X, Y]` (m per kg·m) of probe station `station` (machine frame,
/// x = Re(X e^{iΩt}), the rotor's angle-0 mark as phase reference) to a unit unbalance m·e =
/// 1 kg·m with its heavy spot at angle 0 in unbalance plane `plane` (the machine's list). The
/// response is linear in the unbalance: Σ_p h[p] u_p with u_p = m e e^{iφ_p}.
pub fn influence_coefficients(
    rotor: &Rotor,
    statics: &StaticSolution,
    speed_rpm: f64,
) -> Result<Vec<Vec<[c64; 2]>>, RotorError> {
    if !(speed_rpm.is_finite() && speed_rpm > 0.0) {
        return Err(RotorError::InvalidInput {
            name: "influence-coefficient speed (rpm)",
            value: speed_rpm,
            rule: "must be finite and above zero",
        });
    }
    let omega = rpm_to_rad_s(speed_rpm);
    let mut solvers = BearingSolvers::new(rotor);
    let (coefs, _) = solvers.at_speed(rotor, &statics.bearing_loads_n, omega)?;
    let mut out = Vec::with_capacity(rotor.unbalance.len());
    for u in &rotor.unbalance {
        let unit = [super::Unbalance {
            node: u.node,
            magnitude_kg_m: 1.0,
            phase_rad: 0.0,
            correction_radius_m: None,
        }];
        let q = harmonic_solution_for(rotor, omega, &coefs, &unit)?;
        let per_station = rotor
            .probes
            .iter()
            .map(|p| [q[4 * p.node], q[4 * p.node + 1]])
            .collect();
        out.push(per_station);
    }
    Ok(out)
}

/// The journals' 1X orbits of the linear model at `speed_rpm` (rpm) under `unbalance` instead of
/// the machine's: per bearing of `rotor.bearings` (in its order) the complex amplitudes `[X, Y]`
/// (m) of the journal relative to its pedestal (x = Re(X e^{iΩt})). The viscosity fit's orbits
/// (`calibrate::journal_orbits`).
pub fn journal_orbits(
    rotor: &Rotor,
    statics: &StaticSolution,
    speed_rpm: f64,
    unbalance: &[super::Unbalance],
) -> Result<Vec<[c64; 2]>, RotorError> {
    let omega = rpm_to_rad_s(speed_rpm);
    let mut solvers = BearingSolvers::new(rotor);
    let (coefs, _) = solvers.at_speed(rotor, &statics.bearing_loads_n, omega)?;
    let q = harmonic_solution_for(rotor, omega, &coefs, unbalance)?;
    Ok(rotor
        .bearings
        .iter()
        .map(|b| {
            let st = Station {
                name: b.name.clone(),
                kind: "bearing",
                node: b.node,
            };
            let (x, y) = station_motion(rotor, &st, &q);
            [x, y]
        })
        .collect())
}
// --- end calibration from measurements ---

/// Complex 1X amplitudes of every global DOF (held DOFs zero) at spin `omega` (rad/s).
fn harmonic_solution(
    rotor: &Rotor,
    omega: f64,
    coefs: &[crate::film::FilmCoefficients],
) -> Result<Vec<c64>, RotorError> {
    harmonic_solution_for(rotor, omega, coefs, &rotor.unbalance)
}

/// The same for the unbalances `unbalance` instead of the machine's.
fn harmonic_solution_for(
    rotor: &Rotor,
    omega: f64,
    coefs: &[crate::film::FilmCoefficients],
    unbalance: &[super::Unbalance],
) -> Result<Vec<c64>, RotorError> {
    let sys = assembled_matrices(rotor, omega, coefs);
    let dofs = &sys.free;
    let n = dofs.len();
    let w2 = omega * omega;
    let a = Mat::<c64>::from_fn(n, n, |i, j| {
        let (di, dj) = (dofs[i], dofs[j]);
        c64::new(
            sys.k[(di, dj)] - w2 * sys.m[(di, dj)],
            omega * sys.c[(di, dj)],
        )
    });
    let mut f_full = vec![c64::new(0.0, 0.0); rotor.n_dof()];
    for u in unbalance {
        let f = c64::new(u.phase_rad.cos(), u.phase_rad.sin()) * (u.magnitude_kg_m * w2);
        f_full[4 * u.node] += f;
        f_full[4 * u.node + 1] += f * c64::new(0.0, -1.0);
    }
    let b = Mat::<c64>::from_fn(n, 1, |i, _| f_full[dofs[i]]);
    let x = a.partial_piv_lu().solve(&b);
    if !(0..n).all(|i| x[(i, 0)].re.is_finite() && x[(i, 0)].im.is_finite()) {
        return Err(RotorError::LinearAlgebra {
            what: "unbalance response",
            why: format!(
                "the dynamic stiffness is singular at {:.1} rpm",
                crate::units::rad_s_to_rpm(omega)
            ),
        });
    }
    let mut q = vec![c64::new(0.0, 0.0); rotor.n_dof()];
    for (i, &d) in dofs.iter().enumerate() {
        q[d] = x[(i, 0)];
    }
    Ok(q)
}

/// Complex x and y of a station: the shaft at a probe's node; a journal relative to its pedestal.
fn station_motion(rotor: &Rotor, st: &Station, q: &[c64]) -> (c64, c64) {
    let (mut x, mut y) = (q[4 * st.node], q[4 * st.node + 1]);
    if st.kind == "bearing" {
        if let Some(p) = rotor
            .bearings
            .iter()
            .find(|b| b.name == st.name)
            .and_then(|b| b.pedestal_dofs)
        {
            x -= q[p[0]];
            y -= q[p[1]];
        }
    }
    (x, y)
}

fn station_response(x: c64, y: c64) -> StationResponse {
    let lag = |z: c64| (-z.arg()).to_degrees().rem_euclid(360.0);
    let i = c64::new(0.0, 1.0);
    // forward circle |X + iY|/2, backward |X − iY|/2
    let forward = (x + i * y).norm() / 2.0;
    let backward = (x - i * y).norm() / 2.0;
    StationResponse {
        x_amplitude_m: x.norm(),
        x_phase_lag_deg: lag(x),
        y_amplitude_m: y.norm(),
        y_phase_lag_deg: lag(y),
        major_semi_axis_m: forward + backward,
    }
}

/// API 684's required separation margin (%) of a peak with amplification factor `af`,
/// below (`above` false) or above the operating range (API 617 §2.6.2.10, as API 684 cites it).
pub fn required_separation_margin_pct(af: f64, above: bool) -> f64 {
    if af < 2.5 {
        return 0.0;
    }
    let base = 17.0 * (1.0 - 1.0 / (af - 1.5));
    if above {
        (10.0 + base).min(26.0)
    } else {
        base.min(16.0)
    }
}

/// Least fall on each side of a peak, relative to it, for it to count: smaller wiggles are the
/// film coefficients' solver tolerance, not resonances.
const PEAK_PROMINENCE: f64 = 0.05;

/// Whether the local maximum at `k` falls by [`PEAK_PROMINENCE`] on both sides before the curve
/// rises above it again.
fn prominent(a: &[f64], k: usize) -> bool {
    let floor = (1.0 - PEAK_PROMINENCE) * a[k];
    let falls = |it: &mut dyn Iterator<Item = &f64>| {
        for &v in it {
            if v > a[k] {
                return false;
            }
            if v <= floor {
                return true;
            }
        }
        false
    };
    falls(&mut a[..k].iter().rev()) && falls(&mut a[k + 1..].iter())
}

/// The peaks of the semi-major axis `amplitude_m` over `speeds_rpm` (interior local maxima that
/// stand 5 % above the curve on both sides),
/// with amplification factors and separation margins from the operating range
/// [`min_operating_rpm`, `max_continuous_rpm`].
pub fn response_peaks(
    speeds_rpm: &[f64],
    amplitude_m: &[f64],
    min_operating_rpm: f64,
    max_continuous_rpm: f64,
) -> Vec<ResponsePeak> {
    let mut out = Vec::new();
    for k in 1..amplitude_m.len().saturating_sub(1) {
        let (a0, a1, a2) = (amplitude_m[k - 1], amplitude_m[k], amplitude_m[k + 1]);
        if !(a1 > a0 && a1 >= a2 && prominent(amplitude_m, k)) {
            continue;
        }
        // vertex of the parabola through the three points
        let (s0, s1, s2) = (speeds_rpm[k - 1], speeds_rpm[k], speeds_rpm[k + 1]);
        let den = (s0 - s1) * (s0 - s2) * (s1 - s2);
        let pa = (s2 * (a1 - a0) + s1 * (a0 - a2) + s0 * (a2 - a1)) / den;
        let pb = (s2 * s2 * (a0 - a1) + s1 * s1 * (a2 - a0) + s0 * s0 * (a1 - a2)) / den;
        let (nc, peak) = if pa < 0.0 {
            let v = -pb / (2.0 * pa);
            let pc = a1 - pa * s1 * s1 - pb * s1;
            (v, pa * v * v + pb * v + pc)
        } else {
            (s1, a1)
        };
        let half = peak / std::f64::consts::SQRT_2;
        let crossing = |range: &mut dyn Iterator<Item = usize>| {
            for j in range {
                let (i0, i1) = if j < k { (j, j + 1) } else { (j, j - 1) };
                let (b0, b1) = (amplitude_m[i0], amplitude_m[i1]);
                if b0 <= half && b1 > half {
                    let t = (half - b0) / (b1 - b0);
                    return Some(speeds_rpm[i0] + t * (speeds_rpm[i1] - speeds_rpm[i0]));
                }
            }
            None
        };
        let n1 = crossing(&mut (0..k).rev());
        let n2 = crossing(&mut (k + 1..amplitude_m.len()));
        let half_power_rpm = n1.zip(n2).map(|(a, b)| [a, b]);
        let af = half_power_rpm.map(|[a, b]| nc / (b - a));
        let above = nc > max_continuous_rpm;
        let margin = if above {
            100.0 * (nc - max_continuous_rpm) / max_continuous_rpm
        } else if nc < min_operating_rpm {
            100.0 * (min_operating_rpm - nc) / min_operating_rpm
        } else {
            -100.0 * (nc - min_operating_rpm).min(max_continuous_rpm - nc) / max_continuous_rpm
        };
        // a peak whose AF is unknown (half-power points outside the range) is held to the
        // strictest margin
        let required = af.map_or(if above { 26.0 } else { 16.0 }, |af| {
            required_separation_margin_pct(af, above)
        });
        out.push(ResponsePeak {
            speed_rpm: nc,
            amplitude_m: peak,
            half_power_rpm,
            amplification_factor: af,
            separation_margin_pct: margin,
            required_margin_pct: required,
            meets_api_684: required == 0.0 || margin >= required,
        });
    }
    out
}
