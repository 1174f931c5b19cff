//! Helpers shared by the integration tests: reference tables and the seed's bearing.
#![allow(dead_code)]

use rotor_twin::film::{BearingGeometry, Lubricant};
use std::path::PathBuf;

/// Rows of a reference CSV under tests/reference/ (copied from ../shared/reference/), `#`
/// comment lines skipped, header used to name the columns.
pub fn reference_table(name: &str) -> Vec<std::collections::HashMap<String, f64>> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference")
        .join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(
                    l.split(',')
                        .map(|v| v.trim().parse::<f64>().expect("number")),
                )
                .collect()
        })
        .collect()
}

/// The seed's bearing: D 60 mm, c 40 µm; `l_over_d` sets the length.
pub fn seed_bearing(l_over_d: f64) -> BearingGeometry {
    BearingGeometry::plain(0.06, 0.06 * l_over_d, 40e-6).unwrap()
}

/// The seed's lubricant (MDM): ρ 900 kg/m³, µ 0.0008 Pa·s.
pub fn mdm() -> Lubricant {
    Lubricant::new(900.0, 0.0008).unwrap()
}

/// 9000 rpm in rad/s.
pub const OMEGA_9000_RPM: f64 = 9000.0 * std::f64::consts::PI / 30.0;

/// Relative difference |a − b| / |b|.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
