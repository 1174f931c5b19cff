//! The driver's settings: every default of the live node and the replay in one place, each with
//! its unit and the reason for its value.

use crate::dynamics::{Coupling, FilmEvaluation, TwinConfig};
use crate::session::SessionSettings;
use std::fmt;
use std::str::FromStr;

/// Bearing coupling, as a parameter names it (`linear | nonlinear | prehistory`); the prehistory
/// relaxation factor is a setting of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ModelKind {
    /// Constant coefficients at the static equilibrium (the seed's classical description).
    Linear,
    /// The Reynolds film force at every Newton iteration (the reference).
    #[default]
    Nonlinear,
    /// Reynolds force, relaxed coefficients as the iteration matrix (seed eq. 8).
    Prehistory,
}

impl ModelKind {
    /// The twin's coupling, with relaxation factor `delta` for prehistory.
    pub fn coupling(self, delta: f64) -> Coupling {
        match self {
            ModelKind::Linear => Coupling::Linear,
            ModelKind::Nonlinear => Coupling::Nonlinear,
            ModelKind::Prehistory => Coupling::Prehistory { delta },
        }
    }
}

impl FromStr for ModelKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "linear" => Ok(ModelKind::Linear),
            "nonlinear" => Ok(ModelKind::Nonlinear),
            "prehistory" => Ok(ModelKind::Prehistory),
            other => Err(format!("'{other}' must be linear, nonlinear or prehistory")),
        }
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ModelKind::Linear => "linear",
            ModelKind::Nonlinear => "nonlinear",
            ModelKind::Prehistory => "prehistory",
        })
    }
}

/// Parses a film evaluation (`table | direct`).
pub fn parse_film(s: &str) -> Result<FilmEvaluation, String> {
    match s.trim() {
        "table" => Ok(FilmEvaluation::Table),
        "direct" => Ok(FilmEvaluation::Direct),
        other => Err(format!("'{other}' must be table or direct")),
    }
}

/// The name of a film evaluation, as [`parse_film`] reads it.
pub fn film_name(f: FilmEvaluation) -> &'static str {
    match f {
        FilmEvaluation::Table => "table",
        FilmEvaluation::Direct => "direct",
    }
}

/// Time steps a revolution at rated speed (default of the node and the replay): 64 gives the
/// whip's sub-synchronous amplitude within 0.07 % of 128 (tests/transient_orc.rs), at half the
/// cost.
pub const DEFAULT_STEPS_PER_REV: usize = 64;

/// Prehistory relaxation factor δ (default everywhere): converged results do not depend on it
/// (README "Prehistory"); 0.5 fell back to Newton least often in the whip.
pub const DEFAULT_DELTA: f64 = 0.5;

/// Below this speed (rpm) the twin pauses and starts afresh above it: the time step is sized for
/// the rated speed, and far below it the film carries the load only at large eccentricity.
pub const DEFAULT_MIN_SPEED_RPM: f64 = 1000.0;

/// How the twin is driven from timed inputs (node and replay alike).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriverSettings {
    /// The twin core's configuration (coupling, film evaluation, time step).
    pub twin: TwinConfig,
    /// Output rates and warning thresholds.
    pub session: SessionSettings,
    /// Below this speed (rad/s) the twin pauses; default [`DEFAULT_MIN_SPEED_RPM`].
    pub min_speed_rad_s: f64,
    /// A speed older than this (s) is stale: warned about (repeated at this interval) and held.
    /// Also the tolerance of speed and probe stamps against the clock. Default 1 s: ten missed
    /// samples of a 10 Hz speed source.
    pub input_timeout_s: f64,
    /// With no input at all for this long (s) the twin stops, and starts afresh from the static
    /// equilibrium at the next speed: a recording that spans a pause is not modelled through the
    /// pause. Default 5 s.
    pub max_gap_s: f64,
    /// Speed stamps are checked against the driver's clock (stale, future, backwards). On for
    /// the node, whose stamps and clock share the bus; off for a replay, whose bags may come
    /// from tools that stamp on other clocks (the receive time orders the samples there).
    pub check_speed_stamps: bool,
    /// Heat balances (`oil_heating`) run on a worker thread and their scales are taken at the
    /// next wake after they finish (`driver::heat_worker`): on for the node, whose model thread
    /// must not stall for a balance; off for the replay and the offline runs, which balance on
    /// their own thread so that the same inputs give the same outputs.
    pub heat_balance_off_thread: bool,
}

impl DriverSettings {
    /// The defaults for a machine rated `rated_speed_rad_s`, with `model` and `film`.
    pub fn new(model: ModelKind, film: FilmEvaluation, rated_speed_rad_s: f64) -> Self {
        Self {
            twin: TwinConfig {
                film,
                ..TwinConfig::with_steps_per_rev(
                    model.coupling(DEFAULT_DELTA),
                    rated_speed_rad_s,
                    DEFAULT_STEPS_PER_REV,
                )
            },
            session: SessionSettings::default(),
            min_speed_rad_s: crate::units::rpm_to_rad_s(DEFAULT_MIN_SPEED_RPM),
            input_timeout_s: 1.0,
            max_gap_s: 5.0,
            check_speed_stamps: true,
            heat_balance_off_thread: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for m in [
            ModelKind::Linear,
            ModelKind::Nonlinear,
            ModelKind::Prehistory,
        ] {
            assert_eq!(m.to_string().parse::<ModelKind>(), Ok(m));
        }
        for f in [FilmEvaluation::Table, FilmEvaluation::Direct] {
            assert_eq!(parse_film(film_name(f)), Ok(f));
        }
        assert!("quadratic"
            .parse::<ModelKind>()
            .unwrap_err()
            .contains("quadratic"));
        assert!(parse_film("tabled").is_err());
    }
}
