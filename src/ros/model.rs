//! The model thread: the twin core at real-time pace (wall clock), fed by the latest valid inputs,
//! producing messages for the bus and the recording. It never runs on the async executor, and when
//! it falls behind it says so.

use super::params::NodeParams;
use crate::dynamics::{Coupling, StepInput, Twin, TwinConfig};
use crate::messages::*;
use crate::monitor::{ClassifierSettings, Monitor, RotorState, PRESSURE_POINTS};
use crate::rotor::Rotor;
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

/// A message for the bus and the recording.
#[derive(Debug, Clone)]
pub enum Outgoing {
    /// Journal state of one bearing.
    Journal(JournalState),
    /// Film state of one bearing.
    Film(FilmState),
    /// One revolution's orbit of one bearing.
    Orbit(Orbit),
    /// A warning.
    Warning(InstabilityWarning),
    /// Diagnostics.
    Diagnostics(DiagnosticArray),
    /// Predicted minus measured displacement at a probe station.
    Residual(OrbitResidual),
    /// Distance from the linear stability threshold.
    Margin(StabilityMargin),
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

fn header(ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time::from_nanos(ns),
        frame_id: frame.to_string(),
    }
}

fn warning(ns: i64, level: u8, kind: &str, bearing: &str, evidence: String) -> Outgoing {
    Outgoing::Warning(InstabilityWarning {
        header: header(ns, bearing),
        level,
        kind: kind.into(),
        bearing: bearing.into(),
        evidence,
        ..Default::default()
    })
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
    let config = TwinConfig::with_steps_per_rev(coupling, rated, params.steps_per_rev);
    let h = config.time_step_s;
    let mut min_speed = params.min_speed_rpm * std::f64::consts::PI / 30.0;
    let mut decimation = ((1.0 / params.state_rate_hz) / h).round().max(1.0) as u64;
    let mut map_decimation = ((1.0 / params.pressure_map_rate_hz) / h).round().max(1.0) as u64;
    let mut seen_version = 0u64;
    let mut dropped = 0u64;
    let send = |m: Outgoing, dropped: &mut u64| {
        if out.try_send(m).is_err() {
            *dropped += 1;
        }
    };
    let mut twin: Option<(Twin, Monitor)> = None;
    let mut names: Vec<String> = Vec::new();
    let mut clearances: Vec<f64> = Vec::new();
    let mut profile = vec![0.0; PRESSURE_POINTS];
    let angles: Vec<f64> = (0..PRESSURE_POINTS)
        .map(|k| std::f64::consts::TAU * k as f64 / PRESSURE_POINTS as f64)
        .collect();
    let mut step_index = 0u64;
    let mut wall_start = Instant::now();
    let mut sim_start_ns: Option<i64> = None;
    let mut model_start_s = 0.0;
    let mut last_report = Instant::now();
    let (mut steps_since, mut overruns, mut worst_step_us) = (0u64, 0u64, 0.0f64);
    let mut last_state = RotorState::Stable;
    let mut last_state_warning = Instant::now();
    let mut last_stale_warning = Instant::now() - Duration::from_secs(3600);
    let mut last_behind_warning = Instant::now() - Duration::from_secs(3600);
    let mut epoch_ns = now_ns();
    // the linear threshold depends on the static loads, not on the present speed: compute it once,
    // on a helper thread, and report the margin to it every second
    let threshold: Arc<Mutex<ThresholdSlot>> = Arc::new(Mutex::new(None));
    {
        let (rotor, threshold) = (rotor.clone(), threshold.clone());
        std::thread::spawn(move || {
            let rated_rpm = rotor.rated_speed_rad_s * 30.0 / std::f64::consts::PI;
            let found = crate::rotor::static_solution(&rotor).ok().and_then(|st| {
                crate::rotor::stability_threshold(
                    &rotor,
                    &st,
                    (0.1 * rated_rpm).max(100.0),
                    2.0 * rated_rpm,
                    rated_rpm / 20.0,
                )
                .ok()
            });
            let value = found
                .map(|t| t.map(|t| (t.speed_rpm * std::f64::consts::PI / 30.0, t.whirl_ratio)));
            *threshold.lock().unwrap_or_else(|e| e.into_inner()) = Some(value.unwrap_or(None));
        });
    }
    let station_names: Vec<String> = rotor.probes.iter().map(|p| p.name.clone()).collect();
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
            decimation = ((1.0 / params.state_rate_hz) / h).round().max(1.0) as u64;
            map_decimation = ((1.0 / params.pressure_map_rate_hz) / h).round().max(1.0) as u64;
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
            twin = None;
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        if twin.is_none() {
            match Twin::new(&rotor, config, w) {
                Ok(t) => {
                    names = t.bearing_names().map(str::to_string).collect();
                    clearances = t.bearing_clearances_m();
                    let m =
                        Monitor::new(&t, 2 * params.steps_per_rev, ClassifierSettings::default());
                    twin = Some((t, m));
                    wall_start = Instant::now();
                    sim_start_ns = None;
                    epoch_ns = now_ns();
                    model_start_s = 0.0;
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
        let Some((t, monitor)) = twin.as_mut() else {
            continue;
        };
        for (plane, m, p) in unbalance {
            let _ = t.set_unbalance(plane, m, p);
        }
        // pacing: step k is due at k·h after the start, on the wall clock or on /clock
        let model_elapsed = t.time_s() - model_start_s;
        let clock_elapsed = if params.use_sim_time {
            let sim_now = inputs.lock().unwrap_or_else(|e| e.into_inner()).sim_time_ns;
            match (sim_now, sim_start_ns) {
                (Some(now), Some(start)) => (now - start) as f64 * 1e-9,
                (Some(now), None) => {
                    sim_start_ns = Some(now);
                    0.0
                }
                _ => {
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
        let result = t
            .step(&StepInput {
                speed_rad_s: w,
                accel_rad_s2: accel,
            })
            .map(|_| ());
        let cost = started.elapsed().as_secs_f64() * 1e6;
        worst_step_us = worst_step_us.max(cost);
        steps_since += 1;
        if cost > h * 1e6 {
            overruns += 1;
        }
        step_index += 1;
        // stamps: the clock the model follows, at the model's time
        let stamp = sim_start_ns.unwrap_or(epoch_ns) + ((t.time_s() - model_start_s) * 1e9) as i64;
        match result {
            Err(e) => {
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
                twin = None;
                continue;
            }
            Ok(()) => {
                let o = t.output();
                // measured against predicted at each probe station (the latest prediction)
                for (station, mx, my, stamp_ns) in probes {
                    if let (Some(p), Some(name)) =
                        (o.probes.get(station), station_names.get(station))
                    {
                        let [px, py] = p.displacement_m;
                        send(
                            Outgoing::Residual(OrbitResidual {
                                header: header(stamp_ns, name),
                                station: name.clone(),
                                predicted_x: px,
                                predicted_y: py,
                                measured_x: mx,
                                measured_y: my,
                                residual_x: px - mx,
                                residual_y: py - my,
                            }),
                            &mut dropped,
                        );
                    }
                }
                if step_index % decimation == 0 {
                    for (k, b) in o.bearings.iter().enumerate() {
                        send(
                            Outgoing::Journal(JournalState {
                                header: header(stamp, &names[k]),
                                bearing: names[k].clone(),
                                x: b.position_m[0],
                                y: b.position_m[1],
                                vx: b.velocity_m_s[0],
                                vy: b.velocity_m_s[1],
                                eccentricity_ratio: b.eccentricity_ratio,
                                attitude: b.attitude_rad,
                                speed: o.speed_rad_s,
                                contact: b.contact,
                            }),
                            &mut dropped,
                        );
                        let with_map = step_index % map_decimation == 0;
                        if with_map {
                            t.midplane_pressure(k, &mut profile);
                        }
                        send(
                            Outgoing::Film(FilmState {
                                header: header(stamp, &names[k]),
                                bearing: names[k].clone(),
                                force_x: b.force_n[0],
                                force_y: b.force_n[1],
                                max_pressure: b.max_pressure_pa,
                                max_pressure_angle: b.max_pressure_angle_rad,
                                film_start: b.film_start_rad,
                                film_end: b.film_end_rad,
                                power_loss: b.power_loss_w,
                                pressure_angles: if with_map { angles.clone() } else { Vec::new() },
                                pressure: if with_map {
                                    profile.clone()
                                } else {
                                    Vec::new()
                                },
                            }),
                            &mut dropped,
                        );
                    }
                }
            }
        }
        if let Some(rep) = monitor.record(t) {
            let rep = rep.clone();
            for (k, b) in rep.bearings.iter().enumerate() {
                let orbit = monitor.recent_orbit(k, 1);
                send(
                    Outgoing::Orbit(Orbit {
                        header: header(stamp, &names[k]),
                        bearing: names[k].clone(),
                        revolution: rep.revolution,
                        speed: rep.speed_rad_s,
                        clearance: clearances[k],
                        x: orbit.iter().map(|p| p[0]).collect(),
                        y: orbit.iter().map(|p| p[1]).collect(),
                        one_x_amplitude: b.one_x_amplitude_m,
                        subsync_ratio: b.subsync_ratio,
                        subsync_amplitude: b.subsync_amplitude_m,
                    }),
                    &mut dropped,
                );
            }
            // warn at once on a change of state, and at most once a second while unstable
            let unstable_reminder = rep.state != RotorState::Stable
                && last_state_warning.elapsed() >= Duration::from_secs(1);
            if rep.state != last_state || unstable_reminder {
                last_state_warning = Instant::now();
                let (k, b) = rep
                    .bearings
                    .iter()
                    .enumerate()
                    .max_by(|a, b| a.1.state.cmp(&b.1.state))
                    .map(|(k, b)| (k, *b))
                    .unwrap_or_default();
                let (level, kind) = match rep.state {
                    RotorState::Stable => (InstabilityWarning::OK, "none"),
                    RotorState::Whirl => (InstabilityWarning::WARN, "whirl"),
                    RotorState::Whip => (InstabilityWarning::ERROR, "whip"),
                    RotorState::Contact => (InstabilityWarning::ERROR, "contact"),
                };
                let amplitude = 0.5 * b.orbit_pp_x_m.max(b.orbit_pp_y_m)
                    / clearances.get(k).copied().unwrap_or(1.0);
                let level = if rep.state == RotorState::Stable
                    && amplitude > params.warning_amplitude_ratio
                {
                    InstabilityWarning::WARN
                } else {
                    level
                };
                send(
                    Outgoing::Warning(InstabilityWarning {
                        header: header(stamp, names.get(k).map_or("", String::as_str)),
                        level,
                        kind: kind.into(),
                        bearing: names.get(k).cloned().unwrap_or_default(),
                        whirl_ratio: b.subsync_ratio,
                        amplitude_over_clearance: amplitude,
                        evidence: rep.evidence(),
                    }),
                    &mut dropped,
                );
                last_state = rep.state;
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
                let (threshold_found, threshold_speed, whirl_ratio) = match found {
                    Some((s, r)) => (true, s, r),
                    None => (false, 0.0, 0.0),
                };
                send(
                    Outgoing::Margin(StabilityMargin {
                        header: header(now_ns(), ""),
                        speed: w,
                        threshold_found,
                        threshold_speed,
                        margin: if threshold_found {
                            threshold_speed - w
                        } else {
                            0.0
                        },
                        whirl_ratio,
                    }),
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
                    header: header(now_ns(), ""),
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
