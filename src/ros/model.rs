//! The model thread: the twin core at real-time pace (wall clock), fed by the latest valid inputs,
//! producing messages for the bus and the recording. It never runs on the async executor, and when
//! it falls behind it says so.

use super::params::NodeParams;
use crate::dynamics::{Coupling, FilmEvaluation, StepInput, TwinConfig};
use crate::messages::*;
use crate::rotor::Rotor;
pub use crate::session::Outgoing;
use crate::session::{warning, Session, SessionSettings};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::SyncSender;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// The latest accepted inputs, shared with the subscription side.
#[derive(Debug, Default)]
pub struct Inputs {
    /// Speed (rad/s), acceleration (rad/s²) and when it arrived.
    pub speed: Option<(f64, f64, Instant)>,
    /// Unbalance changes not yet applied: (plane, m·e kg·m, phase rad).
    pub unbalance: Vec<(usize, f64, f64)>,
    /// Measured probe displacements not yet compared: (station index, x m, y m, stamp ns).
    pub probes: Vec<(usize, f64, f64, i64)>,
    /// Rejected inputs since the last report, with the last reason.
    pub rejected: u64,
    /// The last rejection's reason.
    pub last_rejection: String,
    /// With use_sim_time: the latest `/clock` time (ns).
    pub sim_time_ns: Option<i64>,
}

impl Inputs {
    /// Queues a checked probe displacement (m) of station `station`, stamped `stamp_ns` (0:
    /// unstamped, then `now_ns`). The queue is bounded: a burst keeps its newest 1,000 samples.
    pub fn push_probe(&mut self, station: usize, x: f64, y: f64, stamp_ns: i64, now_ns: i64) {
        if self.probes.len() >= 1000 {
            self.probes.remove(0);
        }
        let stamp = if stamp_ns != 0 { stamp_ns } else { now_ns };
        self.probes.push((station, x, y, stamp));
    }
}

/// The linear threshold once computed: Some(Some((speed rad/s, whirl ratio))), Some(None) if
/// stable over the range, None while computing.
type ThresholdSlot = Option<Option<(f64, f64)>>;

/// Wall-clock time (ns since the epoch).
pub fn now_ns() -> i64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as i64)
}

/// The session's output settings from the node's parameters.
fn session_settings(p: &NodeParams) -> SessionSettings {
    SessionSettings {
        state_rate_hz: p.state_rate_hz,
        pressure_map_rate_hz: p.pressure_map_rate_hz,
        warning_amplitude_ratio: p.warning_amplitude_ratio,
        ..SessionSettings::default()
    }
}

/// Runs the model until `stop` is set. Messages go to `out`; when `out` is full a message is
/// dropped and counted (the model never waits for the bus).
pub fn run(
    rotor: Rotor,
    mut params: NodeParams,
    live: (Arc<Mutex<NodeParams>>, Arc<std::sync::atomic::AtomicU64>),
    inputs: Arc<Mutex<Inputs>>,
    out: SyncSender<Outgoing>,
    stop: Arc<AtomicBool>,
) {
    let coupling = match params.model.as_str() {
        "linear" => Coupling::Linear,
        "prehistory" => Coupling::Prehistory {
            delta: params.delta,
        },
        _ => Coupling::Nonlinear,
    };
    let rated = rotor.rated_speed_rad_s;
    let config = TwinConfig {
        film: if params.film == "direct" {
            FilmEvaluation::Direct
        } else {
            FilmEvaluation::Table
        },
        ..TwinConfig::with_steps_per_rev(coupling, rated, params.steps_per_rev)
    };
    let h = config.time_step_s;
    let mut min_speed = params.min_speed_rpm * std::f64::consts::PI / 30.0;
    let mut seen_version = 0u64;
    let mut dropped = 0u64;
    let send = |m: Outgoing, dropped: &mut u64| {
        if out.try_send(m).is_err() {
            *dropped += 1;
        }
    };
    let mut session: Option<Session> = None;
    let mut wall_start = Instant::now();
    let mut sim_started = false;
    let mut last_report = Instant::now();
    let (mut steps_since, mut overruns, mut worst_step_us) = (0u64, 0u64, 0.0f64);
    let mut last_stale_warning = Instant::now() - Duration::from_secs(3600);
    let mut last_behind_warning = Instant::now() - Duration::from_secs(3600);
    // the linear threshold depends on the static loads, not on the present speed: compute it once,
    // on a helper thread, and report the margin to it every second
    let threshold: Arc<Mutex<ThresholdSlot>> = Arc::new(Mutex::new(None));
    {
        let (rotor, threshold) = (rotor.clone(), threshold.clone());
        std::thread::spawn(move || {
            let value = crate::session::linear_threshold(&rotor);
            *threshold.lock().unwrap_or_else(|e| e.into_inner()) = Some(value);
        });
    }
    while !stop.load(Ordering::Relaxed) {
        // parameters changed at run time (rates, thresholds, timeouts)
        let version = live.1.load(Ordering::Relaxed);
        if version != seen_version {
            seen_version = version;
            let p = live.0.lock().unwrap_or_else(|e| e.into_inner()).clone();
            params.state_rate_hz = p.state_rate_hz;
            params.pressure_map_rate_hz = p.pressure_map_rate_hz;
            params.input_timeout_s = p.input_timeout_s;
            params.min_speed_rpm = p.min_speed_rpm;
            params.warning_amplitude_ratio = p.warning_amplitude_ratio;
            min_speed = params.min_speed_rpm * std::f64::consts::PI / 30.0;
            if let Some(s) = session.as_mut() {
                s.set_settings(session_settings(&params));
            }
        }
        let (speed, unbalance, probes, age, rejected, last_rejection) = {
            let mut g = inputs.lock().unwrap_or_else(|e| e.into_inner());
            let r = (
                g.speed,
                std::mem::take(&mut g.unbalance),
                std::mem::take(&mut g.probes),
                g.speed.map(|s| s.2.elapsed()),
                g.rejected,
                g.last_rejection.clone(),
            );
            g.rejected = 0;
            r
        };
        if rejected > 0 {
            send(
                warning(
                    now_ns(),
                    InstabilityWarning::WARN,
                    "bad_input",
                    "",
                    format!("{rejected} input(s) rejected; last: {last_rejection}"),
                ),
                &mut dropped,
            );
        }
        let Some((w, accel, _)) = speed else {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        };
        if age.is_some_and(|a| a.as_secs_f64() > params.input_timeout_s)
            && last_stale_warning.elapsed().as_secs_f64() > params.input_timeout_s
        {
            last_stale_warning = Instant::now();
            send(
                warning(
                    now_ns(),
                    InstabilityWarning::WARN,
                    "stale_input",
                    "",
                    format!(
                        "no speed for {:.2} s; holding {:.1} rad/s",
                        age.unwrap_or_default().as_secs_f64(),
                        w
                    ),
                ),
                &mut dropped,
            );
        }
        if w < min_speed {
            // below the model's range: pause, and start afresh when the speed is back
            session = None;
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        if session.is_none() {
            match Session::new(&rotor, config, w, session_settings(&params), now_ns()) {
                Ok(s) => {
                    session = Some(s);
                    wall_start = Instant::now();
                    sim_started = false;
                }
                Err(e) => {
                    send(
                        warning(
                            now_ns(),
                            InstabilityWarning::ERROR,
                            "bad_input",
                            "",
                            format!("cannot start the twin at {w:.1} rad/s: {e}"),
                        ),
                        &mut dropped,
                    );
                    std::thread::sleep(Duration::from_millis(100));
                    continue;
                }
            }
        }
        let Some(s) = session.as_mut() else {
            continue;
        };
        for (plane, m, p) in unbalance {
            let _ = s.twin_mut().set_unbalance(plane, m, p);
        }
        // pacing: step k is due at k·h after the start, on the wall clock or on /clock
        let model_elapsed = s.twin().time_s();
        let clock_elapsed = if params.use_sim_time {
            let sim_now = inputs.lock().unwrap_or_else(|e| e.into_inner()).sim_time_ns;
            match sim_now {
                Some(now) if sim_started => (now - s.epoch_ns()) as f64 * 1e-9,
                Some(now) => {
                    // model time zero is the first /clock time seen
                    s.set_epoch_ns(now - (model_elapsed * 1e9) as i64);
                    sim_started = true;
                    model_elapsed
                }
                None => {
                    std::thread::sleep(Duration::from_millis(1));
                    continue;
                }
            }
        } else {
            wall_start.elapsed().as_secs_f64()
        };
        let ahead = model_elapsed - clock_elapsed;
        if ahead > 0.0 {
            // ahead of the clock: sleep in short slices (spinning here starves the bus threads
            // of CPU and delays the next input), and look at the inputs again
            std::thread::sleep(Duration::from_secs_f64(ahead.min(0.0005)));
            continue;
        }
        let lag = -ahead;
        let started = Instant::now();
        let input = StepInput {
            speed_rad_s: w,
            accel_rad_s2: accel,
        };
        let result = s.step(&input, &mut |m| send(m, &mut dropped));
        let cost = started.elapsed().as_secs_f64() * 1e6;
        worst_step_us = worst_step_us.max(cost);
        steps_since += 1;
        if cost > h * 1e6 {
            overruns += 1;
        }
        if let Err(e) = result {
            send(
                warning(
                    now_ns(),
                    InstabilityWarning::ERROR,
                    "model_failure",
                    "",
                    format!("step failed: {e}; the twin restarts"),
                ),
                &mut dropped,
            );
            session = None;
            continue;
        }
        // measured against predicted at each probe station
        for (station, mx, my, stamp_ns) in probes {
            if let Some(r) = s.residual(station, [mx, my], stamp_ns) {
                send(Outgoing::Residual(r), &mut dropped);
            }
        }
        if lag > 0.1 && last_behind_warning.elapsed() > Duration::from_secs(1) {
            last_behind_warning = Instant::now();
            send(
                warning(
                    now_ns(),
                    InstabilityWarning::WARN,
                    "falling_behind",
                    "",
                    format!("the model runs {lag:.3} s behind the wall clock"),
                ),
                &mut dropped,
            );
        }
        if last_report.elapsed() >= Duration::from_secs(1) {
            if let Some(found) = *threshold.lock().unwrap_or_else(|e| e.into_inner()) {
                send(
                    Outgoing::Margin(crate::session::margin(now_ns(), w, found)),
                    &mut dropped,
                );
            }
            let wall = last_report.elapsed().as_secs_f64();
            let rtf = steps_since as f64 * h / wall;
            let values = vec![
                KeyValue {
                    key: "real_time_factor".into(),
                    value: format!("{rtf:.3}"),
                },
                KeyValue {
                    key: "lag_s".into(),
                    value: format!("{lag:.4}"),
                },
                KeyValue {
                    key: "step_overruns".into(),
                    value: overruns.to_string(),
                },
                KeyValue {
                    key: "worst_step_us".into(),
                    value: format!("{worst_step_us:.1}"),
                },
                KeyValue {
                    key: "speed_input_age_s".into(),
                    value: format!("{:.3}", age.unwrap_or_default().as_secs_f64()),
                },
                KeyValue {
                    key: "dropped_messages".into(),
                    value: dropped.to_string(),
                },
                KeyValue {
                    key: "time_step_us".into(),
                    value: format!("{:.2}", h * 1e6),
                },
            ];
            let level = if lag > 0.1 { 1 } else { 0 };
            send(
                Outgoing::Diagnostics(DiagnosticArray {
                    header: crate::session::header(now_ns(), ""),
                    status: vec![DiagnosticStatus {
                        level,
                        name: "rotor_twin: model".into(),
                        message: if level == 0 {
                            "keeping up".into()
                        } else {
                            format!("{lag:.3} s behind real time")
                        },
                        hardware_id: "rotor_twin".into(),
                        values,
                    }],
                }),
                &mut dropped,
            );
            last_report = Instant::now();
            steps_since = 0;
            overruns = 0;
            worst_step_us = 0.0;
        }
    }
}
