//! The standard ROS 2 message types rotor-twin reads and writes (std_msgs, geometry_msgs,
//! rosgraph_msgs, diagnostic_msgs), with their `.msg` texts for MCAP schemas.

use super::{Header, RosMessage, Time, HEADER_DEFINITION, TIME_DEFINITION};
use serde::{Deserialize, Serialize};

/// std_msgs/Float64: a plant bus's bare speed value (unit set by a node parameter).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Float64 {
    /// The value.
    pub data: f64,
}

impl RosMessage for Float64 {
    const TYPE_NAME: &'static str = "std_msgs/msg/Float64";
    const DEFINITION: &'static str = "float64 data\n";
    const DEPENDENCIES: &'static [(&'static str, &'static str)] = &[];
    const FIELDS: &'static [(&'static str, &'static str)] = &[("data", "float64")];
}

/// geometry_msgs/Point (m).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Point {
    /// x (m).
    pub x: f64,
    /// y (m).
    pub y: f64,
    /// z (m).
    pub z: f64,
}

const POINT_DEFINITION: &str = "float64 x\nfloat64 y\nfloat64 z\n";

/// geometry_msgs/PointStamped: a probe pair as a plant bus may carry it (x, y in m).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PointStamped {
    /// Time and frame.
    pub header: Header,
    /// The point (m).
    pub point: Point,
}

impl RosMessage for PointStamped {
    const TYPE_NAME: &'static str = "geometry_msgs/msg/PointStamped";
    const DEFINITION: &'static str = "std_msgs/Header header\nPoint point\n";
    const DEPENDENCIES: &'static [(&'static str, &'static str)] = &[
        ("std_msgs/Header", HEADER_DEFINITION),
        ("builtin_interfaces/Time", TIME_DEFINITION),
        ("geometry_msgs/Point", POINT_DEFINITION),
    ];
    const FIELDS: &'static [(&'static str, &'static str)] =
        &[("header", "std_msgs/Header"), ("point", "Point")];
}

/// rosgraph_msgs/Clock: simulation time on `/clock`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Clock {
    /// The time.
    pub clock: Time,
}

impl RosMessage for Clock {
    const TYPE_NAME: &'static str = "rosgraph_msgs/msg/Clock";
    const DEFINITION: &'static str = "builtin_interfaces/Time clock\n";
    const DEPENDENCIES: &'static [(&'static str, &'static str)] =
        &[("builtin_interfaces/Time", TIME_DEFINITION)];
    const FIELDS: &'static [(&'static str, &'static str)] = &[("clock", "builtin_interfaces/Time")];
}

/// diagnostic_msgs/KeyValue.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct KeyValue {
    /// Key.
    pub key: String,
    /// Value.
    pub value: String,
}

impl DiagnosticStatus {
    /// Level OK.
    pub const OK: u8 = 0;
    /// Level WARN.
    pub const WARN: u8 = 1;
    /// Level ERROR.
    pub const ERROR: u8 = 2;
    /// Level STALE.
    pub const STALE: u8 = 3;
}

/// diagnostic_msgs/DiagnosticStatus.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// OK 0, WARN 1, ERROR 2, STALE 3.
    pub level: u8,
    /// Component name.
    pub name: String,
    /// Summary.
    pub message: String,
    /// Hardware id.
    pub hardware_id: String,
    /// Figures.
    pub values: Vec<KeyValue>,
}

const STATUS_DEFINITION: &str = "byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\nbyte level\nstring name\nstring message\nstring hardware_id\nKeyValue[] values\n";
const KEY_VALUE_DEFINITION: &str = "string key\nstring value\n";

/// diagnostic_msgs/DiagnosticArray on `/diagnostics`.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct DiagnosticArray {
    /// Time.
    pub header: Header,
    /// Statuses.
    pub status: Vec<DiagnosticStatus>,
}

impl RosMessage for DiagnosticArray {
    const TYPE_NAME: &'static str = "diagnostic_msgs/msg/DiagnosticArray";
    const DEFINITION: &'static str = "std_msgs/Header header\nDiagnosticStatus[] status\n";
    const DEPENDENCIES: &'static [(&'static str, &'static str)] = &[
        ("std_msgs/Header", HEADER_DEFINITION),
        ("builtin_interfaces/Time", TIME_DEFINITION),
        ("diagnostic_msgs/DiagnosticStatus", STATUS_DEFINITION),
        ("diagnostic_msgs/KeyValue", KEY_VALUE_DEFINITION),
    ];
    const FIELDS: &'static [(&'static str, &'static str)] = &[
        ("header", "std_msgs/Header"),
        ("status", "DiagnosticStatus[]"),
    ];
}

// --- oil supply temperature (issue 12) ---

/// sensor_msgs/Temperature: the oil supply temperature (°C on the wire, as the type defines it).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Temperature {
    /// Time and frame.
    pub header: Header,
    /// Temperature (°C).
    pub temperature: f64,
    /// Variance (°C²); 0: unknown.
    pub variance: f64,
}

impl RosMessage for Temperature {
    const TYPE_NAME: &'static str = "sensor_msgs/msg/Temperature";
    const DEFINITION: &'static str =
        "std_msgs/Header header\nfloat64 temperature\nfloat64 variance\n";
    const DEPENDENCIES: &'static [(&'static str, &'static str)] = &[
        ("std_msgs/Header", HEADER_DEFINITION),
        ("builtin_interfaces/Time", TIME_DEFINITION),
    ];
    const FIELDS: &'static [(&'static str, &'static str)] = &[
        ("header", "std_msgs/Header"),
        ("temperature", "float64"),
        ("variance", "float64"),
    ];
}

// --- end oil supply temperature ---

// --- plant signals (issue 12) ---

/// std_msgs/Header as a message of its own: a keyphasor event from a plant bus that has no
/// keyphasor type (the stamp is the event; accepted by remap onto the keyphasor topic).
impl RosMessage for Header {
    const TYPE_NAME: &'static str = "std_msgs/msg/Header";
    const DEFINITION: &'static str = HEADER_DEFINITION;
    const DEPENDENCIES: &'static [(&'static str, &'static str)] =
        &[("builtin_interfaces/Time", TIME_DEFINITION)];
    const FIELDS: &'static [(&'static str, &'static str)] =
        &[("stamp", "builtin_interfaces/Time"), ("frame_id", "string")];
}
