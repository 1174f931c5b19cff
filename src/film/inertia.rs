//! The film's temporal fluid inertia as added-mass coefficients (issue 11).
//!
//! The Reynolds equation (seed eq. 2) drops the fluid's inertia; its modified Reynolds number
//! Re* = ρωc²/µ is ≈ 1.7 in the seed case at 9,000 rpm, not ≪ 1. To first order in Re* the
//! dominant part for a whirling journal is the temporal inertia ρ ∂u/∂t of the squeeze flow
//! (Reinhardt & Lund, J. Lubr. Technol. 97 (1975) 159; San Andrés & Vance, ASLE Trans. 30 (1987)
//! 63, for the short squeeze film). With the film's momentum integrated across its thickness and
//! the parabolic profile of the pressure flow, the short bearing (axial flow only) gives
//!
//! * squeeze pressure  ∫p dz = µ L³ (n·v) / h³  → damping  c_ij = µ R L³ ∫ n_i n_j / h³ dθ,
//! * inertia pressure  ∫p dz = ρ L³ (n·a) / (12 h) → added mass  m_ij = ρ R L³ / 12 ∫ n_i n_j / h dθ,
//!
//! with n = (cos θ, sin θ), h = c (1 − x/c cos θ − y/c sin θ), v and a the journal's velocity
//! and acceleration, the integrals over the film's active (pressurised) zone ζ1 … ζ2: none of the
//! ruptured zone's fluid carries pressure. The centred full film gives m = π ρ R L³ / (12 c),
//! the classical short-damper value. For a finite length the short bearing overestimates both
//! pressures alike (for a uniform h the inertia pressure is ρh²/(12µ) times the squeeze pressure,
//! at any length), so the short form's added mass is scaled by the ratio of the finite film's own
//! squeeze damping to the short form's at the same state, κ = tr c_film / tr c_short ≤ 1.
//! `temporal` leaves out the convective inertia and the inertia's dependence on velocity (only
//! the acceleration term is kept); `full` adds them (eq. I1: the linear analyses' coefficients,
//! the transient's force). Both leave out the h-weighting of the finite film's circumferential
//! flow beyond κ. Options for studies (machine file `fluid_inertia`), not the default: the
//! seed's model has no film inertia.

use super::BearingGeometry;
use super::{FilmCoefficients, FilmResult};
use nalgebra::Matrix2;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// Panels of the zone integrals (Simpson's rule, an even count). Convergence study
/// (`zone_integrals_converge`): at ε = 0.95 on a π zone the added mass moves 0.03 % and the
/// short damping 0.3 % from 64 to 256 panels; 64 it is.
const ZONE_PANELS: usize = 64;

/// Whether a film bearing carries its film's fluid inertia (machine file `fluid_inertia`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum FluidInertia {
    /// The Reynolds equation as it is: no film inertia (the seed's model).
    #[default]
    None,
    /// The temporal inertia of the squeeze flow as added-mass coefficients (this module).
    Temporal,
    /// The temporal added mass plus the first-order convective and velocity-dependent inertia
    /// of the rotating film (eq. I1): for linear analyses (`modes`, `response`, the linear
    /// coupling) as stiffness and damping corrections ([`FilmInertia::convective_coefficients`]),
    /// in the nonlinear transient and the twin as a force at the journal's state
    /// ([`FilmInertia::transient_force`]).
    Full,
}

/// The data the added mass of one bearing needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmInertia {
    radius_m: f64,
    length_m: f64,
    clearance_m: f64,
    density_kg_m3: f64,
    /// Whether the convective inertia joins the linear coefficients (`FluidInertia::Full`).
    pub convective: bool,
}

/// ∫ n_i n_j / h̄ dθ and ∫ n_i n_j / h̄³ dθ over a zone, as (xx, xy, yy) (h̄ = h / c).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct ZoneIntegrals {
    inertia: [f64; 3],
    squeeze: [f64; 3],
}

impl FilmInertia {
    /// For a bearing of `geometry` lubricated by oil of density `density_kg_m3` (kg/m³).
    pub fn new(geometry: &BearingGeometry, density_kg_m3: f64) -> Self {
        Self {
            radius_m: 0.5 * geometry.diameter_m,
            length_m: geometry.length_m,
            clearance_m: geometry.radial_clearance_m,
            density_kg_m3,
            convective: false,
        }
    }

    /// `coef` (the film's eight coefficients at position `position_m`, film `film`, viscosity
    /// `viscosity_pa_s`) with this film's added mass, and with `convective` also the convective
    /// inertia's stiffness and damping at shaft speed `speed_rad_s` (a journal at rest).
    pub fn add_to(
        &self,
        coef: FilmCoefficients,
        position_m: [f64; 2],
        film: &FilmResult,
        viscosity_pa_s: f64,
        speed_rad_s: f64,
    ) -> FilmCoefficients {
        let damping = &coef.damping_n_s_per_m;
        let added_mass_kg = self.added_mass(position_m, film, damping, viscosity_pa_s);
        if !self.convective {
            return FilmCoefficients {
                added_mass_kg,
                ..coef
            };
        }
        let kappa = self.length_factor(position_m, film, damping, viscosity_pa_s);
        let conv = self.convective_coefficients(position_m, film, speed_rad_s, kappa);
        FilmCoefficients {
            added_mass_kg,
            stiffness_n_per_m: coef.stiffness_n_per_m + conv.stiffness_n_per_m,
            damping_n_s_per_m: coef.damping_n_s_per_m + conv.damping_n_s_per_m,
        }
    }

    /// The added-mass coefficients `[[m_xx, m_xy], [m_yx, m_yy]]` (kg) of the film `film` solved
    /// at journal position `position_m` (m, relative to the bearing), whose squeeze damping is
    /// `damping` (N·s/m) at the running viscosity `viscosity_pa_s`: the film force gains
    /// −m · a, a the journal's acceleration. Zero without a pressurised zone. Allocates nothing.
    pub fn added_mass(
        &self,
        position_m: [f64; 2],
        film: &FilmResult,
        damping: &Matrix2<f64>,
        viscosity_pa_s: f64,
    ) -> Matrix2<f64> {
        let Some((start, span)) = active_zone(film) else {
            return Matrix2::zeros();
        };
        let c = self.clearance_m;
        let z = zone_integrals([position_m[0] / c, position_m[1] / c], start, span);
        let kappa = self.kappa_of(&z, damping, viscosity_pa_s);
        let s = kappa * self.mass_scale();
        let [xx, xy, yy] = z.inertia.map(|v| s * v);
        Matrix2::new(xx, xy, xy, yy)
    }

    /// ρ R L³ / (12 c) (kg): the short film's inertia scale.
    fn mass_scale(&self) -> f64 {
        self.density_kg_m3 * self.radius_m * self.length_m.powi(3) / (12.0 * self.clearance_m)
    }

    /// κ = tr c_film / tr c_short (≤ 1): the finite length's correction of the short form, the
    /// finite film's own squeeze damping `damping` over the short form's at the same state.
    pub fn length_factor(
        &self,
        position_m: [f64; 2],
        film: &FilmResult,
        damping: &Matrix2<f64>,
        viscosity_pa_s: f64,
    ) -> f64 {
        let Some((start, span)) = active_zone(film) else {
            return 1.0;
        };
        let c = self.clearance_m;
        let z = zone_integrals([position_m[0] / c, position_m[1] / c], start, span);
        self.kappa_of(&z, damping, viscosity_pa_s)
    }

    fn kappa_of(&self, z: &ZoneIntegrals, damping: &Matrix2<f64>, viscosity_pa_s: f64) -> f64 {
        let c = self.clearance_m;
        let squeeze_scale = viscosity_pa_s * self.radius_m * self.length_m.powi(3) / c.powi(3);
        let short_trace = squeeze_scale * (z.squeeze[0] + z.squeeze[2]);
        let film_trace = damping.trace();
        if short_trace > 0.0 && film_trace.is_finite() {
            (film_trace / short_trace).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }

    /// The convective (and velocity-dependent temporal) inertia of the rotating film as
    /// stiffness and damping (no added mass), linearised about the journal at rest at
    /// `position_m` (m) at shaft speed `speed_rad_s`, on the pressure zone of `film`, scaled by
    /// the length factor `kappa`. Short bearing, averaged inertia (Szeri, Raimondi & Giron-Duarte,
    /// J. Lubr. Technol. 105 (1983) 326, the momentum integrated across the film; San Andrés &
    /// Vance 1987 for the squeeze film): with the Couette profile circumferentially, the parabolic
    /// profile axially and G = (ω/2) ∂h/∂θ + ∂h/∂t the axial flux per length, the axial momentum
    /// gives the inertia pressure
    ///
    ///   ∫p dz = −ρ L³ / (12 h) · [∂G/∂t + (ω/2) ∂G/∂θ − (12/5) G² / h]                (eq. I1)
    ///
    /// whose ∂²h/∂t² term is the added mass ([`Self::added_mass`]); linear in the journal's
    /// position and velocity about rest, the rest is
    ///   ω ∂ḣ/∂θ − (12/5) ω h_θ ḣ / h   (damping) and (ω²/4)(h_θθ − (12/5) h_θ² / h) (stiffness).
    /// Derivatives with the zone held (as for the added mass). Allocates nothing.
    pub fn convective_coefficients(
        &self,
        position_m: [f64; 2],
        film: &FilmResult,
        speed_rad_s: f64,
        kappa: f64,
    ) -> FilmCoefficients {
        let Some((start, span)) = active_zone(film) else {
            return FilmCoefficients::default();
        };
        let c = self.clearance_m;
        let pos = [position_m[0] / c, position_m[1] / c];
        let z = convective_integrals(pos, start, span);
        let m = kappa * self.mass_scale();
        let w = speed_rad_s;
        let k = |v: f64| -m * 0.25 * w * w * v;
        let d = |v: f64| -m * w * v;
        FilmCoefficients {
            stiffness_n_per_m: z.stiffness.map(k),
            damping_n_s_per_m: z.damping.map(d),
            added_mass_kg: Matrix2::zeros(),
        }
    }

    /// The steady convective inertia force (N) at the equilibrium `eq` (its film and damping
    /// give the zone and κ) at the running viscosity `viscosity_pa_s` and `speed_rad_s`; zero
    /// without `convective`.
    pub fn convective_force_at(
        &self,
        eq: &super::Equilibrium,
        viscosity_pa_s: f64,
        speed_rad_s: f64,
    ) -> [f64; 2] {
        if !self.convective {
            return [0.0; 2];
        }
        let damping = &eq.coefficients.damping_n_s_per_m;
        let kappa = self.length_factor(eq.position_m, &eq.film, damping, viscosity_pa_s);
        self.convective_static_force(eq.position_m, &eq.film, speed_rad_s, kappa)
    }

    /// The steady convective inertia force (N) on the journal at rest at `position_m` (m) at
    /// `speed_rad_s` on the zone of `film`, length factor `kappa`: the (ω²/4) term of eq. I1,
    /// F = ρ R L³ / 12 ∫ n (h_θθ − (12/5) h_θ² / h) (ω²/4) / h dθ. With `full` the linear
    /// analyses' equilibrium carries it (`FilmBearing::equilibrium`).
    pub fn convective_static_force(
        &self,
        position_m: [f64; 2],
        film: &FilmResult,
        speed_rad_s: f64,
        kappa: f64,
    ) -> [f64; 2] {
        let Some((start, span)) = active_zone(film) else {
            return [0.0; 2];
        };
        let c = self.clearance_m;
        let z = convective_integrals([position_m[0] / c, position_m[1] / c], start, span);
        let s = kappa * self.mass_scale() * c * 0.25 * speed_rad_s * speed_rad_s;
        z.force.map(|v| s * v)
    }
}

impl FilmInertia {
    /// The whole of eq. I1 but its ∂²h/∂t² term (the added mass, [`Self::added_mass`]) as a force
    /// (N) on the journal at `position_m` (m) moving at `velocity_m_s` (m/s) at shaft speed
    /// `speed_rad_s`, on the pressure zone of `film` (held), length factor `kappa`, with its
    /// exact derivatives −∂F/∂d and −∂F/∂ḋ at that state (the Newton iteration's Jacobian):
    ///
    ///   F = ρ R L³ / 12 ∫ n B / h dθ,  B = ω ∂ḣ/∂θ + (ω²/4) ∂²h/∂θ² − (12/5) G² / h,
    ///   G = (ω/2) ∂h/∂θ + ḣ.
    ///
    /// At rest it is [`Self::convective_static_force`], its slopes there are
    /// [`Self::convective_coefficients`]; with ω = 0 only the −(12/5) ḣ²/h term is left, quadratic
    /// in the velocity. The ω̇ ∂h/∂θ / 2 term of ∂G/∂t (speed changes) is left out: ω̇ ≪ ω² here.
    /// Allocates nothing.
    pub fn transient_force(
        &self,
        position_m: [f64; 2],
        velocity_m_s: [f64; 2],
        film: &FilmResult,
        speed_rad_s: f64,
        kappa: f64,
    ) -> InertiaForce {
        let c = self.clearance_m;
        let (pos, vel) = (position_m.map(|x| x / c), velocity_m_s.map(|x| x / c));
        let z = match active_zone(film) {
            Some((start, span)) => transient_integrals(pos, vel, speed_rad_s, start, span),
            None => return InertiaForce::default(),
        };
        // ρ R L³ / 12 = mass_scale · c; the derivatives in X = d / c carry 1 / c
        let s = kappa * self.mass_scale() * c;
        InertiaForce {
            force_n: z.force_n.map(|v| s * v),
            stiffness_n_per_m: z.stiffness_n_per_m * (-s / c),
            damping_n_s_per_m: z.damping_n_s_per_m * (-s / c),
        }
    }
}

/// The force of the film's inertia beyond the added mass on a moving journal (eq. I1), and its
/// derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InertiaForce {
    /// Force on the journal (N).
    pub force_n: [f64; 2],
    /// −∂F/∂d (N/m).
    pub stiffness_n_per_m: Matrix2<f64>,
    /// −∂F/∂ḋ (N·s/m).
    pub damping_n_s_per_m: Matrix2<f64>,
}

/// Simpson's rule over `ZONE_PANELS` panels of eq. I1's integrand B̄/h̄ (h̄ = h/c, B̄ = B/c in
/// 1/s²) at dimensionless position `pos` and velocity `vel` (1/s), speed `w`: ∫ n B̄/h̄ and its
/// derivatives ∫ n ∂(B̄/h̄)/∂X_j, ∫ n ∂(B̄/h̄)/∂V_j (unscaled, no sign change).
fn transient_integrals(
    pos: [f64; 2],
    vel: [f64; 2],
    w: f64,
    start: f64,
    span: f64,
) -> InertiaForce {
    let mut out = InertiaForce::default();
    simpson_nodes(pos, start, span, |wt, co, s, h| {
        let h_t = pos[0] * s - pos[1] * co; // ∂h̄/∂θ
        let h_tt = pos[0] * co + pos[1] * s; // ∂²h̄/∂θ²
        let hd = -(vel[0] * co + vel[1] * s); // ∂h̄/∂t
        let hd_t = vel[0] * s - vel[1] * co; // ∂²h̄/∂θ∂t
        let g = 0.5 * w * h_t + hd;
        let b = w * hd_t + 0.25 * w * w * h_tt - 2.4 * g * g / h;
        // ∂/∂X_j: h̄ by dh, h̄_θ by dh_t, h̄_θθ by −dh; ∂/∂V_j: ḣ̄ by dh, ∂ḣ̄/∂θ by dh_t
        let (n, dh, dh_t) = ([co, s], [-co, -s], [s, -co]);
        for i in 0..2 {
            out.force_n[i] += wt * n[i] * b / h;
            for j in 0..2 {
                let db_dx =
                    -0.25 * w * w * dh[j] - 2.4 * (w * g * dh_t[j] / h - g * g * dh[j] / (h * h));
                let df_dx = db_dx / h - b * dh[j] / (h * h);
                let df_dv = (w * dh_t[j] - 4.8 * g * dh[j] / h) / h;
                out.stiffness_n_per_m[(i, j)] += wt * n[i] * df_dx;
                out.damping_n_s_per_m[(i, j)] += wt * n[i] * df_dv;
            }
        }
    });
    out
}

/// The static equilibrium of film `s` (running viscosity `viscosity_pa_s`) under `load` (N) at
/// `speed_rad_s`; with a convective `inertia` the film carries the load plus the steady
/// convective inertia force (fixed point: the force is ≈ 4 % of the load in the seed case, each
/// pass shrinks the change by about that ratio; stops at 1e-9 of `clearance_m`). The one home of
/// this equilibrium for the linear analyses and the twin.
pub fn equilibrium_with_inertia(
    s: &mut dyn super::FilmModel,
    inertia: Option<FilmInertia>,
    viscosity_pa_s: f64,
    load: [f64; 2],
    speed_rad_s: f64,
) -> Result<super::Equilibrium, super::FilmError> {
    let mut eq = super::equilibrium_under_load(s, viscosity_pa_s, load, speed_rad_s)?;
    let Some(inertia) = inertia.filter(|i| i.convective) else {
        return Ok(eq);
    };
    for _ in 0..30 {
        let f = inertia.convective_force_at(&eq, viscosity_pa_s, speed_rad_s);
        let carried = [load[0] + f[0], load[1] + f[1]];
        let next = super::equilibrium_under_load(s, viscosity_pa_s, carried, speed_rad_s)?;
        let moved =
            (next.position_m[0] - eq.position_m[0]).hypot(next.position_m[1] - eq.position_m[1]);
        eq = next;
        if moved < 1e-9 * inertia.clearance_m {
            break;
        }
    }
    Ok(eq)
}

/// The zone integrals of eq. I1's convective terms (dimensionless, h̄ = h/c): the force
/// ∫ n g/h̄, its derivatives ∫ n_i ∂(g/h̄)/∂X_j (stiffness) and ∫ n_i (∂B/∂Ẋ_j)/(ω h̄) (damping),
/// g = h̄_θθ − (12/5) h̄_θ²/h̄.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct ConvectiveIntegrals {
    force: [f64; 2],
    stiffness: Matrix2<f64>,
    damping: Matrix2<f64>,
}

/// Simpson's rule over `ZONE_PANELS` panels, as [`zone_integrals`].
fn convective_integrals(pos: [f64; 2], start: f64, span: f64) -> ConvectiveIntegrals {
    let mut out = ConvectiveIntegrals::default();
    simpson_nodes(pos, start, span, |w, co, s, h| {
        let h_t = pos[0] * s - pos[1] * co; // ∂h̄/∂θ
        let h_tt = 1.0 - h; // ∂²h̄/∂θ²
        let g = h_tt - 2.4 * h_t * h_t / h;
        let n = [co, s];
        // ∂/∂X: h̄ −cos, h̄_θ +sin, h̄_θθ +cos; ∂/∂Y: h̄ −sin, h̄_θ −cos, h̄_θθ +sin
        let dh = [-co, -s];
        let dh_t = [s, -co];
        let df = [0, 1].map(|j| {
            let dg = -dh[j] - 4.8 * h_t * dh_t[j] / h + 2.4 * h_t * h_t * dh[j] / (h * h);
            dg / h - g * dh[j] / (h * h)
        });
        // ḣ̄ = −(Ẋ cos + Ẏ sin), ∂ḣ̄/∂θ = Ẋ sin − Ẏ cos: B/ω = ∂ḣ̄/∂θ − (12/5) h̄_θ ḣ̄/h̄
        let db = [s + 2.4 * h_t * co / h, -co + 2.4 * h_t * s / h];
        for i in 0..2 {
            out.force[i] += w * n[i] * g / h;
            for j in 0..2 {
                out.stiffness[(i, j)] += w * n[i] * df[j];
                out.damping[(i, j)] += w * n[i] * db[j] / h;
            }
        }
    });
    out
}

fn simpson_weight(k: usize) -> f64 {
    if k == 0 || k == ZONE_PANELS {
        1.0
    } else if k % 2 == 1 {
        4.0
    } else {
        2.0
    }
}

/// The pressurised zone (start, span) in rad of a film solution, None if it has none.
fn active_zone(film: &FilmResult) -> Option<(f64, f64)> {
    if film.max_pressure_pa <= 0.0 {
        return None;
    }
    let span = (film.film_end_rad - film.film_start_rad).rem_euclid(TAU);
    // a zone that closes on itself (pressurised all round) is reported start ≈ end
    let span = if span < 1e-9 { TAU } else { span };
    Some((film.film_start_rad, span))
}

/// Simpson's rule over `ZONE_PANELS` panels of [start, start + span] ([`simpson_nodes`]).
fn zone_integrals(pos: [f64; 2], start: f64, span: f64) -> ZoneIntegrals {
    let mut out = ZoneIntegrals::default();
    simpson_nodes(pos, start, span, |w, co, s, h| {
        let (wi, ws) = (w / h, w / (h * h * h));
        let nn = [co * co, co * s, s * s];
        for m in 0..3 {
            out.inertia[m] += wi * nn[m];
            out.squeeze[m] += ws * nn[m];
        }
    });
    out
}

/// Simpson's rule's nodes over `ZONE_PANELS` panels of [start, start + span]: `f(weight, cos θ,
/// sin θ, h̄)` at each, h̄ = 1 − X cos θ − Y sin θ at `pos` (floored at 1e-6), the nodes' cos and
/// sin advanced by one rotation each (no trigonometric call inside the loop).
fn simpson_nodes(pos: [f64; 2], start: f64, span: f64, mut f: impl FnMut(f64, f64, f64, f64)) {
    let d = span / ZONE_PANELS as f64;
    let (sd, cd) = d.sin_cos();
    let (mut s, mut co) = start.sin_cos();
    for k in 0..=ZONE_PANELS {
        let h = (1.0 - pos[0] * co - pos[1] * s).max(1e-6);
        f(simpson_weight(k) * d / 3.0, co, s, h);
        (s, co) = (s * cd + co * sd, co * cd - s * sd);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::{FilmModel, JournalKinematics, Lubricant, ShortFilm};
    use std::f64::consts::PI;

    fn zone(start: f64, end: f64) -> FilmResult {
        FilmResult {
            max_pressure_pa: 1.0,
            film_start_rad: start,
            film_end_rad: end,
            ..FilmResult::default()
        }
    }

    #[test]
    fn centred_full_film_is_the_classical_short_damper_mass() {
        // m = π ρ R L³ / (12 c) (San Andrés & Vance 1987, temporal term; 4.77 kg for the seed's
        // bearing), isotropic; κ = 1 when the given damping is the short form's own
        let g = BearingGeometry::plain(0.060, 0.030, 40e-6).unwrap();
        let inertia = FilmInertia::new(&g, 900.0);
        let mu = 0.8e-3;
        let c_short = PI * mu * 0.03 * 0.03_f64.powi(3) / 40e-6_f64.powi(3);
        let m = inertia.added_mass(
            [0.0; 2],
            &zone(0.0, 0.0),
            &Matrix2::from_diagonal_element(c_short),
            mu,
        );
        let expected = PI * 900.0 * 0.03 * 0.03_f64.powi(3) / (12.0 * 40e-6);
        assert!(
            (m[(0, 0)] / expected - 1.0).abs() < 1e-9,
            "{m:?} vs {expected}"
        );
        assert!((m[(1, 1)] / expected - 1.0).abs() < 1e-9);
        assert!(m[(0, 1)].abs() < 1e-9 * expected);
        assert!((expected - 4.77).abs() < 0.01);
    }

    #[test]
    fn eccentric_zone_integral_equals_the_closed_form() {
        // ∫₀^{2π} cos²θ / (1 + ε cos θ) dθ = 2π (1 − √(1−ε²)) / (ε² √(1−ε²)) (Gradshteyn 3.613),
        // the journal at x = −ε c (h̄ = 1 + ε cos θ)
        for eps in [0.3, 0.7, 0.9] {
            let z = zone_integrals([-eps, 0.0], 0.0, TAU);
            let r = (1.0 - eps * eps).sqrt();
            let exact = TAU * (1.0 - r) / (eps * eps * r);
            assert!(
                (z.inertia[0] / exact - 1.0).abs() < 1e-6,
                "ε {eps}: {} vs {exact}",
                z.inertia[0]
            );
            assert!(z.inertia[1].abs() < 1e-9);
        }
    }

    #[test]
    fn zone_integrals_converge() {
        // the π zone of the short bearing at ε = 0.95: the panel count's convergence study
        let pos = [0.95 * 0.3_f64.cos(), 0.95 * 0.3_f64.sin()];
        let fine = |panels: usize| {
            let d = PI / panels as f64;
            let mut i = [0.0, 0.0];
            for k in 0..panels {
                let t = 0.3 - PI / 2.0 + (k as f64 + 0.5) * d;
                let h = 1.0 - pos[0] * t.cos() - pos[1] * t.sin();
                i[0] += d * t.cos().powi(2) / h;
                i[1] += d * t.cos().powi(2) / h.powi(3);
            }
            i
        };
        let reference = fine(200_000);
        let z = zone_integrals(pos, 0.3 - PI / 2.0, PI);
        assert!(
            (z.inertia[0] / reference[0] - 1.0).abs() < 0.005,
            "{:?} {reference:?}",
            z.inertia
        );
        assert!(
            (z.squeeze[0] / reference[1] - 1.0).abs() < 0.005,
            "{:?} {reference:?}",
            z.squeeze
        );
    }

    #[test]
    fn the_short_film_needs_no_length_correction() {
        // the short-bearing film's own damping is the zone integral of µRL³ n n / h³ over its π
        // film: κ comes out 1 (within the quadrature), the added mass the short form's
        let g = BearingGeometry::plain(0.060, 0.015, 40e-6).unwrap();
        let oil = Lubricant::new(900.0, 0.8e-3).unwrap();
        let mut film = ShortFilm::new(g.clone(), oil).unwrap();
        let pos = [12e-6, -20e-6];
        let (r, coef) = film
            .solve_with_coefficients(&JournalKinematics::at_position(pos, 900.0))
            .unwrap();
        let (start, span) = active_zone(&r).unwrap();
        assert!((span - PI).abs() < 1e-6, "span {span}");
        let z = zone_integrals([pos[0] / 40e-6, pos[1] / 40e-6], start, span);
        let scale = 0.8e-3 * 0.03 * 0.015_f64.powi(3) / 40e-6_f64.powi(3);
        let trace = scale * (z.squeeze[0] + z.squeeze[2]);
        let film_trace = coef.damping_n_s_per_m.trace();
        assert!(
            (film_trace / trace - 1.0).abs() < 0.01,
            "{film_trace} vs {trace}"
        );
    }

    #[test]
    fn centred_full_film_is_the_added_mass_carried_by_the_mean_flow() {
        // Centred, full 2π film: eq. I1 reduces to the added mass m = π ρ R L³/(12c) seen in a
        // frame turning with the film's mean velocity ω/2 (the bulk-flow structure of fluid
        // inertia in annular seals, Childs, Turbomachinery Rotordynamics, 1993, ch. 4):
        // Coriolis damping m ω [[0, 1], [−1, 0]] and centrifugal stiffness −m ω²/4 I, so a
        // forward circular whirl Ω feels m (Ω − ω/2)² r outward; no steady force.
        let g = BearingGeometry::plain(0.060, 0.030, 40e-6).unwrap();
        let inertia = FilmInertia::new(&g, 900.0);
        let w = 942.5;
        let conv = inertia.convective_coefficients([0.0; 2], &zone(0.0, 0.0), w, 1.0);
        let m = PI * 900.0 * 0.03 * 0.03_f64.powi(3) / (12.0 * 40e-6);
        let k = conv.stiffness_n_per_m;
        let c = conv.damping_n_s_per_m;
        let tol = 1e-9 * m * w * w;
        assert!((k[(0, 0)] + m * w * w / 4.0).abs() < tol, "{k:?}");
        assert!((k[(1, 1)] + m * w * w / 4.0).abs() < tol, "{k:?}");
        assert!(k[(0, 1)].abs() < tol && k[(1, 0)].abs() < tol, "{k:?}");
        assert!((c[(0, 1)] - m * w).abs() < 1e-9 * m * w, "{c:?}");
        assert!((c[(1, 0)] + m * w).abs() < 1e-9 * m * w, "{c:?}");
        assert!(c[(0, 0)].abs() < 1e-9 * m * w && c[(1, 1)].abs() < 1e-9 * m * w);
        let f = inertia.convective_static_force([0.0; 2], &zone(0.0, 0.0), w, 1.0);
        assert!(f[0].hypot(f[1]) < 1e-9 * m * w * w * 40e-6, "{f:?}");
    }

    #[test]
    fn convective_stiffness_is_the_slope_of_its_force() {
        // second method: central differences of the steady force (zone held), 2 states
        let g = BearingGeometry::plain(0.060, 0.030, 40e-6).unwrap();
        let inertia = FilmInertia::new(&g, 900.0);
        let w = 942.5;
        for (pos, z) in [
            ([12.8e-6, 17.0e-6], zone(3.766, 1.190)),
            ([-5e-6, 30e-6], zone(-1.2, 2.0)),
        ] {
            let k = inertia
                .convective_coefficients(pos, &z, w, 0.7)
                .stiffness_n_per_m;
            let scale = k.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            let d = 1e-9;
            for j in 0..2 {
                let mut p = pos;
                let mut q = pos;
                p[j] += d;
                q[j] -= d;
                let fp = inertia.convective_static_force(p, &z, w, 0.7);
                let fq = inertia.convective_static_force(q, &z, w, 0.7);
                for i in 0..2 {
                    let fd = -(fp[i] - fq[i]) / (2.0 * d);
                    assert!(
                        (fd - k[(i, j)]).abs() < 1e-5 * scale,
                        "{i}{j}: {fd} vs {}",
                        k[(i, j)]
                    );
                }
            }
        }
    }

    #[test]
    fn seed_bearing_correction_equals_an_independent_quadrature() {
        // The seed bearing at its 9,000 rpm equilibrium (`rotor-twin bearing --speed-rpm 9000
        // --load-n 275`: x = 12.805, y = 17.038 µm, zone 215.78° … 68.20°, κ = 0.6143 from its
        // damping): an independent code (numpy, 4,001-point trapezoid, central differences of
        // the force of eq. I1, tests/reference/convective_inertia_check.py) gave, in MN/m and kN·s/m,
        // ΔK = [[−0.141, 0.721], [−0.668, −0.456]], ΔC = [[1.690, 2.028], [−1.901, 1.257]]
        // and the steady force (−0.664, 11.424) N.
        let g = BearingGeometry::plain(0.060, 0.030, 40e-6).unwrap();
        let inertia = FilmInertia::new(&g, 900.0);
        let w = 9000.0 * PI / 30.0;
        let z = zone(
            215.77863553381786_f64.to_radians(),
            68.2021535739826_f64.to_radians(),
        );
        let pos = [12.805425082239526e-6, 17.03756289405643e-6];
        let kappa = 0.6142900707812364;
        let conv = inertia.convective_coefficients(pos, &z, w, kappa);
        let k_ref = [[-0.141, 0.721], [-0.668, -0.456]];
        let c_ref = [[1.690, 2.028], [-1.901, 1.257]];
        for i in 0..2 {
            for j in 0..2 {
                let k = conv.stiffness_n_per_m[(i, j)] / 1e6;
                let c = conv.damping_n_s_per_m[(i, j)] / 1e3;
                // 3 printed digits: 0.005 of the largest entry
                assert!((k - k_ref[i][j]).abs() < 0.005 * 0.721, "K{i}{j} {k}");
                assert!((c - c_ref[i][j]).abs() < 0.005 * 2.028, "C{i}{j} {c}");
            }
        }
        let f = inertia.convective_static_force(pos, &z, w, kappa);
        assert!(
            (f[0] + 0.664).abs() < 0.02 && (f[1] - 11.424).abs() < 0.02,
            "{f:?}"
        );
    }
}
