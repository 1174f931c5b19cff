//! The film bearings at their effective temperatures (issue 12): each film bearing whose oil
//! has `oil_heating` runs at µ(T_eff), T_eff the fixed point of Raimondi–Boyd's adiabatic heat
//! balance under its static load ([`crate::film::effective_temperature`]), or the
//! flow-weighted mean temperature of its adiabatic thermal film there (issue 18,
//! [`crate::film::thermal_film_temperature`]).

use super::{static_solution, BearingModel, FilmBearing, Rotor};
use crate::dynamics::FilmEvaluation;
use crate::film::{
    EffectiveTemperature, FilmError, FiniteFilm, HeatBalance, ThermalFilm, ThermalOil,
};

/// One film bearing's effective temperature.
#[derive(Debug, Clone)]
pub struct BearingTemperature {
    /// Index of the bearing in the rotor's list.
    pub bearing: usize,
    /// Its name.
    pub name: String,
    /// The fixed point of the heat balance.
    pub effective: EffectiveTemperature,
    /// The viscosity scale set on the bearing (µ(T_eff) / µ_reference × the correction).
    pub viscosity_scale: f64,
}

impl Rotor {
    /// Each film bearing's viscosity field (in the order of the film bearings; empty where
    /// uniform): what [`crate::dynamics::Twin::set_viscosity_fields`] takes.
    pub fn film_viscosity_fields(&self) -> Vec<Vec<f64>> {
        self.film_bearings()
            .map(|f| f.viscosity_field.clone())
            .collect()
    }

    /// Sets film bearing `film`'s viscosity field (its index among the film bearings; empty:
    /// uniform); a film index past the last is ignored.
    pub fn set_film_viscosity_field(&mut self, film: usize, field: &[f64]) {
        if let Some(f) = self.film_bearings_mut().nth(film) {
            f.viscosity_field.clear();
            f.viscosity_field.extend_from_slice(field);
        }
    }

    /// Whether any film bearing models its own heating.
    pub fn has_oil_heating(&self) -> bool {
        self.bearings
            .iter()
            .any(|b| matches!(&b.model, BearingModel::Film(f) if f.heating.is_some()))
    }

    /// Sets each heated film bearing's viscosity to µ(T_eff) × `correction` (a calibrated
    /// factor on the law, 1 without one), T_eff at oil supply temperature `supply_k` (K; the
    /// law's design supply temperature when None) and speed `speed_rad_s` under the bearing's
    /// static load on rigid supports. Bearings without heating are left as they are. Err names
    /// the bearing and why (a temperature beyond the law's range, a film that fails).
    pub fn heat_films(
        &mut self,
        supply_k: Option<f64>,
        speed_rad_s: f64,
        correction: f64,
    ) -> Result<Vec<BearingTemperature>, String> {
        self.heat_films_with(supply_k, speed_rad_s, correction, FilmEvaluation::Direct)
    }

    /// [`heat_films`](Self::heat_films) with the film evaluated as `film` says: `Direct` (the
    /// finite solver, as `bearing` and `modes` do) or `Table` (the tabulated film the running
    /// twin uses, shared in the process: the live twin's choice when it runs on the table).
    pub fn heat_films_with(
        &mut self,
        supply_k: Option<f64>,
        speed_rad_s: f64,
        correction: f64,
        film: FilmEvaluation,
    ) -> Result<Vec<BearingTemperature>, String> {
        if !self.has_oil_heating() {
            return Ok(Vec::new());
        }
        let loads = static_solution(self)
            .map_err(|e| format!("static bearing loads: {e}"))?
            .bearing_loads_n;
        let mut out = Vec::new();
        for (i, b) in self.bearings.iter_mut().enumerate() {
            let BearingModel::Film(f) = &mut b.model else {
                continue;
            };
            let (Some(_), Some(t_s)) = (f.heating, supply_k.or(f.design_supply_temperature_k))
            else {
                continue;
            };
            let effective = f
                .effective_temperature(t_s, loads[i], speed_rad_s, film)
                .map_err(|e| format!("bearing {}: effective temperature: {e}", b.name))?;
            let mu_ref = f.lubricant.viscosity_pa_s;
            let scale =
                crate::film::check_viscosity_scale(effective.viscosity_pa_s / mu_ref * correction)
                    .map_err(|e| format!("bearing {}: {e}", b.name))?;
            f.viscosity_scale = scale;
            f.viscosity_field.clone_from(&effective.viscosity_field);
            out.push(BearingTemperature {
                bearing: i,
                name: b.name.clone(),
                effective,
                viscosity_scale: scale,
            });
        }
        Ok(out)
    }
}

impl FilmBearing {
    /// Why this bearing cannot carry the thermal film of `src/film/thermal.rs`, or None: it is
    /// the finite laminar film of a plain bearing with the Reynolds condition.
    pub fn thermal_film_unsupported(&self) -> Option<&'static str> {
        if self.short {
            Some("the thermal film is built on the finite model (model: finite)")
        } else if !self.geometry.grooves.is_empty() {
            Some("the thermal film is built for a plain bearing (no grooves)")
        } else if self.flow != crate::film::FlowRegime::Laminar {
            Some("the thermal film is laminar (flow: laminar)")
        } else if self.cavitation != crate::film::Cavitation::Reynolds {
            Some("the thermal film uses the Reynolds condition (cavitation: reynolds)")
        } else {
            None
        }
    }

    /// The thermal film of this bearing with `oil`, at the machine file's viscosity µ₀ (the
    /// law sets the field); Err says why it cannot carry one.
    pub fn thermal_film(&self, oil: ThermalOil) -> Result<ThermalFilm, FilmError> {
        if let Some(rule) = self.thermal_film_unsupported() {
            return Err(FilmError::InvalidParameter {
                name: "thermal film",
                value: 0.0,
                rule,
            });
        }
        let film = FiniteFilm::new(self.geometry.clone(), self.lubricant, self.grid)?;
        ThermalFilm::new(film, oil)
    }

    /// This bearing's effective temperature by its `oil_heating` at oil supply temperature
    /// `supply_k` (K), under `load_n` (N) at `speed_rad_s`, the isoviscous film evaluated as
    /// `film` says (the thermal film itself is always the finite solver). Err says why (no
    /// heating or law, a film that fails, a temperature beyond the law's range).
    pub fn effective_temperature(
        &self,
        supply_k: f64,
        load_n: [f64; 2],
        speed_rad_s: f64,
        film: FilmEvaluation,
    ) -> Result<EffectiveTemperature, String> {
        let (Some(heating), Some(law)) = (self.heating, self.viscosity_law) else {
            return Err("oil_heating needs the lubricant's viscosity_temperature law".into());
        };
        let inner = match film {
            FilmEvaluation::Direct => self.reference_solver(),
            FilmEvaluation::Table => self
                .reference_tabulated_solver()
                .map_err(|e| format!("tabulated film: {e}"))?,
        };
        let mut scaled = self.scaled(inner);
        match heating.balance {
            HeatBalance::RaimondiBoyd { .. } => crate::film::effective_temperature(
                &mut scaled,
                self.lubricant.viscosity_pa_s,
                &law,
                &heating,
                self.lubricant.density_kg_m3,
                supply_k,
                load_n,
                speed_rad_s,
            ),
            HeatBalance::ThermalFilm => {
                let oil = ThermalOil {
                    law,
                    specific_heat_j_per_kg_k: heating.specific_heat_j_per_kg_k,
                    supply_temperature_k: supply_k,
                };
                let mut thermal = self.thermal_film(oil).map_err(|e| e.to_string())?;
                crate::film::thermal_film_temperature(
                    &mut thermal,
                    &mut scaled,
                    load_n,
                    speed_rad_s,
                )
            }
        }
    }
}
