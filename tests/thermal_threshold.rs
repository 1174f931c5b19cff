//! The linear stability threshold with the adiabatic thermal film (issue 18, `modes
//! --thermal`; `src/rotor/thermal_threshold.rs`, eq. E1–E3 of `src/film/thermal.rs`).
//!
//! Machines: the built-in default, reading (B) of the seed (config/orc_microturbine_100kw.yaml,
//! isothermal threshold 9,291 rpm), the machine `modes` runs by default and the task's first
//! figure; and reading (A) (config/orc_microturbine_100kw_d55.yaml, 8,471 rpm), the other
//! reading of the seed, for its change. Both carry MDM's viscosity table (40 °C supply) and
//! the same two plain bearings, so the thermal films are the same bearing at the two rotors'
//! loads and whirl frequencies.

use rotor_twin::film::{ThermalOil, ViscosityLaw, ViscosityTable, ZERO_CELSIUS_K};
use rotor_twin::rotor::{
    effective_temperature_threshold, stability_threshold, stability_threshold_thermal,
    static_solution, thermal_equilibria, BearingModel, MachineDescription, Rotor,
};

/// The threshold search's speeds (rpm): wide enough around both readings' thresholds
/// (8,471 and 9,291 rpm isothermal), coarse steps (the search bisects to 0.5 rpm).
const SPEEDS: [f64; 3] = [6000.0, 12000.0, 500.0];

fn rotor(config: Option<&str>) -> Rotor {
    let desc = MachineDescription::load(config.map(std::path::Path::new)).unwrap();
    Rotor::from_description(&desc)
}

/// Each film bearing's machine-file law (MDM's table) with `bearing --thermal`'s defaults:
/// supply 40 °C, c_p 1,820 J/(kg·K).
fn mdm_oils(rotor: &Rotor) -> Vec<ThermalOil> {
    (rotor.bearings.iter())
        .filter_map(|b| match &b.model {
            BearingModel::Film(f) => Some(ThermalOil {
                law: f.viscosity_law.unwrap(),
                specific_heat_j_per_kg_k: 1820.0,
                supply_temperature_k: 40.0 + ZERO_CELSIUS_K,
            }),
            _ => None,
        })
        .collect()
}

fn isothermal(rotor: &Rotor) -> f64 {
    let statics = static_solution(rotor).unwrap();
    let [from, to, step] = SPEEDS;
    (stability_threshold(rotor, &statics, from, to, step).unwrap())
        .unwrap()
        .speed_rpm
}

#[test]
fn a_flat_viscosity_law_gives_the_isothermal_threshold() {
    // µ(T) flat (to 1e-12 over 10–200 °C, the table law must fall: 0.8 mPa·s × (1 + 1e-12)
    // at 10 °C to 0.8 mPa·s at 200 °C, the machine file's µ₀ = 0.8 mPa·s): the temperature
    // field is computed (the films heat by several kelvin) but may not reach the film, so the
    // threshold is the isothermal one to 1e-6 (measured: equal to round-off). A field that
    // leaked in (a wrong µ₀, a ratio not one, the coefficients taken at another state) would
    // move it by the ~1 %/K of the viscosity's effect. Built-in machine (B).
    let rotor = rotor(None);
    let statics = static_solution(&rotor).unwrap();
    let c = |t: f64| t + ZERO_CELSIUS_K;
    let flat = ViscosityTable::new(
        &[(c(10.0), 0.8e-3 * (1.0 + 1e-12)), (c(200.0), 0.8e-3)],
        [c(10.0), c(200.0)],
    )
    .unwrap();
    let oils: Vec<ThermalOil> = mdm_oils(&rotor)
        .into_iter()
        .map(|o| ThermalOil {
            law: ViscosityLaw::Table(flat),
            ..o
        })
        .collect();
    let thermal = stability_threshold_thermal(&rotor, &statics, SPEEDS, &oils)
        .unwrap()
        .unwrap()
        .speed_rpm;
    let iso = isothermal(&rotor);
    let films = thermal_equilibria(&rotor, &statics, thermal, &oils).unwrap();
    println!(
        "flat law: thermal {thermal:.6} rpm, isothermal {iso:.6} rpm ({:+.2e}); peak film {:.2} °C",
        (thermal - iso) / iso,
        films[0].state.max_temperature_k - ZERO_CELSIUS_K
    );
    assert!((thermal - iso).abs() <= 1e-6 * iso, "{thermal} vs {iso}");
    // the field is there, and hot: it is only the flat law that keeps it out of the film
    assert!(films[0].state.max_temperature_k > c(42.0), "{films:?}");
}

/// The thresholds of one reading (rpm) and the bound the effective-temperature route must
/// keep to (a share of the thermal threshold).
struct Reading {
    thermal: f64,
    effective: f64,
    isothermal: f64,
    bound: f64,
}

/// The bound on |effective − thermal| / thermal, to first order: the effective route replaces
/// the film's µ(θ) by µ(T̄), T̄ its flow-weighted mean; whatever weights the eight coefficients
/// give the columns, the viscosity they see lies between µ(T_max) and µ(T_in) (the march only
/// heats: T_in is the film's coolest, T_max its hottest), so the two thresholds differ by at
/// most |S| × the larger relative distance of those two from µ(T̄), with S = d ln N/d ln µ the
/// threshold's sensitivity to a uniform viscosity, measured here between the isothermal film
/// (µ at the supply) and the effective one (µ(T̄)).
fn reading(config: Option<&str>) -> Reading {
    let rotor = rotor(config);
    let statics = static_solution(&rotor).unwrap();
    let oils = mdm_oils(&rotor);
    let thermal = stability_threshold_thermal(&rotor, &statics, SPEEDS, &oils)
        .unwrap()
        .unwrap()
        .speed_rpm;
    let films = thermal_equilibria(&rotor, &statics, thermal, &oils).unwrap();
    let effective = effective_temperature_threshold(&rotor, &statics, SPEEDS, &oils, &films)
        .unwrap()
        .unwrap()
        .speed_rpm;
    let isothermal = isothermal(&rotor);
    let mut bound = 0.0_f64;
    for (f, oil) in films.iter().zip(&oils) {
        let s = &f.state;
        let mu = |t: f64| oil.law.viscosity_pa_s(t);
        let m = mu(s.mean_temperature_k);
        let sensitivity = (effective / isothermal).ln() / (m / mu(oil.supply_temperature_k)).ln();
        let spread = (mu(s.inlet_temperature_k) / m - 1.0).max(1.0 - mu(s.max_temperature_k) / m);
        bound = bound.max(sensitivity.abs() * spread);
        let c = |k: f64| k - ZERO_CELSIUS_K;
        println!(
            "  {}: ε {:.4}, inlet {:.2} °C, max {:.2} °C, mean {:.2} °C, {:.1} W; {} iterations, \
             residual {:.1e} K; S {sensitivity:.3}, µ spread {:.2} %",
            f.bearing,
            f.eccentricity_ratio,
            c(s.inlet_temperature_k),
            c(s.max_temperature_k),
            c(s.mean_temperature_k),
            f.power_loss_w,
            s.iterations,
            s.residual_k,
            100.0 * spread
        );
    }
    Reading {
        thermal,
        effective,
        isothermal,
        bound,
    }
}

#[test]
fn the_thermal_threshold_of_both_readings_and_the_effective_temperature_route() {
    // measured (README "Thermal film"): (B) 9,363.3 rpm, (A) 8,591.1 rpm; pinned to 1 rpm (the
    // search bisects to 0.5 rpm); the isothermal ones are README "Two readings of the seed"'s
    for (name, config, thermal_rpm, isothermal_rpm) in [
        ("(B) built-in", None, 9363.3, 9291.1),
        (
            "(A) d55",
            Some("config/orc_microturbine_100kw_d55.yaml"),
            8591.1,
            8471.3,
        ),
    ] {
        let r = reading(config);
        let off = (r.effective - r.thermal) / r.thermal;
        println!(
            "{name}: isothermal {:.1} rpm, thermal {:.1} rpm ({:+.1} rpm, {:+.2} %), effective-\
             temperature route {:.1} rpm ({:+.3} % of the thermal; bound {:.2} %)",
            r.isothermal,
            r.thermal,
            r.thermal - r.isothermal,
            100.0 * (r.thermal - r.isothermal) / r.isothermal,
            r.effective,
            100.0 * off,
            100.0 * r.bound
        );
        assert!(
            off.abs() <= r.bound,
            "{name}: {off:+.2e} beyond {:.2e}",
            r.bound
        );
        assert!(
            (r.thermal - thermal_rpm).abs() < 1.0,
            "{name}: {}",
            r.thermal
        );
        assert!(
            (r.isothermal - isothermal_rpm).abs() < 1.0,
            "{name}: {}",
            r.isothermal
        );
    }
}

/// A bearing the thermal film cannot carry is refused by name, never run isothermal in its
/// place: here the film's fluid inertia (the thermal threshold is built without it); and the
/// oils must be one per film bearing. Built-in machine (B).
#[test]
fn a_bearing_the_thermal_film_cannot_carry_is_refused_by_name() {
    let mut with_inertia = rotor(None);
    with_inertia.set_fluid_inertia(rotor_twin::film::FluidInertia::Temporal);
    let statics = static_solution(&with_inertia).unwrap();
    let oils = mdm_oils(&with_inertia);
    let err = stability_threshold_thermal(&with_inertia, &statics, SPEEDS, &oils)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bearing_pulley_end") && err.contains("fluid inertia"),
        "{err}"
    );
    let plain = rotor(None);
    let err = stability_threshold_thermal(&plain, &statics, SPEEDS, &oils[..1])
        .unwrap_err()
        .to_string();
    assert!(err.contains("one oil per film bearing"), "{err}");
}
