//! `rotor-twin modes`: natural frequencies, static loads, Campbell diagram, stability threshold.

use crate::rotor::{
    campbell, critical_speeds, natural_frequencies, stability_threshold, static_solution,
    CampbellPoint, Constraint, CriticalSpeed, Rotor,
};
use crate::units::rad_s_to_rpm;
use anyhow::Context;
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;

/// Linear rotordynamics of a machine: modes, Campbell diagram, threshold of stability.
#[derive(Debug, Clone, Args)]
pub struct ModesArgs {
    /// Machine and speeds of the Campbell diagram.
    #[command(flatten)]
    range: super::MachineSpeedRange,
    /// Modes listed per speed.
    #[arg(long, default_value_t = 6)]
    modes: usize,
    /// Print one JSON object instead of tables.
    #[arg(long)]
    json: bool,
    /// Write the Campbell diagram to this SVG file.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// The film's inertia.
    #[command(flatten)]
    inertia: FilmInertiaArgs,
    /// Damped mode shapes at this speed (rpm): each node's orbit and the deflected line of the
    /// lowest --modes modes (at most 6 drawn).
    #[arg(long)]
    shapes_rpm: Option<f64>,
    /// Write the mode shapes at --shapes-rpm to this SVG file.
    #[arg(long, requires = "shapes_rpm")]
    shapes_plot: Option<PathBuf>,
    /// Write a drawing of the rotor model (shaft, discs, bearings, probes; to scale) to this SVG.
    #[arg(long)]
    rotor_plot: Option<PathBuf>,
    /// Also the stability threshold with every film bearing's adiabatic thermal film (eq.
    /// E1–E3 of src/film/thermal.rs): each speed's equilibrium and coefficients at its own
    /// temperature field (the Campbell diagram stays isothermal).
    #[arg(long, conflicts_with_all = ["fluid_inertia", "fluid_inertia_full"])]
    thermal: bool,
    /// Oil supply temperature (°C), with --thermal.
    #[arg(long, default_value_t = 40.0, requires = "thermal")]
    supply_temperature_c: f64,
    /// Specific heat c_p of the oil (J/(kg·K)), with --thermal (default: MDM's, as `bearing
    /// --thermal`).
    #[arg(long, default_value_t = 1820.0, requires = "thermal")]
    specific_heat_j_per_kg_k: f64,
    /// Walther's law through two points °C:mm²/s, with --thermal (default: each bearing's
    /// viscosity_temperature law of the machine file).
    #[arg(long, requires = "thermal")]
    viscosity_points: Option<String>,
}

/// The film's inertia options of `modes` and `response` (one model for the Campbell diagram,
/// the threshold, the critical speeds and the unbalance response).
#[derive(Debug, Clone, Args)]
pub(crate) struct FilmInertiaArgs {
    /// Give every film bearing its film's temporal fluid inertia (added mass, weightless),
    /// whatever the machine file's `fluid_inertia` says.
    #[arg(long)]
    fluid_inertia: bool,
    /// As --fluid-inertia, plus the convective inertia of the rotating film as stiffness and
    /// damping (`fluid_inertia: full`).
    #[arg(long, conflicts_with = "fluid_inertia")]
    fluid_inertia_full: bool,
    /// With the convective inertia (--fluid-inertia-full or `fluid_inertia: full` in the
    /// machine file): the tabulated film, the convective inertia's slopes taken with the
    /// pressure zone and κ following the journal, as the nonlinear transient has them, for
    /// every linear result (threshold, Campbell diagram, critical speeds, response).
    #[arg(long, conflicts_with = "fluid_inertia")]
    zone_following: bool,
}

/// [`FilmInertiaArgs::model`] of the inertialess film (the plots' titles leave it out).
pub(crate) const NO_FILM_INERTIA: &str = "no film inertia";

impl FilmInertiaArgs {
    /// Sets the film's inertia of `rotor` as asked; the zone-following step (share of the
    /// clearance) with --zone-following, refused when no film bearing carries the convective
    /// inertia (nothing would follow).
    pub(crate) fn apply(&self, rotor: &mut Rotor) -> anyhow::Result<Option<f64>> {
        if self.fluid_inertia {
            rotor.set_fluid_inertia(crate::film::FluidInertia::Temporal);
        }
        if self.fluid_inertia_full {
            rotor.set_fluid_inertia(crate::film::FluidInertia::Full);
        }
        if !self.zone_following {
            return Ok(None);
        }
        let convective = rotor.bearings.iter().any(|b| {
            matches!(&b.model, crate::rotor::BearingModel::Film(f)
                if f.inertia.is_some_and(|i| i.convective))
        });
        anyhow::ensure!(
            convective,
            "--zone-following takes the convective film inertia's slopes, and no film bearing \
             carries it: add --fluid-inertia-full or `fluid_inertia: full` in the machine file"
        );
        Ok(Some(crate::rotor::ZONE_FOLLOWING_STEP))
    }

    /// The linear model's film, as the reports name it.
    pub(crate) fn model(rotor: &Rotor, follow: Option<f64>) -> String {
        let choice = rotor.bearings.iter().find_map(|b| match &b.model {
            crate::rotor::BearingModel::Film(f) => Some(f.inertia.map(|i| i.convective)),
            _ => None,
        });
        match (choice.flatten(), follow) {
            (None, _) => NO_FILM_INERTIA.into(),
            (Some(false), _) => "film inertia temporal (added mass)".into(),
            (Some(true), None) => "film inertia full, zone and κ held".into(),
            (Some(true), Some(s)) => format!(
                "film inertia full, zone and κ following (film table, steps {} % c)",
                s * 100.0
            ),
        }
    }
}

/// Frequencies set apart as modes of a massless shaft's own mass (Hz).
#[derive(Debug, Serialize)]
struct MasslessShaftModes {
    free_free: Vec<f64>,
    pinned: Vec<f64>,
}

/// The `--json` report.
#[derive(Debug, Serialize)]
struct ModesReport {
    machine: String,
    rotor_mass_kg: f64,
    nodes: usize,
    elements: usize,
    rated_speed_rpm: f64,
    bearing_names: Vec<String>,
    /// Static load on each bearing, force of the journal on it, [F_x, F_y] (N).
    bearing_loads_n: Vec<[f64; 2]>,
    static_max_deflection_m: f64,
    free_free_hz: Vec<f64>,
    pinned_hz: Vec<f64>,
    /// Modes of a massless-shaft idealisation's own negligible mass (Hz), free–free and pinned:
    /// not modes of the modelled machine, left out of the lists above and of the Campbell diagram.
    massless_shaft_modes_hz: MasslessShaftModes,
    /// The critical speeds: forward modes crossing 1X with an amplification factor ≥ 2.5.
    critical_speeds_rpm: Vec<f64>,
    /// Each critical speed with the track id of its mode, its damping and amplification factor.
    critical_speeds: Vec<CriticalSpeed>,
    /// Forward modes crossing 1X too damped to be critical speeds (API 684: AF < 2.5,
    /// critically damped).
    critically_damped_crossings: Vec<CriticalSpeed>,
    threshold_speed_rpm: Option<f64>,
    whirl_ratio_at_threshold: Option<f64>,
    threshold_frequency_hz: Option<f64>,
    /// The film's inertia of the linearisation (Campbell diagram, threshold, critical speeds).
    film_inertia: String,
    campbell: Vec<CampbellPoint>,
    /// The damped mode shapes at `--shapes-rpm` (absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    mode_shapes: Option<super::mode_shapes::ModeShapes>,
    /// With `oil_heating`: each heated bearing at its effective temperature at the speed the
    /// viscosities were taken at (the threshold found at them, or the rated speed when stable).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    effective_temperatures: Vec<EffectiveTemperatureRow>,
    /// With `--thermal`: the threshold with the adiabatic thermal film.
    #[serde(skip_serializing_if = "Option::is_none")]
    thermal: Option<super::bearing_thermal::ThermalThresholdReport>,
}

/// One heated bearing in the `modes` report.
#[derive(Debug, Serialize)]
struct EffectiveTemperatureRow {
    bearing: String,
    /// `raimondi_boyd` or `thermal_film` (then `temperature_rise_k` is the peak rise).
    heat_balance: &'static str,
    #[serde(skip)]
    balance: crate::film::HeatBalance,
    at_speed_rpm: f64,
    supply_temperature_c: f64,
    effective_temperature_c: f64,
    temperature_rise_k: f64,
    viscosity_pa_s: f64,
    eccentricity_ratio: f64,
    friction_power_w: f64,
}

/// One line per heated bearing.
fn print_effective_temperatures(rows: &[EffectiveTemperatureRow]) {
    for t in rows {
        println!(
            "  {} at {:.0} rpm: {} {:.2} °C (supply {:.1} °C, {} {:.2} K), µ_eff {:.4} mPa·s, ε {:.3}, friction {:.1} W",
            t.bearing,
            t.at_speed_rpm,
            t.balance.temperature_label(),
            t.effective_temperature_c,
            t.supply_temperature_c,
            t.balance.rise_label(),
            t.temperature_rise_k,
            t.viscosity_pa_s * 1e3,
            t.eccentricity_ratio,
            t.friction_power_w
        );
    }
}

/// With `oil_heating`, the films at their effective temperatures at the threshold speed found
/// at those temperatures: a fixed point on the speed (to 1 rpm), from the rated speed; the
/// rated speed's temperatures when the machine is stable over the range.
fn heat_for_threshold(
    rotor: &mut Rotor,
    statics: &crate::rotor::StaticSolution,
    (from, to, step): (f64, f64, f64),
    rated_rpm: f64,
) -> anyhow::Result<Vec<EffectiveTemperatureRow>> {
    if !rotor.has_oil_heating() {
        return Ok(Vec::new());
    }
    let mut rpm = rated_rpm;
    for _ in 0..20 {
        let temps = rotor
            .heat_films(None, crate::units::rpm_to_rad_s(rpm), 1.0)
            .map_err(anyhow::Error::msg)?;
        let next = stability_threshold(rotor, statics, from, to, step)?.map(|t| t.speed_rpm);
        if next.is_none_or(|n| (n - rpm).abs() < 1.0) {
            let c = |k: f64| k - crate::film::ZERO_CELSIUS_K;
            return Ok(temps
                .into_iter()
                .map(|t| EffectiveTemperatureRow {
                    bearing: t.name,
                    heat_balance: t.effective.balance.name(),
                    balance: t.effective.balance,
                    at_speed_rpm: rpm,
                    supply_temperature_c: c(t.effective.supply_temperature_k),
                    effective_temperature_c: c(t.effective.effective_temperature_k),
                    temperature_rise_k: t.effective.temperature_rise_k,
                    viscosity_pa_s: t.effective.viscosity_pa_s,
                    eccentricity_ratio: t.effective.equilibrium.eccentricity_ratio,
                    friction_power_w: t.effective.friction_power_w,
                })
                .collect());
        }
        rpm = next.unwrap_or(rpm);
    }
    anyhow::bail!("the threshold at the effective temperatures did not settle in 20 passes")
}

/// The speeds of the Campbell diagram and threshold search, checked: (speeds, from, to, step)
/// in rpm; by default 10 % to 150 % of the rated speed `rated` in 40 steps.
fn speed_range(args: &ModesArgs, rated: f64) -> anyhow::Result<(Vec<f64>, f64, f64, f64)> {
    let grid = args.range.grid(rated, 40.0, 2000.0)?;
    anyhow::ensure!(
        (1..=100).contains(&args.modes),
        "invalid --modes {}: must be 1 to 100",
        args.modes
    );
    Ok(grid)
}

/// The plot files, checked before anything is computed.
fn check_outputs(args: &ModesArgs) -> anyhow::Result<()> {
    for (option, path) in [
        ("--plot", &args.plot),
        ("--shapes-plot", &args.shapes_plot),
        ("--rotor-plot", &args.rotor_plot),
    ] {
        if let Some(path) = path {
            super::check_output(option, path, super::Output::File)?;
        }
    }
    Ok(())
}

pub(crate) fn run(args: &ModesArgs) -> anyhow::Result<()> {
    let desc = args.range.machine()?;
    let mut rotor = Rotor::from_description(&desc);
    let follow = args.inertia.apply(&mut rotor)?;
    let (speeds, from, to, step) = speed_range(args, desc.rated_speed_rpm)?;
    check_outputs(args)?;
    let oils = thermal_oils(args, &rotor)?;
    let statics = static_solution(&rotor).context("static deflection")?;
    let heated = heat_for_threshold(&mut rotor, &statics, (from, to, step), desc.rated_speed_rpm)
        .context("effective temperatures")?;
    let free_free = natural_frequencies(&rotor, Constraint::FreeFree)?;
    let pinned = natural_frequencies(&rotor, Constraint::Pinned)?;
    let points = match follow {
        Some(s) => crate::rotor::campbell_zone_following(&rotor, &statics, &speeds, args.modes, s),
        None => campbell(&rotor, &statics, &speeds, args.modes),
    }
    .context("Campbell diagram")?;
    let threshold = threshold(follow, &rotor, &statics, [from, to, step])?;
    let thermal = thermal_report(&rotor, &statics, [from, to, step], oils, threshold)?;
    let crossings = match follow {
        Some(s) => crate::rotor::critical_speeds_zone_following(&rotor, &statics, &points, s),
        None => critical_speeds(&rotor, &statics, &points),
    };
    let (criticals, damped): (Vec<CriticalSpeed>, Vec<CriticalSpeed>) = crossings
        .context("critical speeds")?
        .into_iter()
        .partition(|c| c.critical);
    let shapes = args
        .shapes_rpm
        .map(|rpm| super::mode_shapes::mode_shapes(&rotor, &statics, (rpm, follow), args.modes))
        .transpose()
        .context("mode shapes")?;
    write_shape_plots(args, &rotor, shapes.as_ref())?;
    let report = ModesReport {
        machine: desc.name.clone(),
        rotor_mass_kg: rotor.rotor_mass_kg(),
        nodes: rotor.n_nodes(),
        elements: rotor.elements.len(),
        rated_speed_rpm: rad_s_to_rpm(rotor.rated_speed_rad_s),
        bearing_names: rotor.bearings.iter().map(|b| b.name.clone()).collect(),
        bearing_loads_n: statics.bearing_loads_n.clone(),
        static_max_deflection_m: statics.max_deflection_m,
        free_free_hz: free_free.hz.into_iter().take(args.modes).collect(),
        pinned_hz: pinned.hz.into_iter().take(args.modes).collect(),
        massless_shaft_modes_hz: MasslessShaftModes {
            free_free: free_free
                .massless_shaft_hz
                .into_iter()
                .take(args.modes)
                .collect(),
            pinned: pinned
                .massless_shaft_hz
                .into_iter()
                .take(args.modes)
                .collect(),
        },
        critical_speeds_rpm: criticals.iter().map(|c| c.speed_rpm).collect(),
        critical_speeds: criticals,
        critically_damped_crossings: damped,
        threshold_speed_rpm: threshold.map(|t| t.speed_rpm),
        whirl_ratio_at_threshold: threshold.map(|t| t.whirl_ratio),
        threshold_frequency_hz: threshold.map(|t| t.frequency_hz),
        film_inertia: FilmInertiaArgs::model(&rotor, follow),
        campbell: points,
        mode_shapes: shapes,
        effective_temperatures: heated,
        thermal,
    };
    write_campbell(args, &report)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_tables(&report);
        print_effective_temperatures(&report.effective_temperatures);
    }
    Ok(())
}

/// The stability threshold over `[from, to, step]` (rpm): the held linearisation, or with
/// `--zone-following` the tabulated film's with the zone-following slopes.
fn threshold(
    follow: Option<f64>,
    rotor: &Rotor,
    statics: &crate::rotor::StaticSolution,
    [from, to, step]: [f64; 3],
) -> anyhow::Result<Option<crate::rotor::Threshold>> {
    match follow {
        Some(s) => {
            crate::rotor::stability_threshold_zone_following(rotor, statics, [from, to, step], s)
        }
        None => stability_threshold(rotor, statics, from, to, step),
    }
    .context("stability threshold")
}

/// With `--thermal`, each film bearing's oil (checked before anything is computed).
fn thermal_oils(
    args: &ModesArgs,
    rotor: &Rotor,
) -> anyhow::Result<Option<Vec<crate::film::ThermalOil>>> {
    if !args.thermal {
        return Ok(None);
    }
    anyhow::ensure!(
        !rotor.has_oil_heating(),
        "--thermal sets each film's viscosity from its own temperature field: the machine \
         file's oil_heating (Raimondi–Boyd's effective temperature or the thermal film's mean) \
         cannot be used with it"
    );
    super::bearing_thermal::rotor_oils(
        rotor,
        args.viscosity_points.as_deref(),
        args.specific_heat_j_per_kg_k,
        args.supply_temperature_c,
    )
    .map(Some)
}

/// With `--thermal` (`oils`), the threshold with the thermal film over `[from, to, step]`
/// (rpm) beside the isothermal `threshold`.
fn thermal_report(
    rotor: &Rotor,
    statics: &crate::rotor::StaticSolution,
    speeds: [f64; 3],
    oils: Option<Vec<crate::film::ThermalOil>>,
    threshold: Option<crate::rotor::Threshold>,
) -> anyhow::Result<Option<super::bearing_thermal::ThermalThresholdReport>> {
    let Some(oils) = oils else {
        return Ok(None);
    };
    let rated_rpm = rad_s_to_rpm(rotor.rated_speed_rad_s);
    let iso = threshold.map(|t| t.speed_rpm);
    super::bearing_thermal::threshold_report(rotor, statics, speeds, &oils, iso, rated_rpm)
        .map(Some)
}

/// The `--plot` Campbell diagram.
fn write_campbell(args: &ModesArgs, report: &ModesReport) -> anyhow::Result<()> {
    if let Some(path) = &args.plot {
        crate::plot::campbell_svg(
            path,
            &match report.film_inertia.as_str() {
                NO_FILM_INERTIA => format!("Campbell diagram: {}", report.machine),
                model => format!("Campbell diagram: {} — {model}", report.machine),
            },
            &report.campbell,
            report.threshold_speed_rpm,
            &report.critical_speeds,
            &report.critically_damped_crossings,
        )
        .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// The `--shapes-plot` and `--rotor-plot` drawings.
fn write_shape_plots(
    args: &ModesArgs,
    rotor: &Rotor,
    shapes: Option<&super::mode_shapes::ModeShapes>,
) -> anyhow::Result<()> {
    if let (Some(path), Some(s)) = (&args.shapes_plot, shapes) {
        let mut panels = super::mode_shapes::panels(s);
        panels.truncate(6);
        crate::plot::mode_shapes_svg(
            path,
            &format!(
                "Damped mode shapes at {:.0} rpm: {}",
                s.speed_rpm, rotor.name
            ),
            &panels,
            &super::mode_shapes::stations(rotor),
        )
        .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.rotor_plot {
        crate::plot::rotor_svg(path, &super::mode_shapes::rotor_drawing(rotor))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

fn print_tables(r: &ModesReport) {
    print_statics(r);
    print_frequencies(r);
    print_campbell(r);
    print_criticals(r);
    if let Some(s) = &r.mode_shapes {
        print_shapes(s);
    }
    if let Some(t) = &r.thermal {
        super::bearing_thermal::print_threshold(t);
    }
}

/// Each mode at the chosen speed: frequency, sense, the largest orbit and the nodes (zero
/// crossings) of its deflected line.
fn print_shapes(s: &super::mode_shapes::ModeShapes) {
    println!("  damped mode shapes at {:.0} rpm:", s.speed_rpm);
    for (i, m) in s.modes.iter().enumerate() {
        let largest = m
            .nodes
            .iter()
            .max_by(|a, b| a.semi_major.total_cmp(&b.semi_major));
        let crossings: Vec<String> = m
            .nodes
            .windows(2)
            .filter(|w| w[0].deflection * w[1].deflection < 0.0)
            .map(|w| {
                let t = w[0].deflection / (w[0].deflection - w[1].deflection);
                format!("{:.3}", w[0].z_m + t * (w[1].z_m - w[0].z_m))
            })
            .collect();
        println!(
            "    mode {}: {:8.2} Hz {:?}, log dec {:.3}; largest orbit at node {} (z {:.3} m); nodes of \
             the line at z (m): {}",
            i + 1,
            m.frequency_hz,
            m.direction,
            super::mode_shapes::shown_log_dec(m.log_dec),
            largest.map_or(0, |n| n.node),
            largest.map_or(0.0, |n| n.z_m),
            if crossings.is_empty() {
                "none".to_string()
            } else {
                crossings.join(", ")
            }
        );
    }
}

/// Mass, size and the static loads and deflection.
fn print_statics(r: &ModesReport) {
    println!("rotor-twin modes: {}", r.machine);
    println!(
        "  rotor {:.2} kg, {} nodes, {} Timoshenko elements, rated {:.0} rpm",
        r.rotor_mass_kg, r.nodes, r.elements, r.rated_speed_rpm
    );
    println!("  static loads (journal on bearing, rigid supports):");
    for (name, f) in r.bearing_names.iter().zip(&r.bearing_loads_n) {
        println!("    {name:<24} [{:>9.2}, {:>9.2}] N", f[0], f[1]);
    }
    println!(
        "  largest static deflection {:.2} µm",
        r.static_max_deflection_m * 1e6
    );
}

/// Natural frequencies at rest, and a note on the massless-shaft modes left out.
fn print_frequencies(r: &ModesReport) {
    let list = |v: &[f64]| {
        v.iter()
            .map(|f| format!("{f:.1}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let or_none = |v: &[f64]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            list(v)
        }
    };
    println!(
        "  natural frequencies at rest, free–free (Hz): {}",
        or_none(&r.free_free_hz)
    );
    println!(
        "  natural frequencies at rest, pinned at the bearings (Hz): {}",
        or_none(&r.pinned_hz)
    );
    let shaft_own = &r.massless_shaft_modes_hz;
    if let Some(lowest) = shaft_own
        .free_free
        .iter()
        .chain(&shaft_own.pinned)
        .copied()
        .reduce(f64::min)
    {
        println!(
            "  (the shaft is idealised massless, below 0.1 % of the rotor's mass: the modes of its own \
             mass, {:.0} kHz and up, are not modes of the machine and are left out)",
            lowest / 1e3
        );
    }
}

/// The Campbell diagram as a table.
fn print_campbell(r: &ModesReport) {
    println!(
        "  Campbell diagram (film bearings linearised at their static equilibrium; {}):",
        r.film_inertia
    );
    println!(
        "    {:>8}  modes: frequency Hz / log dec / F(orward) B(ackward) and mode id (followed by shape)",
        "rpm"
    );
    for p in &r.campbell {
        let modes: Vec<String> = p
            .modes
            .iter()
            .zip(&p.tracks)
            .map(|(m, id)| {
                let d = if m.direction == crate::rotor::WhirlDirection::Forward {
                    'F'
                } else {
                    'B'
                };
                format!("{:7.1}/{:6.3}/{d}{id:<2}", m.frequency_hz, m.log_dec)
            })
            .collect();
        println!("    {:>8.0}  {}", p.speed_rpm, modes.join("  "));
    }
}

/// Critical speeds, critically damped crossings and the stability threshold.
fn print_criticals(r: &ModesReport) {
    let list = |v: &[CriticalSpeed]| {
        v.iter()
            .map(|c| {
                let af = if c.amplification_factor > 100.0 {
                    "> 100".to_string()
                } else {
                    format!("{:.2}", c.amplification_factor)
                };
                format!(
                    "{:.1} (mode {}, log dec {:.3}, AF {af})",
                    c.speed_rpm, c.track, c.log_dec
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    println!(
        "  forward critical speeds (rpm; API 684: AF = 1/(2ζ) ≥ 2.5): {}",
        if r.critical_speeds.is_empty() {
            "none in the range".to_string()
        } else {
            list(&r.critical_speeds)
        }
    );
    if !r.critically_damped_crossings.is_empty() {
        println!(
            "  forward modes crossing 1X critically damped (AF < 2.5), not critical speeds (rpm): {}",
            list(&r.critically_damped_crossings)
        );
    }
    match (r.threshold_speed_rpm, r.whirl_ratio_at_threshold) {
        (Some(t), Some(w)) => {
            println!("  stability threshold {t:.0} rpm, whirl frequency ratio {w:.3} there")
        }
        _ => println!("  stable over the whole range"),
    }
}
