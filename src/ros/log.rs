//! The node's log lines: on stderr (`rotor_twin: …`) and, once the node is up, on `/rosout`
//! (rcl_interfaces/msg/Log) as rcl publishes them: logger name = the node's fully qualified name
//! without the leading slash and with dots for slashes (`line1.twin_a`), stamp = the system time
//! (rcutils' logging clock, also under `use_sim_time`), only lines at or above `--log-level`.

use super::params::LogLevel;
#[cfg(feature = "ros")]
use ros2_client::builtin_interfaces::Time;
#[cfg(feature = "ros")]
use ros2_client::rosout::{NodeLoggingHandle, RosoutRaw};
use std::sync::OnceLock;

#[cfg(feature = "ros")]
struct Rosout {
    handle: NodeLoggingHandle,
    logger: String,
}

#[cfg(feature = "ros")]
static ROSOUT: OnceLock<Rosout> = OnceLock::new();
static LEVEL: OnceLock<LogLevel> = OnceLock::new();

/// rcl's logger name of node `fqn` (`/line1/twin_a` → `line1.twin_a`).
pub fn logger_name(fqn: &str) -> String {
    fqn.trim_start_matches('/').replace('/', ".")
}

/// Sets the level (once, at start; later calls keep the first).
pub fn set_level(level: LogLevel) {
    let _ = LEVEL.set(level);
}

/// From now on log lines also go to `/rosout` through `handle` (once per process).
#[cfg(feature = "ros")]
pub fn to_rosout(handle: NodeLoggingHandle, fqn: &str) {
    let _ = ROSOUT.set(Rosout {
        handle,
        logger: logger_name(fqn),
    });
}

/// Whether lines at `level` are shown.
pub fn enabled(level: LogLevel) -> bool {
    level >= *LEVEL.get().unwrap_or(&LogLevel::Info)
}

/// One log line at `level`: stderr, and `/rosout` when the node is up.
pub fn say(level: LogLevel, msg: &str) {
    if !enabled(level) {
        return;
    }
    match level {
        LogLevel::Debug | LogLevel::Info => eprintln!("rotor_twin: {msg}"),
        LogLevel::Warn => eprintln!("rotor_twin: WARN: {msg}"),
        LogLevel::Error | LogLevel::Fatal => eprintln!("rotor_twin: ERROR: {msg}"),
    }
    #[cfg(feature = "ros")]
    if let Some(r) = ROSOUT.get() {
        let ros_level = match level {
            LogLevel::Debug => ros2_client::ros2::LogLevel::Debug,
            LogLevel::Info => ros2_client::ros2::LogLevel::Info,
            LogLevel::Warn => ros2_client::ros2::LogLevel::Warn,
            LogLevel::Error => ros2_client::ros2::LogLevel::Error,
            LogLevel::Fatal => ros2_client::ros2::LogLevel::Fatal,
        };
        r.handle.rosout_raw(
            Time::now(),
            ros_level,
            &r.logger,
            msg,
            file!(),
            "rotor_twin",
            line!(),
        );
    }
}

/// An INFO line.
pub fn info(msg: &str) {
    say(LogLevel::Info, msg)
}

/// A WARN line.
pub fn warn(msg: &str) {
    say(LogLevel::Warn, msg)
}

/// An ERROR line.
pub fn error(msg: &str) {
    say(LogLevel::Error, msg)
}

#[cfg(test)]
mod tests {
    #[test]
    fn logger_names_as_rcl() {
        // rcl_node_get_logger_name: namespace and name joined by dots, no leading separator
        assert_eq!(super::logger_name("/rotor_twin"), "rotor_twin");
        assert_eq!(super::logger_name("/line1/twin_a"), "line1.twin_a");
    }
}
