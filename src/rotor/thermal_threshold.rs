//! The linear stability threshold with the adiabatic thermal film (issue 18; `modes --thermal`).
//!
//! At each speed of the threshold search every film bearing finds its static equilibrium with
//! its own temperature field (eq. E1–E3 of `src/film/thermal.rs`: the viscosity follows the
//! bulk temperature around the bearing), and its eight coefficients are taken there with that
//! field held (the "frozen viscosity" coefficients of the THD literature); the damped modes and
//! the search are those of [`super::stability_threshold`]. A second route, the effective
//! temperature: every film isoviscous at µ(T̄), T̄ its thermal film's flow-weighted mean
//! temperature ([`effective_temperature_threshold`]).

use super::modal::{threshold_with, BearingSolvers};
use super::{BearingModel, BearingSite, FilmBearing, RotorError, StaticSolution, Threshold};
use crate::film::{FilmError, FilmModel, ThermalFilm, ThermalOil, ThermalState};
use crate::rotor::Rotor;

/// One film bearing's thermal film at its static equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalBearing {
    /// Bearing name.
    pub bearing: String,
    /// Eccentricity ratio of the thermal film's equilibrium.
    pub eccentricity_ratio: f64,
    /// Friction power of the thermal film there (W).
    pub power_loss_w: f64,
    /// Its temperatures and flows (K, m³/s, W).
    pub state: ThermalState,
}

/// Why a bearing cannot carry the thermal film of the threshold, or None: the film's own
/// rules ([`FilmBearing::thermal_film_unsupported`]), at the machine file's viscosity (the law
/// sets it), without fluid inertia.
fn unsupported(f: &FilmBearing) -> Option<&'static str> {
    if let Some(rule) = f.thermal_film_unsupported() {
        Some(rule)
    } else if f.inertia.is_some() {
        Some("the thermal threshold is built without the film's fluid inertia")
    } else if f.viscosity_scale != 1.0 {
        Some("the thermal film sets its own viscosity (no oil_heating or viscosity scale)")
    } else {
        None
    }
}

/// The film bearings of `rotor`, in order, each with its oil of `oils` (one per film
/// bearing; Err if the count differs).
fn film_bearings<'a>(
    rotor: &'a Rotor,
    oils: &'a [ThermalOil],
) -> Result<impl Iterator<Item = (&'a BearingSite, &'a FilmBearing, &'a ThermalOil)>, RotorError> {
    if oils.len() != rotor.film_bearing_count() {
        return Err(RotorError::InvalidInput {
            name: "thermal oils (one per film bearing)",
            value: oils.len() as f64,
            rule: "must give one oil per film bearing",
        });
    }
    let films = rotor.bearings.iter().filter_map(|b| match &b.model {
        BearingModel::Film(f) => Some((b, f)),
        _ => None,
    });
    Ok(films.zip(oils).map(|((b, f), o)| (b, f, o)))
}

/// The thermal film of bearing `b` (film `f`) with `oil`; Err names the bearing and why it
/// cannot carry one.
fn thermal_film(
    b: &BearingSite,
    f: &FilmBearing,
    oil: &ThermalOil,
    speed_rpm: f64,
) -> Result<ThermalFilm, RotorError> {
    let fail = |cause| RotorError::Film {
        bearing: b.name.clone(),
        speed_rpm,
        cause,
    };
    if let Some(rule) = unsupported(f) {
        return Err(fail(FilmError::InvalidParameter {
            name: "thermal film",
            value: 0.0,
            rule,
        }));
    }
    f.thermal_film(oil.clone()).map_err(fail)
}

/// The linear stability threshold over `[from, to, step]` (rpm) with every film bearing's
/// adiabatic thermal film (`oils` one per film bearing, in order): each speed's equilibria
/// and coefficients with the temperature field of that equilibrium. None if stable over the
/// range. Err names a bearing that cannot carry the thermal film, or a film that fails.
pub fn stability_threshold_thermal(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: [f64; 3],
    oils: &[ThermalOil],
) -> Result<Option<Threshold>, RotorError> {
    let mut films = film_bearings(rotor, oils)?
        .map(|(b, f, oil)| thermal_film(b, f, oil, 0.0))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter();
    let solvers: Vec<Option<Box<dyn FilmModel + Send>>> = (rotor.bearings.iter())
        .map(|b| match b.model {
            BearingModel::Film(_) => films
                .next()
                .map(|t| Box::new(t) as Box<dyn FilmModel + Send>),
            _ => None,
        })
        .collect();
    threshold_with(
        rotor,
        statics,
        speeds_rpm,
        BearingSolvers::from_films(solvers),
    )
}

/// Every film bearing's thermal film at its static equilibrium at `speed_rpm` (the loads of
/// `statics`), in the order of the film bearings.
pub fn thermal_equilibria(
    rotor: &Rotor,
    statics: &StaticSolution,
    speed_rpm: f64,
    oils: &[ThermalOil],
) -> Result<Vec<ThermalBearing>, RotorError> {
    let omega = crate::units::rpm_to_rad_s(speed_rpm);
    let loads = rotor.bearings.iter().zip(&statics.bearing_loads_n);
    let film_loads =
        loads.filter_map(|(b, l)| matches!(b.model, BearingModel::Film(_)).then_some(*l));
    let mut out = Vec::new();
    for ((b, f, oil), load) in film_bearings(rotor, oils)?.zip(film_loads) {
        let mut thermal = thermal_film(b, f, oil, speed_rpm)?;
        let eq = f
            .equilibrium(&mut thermal, load, omega)
            .map_err(|cause| RotorError::Film {
                bearing: b.name.clone(),
                speed_rpm,
                cause,
            })?;
        out.push(ThermalBearing {
            bearing: b.name.clone(),
            eccentricity_ratio: eq.eccentricity_ratio,
            power_loss_w: eq.film.power_loss_w,
            state: thermal.state(),
        });
    }
    Ok(out)
}

/// The effective-temperature approximation of the thermal threshold: every film bearing
/// isoviscous at µ(T̄)/µ₀ (exact scaling of the laminar isoviscous film), T̄ its thermal film's
/// flow-weighted mean temperature in `bearings` (from [`thermal_equilibria`]); the isothermal
/// threshold search over `[from, to, step]` (rpm) with those viscosities.
pub fn effective_temperature_threshold(
    rotor: &Rotor,
    statics: &StaticSolution,
    speeds_rpm: [f64; 3],
    oils: &[ThermalOil],
    bearings: &[ThermalBearing],
) -> Result<Option<Threshold>, RotorError> {
    let mut scales = Vec::with_capacity(bearings.len());
    for ((b, f, oil), t) in film_bearings(rotor, oils)?.zip(bearings) {
        let mu = oil
            .law
            .checked_viscosity_pa_s(t.state.mean_temperature_k)
            .map_err(|_| RotorError::Film {
                bearing: b.name.clone(),
                speed_rpm: 0.0,
                cause: FilmError::InvalidParameter {
                    name: "mean film temperature (K)",
                    value: t.state.mean_temperature_k,
                    rule: "must lie within the viscosity law's range",
                },
            })?;
        scales.push(mu / f.lubricant.viscosity_pa_s);
    }
    let mut effective = rotor.clone();
    effective
        .set_film_viscosity_scales(&scales)
        .map_err(|cause| RotorError::Film {
            bearing: "(every film bearing)".into(),
            speed_rpm: 0.0,
            cause,
        })?;
    let [from, to, step] = speeds_rpm;
    super::stability_threshold(&effective, statics, from, to, step)
}
