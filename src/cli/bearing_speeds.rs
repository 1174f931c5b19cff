//! `rotor-twin bearing --speeds FROM:TO:STEP`: the static equilibrium, ε, attitude angle and
//! the eight coefficients of one bearing over a speed range at a constant load, as bearing codes
//! print them; the bearing from the flags or from a machine file (`--config`, `--bearing`),
//! whose static load on rigid supports it then carries. With `--plot` the coefficients against
//! speed, with `--centerline-plot` the shaft centerline (the journal's static position in the
//! clearance circle against speed).

use super::bearing::{ModelKind, FRAME};
use crate::film::{equilibrium_under_load, FilmModel};
use crate::rotor::{static_solution, BearingModel, MachineDescription, Rotor};
use crate::units::rpm_to_rad_s;
use anyhow::Context;
use nalgebra::{Matrix2, Rotation2};
use serde::Serialize;
use std::path::Path;

/// Most speeds a sweep computes.
const MAX_SPEEDS: usize = 2000;

/// The speeds of `--speeds FROM:TO:STEP` (rpm), FROM and TO included.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SpeedRange(pub Vec<f64>);

impl SpeedRange {
    /// Parses `FROM:TO:STEP` (rpm): 0 < FROM ≤ TO, STEP > 0, at most [`MAX_SPEEDS`] speeds.
    pub(crate) fn parse(text: &str) -> Result<Self, String> {
        let parts: Vec<&str> = text.split(':').collect();
        let [from, to, step] = parts.as_slice() else {
            return Err(format!(
                "'{text}': expected FROM:TO:STEP in rpm, e.g. 1000:12000:500"
            ));
        };
        let num = |name: &str, s: &str| {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or(format!(
                    "'{text}': {name} '{s}' must be a finite speed above zero (rpm)"
                ))
        };
        let (from, to, step) = (num("FROM", from)?, num("TO", to)?, num("STEP", step)?);
        if to < from {
            return Err(format!("'{text}': TO {to} is below FROM {from}"));
        }
        let n = ((to - from) / step + 1e-9).floor() as usize;
        if n + 1 > MAX_SPEEDS {
            return Err(format!(
                "'{text}': {} speeds, more than {MAX_SPEEDS}",
                n + 1
            ));
        }
        let mut speeds: Vec<f64> = (0..=n).map(|k| from + k as f64 * step).collect();
        if to - speeds[n] > 1e-9 * to {
            speeds.push(to);
        }
        Ok(Self(speeds))
    }
}

/// The bearing a sweep runs: its film, the viscosity it runs at and the static load it carries.
pub(crate) struct SweptBearing {
    /// Bearing name ("flags" when given by the flags).
    pub name: String,
    /// Machine it belongs to ("" for the flags).
    pub machine: String,
    /// Model and grid (as `bearing` prints them).
    pub model: ModelKind,
    pub grid: String,
    /// The film solver (warm-started from speed to speed).
    pub film: Box<dyn FilmModel>,
    /// Viscosity of the running oil (Pa·s).
    pub viscosity_pa_s: f64,
    /// Static load on the film, the force of the journal on the bearing, machine frame (N).
    pub load_n: [f64; 2],
    /// The machine file's bearing when its oil models its own heating: each speed is then
    /// solved at its effective temperature (from the law's design supply temperature).
    pub heated: Option<crate::rotor::FilmBearing>,
}

/// The bearing `name` of the machine file `path` (the first film bearing without a name) and
/// its static load on rigid supports.
pub(crate) fn from_machine(path: &Path, name: Option<&str>) -> anyhow::Result<SweptBearing> {
    let desc = MachineDescription::load(Some(path))?;
    let rotor = Rotor::from_description(&desc);
    let film_names: Vec<&str> = rotor
        .bearings
        .iter()
        .filter(|b| matches!(b.model, BearingModel::Film(_)))
        .map(|b| b.name.as_str())
        .collect();
    let index = match name {
        Some(n) => rotor.bearings.iter().position(|b| b.name == n),
        None => rotor
            .bearings
            .iter()
            .position(|b| matches!(b.model, BearingModel::Film(_))),
    };
    let Some(index) = index else {
        anyhow::bail!(
            "invalid --bearing {}: {} has no such film bearing (its film bearings: {})",
            name.unwrap_or("(first film bearing)"),
            path.display(),
            if film_names.is_empty() {
                "none".to_string()
            } else {
                film_names.join(", ")
            }
        );
    };
    let site = &rotor.bearings[index];
    let BearingModel::Film(f) = &site.model else {
        anyhow::bail!(
            "invalid --bearing {}: not a film bearing (its film bearings: {})",
            site.name,
            film_names.join(", ")
        );
    };
    let statics = static_solution(&rotor).context("static bearing loads")?;
    let load_n = statics.bearing_loads_n[index];
    anyhow::ensure!(
        load_n[0].hypot(load_n[1]) > 1e-9,
        "bearing {} carries no static load: its equilibrium does not move with speed",
        site.name
    );
    Ok(SweptBearing {
        name: site.name.clone(),
        machine: desc.name.clone(),
        model: if f.short {
            ModelKind::Short
        } else {
            ModelKind::Finite
        },
        grid: if f.short {
            "closed form".into()
        } else {
            format!("{}x{}", f.grid.n_theta, f.grid.n_z)
        },
        film: f.solver(),
        viscosity_pa_s: f.viscosity_pa_s(),
        load_n,
        heated: f.heating.is_some().then(|| f.clone()),
    })
}

/// One speed of the sweep. The coefficients and positions are in the bearing's load frame
/// ([`FRAME`]: x along the static load); the machine-frame position is the shaft centerline.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct SpeedRow {
    pub speed_rpm: f64,
    pub sommerfeld_number: f64,
    pub eccentricity_ratio: f64,
    pub attitude_angle_deg: f64,
    /// Journal centre relative to the bearing centre, load frame (m).
    pub journal_position_m: [f64; 2],
    /// The same in the machine frame (m): the shaft centerline.
    pub journal_position_machine_m: [f64; 2],
    pub min_film_thickness_m: f64,
    pub max_pressure_pa: f64,
    pub power_loss_w: f64,
    #[serde(with = "crate::film::rows")]
    pub stiffness_n_per_m: Matrix2<f64>,
    #[serde(with = "crate::film::rows")]
    pub damping_n_s_per_m: Matrix2<f64>,
    #[serde(with = "crate::film::rows")]
    pub stiffness_dimensionless: Matrix2<f64>,
    #[serde(with = "crate::film::rows")]
    pub damping_dimensionless: Matrix2<f64>,
    /// With `oil_heating`: the effective temperature (°C), its rise ΔT (K) and µ there (Pa·s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effective_temperature_c: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature_rise_k: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effective_viscosity_pa_s: Option<f64>,
    /// How the temperature was found: `raimondi_boyd` or `thermal_film` (then
    /// `temperature_rise_k` is the peak rise over the supply).
    #[serde(
        skip_serializing_if = "Option::is_none",
        serialize_with = "heat_balance_name"
    )]
    pub heat_balance: Option<crate::film::HeatBalance>,
}

fn heat_balance_name<S: serde::Serializer>(
    b: &Option<crate::film::HeatBalance>,
    s: S,
) -> Result<S::Ok, S::Error> {
    match b {
        Some(b) => s.serialize_str(b.name()),
        None => s.serialize_none(),
    }
}

/// A heated bearing's (T_eff °C, ΔT K, µ_eff Pa·s) and how they were found.
type Heat = (f64, f64, f64, crate::film::HeatBalance);

/// The equilibrium of `b` at `omega`, at its effective temperature when its oil heats.
fn equilibrium(
    b: &mut SweptBearing,
    omega: f64,
) -> anyhow::Result<(crate::film::Equilibrium, Option<Heat>)> {
    let Some(f) = &b.heated else {
        let eq = equilibrium_under_load(b.film.as_mut(), b.viscosity_pa_s, b.load_n, omega)?;
        return Ok((eq, None));
    };
    let Some(t_s) = f.design_supply_temperature_k else {
        anyhow::bail!("oil_heating needs the lubricant's viscosity_temperature law");
    };
    let e = f
        .effective_temperature(
            t_s,
            b.load_n,
            omega,
            crate::dynamics::FilmEvaluation::Direct,
        )
        .map_err(|e| anyhow::anyhow!(e))?;
    let t_c = e.effective_temperature_k - crate::film::ZERO_CELSIUS_K;
    let extra = (t_c, e.temperature_rise_k, e.viscosity_pa_s, e.balance);
    Ok((e.equilibrium, Some(extra)))
}

/// The `--json` report of a sweep.
#[derive(Debug, Serialize)]
pub(crate) struct SweepReport {
    pub machine: String,
    pub bearing: String,
    pub model: ModelKind,
    pub grid: String,
    pub viscosity_pa_s: f64,
    pub radial_clearance_m: f64,
    /// Static load magnitude (N).
    pub load_n: f64,
    /// Direction of the static load in the machine frame, from +x towards +y (deg).
    pub load_direction_deg: f64,
    pub frame: &'static str,
    pub speeds: Vec<SpeedRow>,
    /// The speeds whose equilibrium failed (e.g. a heat balance whose film passes the viscosity
    /// law's range), each with why: the other speeds are reported all the same.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub failed: Vec<FailedSpeed>,
}

/// A speed of a sweep without an equilibrium, and why.
#[derive(Debug, Serialize)]
pub(crate) struct FailedSpeed {
    pub speed_rpm: f64,
    pub error: String,
}

impl SweepReport {
    /// Err naming the failed speeds and the first reason, if any failed (after the report of
    /// the others is out: the command then ends with an error).
    pub(crate) fn check_failures(&self) -> anyhow::Result<()> {
        let Some(first) = self.failed.first() else {
            return Ok(());
        };
        let rpms: Vec<String> = (self.failed.iter())
            .map(|f| format!("{:.0}", f.speed_rpm))
            .collect();
        anyhow::bail!(
            "{} of {} speeds of {} have no equilibrium ({} rpm); at {:.0} rpm: {}",
            self.failed.len(),
            self.failed.len() + self.speeds.len(),
            self.bearing,
            rpms.join(", "),
            first.speed_rpm,
            first.error
        )
    }
}

/// The speeds of a sweep end at the journal's surface speed limit
/// ([`crate::rotor::MAX_SURFACE_SPEED_M_S`], as `--speed-rpm` and the machine file's
/// `rated_speed_rpm`): a faster one is refused before any equilibrium is sought.
fn check_top_speed(b: &SweptBearing, speeds: &[f64]) -> anyhow::Result<()> {
    let d = b.film.geometry().diameter_m;
    let max_rpm = crate::rotor::max_speed_rpm(d);
    // shown rounded down, so that the bound printed is itself allowed
    let max_rpm_shown = max_rpm.floor();
    let top = speeds.iter().copied().fold(0.0, f64::max);
    anyhow::ensure!(
        top <= max_rpm,
        "invalid --speeds: {} rpm is above {max_rpm_shown:.0} rpm, a journal surface speed of {} m/s \
         (Ø {} m of {}); end the range there",
        crate::units::shown_value(top),
        crate::rotor::MAX_SURFACE_SPEED_M_S,
        crate::units::shown_value(d),
        b.name
    );
    Ok(())
}

/// The equilibrium at each speed of `speeds` (rpm), the solver warm-started from the speed
/// before; the coefficients turned from the machine frame into the load frame (K' = Rᵀ K R,
/// R the rotation by the load's direction). A speed whose equilibrium fails is kept in
/// `failed` with why, and the sweep goes on; Err if every speed failed.
pub(crate) fn sweep(b: &mut SweptBearing, speeds: &[f64]) -> anyhow::Result<SweepReport> {
    let w = b.load_n[0].hypot(b.load_n[1]);
    let load_angle = b.load_n[1].atan2(b.load_n[0]);
    let r = Rotation2::new(load_angle);
    let c = b.film.geometry().radial_clearance_m;
    check_top_speed(b, speeds)?;
    let mut rows = Vec::with_capacity(speeds.len());
    let mut failed = Vec::new();
    for &rpm in speeds {
        let omega = rpm_to_rad_s(rpm);
        let (eq, heat) = match equilibrium(b, omega) {
            Ok(v) => v,
            Err(e) if speeds.len() > 1 => {
                failed.push(FailedSpeed {
                    speed_rpm: rpm,
                    error: format!("{e:#}"),
                });
                continue;
            }
            Err(e) => {
                return Err(e.context(format!("static equilibrium of {} at {rpm} rpm", b.name)))
            }
        };
        let coef = eq.coefficients.turned_back(&r);
        let p = r.inverse() * nalgebra::Vector2::new(eq.position_m[0], eq.position_m[1]);
        let row = SpeedRow {
            speed_rpm: rpm,
            sommerfeld_number: eq.sommerfeld_number,
            eccentricity_ratio: eq.eccentricity_ratio,
            attitude_angle_deg: eq.attitude_angle_rad.to_degrees(),
            journal_position_m: [p[0], p[1]],
            journal_position_machine_m: eq.position_m,
            min_film_thickness_m: c * (1.0 - eq.eccentricity_ratio),
            max_pressure_pa: eq.film.max_pressure_pa,
            power_loss_w: eq.film.power_loss_w,
            stiffness_n_per_m: coef.stiffness_n_per_m,
            damping_n_s_per_m: coef.damping_n_s_per_m,
            stiffness_dimensionless: coef.dimensionless_stiffness(w, c),
            damping_dimensionless: coef.dimensionless_damping(w, c, omega),
            effective_temperature_c: heat.map(|h| h.0),
            temperature_rise_k: heat.map(|h| h.1),
            effective_viscosity_pa_s: heat.map(|h| h.2),
            heat_balance: heat.map(|h| h.3),
        };
        anyhow::ensure!(
            row_is_finite(&row),
            "the film solution of {} at {rpm} rpm holds a non-finite number; nothing printed",
            b.name
        );
        rows.push(row);
    }
    if rows.is_empty() {
        let first = &failed[0];
        anyhow::bail!(
            "static equilibrium of {} at {} rpm (and every other speed): {}",
            b.name,
            first.speed_rpm,
            first.error
        );
    }
    Ok(SweepReport {
        machine: b.machine.clone(),
        bearing: b.name.clone(),
        model: b.model,
        grid: b.grid.clone(),
        viscosity_pa_s: b.viscosity_pa_s,
        radial_clearance_m: c,
        load_n: w,
        load_direction_deg: load_angle.to_degrees(),
        frame: FRAME,
        speeds: rows,
        failed,
    })
}

fn row_is_finite(r: &SpeedRow) -> bool {
    let scalars = [
        r.sommerfeld_number,
        r.eccentricity_ratio,
        r.attitude_angle_deg,
        r.max_pressure_pa,
        r.power_loss_w,
    ];
    let matrices = [
        r.stiffness_n_per_m,
        r.damping_n_s_per_m,
        r.stiffness_dimensionless,
        r.damping_dimensionless,
    ];
    scalars.iter().all(|v| v.is_finite())
        && r.journal_position_machine_m.iter().all(|v| v.is_finite())
        && matrices.iter().flatten().all(|v| v.is_finite())
}

/// The sweep as a bearing code's table: S, ε, φ, the four stiffnesses (MN/m) and the four
/// dampings (kN·s/m), one speed a line.
pub(crate) fn print_table(r: &SweepReport) -> anyhow::Result<()> {
    let whose = if r.machine.is_empty() {
        String::new()
    } else {
        format!(" of {}", r.machine)
    };
    outln!(
        "rotor-twin bearing: {}{whose}, {:?} film, grid {}, static load {:.2} N at {:.1} deg \
         (machine frame), µ {} Pa·s",
        r.bearing,
        r.model,
        r.grid,
        r.load_n,
        r.load_direction_deg,
        r.viscosity_pa_s
    );
    outln!("  frame: {}", r.frame);
    outln!(
        "  {:>7} {:>8} {:>6} {:>6} | {:>8} {:>8} {:>8} {:>8} MN/m | {:>7} {:>7} {:>7} {:>7} kN·s/m",
        "rpm",
        "S",
        "ε",
        "φ deg",
        "kxx",
        "kxy",
        "kyx",
        "kyy",
        "cxx",
        "cxy",
        "cyx",
        "cyy"
    );
    // the rows and the failed speeds in speed order
    let mut failed = r.failed.iter().peekable();
    for s in &r.speeds {
        while let Some(f) = failed.next_if(|f| f.speed_rpm < s.speed_rpm) {
            outln!("  {:>7.0}  no equilibrium: {}", f.speed_rpm, f.error);
        }
        print_row(s)?;
    }
    for f in failed {
        outln!("  {:>7.0}  no equilibrium: {}", f.speed_rpm, f.error);
    }
    Ok(())
}

/// One speed's line (and its temperature's, when heated) of [`print_table`].
fn print_row(s: &SpeedRow) -> anyhow::Result<()> {
    // xx, xy, yx, yy: the transpose's column-major order is the matrix's row order
    let flat = |a: Matrix2<f64>, unit: f64| a.transpose() * unit;
    let (k, c) = (
        flat(s.stiffness_n_per_m, 1e-6),
        flat(s.damping_n_s_per_m, 1e-3),
    );
    outln!(
        "  {:>7.0} {:>8.4} {:>6.4} {:>6.2} | {:>8.3} {:>8.3} {:>8.3} {:>8.3}      | {:>7.3} \
         {:>7.3} {:>7.3} {:>7.3}",
        s.speed_rpm,
        s.sommerfeld_number,
        s.eccentricity_ratio,
        s.attitude_angle_deg,
        k[0],
        k[1],
        k[2],
        k[3],
        c[0],
        c[1],
        c[2],
        c[3]
    );
    if let (Some(t), Some(dt), Some(mu), Some(b)) = (
        s.effective_temperature_c,
        s.temperature_rise_k,
        s.effective_viscosity_pa_s,
        s.heat_balance,
    ) {
        outln!(
            "          {} {t:.2} °C ({} {dt:.2} K), µ_eff {:.4} mPa·s",
            b.temperature_label(),
            b.rise_label(),
            mu * 1e3
        );
    }
    Ok(())
}

/// The sweep as the plots take it.
pub(crate) fn curves(r: &SweepReport) -> crate::plot::BearingCurves {
    let of = |f: fn(&SpeedRow) -> f64| r.speeds.iter().map(f).collect();
    crate::plot::BearingCurves {
        name: if r.machine.is_empty() {
            r.bearing.clone()
        } else {
            format!("{} ({})", r.bearing, r.machine)
        },
        speeds_rpm: of(|s| s.speed_rpm),
        eccentricity: of(|s| s.eccentricity_ratio),
        attitude_deg: of(|s| s.attitude_angle_deg),
        stiffness: r.speeds.iter().map(|s| s.stiffness_n_per_m).collect(),
        damping: r.speeds.iter().map(|s| s.damping_n_s_per_m).collect(),
        position_m: r
            .speeds
            .iter()
            .map(|s| s.journal_position_machine_m)
            .collect(),
        clearance_m: r.radial_clearance_m,
        load_direction_deg: r.load_direction_deg,
    }
}
