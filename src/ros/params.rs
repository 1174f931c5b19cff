//! Node parameters and the ROS 2 command-line conventions (`--ros-args -p name:=value
//! --params-file F.yaml -r from:=to`), which ros2-client leaves to the node.

use std::collections::BTreeMap;
use std::path::Path;

pub use crate::driver::SpeedUnit;
use crate::driver::{film_name, parse_film, settings as defaults, ModelKind};
use crate::dynamics::FilmEvaluation;
use std::fmt;
use std::str::FromStr;

/// The type of the speed topic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpeedType {
    /// rotor_twin_msgs/RotorSpeed (rad/s, rad/s², stamped).
    #[default]
    RotorSpeed,
    /// std_msgs/Float64, a bare value in `speed_unit`.
    Float64,
}

impl FromStr for SpeedType {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "rotor_speed" => Ok(SpeedType::RotorSpeed),
            "float64" => Ok(SpeedType::Float64),
            other => Err(format!("'{other}' must be rotor_speed or float64")),
        }
    }
}

impl fmt::Display for SpeedType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SpeedType::RotorSpeed => "rotor_speed",
            SpeedType::Float64 => "float64",
        })
    }
}

/// The type of the keyphasor topic (issue 12).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KeyphasorType {
    /// rotor_twin_msgs/Keyphasor (stamped event, revolution count).
    #[default]
    Keyphasor,
    /// std_msgs/Header: its stamp is the event.
    Header,
}

impl FromStr for KeyphasorType {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "keyphasor" => Ok(KeyphasorType::Keyphasor),
            "header" => Ok(KeyphasorType::Header),
            other => Err(format!("'{other}' must be keyphasor or header")),
        }
    }
}

impl fmt::Display for KeyphasorType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            KeyphasorType::Keyphasor => "keyphasor",
            KeyphasorType::Header => "header",
        })
    }
}

/// `name=/topic,…` pairs of a topic-mapping parameter (`probe_point_topics`,
/// `probe_signal_topics`): each topic absolute.
fn topic_pairs(parameter: &str, value: &str) -> Result<Vec<(String, String)>, String> {
    let mut pairs = Vec::new();
    for item in value.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let option = format!("parameter {parameter}");
        let (name, topic) = item
            .split_once('=')
            .ok_or_else(|| format!("{option}: {} must be name=topic", crate::rotor::shown(item)))?;
        let (name, topic) = (name.trim(), topic.trim());
        crate::rotor::mapping_name(&option, name)?;
        if !topic.starts_with('/') {
            let topic = crate::rotor::shown(topic);
            return Err(format!("{option}: topic {topic} must be absolute (/…)"));
        }
        if pairs.iter().any(|(n, _): &(String, String)| n == name) {
            let name = crate::rotor::shown(name);
            return Err(format!("{option}: name {name} is given twice"));
        }
        pairs.push((name.to_string(), topic.to_string()));
    }
    Ok(pairs)
}

/// The node's parameters (ROS 2 parameters; set with `-p name:=value` or a params file).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeParams {
    /// `model`: linear | nonlinear | prehistory.
    pub model: ModelKind,
    /// `delta`: prehistory relaxation factor δ in (0, 1].
    pub delta: f64,
    /// `film`: table (the finite-length solutions tabulated and interpolated, fast enough for
    /// real time) | direct (the finite solver at every evaluation, the reference).
    pub film: FilmEvaluation,
    /// `steps_per_rev`: time steps per revolution at rated speed.
    pub steps_per_rev: usize,
    /// `state_rate_hz`: rate of journal and film states (Hz), decimated from the step rate.
    pub state_rate_hz: f64,
    /// `pressure_map_rate_hz`: rate of the pressure profile in the film state (Hz).
    pub pressure_map_rate_hz: f64,
    /// `input_timeout_s`: a speed older than this is stale (s).
    pub input_timeout_s: f64,
    /// `min_speed_rpm`: below this speed the model pauses (rpm).
    pub min_speed_rpm: f64,
    /// `speed_type`: rotor_speed (rotor_twin_msgs/RotorSpeed) | float64 (std_msgs/Float64).
    pub speed_type: SpeedType,
    /// `speed_unit`: rpm | rad_s | hz, for `speed_type` float64.
    pub speed_unit: SpeedUnit,
    /// `use_sim_time`: follow `/clock` (rosgraph_msgs/Clock) instead of the wall clock.
    pub use_sim_time: bool,
    /// `warning_amplitude_ratio`: orbit amplitude over clearance that raises a warning.
    pub warning_amplitude_ratio: f64,
    /// `probe_point_topics`: probe pairs as geometry_msgs/PointStamped, `station=topic,…`.
    pub probe_point_topics: Vec<(String, String)>,
    /// `film_cache`: read and store the film tables in the cache directory (false: build them
    /// at every start).
    pub film_cache: bool,
    /// `film_cache_dir`: the film-table cache directory; empty for the command line's (its
    /// `--film-cache-dir`, else $ROTOR_TWIN_CACHE_DIR, $XDG_CACHE_HOME/rotor-twin,
    /// ~/.cache/rotor-twin).
    pub film_cache_dir: String,
    /// `forecast_period_s`: model time between forecasts (s); 0 (the default): no forecast. A
    /// forecast takes about one core for a second per run (see the README's "Forecast").
    pub forecast_period_s: f64,
    /// `forecast_horizon_s`: how far a forecast looks ahead (s).
    pub forecast_horizon_s: f64,
    /// `forecast_offsets_rpm`: constant speeds a forecast probes above the present one (rpm,
    /// ascending, comma separated; empty: the expected path only, no margin).
    pub forecast_offsets_rpm: Vec<f64>,
    /// `keyphasor_type`: keyphasor (rotor_twin_msgs/Keyphasor) | header (std_msgs/Header, its
    /// stamp the event), on `/rotor_twin/keyphasor` (remap it to the plant's topic).
    pub keyphasor_type: KeyphasorType,
    /// `probe_signal_topics`: raw probe readings as std_msgs/Float64, one topic per probe of
    /// the machine file's `proximity_probes`, `probe=topic,…` (the reading in the probe's unit;
    /// no stamp: the receive time is its time).
    pub probe_signal_topics: Vec<(String, String)>,
    /// `calibration_period_s`: node-clock time between live calibration fits (s); 0 (the
    /// default): none. Each fit takes a core for a while (the README's "Calibration").
    pub calibration_period_s: f64,
    /// `calibration_apply`: apply each live estimate to the running twin (may change at run
    /// time; false takes the calibration back).
    pub calibration_apply: bool,
}

impl Default for NodeParams {
    /// The defaults of the driver and the session, where each is documented.
    fn default() -> Self {
        let session = crate::session::SessionSettings::default();
        Self {
            model: ModelKind::default(),
            delta: defaults::DEFAULT_DELTA,
            film: FilmEvaluation::Table,
            steps_per_rev: defaults::DEFAULT_STEPS_PER_REV,
            state_rate_hz: session.state_rate_hz,
            pressure_map_rate_hz: session.pressure_map_rate_hz,
            input_timeout_s: 1.0,
            min_speed_rpm: defaults::DEFAULT_MIN_SPEED_RPM,
            speed_type: SpeedType::default(),
            speed_unit: SpeedUnit::Rpm,
            use_sim_time: false,
            warning_amplitude_ratio: session.warning_amplitude_ratio,
            probe_point_topics: Vec::new(),
            film_cache: true,
            film_cache_dir: String::new(),
            forecast_period_s: 0.0,
            forecast_horizon_s: crate::forecast::DEFAULT_HORIZON_S,
            forecast_offsets_rpm: crate::forecast::DEFAULT_OFFSETS_RPM.to_vec(),
            keyphasor_type: KeyphasorType::default(),
            probe_signal_topics: Vec::new(),
            calibration_period_s: 0.0,
            calibration_apply: false,
        }
    }
}

impl NodeParams {
    /// Sets one parameter from its text value; the error names the parameter, the value and
    /// the rule.
    pub fn set(&mut self, name: &str, value: &str) -> Result<(), String> {
        let num = |v: &str| -> Result<f64, String> {
            v.trim()
                .parse::<f64>()
                .map_err(|_| format!("parameter {name}: '{v}' is not a number"))
        };
        let positive = |v: f64, rule: &str| -> Result<f64, String> {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(format!("parameter {name}: {v} {rule}"))
            }
        };
        match name {
            "model" => self.model = value.parse().map_err(|e| format!("parameter model: {e}"))?,
            "film" => self.film = parse_film(value).map_err(|e| format!("parameter film: {e}"))?,
            "delta" => {
                let d = num(value)?;
                if !(d > 0.0 && d <= 1.0) {
                    return Err(format!("parameter delta: {d} must lie in (0, 1]"));
                }
                self.delta = d;
            }
            "steps_per_rev" => {
                let s: usize = value.trim().parse().map_err(|_| {
                    format!("parameter steps_per_rev: '{value}' is not a whole number")
                })?;
                if !(16..=4096).contains(&s) {
                    return Err(format!("parameter steps_per_rev: {s} must be 16 to 4096"));
                }
                self.steps_per_rev = s;
            }
            "state_rate_hz" => {
                self.state_rate_hz = positive(num(value)?, "must be a rate above zero")?
            }
            "pressure_map_rate_hz" => {
                self.pressure_map_rate_hz = positive(num(value)?, "must be a rate above zero")?
            }
            "input_timeout_s" => {
                self.input_timeout_s = positive(num(value)?, "must be a time above zero")?
            }
            "min_speed_rpm" => {
                self.min_speed_rpm = positive(num(value)?, "must be a speed above zero")?
            }
            "warning_amplitude_ratio" => {
                self.warning_amplitude_ratio = positive(num(value)?, "must be above zero")?
            }
            "probe_point_topics" => self.probe_point_topics = topic_pairs(name, value)?,
            "speed_type" => {
                self.speed_type = value
                    .parse()
                    .map_err(|e| format!("parameter speed_type: {e}"))?
            }
            "speed_unit" => {
                self.speed_unit = value
                    .parse()
                    .map_err(|e| format!("parameter speed_unit: {e}"))?
            }
            "use_sim_time" => self.use_sim_time = boolean(name, value)?,
            "film_cache" => self.film_cache = boolean(name, value)?,
            "film_cache_dir" => self.film_cache_dir = value.trim().to_string(),
            // the forecast's, or unknown
            _ => return self.set_forecast(name, value),
        }
        Ok(())
    }
}

impl NodeParams {
    /// Sets one of the forecast's parameters (issue 14) from its text value; any other name is
    /// unknown.
    fn set_forecast(&mut self, name: &str, value: &str) -> Result<(), String> {
        let num = |v: &str| -> Result<f64, String> {
            v.trim()
                .parse::<f64>()
                .map_err(|_| format!("parameter {name}: '{v}' is not a number"))
        };
        match name {
            "forecast_period_s" => {
                let p = num(value)?;
                if !(p.is_finite() && (p == 0.0 || p >= crate::forecast::MIN_PERIOD_S)) {
                    return Err(format!(
                        "parameter forecast_period_s: {p} must be 0 (off) or at least {} s",
                        crate::forecast::MIN_PERIOD_S
                    ));
                }
                self.forecast_period_s = p;
            }
            "forecast_horizon_s" => {
                let h = num(value)?;
                if !(h.is_finite() && h > 0.0 && h <= 60.0) {
                    return Err(format!(
                        "parameter forecast_horizon_s: {h} must be above 0 and at most 60"
                    ));
                }
                self.forecast_horizon_s = h
            }
            "forecast_offsets_rpm" => {
                let offsets = value
                    .split(',')
                    .map(str::trim)
                    .filter(|v| !v.is_empty())
                    .map(num)
                    .collect::<Result<Vec<f64>, String>>()?;
                crate::forecast::ForecastSettings {
                    offsets_rpm: offsets.clone(),
                    ..Default::default()
                }
                .check()
                .map_err(|e| format!("parameter forecast_offsets_rpm: {e}"))?;
                self.forecast_offsets_rpm = offsets;
            }
            _ => return self.set_plant_signals(name, value),
        }
        Ok(())
    }

    /// Sets one of the plant-signal parameters (issue 12); any other name is unknown.
    fn set_plant_signals(&mut self, name: &str, value: &str) -> Result<(), String> {
        match name {
            "keyphasor_type" => {
                self.keyphasor_type = value
                    .parse()
                    .map_err(|e| format!("parameter keyphasor_type: {e}"))?
            }
            "probe_signal_topics" => self.probe_signal_topics = topic_pairs(name, value)?,
            "calibration_period_s" => {
                let p: f64 = value.trim().parse().map_err(|_| {
                    format!("parameter calibration_period_s: '{value}' is not a number")
                })?;
                if !(p == 0.0 || (p.is_finite() && p >= MIN_CALIBRATION_PERIOD_S)) {
                    return Err(format!(
                        "parameter calibration_period_s: {p} must be 0 (off) or at least {MIN_CALIBRATION_PERIOD_S} s"
                    ));
                }
                self.calibration_period_s = p;
            }
            "calibration_apply" => self.calibration_apply = boolean(name, value)?,
            _ => return Err(format!("unknown parameter '{name}'")),
        }
        Ok(())
    }
}

/// A boolean parameter's value.
fn boolean(name: &str, value: &str) -> Result<bool, String> {
    match value.trim() {
        "true" | "True" | "1" => Ok(true),
        "false" | "False" | "0" => Ok(false),
        _ => Err(format!("parameter {name}: '{value}' must be true or false")),
    }
}

/// Shortest period of the live calibration (s): 1 s, the diagnostics' rate (a fit takes a
/// fraction of a second to seconds).
pub const MIN_CALIBRATION_PERIOD_S: f64 = 1.0;

/// Parameters that may change while the node runs (`ros2 param set`); the others shape the model
/// or its subscriptions and are set at start only.
pub const RUNTIME_PARAMETERS: &[&str] = &[
    "state_rate_hz",
    "pressure_map_rate_hz",
    "input_timeout_s",
    "min_speed_rpm",
    "warning_amplitude_ratio",
    "calibration_apply",
];

impl NodeParams {
    /// A change at run time: refused for start-only parameters and for bad values (the message
    /// names the parameter and the rule), else applied.
    pub fn set_at_runtime(&mut self, name: &str, value: &str) -> Result<(), String> {
        let mut next = self.clone();
        next.set(name, value)?;
        // a start-only parameter may be "set" to the value it has (as at declaration)
        if !RUNTIME_PARAMETERS.contains(&name) && next != *self {
            return Err(format!(
                "parameter {name} can only be set at start (restart the node with -p {name}:=…)"
            ));
        }
        *self = next;
        Ok(())
    }
}

/// What `--ros-args` said.
#[derive(Debug, Clone, PartialEq)]
pub struct RosArgs {
    /// Parameters in order of appearance (files first, then -p).
    pub params: Vec<(String, String)>,
    /// Topic remappings from → to, as given (expanded against the namespace when used).
    pub remaps: BTreeMap<String, String>,
    /// Node name (`-r __node:=NAME`, as launch_ros passes it); default `rotor_twin`.
    pub node_name: String,
    /// Node namespace (`-r __ns:=/NS`); default `/`.
    pub namespace: String,
    /// `--log-level` (debug, info, warn, error, fatal); default info.
    pub log_level: LogLevel,
    /// rcl arguments accepted but without effect here, as given (each noted at start).
    pub ignored: Vec<String>,
}

impl Default for RosArgs {
    fn default() -> Self {
        Self {
            params: Vec::new(),
            remaps: BTreeMap::new(),
            node_name: "rotor_twin".into(),
            namespace: "/".into(),
            log_level: LogLevel::Info,
            ignored: Vec::new(),
        }
    }
}

/// Severity of the node's own log lines (rcutils' levels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum LogLevel {
    /// Everything.
    Debug,
    /// Start-up and shutdown notes (the default).
    Info,
    /// Only what went wrong or may have.
    Warn,
    /// Only errors.
    Error,
    /// Only fatal errors.
    Fatal,
}

impl FromStr for LogLevel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        // `--log-level NAME:=LEVEL` sets one logger's level: ours when NAME is the node
        let level = s.rsplit_once(":=").map_or(s, |(_, l)| l);
        match level.trim().to_ascii_lowercase().as_str() {
            "debug" => Ok(LogLevel::Debug),
            "info" => Ok(LogLevel::Info),
            "warn" => Ok(LogLevel::Warn),
            "error" => Ok(LogLevel::Error),
            "fatal" => Ok(LogLevel::Fatal),
            _ => Err(format!(
                "--log-level '{s}': must be debug, info, warn, error or fatal"
            )),
        }
    }
}

impl RosArgs {
    /// The node's fully qualified name, e.g. `/line1/twin_a`.
    pub fn fully_qualified_name(&self) -> String {
        if self.namespace == "/" {
            format!("/{}", self.node_name)
        } else {
            format!("{}/{}", self.namespace, self.node_name)
        }
    }

    /// A topic name expanded as rcl does (a relative name is put in the node's namespace, `~/`
    /// in the node's own), then remapped: a rule applies when its `from`, expanded the same
    /// way, is the expanded name.
    pub fn topic(&self, name: &str) -> String {
        let expanded = self.expand(name);
        self.remaps
            .iter()
            .filter(|(from, _)| !from.starts_with("__"))
            .find(|(from, _)| self.expand(from) == expanded)
            .map_or(expanded, |(_, to)| self.expand(to))
    }

    fn expand(&self, name: &str) -> String {
        let ns = self.namespace.trim_end_matches('/');
        if name.starts_with('/') {
            name.to_string()
        } else if let Some(private) = name.strip_prefix("~/") {
            format!("{}/{private}", self.fully_qualified_name())
        } else {
            format!("{ns}/{name}")
        }
    }
}

/// rcl arguments that take a value and have no effect on this node.
const IGNORED_WITH_VALUE: &[&str] = &["--enclave", "-e", "--log-config-file", "--log-file-name"];
/// rcl flags without a value that have no effect on this node.
const IGNORED_FLAGS: &[&str] = &[
    "--enable-rosout-logs",
    "--disable-rosout-logs",
    "--enable-stdout-logs",
    "--disable-stdout-logs",
    "--enable-external-lib-logs",
    "--disable-external-lib-logs",
];

/// Checks a node name or namespace set by `-r __node:=` / `-r __ns:=`.
fn check_name(kind: &str, value: &str) -> Result<(), String> {
    let ok = |part: &str| {
        part.chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && part.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
    };
    let good = match kind {
        "__node" => ok(value),
        _ => value == "/" || (value.starts_with('/') && value[1..].split('/').all(ok)),
    };
    if good {
        Ok(())
    } else {
        Err(format!("-r {kind}:={value}: not a valid ROS 2 name"))
    }
}

/// Parses the arguments after `--ros-args` (up to an optional `--`).
pub fn parse_ros_args(args: &[String]) -> Result<RosArgs, String> {
    let mut out = RosArgs::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |what: &str| it.next().ok_or(format!("{a} needs {what}")).cloned();
        match a.as_str() {
            "--" => break,
            "--ros-args" => {}
            "-p" | "--param" => {
                let kv = value("name:=value")?;
                let (k, v) = kv
                    .split_once(":=")
                    .ok_or_else(|| format!("-p {kv}: expected name:=value"))?;
                out.params.push((k.to_string(), v.to_string()));
            }
            "-r" | "--remap" => {
                let kv = value("from:=to")?;
                let (k, v) = kv
                    .split_once(":=")
                    .ok_or_else(|| format!("-r {kv}: expected from:=to"))?;
                // `node:__ns:=…` applies to one node; this process has one
                let k = k.rsplit_once(':').map_or(k, |(_, k)| k);
                match k {
                    "__node" | "__name" => {
                        check_name("__node", v)?;
                        out.node_name = v.to_string();
                    }
                    "__ns" => {
                        check_name("__ns", v)?;
                        out.namespace = v.to_string();
                    }
                    _ => {
                        out.remaps.insert(k.to_string(), v.to_string());
                    }
                }
            }
            "--params-file" => {
                let f = value("a file")?;
                out.params.extend(read_params_file(Path::new(&f))?);
            }
            "--log-level" => out.log_level = value("a level")?.parse()?,
            other if IGNORED_WITH_VALUE.contains(&other) => {
                let v = value("a value")?;
                out.ignored.push(format!("{other} {v}"));
            }
            other if IGNORED_FLAGS.contains(&other) => out.ignored.push(other.to_string()),
            other => {
                return Err(format!(
                    "unsupported ROS argument '{other}' (supported: -p, -r, --params-file, --log-level, and the rcl logging/enclave flags, which are accepted and ignored)"
                ))
            }
        }
    }
    Ok(out)
}

/// Largest params file accepted (bytes): a params file sets some dozens of parameters in a few
/// kB; this bound and the nesting bounds of [`crate::bag::check_yaml_shape`] are checked before
/// parsing (the YAML parser's time grows faster than the nesting, issue 15 item 19).
pub const MAX_PARAMS_FILE_BYTES: usize = 1 << 20;

/// Reads a ROS 2 params file: `<node or /**>: ros__parameters: {name: value}`.
fn read_params_file(path: &Path) -> Result<Vec<(String, String)>, String> {
    use std::io::Read;
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| {
            f.take(MAX_PARAMS_FILE_BYTES as u64 + 1)
                .read_to_string(&mut text)
        })
        .map_err(|e| format!("{}: {e}", path.display()))?;
    crate::bag::check_yaml_shape(&text, MAX_PARAMS_FILE_BYTES)
        .map_err(|rule| format!("params file {}: {rule}", path.display()))?;
    let doc: serde_yaml_ng::Value =
        serde_yaml_ng::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    let Some(map) = doc.as_mapping() else {
        return Err(format!(
            "{}: expected a mapping of node names",
            path.display()
        ));
    };
    for (node, body) in map {
        let node = node.as_str().unwrap_or("");
        if !matches!(node, "rotor_twin" | "/rotor_twin" | "/**") {
            continue;
        }
        let params = body
            .get("ros__parameters")
            .and_then(|p| p.as_mapping())
            .ok_or_else(|| format!("{}: {node} has no ros__parameters", path.display()))?;
        for (k, v) in params {
            let key = k
                .as_str()
                .ok_or_else(|| format!("{}: a parameter name is not text", path.display()))?;
            let value = match v {
                serde_yaml_ng::Value::String(s) => s.clone(),
                serde_yaml_ng::Value::Number(n) => n.to_string(),
                serde_yaml_ng::Value::Bool(b) => b.to_string(),
                other => {
                    return Err(format!(
                        "{}: parameter {key}: unsupported value {other:?}",
                        path.display()
                    ))
                }
            };
            out.push((key.to_string(), value));
        }
    }
    Ok(out)
}

impl NodeParams {
    /// The film evaluation's parameter text.
    pub fn film_text(&self) -> &'static str {
        film_name(self.film)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The forecast's parameters: defaults (off, 3 s, +0/100/250/500 rpm), good values taken,
    /// bad ones refused naming the parameter and the value; an unknown name stays unknown.
    #[test]
    fn forecast_parameters_are_checked() {
        let mut p = NodeParams::default();
        assert_eq!(p.forecast_period_s, 0.0);
        assert_eq!(p.forecast_horizon_s, 3.0);
        assert_eq!(p.forecast_offsets_rpm, vec![0.0, 100.0, 250.0, 500.0]);
        p.set("forecast_period_s", "2.5").unwrap();
        p.set("forecast_offsets_rpm", "0, 200").unwrap();
        p.set("forecast_horizon_s", "1.5").unwrap();
        assert_eq!(
            (
                p.forecast_period_s,
                p.forecast_horizon_s,
                p.forecast_offsets_rpm.clone()
            ),
            (2.5, 1.5, vec![0.0, 200.0])
        );
        let refused = |name: &str, value: &str| {
            let e = NodeParams::default().set(name, value).unwrap_err();
            assert!(e.contains(name) || e.contains(value), "{name}={value}: {e}");
        };
        refused("forecast_period_s", "-1");
        refused("forecast_period_s", "NaN");
        refused("forecast_horizon_s", "0");
        refused("forecast_horizon_s", "100");
        refused("forecast_offsets_rpm", "100,50");
        refused("forecast_offsets_rpm", "-10");
        refused("forecast_offsets_rpm", "x");
        assert!(NodeParams::default()
            .set("forecast_nonsense", "1")
            .unwrap_err()
            .contains("unknown parameter"));
    }

    #[test]
    fn ros_args_and_parameters() {
        let args: Vec<String> = [
            "-p",
            "model:=linear",
            "-r",
            "/rotor_twin/speed:=/plant/speed",
            "-p",
            "speed_unit:=hz",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let r = parse_ros_args(&args).unwrap();
        let mut p = NodeParams::default();
        for (k, v) in &r.params {
            p.set(k, v).unwrap();
        }
        assert_eq!(p.model, ModelKind::Linear);
        assert_eq!(p.speed_unit, SpeedUnit::Hz);
        assert_eq!(r.remaps["/rotor_twin/speed"], "/plant/speed");
        assert!(p.set("delta", "0").unwrap_err().contains("delta"));
        assert!(p
            .set("steps_per_rev", "3")
            .unwrap_err()
            .contains("steps_per_rev"));
        assert!(p.set("bogus", "1").unwrap_err().contains("bogus"));
        p.set(
            "probe_point_topics",
            "probe_outboard=/plant/probe_a, probe_pulley_end=/plant/probe_b",
        )
        .unwrap();
        assert_eq!(
            p.probe_point_topics[1],
            ("probe_pulley_end".to_string(), "/plant/probe_b".to_string())
        );
        assert!(p.set("probe_point_topics", "x:/a").is_err());
        // issue 15, item 13: duplicate, empty and megabyte names refused, the name shown cut
        // (a 1 MB name was echoed whole into the latched warning before)
        let twice = p.set("probe_point_topics", "a=/x, a=/y").unwrap_err();
        assert!(twice.contains("given twice"), "{twice}");
        let empty = p.set("probe_signal_topics", " =/x").unwrap_err();
        assert!(empty.contains("must not be empty"), "{empty}");
        let huge = format!("{}=/x", "n".repeat(1 << 20));
        let why = p.set("probe_point_topics", &huge).unwrap_err();
        assert!(
            why.contains("at most 64") && why.len() < 200,
            "{}",
            why.len()
        );
        assert!(p.set("probe_point_topics", &huge[1..]).is_err());
        // issue 12: the keyphasor as std_msgs/Header, raw probes as std_msgs/Float64 topics
        p.set("keyphasor_type", "header").unwrap();
        assert_eq!(p.keyphasor_type, KeyphasorType::Header);
        assert!(p
            .set("keyphasor_type", "bool")
            .unwrap_err()
            .contains("keyphasor_type"));
        p.set(
            "probe_signal_topics",
            "probe_outboard_x=/plant/px,probe_outboard_y=/plant/py",
        )
        .unwrap();
        assert_eq!(p.probe_signal_topics[1].1, "/plant/py");
        assert!(p
            .set("probe_signal_topics", "probe_outboard_x=plant/px")
            .unwrap_err()
            .contains("absolute"));
        p.set("calibration_period_s", "5").unwrap();
        assert!(p
            .set("calibration_period_s", "0.2")
            .unwrap_err()
            .contains("at least 1"));
        p.set_at_runtime("calibration_apply", "true").unwrap();
        assert!(p.calibration_apply);
        // at run time: rates and thresholds yes, the model no
        p.set_at_runtime("state_rate_hz", "50").unwrap();
        assert_eq!(p.state_rate_hz, 50.0);
        assert!(p
            .set_at_runtime("model", "nonlinear")
            .unwrap_err()
            .contains("only be set at start"));
        assert!(
            p.set_at_runtime("model", "linear").is_ok(),
            "its own value is accepted"
        );
        assert!(p.set_at_runtime("state_rate_hz", "-1").is_err());
        assert_eq!(p.state_rate_hz, 50.0, "a refused change leaves the value");
        assert!((SpeedUnit::Rpm.to_rad_s(9000.0) - 942.477_796).abs() < 1e-5);
    }

    fn args(list: &[&str]) -> Result<RosArgs, String> {
        parse_ros_args(&list.iter().map(|s| s.to_string()).collect::<Vec<_>>())
    }

    #[test]
    fn node_name_namespace_and_topic_names_as_rcl_expands_them() {
        let r = args(&["-r", "__node:=twin_a", "-r", "__ns:=/line1"]).unwrap();
        assert_eq!(r.fully_qualified_name(), "/line1/twin_a");
        // the twin's topics are relative: in the namespace; /diagnostics and /clock absolute
        assert_eq!(r.topic("rotor_twin/speed"), "/line1/rotor_twin/speed");
        assert_eq!(r.topic("/diagnostics"), "/diagnostics");
        assert_eq!(r.topic("~/state"), "/line1/twin_a/state");
        // remaps apply after expansion, their `from` expanded the same way
        let r = args(&[
            "-r",
            "__ns:=/line1",
            "-r",
            "rotor_twin/speed:=/plant/rpm",
            "-r",
            "/line1/rotor_twin/probe:=probes",
        ])
        .unwrap();
        assert_eq!(r.topic("rotor_twin/speed"), "/plant/rpm");
        assert_eq!(r.topic("rotor_twin/probe"), "/line1/probes");
        // without a namespace everything reads as before
        let r = args(&["-r", "/rotor_twin/speed:=/plant/rpm"]).unwrap();
        assert_eq!(r.topic("rotor_twin/speed"), "/plant/rpm");
        assert_eq!(r.topic("rotor_twin/orbit"), "/rotor_twin/orbit");
        assert!(
            args(&["-r", "__ns:=line1"]).is_err(),
            "a namespace is absolute"
        );
        assert!(args(&["-r", "__node:=9lives"]).is_err());
    }

    /// A params file's size and nesting are bounded before it is parsed (issue 15, item 19: 200
    /// kB of nesting took minutes); an endless file (/dev/zero) is read no further than the bound.
    #[test]
    fn params_files_are_bounded_before_parsing() {
        let dir = std::env::temp_dir().join(format!("rotor-twin-params-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let refusal = |name: &str, text: &str| {
            let f = dir.join(name);
            std::fs::write(&f, text).unwrap();
            args(&["--params-file", f.to_str().unwrap()]).unwrap_err()
        };
        let deep = format!(
            "rotor_twin: {}{}\n",
            "[".repeat(100_000),
            "]".repeat(100_000)
        );
        let e = refusal("deep.yaml", &deep);
        assert!(e.contains("params file") && e.contains("brackets"), "{e}");
        let e = refusal("big.yaml", &"a: 1\n".repeat(300_000));
        assert!(e.contains("bytes"), "{e}");
        let e = args(&["--params-file", "/dev/zero"]).unwrap_err();
        assert!(e.contains("bytes"), "{e}");
        let e = refusal("shape.yaml", "rotor_twin:\n  ros__parameters: [1, 2]\n");
        assert!(e.contains("no ros__parameters"), "{e}");
        let ok = dir.join("ok.yaml");
        std::fs::write(&ok, "/**:\n  ros__parameters:\n    model: linear\n").unwrap();
        let r = args(&["--params-file", ok.to_str().unwrap()]).unwrap();
        assert_eq!(
            r.params.iter().find(|(k, _)| k == "model").unwrap().1,
            "linear"
        );
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn other_rcl_arguments_are_accepted() {
        let r = args(&[
            "--log-level",
            "warn",
            "--enclave",
            "/secure",
            "--disable-rosout-logs",
        ])
        .unwrap();
        assert_eq!(r.log_level, LogLevel::Warn);
        assert_eq!(r.ignored, ["--enclave /secure", "--disable-rosout-logs"]);
        assert_eq!(
            args(&["--log-level", "rotor_twin:=DEBUG"])
                .unwrap()
                .log_level,
            LogLevel::Debug
        );
        assert!(args(&["--log-level", "loud"]).unwrap_err().contains("loud"));
        assert!(args(&["--bogus"]).unwrap_err().contains("--bogus"));
    }
}

/// A parameter's ROS 2 descriptor (rcl_interfaces/ParameterDescriptor): what `ros2 param
/// describe` shows. The rules themselves are checked in [`NodeParams::set`]; a range here is the
/// closed interval ROS 2 can express, the open end stated in `constraints`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamDoc {
    /// The parameter's name.
    pub name: &'static str,
    /// One line for a user, with the unit.
    pub description: &'static str,
    /// What the range cannot say (an open bound, a list of values, a format).
    pub constraints: &'static str,
    /// Closed numeric range (from, to), if any.
    pub range: Option<(f64, f64)>,
}

impl ParamDoc {
    /// True for parameters set at start only (`read_only` in the descriptor).
    pub fn read_only(&self) -> bool {
        !RUNTIME_PARAMETERS.contains(&self.name)
    }
}

const fn doc(
    name: &'static str,
    description: &'static str,
    constraints: &'static str,
    range: Option<(f64, f64)>,
) -> ParamDoc {
    ParamDoc {
        name,
        description,
        constraints,
        range,
    }
}

/// Every declared parameter's descriptor, in declaration order (one home: the node's parameter
/// services answer `describe_parameters` from it, and a test checks it covers every parameter).
pub const PARAMETER_DOCS: &[ParamDoc] = &[
    doc("model", "rotor-bearing model", "linear, nonlinear or prehistory", None),
    doc("delta", "prehistory relaxation factor δ", "above 0, at most 1", Some((0.0, 1.0))),
    doc("film", "film forces: table (tabulated finite-length solutions) or direct (the solver at every step)", "table or direct", None),
    doc("steps_per_rev", "time steps per revolution at rated speed", "whole number", Some((16.0, 4096.0))),
    doc("state_rate_hz", "rate of journal and film states (Hz)", "above 0", None),
    doc("pressure_map_rate_hz", "rate of the pressure profile in the film state (Hz)", "above 0", None),
    doc("input_timeout_s", "a speed older than this is stale (s)", "above 0", None),
    doc("min_speed_rpm", "below this speed the model pauses (rpm)", "above 0", None),
    doc("speed_type", "type of the speed topic", "rotor_speed (rotor_twin_msgs/RotorSpeed) or float64 (std_msgs/Float64)", None),
    doc("speed_unit", "unit of a std_msgs/Float64 speed", "rpm, rad_s or hz", None),
    doc("probe_point_topics", "probe pairs as geometry_msgs/PointStamped (m)", "station=topic, comma separated", None),
    doc("use_sim_time", "follow /clock (rosgraph_msgs/Clock) instead of the wall clock", "", None),
    doc("film_cache", "read and store the film tables in the cache directory", "", None),
    doc("film_cache_dir", "film-table cache directory; empty: the command line's or the default", "", None),
    doc("warning_amplitude_ratio", "orbit amplitude over clearance that raises a warning", "above 0", None),
    doc("forecast_period_s", "model time between forecasts (s); 0: no forecast", "0 or at least 0.1 s", None),
    doc("forecast_horizon_s", "how far a forecast looks ahead (s)", "above 0", Some((0.0, 60.0))),
    doc("forecast_offsets_rpm", "constant speeds a forecast probes above the present one (rpm)", "ascending, comma separated", None),
    doc("keyphasor_type", "type of the keyphasor topic", "keyphasor (rotor_twin_msgs/Keyphasor) or header (std_msgs/Header)", None),
    doc("probe_signal_topics", "raw probe readings as std_msgs/Float64, in the probe's unit", "probe=topic, comma separated", None),
    doc("calibration_period_s", "node-clock time between live calibration fits (s); 0: none", "0 or at least 1 s", None),
    doc("calibration_apply", "apply each live calibration estimate to the running twin", "", None),
];

/// The descriptor of parameter `name`, if it is one of the node's.
pub fn parameter_doc(name: &str) -> Option<&'static ParamDoc> {
    PARAMETER_DOCS.iter().find(|d| d.name == name)
}
