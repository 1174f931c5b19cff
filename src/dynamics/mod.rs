//! The twin core: seed eq. 5, M q̈ + D(q, q̇, t) q̇ + K(q, q̇, t) q = F(t), advanced in time by the
//! implicit Newmark method with the bearing films in the loop. One I/O-free engine ([`Twin`]) with
//! explicit state that the node, the replay and the offline tools all drive: it knows no ROS, no
//! files and no clock. A step allocates nothing.
//!
//! Bearing coupling ([`Coupling`]):
//! - `Linear`: the seed's classical description, constant coefficients at the static equilibrium;
//! - `Nonlinear`: the film force from the Reynolds solution at every Newton iteration, its
//!   perturbation coefficients as the Jacobian (the reference);
//! - `Prehistory { delta }`: seed eq. 8 as the seed summary found it consistent: the film force is
//!   the Reynolds force at every iteration, while the film coefficients, computed once a step and
//!   relaxed as c(k+1) = δ c(k) + (1 − δ) c(k−1), serve as the iteration matrix. Iterated to the
//!   same tolerance as `Nonlinear`; a step whose relaxed iteration does not converge falls back to
//!   Newton and is counted (`prehistory_fallbacks`).

mod band_lu;
mod bearing_link;
mod linear;
pub use linear::MAX_CONDENSED_DOFS;
mod twin;

pub use bearing_link::{ContactModel, LinkEvaluation};
pub use twin::{Checkpoint, Twin};

/// A speed above this multiple of the machine's rated speed is absurd: the twin refuses to step
/// there, the driver refuses such an input, `sweep` refuses such a speed before computing any.
pub const MAX_SPEED_OVER_RATED: f64 = 10.0;

/// Longest time step the twin takes (s): a revolution in `steps_per_rev` steps sets the slowest
/// speed it can run.
pub const MAX_TIME_STEP_S: f64 = 0.1;

use crate::film::FilmError;
use serde::Serialize;
use thiserror::Error;

/// How the bearing films enter the equations of motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "model")]
pub enum Coupling {
    /// Constant coefficients at the static equilibrium (re-linearised when the speed changes).
    Linear,
    /// Film force from the Reynolds equation, Newton-iterated to convergence.
    Nonlinear,
    /// Reynolds force each iteration, relaxed coefficients (factor `delta`, seed eq. 8) as the
    /// iteration matrix.
    Prehistory {
        /// Relaxation factor δ in (0, 1]; 1 means no relaxation.
        delta: f64,
    },
}

/// How the film force of a fluid-film bearing is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FilmEvaluation {
    /// The film model itself at every evaluation (the finite-length Reynolds solver: the
    /// reference).
    #[default]
    Direct,
    /// The same finite-length solutions, tabulated once over (ε, ψ) and interpolated
    /// ([`crate::film::TabulatedFilm`]); plain bearings on the finite model only.
    Table,
}

/// Builds (or finds: in the process, in the disk cache) the film tables of every plain
/// finite-film bearing of `rotor`, so that a twin with [`FilmEvaluation::Table`] starts without
/// delay; where each came from, bearing by bearing.
pub fn prepare_film_tables(
    rotor: &crate::rotor::Rotor,
) -> Result<Vec<crate::film::TableOrigin>, crate::film::FilmError> {
    let mut origins = Vec::new();
    for b in &rotor.bearings {
        if let crate::rotor::BearingModel::Film(f) = &b.model {
            if !f.short && f.geometry.grooves.is_empty() {
                let (_, origin) =
                    crate::film::FilmTable::shared_with_origin(&f.geometry, f.lubricant, f.grid)?;
                origins.push(origin);
            }
        }
    }
    Ok(origins)
}

/// Settings of the twin core.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwinConfig {
    /// Bearing coupling.
    pub coupling: Coupling,
    /// Time step h (s); e.g. one 128th of a revolution at rated speed.
    pub time_step_s: f64,
    /// Newton converges when the error left in the journal positions is below this share of the
    /// clearance: a correction below √(tol (1 − ε)) (Newton's quadratic convergence leaves
    /// ~|Δ|²/((1 − ε)c)) while every journal stays below ε = 0.8, below tol otherwise (near the
    /// wall, in contact) and in prehistory.
    pub newton_tolerance: f64,
    /// Newton iterations allowed before the step is retried with half the time step.
    pub max_newton_iterations: usize,
    /// Relative speed change after which the gyroscopic part is refactored (and, in linear
    /// coupling, the bearings re-linearised).
    pub speed_refactor_tolerance: f64,
    /// Wall contact.
    pub contact: ContactModel,
    /// Film evaluation.
    pub film: FilmEvaluation,
}

impl TwinConfig {
    /// Defaults for `steps_per_rev` steps per revolution at `speed_rad_s` (rad/s).
    pub fn with_steps_per_rev(coupling: Coupling, speed_rad_s: f64, steps_per_rev: usize) -> Self {
        Self {
            coupling,
            time_step_s: std::f64::consts::TAU / (speed_rad_s.abs() * steps_per_rev as f64),
            newton_tolerance: 1e-7,
            max_newton_iterations: 25,
            speed_refactor_tolerance: 2e-3,
            contact: ContactModel::default(),
            film: FilmEvaluation::Direct,
        }
    }
}

/// What drives one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepInput {
    /// Spin speed at the end of the step (rad/s).
    pub speed_rad_s: f64,
    /// Angular acceleration (rad/s²), for the tangential unbalance force.
    pub accel_rad_s2: f64,
}

/// The state of one bearing after a step. Angles from +x towards +y (rad).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct BearingState {
    /// Journal centre relative to the bearing (pedestal) centre `[x, y]` (m).
    pub position_m: [f64; 2],
    /// Its velocity (m/s).
    pub velocity_m_s: [f64; 2],
    /// Eccentricity ratio e/c.
    pub eccentricity_ratio: f64,
    /// Angle of the journal centre's displacement (rad).
    pub attitude_rad: f64,
    /// Film (and contact) force on the journal (N).
    pub force_n: [f64; 2],
    /// Peak film pressure (Pa) and its angle (rad).
    pub max_pressure_pa: f64,
    /// Angle of the peak pressure (rad).
    pub max_pressure_angle_rad: f64,
    /// ζ1, start of the pressure zone (rad).
    pub film_start_rad: f64,
    /// ζ2, film rupture (rad).
    pub film_end_rad: f64,
    /// Power dissipated in the film (W).
    pub power_loss_w: f64,
    /// True if the journal touched the wall in this step.
    pub contact: bool,
    /// Power dissipated by rubbing on the wall in this step (W; zero without contact).
    pub rub_power_w: f64,
}

/// A probe station after a step.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ProbeState {
    /// Shaft displacement at the station `[x, y]` (m).
    pub displacement_m: [f64; 2],
    /// What the two probes read: the displacement along each probe's direction (m).
    pub readings_m: [f64; 2],
}

/// Everything a step reports. Lives inside the twin and is overwritten by the next step.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct StepOutput {
    /// Time at the end of the step (s).
    pub time_s: f64,
    /// Rotor angle (rad), the phase reference of the unbalance.
    pub angle_rad: f64,
    /// Spin speed (rad/s).
    pub speed_rad_s: f64,
    /// One entry per film or linear bearing, in machine order.
    pub bearings: Vec<BearingState>,
    /// One entry per probe station.
    pub probes: Vec<ProbeState>,
    /// Newton iterations of this step (summed over substeps).
    pub newton_iterations: usize,
    /// Substeps the step was split into (1 when it converged at once).
    pub substeps: usize,
    /// Prehistory coupling: substeps whose relaxed-coefficient iteration did not converge and
    /// fell back to Newton.
    pub prehistory_fallbacks: usize,
}

/// Why a twin could not be built or a step not taken.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TwinError {
    /// An input out of range (NaN, negative, absurd).
    #[error("invalid {name}: {value} ({rule})")]
    InvalidInput {
        /// Which input, with its unit.
        name: &'static str,
        /// The value.
        value: f64,
        /// The rule.
        rule: &'static str,
    },
    /// A film solve failed.
    #[error("bearing '{bearing}' at t = {time_s:.6} s: {cause}")]
    Film {
        /// Bearing name.
        bearing: String,
        /// Time (s).
        time_s: f64,
        /// The film model's error (in this error's text, not again as its source).
        cause: FilmError,
    },
    /// The step did not converge even with a sixteenth of the time step; the state is unchanged.
    #[error(
        "step at t = {time_s:.6} s did not converge ({iterations} Newton iterations, even at h/16)"
    )]
    NotConverged {
        /// Time (s).
        time_s: f64,
        /// Iterations made.
        iterations: usize,
    },
    /// The model could not be set up.
    #[error("cannot set up the twin: {0}")]
    Setup(String),
}
