//! `rotor-twin simulate` and `rotor-twin sweep`: nonlinear transients at constant speed or along
//! a speed history, with kicks.

use crate::cli::bearing::CavitationKind;
use crate::dynamics::Coupling;
use crate::film::FilmGrid;
use crate::monitor::RotorState;
use crate::rotor::{shown, MachineDescription, Rotor};
use crate::transient::{run_driven, Drive, Kick, SpeedHistory, TransientResult, TransientSpec};
use crate::units::shown_value;
use anyhow::Context;
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum ModelArg {
    /// Constant coefficients at the static equilibrium.
    Linear,
    /// Reynolds film force at every Newton iteration (the reference).
    Nonlinear,
    /// Reynolds film force at every iteration, relaxed coefficients as the iteration matrix
    /// (seed eq. 8).
    Prehistory,
}

/// Options shared by `simulate` and `sweep`.
#[derive(Debug, Clone, Args)]
pub(crate) struct RunOptions {
    /// Machine description (YAML); the built-in ORC microturbine if absent.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Give every film bearing its film's temporal fluid inertia (added mass, weightless),
    /// whatever the machine file's `fluid_inertia` says.
    #[arg(long)]
    fluid_inertia: bool,
    /// As --fluid-inertia, plus the convective and velocity-dependent inertia of the rotating
    /// film (eq. I1 of `src/film/inertia.rs`, `fluid_inertia: full`) as a force at every step.
    #[arg(long, conflicts_with = "fluid_inertia")]
    fluid_inertia_full: bool,
    /// Revolutions to simulate.
    #[arg(long, default_value_t = 200)]
    revs: usize,
    /// Bearing coupling.
    #[arg(long, value_enum, default_value_t = ModelArg::Nonlinear)]
    model: ModelArg,
    /// Prehistory relaxation factor δ in (0, 1].
    #[arg(long, default_value_t = 0.5)]
    delta: f64,
    /// Time steps per revolution.
    #[arg(long, default_value_t = 128)]
    steps_per_rev: usize,
    /// Film grid NTHxNZ for every finite film bearing (default: the machine file's).
    #[arg(long, value_parser = FilmGrid::parse)]
    grid: Option<FilmGrid>,
    /// Film evaluation: direct (the finite solver at every evaluation, the reference) or table
    /// (the same solutions tabulated once and interpolated; plain bearings).
    #[arg(long, value_enum, default_value_t = FilmArg::Direct)]
    film: FilmArg,
    /// Cavitation of every finite film: reynolds, or mass-conserving (JFO, the fluid fraction
    /// carried from step to step; direct film only; issue 18).
    #[arg(long, value_enum, default_value_t = CavitationKind::Reynolds)]
    cavitation: CavitationKind,
}

/// `--film`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum FilmArg {
    /// The finite solver at every evaluation.
    Direct,
    /// Tabulated finite solutions, interpolated.
    Table,
}

impl From<FilmArg> for crate::dynamics::FilmEvaluation {
    fn from(f: FilmArg) -> Self {
        match f {
            FilmArg::Direct => Self::Direct,
            FilmArg::Table => Self::Table,
        }
    }
}

impl RunOptions {
    fn coupling(&self) -> anyhow::Result<Coupling> {
        Ok(match self.model {
            ModelArg::Linear => Coupling::Linear,
            ModelArg::Nonlinear => Coupling::Nonlinear,
            ModelArg::Prehistory => {
                anyhow::ensure!(
                    self.delta.is_finite() && self.delta > 0.0 && self.delta <= 1.0,
                    "invalid --delta {}: the relaxation factor must lie in (0, 1]",
                    self.delta
                );
                Coupling::Prehistory { delta: self.delta }
            }
        })
    }

    fn machine(&self) -> anyhow::Result<(MachineDescription, Rotor)> {
        let desc = MachineDescription::load(self.config.as_deref())?;
        let mut rotor = Rotor::from_description(&desc);
        if self.fluid_inertia {
            rotor.set_fluid_inertia(crate::film::FluidInertia::Temporal);
        }
        if self.fluid_inertia_full {
            rotor.set_fluid_inertia(crate::film::FluidInertia::Full);
        }
        if self.cavitation != CavitationKind::Reynolds {
            anyhow::ensure!(
                self.film == FilmArg::Direct,
                "--cavitation mass-conserving needs --film direct: the film table holds \
                 Reynolds-condition films, and a mass-conserving film carries its fluid fraction \
                 from step to step, which a table over (ε, ψ) cannot"
            );
            rotor.set_cavitation(self.cavitation.into())?;
        }
        Ok((desc, rotor))
    }

    /// Why the twin cannot run at `speed_rpm` (issue 15, item 21), if it cannot: the one rule of
    /// `--speed-rpm`, the speeds of `--ramp` and `--speed-history`, and `sweep`'s speeds.
    fn speed_rule(&self, speed_rpm: f64, rotor: &Rotor) -> Result<(), String> {
        if !(speed_rpm.is_finite() && speed_rpm > 0.0) {
            return Err("must be finite and above zero".into());
        }
        let rpm = 30.0 / std::f64::consts::PI;
        let max_rpm = crate::dynamics::MAX_SPEED_OVER_RATED * rotor.rated_speed_rad_s * rpm;
        if speed_rpm > max_rpm {
            return Err(format!(
                "above {max_rpm:.0} rpm, {}× the rated speed of {}",
                crate::dynamics::MAX_SPEED_OVER_RATED,
                rotor.name
            ));
        }
        // one revolution in steps_per_rev steps of at most MAX_TIME_STEP_S
        let min_rpm = 60.0 / (self.steps_per_rev as f64 * crate::dynamics::MAX_TIME_STEP_S);
        if speed_rpm <= min_rpm {
            return Err(format!(
                "at or below {min_rpm:.2} rpm, where {} steps a revolution make the time step {} s or longer (raise --steps-per-rev)",
                self.steps_per_rev,
                crate::dynamics::MAX_TIME_STEP_S
            ));
        }
        Ok(())
    }

    /// The transient at `speed_rpm`, refused with the reason when the twin cannot run there
    /// (issue 15, item 21: a negative speed said "equilibrium not found", 1 rpm "invalid time
    /// step 0.46875", a 300-digit speed was tried and echoed whole).
    fn spec(&self, speed_rpm: f64, rotor: &Rotor) -> anyhow::Result<TransientSpec> {
        self.speed_rule(speed_rpm, rotor).map_err(|rule| {
            anyhow::anyhow!("invalid speed {} rpm: {rule}", shown_value(speed_rpm))
        })?;
        Ok(TransientSpec {
            speed_rpm,
            revolutions: self.revs,
            coupling: self.coupling()?,
            steps_per_rev: self.steps_per_rev,
            grid: self.grid,
            film: self.film.into(),
        })
    }
}

/// A nonlinear transient at constant speed or along a speed history, with kicks: orbits,
/// spectrum, classification.
#[derive(Debug, Clone, Args)]
pub struct SimulateArgs {
    /// Speed (rpm); not with --ramp or --speed-history.
    #[arg(long,
          required_unless_present_any = ["ramp", "speed_history"],
          conflicts_with_all = ["ramp", "speed_history"])]
    speed_rpm: Option<f64>,
    /// Run-up or run-down FROM:TO:RATE (rpm, rpm, rpm/s), then --revs revolutions at TO.
    #[arg(long, value_name = "FROM:TO:RATE", conflicts_with = "speed_history")]
    ramp: Option<String>,
    /// Speed history T:RPM,T:RPM,… (s from 0, increasing; rpm), linear between the points, then
    /// --revs revolutions at the last speed.
    #[arg(long, value_name = "T:RPM,…")]
    speed_history: Option<String>,
    /// An impulse T:NODE:JX:JY (s, shaft node, N·s, N·s) on the shaft; repeatable.
    #[arg(long, value_name = "T:NODE:JX:JY")]
    kick: Vec<String>,
    /// Write one line a revolution (time, speed, state, amplitudes, ε) to this CSV file.
    #[arg(long, value_name = "FILE")]
    history_csv: Option<PathBuf>,
    #[command(flatten)]
    options: RunOptions,
    /// Write orbit, spectrum and pressure-map SVGs of each bearing into this directory (with
    /// `--cavitation mass-conserving` also the fluid-fraction map, `fluid_fraction_<bearing>.svg`).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// `A:B:…` into numbers, naming the option and the field that is not one.
fn numbers(option: &str, text: &str, fields: &[&str]) -> anyhow::Result<Vec<f64>> {
    let parts: Vec<&str> = text.split(':').collect();
    anyhow::ensure!(
        parts.len() == fields.len(),
        "invalid {option} {}: expected {}",
        shown(text),
        fields.join(":")
    );
    parts
        .iter()
        .zip(fields)
        .map(|(p, f)| {
            p.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow::anyhow!(
                        "invalid {option} {}: {f} = {} is not a finite number",
                        shown(text),
                        shown(p)
                    )
                })
        })
        .collect()
}

/// Largest velocity (m/s) a `--kick` may give the whole rotor, J / M: 1 m/s crosses a 0.1 mm
/// clearance in 0.1 ms, about two time steps at 9,000 rpm and 128 steps a revolution; a larger
/// impulse is no disturbance the film model can follow, and 1e300 N·s is a typing slip.
const MAX_KICK_VELOCITY_M_S: f64 = 1.0;

/// `--kick T:NODE:JX:JY`, each field checked and named: T at least 0, NODE a shaft node, the
/// impulse within [`MAX_KICK_VELOCITY_M_S`] times the rotor's mass.
fn kick(text: &str, rotor: &Rotor) -> anyhow::Result<Kick> {
    let v = numbers("--kick", text, &["T", "NODE", "JX", "JY"])?;
    let shown = shown(text);
    anyhow::ensure!(
        v[0] >= 0.0,
        "invalid --kick {shown}: T = {} s must be at least 0",
        shown_value(v[0])
    );
    let nodes = rotor.node_z_m.len();
    anyhow::ensure!(
        v[1] >= 0.0 && v[1].fract() == 0.0 && v[1] < nodes as f64,
        "invalid --kick {shown}: NODE = {} must be a shaft node, 0 to {}",
        shown_value(v[1]),
        nodes - 1
    );
    let mass_kg: f64 = rotor.elements.iter().map(|e| e.mass_kg()).sum::<f64>()
        + rotor.discs.iter().map(|d| d.mass_kg).sum::<f64>();
    let max_n_s = MAX_KICK_VELOCITY_M_S * mass_kg;
    for (field, j) in [("JX", v[2]), ("JY", v[3])] {
        anyhow::ensure!(
            j.abs() <= max_n_s,
            "invalid --kick {shown}: {field} = {} N·s must be at most {} N·s in size, the \
             impulse that gives the whole rotor ({mass_kg:.1} kg) {MAX_KICK_VELOCITY_M_S} m/s",
            shown_value(j),
            shown_value((max_n_s * 1e3).round() / 1e3)
        );
    }
    Ok(Kick {
        time_s: v[0],
        node: v[1] as usize,
        impulse_n_s: [v[2], v[3]],
    })
}

impl SimulateArgs {
    /// The speed history and kicks the options ask for, checked field by field before anything
    /// is computed (issue 15, item 21: `--speed-history 0:8000,1:1e300` and `--kick
    /// 0.01:15:1e300:0` gave errors unrelated to the field).
    fn drive(&self, rotor: &Rotor) -> anyhow::Result<Drive> {
        let speed = match (&self.ramp, &self.speed_history) {
            (Some(r), _) => {
                let v = numbers("--ramp", r, &["FROM", "TO", "RATE"])?;
                for (field, rpm) in [("FROM", v[0]), ("TO", v[1])] {
                    self.check_field_speed("--ramp", r, field, rpm, rotor)?;
                }
                Some(SpeedHistory::ramp(v[0], v[1], v[2]).context("--ramp")?)
            }
            (None, Some(h)) => {
                let points = h
                    .split(',')
                    .map(|p| {
                        let v = numbers("--speed-history", p, &["T", "RPM"])?;
                        self.check_field_speed("--speed-history", p, "RPM", v[1], rotor)?;
                        Ok((v[0], v[1]))
                    })
                    .collect::<anyhow::Result<Vec<_>>>()?;
                Some(SpeedHistory::new(points).context("--speed-history")?)
            }
            (None, None) => None,
        };
        let kicks = self
            .kick
            .iter()
            .map(|k| kick(k, rotor))
            .collect::<anyhow::Result<Vec<_>>>()?;
        Ok(Drive { speed, kicks })
    }

    /// A speed field of `option` ('text'), under the one speed rule.
    fn check_field_speed(
        &self,
        option: &str,
        text: &str,
        field: &str,
        rpm: f64,
        rotor: &Rotor,
    ) -> anyhow::Result<()> {
        self.options.speed_rule(rpm, rotor).map_err(|rule| {
            anyhow::anyhow!(
                "invalid {option} {}: {field} = {} rpm: {rule}",
                shown(text),
                shown_value(rpm)
            )
        })
    }

    /// The speed the run starts at (rpm).
    fn start_speed_rpm(&self, drive: &Drive) -> f64 {
        match &drive.speed {
            Some(h) => h.at(0.0).0,
            None => self.speed_rpm.unwrap_or(f64::NAN),
        }
    }
}

/// One bearing in the `--json` report.
#[derive(Debug, Serialize)]
struct BearingSummary {
    name: String,
    orbit_pp_x_m: f64,
    orbit_pp_y_m: f64,
    max_eccentricity_ratio: f64,
    one_x_amplitude_m: f64,
    one_x_phase_deg: f64,
    subsync_ratio: f64,
    subsync_amplitude_m: f64,
    max_pressure_pa: f64,
    rev_to_rev_orbit_diff: f64,
    rev_to_rev_orbit_path_diff: f64,
    rev_to_rev_pressure_diff: f64,
    subsync_growth_per_rev: Option<f64>,
    time_to_alert_s: Option<f64>,
    amplitude_m: f64,
    alert_level_m: f64,
    danger_level_m: f64,
    contact_events: u32,
    max_penetration_m: f64,
    wall_valid: bool,
    max_rub_power_w: f64,
    mean_rub_power_w: f64,
    min_film_thickness_m: f64,
    pressure_valid: bool,
    span_revolutions: usize,
    beyond_clearance: bool,
    state: ReportedState,
}

/// The `--json` report of `simulate`.
#[derive(Debug, Serialize)]
struct SimulateReport {
    machine: String,
    speed_rpm: f64,
    model: ModelArg,
    /// Cavitation of the finite films.
    cavitation: CavitationKind,
    delta: Option<f64>,
    revs: usize,
    steps_per_rev: usize,
    state: ReportedState,
    evidence: String,
    rev_to_rev_orbit_diff: f64,
    rev_to_rev_pressure_diff: f64,
    wall_time_s: f64,
    simulated_time_s: f64,
    real_time_factor: f64,
    newton_iterations_per_step: f64,
    max_substeps: usize,
    /// Prehistory coupling: substeps whose relaxed iteration fell back to Newton (0 otherwise).
    prehistory_fallbacks: usize,
    /// False when the run left the model's validity: the linear coupling has no wall, and an
    /// orbit beyond the clearance (ε ≥ 1) is then no motion the machine can make.
    valid: bool,
    /// Why `valid` is false (empty when valid).
    validity: String,
    /// False when a bearing's film was thinner than the full-film limit in the last revolution:
    /// its `max_pressure_pa` is then no physical figure (grazing).
    pressure_valid: bool,
    /// Why `pressure_valid` is false (empty when valid).
    pressure_validity: String,
    /// Largest rubbing power of the wall contact in any revolution and bearing (W).
    max_rub_power_w: f64,
    /// The speed at the end of the run (rpm; `speed_rpm` is the start).
    final_speed_rpm: f64,
    /// The kicks applied: [t (s), node, J_x, J_y (N·s)].
    kicks: Vec<[f64; 4]>,
    bearings: Vec<BearingSummary>,
}

/// The state `simulate` reports: the monitor's, except for a journal that left its clearance
/// circle without a wall (the linear coupling, `beyond_clearance`): its motion is none the
/// machine can make, so it carries no whirl or whip label (issue 11: a linear run at ε = 970
/// was labelled "whip", then "whirl").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
enum ReportedState {
    Stable,
    Growing,
    Whirl,
    Whip,
    /// Outside the model's validity: the journal beyond the clearance, no wall to stop it.
    BeyondClearance,
}

impl ReportedState {
    fn new(state: RotorState, beyond_clearance: bool) -> Self {
        match (beyond_clearance, state) {
            (true, _) => Self::BeyondClearance,
            (false, RotorState::Stable) => Self::Stable,
            (false, RotorState::Growing) => Self::Growing,
            (false, RotorState::Whirl) => Self::Whirl,
            (false, RotorState::Whip) => Self::Whip,
        }
    }

    /// The name in the JSON and the history CSV.
    fn name(self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Growing => "growing",
            Self::Whirl => "whirl",
            Self::Whip => "whip",
            Self::BeyondClearance => "beyond_clearance",
        }
    }
}

/// Whether bearing `k` (all bearings when None) of run `r` was beyond its clearance without
/// a wall in any revolution.
fn left_clearance(r: &TransientResult, k: Option<usize>) -> bool {
    r.history.iter().any(|rev| {
        rev.bearings
            .iter()
            .enumerate()
            .any(|(i, b)| b.beyond_clearance && k.is_none_or(|k| k == i))
    })
}

/// Whether run `r` stayed inside what its model can represent, and why not: with the linear
/// coupling (no film nonlinearity, no wall) every journal must stay inside its clearance circle;
/// with the wall, its penalty spring must hold the journal centre inside the bore (a penetration
/// beyond the contact onset of at most the film left there) in every revolution.
fn validity(model: ModelArg, r: &TransientResult) -> (bool, String) {
    let all = || r.history.iter().flat_map(|rev| rev.bearings.iter());
    let worst = all()
        .map(|b| b.max_eccentricity_ratio)
        .fold(0.0_f64, f64::max);
    let mut why = Vec::new();
    if model == ModelArg::Linear && worst >= 1.0 {
        why.push(format!(
            "linear model beyond the clearance: eccentricity ratio reached {worst:.3} \
             (the linear coupling has no wall; use the nonlinear model)"
        ));
    }
    let through = all().filter(|b| !b.wall_valid).count();
    if through > 0 {
        let pen = all().map(|b| b.max_penetration_m).fold(0.0_f64, f64::max);
        why.push(format!(
            "wall penetration up to {:.2} µm beyond the contact onset in {through} bearing-\
             revolutions: the journal centre passed the bore (the wall spring is a penalty, too \
             soft for the load there)",
            pen * 1e6
        ));
    }
    (why.is_empty(), why.join("; "))
}

/// Whether the last revolution's film pressures are physical figures, and why not: at grazing
/// (film thinner than the full-film limit) the isoviscous rigid-surface pressure is not.
fn pressure_validity(r: &TransientResult) -> (bool, String) {
    let bad: Vec<String> = r
        .report
        .bearings
        .iter()
        .zip(&r.bearing_names)
        .filter(|(b, _)| !b.pressure_valid)
        .map(|(b, name)| {
            format!(
                "{name}: p_max {:.1} MPa at a film of {:.2} µm, below the full-film limit \
                 (Λ = h/σ < 3): grazing, not a physical pressure",
                b.max_pressure_pa * 1e-6,
                b.min_film_thickness_m * 1e6
            )
        })
        .collect();
    (bad.is_empty(), bad.join("; "))
}

fn summarise(
    desc: &MachineDescription,
    args: &SimulateArgs,
    drive: &Drive,
    r: &TransientResult,
) -> SimulateReport {
    let rep = &r.report;
    let (valid, why) = validity(args.options.model, r);
    let (pressure_valid, pressure_why) = pressure_validity(r);
    SimulateReport {
        machine: desc.name.clone(),
        speed_rpm: args.start_speed_rpm(drive),
        final_speed_rpm: crate::units::rad_s_to_rpm(rep.speed_rad_s),
        kicks: drive
            .kicks
            .iter()
            .map(|k| [k.time_s, k.node as f64, k.impulse_n_s[0], k.impulse_n_s[1]])
            .collect(),
        pressure_valid,
        pressure_validity: pressure_why,
        max_rub_power_w: r
            .history
            .iter()
            .flat_map(|rev| rev.bearings.iter().map(|b| b.max_rub_power_w))
            .fold(0.0, f64::max),
        model: args.options.model,
        cavitation: args.options.cavitation,
        delta: (args.options.model == ModelArg::Prehistory).then_some(args.options.delta),
        revs: args.options.revs,
        steps_per_rev: args.options.steps_per_rev,
        state: ReportedState::new(rep.state, left_clearance(r, None)),
        evidence: rep.evidence(),
        rev_to_rev_orbit_diff: rep.rev_to_rev_orbit_diff,
        rev_to_rev_pressure_diff: rep.rev_to_rev_pressure_diff,
        wall_time_s: r.wall_time_s,
        simulated_time_s: r.simulated_s,
        real_time_factor: r.real_time_factor(),
        newton_iterations_per_step: r.newton_iterations as f64 / r.steps.max(1) as f64,
        max_substeps: r.max_substeps,
        prehistory_fallbacks: r.prehistory_fallbacks,
        valid,
        validity: why,
        bearings: rep
            .bearings
            .iter()
            .zip(&r.bearing_names)
            .enumerate()
            .map(|(k, (b, name))| BearingSummary {
                name: name.clone(),
                orbit_pp_x_m: b.orbit_pp_x_m,
                orbit_pp_y_m: b.orbit_pp_y_m,
                max_eccentricity_ratio: b.max_eccentricity_ratio,
                one_x_amplitude_m: b.one_x_amplitude_m,
                one_x_phase_deg: b.one_x_phase_rad.to_degrees(),
                subsync_ratio: b.subsync_ratio,
                subsync_amplitude_m: b.subsync_amplitude_m,
                max_pressure_pa: b.max_pressure_pa,
                rev_to_rev_orbit_diff: b.orbit_diff,
                rev_to_rev_orbit_path_diff: b.orbit_path_diff,
                rev_to_rev_pressure_diff: b.pressure_diff,
                subsync_growth_per_rev: b.subsync_growth_per_rev,
                time_to_alert_s: b.time_to_alert_s,
                amplitude_m: b.amplitude_m,
                alert_level_m: b.alert_level_m,
                danger_level_m: b.danger_level_m,
                contact_events: b.contact_events,
                max_penetration_m: b.max_penetration_m,
                wall_valid: b.wall_valid,
                max_rub_power_w: b.max_rub_power_w,
                mean_rub_power_w: b.mean_rub_power_w,
                min_film_thickness_m: b.min_film_thickness_m,
                pressure_valid: b.pressure_valid,
                span_revolutions: b.span_revolutions,
                beyond_clearance: b.beyond_clearance,
                state: ReportedState::new(b.state, left_clearance(r, Some(k))),
            })
            .collect(),
    }
}

pub(crate) fn run_simulate(args: &SimulateArgs) -> anyhow::Result<()> {
    let (desc, rotor) = args.options.machine()?;
    let drive = args.drive(&rotor)?;
    let spec = args.options.spec(args.start_speed_rpm(&drive), &rotor)?;
    if let Some(dir) = &args.plot {
        super::check_output("--plot", dir, super::Output::Directory)?;
    }
    if let Some(path) = &args.history_csv {
        super::check_output("--history-csv", path, super::Output::File)?;
    }
    note_heating(&rotor, spec.film);
    let result = run_driven(&rotor, &spec, None, &drive).context("transient")?;
    if let Some(dir) = &args.plot {
        write_plots(dir, &result)
            .with_context(|| format!("writing plots into {}", dir.display()))?;
    }
    if let Some(path) = &args.history_csv {
        write_history_csv(path, &result).with_context(|| format!("writing {}", path.display()))?;
    }
    let report = summarise(&desc, args, &drive, &result);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "rotor-twin simulate: {} at {:.0} rpm, {:?} coupling{}, {:?} cavitation, {} revolutions × {} steps",
            report.machine,
            report.speed_rpm,
            report.model,
            report
                .delta
                .map_or(String::new(), |d| format!(" (δ = {d})")),
            report.cavitation,
            report.revs,
            report.steps_per_rev
        );
        println!("  state: {:?} — {}", report.state, report.evidence);
        if !report.valid {
            println!("  NOT VALID: {}", report.validity);
        }
        if !report.pressure_valid {
            println!("  PRESSURES NOT VALID: {}", report.pressure_validity);
        }
        if report.prehistory_fallbacks > 0 {
            println!(
                "  prehistory: {} substeps fell back to Newton",
                report.prehistory_fallbacks
            );
        }
        println!(
            "  last two revolutions: orbit difference {:.2e} of the clearance, pressure-field difference {:.2e}",
            report.rev_to_rev_orbit_diff, report.rev_to_rev_pressure_diff
        );
        for b in &report.bearings {
            println!(
                "  {:<22} orbit p-p {:6.2} × {:6.2} µm, max ε {:.3}, 1X {:6.2} µm @ {:6.1}°, sub-sync {}, growth {}, p_max {:.3} MPa",
                b.name,
                b.orbit_pp_x_m * 1e6,
                b.orbit_pp_y_m * 1e6,
                b.max_eccentricity_ratio,
                b.one_x_amplitude_m * 1e6,
                b.one_x_phase_deg,
                crate::monitor::subsync_words(b.subsync_ratio, b.subsync_amplitude_m),
                crate::monitor::growth_words_per_rev(b.subsync_growth_per_rev),
                b.max_pressure_pa * 1e-6
            );
        }
        println!(
            "  {:.3} s simulated in {:.2} s: real-time factor {:.3}; {:.2} Newton iterations a step",
            report.simulated_time_s, report.wall_time_s, report.real_time_factor, report.newton_iterations_per_step
        );
    }
    Ok(())
}

/// One line a revolution: time, speed, state, and per bearing the amplitude (half the larger
/// peak-to-peak over the whirl span), the sub-synchronous semi-major axis, the largest ε and
/// the contacts begun.
fn write_history_csv(path: &Path, r: &TransientResult) -> anyhow::Result<()> {
    let mut csv = String::from("revolution,time_s,speed_rpm,state");
    for name in &r.bearing_names {
        csv += &format!(
            ",{name}_amplitude_m,{name}_subsync_amplitude_m,{name}_max_eccentricity_ratio,{name}_contact_events"
        );
    }
    csv.push('\n');
    for rev in &r.history {
        csv += &format!(
            "{},{},{},{}",
            rev.revolution,
            rev.time_s,
            crate::units::rad_s_to_rpm(rev.speed_rad_s),
            ReportedState::new(rev.state, rev.bearings.iter().any(|b| b.beyond_clearance)).name()
        );
        for b in &rev.bearings {
            csv += &format!(
                ",{},{},{},{}",
                b.amplitude_m, b.subsync_amplitude_m, b.max_eccentricity_ratio, b.contact_events
            );
        }
        csv.push('\n');
    }
    std::fs::write(path, csv)?;
    Ok(())
}

/// With `oil_heating`, says (on stderr) that the run heats its films as the node does, and
/// with the thermal film, what the `film` evaluation runs of its field.
fn note_heating(rotor: &Rotor, film: crate::dynamics::FilmEvaluation) {
    if !rotor.has_oil_heating() {
        return;
    }
    eprintln!(
        "oil_heating: each film runs at its heat balance's viscosity (the machine file's supply \
         temperature), redone past {} % of speed, as the node does",
        100.0 * crate::driver::HEAT_BALANCE_SPEED_STEP
    );
    let thermal = rotor.bearings.iter().any(|b| {
        matches!(&b.model, crate::rotor::BearingModel::Film(f)
            if f.heating.is_some_and(|h| h.balance == crate::film::HeatBalance::ThermalFilm))
    });
    if thermal {
        eprintln!(
            "  thermal_film: {}",
            match film {
                crate::dynamics::FilmEvaluation::Direct =>
                    "the direct film runs the thermal film's viscosity field around each bearing",
                crate::dynamics::FilmEvaluation::Table =>
                    "the table runs the thermal film's mean temperature (a table holds a uniform \
                     viscosity; --film direct runs its field)",
            }
        );
    }
}

fn write_plots(dir: &Path, r: &TransientResult) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    for (i, name) in r.bearing_names.iter().enumerate() {
        crate::plot::orbit_svg(
            &dir.join(format!("orbit_{name}.svg")),
            &format!("orbit: {name}"),
            &r.orbits[i],
            r.clearances_m[i],
        )?;
        crate::plot::spectrum_svg(
            &dir.join(format!("spectrum_{name}.svg")),
            &format!("full spectrum: {name}"),
            &r.spectra[i],
        )?;
        let not_valid = r
            .report
            .bearings
            .get(i)
            .filter(|b| !b.pressure_valid)
            .map(|b| {
                format!(
                    "grazing: film {:.2} µm, below the full-film limit (Λ = h/σ < 3); p_max {:.1} MPa \
                     is not a physical pressure",
                    b.min_film_thickness_m * 1e6,
                    b.max_pressure_pa * 1e-6
                )
            });
        crate::plot::pressure_map_svg(
            &dir.join(format!("pressure_{name}.svg")),
            &format!("mid-plane pressure: {name}"),
            &r.pressure_maps[i],
            not_valid.as_deref(),
        )?;
        if !r.fluid_fraction_maps[i].is_empty() {
            crate::plot::fluid_fraction_map_svg(
                &dir.join(format!("fluid_fraction_{name}.svg")),
                &format!("mid-plane fluid fraction: {name}"),
                &r.fluid_fraction_maps[i],
                r.feed_angles_rad[i].map(f64::to_degrees),
            )?;
        }
    }
    Ok(())
}

/// Amplitude–speed characteristic: a transient at each speed, in parallel.
#[derive(Debug, Clone, Args)]
pub struct SweepArgs {
    /// Lowest speed (rpm).
    #[arg(long)]
    from_rpm: f64,
    /// Highest speed (rpm).
    #[arg(long)]
    to_rpm: f64,
    /// Speed step (rpm).
    #[arg(long)]
    step_rpm: f64,
    #[command(flatten)]
    options: RunOptions,
    /// Directory for sweep.csv and sweep.svg.
    #[arg(long, default_value = "sweep")]
    out: PathBuf,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct SweepReport {
    machine: String,
    model: ModelArg,
    /// Cavitation of the finite films.
    cavitation: CavitationKind,
    onset_speed_rpm: Option<f64>,
    points: Vec<crate::sweep::SweepPoint>,
    csv: String,
    svg: String,
}

/// What a sweep can check before computing any speed (issue 15, item 20): every speed within
/// the twin's limit for this machine, and an output directory that can be made.
fn check_sweep_first(args: &SweepArgs, rotor: &Rotor) -> anyhow::Result<()> {
    for (option, rpm) in [("--from-rpm", args.from_rpm), ("--to-rpm", args.to_rpm)] {
        args.options
            .speed_rule(rpm, rotor)
            .map_err(|rule| anyhow::anyhow!("invalid {option} {}: {rule}", shown_value(rpm)))?;
    }
    super::check_output("--out", &args.out, super::Output::Directory)
}

/// The sweep's speeds (rpm), checked: finite, positive, ascending, at most 500.
fn sweep_speeds(args: &SweepArgs) -> anyhow::Result<Vec<f64>> {
    for (name, v) in [
        ("--from-rpm", args.from_rpm),
        ("--to-rpm", args.to_rpm),
        ("--step-rpm", args.step_rpm),
    ] {
        anyhow::ensure!(
            v.is_finite() && v > 0.0,
            "invalid {name} {}: must be a finite speed above zero",
            shown_value(v)
        );
    }
    anyhow::ensure!(
        args.to_rpm >= args.from_rpm,
        "invalid --to-rpm {}: below --from-rpm {}",
        shown_value(args.to_rpm),
        shown_value(args.from_rpm)
    );
    let count = ((args.to_rpm - args.from_rpm) / args.step_rpm).round() as usize + 1;
    anyhow::ensure!(
        count <= 500,
        "invalid --step-rpm {}: more than 500 speeds",
        shown_value(args.step_rpm)
    );
    Ok((0..count)
        .map(|k| (args.from_rpm + k as f64 * args.step_rpm).min(args.to_rpm))
        .collect())
}

/// Runs `rotor-twin sweep` ([`crate::sweep`]): writes sweep.csv and sweep.svg, prints the table
/// and the onset.
pub(crate) fn run_sweep(args: &SweepArgs) -> anyhow::Result<()> {
    let speeds = sweep_speeds(args)?;
    let (desc, rotor) = args.options.machine()?;
    check_sweep_first(args, &rotor)?;
    note_heating(&rotor, args.options.film.into());
    let specs = speeds
        .iter()
        .map(|&s| args.options.spec(s, &rotor))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let sweep = crate::sweep::run_sweep(&rotor, &specs, |d, count| {
        let bar = "#".repeat(30 * d / count);
        eprint!("\rsweep [{bar:<30}] {d}/{count} speeds");
    });
    eprintln!();
    let sweep = sweep?;
    let csv_path = args.out.join("sweep.csv");
    let svg_path = args.out.join("sweep.svg");
    std::fs::write(&csv_path, sweep.csv())
        .with_context(|| format!("writing {}", csv_path.display()))?;
    let series: Vec<(String, Vec<f64>, Vec<f64>)> = sweep
        .series
        .iter()
        .map(|s| {
            (
                s.name.clone(),
                s.amplitude_m.clone(),
                s.subsync_amplitude_m.clone(),
            )
        })
        .collect();
    crate::plot::sweep_svg(
        &svg_path,
        &format!("amplitude–speed characteristic: {}", desc.name),
        &speeds,
        &series,
    )?;
    let report = SweepReport {
        machine: desc.name,
        model: args.options.model,
        cavitation: args.options.cavitation,
        onset_speed_rpm: sweep.onset_speed_rpm(),
        points: sweep.points,
        csv: csv_path.display().to_string(),
        svg: svg_path.display().to_string(),
    };
    print_sweep(&report, args.json)
}

/// The sweep's table (or its JSON).
fn print_sweep(report: &SweepReport, json: bool) -> anyhow::Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(report)?);
        return Ok(());
    }
    println!(
        "rotor-twin sweep: {} ({:?} coupling, {:?} cavitation)",
        report.machine, report.model, report.cavitation
    );
    for p in &report.points {
        println!(
            "  {:>8.0} rpm  {:<8}  sub-sync growth {}  max ε {:.3}  sub-sync {}",
            p.speed_rpm,
            format!("{:?}", p.state),
            crate::monitor::growth_words_per_rev(p.subsync_growth_per_rev),
            p.max_eccentricity_ratio,
            if p.subsync_ratio > 0.0 {
                format!("{:.3}X", p.subsync_ratio)
            } else {
                "none".into()
            }
        );
    }
    match report.onset_speed_rpm {
        Some(s) => println!("  onset of instability: {s:.0} rpm"),
        None => println!("  stable over the range"),
    }
    println!("  wrote {} and {}", report.csv, report.svg);
    Ok(())
}
