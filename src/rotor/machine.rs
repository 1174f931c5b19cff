//! The machine description: one YAML file describes one machine (config/*.yaml).
//!
//! Nodes are numbered from 0 at `z = 0` along the shaft; shaft sections are listed in order and
//! each is split into `elements` equal Timoshenko elements. Field names carry their unit where it
//! is not SI. Angles are measured from `+x` towards `+y`, the direction of rotation.

use super::error::ConfigError;
use crate::film::FilmGrid;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The built-in default machine: the seed's 100 kW ORC microturbine.
pub const DEFAULT_MACHINE_YAML: &str = include_str!("../../config/orc_microturbine_100kw.yaml");
/// File name reported for the built-in machine.
pub const DEFAULT_MACHINE_NAME: &str = "config/orc_microturbine_100kw.yaml (built in)";

/// One machine, as written in its YAML file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineDescription {
    /// Short name.
    pub name: String,
    /// Free text: what the machine is and where its figures come from.
    #[serde(default)]
    pub description: String,
    /// Rated speed (rpm).
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
    pub bearings: Vec<BearingSpec>,
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
    // --- plant signals (issue 12) ---
    /// Optional raw proximity probes: one scalar signal each along its own axis, two per probe
    /// station (see [`ProximityProbeSpec`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub proximity_probes: Vec<ProximityProbeSpec>,
    /// Optional slow-roll speed (rpm): below it (and above zero) the 1X vector of each raw probe
    /// is measured as its runout, and subtracted from then on (a runout given per probe wins).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slow_roll_speed_rpm: Option<f64>,
    // --- end plant signals ---
}

// --- plant signals (issue 12) ---

use crate::signals::probes::{check_orthogonal, reading_to_m, ProbeCoupling, ProbeUnit, RawProbe};

/// One raw proximity probe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProximityProbeSpec {
    /// Probe name (the ProbeSignal message's `probe`; unique).
    pub name: String,
    /// The probe station (a `probes` entry's name) it belongs to; two probes a station.
    pub station: String,
    /// Mounting angle, from `+x` towards `+y` (the direction of rotation) (deg). API 670's X–Y
    /// pair, 45° either side of vertical, is at 45° and 135° with `+y` up.
    pub angle_deg: f64,
    /// Unit of the readings: `m`, `um`, `mil` or `V` (default `um`).
    #[serde(default = "default_probe_unit")]
    pub unit: String,
    /// Sensitivity for readings in volts (V/m); default 7870 (7.87 V/mm = 200 mV/mil).
    #[serde(default = "default_sensitivity")]
    pub sensitivity_v_per_m: f64,
    /// `ac` (mean removed; the default) or `dc` (gap kept as the journal's mean position).
    #[serde(default = "default_coupling")]
    pub coupling: String,
    /// Gap at the reference position (the shaft centred), in the probe's unit; DC coupling.
    #[serde(default)]
    pub reference_gap: f64,
    /// Slow-roll runout 1X vector, if known: amplitude (m) and phase lag (deg) from the keyphasor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runout: Option<RunoutSpec>,
}

/// A slow-roll runout vector.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunoutSpec {
    /// Amplitude, zero to peak, along the probe's axis (m).
    pub amplitude_m: f64,
    /// Phase lag from the keyphasor event to the positive peak (deg).
    pub phase_lag_deg: f64,
}

fn default_probe_unit() -> String {
    "um".into()
}

fn default_sensitivity() -> f64 {
    crate::signals::probes::DEFAULT_SENSITIVITY_V_PER_M
}

fn default_coupling() -> String {
    "ac".into()
}

impl MachineDescription {
    /// The raw proximity probes of the file as the driver uses them, checked: names unique,
    /// stations known, two orthogonal probes a station, unit, sensitivity, coupling, gap and
    /// runout valid, the slow-roll speed within (0, rated].
    pub fn raw_probes(&self, file: &str) -> Result<Vec<RawProbe>, ConfigError> {
        let mut out: Vec<RawProbe> = Vec::with_capacity(self.proximity_probes.len());
        for (i, p) in self.proximity_probes.iter().enumerate() {
            let probe = self.raw_probe(i, p, &out, file)?;
            out.push(probe);
        }
        self.check_probe_pairs(&out, file)?;
        if let Some(v) = self.slow_roll_speed_rpm {
            if !(v.is_finite() && v > 0.0 && v <= self.rated_speed_rpm) {
                return Err(ConfigError {
                    file: file.to_string(),
                    field: "slow_roll_speed_rpm".into(),
                    value: v.to_string(),
                    rule: "must be above 0 and at most the rated speed".into(),
                });
            }
        }
        Ok(out)
    }

    /// Entry `i` of `proximity_probes`, checked against the probes before it (`before`).
    fn raw_probe(
        &self,
        i: usize,
        p: &ProximityProbeSpec,
        before: &[RawProbe],
        file: &str,
    ) -> Result<RawProbe, ConfigError> {
        let err = |field: &str, value: String, rule: String| ConfigError {
            file: file.to_string(),
            field: format!("proximity_probes[{i}].{field}"),
            value,
            rule,
        };
        if let Some(rule) = name_problem(&p.name) {
            return Err(err("name", shown(&p.name), rule));
        }
        if before.iter().any(|q| q.name == p.name) {
            return Err(err("name", shown(&p.name), "must be unique".into()));
        }
        let station = self
            .probes
            .iter()
            .position(|s| s.name == p.station)
            .ok_or_else(|| {
                err(
                    "station",
                    shown(&p.station),
                    "must name one of the probes stations".into(),
                )
            })?;
        let axis = before.iter().filter(|q| q.station == station).count();
        if axis >= 2 {
            return Err(err(
                "station",
                shown(&p.station),
                "has two probes already".into(),
            ));
        }
        let unit: ProbeUnit = p.unit.parse().map_err(|e| err("unit", shown(&p.unit), e))?;
        let coupling: ProbeCoupling = p
            .coupling
            .parse()
            .map_err(|e| err("coupling", shown(&p.coupling), e))?;
        let s = p.sensitivity_v_per_m;
        if !s.is_finite() || s.abs() < 1.0 {
            return Err(err(
                "sensitivity_v_per_m",
                s.to_string(),
                "must be finite and at least 1 V/m in size".into(),
            ));
        }
        for (field, v) in [
            ("angle_deg", p.angle_deg),
            ("reference_gap", p.reference_gap),
        ] {
            if !v.is_finite() {
                return Err(err(field, v.to_string(), "must be finite".into()));
            }
        }
        if let Some(r) = p.runout {
            if !(r.amplitude_m.is_finite()
                && (0.0..=1e-3).contains(&r.amplitude_m)
                && r.phase_lag_deg.is_finite())
            {
                return Err(err(
                    "runout",
                    format!("{r:?}"),
                    "amplitude must be 0 to 1 mm, phase finite".into(),
                ));
            }
        }
        Ok(RawProbe {
            name: p.name.clone(),
            station,
            axis,
            angle_rad: p.angle_deg.to_radians(),
            unit,
            sensitivity_v_per_m: s,
            coupling,
            reference_gap_m: reading_to_m(p.reference_gap, unit, s),
            runout: p.runout.map(|r| crate::signals::OneXVector {
                amplitude_m: r.amplitude_m,
                phase_lag_deg: r.phase_lag_deg.rem_euclid(360.0),
            }),
        })
    }

    /// Each station with raw probes has two, orthogonal.
    fn check_probe_pairs(&self, probes: &[RawProbe], file: &str) -> Result<(), ConfigError> {
        for (k, st) in self.probes.iter().enumerate() {
            let at: Vec<&RawProbe> = probes.iter().filter(|q| q.station == k).collect();
            let problem = match at.len() {
                0 => None,
                2 => check_orthogonal([at[0].angle_rad, at[1].angle_rad]).err(),
                _ => Some("a station needs two probes (one is not enough for an orbit)".into()),
            };
            if let Some(rule) = problem {
                return Err(ConfigError {
                    file: file.to_string(),
                    field: "proximity_probes[*]".into(),
                    value: st.name.clone(),
                    rule,
                });
            }
        }
        Ok(())
    }
}
// --- end plant signals ---

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

/// How a bearing is modelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BearingModelKind {
    /// Fluid film, finite-length Reynolds equation.
    Finite,
    /// Fluid film, short-bearing (Ocvirk) closed form.
    Short,
    /// Constant stiffness and damping.
    Linear,
    /// Rigid: the journal cannot move (a pinned support).
    Rigid,
}

/// Supply grooves of a film bearing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum GroovesSpec {
    /// Plain 360° bearing.
    #[default]
    None,
    /// Two axial grooves, 90° either side of the static load.
    TwoAxial,
}

/// Lubricant properties.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LubricantSpec {
    /// Density ρ (kg/m³).
    pub density_kg_m3: f64,
    /// Dynamic viscosity µ (Pa·s); with a `viscosity_temperature` law, at its design supply
    /// temperature (the viscosity the films are solved, and tabulated, at).
    pub viscosity_pa_s: f64,
    /// Optional viscosity–temperature law: an oil temperature received on the bus then sets the
    /// viscosity of the running twin's films.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub viscosity_temperature: Option<ViscosityTemperatureSpec>,
}

// --- oil supply temperature (issue 12) ---

/// Walther's viscosity–temperature law (ASTM D341-09) through two kinematic viscosities, with
/// the lubricant's density (`crate::film::WaltherLaw`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViscosityTemperatureSpec {
    /// The two temperatures of the measured viscosities (°C).
    pub temperatures_c: [f64; 2],
    /// Kinematic viscosities there (mm²/s = cSt), at least 0.21 (D341-09's range).
    pub kinematic_viscosities_mm2_s: [f64; 2],
    /// The design oil supply temperature (°C), where the law must give `viscosity_pa_s` within 1 %.
    pub design_supply_temperature_c: f64,
    /// Oil temperatures accepted (°C), lowest and highest; others are refused as bad input.
    pub valid_range_c: [f64; 2],
}

/// How far the law may miss `viscosity_pa_s` at the design supply temperature (relative).
pub const LAW_DESIGN_TOLERANCE: f64 = 0.01;

impl ViscosityTemperatureSpec {
    /// The law, with density `density_kg_m3` (kg/m³), or the broken rule.
    pub fn law(&self, density_kg_m3: f64) -> Result<crate::film::WaltherLaw, String> {
        let k = |c: f64| c + crate::film::ZERO_CELSIUS_K;
        if let Some(bad) = self
            .valid_range_c
            .iter()
            .chain(&self.temperatures_c)
            .chain([&self.design_supply_temperature_c])
            .find(|t| !(t.is_finite() && (-100.0..=500.0).contains(*t)))
        {
            return Err(format!(
                "temperature {bad} °C must be finite, between -100 and 500 °C"
            ));
        }
        let [t1, t2] = self.temperatures_c;
        let [nu1, nu2] = self.kinematic_viscosities_mm2_s;
        crate::film::WaltherLaw::through(
            [(k(t1), nu1), (k(t2), nu2)],
            density_kg_m3,
            self.valid_range_c.map(k),
        )
    }
}

impl MachineDescription {
    /// Checks every bearing's viscosity–temperature law: valid points and range, the design
    /// supply temperature inside the range, and `viscosity_pa_s` there within 1 %.
    fn validate_viscosity_laws(&self, file: &str) -> Result<(), ConfigError> {
        for (i, b) in self.bearings.iter().enumerate() {
            let Some(lub) = b.lubricant else { continue };
            let Some(spec) = lub.viscosity_temperature else {
                continue;
            };
            let field =
                |name: &str| format!("bearings[{i}].lubricant.viscosity_temperature.{name}");
            let err = |field: String, value: String, rule: String| ConfigError {
                file: file.to_string(),
                field,
                value,
                rule,
            };
            let law = spec.law(lub.density_kg_m3).map_err(|rule| {
                err(
                    field("(law)"),
                    format!(
                        "{:?} °C, {:?} mm²/s, range {:?} °C",
                        spec.temperatures_c, spec.kinematic_viscosities_mm2_s, spec.valid_range_c
                    ),
                    rule,
                )
            })?;
            let td = spec.design_supply_temperature_c;
            let [lo, hi] = spec.valid_range_c;
            if td < lo || td > hi {
                return Err(err(
                    field("design_supply_temperature_c"),
                    td.to_string(),
                    format!("must lie inside valid_range_c [{lo}, {hi}] °C"),
                ));
            }
            let mu = law.viscosity_pa_s(td + crate::film::ZERO_CELSIUS_K);
            if (mu / lub.viscosity_pa_s - 1.0).abs() > LAW_DESIGN_TOLERANCE {
                return Err(err(
                    field("kinematic_viscosities_mm2_s"),
                    format!("{:?}", spec.kinematic_viscosities_mm2_s),
                    format!(
                        "the law gives {mu:.4e} Pa·s at the design supply temperature {td} °C; bearings[{i}].lubricant.viscosity_pa_s is {:.4e}: they must agree within 1 %",
                        lub.viscosity_pa_s
                    ),
                ));
            }
        }
        self.validate_one_oil_supply(file)
    }

    /// One oil supply: when a bearing has a viscosity–temperature law, every bearing with a
    /// lubricant has the same lubricant (an oil temperature sets one viscosity scale for every
    /// film, `driver::oil_viscosity_scale`).
    fn validate_one_oil_supply(&self, file: &str) -> Result<(), ConfigError> {
        let lubricated: Vec<(usize, LubricantSpec)> = self
            .bearings
            .iter()
            .enumerate()
            .filter_map(|(i, b)| b.lubricant.map(|l| (i, l)))
            .collect();
        if lubricated
            .iter()
            .all(|(_, l)| l.viscosity_temperature.is_none())
        {
            return Ok(());
        }
        let (first, reference) = lubricated[0];
        match lubricated.iter().find(|(_, l)| *l != reference) {
            None => Ok(()),
            Some((i, l)) => Err(ConfigError {
                file: file.to_string(),
                field: format!("bearings[{i}].lubricant"),
                value: format!("{l:?}"),
                rule: format!(
                    "with a viscosity_temperature law the bearings share one oil supply: every lubricant must equal bearings[{first}].lubricant ({reference:?}), since an oil temperature sets one viscosity scale for every film"
                ),
            }),
        }
    }
}

// --- end oil supply temperature ---

/// A bearing at a shaft node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingSpec {
    /// Name (also the ROS frame suffix later).
    pub name: String,
    /// Shaft node at the journal centre.
    pub node: usize,
    /// How it is modelled.
    pub model: BearingModelKind,
    /// Film bearings: journal diameter D (m).
    #[serde(default)]
    pub diameter_m: Option<f64>,
    /// Film bearings: length L (m).
    #[serde(default)]
    pub length_m: Option<f64>,
    /// Film bearings: radial clearance c (m).
    #[serde(default)]
    pub radial_clearance_m: Option<f64>,
    /// Film bearings: lubricant.
    #[serde(default)]
    pub lubricant: Option<LubricantSpec>,
    /// Film bearings: grid over the half bearing, `NTHxNZ` (default 60x10).
    #[serde(default)]
    pub grid: Option<String>,
    /// Film bearings: supply grooves.
    #[serde(default)]
    pub grooves: GroovesSpec,
    /// Linear bearings: `[[kxx, kxy], [kyx, kyy]]` (N/m).
    #[serde(default)]
    pub stiffness_n_per_m: Option<[[f64; 2]; 2]>,
    /// Linear bearings: `[[cxx, cxy], [cyx, cyy]]` (N·s/m).
    #[serde(default)]
    pub damping_n_s_per_m: Option<[[f64; 2]; 2]>,
    /// Flexible support under the bearing (the seed's C_mn, D_mn); rigid if absent.
    #[serde(default)]
    pub support: Option<SupportSpec>,
}

/// A pedestal: a mass on a spring–damper to the ground, carrying the bearing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupportSpec {
    /// Pedestal mass (kg), greater than zero.
    pub mass_kg: f64,
    /// `[[kxx, kxy], [kyx, kyy]]` to the ground (N/m).
    pub stiffness_n_per_m: [[f64; 2]; 2],
    /// `[[cxx, cxy], [cyx, cyy]]` to the ground (N·s/m).
    #[serde(default)]
    pub damping_n_s_per_m: [[f64; 2]; 2],
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
}

/// A probe station: two proximity probes looking at the shaft at one node.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Station name.
    pub name: String,
    /// Shaft node.
    pub node: usize,
    /// Mounting angles of the two probes, from `+x` towards `+y` (deg).
    pub angles_deg: [f64; 2],
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
        let desc: Self = serde_path_to_error::deserialize(de).map_err(|e| {
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
        desc.validate(file)?;
        Ok(desc)
    }

    /// Number of shaft nodes.
    pub fn node_count(&self) -> usize {
        self.shaft.iter().map(|s| s.elements).sum::<usize>() + 1
    }

    /// Checks every field against its rule; the first broken rule is reported.
    // Long (≈265 lines): a flat list of independent field checks in the file's order, no
    // control flow between them; splitting it by section (rotor, bearings, unbalance, probes)
    // with the bearing entry as a tagged enum is open in issue 10.
    pub fn validate(&self, file: &str) -> Result<(), ConfigError> {
        self.validate_limits(file)?;
        self.raw_probes(file)?;
        let err = |field: String, value: String, rule: &str| ConfigError {
            file: file.to_string(),
            field,
            value,
            rule: rule.to_string(),
        };
        let positive = |field: String, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(err(
                    field,
                    v.to_string(),
                    "must be a finite number greater than zero",
                ))
            }
        };
        let non_negative = |field: String, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(err(
                    field,
                    v.to_string(),
                    "must be a finite number, zero or more",
                ))
            }
        };
        positive("rated_speed_rpm".into(), self.rated_speed_rpm)?;
        if let Some(a) = &self.alarm_levels {
            positive("alarm_levels.alert_amplitude_m".into(), a.alert_amplitude_m)?;
            positive(
                "alarm_levels.danger_amplitude_m".into(),
                a.danger_amplitude_m,
            )?;
            if a.danger_amplitude_m < a.alert_amplitude_m {
                return Err(err(
                    "alarm_levels.danger_amplitude_m".into(),
                    a.danger_amplitude_m.to_string(),
                    "must be at least alarm_levels.alert_amplitude_m",
                ));
            }
        }
        non_negative("shaft_damping_beta_s".into(), self.shaft_damping_beta_s)?;
        if self.shaft_damping_beta_s > 1e-2 {
            return Err(err(
                "shaft_damping_beta_s".into(),
                self.shaft_damping_beta_s.to_string(),
                "is absurd (more than 0.01 s)",
            ));
        }
        for (i, g) in self.gravity_m_s2.iter().enumerate() {
            if !g.is_finite() || g.abs() > 100.0 {
                return Err(err(
                    format!("gravity_m_s2[{i}]"),
                    g.to_string(),
                    "must be finite and at most 100 m/s² in size",
                ));
            }
        }
        for (name, m) in &self.materials {
            positive(
                format!("materials.{name}.youngs_modulus_pa"),
                m.youngs_modulus_pa,
            )?;
            positive(format!("materials.{name}.density_kg_m3"), m.density_kg_m3)?;
            if !(m.poisson_ratio.is_finite() && m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5) {
                return Err(err(
                    format!("materials.{name}.poisson_ratio"),
                    m.poisson_ratio.to_string(),
                    "must lie between -1 and 0.5",
                ));
            }
        }
        if self.shaft.is_empty() {
            return Err(err(
                "shaft".into(),
                "[]".into(),
                "needs at least one section",
            ));
        }
        for (i, s) in self.shaft.iter().enumerate() {
            positive(format!("shaft[{i}].length_m"), s.length_m)?;
            positive(format!("shaft[{i}].outer_diameter_m"), s.outer_diameter_m)?;
            non_negative(format!("shaft[{i}].inner_diameter_m"), s.inner_diameter_m)?;
            if s.inner_diameter_m >= s.outer_diameter_m {
                return Err(err(
                    format!("shaft[{i}].inner_diameter_m"),
                    s.inner_diameter_m.to_string(),
                    "must be smaller than outer_diameter_m",
                ));
            }
            if !self.materials.contains_key(&s.material) {
                return Err(err(
                    format!("shaft[{i}].material"),
                    s.material.clone(),
                    "must name an entry of materials",
                ));
            }
            if !(1..=200).contains(&s.elements) {
                return Err(err(
                    format!("shaft[{i}].elements"),
                    s.elements.to_string(),
                    "must be between 1 and 200",
                ));
            }
        }
        let nodes = self.node_count();
        let node_ok = |field: String, node: usize| {
            if node < nodes {
                Ok(())
            } else {
                Err(err(
                    field,
                    node.to_string(),
                    &format!("must be a shaft node, 0 to {}", nodes - 1),
                ))
            }
        };
        for (i, d) in self.discs.iter().enumerate() {
            node_ok(format!("discs[{i}].node"), d.node)?;
            positive(format!("discs[{i}].mass_kg"), d.mass_kg)?;
            non_negative(
                format!("discs[{i}].polar_inertia_kg_m2"),
                d.polar_inertia_kg_m2,
            )?;
            non_negative(
                format!("discs[{i}].diametral_inertia_kg_m2"),
                d.diametral_inertia_kg_m2,
            )?;
        }
        if self.bearings.is_empty() {
            return Err(err(
                "bearings".into(),
                "[]".into(),
                "needs at least one bearing",
            ));
        }
        for (i, b) in self.bearings.iter().enumerate() {
            let f = |name: &str| format!("bearings[{i}].{name}");
            node_ok(f("node"), b.node)?;
            match b.model {
                BearingModelKind::Finite | BearingModelKind::Short => {
                    for (name, v) in [
                        ("diameter_m", b.diameter_m),
                        ("length_m", b.length_m),
                        ("radial_clearance_m", b.radial_clearance_m),
                    ] {
                        match v {
                            Some(v) => positive(f(name), v)?,
                            None => {
                                return Err(err(
                                    f(name),
                                    "(missing)".into(),
                                    "is required for a film bearing",
                                ))
                            }
                        }
                    }
                    let Some(lub) = b.lubricant else {
                        return Err(err(
                            f("lubricant"),
                            "(missing)".into(),
                            "is required for a film bearing",
                        ));
                    };
                    positive(f("lubricant.density_kg_m3"), lub.density_kg_m3)?;
                    positive(f("lubricant.viscosity_pa_s"), lub.viscosity_pa_s)?;
                    if let Some(g) = &b.grid {
                        FilmGrid::parse(g).map_err(|e| err(f("grid"), g.clone(), &e))?;
                    }
                    if b.model == BearingModelKind::Short && b.grooves != GroovesSpec::None {
                        return Err(err(
                            f("grooves"),
                            "two-axial".into(),
                            "the short-bearing model has no grooves",
                        ));
                    }
                    let (dm, cm) = (
                        b.diameter_m.unwrap_or(0.0),
                        b.radial_clearance_m.unwrap_or(0.0),
                    );
                    if cm > 0.025 * dm {
                        return Err(err(
                            f("radial_clearance_m"),
                            cm.to_string(),
                            "must be below 5 % of the journal radius",
                        ));
                    }
                }
                BearingModelKind::Linear => {
                    let Some(k) = b.stiffness_n_per_m else {
                        return Err(err(
                            f("stiffness_n_per_m"),
                            "(missing)".into(),
                            "is required for a linear bearing",
                        ));
                    };
                    finite_matrix(&f("stiffness_n_per_m"), &k)
                        .map_err(|(fld, v)| err(fld, v, "must be finite"))?;
                    if let Some(c) = b.damping_n_s_per_m {
                        finite_matrix(&f("damping_n_s_per_m"), &c)
                            .map_err(|(fld, v)| err(fld, v, "must be finite"))?;
                    }
                }
                BearingModelKind::Rigid => {
                    if b.support.is_some() {
                        return Err(err(
                            f("support"),
                            "(given)".into(),
                            "a rigid bearing has no flexible support",
                        ));
                    }
                }
            }
            if let Some(s) = &b.support {
                positive(f("support.mass_kg"), s.mass_kg)?;
                finite_matrix(&f("support.stiffness_n_per_m"), &s.stiffness_n_per_m)
                    .map_err(|(fld, v)| err(fld, v, "must be finite"))?;
                finite_matrix(&f("support.damping_n_s_per_m"), &s.damping_n_s_per_m)
                    .map_err(|(fld, v)| err(fld, v, "must be finite"))?;
            }
        }
        for (i, u) in self.unbalance.iter().enumerate() {
            node_ok(format!("unbalance[{i}].node"), u.node)?;
            non_negative(format!("unbalance[{i}].magnitude_g_mm"), u.magnitude_g_mm)?;
            // the one bound on an unbalance, as for one received on the bus
            let max_g_mm = crate::driver::inputs::MAX_UNBALANCE_KG_M * 1e6;
            if u.magnitude_g_mm > max_g_mm {
                return Err(err(
                    format!("unbalance[{i}].magnitude_g_mm"),
                    u.magnitude_g_mm.to_string(),
                    &format!("is absurd (more than {max_g_mm} g·mm)"),
                ));
            }
            if !u.phase_deg.is_finite() {
                return Err(err(
                    format!("unbalance[{i}].phase_deg"),
                    u.phase_deg.to_string(),
                    "must be finite",
                ));
            }
        }
        self.validate_viscosity_laws(file)?;
        for (i, p) in self.probes.iter().enumerate() {
            node_ok(format!("probes[{i}].node"), p.node)?;
            if p.angles_deg.iter().any(|a| !a.is_finite()) {
                return Err(err(
                    format!("probes[{i}].angles_deg"),
                    format!("{:?}", p.angles_deg),
                    "must be finite",
                ));
            }
            let gap = (p.angles_deg[1] - p.angles_deg[0]).to_radians().sin().abs();
            if gap < 0.1 {
                return Err(err(
                    format!("probes[{i}].angles_deg"),
                    format!("{:?}", p.angles_deg),
                    "the two probes must not look along the same line",
                ));
            }
        }
        Ok(())
    }
}

/// Largest machine file read (bytes): 1 MiB (the shipped ones are 2–4 kB).
pub const MAX_MACHINE_FILE_BYTES: usize = 1 << 20;
/// Most shaft elements in total: 200. The matrices are dense, 4 degrees of freedom a node, and
/// the modal analysis solves a state-space eigenproblem of 8 per node: its cost grows as the cube
/// of the node count (10,000 elements would ask for 12.8 GB). The shipped machines use 30.
pub const MAX_SHAFT_ELEMENTS: usize = 200;
/// Longest name of a bearing or probe station (characters); names appear in topics, warnings
/// and file names.
pub const MAX_NAME_CHARS: usize = 64;
/// A film bearing at most this many diameters long (the film model's own bound).
const MAX_BEARING_LENGTH_DIAMETERS: f64 = 10.0;

impl MachineDescription {
    /// The bounds checked before the per-field rules: model size, names, bearing proportions.
    fn validate_limits(&self, file: &str) -> Result<(), ConfigError> {
        let err = |field: String, value: String, rule: String| ConfigError {
            file: file.to_string(),
            field,
            value,
            rule,
        };
        let elements: usize = self.shaft.iter().map(|s| s.elements).sum();
        if elements > MAX_SHAFT_ELEMENTS {
            return Err(err(
                "shaft[*].elements".into(),
                format!("{elements} in total"),
                format!(
                    "at most {MAX_SHAFT_ELEMENTS} elements in all: the dense model's memory grows as the square and its modal analysis as the cube of the node count"
                ),
            ));
        }
        let bearing_names = self.bearings.iter().map(|b| &b.name);
        let probe_names = self.probes.iter().map(|p| &p.name);
        for (kind, names) in [
            ("bearings", bearing_names.collect::<Vec<_>>()),
            ("probes", probe_names.collect::<Vec<_>>()),
        ] {
            for (i, name) in names.iter().enumerate() {
                let field = format!("{kind}[{i}].name");
                if let Some(rule) = name_problem(name) {
                    return Err(err(field, shown(name), rule));
                }
                if names[..i].contains(name) {
                    return Err(err(field, shown(name), "must be unique".into()));
                }
            }
        }
        for (i, b) in self.bearings.iter().enumerate() {
            if let (Some(d), Some(l)) = (b.diameter_m, b.length_m) {
                if l > MAX_BEARING_LENGTH_DIAMETERS * d {
                    return Err(err(
                        format!("bearings[{i}].length_m"),
                        l.to_string(),
                        format!(
                            "must not exceed {MAX_BEARING_LENGTH_DIAMETERS} diameters (diameter_m = {d}): beyond it the film model does not hold"
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Why `name` cannot name a bearing or station, if it cannot.
fn name_problem(name: &str) -> Option<String> {
    if name.trim().is_empty() {
        Some("must not be empty".into())
    } else if name.chars().count() > MAX_NAME_CHARS {
        Some(format!("must be at most {MAX_NAME_CHARS} characters"))
    } else if name.chars().any(char::is_control) {
        Some("must not contain control characters".into())
    } else {
        None
    }
}

/// `value` as shown in an error: at most 40 characters, then its length.
fn shown(value: &str) -> String {
    if value.chars().count() <= 40 {
        format!("{value:?}")
    } else {
        let head: String = value.chars().take(40).collect();
        format!("{head:?}… ({} characters)", value.chars().count())
    }
}

fn finite_matrix(field: &str, m: &[[f64; 2]; 2]) -> Result<(), (String, String)> {
    for (i, row) in m.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            if !v.is_finite() {
                return Err((format!("{field}[{i}][{j}]"), v.to_string()));
            }
        }
    }
    Ok(())
}
