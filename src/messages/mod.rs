//! The messages rotor-twin speaks, mirrored from the ROS 2 interface package in `msg/`
//! (`rotor_twin_msgs`) and the standard ROS 2 types it uses. I/O-free: the node, the recorder and
//! the replay all use these. Each type carries its `.msg` text (the MCAP schema) and its field list,
//! which a test checks against the `.msg` files. Units: SI (REP 103), stated in the `.msg` files.

mod standard;
pub mod type_hash;

pub use standard::{
    Clock, DiagnosticArray, DiagnosticStatus, Float64, KeyValue, Point, PointStamped, Temperature,
};

use serde::{Deserialize, Serialize};

/// A ROS 2 message type: its full name, `.msg` text, direct dependencies and fields.
pub trait RosMessage: Serialize + for<'de> Deserialize<'de> {
    /// `pkg/msg/Type`.
    const TYPE_NAME: &'static str;
    /// The `.msg` text.
    const DEFINITION: &'static str;
    /// Every type this one uses, each once, as (`pkg/Type`, `.msg` text), depth first.
    const DEPENDENCIES: &'static [(&'static str, &'static str)];
    /// Fields in order: (name, ROS type as written in the `.msg`).
    const FIELDS: &'static [(&'static str, &'static str)];

    /// The MCAP / rosbag2 schema: the definition, then each dependency after a line of 80 `=`
    /// and a `MSG: pkg/Type` line.
    fn schema() -> String {
        let mut s = Self::DEFINITION.trim_end().to_string();
        for (name, text) in Self::DEPENDENCIES {
            s.push('\n');
            s.push_str(&"=".repeat(80));
            s.push_str(&format!("\nMSG: {name}\n"));
            s.push_str(text.trim_end());
        }
        s
    }

    /// The type's RIHS01 hash (REP 2016), from its definition and dependencies.
    fn type_hash() -> String {
        type_hash::rihs01(Self::TYPE_NAME, &Self::schema())
            .expect("the crate's own message definitions parse (tests/messages.rs checks each)")
    }
}

/// builtin_interfaces/Time `.msg` text.
pub const TIME_DEFINITION: &str = "int32 sec\nuint32 nanosec\n";
/// std_msgs/Header `.msg` text.
pub const HEADER_DEFINITION: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
/// Dependencies of a message holding a std_msgs/Header.
pub const HEADER_DEPENDENCIES: &[(&str, &str)] = &[
    ("std_msgs/Header", HEADER_DEFINITION),
    ("builtin_interfaces/Time", TIME_DEFINITION),
];

/// builtin_interfaces/Time: seconds and nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds (s).
    pub sec: i32,
    /// Nanoseconds within the second (ns).
    pub nanosec: u32,
}

impl Time {
    /// From nanoseconds (ns); saturates outside the i32-second range.
    pub fn from_nanos(ns: i64) -> Self {
        let sec = ns
            .div_euclid(1_000_000_000)
            .clamp(i64::from(i32::MIN), i64::from(i32::MAX));
        Self {
            sec: sec as i32,
            nanosec: ns.rem_euclid(1_000_000_000) as u32,
        }
    }

    /// From seconds (s).
    pub fn from_secs_f64(s: f64) -> Self {
        Self::from_nanos((s * 1e9).round() as i64)
    }

    /// In nanoseconds (ns).
    pub fn as_nanos(&self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }

    /// In seconds (s).
    pub fn as_secs_f64(&self) -> f64 {
        self.as_nanos() as f64 * 1e-9
    }
}

/// std_msgs/Header.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Header {
    /// Time stamp.
    pub stamp: Time,
    /// Frame of the data.
    pub frame_id: String,
}

/// Declares a rotor_twin_msgs message: the struct, its `.msg` text and its field list.
macro_rules! ros_message {
    ($(#[$m:meta])* $name:ident, $file:literal { $( $(#[$fm:meta])* $field:ident : $ty:ty = $ros:literal ),* $(,)? }) => {
        $(#[$m])*
        #[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
        pub struct $name {
            $( $(#[$fm])* pub $field: $ty, )*
        }

        impl RosMessage for $name {
            const TYPE_NAME: &'static str = concat!("rotor_twin_msgs/msg/", stringify!($name));
            const DEFINITION: &'static str = include_str!(concat!("../../msg/msg/", $file));
            const DEPENDENCIES: &'static [(&'static str, &'static str)] = HEADER_DEPENDENCIES;
            const FIELDS: &'static [(&'static str, &'static str)] = &[ $( (stringify!($field), $ros) ),* ];
        }
    };
}

ros_message!(
    /// Spin speed of the rotor (rad/s), stamped.
    RotorSpeed, "RotorSpeed.msg" {
        /// Time of the measurement.
        header: Header = "std_msgs/Header",
        /// Spin speed (rad/s).
        speed: f64 = "float64",
        /// Angular acceleration (rad/s²).
        acceleration: f64 = "float64",
    }
);

ros_message!(
    /// A residual unbalance in one plane (kg·m, rad).
    Unbalance, "Unbalance.msg" {
        /// Time the value applies from.
        header: Header = "std_msgs/Header",
        /// Plane index in the machine description.
        plane: u32 = "uint32",
        /// m·e (kg·m).
        magnitude: f64 = "float64",
        /// Heavy-spot angle (rad).
        phase: f64 = "float64",
    }
);

ros_message!(
    /// A measured shaft displacement at a probe station (m).
    ProbeDisplacement, "ProbeDisplacement.msg" {
        /// Time of the measurement.
        header: Header = "std_msgs/Header",
        /// Station name.
        station: String = "string",
        /// Displacement along x (m).
        x: f64 = "float64",
        /// Displacement along y (m).
        y: f64 = "float64",
    }
);

ros_message!(
    /// A journal's predicted state (m, m/s, rad).
    JournalState, "JournalState.msg" {
        /// Simulation time; frame: the bearing.
        header: Header = "std_msgs/Header",
        /// Bearing name.
        bearing: String = "string",
        /// Journal centre x (m).
        x: f64 = "float64",
        /// Journal centre y (m).
        y: f64 = "float64",
        /// Velocity x (m/s).
        vx: f64 = "float64",
        /// Velocity y (m/s).
        vy: f64 = "float64",
        /// e/c.
        eccentricity_ratio: f64 = "float64",
        /// Angle of the journal centre (rad).
        attitude: f64 = "float64",
        /// Spin speed (rad/s).
        speed: f64 = "float64",
        /// Wall contact in this step.
        contact: bool = "bool",
    }
);

ros_message!(
    /// A bearing film's predicted state (N, Pa, rad, W).
    FilmState, "FilmState.msg" {
        /// Simulation time; frame: the bearing.
        header: Header = "std_msgs/Header",
        /// Bearing name.
        bearing: String = "string",
        /// Film force x (N).
        force_x: f64 = "float64",
        /// Film force y (N).
        force_y: f64 = "float64",
        /// Peak pressure (Pa).
        max_pressure: f64 = "float64",
        /// Its angle (rad).
        max_pressure_angle: f64 = "float64",
        /// ζ1 (rad).
        film_start: f64 = "float64",
        /// ζ2 (rad).
        film_end: f64 = "float64",
        /// Power loss (W).
        power_loss: f64 = "float64",
        /// Pressure-profile angles (rad).
        pressure_angles: Vec<f64> = "float64[]",
        /// Pressure profile (Pa).
        pressure: Vec<f64> = "float64[]",
    }
);

ros_message!(
    /// The last revolution's orbit (whole whirl loops, `session::orbit_revolutions`, when a
    /// sub-synchronous component is present) and spectral summary (m).
    Orbit, "Orbit.msg" {
        /// Simulation time; frame: the bearing.
        header: Header = "std_msgs/Header",
        /// Bearing name.
        bearing: String = "string",
        /// Revolution count.
        revolution: u64 = "uint64",
        /// Spin speed (rad/s).
        speed: f64 = "float64",
        /// Radial clearance (m).
        clearance: f64 = "float64",
        /// Orbit x (m).
        x: Vec<f64> = "float64[]",
        /// Orbit y (m).
        y: Vec<f64> = "float64[]",
        /// 1X semi-major axis (m).
        one_x_amplitude: f64 = "float64",
        /// Sub-synchronous order.
        subsync_ratio: f64 = "float64",
        /// Sub-synchronous semi-major axis (m).
        subsync_amplitude: f64 = "float64",
    }
);

ros_message!(
    /// An instability or health warning.
    InstabilityWarning, "InstabilityWarning.msg" {
        /// Time found; frame: the bearing or empty.
        header: Header = "std_msgs/Header",
        /// OK (0), WARN (1), ERROR (2).
        level: u8 = "uint8",
        /// none, whirl, whip, contact, stale_input, falling_behind, bad_input.
        kind: String = "string",
        /// Bearing concerned, or empty.
        bearing: String = "string",
        /// Sub-synchronous order.
        whirl_ratio: f64 = "float64",
        /// Largest amplitude over clearance.
        amplitude_over_clearance: f64 = "float64",
        /// The evidence in words.
        evidence: String = "string",
        /// Growth rate of the sub-synchronous amplitude (1/rev); 0 if not yet known.
        growth_per_rev: f64 = "float64",
        /// Predicted time to the alert level (s); −1 if not growing.
        time_to_alert: f64 = "float64",
        /// Orbit amplitude, half peak-to-peak (m).
        amplitude: f64 = "float64",
        /// Alert amplitude (m).
        alert_level: f64 = "float64",
        /// Danger amplitude (m).
        danger_level: f64 = "float64",
        /// Basis of the two levels.
        alarm_basis: String = "string",
        /// Wall contact in the last revolution.
        contact: bool = "bool",
        /// Contacts begun in the last revolution.
        contact_count: u32 = "uint32",
        /// Largest penetration beyond the contact onset (m).
        max_penetration: f64 = "float64",
        /// Journal beyond the clearance without contact (model outside its validity).
        beyond_clearance: bool = "bool",
    }
);

impl InstabilityWarning {
    /// Level: all well.
    pub const OK: u8 = 0;
    /// Level: a warning.
    pub const WARN: u8 = 1;
    /// Level: an error.
    pub const ERROR: u8 = 2;
}

ros_message!(
    /// Distance from the linear stability threshold (rad/s).
    StabilityMargin, "StabilityMargin.msg" {
        /// Time of the estimate.
        header: Header = "std_msgs/Header",
        /// Present speed (rad/s).
        speed: f64 = "float64",
        /// A threshold was found.
        threshold_found: bool = "bool",
        /// Threshold speed (rad/s).
        threshold_speed: f64 = "float64",
        /// threshold − speed (rad/s).
        margin: f64 = "float64",
        /// Whirl ratio at the threshold.
        whirl_ratio: f64 = "float64",
    }
);

ros_message!(
    /// Predicted minus measured displacement at a probe station (m).
    OrbitResidual, "OrbitResidual.msg" {
        /// Time of the measurement.
        header: Header = "std_msgs/Header",
        /// Station name.
        station: String = "string",
        /// Predicted x (m).
        predicted_x: f64 = "float64",
        /// Predicted y (m).
        predicted_y: f64 = "float64",
        /// Measured x (m).
        measured_x: f64 = "float64",
        /// Measured y (m).
        measured_y: f64 = "float64",
        /// Residual x (m).
        residual_x: f64 = "float64",
        /// Residual y (m).
        residual_y: f64 = "float64",
    }
);

// --- plant signals (issue 12): keyphasor and raw proximity probes ---

ros_message!(
    /// A once-per-revolution keyphasor event: shaft angle 0 of the plant at the stamp.
    Keyphasor, "Keyphasor.msg" {
        /// Time of the event; frame: the keyphasor's name.
        header: Header = "std_msgs/Header",
        /// Revolution count kept by the sensor (0: none); not used.
        revolution: u32 = "uint32",
    }
);

ros_message!(
    /// One raw proximity-probe reading along the probe's own axis, in the probe's unit.
    ProbeSignal, "ProbeSignal.msg" {
        /// Time of the reading; frame: the probe.
        header: Header = "std_msgs/Header",
        /// Probe name (machine file's `proximity_probes`).
        probe: String = "string",
        /// Reading in the probe's unit (m, um, mil or V).
        value: f64 = "float64",
    }
);

ros_message!(
    /// The 1X vectors of one probe station over a block of whole revolutions, per probe axis,
    /// measured and predicted; phase lags from the keyphasor (API 670), empty when null.
    OneXVectors, "OneXVectors.msg" {
        /// Time of the block's last sample; frame: the station.
        header: Header = "std_msgs/Header",
        /// Probe station name.
        station: String = "string",
        /// Mean speed (rad/s).
        speed: f64 = "float64",
        /// Whole revolutions in the block.
        revolutions: u32 = "uint32",
        /// Probe samples in the block.
        samples: u32 = "uint32",
        /// Probe axis angles (rad).
        axis_angles: Vec<f64> = "float64[]",
        /// Measured 1X amplitudes (m).
        measured_amplitudes: Vec<f64> = "float64[]",
        /// Measured 1X phase lags (deg); empty when null.
        measured_phase_lags_deg: Vec<f64> = "float64[]",
        /// Predicted 1X amplitudes (m).
        predicted_amplitudes: Vec<f64> = "float64[]",
        /// Predicted 1X phase lags (deg); empty when null.
        predicted_phase_lags_deg: Vec<f64> = "float64[]",
        /// Predicted − measured phase lags (deg); empty when null.
        phase_lag_errors_deg: Vec<f64> = "float64[]",
        /// Why the phase lags are empty ('' when keyphasor-referenced).
        phase_null_reason: String = "string",
    }
);

ros_message!(
    /// The live calibration: viscosity from the mean positions, unbalance from the 1X vectors
    /// (see `msg/msg/CalibrationEstimate.msg`).
    CalibrationEstimate, "CalibrationEstimate.msg" {
        /// Time of the estimate.
        header: Header = "std_msgs/Header",
        /// 1X vectors used.
        vectors: u32 = "uint32",
        /// Mean positions used.
        positions: u32 = "uint32",
        /// The viscosity was fitted.
        viscosity_valid: bool = "bool",
        /// Why not.
        viscosity_reason: String = "string",
        /// µ / µ of the machine file.
        viscosity_scale: f64 = "float64",
        /// Its 1σ.
        viscosity_scale_std: f64 = "float64",
        /// Effective viscosity (Pa·s).
        viscosity: f64 = "float64",
        /// The law gives a temperature.
        temperature_valid: bool = "bool",
        /// Oil temperature (K).
        oil_temperature: f64 = "float64",
        /// Its 1σ (K).
        oil_temperature_std: f64 = "float64",
        /// Offset from the design supply temperature (K).
        temperature_offset: f64 = "float64",
        /// Position residual RMS (m).
        viscosity_residual: f64 = "float64",
        /// The unbalance was fitted.
        unbalance_valid: bool = "bool",
        /// Why not.
        unbalance_reason: String = "string",
        /// Node per plane.
        unbalance_nodes: Vec<u32> = "uint32[]",
        /// m·e per plane (kg·m).
        unbalance_magnitudes: Vec<f64> = "float64[]",
        /// Heavy-spot angle per plane (rad).
        unbalance_phases: Vec<f64> = "float64[]",
        /// Correction mass per plane (kg).
        correction_masses: Vec<f64> = "float64[]",
        /// Correction angle per plane (rad).
        correction_angles: Vec<f64> = "float64[]",
        /// Correction radius (m).
        correction_radius: f64 = "float64",
        /// 1X residual RMS (m).
        unbalance_residual: f64 = "float64",
        /// Relative 1X residual.
        unbalance_relative_residual: f64 = "float64",
        /// Condition number.
        condition_number: f64 = "float64",
        /// In force in the running twin.
        applied: bool = "bool",
    }
);
// --- end plant signals ---

// --- forecast (issue 14) ---

ros_message!(
    /// The twin's look-ahead from a checkpoint of its present state (see `msg/msg/Forecast.msg`).
    Forecast, "Forecast.msg" {
        /// Time of the checkpoint the forecast starts from.
        header: Header = "std_msgs/Header",
        /// Look-ahead horizon (s).
        horizon: f64 = "float64",
        /// Speed at the checkpoint (rad/s).
        speed: f64 = "float64",
        /// Acceleration at the checkpoint (rad/s²).
        acceleration: f64 = "float64",
        /// Expected state at the end of the expected path.
        expected_state: String = "string",
        /// Time to a persisting whirl or whip on the expected path (s); −1 if none.
        time_to_onset: f64 = "float64",
        /// Time to a persisting whip on the expected path (s); −1 if none.
        time_to_whip: f64 = "float64",
        /// Largest orbit amplitude on the expected path (m).
        amplitude: f64 = "float64",
        /// Speeds of the constant-speed runs (rad/s).
        speeds: Vec<f64> = "float64[]",
        /// State at the end of each run.
        states: Vec<String> = "string[]",
        /// Time to onset per run (s); −1 if none.
        onset_times: Vec<f64> = "float64[]",
        /// Time to whip per run (s); −1 if none.
        whip_times: Vec<f64> = "float64[]",
        /// Largest amplitude per run (m).
        amplitudes: Vec<f64> = "float64[]",
        /// A constant-speed run went into whip.
        nonlinear_threshold_found: bool = "bool",
        /// Lowest speed going into whip within the horizon (rad/s).
        nonlinear_threshold_speed: f64 = "float64",
        /// Width of its bracket (rad/s).
        nonlinear_threshold_resolution: f64 = "float64",
        /// Nonlinear threshold − speed (rad/s).
        nonlinear_margin: f64 = "float64",
        /// The linear threshold is known.
        linear_threshold_found: bool = "bool",
        /// Linear threshold (rad/s).
        linear_threshold_speed: f64 = "float64",
        /// Linear threshold − speed (rad/s).
        linear_margin: f64 = "float64",
        /// Wall time of the computation (s).
        compute_duration: f64 = "float64",
    }
);
// --- end forecast ---

/// CDR (XCDR1, little endian) payload with its 4-byte encapsulation header `00 01 00 00`: what
/// DDS puts on the wire and rosbag2 stores.
pub fn to_cdr<T: Serialize>(message: &T) -> Result<Vec<u8>, String> {
    let body =
        cdr_encoding::to_vec::<T, byteorder::LittleEndian>(message).map_err(|e| e.to_string())?;
    let mut out = Vec::with_capacity(body.len() + 4);
    out.extend_from_slice(&[0x00, 0x01, 0x00, 0x00]);
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decodes a CDR payload with its encapsulation header (little or big endian).
pub fn from_cdr<T: for<'de> Deserialize<'de>>(bytes: &[u8]) -> Result<T, String> {
    if bytes.len() < 4 {
        return Err(format!(
            "CDR payload of {} bytes has no encapsulation header",
            bytes.len()
        ));
    }
    let body = &bytes[4..];
    let (value, _) = match bytes[1] {
        0x01 => cdr_encoding::from_bytes::<T, byteorder::LittleEndian>(body),
        0x00 => cdr_encoding::from_bytes::<T, byteorder::BigEndian>(body),
        other => return Err(format!("unsupported CDR representation 0x{other:02x}")),
    }
    .map_err(|e| e.to_string())?;
    Ok(value)
}
