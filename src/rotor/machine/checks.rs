//! The rules of a parsed machine description, section by section, in the file's order; the
//! first broken rule is reported with its field and value.

use super::rules::{shown, Rules};
use super::MachineDescription;
use crate::rotor::ConfigError;

/// Largest machine file read (bytes): 1 MiB (the shipped ones are 2–4 kB).
pub const MAX_MACHINE_FILE_BYTES: usize = 1 << 20;
/// Most shaft elements in total: 200. The matrices are dense, 4 degrees of freedom a node, and
/// the modal analysis solves a state-space eigenproblem of 8 per node: its cost grows as the cube
/// of the node count (10,000 elements would ask for 12.8 GB). The shipped machines use 30.
pub const MAX_SHAFT_ELEMENTS: usize = 200;
/// Most elements in one shaft section.
const MAX_SECTION_ELEMENTS: usize = 200;
/// Largest stiffness-proportional damping coefficient β (s): beyond it the shaft is a dashpot.
const MAX_SHAFT_DAMPING_BETA_S: f64 = 1e-2;
/// Largest surface speed of a shaft (m/s), π·D·n at the rated speed n over its largest outer
/// diameter D: the centrifugal stress at the centre of a spinning solid cylinder,
/// (3 + ν)/8 · ρ · v² (Timoshenko & Goodier, rotating disc), is 0.81 GPa for steel (ρ 7850 kg/m³,
/// ν 0.3) at 500 m/s, the yield strength of a quenched-and-tempered alloy steel (34CrNiMo6:
/// 0.8–0.9 GPa): no shaft runs faster, so a rated speed beyond it is a unit slip, not a machine.
/// The `bearing` command bounds the journal speed by the same figure.
pub const MAX_SURFACE_SPEED_M_S: f64 = 500.0;

/// The speed (rpm) at which a shaft or journal of `diameter_m` reaches
/// [`MAX_SURFACE_SPEED_M_S`]: the upper bound of every speed given for it.
pub fn max_speed_rpm(diameter_m: f64) -> f64 {
    MAX_SURFACE_SPEED_M_S / (std::f64::consts::PI * diameter_m) * 60.0
}
/// Largest gravity component (m/s²).
const MAX_GRAVITY_M_S2: f64 = 100.0;

impl MachineDescription {
    /// Checks every field against its rule; the first broken rule is reported.
    pub fn validate(&self, file: &str) -> Result<(), ConfigError> {
        let rules = Rules { file };
        self.check_general(&rules)?;
        self.check_materials(&rules)?;
        self.check_shaft(&rules)?;
        self.check_discs(&rules)?;
        self.check_bearings(&rules)?;
        self.check_unbalance(&rules)?;
        self.check_probe_stations(&rules)?;
        self.raw_probes(file).map(|_| ())
    }

    /// Rated speed, alarm levels, shaft damping, gravity.
    fn check_general(&self, rules: &Rules) -> Result<(), ConfigError> {
        rules.positive("rated_speed_rpm", self.rated_speed_rpm)?;
        let diameter_m = self
            .shaft
            .iter()
            .map(|s| s.outer_diameter_m)
            .fold(0.0, f64::max);
        let max_rpm = max_speed_rpm(diameter_m);
        // shown rounded down, so that the bound printed is itself allowed
        let max_rpm_shown = max_rpm.floor();
        if self.rated_speed_rpm > max_rpm {
            return Err(rules.error(
                "rated_speed_rpm",
                crate::units::shown_value(self.rated_speed_rpm),
                format!(
                    "must be at most {max_rpm_shown:.0} rpm: the shaft's surface speed (Ø {diameter_m} m) \
                     would exceed {MAX_SURFACE_SPEED_M_S} m/s, where the centrifugal stress reaches \
                     the yield strength of steel"
                ),
            ));
        }
        if let Some(a) = &self.alarm_levels {
            rules.positive("alarm_levels.alert_amplitude_m", a.alert_amplitude_m)?;
            rules.positive("alarm_levels.danger_amplitude_m", a.danger_amplitude_m)?;
            if a.danger_amplitude_m < a.alert_amplitude_m {
                return Err(rules.error(
                    "alarm_levels.danger_amplitude_m",
                    a.danger_amplitude_m,
                    "must be at least alarm_levels.alert_amplitude_m",
                ));
            }
        }
        rules.non_negative("shaft_damping_beta_s", self.shaft_damping_beta_s)?;
        if self.shaft_damping_beta_s > MAX_SHAFT_DAMPING_BETA_S {
            return Err(rules.error(
                "shaft_damping_beta_s",
                self.shaft_damping_beta_s,
                format!("is absurd (more than {MAX_SHAFT_DAMPING_BETA_S} s)"),
            ));
        }
        for (i, g) in self.gravity_m_s2.iter().enumerate() {
            if !g.is_finite() || g.abs() > MAX_GRAVITY_M_S2 {
                return Err(rules.error(
                    format!("gravity_m_s2[{i}]"),
                    crate::units::shown_value(*g),
                    format!("must be finite and at most {MAX_GRAVITY_M_S2} m/s² in size"),
                ));
            }
        }
        Ok(())
    }

    /// Elastic constants and density of each material.
    fn check_materials(&self, rules: &Rules) -> Result<(), ConfigError> {
        for (name, m) in &self.materials {
            let field = |f: &str| format!("materials.{name}.{f}");
            rules.positive(field("youngs_modulus_pa"), m.youngs_modulus_pa)?;
            rules.positive(field("density_kg_m3"), m.density_kg_m3)?;
            if !(m.poisson_ratio.is_finite() && m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) {
                return Err(rules.error(
                    field("poisson_ratio"),
                    m.poisson_ratio,
                    "must lie between -1 and 0.5",
                ));
            }
        }
        Ok(())
    }

    /// Shaft sections: dimensions, material, element counts (each and in all).
    fn check_shaft(&self, rules: &Rules) -> Result<(), ConfigError> {
        if self.shaft.is_empty() {
            return Err(rules.error("shaft", "[]", "needs at least one section"));
        }
        for (i, s) in self.shaft.iter().enumerate() {
            let field = |f: &str| format!("shaft[{i}].{f}");
            rules.positive(field("length_m"), s.length_m)?;
            rules.positive(field("outer_diameter_m"), s.outer_diameter_m)?;
            rules.non_negative(field("inner_diameter_m"), s.inner_diameter_m)?;
            if s.inner_diameter_m >= s.outer_diameter_m {
                return Err(rules.error(
                    field("inner_diameter_m"),
                    s.inner_diameter_m,
                    "must be smaller than outer_diameter_m",
                ));
            }
            if !self.materials.contains_key(&s.material) {
                return Err(rules.error(
                    field("material"),
                    shown(&s.material),
                    "must name an entry of materials",
                ));
            }
            if !(1..=MAX_SECTION_ELEMENTS).contains(&s.elements) {
                return Err(rules.error(
                    field("elements"),
                    s.elements,
                    format!("must be between 1 and {MAX_SECTION_ELEMENTS}"),
                ));
            }
        }
        let elements: usize = self.shaft.iter().map(|s| s.elements).sum();
        if elements > MAX_SHAFT_ELEMENTS {
            return Err(rules.error(
                "shaft[*].elements",
                format!("{elements} in total"),
                format!(
                    "at most {MAX_SHAFT_ELEMENTS} elements in all: the dense model's memory grows as the square and its modal analysis as the cube of the node count"
                ),
            ));
        }
        Ok(())
    }

    /// Discs: node, mass and inertias.
    fn check_discs(&self, rules: &Rules) -> Result<(), ConfigError> {
        let nodes = self.node_count();
        for (i, d) in self.discs.iter().enumerate() {
            let field = |f: &str| format!("discs[{i}].{f}");
            rules.node(field("node"), d.node, nodes)?;
            rules.positive(field("mass_kg"), d.mass_kg)?;
            rules.non_negative(field("polar_inertia_kg_m2"), d.polar_inertia_kg_m2)?;
            rules.non_negative(field("diametral_inertia_kg_m2"), d.diametral_inertia_kg_m2)?;
        }
        Ok(())
    }

    /// Bearings: names unique, nodes on the shaft, at least two distinct nodes (the model's
    /// bearings carry forces, not moments: one bearing cannot hold the shaft's tilt).
    fn check_bearings(&self, rules: &Rules) -> Result<(), ConfigError> {
        let nodes = self.node_count();
        for (i, b) in self.bearings.iter().enumerate() {
            let field = |f: &str| format!("bearings[{i}].{f}");
            rules.name(field("name"), &b.name)?;
            if self.bearings[..i].iter().any(|o| o.name == b.name) {
                return Err(rules.error(field("name"), shown(&b.name), "must be unique"));
            }
            rules.node(field("node"), b.node, nodes)?;
        }
        let condensed: usize = (self.bearings.iter().filter(|b| b.film().is_some()))
            .map(|b| if b.support.is_some() { 4 } else { 2 })
            .sum();
        if condensed > crate::dynamics::MAX_CONDENSED_DOFS {
            return Err(rules.error(
                "bearings",
                format!("{condensed} film-bearing degrees of freedom"),
                format!(
                    "at most {} (two per film bearing, two more for each on a flexible support): the twin's Newton system is solved on the stack",
                    crate::dynamics::MAX_CONDENSED_DOFS
                ),
            ));
        }
        let mut at: Vec<usize> = self.bearings.iter().map(|b| b.node).collect();
        at.sort_unstable();
        at.dedup();
        if at.len() < 2 {
            return Err(rules.error(
                "bearings",
                format!("{} at node(s) {at:?}", self.bearings.len()),
                "needs bearings at two or more shaft nodes: a bearing carries forces, not moments, so one alone cannot hold the shaft's tilt",
            ));
        }
        Ok(())
    }

    /// Unbalance planes: node, magnitude within the one bound on an unbalance, phase.
    fn check_unbalance(&self, rules: &Rules) -> Result<(), ConfigError> {
        let nodes = self.node_count();
        // the one bound on an unbalance, as for one received on the bus
        let max_g_mm = crate::driver::inputs::MAX_UNBALANCE_KG_M * 1e6;
        for (i, u) in self.unbalance.iter().enumerate() {
            let field = |f: &str| format!("unbalance[{i}].{f}");
            rules.node(field("node"), u.node, nodes)?;
            rules.non_negative(field("magnitude_g_mm"), u.magnitude_g_mm)?;
            if u.magnitude_g_mm > max_g_mm {
                return Err(rules.error(
                    field("magnitude_g_mm"),
                    u.magnitude_g_mm,
                    format!("is absurd (more than {max_g_mm} g·mm)"),
                ));
            }
            rules.finite(field("phase_deg"), u.phase_deg)?;
            if let Some(r) = u.correction_radius_m {
                rules.positive(field("correction_radius_m"), r)?;
                if r > 10.0 {
                    return Err(rules.error(
                        field("correction_radius_m"),
                        r,
                        "is absurd (more than 10 m): the radius is in metres",
                    ));
                }
            }
        }
        Ok(())
    }
}
