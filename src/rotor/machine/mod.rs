//! The machine description: one YAML file describes one machine (config/*.yaml).
//!
//! Nodes are numbered from 0 at `z = 0` along the shaft; shaft sections are listed in order and
//! each is split into `elements` equal Timoshenko elements. Field names carry their unit where it
//! is not SI. Angles are measured from `+x` towards `+y`, the direction of rotation.
//!
//! Reading a file is two steps: serde reads it as written (unknown fields and wrong types refused
//! with their path), then [`MachineDescription::from_yaml`] parses the bearings into one variant
//! per model (`bearing.rs`) and checks the rules that span fields (`checks.rs`, `probes.rs`,
//! `oil.rs`); every rule lives in `rules.rs` or beside the field it governs.

mod bearing;
mod checks;
mod oil;
mod probes;
mod rules;

pub use bearing::{
    BearingModelSpec, BearingSpec, FilmSpec, GroovesSpec, RawBearingSpec, SupportSpec,
};
pub use oil::{
    LubricantSpec, OilHeatingModel, OilHeatingSpec, ViscosityTableSpec, ViscosityTemperatureSpec,
    DEFAULT_CARRY_OVER,
};
pub use probes::{ProbeSpec, ProximityProbeSpec, RunoutSpec};

use super::error::ConfigError;
use checks::MAX_MACHINE_FILE_BYTES;
pub use checks::{max_speed_rpm, MAX_SURFACE_SPEED_M_S};
use rules::Rules;
pub(crate) use rules::{mapping_name, shown};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The built-in default machine: the seed's 100 kW ORC microturbine.
pub const DEFAULT_MACHINE_YAML: &str = include_str!("../../../config/orc_microturbine_100kw.yaml");
/// File name reported for the built-in machine.
pub const DEFAULT_MACHINE_NAME: &str = "config/orc_microturbine_100kw.yaml (built in)";

/// One machine, its bearings checked and parsed (what every command and the node use).
pub type MachineDescription = MachineDescriptionOf<BearingSpec>;

/// One machine, checked: [`MachineDescription`]. The file is read into
/// `MachineDescriptionOf<RawBearingSpec>` (every bearing field as written, so that serde's errors
/// name the exact field), and its bearings are then parsed into [`BearingSpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineDescriptionOf<B> {
    /// Short name.
    pub name: String,
    /// Free text: what the machine is and where its figures come from.
    #[serde(default)]
    pub description: String,
    /// Rated speed (rpm). At most the speed at which the shaft's largest outer diameter turns at
    /// [`MAX_SURFACE_SPEED_M_S`] (500 m/s, where a steel shaft's centrifugal stress reaches its
    /// yield strength): the twin runs to 10× this speed, so an unbounded rated speed would let it
    /// report as "stable" speeds no rotor survives.
    pub rated_speed_rpm: f64,
    /// Gravity `[g_x, g_y]` in the machine frame (m/s²); `[0, -9.81]` for y up.
    #[serde(default = "default_gravity")]
    pub gravity_m_s2: [f64; 2],
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Shaft sections from `z = 0`.
    pub shaft: Vec<ShaftSection>,
    /// Rigid discs.
    #[serde(default)]
    pub discs: Vec<DiscSpec>,
    /// Bearings (each at a shaft node, with an optional flexible support).
    pub bearings: Vec<B>,
    /// Unbalance planes.
    #[serde(default)]
    pub unbalance: Vec<UnbalanceSpec>,
    /// Proximity-probe stations (pairs of probes) for comparing with measured orbits.
    #[serde(default)]
    pub probes: Vec<ProbeSpec>,
    /// Optional stiffness-proportional structural damping of the shaft, C = β K_shaft (β in s).
    #[serde(default)]
    pub shaft_damping_beta_s: f64,
    /// Optional alarm levels of the orbit amplitude at every bearing. Absent (the default): the
    /// field-practice levels, API 617's 75 % of the clearance and the ISO 20816-3 zone
    /// boundaries, each capped by the clearance (`monitor::AlarmLevels`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alarm_levels: Option<AlarmLevelsSpec>,
    /// Optional raw proximity probes: one scalar signal each along its own axis, two per probe
    /// station (see [`ProximityProbeSpec`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub proximity_probes: Vec<ProximityProbeSpec>,
    /// Optional slow-roll speed (rpm): below it (and above zero) the 1X vector of each raw probe
    /// is measured as its runout, and subtracted from then on (a runout given per probe wins).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slow_roll_speed_rpm: Option<f64>,
}

/// Alarm levels set by the machine's owner: orbit amplitudes (half the peak-to-peak
/// displacement), each capped by the bearing's clearance when applied.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlarmLevelsSpec {
    /// Alert (warning) amplitude (m).
    pub alert_amplitude_m: f64,
    /// Danger amplitude (m), at least the alert one.
    pub danger_amplitude_m: f64,
}

fn default_gravity() -> [f64; 2] {
    [0.0, -9.81]
}

fn one() -> usize {
    1
}

/// An isotropic material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Young's modulus E (Pa).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν.
    pub poisson_ratio: f64,
    /// Density ρ (kg/m³).
    pub density_kg_m3: f64,
}

/// A uniform length of shaft.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShaftSection {
    /// Section length (m).
    pub length_m: f64,
    /// Outer diameter (m).
    pub outer_diameter_m: f64,
    /// Bore diameter (m), 0 for solid.
    #[serde(default)]
    pub inner_diameter_m: f64,
    /// Name of a material in `materials`.
    pub material: String,
    /// Equal elements the section is split into.
    #[serde(default = "one")]
    pub elements: usize,
}

/// A rigid disc.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscSpec {
    /// Name for reports.
    #[serde(default)]
    pub name: String,
    /// Shaft node.
    pub node: usize,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Polar moment of inertia (kg·m²).
    pub polar_inertia_kg_m2: f64,
    /// Diametral moment of inertia (kg·m²).
    pub diametral_inertia_kg_m2: f64,
}

/// A residual unbalance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnbalanceSpec {
    /// Shaft node of the unbalance plane.
    pub node: usize,
    /// Unbalance m·e (g·mm).
    pub magnitude_g_mm: f64,
    /// Angle of the heavy spot at t = 0, from `+x` towards `+y` (deg).
    #[serde(default)]
    pub phase_deg: f64,
    /// Radius at which a balancing correction mass is placed in this plane (m); the
    /// calibration's default, 100 mm, when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correction_radius_m: Option<f64>,
}

impl MachineDescription {
    /// Reads and checks a machine file.
    pub fn from_file(path: &Path) -> Result<Self, ConfigError> {
        let file = path.display().to_string();
        let unreadable = |rule: String| ConfigError {
            file: file.clone(),
            field: "(file)".into(),
            value: String::new(),
            rule,
        };
        let meta =
            std::fs::metadata(path).map_err(|e| unreadable(format!("cannot be read: {e}")))?;
        if !meta.is_file() {
            return Err(unreadable("is not a regular file".into()));
        }
        if meta.len() > MAX_MACHINE_FILE_BYTES as u64 {
            return Err(unreadable(format!(
                "is {} bytes, more than the {MAX_MACHINE_FILE_BYTES} a machine description may be",
                meta.len()
            )));
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| unreadable(format!("cannot be read: {e}")))?;
        Self::from_yaml(&text, &file)
    }

    /// The machine in `path`, or the built-in default machine without one: the one way every
    /// command and the node load a machine.
    pub fn load(path: Option<&Path>) -> Result<Self, ConfigError> {
        match path {
            Some(p) => Self::from_file(p),
            None => Ok(Self::builtin_default()),
        }
    }

    /// The built-in default machine.
    pub fn builtin_default() -> Self {
        Self::from_yaml(DEFAULT_MACHINE_YAML, DEFAULT_MACHINE_NAME)
            .expect("the built-in machine description is valid (checked by a test)")
    }

    /// Parses and checks YAML text; `file` names it in errors.
    pub fn from_yaml(text: &str, file: &str) -> Result<Self, ConfigError> {
        crate::bag::check_yaml_shape(text, MAX_MACHINE_FILE_BYTES).map_err(|rule| ConfigError {
            file: file.to_string(),
            field: "(document)".into(),
            value: String::new(),
            rule,
        })?;
        let de = serde_yaml_ng::Deserializer::from_str(text);
        let raw: MachineDescriptionOf<RawBearingSpec> = serde_path_to_error::deserialize(de)
            .map_err(|e| {
                let field = e.path().to_string();
                let inner = e.into_inner();
                ConfigError {
                    file: file.to_string(),
                    field: if field == "." {
                        "(document)".into()
                    } else {
                        field
                    },
                    value: String::new(),
                    rule: inner.to_string(),
                }
            })?;
        let desc = raw.parse_bearings(file)?;
        desc.validate(file)?;
        Ok(desc)
    }

    /// Number of shaft nodes.
    pub fn node_count(&self) -> usize {
        self.shaft.iter().map(|s| s.elements).sum::<usize>() + 1
    }
}

impl MachineDescriptionOf<RawBearingSpec> {
    /// The description with each bearing entry parsed (see [`RawBearingSpec`]).
    fn parse_bearings(self, file: &str) -> Result<MachineDescription, ConfigError> {
        let rules = Rules { file };
        let films: Vec<(usize, LubricantSpec)> = (self.bearings.iter().enumerate())
            .filter_map(|(i, b)| b.film_lubricant().map(|l| (i, l)))
            .collect();
        let bearings = self
            .bearings
            .into_iter()
            .enumerate()
            .map(|(i, b)| b.parse(i, &rules))
            .collect::<Result<Vec<_>, _>>()?;
        oil::check_one_oil_supply(&films, &rules)?;
        Ok(MachineDescriptionOf {
            bearings,
            name: self.name,
            description: self.description,
            rated_speed_rpm: self.rated_speed_rpm,
            gravity_m_s2: self.gravity_m_s2,
            materials: self.materials,
            shaft: self.shaft,
            discs: self.discs,
            unbalance: self.unbalance,
            probes: self.probes,
            shaft_damping_beta_s: self.shaft_damping_beta_s,
            alarm_levels: self.alarm_levels,
            proximity_probes: self.proximity_probes,
            slow_roll_speed_rpm: self.slow_roll_speed_rpm,
        })
    }
}
