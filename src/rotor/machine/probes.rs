//! Probe stations and raw proximity probes of the machine file (issue 12).

use super::rules::{shown, Rules};
use super::MachineDescription;
use crate::rotor::ConfigError;
use crate::signals::probes::{
    check_orthogonal, reading_to_m, ProbeCoupling, ProbeUnit, RawProbe, MAX_GAP_M,
};
use serde::{Deserialize, Serialize};

/// Largest slow-roll runout accepted (m): 1 mm, far beyond any shaft a probe can look at.
const MAX_RUNOUT_M: f64 = 1e-3;
/// Smallest sensitivity in size (V/m): below it the readings are not volts of a proximity probe.
const MIN_SENSITIVITY_V_PER_M: f64 = 1.0;
/// Two probes of a station must be at least this far from looking along one line (|sin Δα|).
const MIN_PROBE_PAIR_SINE: f64 = 0.1;

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
    pub unit: ProbeUnit,
    /// Sensitivity for readings in volts (V/m); default 7870 (7.87 V/mm = 200 mV/mil).
    #[serde(default = "default_sensitivity")]
    pub sensitivity_v_per_m: f64,
    /// `ac` (mean removed; the default) or `dc` (gap kept as the journal's mean position).
    #[serde(default = "default_coupling")]
    pub coupling: ProbeCoupling,
    /// Gap at the reference position (the shaft centred), in the probe's unit; DC coupling.
    #[serde(default)]
    pub reference_gap: f64,
    /// Slow-roll runout 1X vector, if known: amplitude (m) and phase lag (deg) from the keyphasor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runout: Option<RunoutSpec>,
    /// The transducer system's linear range, two readings in the probe's unit in either order
    /// (e.g. `[-2.0, -18.0]` V for an API 670 system on a −24 V supply, `[250, 2300]` µm);
    /// readings outside it are refused as saturated or out of range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_range: Option<[f64; 2]>,
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

fn default_probe_unit() -> ProbeUnit {
    ProbeUnit::Um
}

fn default_sensitivity() -> f64 {
    crate::signals::probes::DEFAULT_SENSITIVITY_V_PER_M
}

fn default_coupling() -> ProbeCoupling {
    ProbeCoupling::Ac
}

/// A probe's linear range `[a, b]` (readings in `unit`), checked: finite, not empty, and its
/// gaps within ±[`MAX_GAP_M`]; returned as (low, high).
fn check_linear_range(
    r: [f64; 2],
    unit: ProbeUnit,
    sensitivity_v_per_m: f64,
    field: &str,
    rules: &Rules,
) -> Result<(f64, f64), ConfigError> {
    let (low, high) = (r[0].min(r[1]), r[0].max(r[1]));
    let gap_ok = |v: f64| reading_to_m(v, unit, sensitivity_v_per_m).abs() <= MAX_GAP_M;
    if !(low.is_finite() && high.is_finite() && low < high && gap_ok(low) && gap_ok(high)) {
        return Err(rules.error(
            field,
            format!("{r:?}"),
            format!(
                "must be two different finite readings within {} mm of gap",
                MAX_GAP_M * 1e3
            ),
        ));
    }
    Ok((low, high))
}

impl MachineDescription {
    /// The raw proximity probes of the file as the driver uses them, checked: names unique,
    /// stations known, two orthogonal probes a station, sensitivity, gap and runout valid, the
    /// slow-roll speed within (0, rated].
    pub fn raw_probes(&self, file: &str) -> Result<Vec<RawProbe>, ConfigError> {
        let rules = Rules { file };
        let mut out: Vec<RawProbe> = Vec::with_capacity(self.proximity_probes.len());
        for (i, p) in self.proximity_probes.iter().enumerate() {
            let probe = self.raw_probe(i, p, &out, &rules)?;
            out.push(probe);
        }
        self.check_probe_pairs(&out, &rules)?;
        if let Some(v) = self.slow_roll_speed_rpm {
            if !(v.is_finite() && v > 0.0 && v <= self.rated_speed_rpm) {
                return Err(rules.error(
                    "slow_roll_speed_rpm",
                    v,
                    "must be above 0 and at most the rated speed",
                ));
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
        rules: &Rules,
    ) -> Result<RawProbe, ConfigError> {
        let field = |name: &str| format!("proximity_probes[{i}].{name}");
        rules.name(field("name"), &p.name)?;
        if before.iter().any(|q| q.name == p.name) {
            return Err(rules.error(field("name"), shown(&p.name), "must be unique"));
        }
        let station = self
            .probes
            .iter()
            .position(|s| s.name == p.station)
            .ok_or_else(|| {
                rules.error(
                    field("station"),
                    shown(&p.station),
                    "must name one of the probes stations",
                )
            })?;
        let axis = before.iter().filter(|q| q.station == station).count();
        if axis >= 2 {
            return Err(rules.error(
                field("station"),
                shown(&p.station),
                "has two probes already",
            ));
        }
        let s = p.sensitivity_v_per_m;
        if !s.is_finite() || s.abs() < MIN_SENSITIVITY_V_PER_M {
            return Err(rules.error(
                field("sensitivity_v_per_m"),
                s,
                format!("must be finite and at least {MIN_SENSITIVITY_V_PER_M} V/m in size"),
            ));
        }
        rules.finite(field("angle_deg"), p.angle_deg)?;
        rules.finite(field("reference_gap"), p.reference_gap)?;
        if let Some(r) = p.runout {
            if !(r.amplitude_m.is_finite()
                && (0.0..=MAX_RUNOUT_M).contains(&r.amplitude_m)
                && r.phase_lag_deg.is_finite())
            {
                return Err(rules.error(
                    field("runout"),
                    format!("{r:?}"),
                    "amplitude must be 0 to 1 mm, phase finite",
                ));
            }
        }
        let linear_range = p
            .linear_range
            .map(|r| check_linear_range(r, p.unit, s, &field("linear_range"), rules))
            .transpose()?;
        Ok(RawProbe {
            linear_range,
            name: p.name.clone(),
            station,
            axis,
            angle_rad: p.angle_deg.to_radians(),
            unit: p.unit,
            sensitivity_v_per_m: s,
            coupling: p.coupling,
            reference_gap_m: reading_to_m(p.reference_gap, p.unit, s),
            runout: p.runout.map(|r| crate::signals::OneXVector {
                amplitude_m: r.amplitude_m,
                phase_lag_deg: r.phase_lag_deg.rem_euclid(360.0),
            }),
        })
    }

    /// Each station with raw probes has two, orthogonal.
    fn check_probe_pairs(&self, probes: &[RawProbe], rules: &Rules) -> Result<(), ConfigError> {
        for (k, st) in self.probes.iter().enumerate() {
            let at: Vec<&RawProbe> = probes.iter().filter(|q| q.station == k).collect();
            let problem = match at.len() {
                0 => None,
                2 => check_orthogonal([at[0].angle_rad, at[1].angle_rad]).err(),
                _ => Some("a station needs two probes (one is not enough for an orbit)".into()),
            };
            if let Some(rule) = problem {
                return Err(rules.error("proximity_probes[*]", &st.name, rule));
            }
        }
        Ok(())
    }

    /// The probe stations: names unique, nodes on the shaft, the two probes not along one line.
    pub(super) fn check_probe_stations(&self, rules: &Rules) -> Result<(), ConfigError> {
        let nodes = self.node_count();
        for (i, p) in self.probes.iter().enumerate() {
            let field = |name: &str| format!("probes[{i}].{name}");
            rules.name(field("name"), &p.name)?;
            if self.probes[..i].iter().any(|q| q.name == p.name) {
                return Err(rules.error(field("name"), shown(&p.name), "must be unique"));
            }
            rules.node(field("node"), p.node, nodes)?;
            if p.angles_deg.iter().any(|a| !a.is_finite()) {
                return Err(rules.error(
                    field("angles_deg"),
                    format!("{:?}", p.angles_deg),
                    "must be finite",
                ));
            }
            let gap = (p.angles_deg[1] - p.angles_deg[0]).to_radians().sin().abs();
            if gap < MIN_PROBE_PAIR_SINE {
                return Err(rules.error(
                    field("angles_deg"),
                    format!("{:?}", p.angles_deg),
                    "the two probes must not look along the same line",
                ));
            }
        }
        Ok(())
    }
}
