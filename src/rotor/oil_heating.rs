//! The film bearings at their effective temperatures (issue 12): each film bearing whose oil
//! has `oil_heating` runs at µ(T_eff), T_eff the fixed point of Raimondi–Boyd's adiabatic heat
//! balance under its static load ([`crate::film::effective_temperature`]).

use super::{static_solution, BearingModel, Rotor};
use crate::dynamics::FilmEvaluation;
use crate::film::EffectiveTemperature;

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
            let (Some(heating), Some(law)) = (f.heating, f.viscosity_law) else {
                continue;
            };
            let Some(t_s) = supply_k.or(f.design_supply_temperature_k) else {
                continue;
            };
            let inner = match film {
                FilmEvaluation::Direct => f.reference_solver(),
                FilmEvaluation::Table => f
                    .reference_tabulated_solver()
                    .map_err(|e| format!("bearing {}: tabulated film: {e}", b.name))?,
            };
            let mut solver = f.scaled(inner);
            let mu_ref = f.lubricant.viscosity_pa_s;
            let effective = crate::film::effective_temperature(
                &mut solver,
                mu_ref,
                &law,
                &heating,
                f.lubricant.density_kg_m3,
                t_s,
                loads[i],
                speed_rad_s,
            )
            .map_err(|e| format!("bearing {}: effective temperature: {e}", b.name))?;
            let scale =
                crate::film::check_viscosity_scale(effective.viscosity_pa_s / mu_ref * correction)
                    .map_err(|e| format!("bearing {}: {e}", b.name))?;
            f.viscosity_scale = scale;
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
