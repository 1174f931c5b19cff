//! Errors of the film models: each names the parameter, the value and the rule it broke.

use thiserror::Error;

/// Why a film computation could not be done.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FilmError {
    /// An input is not a finite number, or is outside its physical range.
    #[error("invalid {name}: {value} ({rule})")]
    InvalidParameter {
        /// Which input, with its unit.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The rule it breaks.
        rule: &'static str,
    },
    /// The journal is at or beyond the bearing wall: the film cannot carry it.
    #[error(
        "journal outside the film: eccentricity ratio {eccentricity_ratio:.4} (must be below {})",
        super::MAX_ECCENTRICITY_RATIO
    )]
    JournalOutsideFilm {
        /// e / c (dimensionless).
        eccentricity_ratio: f64,
    },
    /// The complementarity (cavitation) iteration did not settle.
    #[error(
        "cavitation active-set iteration did not converge in {iterations} iterations, journal at ε {eccentricity_ratio:.4}, attitude {attitude_deg:.1}° from +x, velocity ({:.3e}, {:.3e}) m/s, speed {speed_rad_s:.2} rad/s",
        velocity_m_s[0],
        velocity_m_s[1]
    )]
    CavitationNotConverged {
        /// Iterations made.
        iterations: usize,
        /// e / c of the journal (dimensionless).
        eccentricity_ratio: f64,
        /// Angle of the journal centre from +x, in the direction of rotation (degrees).
        attitude_deg: f64,
        /// Journal velocity (ẋ, ẏ) (m/s).
        velocity_m_s: [f64; 2],
        /// Shaft speed (rad/s).
        speed_rad_s: f64,
    },
    /// The film matrix was not positive definite (film thickness not positive somewhere).
    #[error("film matrix not positive definite: the film thickness is not positive everywhere")]
    SingularFilm,
    /// The static equilibrium search did not converge.
    #[error("static equilibrium not found after {iterations} iterations (force residual {residual_n:.3e} N)")]
    EquilibriumNotFound {
        /// Iterations made.
        iterations: usize,
        /// Remaining force imbalance (N).
        residual_n: f64,
    },
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, FilmError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(FilmError::InvalidParameter {
            name,
            value,
            rule: "must be a finite number greater than zero",
        })
    }
}
