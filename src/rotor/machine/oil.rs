//! The lubricant of the film bearings and its viscosity–temperature law (issue 12).

use super::rules::Rules;
use crate::film::{ViscosityLaw, ViscosityTable, WaltherLaw, ZERO_CELSIUS_K};
use crate::rotor::ConfigError;
use serde::{Deserialize, Serialize};

/// How far the law may miss `viscosity_pa_s` at the design supply temperature (relative).
pub const LAW_DESIGN_TOLERANCE: f64 = 0.01;
/// Temperatures a law may name (°C): beyond them no mineral or synthetic oil is a liquid film.
const LAW_TEMPERATURE_RANGE_C: std::ops::RangeInclusive<f64> = -100.0..=500.0;

/// Lubricant properties.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
    /// The flow-weighted mean temperature of the adiabatic thermal film (issue 18,
    /// `crate::film::thermal_film_temperature`).
    ThermalFilm,
}

/// `oil_heating: {model: effective_temperature, specific_heat_j_per_kg_k: …, carry_over: …}`
/// or `{model: thermal_film, specific_heat_j_per_kg_k: …}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OilHeatingSpec {
    /// The model (one so far).
    pub model: OilHeatingModel,
    /// Specific heat capacity c_p of the oil (J/(kg·K)).
    pub specific_heat_j_per_kg_k: f64,
    /// Hot-oil carry-over factor k: T_eff = T_supply + k ΔT (`effective_temperature` only;
    /// [`DEFAULT_CARRY_OVER`] when absent: the mean film temperature of Raimondi–Boyd and
    /// Shigley). The thermal film mixes its own carry-over and refuses one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carry_over: Option<f64>,
}

/// k of T_eff = T_supply + k ΔT when the machine file gives none.
pub const DEFAULT_CARRY_OVER: f64 = 0.5;

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
        let cp = self.specific_heat_j_per_kg_k;
        let heating = match (self.model, self.carry_over) {
            (OilHeatingModel::EffectiveTemperature, k) => {
                let k = k.unwrap_or(DEFAULT_CARRY_OVER);
                crate::film::OilHeating::new(cp, k)
                    .map_err(|rule| (format!("c_p {cp} J/(kg·K), carry_over {k}"), rule))
            }
            (OilHeatingModel::ThermalFilm, None) => crate::film::OilHeating::thermal_film(cp)
                .map_err(|rule| (format!("c_p {cp} J/(kg·K)"), rule)),
            (OilHeatingModel::ThermalFilm, Some(k)) => Err((
                format!("model thermal_film, carry_over {k}"),
                "carry_over is Raimondi–Boyd's (model: effective_temperature); the thermal film mixes its own hot oil (E3)".into(),
            )),
        };
        heating.map_err(|(value, rule)| rules.error(format!("{prefix}.oil_heating"), value, rule))
    }
}

/// The viscosity–temperature law of a lubricant: Walther's (ASTM D341-09) through two kinematic
/// viscosities with the lubricant's density (`crate::film::WaltherLaw`: `temperatures_c` and
/// `kinematic_viscosities_mm2_s`), or a `table` of dynamic viscosities
/// (`crate::film::ViscosityTable`); one or the other.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViscosityTemperatureSpec {
    /// Walther: the two temperatures of the measured viscosities (°C).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperatures_c: Option<[f64; 2]>,
    /// Walther: kinematic viscosities there (mm²/s = cSt), at least 0.21 (D341-09's range).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kinematic_viscosities_mm2_s: Option<[f64; 2]>,
    /// Or a table of dynamic viscosities.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<ViscosityTableSpec>,
    /// The design oil supply temperature (°C), where the law must give `viscosity_pa_s` within 1 %.
    pub design_supply_temperature_c: f64,
    /// Oil temperatures accepted (°C), lowest and highest; others are refused as bad input
    /// (inside the table's span for a table: no extrapolation).
    pub valid_range_c: [f64; 2],
}

/// `table: {temperatures_c: [...], viscosities_pa_s: [...]}`: dynamic viscosities (Pa·s) at
/// rising temperatures (°C), falling strictly; 2 to `crate::film::MAX_TABLE_POINTS` points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViscosityTableSpec {
    /// Temperatures (°C), rising.
    pub temperatures_c: Vec<f64>,
    /// Dynamic viscosities there (Pa·s), falling.
    pub viscosities_pa_s: Vec<f64>,
}

fn kelvin(c: f64) -> f64 {
    c + ZERO_CELSIUS_K
}

/// The first temperature of `temps` (°C) that is not finite or outside the range a law may name.
fn bad_temperature<'a>(mut temps: impl Iterator<Item = &'a f64>) -> Option<f64> {
    temps
        .find(|t| !(t.is_finite() && LAW_TEMPERATURE_RANGE_C.contains(*t)))
        .copied()
}

fn temperature_rule(t: f64) -> String {
    format!(
        "temperature {t} °C must be finite, between {} and {} °C",
        LAW_TEMPERATURE_RANGE_C.start(),
        LAW_TEMPERATURE_RANGE_C.end()
    )
}

impl ViscosityTableSpec {
    /// The table, used over `range_c` (°C). Err: (field under `table`, value, rule).
    fn law(&self, range_c: [f64; 2]) -> Result<ViscosityTable, (String, String, String)> {
        let (t, mu) = (&self.temperatures_c, &self.viscosities_pa_s);
        if t.len() != mu.len() {
            return Err((
                "viscosities_pa_s".into(),
                format!("{} values for {} temperatures", mu.len(), t.len()),
                "needs one viscosity per temperature".into(),
            ));
        }
        for i in 0..t.len() {
            let field = |name: &str| format!("{name}[{i}]");
            if bad_temperature([t[i]].iter()).is_some() {
                return Err((
                    field("temperatures_c"),
                    t[i].to_string(),
                    temperature_rule(t[i]),
                ));
            }
            if !(mu[i].is_finite() && mu[i] > 0.0) {
                return Err((
                    field("viscosities_pa_s"),
                    mu[i].to_string(),
                    "must be above zero".into(),
                ));
            }
            if i > 0 && t[i] <= t[i - 1] {
                return Err((
                    field("temperatures_c"),
                    t[i].to_string(),
                    format!(
                        "must be above temperatures_c[{}] = {}: the table is in rising temperature",
                        i - 1,
                        t[i - 1]
                    ),
                ));
            }
            if i > 0 && mu[i] >= mu[i - 1] {
                return Err((
                    field("viscosities_pa_s"),
                    mu[i].to_string(),
                    format!("must be below viscosities_pa_s[{}] = {}: the viscosity must fall as the temperature rises", i - 1, mu[i - 1]),
                ));
            }
        }
        let points: Vec<(f64, f64)> = t
            .iter()
            .map(|&c| kelvin(c))
            .zip(mu.iter().copied())
            .collect();
        ViscosityTable::new(&points, range_c.map(kelvin)).map_err(|rule| {
            (
                "(table)".into(),
                format!("{} points, range {range_c:?} °C", t.len()),
                rule,
            )
        })
    }
}

impl ViscosityTemperatureSpec {
    /// The law, with density `density_kg_m3` (kg/m³; Walther's ν → µ), or (field under
    /// `viscosity_temperature`, value, the broken rule).
    pub fn law(&self, density_kg_m3: f64) -> Result<ViscosityLaw, (String, String, String)> {
        let all = || {
            format!(
                "{:?} °C, {:?} mm²/s, range {:?} °C",
                self.temperatures_c, self.kinematic_viscosities_mm2_s, self.valid_range_c
            )
        };
        let given = |rule: &str| Err(("(law)".to_string(), all(), rule.to_string()));
        if let Some(bad) = bad_temperature(
            self.valid_range_c
                .iter()
                .chain([&self.design_supply_temperature_c]),
        ) {
            return Err((
                "valid_range_c".into(),
                format!("{:?}", self.valid_range_c),
                temperature_rule(bad),
            ));
        }
        match (&self.table, self.temperatures_c, self.kinematic_viscosities_mm2_s) {
            (Some(table), None, None) => table
                .law(self.valid_range_c)
                .map(ViscosityLaw::Table)
                .map_err(|(f, v, r)| (format!("table.{f}"), v, r)),
            (None, Some(temps), Some([nu1, nu2])) => {
                if let Some(bad) = bad_temperature(temps.iter()) {
                    return Err(("temperatures_c".into(), format!("{temps:?}"), temperature_rule(bad)));
                }
                let [t1, t2] = temps.map(kelvin);
                WaltherLaw::through(
                    [(t1, nu1), (t2, nu2)],
                    density_kg_m3,
                    self.valid_range_c.map(kelvin),
                )
                .map(ViscosityLaw::Walther)
                .map_err(|rule| ("(law)".into(), all(), rule))
            }
            (Some(_), _, _) => given("either a table or temperatures_c with kinematic_viscosities_mm2_s (Walther), not both"),
            (None, _, _) => given("needs temperatures_c and kinematic_viscosities_mm2_s (Walther), or a table"),
        }
    }

    /// The law of lubricant `lub` (written at `prefix`, e.g. `bearings[0].lubricant`), checked:
    /// valid points and range, the design supply temperature inside the range, and
    /// `viscosity_pa_s` there within [`LAW_DESIGN_TOLERANCE`].
    pub(super) fn checked_law(
        &self,
        lub: &LubricantSpec,
        prefix: &str,
        rules: &Rules,
    ) -> Result<ViscosityLaw, ConfigError> {
        let field = |name: &str| format!("{prefix}.viscosity_temperature.{name}");
        let law = self
            .law(lub.density_kg_m3)
            .map_err(|(f, value, rule)| rules.error(field(&f), value, rule))?;
        let td = self.design_supply_temperature_c;
        let [lo, hi] = self.valid_range_c;
        if td < lo || td > hi {
            return Err(rules.error(
                field("design_supply_temperature_c"),
                td,
                format!("must lie inside valid_range_c [{lo}, {hi}] °C"),
            ));
        }
        let mu = law.viscosity_pa_s(kelvin(td));
        if (mu / lub.viscosity_pa_s - 1.0).abs() > LAW_DESIGN_TOLERANCE {
            let (name, value) = match (&self.table, self.kinematic_viscosities_mm2_s) {
                (Some(t), _) => (
                    "table.viscosities_pa_s",
                    format!("{:?}", t.viscosities_pa_s),
                ),
                (None, nu) => (
                    "kinematic_viscosities_mm2_s",
                    format!("{:?}", nu.unwrap_or_default()),
                ),
            };
            return Err(rules.error(
                field(name),
                value,
                format!(
                    "the law gives {mu:.4e} Pa·s at the design supply temperature {td} °C; {prefix}.viscosity_pa_s is {:.4e}: they must agree within 1 %",
                    lub.viscosity_pa_s
                ),
            ));
        }
        Ok(law)
    }
}

/// One oil supply: when a film bearing has a viscosity–temperature law, every film bearing has
/// one (an oil supply temperature reaches them all; each bearing's own law and lubricant give
/// its own scale µ_i(T)/µ_reference,i, `driver::oil_viscosity_scales`). `films` holds (bearing
/// index, lubricant) of the film bearings.
pub(super) fn check_one_oil_supply(
    films: &[(usize, LubricantSpec)],
    rules: &Rules,
) -> Result<(), ConfigError> {
    let Some((first, _)) = films
        .iter()
        .find(|(_, l)| l.viscosity_temperature.is_some())
    else {
        return Ok(());
    };
    match films.iter().find(|(_, l)| l.viscosity_temperature.is_none()) {
        None => Ok(()),
        Some((i, _)) => Err(rules.error(
            format!("bearings[{i}].lubricant.viscosity_temperature"),
            "(missing)",
            format!(
                "bearings[{first}].lubricant has a viscosity_temperature law: every film bearing needs one (its own), since an oil supply temperature reaches every film"
            ),
        )),
    }
}
