//! The lubricant of the film bearings and its viscosity–temperature law (issue 12).

use super::rules::Rules;
use crate::film::{WaltherLaw, ZERO_CELSIUS_K};
use crate::rotor::ConfigError;
use serde::{Deserialize, Serialize};

/// How far the law may miss `viscosity_pa_s` at the design supply temperature (relative).
pub const LAW_DESIGN_TOLERANCE: f64 = 0.01;
/// Temperatures a law may name (°C): beyond them no mineral or synthetic oil is a liquid film.
const LAW_TEMPERATURE_RANGE_C: std::ops::RangeInclusive<f64> = -100.0..=500.0;

/// Lubricant properties.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LubricantSpec {
    /// Density ρ (kg/m³).
    pub density_kg_m3: f64,
    /// Dynamic viscosity µ (Pa·s); with a `viscosity_temperature` law, at its design supply
    /// temperature (the viscosity the films are solved, and tabulated, at).
    pub viscosity_pa_s: f64,
    /// Optional viscosity–temperature law: an oil temperature received on the bus then sets the
    /// viscosity of the running twin's films.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub viscosity_temperature: Option<ViscosityTemperatureSpec>,
    /// Optional: the bearing's own heating by an effective temperature (`crate::film::OilHeating`;
    /// needs `viscosity_temperature`). Absent: the film runs at the supply temperature.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub oil_heating: Option<OilHeatingSpec>,
}

/// How the film's own heating is modelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OilHeatingModel {
    /// Raimondi–Boyd's adiabatic effective temperature (`crate::film::effective_temperature`).
    EffectiveTemperature,
}

/// `oil_heating: {model: effective_temperature, specific_heat_j_per_kg_k: …, carry_over: …}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OilHeatingSpec {
    /// The model (one so far).
    pub model: OilHeatingModel,
    /// Specific heat capacity c_p of the oil (J/(kg·K)).
    pub specific_heat_j_per_kg_k: f64,
    /// Hot-oil carry-over factor k: T_eff = T_supply + k ΔT (0.5 when absent: the mean film
    /// temperature of Raimondi–Boyd and Shigley).
    #[serde(default = "default_carry_over")]
    pub carry_over: f64,
}

/// k of T_eff = T_supply + k ΔT when the machine file gives none.
pub const DEFAULT_CARRY_OVER: f64 = 0.5;

fn default_carry_over() -> f64 {
    DEFAULT_CARRY_OVER
}

impl OilHeatingSpec {
    /// The checked option of lubricant `lub` written at `prefix` (it needs a viscosity law).
    pub(super) fn checked(
        &self,
        lub: &LubricantSpec,
        prefix: &str,
        rules: &Rules,
    ) -> Result<crate::film::OilHeating, ConfigError> {
        if lub.viscosity_temperature.is_none() {
            return Err(rules.error(
                format!("{prefix}.oil_heating"),
                "(given)",
                "needs lubricant.viscosity_temperature: the effective temperature acts through the viscosity law",
            ));
        }
        crate::film::OilHeating::new(self.specific_heat_j_per_kg_k, self.carry_over).map_err(
            |rule| {
                rules.error(
                    format!("{prefix}.oil_heating"),
                    format!(
                        "c_p {} J/(kg·K), carry_over {}",
                        self.specific_heat_j_per_kg_k, self.carry_over
                    ),
                    rule,
                )
            },
        )
    }
}

/// Walther's viscosity–temperature law (ASTM D341-09) through two kinematic viscosities, with
/// the lubricant's density (`crate::film::WaltherLaw`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViscosityTemperatureSpec {
    /// The two temperatures of the measured viscosities (°C).
    pub temperatures_c: [f64; 2],
    /// Kinematic viscosities there (mm²/s = cSt), at least 0.21 (D341-09's range).
    pub kinematic_viscosities_mm2_s: [f64; 2],
    /// The design oil supply temperature (°C), where the law must give `viscosity_pa_s` within 1 %.
    pub design_supply_temperature_c: f64,
    /// Oil temperatures accepted (°C), lowest and highest; others are refused as bad input.
    pub valid_range_c: [f64; 2],
}

impl ViscosityTemperatureSpec {
    /// The law, with density `density_kg_m3` (kg/m³), or the broken rule.
    pub fn law(&self, density_kg_m3: f64) -> Result<WaltherLaw, String> {
        let k = |c: f64| c + ZERO_CELSIUS_K;
        if let Some(bad) = self
            .valid_range_c
            .iter()
            .chain(&self.temperatures_c)
            .chain([&self.design_supply_temperature_c])
            .find(|t| !(t.is_finite() && LAW_TEMPERATURE_RANGE_C.contains(*t)))
        {
            return Err(format!(
                "temperature {bad} °C must be finite, between {} and {} °C",
                LAW_TEMPERATURE_RANGE_C.start(),
                LAW_TEMPERATURE_RANGE_C.end()
            ));
        }
        let [t1, t2] = self.temperatures_c;
        let [nu1, nu2] = self.kinematic_viscosities_mm2_s;
        WaltherLaw::through(
            [(k(t1), nu1), (k(t2), nu2)],
            density_kg_m3,
            self.valid_range_c.map(k),
        )
    }

    /// The law of lubricant `lub` (written at `prefix`, e.g. `bearings[0].lubricant`), checked:
    /// valid points and range, the design supply temperature inside the range, and
    /// `viscosity_pa_s` there within [`LAW_DESIGN_TOLERANCE`].
    pub(super) fn checked_law(
        &self,
        lub: &LubricantSpec,
        prefix: &str,
        rules: &Rules,
    ) -> Result<WaltherLaw, ConfigError> {
        let field = |name: &str| format!("{prefix}.viscosity_temperature.{name}");
        let law = self.law(lub.density_kg_m3).map_err(|rule| {
            rules.error(
                field("(law)"),
                format!(
                    "{:?} °C, {:?} mm²/s, range {:?} °C",
                    self.temperatures_c, self.kinematic_viscosities_mm2_s, self.valid_range_c
                ),
                rule,
            )
        })?;
        let td = self.design_supply_temperature_c;
        let [lo, hi] = self.valid_range_c;
        if td < lo || td > hi {
            return Err(rules.error(
                field("design_supply_temperature_c"),
                td,
                format!("must lie inside valid_range_c [{lo}, {hi}] °C"),
            ));
        }
        let mu = law.viscosity_pa_s(td + ZERO_CELSIUS_K);
        if (mu / lub.viscosity_pa_s - 1.0).abs() > LAW_DESIGN_TOLERANCE {
            return Err(rules.error(
                field("kinematic_viscosities_mm2_s"),
                format!("{:?}", self.kinematic_viscosities_mm2_s),
                format!(
                    "the law gives {mu:.4e} Pa·s at the design supply temperature {td} °C; {prefix}.viscosity_pa_s is {:.4e}: they must agree within 1 %",
                    lub.viscosity_pa_s
                ),
            ));
        }
        Ok(law)
    }
}

/// One oil supply: when a bearing has a viscosity–temperature law, every film bearing has the
/// same lubricant as written (an oil temperature sets one viscosity scale for every film,
/// `driver::oil_viscosity_scale`). `films` holds (bearing index, lubricant) of the film bearings.
pub(super) fn check_one_oil_supply(
    films: &[(usize, LubricantSpec)],
    rules: &Rules,
) -> Result<(), ConfigError> {
    if films.iter().all(|(_, l)| l.viscosity_temperature.is_none()) {
        return Ok(());
    }
    let (first, reference) = films[0];
    match films.iter().find(|(_, l)| *l != reference) {
        None => Ok(()),
        Some((i, l)) => Err(rules.error(
            format!("bearings[{i}].lubricant"),
            format!("{l:?}"),
            format!(
                "with a viscosity_temperature law the bearings share one oil supply: every lubricant must equal bearings[{first}].lubricant ({reference:?}), since an oil temperature sets one viscosity scale for every film"
            ),
        )),
    }
}
