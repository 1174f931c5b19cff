//! The twin's topics and their QoS: one table for the node, its recording and the replay's
//! output bag.

use crate::record::TopicQos;

/// Rotor speed in (rotor_twin_msgs/RotorSpeed, or std_msgs/Float64 in a stated unit).
pub const SPEED: &str = "/rotor_twin/speed";
/// Residual unbalance in (rotor_twin_msgs/Unbalance).
pub const UNBALANCE: &str = "/rotor_twin/unbalance";
/// Oil supply temperature in (sensor_msgs/Temperature, °C), best effort (a sensor).
pub const OIL_TEMPERATURE: &str = "/rotor_twin/oil_temperature";
/// Measured probe displacements in (rotor_twin_msgs/ProbeDisplacement).
pub const PROBE: &str = "/rotor_twin/probe";
// --- plant signals (issue 12) ---
/// Keyphasor events in (rotor_twin_msgs/Keyphasor, or std_msgs/Header by remap): best effort,
/// [`SENSOR_READER`].
pub const KEYPHASOR: &str = "/rotor_twin/keyphasor";
/// Raw proximity-probe readings in (rotor_twin_msgs/ProbeSignal; std_msgs/Float64 topics per
/// probe by the `probe_signal_topics` mapping): best effort, [`SENSOR_READER`].
pub const PROBE_SIGNAL: &str = "/rotor_twin/probe_signal";
/// The 1X vectors and phase lags per probe axis, per block of revolutions
/// (rotor_twin_msgs/OneXVectors), out: [`STATE`].
pub const ONE_X: &str = "/rotor_twin/one_x";
/// The live calibration estimate (rotor_twin_msgs/CalibrationEstimate), out: latched, keep last
/// 1 ([`CALIBRATION_QOS`]).
pub const CALIBRATION: &str = "/rotor_twin/calibration";
// --- end plant signals ---
/// Predicted minus measured at a probe station, out.
pub const RESIDUAL: &str = "/rotor_twin/residual";
/// Distance from the linear stability threshold, out.
pub const MARGIN: &str = "/rotor_twin/stability_margin";
/// The twin's look-ahead (rotor_twin_msgs/Forecast), out (issue 14).
pub const FORECAST: &str = "/rotor_twin/forecast";
/// Journal state of each bearing, out.
pub const JOURNAL: &str = "/rotor_twin/journal_state";
/// Film state of each bearing, out.
pub const FILM: &str = "/rotor_twin/film_state";
/// The orbit of each bearing, every revolution (both bearings on one topic), out: whole whirl
/// periods when a sub-synchronous component is present (see `session`).
pub const ORBIT: &str = "/rotor_twin/orbit";
/// Highest rate of a viewer's topics (Hz): the per-bearing orbit topics keep one orbit in every
/// 1/`VIEWER_MAX_HZ` s of model time per bearing. Foxglove and Lichtblick warn about "High
/// frequency topics" above 60 Hz (`FREQUENCY_LIMIT` in Lichtblick's players/utils/constants.ts);
/// 50 Hz leaves room for jitter of the stamps.
pub const VIEWER_MAX_HZ: f64 = 50.0;

/// The orbit topic of one bearing, for viewers: `/rotor_twin/orbit/<bearing>` (in the node's
/// namespace like the twin's other topics), the same Orbit messages as [`ORBIT`] for that bearing,
/// at most [`VIEWER_MAX_HZ`]. A character a ROS 2 name token does not allow (not a letter, digit
/// or `_`) becomes `_`, and a leading digit gets a `_` before it.
pub fn bearing_orbit(bearing: &str) -> String {
    let mut token: String = bearing
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if token.is_empty() || token.starts_with(|c: char| c.is_ascii_digit()) {
        token.insert(0, '_');
    }
    format!("{ORBIT}/{token}")
}
/// Instability and input warnings, out.
pub const WARNING: &str = "/rotor_twin/warning";
/// diagnostic_msgs/DiagnosticArray, out.
pub const DIAGNOSTICS: &str = "/diagnostics";
/// rosgraph_msgs/Clock, in with use_sim_time.
pub const CLOCK: &str = "/clock";

/// QoS the node's sensor subscriptions ask for (speed, probes): best effort, so that a
/// best-effort sensor publisher (REP 2003 SensorDataQoS, what drivers use) is matched as well as
/// a reliable one; a deep history (20,000 samples) because RustDDS drops unread samples beyond
/// it silently, and a burst of 10,000 messages must not lose any.
pub const SENSOR_READER: TopicQos = TopicQos::sensor(20_000);

/// QoS of the unbalance subscription: reliable (a setting, sent rarely, that must arrive), with
/// the same deep history.
pub const COMMAND_READER: TopicQos = TopicQos::reliable(20_000);

/// QoS recorded for every input topic (what `ros2 bag play` then offers): reliable, keep last
/// 100, which every reader matches.
pub const INPUT_RECORDED: TopicQos = TopicQos::reliable(100);

/// QoS of the streamed outputs (journal and film states, orbits, residuals, diagnostics):
/// reliable, keep last 10.
pub const STATE: TopicQos = TopicQos::reliable(10);

/// QoS of the warning topic: reliable, transient local, keep last 1, so that a late subscriber
/// sees the warning in force.
pub const WARNING_QOS: TopicQos = TopicQos::latched(1);

/// QoS of the stability margin: latched, keep last 1.
pub const MARGIN_QOS: TopicQos = TopicQos::latched(1);

/// QoS of the /clock subscription: best effort, keep last 10 (as rclcpp's clock subscription).
pub const CLOCK_READER: TopicQos = TopicQos::sensor(10);

/// QoS of the calibration estimate: latched, keep last 1 (a late subscriber gets the last).
pub const CALIBRATION_QOS: TopicQos = TopicQos::latched(1);

/// QoS of the forecast: latched, keep last 1 (a late subscriber gets the last look-ahead).
pub const FORECAST_QOS: TopicQos = TopicQos::latched(1);
