//! The bearing's own heating by an **effective temperature** (issue 12): Raimondi & Boyd's
//! (1958, part III) adiabatic heat balance as design texts state it (Shigley's Mechanical
//! Engineering Design, the temperature-rise equation of its journal-bearing chapter).
//!
//! All the friction power P_f of the film goes into the oil (no conduction into journal or
//! bush: adiabatic). The oil Q enters the pressure zone at the supply temperature T_s; the side
//! flow Q_s leaks out of the ends on the way, on average half-heated (T_s + ΔT/2), the rest
//! Q − Q_s leaves at T_s + ΔT. The balance
//!
//!   P_f = ρ c_p ΔT (Q − Q_s/2)                                                    (H1)
//!
//! gives the temperature rise ΔT, and the viscosity of the whole film is taken at one
//! effective temperature
//!
//!   T_eff = T_s + k ΔT                                                             (H2)
//!
//! with k the hot-oil carry-over factor (k = 1/2: Raimondi–Boyd's and Shigley's mean film
//! temperature T_s + ΔT/2; larger k stands for hot oil carried over past the supply into the
//! next pass). Since P_f, Q and Q_s depend on µ(T_eff), (H1)–(H2) are solved as a fixed point
//! through the oil's viscosity–temperature law. **An approximation**: one viscosity for the
//! whole film (no temperature field, no viscosity varying around or across the film), no heat
//! into the solids, constant ρ and c_p.

use super::{equilibrium_under_load, Equilibrium, FilmResult, ViscosityLaw, ViscosityScaledFilm};

/// The effective-temperature option of a film bearing's oil.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OilHeating {
    /// Specific heat capacity c_p of the oil (J/(kg·K)).
    pub specific_heat_j_per_kg_k: f64,
    /// Hot-oil carry-over factor k of (H2), 0 < k ≤ 1.
    pub carry_over: f64,
}

/// Specific heats accepted (J/(kg·K)): mineral and synthetic oils are 1,700–2,300, refrigerants
/// and water up to 4,200; outside this range it is a unit error.
pub const SPECIFIC_HEAT_RANGE_J_PER_KG_K: std::ops::RangeInclusive<f64> = 500.0..=10_000.0;

impl OilHeating {
    /// The option, checked: c_p in [`SPECIFIC_HEAT_RANGE_J_PER_KG_K`], 0 < k ≤ 1. Err names the
    /// field and the value.
    pub fn new(specific_heat_j_per_kg_k: f64, carry_over: f64) -> Result<Self, String> {
        if !(specific_heat_j_per_kg_k.is_finite()
            && SPECIFIC_HEAT_RANGE_J_PER_KG_K.contains(&specific_heat_j_per_kg_k))
        {
            return Err(format!(
                "specific_heat_j_per_kg_k {specific_heat_j_per_kg_k} must be between {} and {} J/(kg·K)",
                SPECIFIC_HEAT_RANGE_J_PER_KG_K.start(),
                SPECIFIC_HEAT_RANGE_J_PER_KG_K.end()
            ));
        }
        if !(carry_over.is_finite() && carry_over > 0.0 && carry_over <= 1.0) {
            return Err(format!(
                "carry_over {carry_over} must be above 0 and at most 1"
            ));
        }
        Ok(Self {
            specific_heat_j_per_kg_k,
            carry_over,
        })
    }

    /// ΔT of (H1) for the film solution `film` of an oil of density `density_kg_m3` (K), or
    /// None where the flows carry no heat (Q − Q_s/2 ≤ 0: a film with no pressure zone).
    pub fn temperature_rise_k(&self, film: &FilmResult, density_kg_m3: f64) -> Option<f64> {
        let carried = film.inflow_m3_s - 0.5 * film.side_flow_m3_s;
        (carried > 0.0 && film.power_loss_w.is_finite()).then(|| {
            film.power_loss_w.abs() / (density_kg_m3 * self.specific_heat_j_per_kg_k * carried)
        })
    }
}

/// A film bearing at its effective temperature: the fixed point of (H1)–(H2).
#[derive(Debug, Clone, PartialEq)]
pub struct EffectiveTemperature {
    /// Oil supply temperature T_s (K).
    pub supply_temperature_k: f64,
    /// Effective temperature T_eff (K).
    pub effective_temperature_k: f64,
    /// Temperature rise ΔT through the film (K): (T_eff − T_s)/k.
    pub temperature_rise_k: f64,
    /// Viscosity µ(T_eff) (Pa·s).
    pub viscosity_pa_s: f64,
    /// Friction power P_f at T_eff (W).
    pub friction_power_w: f64,
    /// Heat the oil carries away at the temperature found, ρ c_p ((T_eff − T_s)/k) (Q − Q_s/2)
    /// (W): equal to `friction_power_w` at the fixed point (H1).
    pub heat_carried_w: f64,
    /// The static equilibrium at µ(T_eff).
    pub equilibrium: Equilibrium,
    /// Evaluations of the film equilibrium the fixed point took.
    pub evaluations: usize,
}

/// Largest number of film equilibria the fixed point may take.
const MAX_EVALUATIONS: usize = 80;
/// The fixed point is found when T_eff moves less than this (K).
const TEMPERATURE_TOLERANCE_K: f64 = 1e-9;

/// The effective temperature of the bearing whose film (solved at `reference_viscosity_pa_s`,
/// scaled) is `film`, under static load `load_n` (N, the journal's force on the film, machine
/// frame) at `speed_rad_s`, with oil supplied at `supply_k` (K) of density `density_kg_m3`
/// following `law`. g(T) = T_s + k ΔT(µ(T)) falls as T rises (a thinner oil dissipates less),
/// so h(T) = g(T) − T has one root, bracketed by [T_s, g(T_s)] and found by the Illinois
/// variant of regula falsi. The film's scale is left at the root. Err says why (a temperature
/// beyond the law's range, a film that does not carry the load).
#[allow(clippy::too_many_arguments)]
pub fn effective_temperature(
    film: &mut ViscosityScaledFilm,
    reference_viscosity_pa_s: f64,
    law: &ViscosityLaw,
    heating: &OilHeating,
    density_kg_m3: f64,
    supply_k: f64,
    load_n: [f64; 2],
    speed_rad_s: f64,
) -> Result<EffectiveTemperature, String> {
    let evaluations = std::cell::Cell::new(0);
    let mut at = |t_k: f64| -> Result<(f64, Equilibrium), String> {
        evaluations.set(evaluations.get() + 1);
        let mu = law.checked_viscosity_pa_s(t_k)?;
        film.set_scale(mu / reference_viscosity_pa_s)
            .map_err(|e| e.to_string())?;
        let eq = equilibrium_under_load(film, mu, load_n, speed_rad_s)
            .map_err(|e| format!("film equilibrium at {t_k:.2} K: {e}"))?;
        let rise = heating
            .temperature_rise_k(&eq.film, density_kg_m3)
            .ok_or("the film carries no flow through its pressure zone")?;
        Ok((supply_k + heating.carry_over * rise - t_k, eq))
    };
    let (h_lo, eq0) = at(supply_k)?;
    if h_lo <= TEMPERATURE_TOLERANCE_K {
        return Ok(done(
            supply_k,
            supply_k,
            eq0,
            heating,
            law,
            density_kg_m3,
            1,
        ));
    }
    let top = law.range_k()[1];
    let mut hi = (supply_k + h_lo).min(top);
    let (mut h_hi, eq_hi) = at(hi)?;
    if h_hi > 0.0 {
        return Err(format!(
            "the effective temperature lies beyond the viscosity law's range (up to {:.1} °C)",
            top - super::ZERO_CELSIUS_K
        ));
    }
    let (mut lo, mut h_lo) = (supply_k, h_lo);
    // the point evaluated last: the root when |h| or the bracket is below the tolerance
    let (mut last_t, mut last_h, mut last_eq) = (hi, h_hi, eq_hi);
    let mut side = 0;
    while last_h.abs() > TEMPERATURE_TOLERANCE_K && hi - lo > TEMPERATURE_TOLERANCE_K {
        if evaluations.get() >= MAX_EVALUATIONS {
            return Err(format!(
                "the effective temperature did not converge in {MAX_EVALUATIONS} film equilibria"
            ));
        }
        let t = (lo * h_hi - hi * h_lo) / (h_hi - h_lo);
        let (h, eq) = at(t)?;
        if h > 0.0 {
            (lo, h_lo) = (t, h);
            if side == -1 {
                h_hi *= 0.5;
            }
            side = -1;
        } else {
            (hi, h_hi) = (t, h);
            if side == 1 {
                h_lo *= 0.5;
            }
            side = 1;
        }
        (last_t, last_h, last_eq) = (t, h, eq);
    }
    Ok(done(
        supply_k,
        last_t,
        last_eq,
        heating,
        law,
        density_kg_m3,
        evaluations.get(),
    ))
}

#[allow(clippy::too_many_arguments)]
fn done(
    supply_k: f64,
    t_k: f64,
    equilibrium: Equilibrium,
    heating: &OilHeating,
    law: &ViscosityLaw,
    density_kg_m3: f64,
    evaluations: usize,
) -> EffectiveTemperature {
    let f = &equilibrium.film;
    let rise_k = (t_k - supply_k) / heating.carry_over;
    EffectiveTemperature {
        supply_temperature_k: supply_k,
        effective_temperature_k: t_k,
        temperature_rise_k: rise_k,
        viscosity_pa_s: law.viscosity_pa_s(t_k),
        friction_power_w: f.power_loss_w.abs(),
        heat_carried_w: density_kg_m3
            * heating.specific_heat_j_per_kg_k
            * rise_k
            * (f.inflow_m3_s - 0.5 * f.side_flow_m3_s),
        equilibrium,
        evaluations,
    }
}
