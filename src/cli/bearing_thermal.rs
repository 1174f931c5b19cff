//! `rotor-twin bearing --thermal`: the adiabatic thermal film (`src/film/thermal.rs`, eq. E1–E3).

use crate::film::{
    FilmModel, FiniteFilm, JournalKinematics, ThermalFilm, ThermalOil, ViscosityLaw, WaltherLaw,
    ZERO_CELSIUS_K,
};
use crate::rotor::{BearingModel, MachineDescription, Rotor};
use anyhow::Context;
use serde::Serialize;

/// The oil of `--thermal`: Walther's law through two `°C:mm²/s` points if `points` is given,
/// else the built-in machine's MDM table (config/orc_microturbine_100kw.yaml); density ρ, c_p
/// and supply temperature (inside the law's range).
pub(crate) fn thermal_oil(
    points: Option<&str>,
    density_kg_m3: f64,
    specific_heat_j_per_kg_k: f64,
    supply_temperature_c: f64,
) -> anyhow::Result<ThermalOil> {
    let law = match points {
        Some(points) => ViscosityLaw::Walther(walther_through(points, density_kg_m3)?),
        None => built_in_law()?,
    };
    let range = law.range_k();
    let supply_k = supply_temperature_c + ZERO_CELSIUS_K;
    anyhow::ensure!(
        supply_k.is_finite() && (range[0]..=range[1]).contains(&supply_k),
        "invalid --supply-temperature-c {supply_temperature_c}: must lie within the oil law's {:.0}–{:.0} °C",
        range[0] - ZERO_CELSIUS_K,
        range[1] - ZERO_CELSIUS_K
    );
    Ok(ThermalOil {
        law,
        specific_heat_j_per_kg_k,
        supply_temperature_k: supply_k,
    })
}

/// The built-in machine's viscosity–temperature law (its first film bearing's: MDM's curve).
fn built_in_law() -> anyhow::Result<ViscosityLaw> {
    Rotor::from_description(&MachineDescription::builtin_default())
        .bearings
        .iter()
        .find_map(|b| match &b.model {
            BearingModel::Film(f) => f.viscosity_law,
            _ => None,
        })
        .context("the built-in machine has no viscosity–temperature law")
}

/// Walther's law through two `°C:mm²/s` points, used from 0 to 250 °C.
fn walther_through(points: &str, density_kg_m3: f64) -> anyhow::Result<WaltherLaw> {
    let parsed: Vec<(f64, f64)> = points
        .split(',')
        .map(|p| {
            let (t, nu) = p.split_once(':').with_context(|| {
                format!("invalid --viscosity-points '{p}': each point is °C:mm²/s")
            })?;
            let num = |s: &str| {
                s.trim().parse::<f64>().with_context(|| {
                    format!("invalid --viscosity-points '{p}': '{s}' is not a number")
                })
            };
            Ok((num(t)? + ZERO_CELSIUS_K, num(nu)?))
        })
        .collect::<anyhow::Result<_>>()?;
    let [a, b] = parsed[..] else {
        anyhow::bail!(
            "invalid --viscosity-points '{points}': Walther's law takes exactly two °C:mm²/s points"
        );
    };
    let range = [ZERO_CELSIUS_K, 250.0 + ZERO_CELSIUS_K];
    WaltherLaw::through([a, b], density_kg_m3, range)
        .map_err(|e| anyhow::anyhow!("invalid --viscosity-points '{points}': {e}"))
}

/// The thermal figures of the `--json` report (°C where named so).
#[derive(Debug, Serialize)]
pub(crate) struct ThermalReport {
    supply_temperature_c: f64,
    /// After mixing where the film re-forms (E3).
    inlet_temperature_c: f64,
    rupture_temperature_c: f64,
    max_temperature_c: f64,
    mean_temperature_c: f64,
    fresh_flow_m3_s: f64,
    dissipation_w: f64,
    heat_carried_w: f64,
    iterations: usize,
    /// Per grid column, from +x in the direction of rotation.
    temperature_c: Vec<f64>,
}

/// The thermal film's state at `kin` (the equilibrium found), solved anew from the supply
/// temperature (the fixed point of E1–E3 does not depend on where it starts).
pub(crate) fn report(
    film: FiniteFilm,
    oil: ThermalOil,
    kin: &JournalKinematics,
) -> anyhow::Result<ThermalReport> {
    let supply = oil.supply_temperature_k;
    let mut thermal = ThermalFilm::new(film, oil)?;
    thermal
        .solve(kin)
        .context("thermal film at the equilibrium")?;
    let s = thermal.state();
    let c = |k: f64| k - ZERO_CELSIUS_K;
    Ok(ThermalReport {
        supply_temperature_c: c(supply),
        inlet_temperature_c: c(s.inlet_temperature_k),
        rupture_temperature_c: c(s.rupture_temperature_k),
        max_temperature_c: c(s.max_temperature_k),
        mean_temperature_c: c(s.mean_temperature_k),
        fresh_flow_m3_s: s.fresh_flow_m3_s,
        dissipation_w: s.dissipation_w,
        heat_carried_w: s.heat_carried_w,
        iterations: s.iterations,
        temperature_c: thermal.temperature_k().iter().map(|&t| c(t)).collect(),
    })
}

/// The terminal lines of `--thermal`.
pub(crate) fn print(t: &ThermalReport) -> anyhow::Result<()> {
    outln!(
        "  thermal film (adiabatic)   supply {:.2} °C, inlet after mixing {:.2} °C, at rupture {:.2} °C",
        t.supply_temperature_c,
        t.inlet_temperature_c,
        t.rupture_temperature_c
    );
    outln!(
        "                             max {:.2} °C, flow-weighted mean {:.2} °C; fresh oil {:.3e} m³/s; dissipation {:.2} W ({} iterations)",
        t.max_temperature_c,
        t.mean_temperature_c,
        t.fresh_flow_m3_s,
        t.dissipation_w,
        t.iterations
    );
    Ok(())
}
