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

use super::{
    equilibrium_position, equilibrium_under_load, Equilibrium, FilmModel, FilmResult, ThermalFilm,
    ViscosityLaw, ViscosityScaledFilm,
};

/// The effective-temperature option of a film bearing's oil.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OilHeating {
    /// Specific heat capacity c_p of the oil (J/(kg·K)).
    pub specific_heat_j_per_kg_k: f64,
    /// How the effective temperature is found.
    pub balance: HeatBalance,
}

/// Where the one temperature of the whole film comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HeatBalance {
    /// Raimondi–Boyd's global balance (H1)–(H2), T_eff = T_s + k ΔT; hot-oil carry-over
    /// factor k, 0 < k ≤ 1.
    RaimondiBoyd {
        /// k of (H2).
        carry_over: f64,
    },
    /// The adiabatic thermal film (E1–E3 of [`super::thermal`]): the temperature field around
    /// the bearing under the static load, T_eff its flow-weighted mean temperature (the
    /// effective-temperature route of `modes --thermal`); the film mixes its own carry-over (E3).
    ThermalFilm,
}

impl HeatBalance {
    /// The name a report gives it (`raimondi_boyd`, `thermal_film`).
    pub fn name(&self) -> &'static str {
        match self {
            Self::RaimondiBoyd { .. } => "raimondi_boyd",
            Self::ThermalFilm => "thermal_film",
        }
    }

    /// What [`EffectiveTemperature::effective_temperature_k`] is, for a printed line.
    pub fn temperature_label(&self) -> &'static str {
        match self {
            Self::RaimondiBoyd { .. } => "effective temperature",
            Self::ThermalFilm => "thermal film's mean temperature",
        }
    }

    /// What [`EffectiveTemperature::temperature_rise_k`] is, for a printed line.
    pub fn rise_label(&self) -> &'static str {
        match self {
            Self::RaimondiBoyd { .. } => "ΔT",
            Self::ThermalFilm => "peak rise",
        }
    }
}

/// Specific heats accepted (J/(kg·K)): mineral and synthetic oils are 1,700–2,300, refrigerants
/// and water up to 4,200; outside this range it is a unit error.
pub const SPECIFIC_HEAT_RANGE_J_PER_KG_K: std::ops::RangeInclusive<f64> = 500.0..=10_000.0;

impl OilHeating {
    /// The option, checked: c_p in [`SPECIFIC_HEAT_RANGE_J_PER_KG_K`], 0 < k ≤ 1. Err names the
    /// field and the value.
    pub fn new(specific_heat_j_per_kg_k: f64, carry_over: f64) -> Result<Self, String> {
        Self::checked_specific_heat(specific_heat_j_per_kg_k)?;
        if !(carry_over.is_finite() && carry_over > 0.0 && carry_over <= 1.0) {
            return Err(format!(
                "carry_over {carry_over} must be above 0 and at most 1"
            ));
        }
        Ok(Self {
            specific_heat_j_per_kg_k,
            balance: HeatBalance::RaimondiBoyd { carry_over },
        })
    }

    /// The thermal-film option ([`HeatBalance::ThermalFilm`]), c_p checked as in [`Self::new`].
    pub fn thermal_film(specific_heat_j_per_kg_k: f64) -> Result<Self, String> {
        Self::checked_specific_heat(specific_heat_j_per_kg_k)?;
        Ok(Self {
            specific_heat_j_per_kg_k,
            balance: HeatBalance::ThermalFilm,
        })
    }

    fn checked_specific_heat(specific_heat_j_per_kg_k: f64) -> Result<(), String> {
        if !(specific_heat_j_per_kg_k.is_finite()
            && SPECIFIC_HEAT_RANGE_J_PER_KG_K.contains(&specific_heat_j_per_kg_k))
        {
            return Err(format!(
                "specific_heat_j_per_kg_k {specific_heat_j_per_kg_k} must be between {} and {} J/(kg·K)",
                SPECIFIC_HEAT_RANGE_J_PER_KG_K.start(),
                SPECIFIC_HEAT_RANGE_J_PER_KG_K.end()
            ));
        }
        Ok(())
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

/// A film bearing at its effective temperature: the fixed point of (H1)–(H2), or the thermal
/// film's mean temperature ([`HeatBalance::ThermalFilm`]).
#[derive(Debug, Clone, PartialEq)]
pub struct EffectiveTemperature {
    /// How it was found.
    pub balance: HeatBalance,
    /// Oil supply temperature T_s (K).
    pub supply_temperature_k: f64,
    /// Effective temperature T_eff (K): Raimondi–Boyd's, or the thermal film's flow-weighted
    /// mean temperature.
    pub effective_temperature_k: f64,
    /// Temperature rise ΔT through the film (K): (T_eff − T_s)/k (Raimondi–Boyd); the thermal
    /// film's peak rise T_max − T_s.
    pub temperature_rise_k: f64,
    /// Viscosity µ(T_eff) (Pa·s).
    pub viscosity_pa_s: f64,
    /// Friction power P_f at T_eff (W): the film's `power_loss_w` at µ(T_eff), for either
    /// balance: Couette shear over the full film with the Reynolds condition (Raimondi–Boyd's
    /// friction variable); a mass-conserving film shears its streamers only.
    pub friction_power_w: f64,
    /// Heat the oil carries away at the temperature found (W): Raimondi–Boyd's
    /// ρ c_p ((T_eff − T_s)/k) (Q − Q_s/2), equal to `friction_power_w` at the fixed point (H1);
    /// the thermal film's, equal to its own dissipation (shear in the ruptured zone in its
    /// streamers only, E2), below the full-film friction.
    pub heat_carried_w: f64,
    /// The static equilibrium at µ(T_eff), of the film as the twin runs it: isoviscous for
    /// Raimondi–Boyd's and on a table, with the thermal film's viscosity field on the finite
    /// film.
    pub equilibrium: Equilibrium,
    /// Evaluations of the film equilibrium the fixed point took (the thermal film: one a
    /// staggered pass, and the isoviscous one at µ(T_eff)).
    pub evaluations: usize,
    /// The thermal film's viscosity around the bearing relative to µ(T_eff): µ(T_i)/µ(T̄) per
    /// grid column, T_i its temperatures at the balance (empty for Raimondi–Boyd's, whose film
    /// is isoviscous).
    pub viscosity_field: Vec<f64>,
}

/// Largest number of film equilibria the fixed point may take.
const MAX_EVALUATIONS: usize = 80;
/// The fixed point is found when T_eff moves less than this (K).
const TEMPERATURE_TOLERANCE_K: f64 = 1e-9;

/// The effective temperature of the bearing whose film (solved at `reference_viscosity_pa_s`,
/// scaled) is `film`, under static load `load_n` (N, the journal's force on the film, machine
/// frame) at `speed_rad_s`, with oil supplied at `supply_k` (K) of density `density_kg_m3`
/// following `law`. g(T) = T_s + k ΔT(µ(T)) falls as T rises for a laminar film (a thinner oil
/// dissipates less), so h(T) = g(T) − T has one root, bracketed by [T_s, g(T_s)]; a turbulent
/// film, whose Reynolds number follows µ, dissipates more as it thins past Taylor's onset, and
/// g may rise slowly: the bracket's top is then moved up by twice h there until h < 0 (h's
/// slope g' − 1 is near −1). The root is found by the Illinois variant of regula falsi. The
/// film's scale is left at the root. Err says why (a temperature beyond the law's range, a film
/// that does not carry the load).
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
    let HeatBalance::RaimondiBoyd { carry_over } = heating.balance else {
        return Err("Raimondi–Boyd's balance asked of a thermal-film bearing".into());
    };
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
        Ok((supply_k + carry_over * rise - t_k, eq))
    };
    let (h_lo, eq0) = at(supply_k)?;
    if h_lo <= TEMPERATURE_TOLERANCE_K {
        return Ok(done(
            supply_k,
            supply_k,
            eq0,
            (heating, carry_over),
            law,
            density_kg_m3,
            1,
        ));
    }
    let top = law.range_k()[1];
    let (mut lo, mut h_lo) = (supply_k, h_lo);
    let mut hi = (supply_k + h_lo).min(top);
    let (mut h_hi, mut eq_hi) = at(hi)?;
    while h_hi > 0.0 {
        // g rose with T (a turbulent film): the root lies above hi
        if hi >= top || evaluations.get() >= MAX_EVALUATIONS {
            return Err(format!(
                "the effective temperature lies beyond the viscosity law's range (up to {:.1} °C)",
                top - super::ZERO_CELSIUS_K
            ));
        }
        (lo, h_lo) = (hi, h_hi);
        hi = (hi + 2.0 * h_hi).min(top);
        (h_hi, eq_hi) = at(hi)?;
    }
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
        (heating, carry_over),
        law,
        density_kg_m3,
        evaluations.get(),
    ))
}

/// Outer passes of [`thermal_film_temperature`] at most; it settles in 3–6 (printed by
/// `tests/oil_heating_thermal.rs`).
const THERMAL_PASSES: usize = 30;
/// The passes stop when T̄ moves less than this (K).
const THERMAL_TOLERANCE_K: f64 = 1e-7;
/// Where the field's discrete rupture flips a grid node, the passes may alternate between two
/// states (T̄ back to the pass before last within [`THERMAL_TOLERANCE_K`]); a cycle whose two
/// T̄ differ by less than this (K) is taken as settled at their mean. Measured on a run-up
/// (1,000–12,000 rpm in 1 % steps): 2 of 250 speeds, flips of 0.022 and 0.046 K (0.5–1 % of
/// the rise; µ moves 0.005 %).
const THERMAL_FLIP_K: f64 = 0.1;

/// The effective temperature of [`HeatBalance::ThermalFilm`]: the equilibrium of `thermal`
/// under `load_n` (N) at `speed_rad_s` with its own temperature field (E1–E3), T_eff its
/// flow-weighted mean temperature; then the isoviscous `film` (solved at the thermal film's
/// µ₀, scaled) left at µ(T_eff), with its equilibrium there. Err says why (a film that does
/// not carry the load, a temperature beyond the law's range, passes that do not settle).
///
/// Staggered, not one Newton iteration on the coupled film: each pass finds the equilibrium
/// with the viscosity field of the last pass frozen (a smooth force in the position), then
/// the field at that position (`ThermalFilm::solve`). Why: the coupled force jumps (by up to
/// about 1e-4 of the load) where the field's discrete rupture flips a grid node, and Newton on
/// it failed at 4 of 250 speeds of a run-up (1,000–12,000 rpm in 1 % steps); the fixed point
/// is the same, and where the flip leaves two states the passes alternate between them
/// ([`THERMAL_FLIP_K`]).
pub fn thermal_film_temperature(
    thermal: &mut ThermalFilm,
    film: &mut ViscosityScaledFilm,
    load_n: [f64; 2],
    speed_rad_s: f64,
) -> Result<EffectiveTemperature, String> {
    let mu0 = thermal.reference_viscosity_pa_s();
    // T̄ of the last two passes
    let (mut before, mut last) = (f64::NAN, f64::NAN);
    let mut position = None;
    for pass in 1..=THERMAL_PASSES {
        let mut frozen = thermal.film().clone();
        let (q, _) = equilibrium_position(&mut frozen, mu0, load_n, speed_rad_s, position)
            .map_err(|e| format!("film equilibrium with the thermal field held: {e}"))?;
        position = Some(q);
        let kin = super::JournalKinematics::at_position(q, speed_rad_s);
        thermal
            .solve(&kin)
            .map_err(|e| format!("thermal film at the equilibrium: {e}"))?;
        let t_k = thermal.state().mean_temperature_k;
        if (t_k - last).abs() < THERMAL_TOLERANCE_K {
            return isoviscous_at(t_k, thermal, film, load_n, speed_rad_s, pass);
        }
        let flip = (t_k - last).abs();
        if (t_k - before).abs() < THERMAL_TOLERANCE_K && flip < THERMAL_FLIP_K {
            let mean = 0.5 * (t_k + last);
            return isoviscous_at(mean, thermal, film, load_n, speed_rad_s, pass);
        }
        (before, last) = (last, t_k);
    }
    Err(format!(
        "the thermal film's mean temperature did not settle in {THERMAL_PASSES} passes (last two {:.4} and {:.4} °C)",
        before - super::ZERO_CELSIUS_K,
        last - super::ZERO_CELSIUS_K
    ))
}

/// `film` at µ(`t_k`), `t_k` the mean temperature of `thermal`'s last solves, with the thermal
/// film's viscosity field around it where `film` can hold one (the finite film; a table runs
/// the uniform µ(`t_k`)), and its equilibrium — the film as the twin runs it: the
/// [`EffectiveTemperature`] of [`thermal_film_temperature`] after `passes`.
fn isoviscous_at(
    t_k: f64,
    thermal: &ThermalFilm,
    film: &mut ViscosityScaledFilm,
    load_n: [f64; 2],
    speed_rad_s: f64,
    passes: usize,
) -> Result<EffectiveTemperature, String> {
    let s = thermal.state();
    let mu0 = thermal.reference_viscosity_pa_s();
    let (law, supply_k) = (thermal.oil().law, thermal.oil().supply_temperature_k);
    let mu = law.checked_viscosity_pa_s(t_k)?;
    let viscosity_field = (thermal.temperature_k().iter())
        .map(|&t| law.checked_viscosity_pa_s(t).map(|m| m / mu))
        .collect::<Result<Vec<f64>, String>>()?;
    film.set_scale(mu / mu0).map_err(|e| e.to_string())?;
    film.set_viscosity_field(&viscosity_field)
        .map_err(|e| e.to_string())?;
    let equilibrium = equilibrium_under_load(film, mu, load_n, speed_rad_s)
        .map_err(|e| format!("film equilibrium at the thermal film's mean {t_k:.2} K: {e}"))?;
    Ok(EffectiveTemperature {
        balance: HeatBalance::ThermalFilm,
        supply_temperature_k: supply_k,
        effective_temperature_k: t_k,
        temperature_rise_k: s.max_temperature_k - supply_k,
        viscosity_pa_s: mu,
        friction_power_w: equilibrium.film.power_loss_w.abs(),
        heat_carried_w: s.heat_carried_w,
        equilibrium,
        evaluations: passes + 1,
        viscosity_field,
    })
}

#[allow(clippy::too_many_arguments)]
fn done(
    supply_k: f64,
    t_k: f64,
    equilibrium: Equilibrium,
    (heating, carry_over): (&OilHeating, f64),
    law: &ViscosityLaw,
    density_kg_m3: f64,
    evaluations: usize,
) -> EffectiveTemperature {
    let f = &equilibrium.film;
    let rise_k = (t_k - supply_k) / carry_over;
    EffectiveTemperature {
        balance: heating.balance,
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
        viscosity_field: Vec::new(),
    }
}
