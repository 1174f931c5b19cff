//! The field rules of a machine file, one place: each names the field and the value it refuses.

use crate::rotor::ConfigError;
use nalgebra::Matrix2;
use std::fmt::Display;

/// Longest name of a bearing or probe station (characters); names appear in topics, warnings
/// and file names.
pub const MAX_NAME_CHARS: usize = 64;

/// Rule checks for one file; every error names `file`.
pub(crate) struct Rules<'a> {
    /// The file (or "built in").
    pub file: &'a str,
}

impl Rules<'_> {
    /// The error for `field` holding `value`, which breaks `rule`.
    pub fn error(
        &self,
        field: impl Into<String>,
        value: impl Display,
        rule: impl Display,
    ) -> ConfigError {
        ConfigError {
            file: self.file.to_string(),
            field: field.into(),
            value: value.to_string(),
            rule: rule.to_string(),
        }
    }

    /// `v` is finite and greater than zero.
    pub fn positive(&self, field: impl Into<String>, v: f64) -> Result<(), ConfigError> {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(self.error(
                field,
                crate::units::shown_value(v),
                "must be a finite number greater than zero",
            ))
        }
    }

    /// `v` is finite and zero or more.
    pub fn non_negative(&self, field: impl Into<String>, v: f64) -> Result<(), ConfigError> {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err(self.error(
                field,
                crate::units::shown_value(v),
                "must be a finite number, zero or more",
            ))
        }
    }

    /// `v` is finite.
    pub fn finite(&self, field: impl Into<String>, v: f64) -> Result<(), ConfigError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.error(field, crate::units::shown_value(v), "must be finite"))
        }
    }

    /// Every entry of the 2 × 2 matrix `m` is finite (the bad one is named by its indices).
    pub fn finite_matrix(&self, field: String, m: &Matrix2<f64>) -> Result<(), ConfigError> {
        for i in 0..2 {
            for j in 0..2 {
                self.finite(format!("{field}[{i}][{j}]"), m[(i, j)])?;
            }
        }
        Ok(())
    }

    /// `node` is one of the shaft's `nodes` nodes.
    pub fn node(&self, field: String, node: usize, nodes: usize) -> Result<(), ConfigError> {
        if node < nodes {
            Ok(())
        } else {
            Err(self.error(
                field,
                node,
                format!("must be a shaft node, 0 to {}", nodes - 1),
            ))
        }
    }

    /// `name` can name a bearing, station or probe: not empty, at most [`MAX_NAME_CHARS`]
    /// characters, no control characters.
    pub fn name(&self, field: String, name: &str) -> Result<(), ConfigError> {
        let problem = if name.trim().is_empty() {
            Some("must not be empty".to_string())
        } else if name.chars().count() > MAX_NAME_CHARS {
            Some(format!("must be at most {MAX_NAME_CHARS} characters"))
        } else if name.chars().any(char::is_control) {
            Some("must not contain control characters".to_string())
        } else {
            None
        };
        match problem {
            Some(rule) => Err(self.error(field, shown(name), rule)),
            None => Ok(()),
        }
    }
}

/// A station or probe name given in a topic mapping (`--probe-point`, `--probe-signal`, the
/// node's `probe_point_topics` / `probe_signal_topics`): the machine file's name rules, the
/// error naming `option` and showing at most 40 characters of the name (issue 15, item 13).
pub(crate) fn mapping_name(option: &str, name: &str) -> Result<(), String> {
    let rule = if name.trim().is_empty() {
        "must not be empty".to_string()
    } else if name.chars().count() > MAX_NAME_CHARS {
        format!("must be at most {MAX_NAME_CHARS} characters")
    } else if name.chars().any(char::is_control) {
        "must not contain control characters".to_string()
    } else {
        return Ok(());
    };
    Err(format!("{option}: name {} {rule}", shown(name)))
}

/// `value` as shown in an error: at most 40 characters, then its length.
pub(crate) fn shown(value: &str) -> String {
    if value.chars().count() <= 40 {
        format!("{value:?}")
    } else {
        let head: String = value.chars().take(40).collect();
        format!("{head:?}… ({} characters)", value.chars().count())
    }
}
