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
//! What this leaves out, stated: the convective inertia (of the same order as the temporal at
//! Re* ≈ 1 but smaller in the added mass of a whirling journal, San Andrés & Vance), the
//! h-weighting of the finite film's circumferential flow beyond κ, and the inertia's dependence
//! on velocity (only the acceleration term is kept). An option for studies (machine file
//! `fluid_inertia: temporal`), not the default: the seed's model has no film inertia.

use super::BearingGeometry;
use super::{FilmCoefficients, FilmResult};
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
}

/// The data the added mass of one bearing needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmInertia {
    radius_m: f64,
    length_m: f64,
    clearance_m: f64,
    density_kg_m3: f64,
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
        }
    }

    /// `coef` (the film's eight coefficients at position `position_m`, film `film`, viscosity
    /// `viscosity_pa_s`) with this film's added mass.
    pub fn add_to(
        &self,
        coef: FilmCoefficients,
        position_m: [f64; 2],
        film: &FilmResult,
        viscosity_pa_s: f64,
    ) -> FilmCoefficients {
        FilmCoefficients {
            added_mass_kg: self.added_mass(
                position_m,
                film,
                &coef.damping_n_s_per_m,
                viscosity_pa_s,
            ),
            ..coef
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
        damping: &[[f64; 2]; 2],
        viscosity_pa_s: f64,
    ) -> [[f64; 2]; 2] {
        let Some((start, span)) = active_zone(film) else {
            return [[0.0; 2]; 2];
        };
        let c = self.clearance_m;
        let z = zone_integrals([position_m[0] / c, position_m[1] / c], start, span);
        let l3 = self.length_m.powi(3);
        let squeeze_scale = viscosity_pa_s * self.radius_m * l3 / c.powi(3);
        let short_trace = squeeze_scale * (z.squeeze[0] + z.squeeze[2]);
        let film_trace = damping[0][0] + damping[1][1];
        let kappa = if short_trace > 0.0 && film_trace.is_finite() {
            (film_trace / short_trace).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let s = kappa * self.density_kg_m3 * self.radius_m * l3 / (12.0 * c);
        let [xx, xy, yy] = z.inertia.map(|v| s * v);
        [[xx, xy], [xy, yy]]
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

/// Simpson's rule over `ZONE_PANELS` panels of [start, start + span], the nodes' cos and sin
/// advanced by one rotation each (no trigonometric call inside the loop).
fn zone_integrals(pos: [f64; 2], start: f64, span: f64) -> ZoneIntegrals {
    let d = span / ZONE_PANELS as f64;
    let (sd, cd) = d.sin_cos();
    let (mut s, mut co) = start.sin_cos();
    let mut out = ZoneIntegrals::default();
    for k in 0..=ZONE_PANELS {
        let w = if k == 0 || k == ZONE_PANELS {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        } * d
            / 3.0;
        let h = (1.0 - pos[0] * co - pos[1] * s).max(1e-6);
        let (wi, ws) = (w / h, w / (h * h * h));
        let nn = [co * co, co * s, s * s];
        for m in 0..3 {
            out.inertia[m] += wi * nn[m];
            out.squeeze[m] += ws * nn[m];
        }
        (s, co) = (s * cd + co * sd, co * cd - s * sd);
    }
    out
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
            &[[c_short, 0.0], [0.0, c_short]],
            mu,
        );
        let expected = PI * 900.0 * 0.03 * 0.03_f64.powi(3) / (12.0 * 40e-6);
        assert!(
            (m[0][0] / expected - 1.0).abs() < 1e-9,
            "{m:?} vs {expected}"
        );
        assert!((m[1][1] / expected - 1.0).abs() < 1e-9);
        assert!(m[0][1].abs() < 1e-9 * expected);
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
        let film_trace = coef.damping_n_s_per_m[0][0] + coef.damping_n_s_per_m[1][1];
        assert!(
            (film_trace / trace - 1.0).abs() < 0.01,
            "{film_trace} vs {trace}"
        );
    }
}
