//! Errors of machine descriptions and rotor analyses.

use thiserror::Error;

/// A machine description that breaks a rule: names the file, the field, the value and the rule.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{file}: {field}{}: {rule}", if value.is_empty() { String::new() } else { format!(" = {value}") })]
pub struct ConfigError {
    /// The file (or "built in").
    pub file: String,
    /// Path of the field, e.g. `bearings[1].radial_clearance_m`.
    pub field: String,
    /// The value found (empty when the parser could not read one).
    pub value: String,
    /// The rule it breaks.
    pub rule: String,
}

/// Why a rotor analysis could not be done.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RotorError {
    /// A film computation failed at a bearing.
    #[error("bearing '{bearing}' at {speed_rpm:.0} rpm: {cause}")]
    Film {
        /// Bearing name.
        bearing: String,
        /// Speed (rpm).
        speed_rpm: f64,
        /// What the film model said (shown in this error's text, not again as its source:
        /// the chain printed it twice).
        cause: crate::film::FilmError,
    },
    /// A linear-algebra step failed (singular or indefinite matrix, eigen solver).
    #[error("{what}: {why}")]
    LinearAlgebra {
        /// Which step.
        what: &'static str,
        /// Why.
        why: String,
    },
    /// An analysis input is out of range.
    #[error("invalid {name}: {value} ({rule})")]
    InvalidInput {
        /// Which input, with its unit.
        name: &'static str,
        /// The value.
        value: f64,
        /// The rule it breaks.
        rule: &'static str,
    },
}
