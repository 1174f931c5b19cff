//! Unit conversions at the edges (CLI, configs, messages). Inside, everything is SI.

use std::f64::consts::PI;

/// Revolutions per minute → rad/s.
pub fn rpm_to_rad_s(speed_rpm: f64) -> f64 {
    speed_rpm * PI / 30.0
}

/// rad/s → revolutions per minute.
pub fn rad_s_to_rpm(speed_rad_s: f64) -> f64 {
    speed_rad_s * 30.0 / PI
}

/// A number as an error message shows it: as written when that is short (at most 12
/// characters: `9000`, `-5`, `0.0125`, `inf`), else in scientific notation with four significant
/// digits (`1.000e300`, `1.235e-7`), so that a 300-digit input is never echoed whole (issue 15,
/// item 21). The one format of numbers in the errors of the command line and the machine file.
pub fn shown_value(v: f64) -> String {
    let plain = v.to_string();
    if plain.len() <= 12 {
        plain
    } else {
        format!("{v:.3e}")
    }
}
