//! The convective film inertia's slopes with the pressure zone following the journal (README
//! "The transient against its linearisation"): in the transient the zone ζ1 … ζ2 and the length
//! factor κ move with the journal's state, and eq. I1's inertia pressure does not vanish at ζ1,
//! ζ2, so their motion adds stiffness and damping that the held slopes of
//! [`FilmInertia::convective_coefficients`](crate::film::FilmInertia::convective_coefficients)
//! leave out. Central differences of the transient's own force (film solved at the moved and
//! moving journal) give them; on the tabulated film (ζ1, ζ2 and κ interpolated, smooth in the
//! state) steps of 0.01–0.3 % of the clearance agree within 1 % (the plateau, README).

use super::FilmBearing;
use crate::film::{Equilibrium, FilmError, FilmModel, JournalKinematics};
use nalgebra::Matrix2;

/// Default finite-difference step, as a share of the clearance c in position and of c ω in
/// velocity: 0.1 %, inside the measured plateau (0.01–0.3 %; 1 % shows the nonlinearity).
pub const ZONE_FOLLOWING_STEP: f64 = 1e-3;

/// The convective inertia's slopes of bearing `f` at its equilibrium `eq` (speed `speed_rad_s`,
/// film `solver`) with the zone and κ following the state, minus the held slopes: [ΔK (N/m),
/// ΔC (N·s/m)] to add to the coefficients of [`FilmBearing::with_added_mass`]. Central
/// differences of eq. I1's force, steps `step` × c in position and `step` × c ω in velocity.
/// Zero for a bearing without the convective inertia (`fluid_inertia` none or temporal: the
/// zone moves only the added mass, whose force has no linear part at rest).
pub fn following_minus_held(
    f: &FilmBearing,
    solver: &mut dyn FilmModel,
    eq: &Equilibrium,
    speed_rad_s: f64,
    step: f64,
) -> Result<[Matrix2<f64>; 2], FilmError> {
    let Some(inertia) = f.inertia.filter(|i| i.convective) else {
        return Ok([Matrix2::zeros(); 2]);
    };
    let mu = f.viscosity_pa_s();
    let w = speed_rad_s;
    let mut force = |d: [f64; 2], v: [f64; 2]| -> Result<[f64; 2], FilmError> {
        let kin = JournalKinematics {
            position_m: d,
            velocity_m_s: v,
            speed_rad_s: w,
        };
        let (r, c) = solver.solve_with_coefficients(&kin)?;
        let kappa = inertia.length_factor(d, &r, &c.damping_n_s_per_m, mu);
        Ok(inertia.transient_force(d, v, &r, w, kappa).force_n)
    };
    let clearance = f.geometry.radial_clearance_m;
    let (dx, dv, d0) = (step * clearance, step * clearance * w, eq.position_m);
    let mut out = [Matrix2::zeros(); 2];
    for j in 0..2 {
        let (mut dp, mut dm, mut vp, mut vm) = (d0, d0, [0.0; 2], [0.0; 2]);
        dp[j] += dx;
        dm[j] -= dx;
        vp[j] += dv;
        vm[j] -= dv;
        let (fdp, fdm) = (force(dp, [0.0; 2])?, force(dm, [0.0; 2])?);
        let (fvp, fvm) = (force(d0, vp)?, force(d0, vm)?);
        for i in 0..2 {
            out[0][(i, j)] = -(fdp[i] - fdm[i]) / (2.0 * dx);
            out[1][(i, j)] = -(fvp[i] - fvm[i]) / (2.0 * dv);
        }
    }
    let kappa = inertia.length_factor(d0, &eq.film, &eq.coefficients.damping_n_s_per_m, mu);
    let held = inertia.convective_coefficients(d0, &eq.film, w, kappa);
    Ok([
        out[0] - held.stiffness_n_per_m,
        out[1] - held.damping_n_s_per_m,
    ])
}
