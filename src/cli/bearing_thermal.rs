//! `rotor-twin bearing --thermal`: the adiabatic thermal film (`src/film/thermal.rs`, eq. E1–E3).

use crate::film::{
    FilmModel, FiniteFilm, JournalKinematics, ThermalFilm, ThermalOil, ViscosityLaw, WaltherLaw,
    ZERO_CELSIUS_K,
};
use crate::rotor::{
    effective_temperature_threshold, stability_threshold_thermal, thermal_equilibria, BearingModel,
    MachineDescription, Rotor, StaticSolution,
};
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
    oil_with_law(law, specific_heat_j_per_kg_k, supply_temperature_c)
}

/// The oil of `law` with c_p and the supply temperature (checked inside the law's range).
fn oil_with_law(
    law: ViscosityLaw,
    specific_heat_j_per_kg_k: f64,
    supply_temperature_c: f64,
) -> anyhow::Result<ThermalOil> {
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

/// The oil of `modes --thermal` for each film bearing of `rotor`, in order: Walther's law
/// through `points` (with the bearing's density) if given, else the machine file's own
/// viscosity–temperature law of the bearing (Err naming a bearing without one).
pub(crate) fn rotor_oils(
    rotor: &Rotor,
    points: Option<&str>,
    specific_heat_j_per_kg_k: f64,
    supply_temperature_c: f64,
) -> anyhow::Result<Vec<ThermalOil>> {
    let films = rotor.bearings.iter().filter_map(|b| match &b.model {
        BearingModel::Film(f) => Some((b, f)),
        _ => None,
    });
    films
        .map(|(b, f)| {
            let law = match points {
                Some(p) => ViscosityLaw::Walther(walther_through(p, f.lubricant.density_kg_m3)?),
                None => f.viscosity_law.with_context(|| {
                    format!(
                        "--thermal: bearing '{}' has no viscosity_temperature law in the machine \
                         file; give --viscosity-points",
                        b.name
                    )
                })?,
            };
            oil_with_law(law, specific_heat_j_per_kg_k, supply_temperature_c)
        })
        .collect()
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

/// One film bearing's thermal film in the `modes --thermal` report (°C where named so).
#[derive(Debug, Serialize)]
pub(crate) struct ThermalBearingRow {
    bearing: String,
    eccentricity_ratio: f64,
    power_loss_w: f64,
    inlet_temperature_c: f64,
    max_temperature_c: f64,
    /// Flow-weighted mean: the effective temperature of the second route.
    mean_temperature_c: f64,
}

/// The threshold with the thermal film (`modes --thermal`).
#[derive(Debug, Serialize)]
pub(crate) struct ThermalThresholdReport {
    pub(crate) supply_temperature_c: f64,
    pub(crate) specific_heat_j_per_kg_k: f64,
    /// With every film bearing's adiabatic thermal film (None: stable over the range).
    pub(crate) threshold_speed_rpm: Option<f64>,
    pub(crate) whirl_ratio_at_threshold: Option<f64>,
    pub(crate) threshold_frequency_hz: Option<f64>,
    /// The isothermal film's (the report's `threshold_speed_rpm`), and the change.
    pub(crate) isothermal_threshold_speed_rpm: Option<f64>,
    pub(crate) change_rpm: Option<f64>,
    /// The speed the bearings' thermal films are reported at: the thermal threshold, or the
    /// rated speed when stable over the range.
    pub(crate) at_speed_rpm: f64,
    pub(crate) bearings: Vec<ThermalBearingRow>,
    /// The second route: every film isoviscous at µ of its flow-weighted mean temperature at
    /// `at_speed_rpm` (the effective-temperature approximation).
    pub(crate) effective_temperature_threshold_rpm: Option<f64>,
}

/// `modes --thermal`: the threshold over `[from, to, step]` (rpm) with the thermal films of
/// `oils`, the films at that speed (or `rated_rpm`), and the effective-temperature route.
pub(crate) fn threshold_report(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: [f64; 3],
    oils: &[ThermalOil],
    isothermal: Option<f64>,
    rated_rpm: f64,
) -> anyhow::Result<ThermalThresholdReport> {
    let threshold = stability_threshold_thermal(rotor, statics, speeds_rpm, oils)
        .context("stability threshold with the thermal film")?;
    let at = threshold.map_or(rated_rpm, |t| t.speed_rpm);
    let bearings =
        thermal_equilibria(rotor, statics, at, oils).context("thermal films at the threshold")?;
    let effective = effective_temperature_threshold(rotor, statics, speeds_rpm, oils, &bearings)
        .context("threshold at the effective temperatures")?;
    let c = |k: f64| k - ZERO_CELSIUS_K;
    let first = oils.first().context("the machine has no film bearing")?;
    Ok(ThermalThresholdReport {
        supply_temperature_c: c(first.supply_temperature_k),
        specific_heat_j_per_kg_k: first.specific_heat_j_per_kg_k,
        threshold_speed_rpm: threshold.map(|t| t.speed_rpm),
        whirl_ratio_at_threshold: threshold.map(|t| t.whirl_ratio),
        threshold_frequency_hz: threshold.map(|t| t.frequency_hz),
        isothermal_threshold_speed_rpm: isothermal,
        change_rpm: threshold.zip(isothermal).map(|(t, i)| t.speed_rpm - i),
        at_speed_rpm: at,
        bearings: bearings
            .into_iter()
            .map(|t| ThermalBearingRow {
                bearing: t.bearing,
                eccentricity_ratio: t.eccentricity_ratio,
                power_loss_w: t.power_loss_w,
                inlet_temperature_c: c(t.state.inlet_temperature_k),
                max_temperature_c: c(t.state.max_temperature_k),
                mean_temperature_c: c(t.state.mean_temperature_k),
            })
            .collect(),
        effective_temperature_threshold_rpm: effective.map(|t| t.speed_rpm),
    })
}

/// The terminal lines of `modes --thermal`.
pub(crate) fn print_threshold(t: &ThermalThresholdReport) {
    let rpm = |v: Option<f64>| v.map_or("none in the range".to_string(), |v| format!("{v:.0} rpm"));
    println!(
        "  thermal film (adiabatic, supply {:.1} °C, c_p {:.0} J/(kg·K)): stability threshold {}, \
         isothermal {}{}",
        t.supply_temperature_c,
        t.specific_heat_j_per_kg_k,
        rpm(t.threshold_speed_rpm),
        rpm(t.isothermal_threshold_speed_rpm),
        t.change_rpm
            .map_or(String::new(), |d| format!(" (change {d:+.0} rpm)"))
    );
    for b in &t.bearings {
        println!(
            "    {} at {:.0} rpm: ε {:.3}, inlet {:.2} °C, max {:.2} °C, flow-weighted mean {:.2} °C, friction {:.1} W",
            b.bearing,
            t.at_speed_rpm,
            b.eccentricity_ratio,
            b.inlet_temperature_c,
            b.max_temperature_c,
            b.mean_temperature_c,
            b.power_loss_w
        );
    }
    println!(
        "    effective-temperature route (isoviscous at µ of each mean temperature): threshold {}",
        rpm(t.effective_temperature_threshold_rpm)
    );
}
