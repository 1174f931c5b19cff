//! `rotor-twin bearing`: static analysis of one journal bearing.

use super::bearing_speeds::{self, SpeedRange, SweptBearing};
use crate::film::rows2;
use crate::film::{
    equilibrium_at_eccentricity, equilibrium_under_load, BearingGeometry, Equilibrium, FilmGrid,
    FilmModel, FiniteFilm, Lubricant, ShortFilm, MAX_EQUILIBRIUM_ECCENTRICITY,
};
use crate::rotor::MAX_SURFACE_SPEED_M_S;
use crate::units::{rpm_to_rad_s, shown_value};
use anyhow::Context;
use clap::{Args, ValueEnum};
use nalgebra::Matrix2;
use serde::Serialize;
use std::path::PathBuf;

/// The frame every bearing result is given in.
pub const FRAME: &str = "x along the static load, y perpendicular to it, 90 deg ahead of x in the \
direction of rotation; angles from +x in the direction of rotation; force on the journal \
F = -K q - C qdot";

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum Grooves {
    /// Plain 360° bearing.
    None,
    /// Two axial grooves on the split line, 90° either side of the load (Lund & Thomsen).
    TwoAxial,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum ModelKind {
    /// Finite-length Reynolds equation with the Reynolds cavitation condition.
    Finite,
    /// Ocvirk's short bearing, π-film.
    Short,
}

/// How the film cavitates (finite model).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum CavitationKind {
    /// Reynolds condition: p ≥ 0, p = ∂p/∂n = 0 at rupture (seed eq. 6).
    Reynolds,
    /// Jakobsson–Floberg–Olsson / Elrod–Adams: pressure and fluid fraction (issue 18); a plain
    /// bearing is fed at ambient pressure at its widest gap.
    MassConserving,
}

impl From<CavitationKind> for crate::film::Cavitation {
    fn from(kind: CavitationKind) -> Self {
        match kind {
            CavitationKind::Reynolds => Self::Reynolds,
            CavitationKind::MassConserving => Self::MassConserving,
        }
    }
}

/// Static analysis of one journal bearing (defaults: the seed's microturbine bearing).
#[derive(Debug, Clone, Args)]
pub struct BearingArgs {
    /// Journal diameter D (m).
    #[arg(long, default_value_t = 0.06)]
    diameter_m: f64,
    /// Bearing length L (m).
    #[arg(long, default_value_t = 0.03)]
    length_m: f64,
    /// Radial clearance c (m).
    #[arg(long, default_value_t = 40e-6)]
    clearance_m: f64,
    /// Lubricant dynamic viscosity µ (Pa·s).
    #[arg(long, default_value_t = 0.0008)]
    viscosity_pa_s: f64,
    /// Lubricant density ρ (kg/m³); used for the film Reynolds number.
    #[arg(long, default_value_t = 900.0)]
    density_kg_m3: f64,
    /// Journal speed (rpm).
    #[arg(long, default_value_t = 9000.0)]
    speed_rpm: f64,
    /// Static load on the bearing (N), along +x. Default 275 N when no eccentricity is given.
    #[arg(long, conflicts_with = "eccentricity_ratio")]
    load_n: Option<f64>,
    /// Eccentricity ratio ε = e/c instead of a load: the load it carries is computed.
    #[arg(long)]
    eccentricity_ratio: Option<f64>,
    /// Supply grooves.
    #[arg(long, value_enum, default_value_t = Grooves::None)]
    grooves: Grooves,
    /// Arc width of each axial groove (deg).
    #[arg(long, default_value_t = 20.0)]
    groove_width_deg: f64,
    /// Gauge supply pressure at the grooves (Pa).
    #[arg(long, default_value_t = 0.0)]
    supply_pressure_pa: f64,
    /// Film grid over the half bearing: nodes around × intervals from mid-plane to edge.
    #[arg(long, default_value = "60x10", value_parser = FilmGrid::parse)]
    grid: FilmGrid,
    /// Film model.
    #[arg(long, value_enum, default_value_t = ModelKind::Finite)]
    model: ModelKind,
    /// Flow in the film (finite model): laminar, turbulent (Ng–Pan / Taylor–Dowson) or auto
    /// (laminar below Taylor's onset 41.3·√(R/c)).
    #[arg(long, default_value = "laminar", value_parser = parse_flow)]
    flow: crate::film::FlowRegime,
    /// Adiabatic thermal film (finite model, plain bearing): the viscosity follows the film's
    /// own temperature around the bearing (eq. E1–E3 of src/film/thermal.rs).
    #[arg(long)]
    thermal: bool,
    /// Oil supply temperature (°C), with --thermal.
    #[arg(long, default_value_t = 40.0)]
    supply_temperature_c: f64,
    /// Specific heat c_p of the oil (J/(kg·K)), with --thermal (default: MDM's at 40–42 °C, from
    /// the Colonna et al. 2008 equation of state; tests/reference/mdm_viscosity.csv).
    #[arg(long, default_value_t = 1820.0)]
    specific_heat_j_per_kg_k: f64,
    /// Walther's law through two points °C:mm²/s, e.g. 40:0.889,80:0.60, with --thermal
    /// (default: the built-in machine's MDM viscosity table).
    #[arg(long)]
    viscosity_points: Option<String>,
    /// Cavitation condition of the finite film: reynolds or mass-conserving (JFO, issue 18).
    #[arg(long, value_enum, default_value_t = CavitationKind::Reynolds)]
    cavitation: CavitationKind,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Speeds FROM:TO:STEP (rpm): the equilibrium, ε, attitude and eight coefficients at each,
    /// at a constant load, one line a speed (instead of --speed-rpm).
    #[arg(long, value_parser = SpeedRange::parse, conflicts_with_all = ["speed_rpm", "eccentricity_ratio"])]
    speeds: Option<SpeedRange>,
    /// Machine description (YAML): the bearing (--bearing) and its static load on rigid supports
    /// are taken from it (with --speeds).
    #[arg(long, requires = "speeds", conflicts_with_all = [
        "diameter_m", "length_m", "clearance_m", "viscosity_pa_s", "density_kg_m3", "load_n",
        "grooves", "groove_width_deg", "supply_pressure_pa", "grid", "model", "flow", "thermal", "cavitation",
    ])]
    config: Option<PathBuf>,
    /// The machine file's bearing, by name; default its first film bearing.
    #[arg(long, requires = "config")]
    bearing: Option<String>,
    /// Write the eight coefficients, ε and attitude against speed to this SVG (with --speeds).
    #[arg(long, requires = "speeds")]
    plot: Option<PathBuf>,
    /// Write the shaft centerline (journal position in the clearance circle against speed,
    /// machine frame, 1:1) to this SVG (with --speeds).
    #[arg(long, requires = "speeds")]
    centerline_plot: Option<PathBuf>,
}

/// The `--json` report (field names carry their units).
#[derive(Debug, Serialize)]
struct BearingReport {
    model: ModelKind,
    cavitation: CavitationKind,
    grid: String,
    grooves: Grooves,
    speed_rpm: f64,
    load_n: f64,
    eccentricity_ratio: f64,
    attitude_angle_deg: f64,
    journal_position_m: [f64; 2],
    min_film_thickness_m: f64,
    sommerfeld_number: f64,
    max_pressure_pa: f64,
    max_pressure_angle_deg: f64,
    film_start_deg: f64,
    film_end_deg: f64,
    friction_torque_n_m: f64,
    power_loss_w: f64,
    side_flow_m3_s: f64,
    inflow_m3_s: f64,
    film_reynolds_number: f64,
    #[serde(with = "crate::film::rows")]
    stiffness_n_per_m: Matrix2<f64>,
    #[serde(with = "crate::film::rows")]
    damping_n_s_per_m: Matrix2<f64>,
    #[serde(with = "crate::film::rows")]
    stiffness_dimensionless: Matrix2<f64>,
    #[serde(with = "crate::film::rows")]
    damping_dimensionless: Matrix2<f64>,
    frame: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    thermal: Option<super::bearing_thermal::ThermalReport>,
}

pub(crate) fn run(args: &BearingArgs) -> anyhow::Result<()> {
    if let Some(speeds) = &args.speeds {
        return run_speeds(args, &speeds.0);
    }
    let report = analyse(args)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_table(&report)?;
    }
    Ok(())
}

/// `--speeds`: the sweep of the flags' bearing or the machine file's, its table or JSON, plots.
fn run_speeds(args: &BearingArgs, speeds: &[f64]) -> anyhow::Result<()> {
    let mut bearing = match &args.config {
        Some(path) => bearing_speeds::from_machine(path, args.bearing.as_deref())?,
        None => {
            let (film, lubricant) = film_from_flags(args)?;
            let w = args.load_n.unwrap_or(275.0);
            anyhow::ensure!(
                w.is_finite() && w > 0.0,
                "invalid --load-n {w}: the static load (N) must be a finite number greater than zero"
            );
            SweptBearing {
                name: "bearing (flags)".into(),
                machine: String::new(),
                model: args.model,
                grid: match args.model {
                    ModelKind::Finite => format!("{}x{}", args.grid.n_theta, args.grid.n_z),
                    ModelKind::Short => "closed form".into(),
                },
                film,
                viscosity_pa_s: lubricant.viscosity_pa_s,
                load_n: [w, 0.0],
                heated: None,
            }
        }
    };
    let report = bearing_speeds::sweep(&mut bearing, speeds)?;
    if let Some(path) = &args.plot {
        crate::plot::bearing_coefficients_svg(path, &bearing_speeds::curves(&report))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.centerline_plot {
        crate::plot::centerline_svg(path, &bearing_speeds::curves(&report))
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        bearing_speeds::print_table(&report)?;
    }
    report.check_failures()
}

/// The film solver and lubricant of the flags' bearing.
fn film_from_flags(args: &BearingArgs) -> anyhow::Result<(Box<dyn FilmModel>, Lubricant)> {
    let geometry = match args.grooves {
        Grooves::None => BearingGeometry::plain(args.diameter_m, args.length_m, args.clearance_m),
        Grooves::TwoAxial => BearingGeometry::two_axial_grooves(
            args.diameter_m,
            args.length_m,
            args.clearance_m,
            args.groove_width_deg.to_radians(),
            args.supply_pressure_pa,
        ),
    }
    .context("bearing geometry")?;
    let lubricant = Lubricant::new(args.density_kg_m3, args.viscosity_pa_s).context("lubricant")?;
    if args.model == ModelKind::Short && args.grooves != Grooves::None {
        anyhow::bail!("--model short represents a plain bearing only; use --grooves none");
    }
    if args.model == ModelKind::Short && args.cavitation != CavitationKind::Reynolds {
        anyhow::bail!(
            "--cavitation mass-conserving is built in the finite model only; use --model finite"
        );
    }
    if args.model == ModelKind::Short && args.flow != crate::film::FlowRegime::Laminar {
        anyhow::bail!(
            "--flow {:?} is built in the finite model only; use --model finite",
            args.flow
        );
    }
    if args.thermal {
        anyhow::ensure!(
            args.model == ModelKind::Finite
                && args.grooves == Grooves::None
                && args.flow == crate::film::FlowRegime::Laminar
                && args.cavitation == CavitationKind::Reynolds,
            "--thermal is built for the finite laminar film of a plain bearing with the Reynolds \
             condition (--model finite --grooves none --flow laminar --cavitation reynolds)"
        );
        let film = FiniteFilm::new(geometry, lubricant, args.grid)?;
        let thermal = crate::film::ThermalFilm::new(film, thermal_oil(args)?)?;
        return Ok((Box::new(thermal), lubricant));
    }
    let model: Box<dyn FilmModel> = match args.model {
        ModelKind::Finite => {
            let film = FiniteFilm::new(geometry, lubricant, args.grid)?.with_flow(args.flow);
            Box::new(film.with_cavitation(args.cavitation.into()))
        }
        ModelKind::Short => Box::new(ShortFilm::new(geometry, lubricant)?),
    };
    Ok((model, lubricant))
}

/// The oil of `--thermal` from the flags.
fn thermal_oil(args: &BearingArgs) -> anyhow::Result<crate::film::ThermalOil> {
    super::bearing_thermal::thermal_oil(
        args.viscosity_points.as_deref(),
        args.density_kg_m3,
        args.specific_heat_j_per_kg_k,
        args.supply_temperature_c,
    )
}

/// The thermal figures at the equilibrium `eq`, with `--thermal`.
fn thermal_report(
    args: &BearingArgs,
    lubricant: Lubricant,
    eq: &Equilibrium,
    omega: f64,
) -> anyhow::Result<Option<super::bearing_thermal::ThermalReport>> {
    if !args.thermal {
        return Ok(None);
    }
    let geometry = BearingGeometry::plain(args.diameter_m, args.length_m, args.clearance_m)?;
    let film = FiniteFilm::new(geometry, lubricant, args.grid)?;
    let kin = crate::film::JournalKinematics::at_position(eq.position_m, omega);
    super::bearing_thermal::report(film, thermal_oil(args)?, &kin).map(Some)
}

/// `--speed-rpm`, checked before any equilibrium is sought (issue 15, item 21: -5, 1 and 1e30
/// rpm said "static equilibrium not found"): finite, above zero, at most the surface speed
/// [`MAX_SURFACE_SPEED_M_S`] of the journal.
fn check_speed(args: &BearingArgs) -> anyhow::Result<()> {
    let n = args.speed_rpm;
    let max_rpm = crate::rotor::max_speed_rpm(args.diameter_m);
    // shown rounded down, so that the bound printed is itself allowed
    let max_rpm_shown = max_rpm.floor();
    anyhow::ensure!(
        n.is_finite() && n > 0.0 && n <= max_rpm,
        "invalid --speed-rpm {}: must lie in (0, {max_rpm_shown:.0}] rpm, above zero and at most a \
         journal surface speed of {MAX_SURFACE_SPEED_M_S} m/s (Ø {} m)",
        shown_value(n),
        shown_value(args.diameter_m)
    );
    Ok(())
}

/// The load `w` (N) is carried at `--speed-rpm` within the equilibrium's eccentricity bound: the
/// film's force at ε = [`MAX_EQUILIBRIUM_ECCENTRICITY`] is at least `w`. If not, the lowest
/// speed that carries it is named, from the laminar film's force ∝ speed (a turbulent film's
/// grows faster: the figure is then an upper estimate); near it the equilibrium lies close to the
/// bound, where Newton's method may still fail (at 24 rpm of the seed bearing's 23.4 it does, at
/// 25 rpm it finds ε 0.992).
fn check_capacity(model: &mut dyn FilmModel, args: &BearingArgs, w: f64) -> anyhow::Result<()> {
    let c = args.clearance_m;
    let e = MAX_EQUILIBRIUM_ECCENTRICITY;
    let kin =
        crate::film::JournalKinematics::at_position([e * c, 0.0], rpm_to_rad_s(args.speed_rpm));
    let f = model
        .solve(&kin)
        .context("film at the largest eccentricity")?;
    let capacity = f.force_n[0].hypot(f.force_n[1]);
    anyhow::ensure!(
        capacity >= w,
        "invalid --speed-rpm {}: too slow for the load of {} N: the film carries at most {} N \
         there (at ε {e:.3}); the lowest speed that carries it is about {} rpm",
        shown_value(args.speed_rpm),
        shown_value(w),
        shown_value((capacity * 1e3).round() / 1e3),
        shown_value((10.0 * args.speed_rpm * w / capacity).ceil() / 10.0)
    );
    Ok(())
}

fn analyse(args: &BearingArgs) -> anyhow::Result<BearingReport> {
    let (mut model, lubricant) = film_from_flags(args)?;
    check_speed(args)?;
    let omega = rpm_to_rad_s(args.speed_rpm);
    let eq: Equilibrium = match args.eccentricity_ratio {
        Some(e) => equilibrium_at_eccentricity(model.as_mut(), args.viscosity_pa_s, e, omega),
        None => {
            let w = args.load_n.unwrap_or(275.0);
            anyhow::ensure!(
                w.is_finite() && w > 0.0,
                "invalid --load-n {}: the static load (N) must be a finite number greater than zero",
                shown_value(w)
            );
            if args.thermal {
                // the capacity of the film at the supply temperature (a hotter film carries
                // less: the equilibrium search then names the failure)
                let g = BearingGeometry::plain(args.diameter_m, args.length_m, args.clearance_m)?;
                check_capacity(&mut FiniteFilm::new(g, lubricant, args.grid)?, args, w)?;
            } else {
                check_capacity(model.as_mut(), args, w)?;
            }
            equilibrium_under_load(model.as_mut(), args.viscosity_pa_s, [w, 0.0], omega)
        }
    }
    .context("static equilibrium")?;
    let w = eq.load_n[0].hypot(eq.load_n[1]);
    let c = args.clearance_m;
    let f = &eq.film;
    let report = BearingReport {
        model: args.model,
        cavitation: args.cavitation,
        grid: match args.model {
            ModelKind::Finite => format!("{}x{}", args.grid.n_theta, args.grid.n_z),
            ModelKind::Short => "closed form".into(),
        },
        grooves: args.grooves,
        speed_rpm: args.speed_rpm,
        load_n: w,
        eccentricity_ratio: eq.eccentricity_ratio,
        attitude_angle_deg: eq.attitude_angle_rad.to_degrees(),
        journal_position_m: eq.position_m,
        min_film_thickness_m: c * (1.0 - eq.eccentricity_ratio),
        sommerfeld_number: eq.sommerfeld_number,
        max_pressure_pa: f.max_pressure_pa,
        max_pressure_angle_deg: f.max_pressure_angle_rad.to_degrees(),
        film_start_deg: f.film_start_rad.to_degrees(),
        film_end_deg: f.film_end_rad.to_degrees(),
        friction_torque_n_m: f.friction_torque_n_m,
        power_loss_w: f.power_loss_w,
        side_flow_m3_s: f.side_flow_m3_s,
        inflow_m3_s: f.inflow_m3_s,
        film_reynolds_number: lubricant.film_reynolds_number(omega, 0.5 * args.diameter_m, c),
        stiffness_n_per_m: eq.coefficients.stiffness_n_per_m,
        damping_n_s_per_m: eq.coefficients.damping_n_s_per_m,
        stiffness_dimensionless: eq.coefficients.dimensionless_stiffness(w, c),
        damping_dimensionless: eq.coefficients.dimensionless_damping(w, c, omega),
        frame: FRAME,
        thermal: thermal_report(args, lubricant, &eq, omega)?,
    };
    anyhow::ensure!(
        report_is_finite(&report),
        "the film solution holds a non-finite number; nothing printed"
    );
    Ok(report)
}

fn report_is_finite(r: &BearingReport) -> bool {
    let scalars = [
        r.eccentricity_ratio,
        r.attitude_angle_deg,
        r.sommerfeld_number,
        r.max_pressure_pa,
        r.max_pressure_angle_deg,
        r.film_start_deg,
        r.film_end_deg,
        r.friction_torque_n_m,
        r.power_loss_w,
        r.side_flow_m3_s,
        r.inflow_m3_s,
        r.film_reynolds_number,
    ];
    let matrices = [
        r.stiffness_n_per_m,
        r.damping_n_s_per_m,
        r.stiffness_dimensionless,
        r.damping_dimensionless,
    ];
    scalars.iter().all(|v| v.is_finite()) && matrices.iter().flatten().all(|v| v.is_finite())
}

fn print_table(r: &BearingReport) -> anyhow::Result<()> {
    let m = |a: Matrix2<f64>| {
        let [[a00, a01], [a10, a11]] = rows2(&a);
        format!("[{a00:>11.4e} {a01:>11.4e}; {a10:>11.4e} {a11:>11.4e}]")
    };
    let d = |a: Matrix2<f64>| {
        let [[a00, a01], [a10, a11]] = rows2(&a);
        format!("[{a00:>8.3} {a01:>8.3}; {a10:>8.3} {a11:>8.3}]")
    };
    outln!(
        "rotor-twin bearing: {:?} film, grid {}, grooves {:?}, cavitation {:?}",
        r.model,
        r.grid,
        r.grooves,
        r.cavitation
    );
    outln!("  speed                      {:>12.1} rpm", r.speed_rpm);
    outln!("  static load                {:>12.2} N", r.load_n);
    outln!("  Sommerfeld number S        {:>12.5}", r.sommerfeld_number);
    outln!(
        "  eccentricity ratio ε       {:>12.4}",
        r.eccentricity_ratio
    );
    outln!(
        "  attitude angle φ           {:>12.2} deg",
        r.attitude_angle_deg
    );
    outln!(
        "  minimum film               {:>12.2} µm",
        r.min_film_thickness_m * 1e6
    );
    outln!(
        "  peak pressure              {:>12.4} MPa at {:.1} deg",
        r.max_pressure_pa * 1e-6,
        r.max_pressure_angle_deg
    );
    outln!(
        "  pressure zone ζ1 → ζ2      {:>6.1} → {:.1} deg",
        r.film_start_deg,
        r.film_end_deg
    );
    outln!(
        "  friction torque            {:>12.4} N·m",
        r.friction_torque_n_m
    );
    outln!("  power loss                 {:>12.1} W", r.power_loss_w);
    outln!(
        "  side flow                  {:>12.3} cm³/s",
        r.side_flow_m3_s * 1e6
    );
    outln!(
        "  inflow at ζ1               {:>12.3} cm³/s",
        r.inflow_m3_s * 1e6
    );
    outln!(
        "  film Reynolds number       {:>12.0}{}",
        r.film_reynolds_number,
        if r.film_reynolds_number > 1000.0 {
            "  (near the laminar limit: a turbulent film would differ)"
        } else {
            ""
        }
    );
    outln!("  stiffness k (N/m)          {}", m(r.stiffness_n_per_m));
    outln!("  damping c (N·s/m)          {}", m(r.damping_n_s_per_m));
    outln!(
        "  K = k c/W                  {}",
        d(r.stiffness_dimensionless)
    );
    outln!(
        "  B = c ω c_r/W              {}",
        d(r.damping_dimensionless)
    );
    if let Some(t) = &r.thermal {
        super::bearing_thermal::print(t)?;
    }
    outln!("  frame: {}", r.frame);
    Ok(())
}

/// `--flow laminar | turbulent | auto`.
pub(crate) fn parse_flow(s: &str) -> Result<crate::film::FlowRegime, String> {
    match s {
        "laminar" => Ok(crate::film::FlowRegime::Laminar),
        "turbulent" => Ok(crate::film::FlowRegime::Turbulent),
        "auto" => Ok(crate::film::FlowRegime::Auto),
        _ => Err(format!("'{s}': must be laminar, turbulent or auto")),
    }
}
