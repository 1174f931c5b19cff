//! What may reach the twin from outside (a bus or a bag): the inputs as typed values, the limits
//! they are checked against (taken from the machine that runs), and the checks. A NaN, negative,
//! absurd, stale, future or backwards value is refused with a reason and never reaches the model.

use crate::messages;
use crate::rotor::Rotor;
use std::fmt;
use std::str::FromStr;

/// Largest plausible residual unbalance m·e (kg·m): 0.01 kg·m = 10,000 g·mm, about 200 times the
/// ISO 21940 G2.5 allowance of a 50 kg rotor at 9,000 rpm; more is a unit error, not a rotor.
pub const MAX_UNBALANCE_KG_M: f64 = 0.01;

/// Largest plausible probe displacement (m): 10 mm, far beyond any fluid-film clearance.
pub const MAX_PROBE_DISPLACEMENT_M: f64 = 0.01;

/// Largest plausible angular acceleration (rad/s²): 10⁴ rad/s² takes a rotor from rest to
/// 9,000 rpm in 0.1 s, far faster than any turbine is run up.
pub const MAX_ACCEL_RAD_S2: f64 = 1.0e4;

pub use crate::dynamics::MAX_SPEED_OVER_RATED;

/// Unit of a bare speed value (std_msgs/Float64 on a plant bus).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedUnit {
    /// Revolutions per minute.
    Rpm,
    /// Radians per second.
    RadPerS,
    /// Revolutions per second.
    Hz,
}

impl SpeedUnit {
    /// Converts a value in this unit to rad/s.
    pub fn to_rad_s(self, v: f64) -> f64 {
        match self {
            SpeedUnit::Rpm => v * std::f64::consts::PI / 30.0,
            SpeedUnit::RadPerS => v,
            SpeedUnit::Hz => v * std::f64::consts::TAU,
        }
    }
}

impl FromStr for SpeedUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "rpm" => Ok(SpeedUnit::Rpm),
            "rad_s" => Ok(SpeedUnit::RadPerS),
            "hz" => Ok(SpeedUnit::Hz),
            other => Err(format!("'{other}' must be rpm, rad_s or hz")),
        }
    }
}

impl fmt::Display for SpeedUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SpeedUnit::Rpm => "rpm",
            SpeedUnit::RadPerS => "rad_s",
            SpeedUnit::Hz => "hz",
        })
    }
}

/// A probe station, as a message names it (ProbeDisplacement) or as a topic mapping fixes it
/// (one PointStamped topic per station).
#[derive(Debug, Clone, PartialEq)]
pub enum StationRef {
    /// By name, checked against the machine's stations.
    Name(String),
    /// By index into the machine's stations (already checked).
    Index(usize),
}

/// One input to the twin, before its checks.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    /// Rotor speed.
    Speed {
        /// Speed (rad/s).
        speed_rad_s: f64,
        /// Angular acceleration (rad/s²).
        accel_rad_s2: f64,
        /// Header stamp (ns since the epoch; 0: unstamped).
        stamp_ns: i64,
    },
    /// A residual unbalance in one of the machine's planes.
    Unbalance {
        /// Plane index (the machine file's `unbalance` list).
        plane: u32,
        /// m·e (kg·m).
        magnitude_kg_m: f64,
        /// Phase against the shaft angle (rad).
        phase_rad: f64,
    },
    /// A measured journal displacement at a probe station, in the machine frame.
    Probe {
        /// The station.
        station: StationRef,
        /// Displacement x (m).
        x_m: f64,
        /// Displacement y (m).
        y_m: f64,
        /// Header stamp (ns since the epoch; 0: unstamped).
        stamp_ns: i64,
    },
    // --- oil supply temperature (issue 12) ---
    /// The oil supply temperature (sensor_msgs/Temperature, °C on the wire): sets the films'
    /// viscosity through the machine file's viscosity–temperature law.
    OilTemperature {
        /// Temperature (K).
        temperature_k: f64,
        /// Header stamp (ns since the epoch; 0: unstamped).
        stamp_ns: i64,
    },
    // --- end oil supply temperature ---
    // --- plant signals (issue 12) ---
    /// A once-per-revolution keyphasor event: the plant's shaft angle 0 at the stamp.
    Keyphasor {
        /// Header stamp of the event (ns since the epoch; 0: unstamped, the receive time).
        stamp_ns: i64,
    },
    /// One raw proximity-probe reading along the probe's own axis.
    ProbeSignal {
        /// The probe.
        probe: ProbeRef,
        /// The reading in the probe's unit (machine file's `proximity_probes`).
        value: f64,
        /// Header stamp (ns since the epoch; 0: unstamped).
        stamp_ns: i64,
    },
    // --- end plant signals ---
}

// --- oil supply temperature (issue 12) ---
impl From<&messages::Temperature> for Input {
    fn from(m: &messages::Temperature) -> Self {
        Input::OilTemperature {
            temperature_k: m.temperature + crate::film::ZERO_CELSIUS_K,
            stamp_ns: m.header.stamp.as_nanos(),
        }
    }
}
// --- end oil supply temperature ---

// --- plant signals (issue 12) ---

/// A raw proximity probe, as a message names it (ProbeSignal) or as a topic mapping fixes it
/// (one std_msgs/Float64 topic per probe).
#[derive(Debug, Clone, PartialEq)]
pub enum ProbeRef {
    /// By name, checked against the machine's `proximity_probes`.
    Name(String),
    /// By index into the machine's `proximity_probes` (already checked).
    Index(usize),
}

impl From<&messages::Keyphasor> for Input {
    fn from(m: &messages::Keyphasor) -> Self {
        Input::Keyphasor {
            stamp_ns: m.header.stamp.as_nanos(),
        }
    }
}

/// The viscosity scale µ_i(T) / µ_reference,i an oil supply temperature `t_k` (K) gives each
/// film bearing of `rotor` through its own law, written into `out` (one per film bearing, in
/// their order; allocates nothing), or why the temperature is refused: not finite, outside a
/// law's range, or no law in the machine file (which gives every film bearing a law once one
/// has: one oil supply).
pub fn oil_viscosity_scales(rotor: &Rotor, t_k: f64, out: &mut [f64]) -> Result<(), String> {
    let films = rotor.bearings.iter().filter_map(|b| match &b.model {
        crate::rotor::BearingModel::Film(f) => Some((b, f)),
        _ => None,
    });
    let mut n = 0;
    for ((b, f), slot) in films.zip(out.iter_mut()) {
        let Some(law) = f.viscosity_law else {
            return Err(
                "an oil temperature needs a viscosity–temperature law (lubricant.viscosity_temperature in the machine file); this machine has none"
                    .into(),
            );
        };
        let mu = law.checked_viscosity_pa_s(t_k)?;
        *slot = crate::film::check_viscosity_scale(mu / f.lubricant.viscosity_pa_s)
            .map_err(|e| format!("oil temperature, bearing {}: {e}", b.name))?;
        n += 1;
    }
    if n == 0 {
        return Err("an oil temperature needs a film bearing with a viscosity–temperature law; this machine has none".into());
    }
    Ok(())
}
// --- end oil supply temperature ---
impl From<&messages::Header> for Input {
    /// A std_msgs/Header on the keyphasor topic: its stamp is the event.
    fn from(m: &messages::Header) -> Self {
        Input::Keyphasor {
            stamp_ns: m.stamp.as_nanos(),
        }
    }
}

impl From<&messages::ProbeSignal> for Input {
    fn from(m: &messages::ProbeSignal) -> Self {
        Input::ProbeSignal {
            probe: ProbeRef::Name(m.probe.clone()),
            value: m.value,
            stamp_ns: m.header.stamp.as_nanos(),
        }
    }
}

impl Input {
    /// A bare probe reading (std_msgs/Float64) of raw probe `probe`: unstamped.
    pub fn probe_value(value: f64, probe: usize) -> Self {
        Input::ProbeSignal {
            probe: ProbeRef::Index(probe),
            value,
            stamp_ns: 0,
        }
    }
}
// --- end plant signals ---

impl From<&messages::RotorSpeed> for Input {
    fn from(m: &messages::RotorSpeed) -> Self {
        Input::Speed {
            speed_rad_s: m.speed,
            accel_rad_s2: m.acceleration,
            stamp_ns: m.header.stamp.as_nanos(),
        }
    }
}

impl From<&messages::Unbalance> for Input {
    fn from(m: &messages::Unbalance) -> Self {
        Input::Unbalance {
            plane: m.plane,
            magnitude_kg_m: m.magnitude,
            phase_rad: m.phase,
        }
    }
}

impl From<&messages::ProbeDisplacement> for Input {
    fn from(m: &messages::ProbeDisplacement) -> Self {
        Input::Probe {
            station: StationRef::Name(m.station.clone()),
            x_m: m.x,
            y_m: m.y,
            stamp_ns: m.header.stamp.as_nanos(),
        }
    }
}

impl Input {
    /// A bare speed value (std_msgs/Float64) in `unit`: unstamped, no acceleration.
    pub fn speed_value(value: f64, unit: SpeedUnit) -> Self {
        Input::Speed {
            speed_rad_s: unit.to_rad_s(value),
            accel_rad_s2: 0.0,
            stamp_ns: 0,
        }
    }

    /// A geometry_msgs/PointStamped probe pair (x, y in m) of station `station`.
    pub fn probe_point(m: &messages::PointStamped, station: usize) -> Self {
        Input::Probe {
            station: StationRef::Index(station),
            x_m: m.point.x,
            y_m: m.point.y,
            stamp_ns: m.header.stamp.as_nanos(),
        }
    }
}

/// The limits inputs are checked against: from the machine that runs (its rated speed, planes and
/// stations), never from another one.
#[derive(Debug, Clone, PartialEq)]
pub struct InputLimits {
    /// Largest plausible speed (rad/s): [`MAX_SPEED_OVER_RATED`] × the machine's rated speed.
    pub max_speed_rad_s: f64,
    /// Number of unbalance planes of the machine.
    pub planes: usize,
    /// Probe station names of the machine.
    pub stations: Vec<String>,
}

impl InputLimits {
    /// The limits of `rotor`.
    pub fn of(rotor: &Rotor) -> Self {
        Self {
            max_speed_rad_s: MAX_SPEED_OVER_RATED * rotor.rated_speed_rad_s.max(1.0),
            planes: rotor.unbalance.len(),
            stations: rotor.probes.iter().map(|p| p.name.clone()).collect(),
        }
    }

    /// Index of a station, or the reason it is refused.
    pub fn station(&self, station: &StationRef) -> Result<usize, String> {
        match station {
            StationRef::Index(k) if *k < self.stations.len() => Ok(*k),
            StationRef::Index(k) => Err(format!("probe station {k} does not exist")),
            StationRef::Name(name) => {
                self.stations.iter().position(|s| s == name).ok_or_else(|| {
                    format!(
                        "probe station '{}' is not in the machine description",
                        bounded(name)
                    )
                })
            }
        }
    }
}

/// A name as it may be echoed in a message: at most 64 characters.
fn bounded(text: &str) -> String {
    if text.chars().count() <= 64 {
        text.to_string()
    } else {
        format!("{}…", text.chars().take(64).collect::<String>())
    }
}

/// Gate for speed messages: finite, not negative, at most the machine's limit, acceleration
/// finite and bounded; a stamp neither older than the timeout nor further ahead than it (a clock
/// that jumps ahead must not lock out every later speed), nor behind the last accepted stamp.
#[derive(Debug, Clone)]
pub struct SpeedGate {
    /// Largest plausible speed (rad/s).
    pub max_speed_rad_s: f64,
    /// Largest plausible angular acceleration (rad/s²).
    pub max_accel_rad_s2: f64,
    /// A stamp further than this (ns) from the receive time, either way, is refused.
    pub timeout_ns: i64,
    last_stamp_ns: Option<i64>,
}

impl SpeedGate {
    /// A gate accepting speeds up to `max_speed_rad_s` and stamps within `timeout_s` of the
    /// receive time.
    pub fn new(max_speed_rad_s: f64, timeout_s: f64) -> Self {
        Self {
            max_speed_rad_s,
            max_accel_rad_s2: MAX_ACCEL_RAD_S2,
            timeout_ns: seconds_to_ns(timeout_s),
            last_stamp_ns: None,
        }
    }

    /// Checks one speed (rad/s) and acceleration (rad/s²) stamped `stamp_ns` (0: unstamped)
    /// received at `now_ns`. Ok((speed, accel)) or the reason for refusing it.
    pub fn check(
        &mut self,
        speed: f64,
        accel: f64,
        stamp_ns: i64,
        now_ns: i64,
    ) -> Result<(f64, f64), String> {
        check_speed_value(speed, accel, self.max_speed_rad_s, self.max_accel_rad_s2)?;
        if stamp_ns != 0 {
            // a last stamp now in the future of the clock means the clock went back (a
            // simulator reset, a bag looped): it no longer orders anything
            if self
                .last_stamp_ns
                .is_some_and(|last| last.saturating_sub(now_ns) > self.timeout_ns)
            {
                self.last_stamp_ns = None;
            }
            if let Some(last) = self.last_stamp_ns {
                if stamp_ns < last {
                    return Err(format!(
                        "stamp {:.6} s goes backwards (last {:.6} s)",
                        stamp_ns as f64 * 1e-9,
                        last as f64 * 1e-9
                    ));
                }
            }
            let age = now_ns.saturating_sub(stamp_ns);
            if age > self.timeout_ns {
                return Err(format!("stamp is stale: {:.3} s old", age as f64 * 1e-9));
            }
            if -age > self.timeout_ns {
                return Err(format!(
                    "stamp is {:.3} s in the future of the clock",
                    -age as f64 * 1e-9
                ));
            }
            self.last_stamp_ns = Some(stamp_ns);
        }
        Ok((speed, accel))
    }
}

/// A time (s) as ns, saturating (an infinite timeout never expires).
pub fn seconds_to_ns(s: f64) -> i64 {
    if s.is_finite() {
        (s * 1e9).clamp(i64::MIN as f64, i64::MAX as f64) as i64
    } else if s > 0.0 {
        i64::MAX
    } else {
        0
    }
}

fn check_speed_value(speed: f64, accel: f64, max: f64, max_accel: f64) -> Result<(), String> {
    if !speed.is_finite() {
        return Err(format!("speed {speed} rad/s is not a finite number"));
    }
    if speed < 0.0 {
        return Err(format!(
            "speed {speed} rad/s is negative (the machine turns one way)"
        ));
    }
    if speed > max {
        return Err(format!(
            "speed {speed:.1} rad/s is absurd (above {max:.1} rad/s, {MAX_SPEED_OVER_RATED}× the machine's rated speed)"
        ));
    }
    if !accel.is_finite() || accel.abs() > max_accel {
        return Err(format!(
            "angular acceleration {accel} rad/s² is not finite or above {max_accel} rad/s²"
        ));
    }
    Ok(())
}

/// Checks an unbalance: plane index among `planes`, m·e (kg·m) finite in
/// [0, [`MAX_UNBALANCE_KG_M`]], phase (rad) finite.
pub fn check_unbalance(
    plane: u32,
    magnitude: f64,
    phase: f64,
    planes: usize,
) -> Result<(usize, f64, f64), String> {
    let p = plane as usize;
    if p >= planes {
        return Err(format!(
            "unbalance plane {plane} does not exist (the machine has {planes})"
        ));
    }
    if !magnitude.is_finite() || !(0.0..=MAX_UNBALANCE_KG_M).contains(&magnitude) {
        return Err(format!(
            "unbalance {magnitude} kg·m must be finite, 0 to {MAX_UNBALANCE_KG_M} kg·m"
        ));
    }
    if !phase.is_finite() {
        return Err(format!("unbalance phase {phase} rad is not finite"));
    }
    Ok((p, magnitude, phase))
}

/// Checks a probe displacement (m): finite and within [`MAX_PROBE_DISPLACEMENT_M`].
pub fn check_probe(x: f64, y: f64) -> Result<(f64, f64), String> {
    let max = MAX_PROBE_DISPLACEMENT_M;
    if !(x.is_finite() && y.is_finite()) || x.abs() > max || y.abs() > max {
        return Err(format!(
            "probe displacement ({x}, {y}) m is not finite or beyond {} mm",
            max * 1e3
        ));
    }
    Ok((x, y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_gate_refuses_bad_values_and_stamps() {
        let mut g = SpeedGate::new(9424.0, 1.0);
        let now = 100_000_000_000;
        assert!(g.check(942.0, 0.0, now - 1_000_000, now).is_ok());
        for bad in [f64::NAN, f64::INFINITY, -1.0, 1e6] {
            assert!(g.check(bad, 0.0, now, now).is_err(), "{bad}");
        }
        assert!(g.check(942.0, f64::NAN, now, now).is_err());
        assert!(g
            .check(942.0, 0.0, now - 2_000_000, now)
            .unwrap_err()
            .contains("backwards"));
        assert!(g
            .check(942.0, 0.0, now - 500_000, now + 2_000_000_000)
            .unwrap_err()
            .contains("stale"));
        assert!(g.check(942.0, 0.0, 0, now).is_ok(), "unstamped is accepted");
        assert!(check_unbalance(0, 1.4e-4, 0.0, 1).is_ok());
        assert!(check_unbalance(1, 1.4e-4, 0.0, 1).is_err());
        assert!(check_unbalance(0, f64::NAN, 0.0, 1).is_err());
        assert!(check_unbalance(0, 5.0, 0.0, 1).is_err());
        assert!(check_probe(f64::NAN, 0.0).is_err());
    }

    #[test]
    fn a_stamp_from_the_future_is_refused_and_locks_nothing_out() {
        // one speed stamped 1 h ahead used to be accepted, and every later correctly stamped
        // speed was then refused as going backwards (issue 15, item 10)
        let mut g = SpeedGate::new(9424.0, 1.0);
        let now = 100_000_000_000;
        let hour = 3_600_000_000_000;
        assert!(g
            .check(942.0, 0.0, now + hour, now)
            .unwrap_err()
            .contains("future"));
        for k in 1..=10 {
            let t = now + k * 10_000_000;
            assert!(g.check(942.0, 0.0, t, t).is_ok(), "sample {k}");
        }
        // a reordered sample is still refused as going backwards
        assert!(g
            .check(942.0, 0.0, now, now + 100_000_000)
            .unwrap_err()
            .contains("backwards"));
        // the clock itself went back 50 s (a simulator reset): speeds stamped on it are taken
        let back = now - 50_000_000_000;
        assert!(g.check(942.0, 0.0, back, back).is_ok());
    }

    #[test]
    fn units_and_station_names() {
        assert!((SpeedUnit::Rpm.to_rad_s(9000.0) - 942.477_796).abs() < 1e-5);
        assert!((SpeedUnit::Hz.to_rad_s(150.0) - 942.477_796).abs() < 1e-5);
        for u in [SpeedUnit::Rpm, SpeedUnit::RadPerS, SpeedUnit::Hz] {
            assert_eq!(u.to_string().parse::<SpeedUnit>(), Ok(u));
        }
        assert!("furlongs".parse::<SpeedUnit>().is_err());
        let limits = InputLimits {
            max_speed_rad_s: 1.0,
            planes: 1,
            stations: vec!["a".into()],
        };
        assert_eq!(limits.station(&StationRef::Name("a".into())), Ok(0));
        let long = "x".repeat(1_000_000);
        let why = limits.station(&StationRef::Name(long)).unwrap_err();
        assert!(
            why.len() < 200,
            "a huge name is not echoed: {} bytes",
            why.len()
        );
    }
}
