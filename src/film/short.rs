//! Ocvirk's short-bearing film with the π-film (half-Sommerfeld) condition.
//!
//! Dropping the circumferential pressure flow from seed eq. 2 leaves, in the fixed frame,
//!
//! ```text
//!   p(θ, z) = (3µ/h³)(z² − L²/4) g(θ),   g = ω ∂h/∂θ + 2 ∂h/∂t = A sin θ − B cos θ,
//!   A = ω x − 2ẏ,   B = ω y + 2ẋ,
//! ```
//!
//! kept where positive, i.e. where g < 0: exactly half the circle, θ ∈ (β + π, β + 2π) with
//! β = atan2(B, A). Integrating over z (∫(z² − L²/4) dz = −L³/6) leaves one integral over θ,
//! taken by composite Gauss–Legendre quadrature; the coefficients differentiate under the
//! integral (the integrand vanishes at both ends of the zone). Friswell et al., *Dynamics of
//! Rotating Machines* (CUP 2010), ch. 5.

use super::coefficients::FilmCoefficients;
use super::error::FilmError;
use super::geometry::{BearingGeometry, Lubricant};
use super::{wrap_angle_rad, FilmModel, FilmResult, JournalKinematics};
use std::f64::consts::PI;

/// 8-point Gauss–Legendre abscissae on [−1, 1] (positive half).
const GL_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
/// Matching weights.
const GL_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];
/// Panels of the composite rule over the half circle.
const PANELS: usize = 32;

/// The short-bearing film model.
#[derive(Debug, Clone)]
pub struct ShortFilm {
    geometry: BearingGeometry,
    lubricant: Lubricant,
    /// The state of the last solve (for the pressure profile).
    last: JournalKinematics,
}

/// Integrals over the pressure zone gathered by one quadrature pass.
#[derive(Default)]
struct ZoneIntegrals {
    /// ∫ g/h³ (cos, sin) dθ
    force: [f64; 2],
    /// ∂/∂(x, y, ẋ, ẏ) of the force integral
    d_force: [[f64; 2]; 4],
    /// ∫ g ∂h/∂θ / h³ dθ
    shear: f64,
    /// (θ, p) of the largest mid-plane pressure sampled
    peak: (f64, f64),
}

impl ShortFilm {
    /// A short-bearing model; grooves are not represented (a π-film over half the circle).
    pub fn new(geometry: BearingGeometry, lubricant: Lubricant) -> Result<Self, FilmError> {
        geometry.validate()?;
        let lubricant = Lubricant::new(lubricant.density_kg_m3, lubricant.viscosity_pa_s)?;
        Ok(Self {
            geometry,
            lubricant,
            last: JournalKinematics::default(),
        })
    }

    /// Integrates over the pressure zone that starts at `start` (rad).
    fn integrate(
        &self,
        kin: &JournalKinematics,
        start: f64,
        with_derivatives: bool,
    ) -> ZoneIntegrals {
        let [x, y] = kin.position_m;
        let [vx, vy] = kin.velocity_m_s;
        let w = kin.speed_rad_s;
        let c = self.geometry.radial_clearance_m;
        let mu = self.lubricant.viscosity_pa_s;
        let l = self.geometry.length_m;
        let (a, b) = (w * x - 2.0 * vy, w * y + 2.0 * vx);
        let mut out = ZoneIntegrals::default();
        let half = 0.5 * PI / PANELS as f64;
        for panel in 0..PANELS {
            let mid = start + (2 * panel + 1) as f64 * half;
            for (gx, gw) in GL_X.iter().zip(GL_W) {
                for t in [mid - gx * half, mid + gx * half] {
                    let (s, co) = t.sin_cos();
                    let h = c - x * co - y * s;
                    let g = a * s - b * co;
                    let h3 = h * h * h;
                    let wt = gw * half;
                    let f = g / h3;
                    out.force[0] += wt * f * co;
                    out.force[1] += wt * f * s;
                    out.shear += wt * f * (x * s - y * co);
                    let p_mid = -0.75 * mu * l * l * f;
                    if p_mid > out.peak.1 {
                        out.peak = (t, p_mid);
                    }
                    if with_derivatives {
                        // ∂(g/h³)/∂q = g_q/h³ − 3 g h_q/h⁴
                        let h4 = h3 * h;
                        let dq = [
                            w * s / h3 - 3.0 * g * (-co) / h4,
                            -w * co / h3 - 3.0 * g * (-s) / h4,
                            -2.0 * co / h3,
                            -2.0 * s / h3,
                        ];
                        for (d, v) in out.d_force.iter_mut().zip(dq) {
                            d[0] += wt * v * co;
                            d[1] += wt * v * s;
                        }
                    }
                }
            }
        }
        out
    }

    fn solve_inner(
        &self,
        kin: &JournalKinematics,
        with_derivatives: bool,
    ) -> Result<(FilmResult, ZoneIntegrals), FilmError> {
        kin.validate(self.geometry.radial_clearance_m)?;
        let [x, y] = kin.position_m;
        let [vx, vy] = kin.velocity_m_s;
        let w = kin.speed_rad_s;
        let (a, b) = (w * x - 2.0 * vy, w * y + 2.0 * vx);
        let r = self.geometry.radius_m();
        let l = self.geometry.length_m;
        let c = self.geometry.radial_clearance_m;
        let mu = self.lubricant.viscosity_pa_s;
        let eps = kin.eccentricity_ratio(c);
        // Couette friction over 360°: ∫ dθ/h = 2π / (c √(1 − ε²))
        let couette = mu * w * r.powi(3) * l * 2.0 * PI / (c * (1.0 - eps * eps).sqrt());
        if a == 0.0 && b == 0.0 {
            let res = FilmResult {
                friction_torque_n_m: couette,
                power_loss_w: couette * w,
                ..FilmResult::default()
            };
            return Ok((res, ZoneIntegrals::default()));
        }
        let beta = b.atan2(a);
        let start = beta + PI;
        let zi = self.integrate(kin, start, with_derivatives);
        // F = (µ R L³ / 2) ∫ g/h³ (cos, sin) dθ
        let k = 0.5 * mu * r * l.powi(3);
        // T_p = (µ R L³ / 4) ∫ g h_θ / h³ dθ
        let torque = couette + 0.5 * k * zi.shear;
        let amplitude = a.hypot(b);
        let res = FilmResult {
            force_n: [k * zi.force[0], k * zi.force[1]],
            max_pressure_pa: zi.peak.1,
            max_pressure_angle_rad: wrap_angle_rad(zi.peak.0),
            film_start_rad: wrap_angle_rad(start),
            film_end_rad: wrap_angle_rad(start + PI),
            friction_torque_n_m: torque,
            power_loss_w: torque * w,
            // Q_s = 2 ∫ (h³/12µ)(−∂p/∂z) R dθ at z = L/2, = R L √(A² + B²)
            side_flow_m3_s: r * l * amplitude,
            // Couette flow into the zone at ζ1 (the short theory has no circumferential pressure flow)
            inflow_m3_s: 0.5 * w * r * l * (c - x * start.cos() - y * start.sin()),
        };
        Ok((res, zi))
    }
}

impl FilmModel for ShortFilm {
    fn geometry(&self) -> &BearingGeometry {
        &self.geometry
    }

    fn clone_box(&self) -> Box<dyn FilmModel + Send> {
        Box::new(self.clone())
    }

    fn solve(&mut self, kin: &JournalKinematics) -> Result<FilmResult, FilmError> {
        let r = self.solve_inner(kin, false).map(|(r, _)| r)?;
        self.last = *kin;
        Ok(r)
    }

    fn midplane_pressure(&self, out: &mut [f64]) {
        // p(θ, 0) = −(3µL²/4) g/h³ where g < 0 (π-film)
        let [x, y] = self.last.position_m;
        let [vx, vy] = self.last.velocity_m_s;
        let w = self.last.speed_rad_s;
        let (a, b) = (w * x - 2.0 * vy, w * y + 2.0 * vx);
        let c = self.geometry.radial_clearance_m;
        let k = 0.75 * self.lubricant.viscosity_pa_s * self.geometry.length_m.powi(2);
        let len = out.len().max(1) as f64;
        for (i, p) in out.iter_mut().enumerate() {
            let (s, co) = (std::f64::consts::TAU * i as f64 / len).sin_cos();
            let h = c - x * co - y * s;
            *p = (-k * (a * s - b * co) / (h * h * h)).max(0.0);
        }
    }

    fn solve_with_coefficients(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<(FilmResult, FilmCoefficients), FilmError> {
        let (res, zi) = self.solve_inner(kin, true)?;
        self.last = *kin;
        let k = 0.5
            * self.lubricant.viscosity_pa_s
            * self.geometry.radius_m()
            * self.geometry.length_m.powi(3);
        let mut out = FilmCoefficients::default();
        for i in 0..2 {
            for j in 0..2 {
                out.stiffness_n_per_m[(i, j)] = -k * zi.d_force[j][i];
                out.damping_n_s_per_m[(i, j)] = -k * zi.d_force[2 + j][i];
            }
        }
        Ok((res, out))
    }
}
