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
