//! The live node: ROS 2 in and out through ros2-client (RustDDS), the twin on its own thread at
//! real-time pace, every input and output recorded to MCAP. Only this module opens DDS.
//!
//! Topics (names remappable with `-r from:=to`; QoS stated per topic):
//! - in  `/rotor_twin/speed` rotor_twin_msgs/RotorSpeed, or std_msgs/Float64 with `speed_type:=float64`
//!   (unit `speed_unit`), best effort (matches best-effort and reliable publishers);
//! - in  `/rotor_twin/unbalance` rotor_twin_msgs/Unbalance, reliable;
//! - in  `/rotor_twin/probe` rotor_twin_msgs/ProbeDisplacement (m), best effort;
//!   out `/rotor_twin/residual` OrbitResidual: predicted minus measured at that station;
//! - in  `/rotor_twin/oil_temperature` sensor_msgs/Temperature (°C), best effort: the films' viscosity
//!   through the machine file's viscosity–temperature law (issue 12);
//! - out `/rotor_twin/journal_state` JournalState and `/rotor_twin/film_state` FilmState, reliable,
//!   keep last 10, at `state_rate_hz`; `/rotor_twin/orbit` Orbit per revolution, reliable, keep
//!   last 10, and `/rotor_twin/orbit/<bearing>` (each bearing's, ≤ 50 Hz, for viewers:
//!   [`crate::viewer`]); `/rotor_twin/warning` InstabilityWarning, reliable, transient local, keep last 1
//!   (a late subscriber sees the last one); `/diagnostics` diagnostic_msgs/DiagnosticArray, 1 Hz;
//!   the journal and film states, orbits and residuals only while a reader is matched (all of
//!   them when recording: [`model::Audience`]);
//!
//! Every QoS is in [`crate::topics`]. The subscriptions only decode and queue, stamped with the
//! receive time on the node's clock; the model thread feeds the queue to the shared
//! [`crate::driver::Driver`], which checks and applies each input.
//! - in  `/clock` rosgraph_msgs/Clock with `use_sim_time:=true`: the model is paced by it and its
//!   outputs are stamped in simulation time.

mod calibration;
mod forecast;
pub mod log;
pub mod loss;
pub mod model;
#[cfg(feature = "ros")]
mod node;
#[cfg(feature = "ros")]
mod param_client;
#[cfg(feature = "ros")]
mod param_services;
mod params;
#[cfg(feature = "ros")]
mod recording;

#[cfg(feature = "ros")]
pub use node::{run, NodeSetup, MAX_DOMAIN_ID};
#[cfg(feature = "ros")]
pub use param_client::{run as param_call, ParamCall};
pub use params::{
    parameter_doc, parse_ros_args, KeyphasorType, LogLevel, NodeParams, ParamDoc, RosArgs,
    SpeedType, SpeedUnit, PARAMETER_DOCS, RUNTIME_PARAMETERS,
};
