//! The live node: ROS 2 in and out through ros2-client (RustDDS), the twin on its own thread at
//! real-time pace, every input and output recorded to MCAP. Only this module opens DDS.
//!
//! Topics (names remappable with `-r from:=to`; QoS stated per topic):
//! - in  `/rotor_twin/speed` rotor_twin_msgs/RotorSpeed, or std_msgs/Float64 with `speed_type:=float64`
//!   (unit `speed_unit`), reliable, keep last 100;
//! - in  `/rotor_twin/unbalance` rotor_twin_msgs/Unbalance, reliable, keep last 100;
//! - in  `/rotor_twin/probe` rotor_twin_msgs/ProbeDisplacement (m), reliable, keep last 100;
//!   out `/rotor_twin/residual` OrbitResidual: predicted minus measured at that station;
//! - out `/rotor_twin/journal_state` JournalState and `/rotor_twin/film_state` FilmState, reliable,
//!   keep last 10, at `state_rate_hz`; `/rotor_twin/orbit` Orbit per revolution, reliable, keep
//!   last 10; `/rotor_twin/warning` InstabilityWarning, reliable, transient local, keep last 1
//!   (a late subscriber sees the last one); `/diagnostics` diagnostic_msgs/DiagnosticArray, 1 Hz;
//! - in  `/clock` rosgraph_msgs/Clock with `use_sim_time:=true`: the model is paced by it and its
//!   outputs are stamped in simulation time.

mod inputs;
mod model;
mod param_client;
mod params;
mod recording;

pub use inputs::{check_probe, check_unbalance, SpeedGate};
pub use param_client::{run as param_call, ParamCall};
pub use params::{parse_ros_args, NodeParams, RosArgs, SpeedUnit, RUNTIME_PARAMETERS};

use crate::messages::{self, RosMessage};
use crate::record::TopicQos;
use crate::rotor::{MachineDescription, Rotor};
use anyhow::Context as _;
use futures::StreamExt;
use model::{now_ns, Inputs, Outgoing};
use recording::ToRecord;
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions, ParameterValue,
};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Instant;

/// Everything `rotor-twin node` needs.
#[derive(Debug, Clone)]
pub struct NodeSetup {
    /// Machine description file; the built-in microturbine if None.
    pub config: Option<PathBuf>,
    /// Bag directory to record into.
    pub record: Option<PathBuf>,
    /// Arguments after `--ros-args`.
    pub ros_args: Vec<String>,
}

const SPEED: &str = "/rotor_twin/speed";
const UNBALANCE: &str = "/rotor_twin/unbalance";
const PROBE: &str = "/rotor_twin/probe";
const RESIDUAL: &str = "/rotor_twin/residual";
const MARGIN: &str = "/rotor_twin/stability_margin";
const JOURNAL: &str = "/rotor_twin/journal_state";
const FILM: &str = "/rotor_twin/film_state";
const ORBIT: &str = "/rotor_twin/orbit";
const WARNING: &str = "/rotor_twin/warning";
const DIAGNOSTICS: &str = "/diagnostics";

fn qos_profile(q: TopicQos) -> ros2_client::QosProfile {
    use ros2_client::qos::{Durability, History, Reliability, WhenFull};
    let base = ros2_client::QosProfile::publisher_default();
    ros2_client::QosProfile {
        reliability: if q.reliable {
            Reliability::Reliable {
                when_full: WhenFull::Fail,
            }
        } else {
            Reliability::BestEffort
        },
        durability: if q.transient_local {
            Durability::TransientLocal
        } else {
            Durability::Volatile
        },
        history: History::KeepLast {
            depth: q.depth as usize,
        },
        ..base
    }
}

/// A topic name after remapping, as a ros2-client Name.
fn topic_name(
    remaps: &std::collections::BTreeMap<String, String>,
    default: &str,
) -> anyhow::Result<Name> {
    let name = remaps.get(default).map_or(default, String::as_str);
    Name::parse(name).map_err(|e| anyhow::anyhow!("topic name '{name}': {e:?}"))
}

fn type_name<T: RosMessage>() -> MessageTypeName {
    let mut parts = T::TYPE_NAME.split('/');
    let pkg = parts.next().unwrap_or_default();
    let ty = parts.next_back().unwrap_or_default();
    MessageTypeName::new(pkg, ty)
}

/// True if the environment asks for discovery on this host only: ROS_AUTOMATIC_DISCOVERY_RANGE
/// LOCALHOST (or OFF, which this node treats the same way: it has no static peers), or the older
/// ROS_LOCALHOST_ONLY=1. An unknown value is an error naming it.
fn discovery_localhost_only() -> anyhow::Result<bool> {
    let var = |name: &str| std::env::var(name).ok().filter(|v| !v.trim().is_empty());
    if let Some(range) = var("ROS_AUTOMATIC_DISCOVERY_RANGE") {
        return match range.trim() {
            "LOCALHOST" | "OFF" => Ok(true),
            "SUBNET" | "SYSTEM_DEFAULT" => Ok(false),
            other => anyhow::bail!(
                "ROS_AUTOMATIC_DISCOVERY_RANGE '{other}': must be SUBNET, LOCALHOST, OFF or SYSTEM_DEFAULT"
            ),
        };
    }
    Ok(match var("ROS_LOCALHOST_ONLY").as_deref().map(str::trim) {
        Some("1") => true,
        Some("0") | None => false,
        Some(other) => anyhow::bail!("ROS_LOCALHOST_ONLY '{other}': must be 0 or 1"),
    })
}

/// Runs the node until SIGINT or SIGTERM.
pub fn run(setup: NodeSetup) -> anyhow::Result<()> {
    let ros = parse_ros_args(&setup.ros_args).map_err(anyhow::Error::msg)?;
    let mut params = NodeParams::default();
    for (k, v) in &ros.params {
        params.set(k, v).map_err(anyhow::Error::msg)?;
    }
    let desc = match &setup.config {
        Some(p) => MachineDescription::from_file(p)?,
        None => MachineDescription::builtin_default(),
    };
    let rotor = Rotor::from_description(&desc);
    if params.film == "table" && params.model != "linear" {
        // the film tables are built before the node joins the bus, so that the first speed
        // starts the twin at once
        eprintln!("rotor_twin: tabulating the bearing films…");
        crate::dynamics::prepare_film_tables(&rotor)?;
    }
    let domain: u16 = match std::env::var("ROS_DOMAIN_ID") {
        Ok(v) if !v.trim().is_empty() => v
            .trim()
            .parse()
            .with_context(|| format!("ROS_DOMAIN_ID '{v}' is not a domain number"))?,
        _ => 0,
    };
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    runtime.block_on(run_async(setup, ros, params, rotor, domain))
}

async fn run_async(
    setup: NodeSetup,
    ros: RosArgs,
    params: NodeParams,
    rotor: Rotor,
    domain: u16,
) -> anyhow::Result<()> {
    let context = if discovery_localhost_only()? {
        // only the loopback interface for multicast and advertised locators
        let participant = ros2_client::dds::rustdds::DomainParticipantBuilder::new(domain)
            .with_only_networks([std::net::IpAddr::from([127, 0, 0, 1])])
            .build()
            .map_err(|e| anyhow::anyhow!("DDS participant: {e:?}"))?;
        Context::from_domain_participant(participant)
    } else {
        Context::with_options(ContextOptions::new().domain_id(domain))
    }
    .map_err(|e| anyhow::anyhow!("DDS context: {e:?}"))?;
    // parameters that may change at run time are shared with the model thread
    let live_params = Arc::new(Mutex::new(params.clone()));
    let params_version = Arc::new(std::sync::atomic::AtomicU64::new(0));
    let text_of = |v: &ParameterValue| -> Option<String> {
        match v {
            ParameterValue::Double(d) => Some(d.to_string()),
            ParameterValue::Integer(i) => Some(i.to_string()),
            ParameterValue::Boolean(b) => Some(b.to_string()),
            ParameterValue::String(s) => Some(s.clone()),
            _ => None,
        }
    };
    let validator_params = live_params.clone();
    let action_params = live_params.clone();
    let action_version = params_version.clone();
    let mut options = NodeOptions::new()
        .enable_rosout(false)
        .parameter_validator(Box::new(move |name, value| {
            let text =
                text_of(value).ok_or_else(|| format!("parameter {name}: unsupported type"))?;
            let mut trial = validator_params
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .clone();
            trial.set_at_runtime(name, &text)
        }))
        .parameter_set_action(Box::new(move |name, value| {
            let text =
                text_of(value).ok_or_else(|| format!("parameter {name}: unsupported type"))?;
            action_params
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .set_at_runtime(name, &text)?;
            action_version.fetch_add(1, Ordering::SeqCst);
            Ok(())
        }));
    for (name, value) in [
        ("model", ParameterValue::String(params.model.clone())),
        ("delta", ParameterValue::Double(params.delta)),
        ("film", ParameterValue::String(params.film.clone())),
        (
            "steps_per_rev",
            ParameterValue::Integer(params.steps_per_rev as i64),
        ),
        (
            "state_rate_hz",
            ParameterValue::Double(params.state_rate_hz),
        ),
        (
            "pressure_map_rate_hz",
            ParameterValue::Double(params.pressure_map_rate_hz),
        ),
        (
            "input_timeout_s",
            ParameterValue::Double(params.input_timeout_s),
        ),
        (
            "min_speed_rpm",
            ParameterValue::Double(params.min_speed_rpm),
        ),
        (
            "speed_type",
            ParameterValue::String(params.speed_type.clone()),
        ),
        ("use_sim_time", ParameterValue::Boolean(params.use_sim_time)),
        (
            "warning_amplitude_ratio",
            ParameterValue::Double(params.warning_amplitude_ratio),
        ),
    ] {
        options = options.declare_parameter(name, value);
    }
    let mut node = context
        .new_node(
            NodeName::new("/", "rotor_twin").map_err(|e| anyhow::anyhow!("{e:?}"))?,
            options,
        )
        .map_err(|e| anyhow::anyhow!("node: {e:?}"))?;
    let input_qos = TopicQos::reliable(100);
    // subscriptions keep a deep history: RustDDS drops unread samples beyond it silently, and a
    // burst of 10,000 messages must not lose any
    let reader_qos = qos_profile(TopicQos::reliable(20_000));
    let state_qos = TopicQos::reliable(10);
    let warning_qos = TopicQos::latched(1);

    macro_rules! publisher {
        ($ty:ty, $name:expr, $qos:expr) => {{
            let topic = node
                .create_topic(
                    &topic_name(&ros.remaps, $name)?,
                    type_name::<$ty>(),
                    &qos_profile($qos),
                )
                .map_err(|e| anyhow::anyhow!("topic {}: {e:?}", $name))?;
            node.create_publisher::<$ty>(&topic, None)
                .map_err(|e| anyhow::anyhow!("publisher {}: {e:?}", $name))?
        }};
    }
    let pub_journal = publisher!(messages::JournalState, JOURNAL, state_qos);
    let pub_film = publisher!(messages::FilmState, FILM, state_qos);
    let pub_orbit = publisher!(messages::Orbit, ORBIT, state_qos);
    let pub_warning = publisher!(messages::InstabilityWarning, WARNING, warning_qos);
    let pub_diag = publisher!(messages::DiagnosticArray, DIAGNOSTICS, state_qos);
    let pub_residual = publisher!(messages::OrbitResidual, RESIDUAL, state_qos);
    let pub_margin = publisher!(messages::StabilityMargin, MARGIN, TopicQos::latched(1));

    // recording
    let (rec_tx, rec_rx) = mpsc::sync_channel::<ToRecord>(65_536);
    let stop = Arc::new(AtomicBool::new(false));
    let recorder_thread = match &setup.record {
        Some(dir) => Some(recording::spawn(
            dir,
            params.speed_type == "float64",
            recording::Qos {
                input: input_qos,
                state: state_qos,
                warning: warning_qos,
            },
            rec_rx,
            stop.clone(),
        )?),
        None => {
            drop(rec_rx);
            None
        }
    };
    let recording = setup.record.is_some();

    // the model thread and the publishing thread
    let inputs = Arc::new(Mutex::new(Inputs::default()));
    let (out_tx, out_rx) = mpsc::sync_channel::<Outgoing>(4096);
    let model_thread = {
        let (inputs, stop) = (inputs.clone(), stop.clone());
        let params = params.clone();
        let live = (live_params.clone(), params_version.clone());
        std::thread::Builder::new()
            .name("rotor_twin model".into())
            .spawn(move || model::run(rotor.clone(), params, live, inputs, out_tx, stop))?
    };
    let rec_out = rec_tx.clone();
    let publish_thread = std::thread::Builder::new()
        .name("rotor_twin publish".into())
        .spawn(move || {
            for item in out_rx {
                let t = now_ns();
                let _sent = match &item {
                    // a full send window drops the sample (never block the model)
                    Outgoing::Journal(m) => pub_journal.publish(m.clone()).is_ok(),
                    Outgoing::Film(m) => pub_film.publish(m.clone()).is_ok(),
                    Outgoing::Orbit(m) => pub_orbit.publish(m.clone()).is_ok(),
                    Outgoing::Warning(m) => pub_warning.publish(m.clone()).is_ok(),
                    Outgoing::Diagnostics(m) => pub_diag.publish(m.clone()).is_ok(),
                    Outgoing::Residual(m) => pub_residual.publish(m.clone()).is_ok(),
                    Outgoing::Margin(m) => pub_margin.publish(m.clone()).is_ok(),
                };
                if recording {
                    let _ = rec_out.try_send(ToRecord::Out(item, t));
                }
            }
        })?;

    // subscriptions
    let max_speed = 10.0
        * crate::units::rpm_to_rad_s(MachineDescription::builtin_default().rated_speed_rpm)
            .max(1.0);
    let gate = Arc::new(Mutex::new(SpeedGate::new(
        max_speed,
        params.input_timeout_s,
    )));
    let reject = |inputs: &Arc<Mutex<Inputs>>, why: String| {
        let mut g = inputs.lock().unwrap_or_else(|e| e.into_inner());
        g.rejected += 1;
        g.last_rejection = why;
    };
    let speed_topic = topic_name(&ros.remaps, SPEED)?;
    if params.speed_type == "float64" {
        let topic = node
            .create_topic(
                &speed_topic,
                type_name::<messages::Float64>(),
                &qos_profile(input_qos),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let sub = node
            .create_subscription::<messages::Float64>(&topic, Some(reader_qos.clone()))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let (inputs, gate, rec, unit) = (
            inputs.clone(),
            gate.clone(),
            rec_tx.clone(),
            params.speed_unit,
        );
        tokio::spawn(async move {
            let mut stream = Box::pin(sub.async_stream());
            while let Some(Ok((m, _info))) = stream.next().await {
                let now = now_ns();
                if recording {
                    let _ = rec.try_send(ToRecord::Speed64(m, now));
                }
                let checked = gate.lock().unwrap_or_else(|e| e.into_inner()).check(
                    unit.to_rad_s(m.data),
                    0.0,
                    0,
                    now,
                );
                match checked {
                    Ok((w, a)) => {
                        inputs.lock().unwrap_or_else(|e| e.into_inner()).speed =
                            Some((w, a, Instant::now()))
                    }
                    Err(why) => reject(&inputs, why),
                }
            }
        });
    } else {
        let topic = node
            .create_topic(
                &speed_topic,
                type_name::<messages::RotorSpeed>(),
                &qos_profile(input_qos),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let sub = node
            .create_subscription::<messages::RotorSpeed>(&topic, Some(reader_qos.clone()))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let (inputs, gate, rec) = (inputs.clone(), gate.clone(), rec_tx.clone());
        let sim_time = params.use_sim_time;
        let live = live_params.clone();
        tokio::spawn(async move {
            let mut stream = Box::pin(sub.async_stream());
            while let Some(Ok((m, _info))) = stream.next().await {
                let now = now_ns();
                // stamps are judged against the clock the node follows
                let clock_now = if sim_time {
                    let sim = inputs.lock().unwrap_or_else(|e| e.into_inner()).sim_time_ns;
                    sim.unwrap_or(m.header.stamp.as_nanos())
                } else {
                    now
                };
                let timeout_s = live
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .input_timeout_s;
                let mut g = gate.lock().unwrap_or_else(|e| e.into_inner());
                g.timeout_ns = (timeout_s * 1e9) as i64;
                let checked = g.check(
                    m.speed,
                    m.acceleration,
                    m.header.stamp.as_nanos(),
                    clock_now,
                );
                drop(g);
                if recording {
                    let _ = rec.try_send(ToRecord::Speed(m, now));
                }
                match checked {
                    Ok((w, a)) => {
                        inputs.lock().unwrap_or_else(|e| e.into_inner()).speed =
                            Some((w, a, Instant::now()))
                    }
                    Err(why) => reject(&inputs, why),
                }
            }
        });
    }
    {
        let topic = node
            .create_topic(
                &topic_name(&ros.remaps, UNBALANCE)?,
                type_name::<messages::Unbalance>(),
                &qos_profile(input_qos),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let sub = node
            .create_subscription::<messages::Unbalance>(&topic, Some(reader_qos.clone()))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let (inputs, rec) = (inputs.clone(), rec_tx.clone());
        let planes = desc_planes(&setup)?;
        tokio::spawn(async move {
            let mut stream = Box::pin(sub.async_stream());
            while let Some(Ok((m, _info))) = stream.next().await {
                if recording {
                    let _ = rec.try_send(ToRecord::Unbalance(m.clone(), now_ns()));
                }
                match check_unbalance(m.plane, m.magnitude, m.phase, planes) {
                    Ok(u) => inputs
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .unbalance
                        .push(u),
                    Err(why) => reject(&inputs, why),
                }
            }
        });
    }
    {
        let topic = node
            .create_topic(
                &topic_name(&ros.remaps, PROBE)?,
                type_name::<messages::ProbeDisplacement>(),
                &qos_profile(input_qos),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let sub = node
            .create_subscription::<messages::ProbeDisplacement>(&topic, Some(reader_qos.clone()))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let (inputs, rec) = (inputs.clone(), rec_tx.clone());
        let stations = desc_stations(&setup)?;
        tokio::spawn(async move {
            let mut stream = Box::pin(sub.async_stream());
            while let Some(Ok((m, _info))) = stream.next().await {
                let now = now_ns();
                if recording {
                    let _ = rec.try_send(ToRecord::Probe(m.clone(), now));
                }
                let station = stations.iter().position(|s| *s == m.station);
                match (station, check_probe(m.x, m.y)) {
                    (Some(k), Ok((x, y))) => {
                        let stamp = m.header.stamp.as_nanos();
                        inputs
                            .lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .push_probe(k, x, y, stamp, now);
                    }
                    (None, _) => reject(
                        &inputs,
                        format!(
                            "probe station '{}' is not in the machine description",
                            m.station
                        ),
                    ),
                    (_, Err(why)) => reject(&inputs, why),
                }
            }
        });
    }
    // probe pairs as geometry_msgs/PointStamped (x, y in m), one topic per station
    let stations = desc_stations(&setup)?;
    for (station, topic_text) in &params.probe_point_topics {
        let k = stations
            .iter()
            .position(|s| s == station)
            .ok_or_else(|| anyhow::anyhow!("parameter probe_point_topics: station '{station}' is not in the machine description"))?;
        let name = Name::parse(topic_text)
            .map_err(|e| anyhow::anyhow!("topic name '{topic_text}': {e:?}"))?;
        let topic = node
            .create_topic(
                &name,
                type_name::<messages::PointStamped>(),
                &qos_profile(input_qos),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let sub = node
            .create_subscription::<messages::PointStamped>(&topic, Some(reader_qos.clone()))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let inputs = inputs.clone();
        tokio::spawn(async move {
            let mut stream = Box::pin(sub.async_stream());
            while let Some(Ok((m, _info))) = stream.next().await {
                match check_probe(m.point.x, m.point.y) {
                    Ok((x, y)) => {
                        let stamp = m.header.stamp.as_nanos();
                        inputs.lock().unwrap_or_else(|e| e.into_inner()).push_probe(
                            k,
                            x,
                            y,
                            stamp,
                            now_ns(),
                        );
                    }
                    Err(why) => reject(&inputs, why),
                }
            }
        });
    }
    if params.use_sim_time {
        // rosgraph_msgs/Clock on /clock (ros2-client's own /clock handling uses another type)
        let topic = node
            .create_topic(
                &topic_name(&ros.remaps, "/clock")?,
                type_name::<messages::Clock>(),
                &qos_profile(TopicQos::sensor(1)),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let sub = node
            .create_subscription::<messages::Clock>(&topic, Some(qos_profile(TopicQos::sensor(10))))
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let inputs = inputs.clone();
        tokio::spawn(async move {
            let mut stream = Box::pin(sub.async_stream());
            while let Some(Ok((m, _info))) = stream.next().await {
                let ns = m.clock.as_nanos();
                let mut g = inputs.lock().unwrap_or_else(|e| e.into_inner());
                // simulation time never runs backwards
                if g.sim_time_ns.is_none_or(|t| ns >= t) {
                    g.sim_time_ns = Some(ns);
                } else {
                    g.rejected += 1;
                    g.last_rejection =
                        format!("/clock went backwards to {:.6} s", ns as f64 * 1e-9);
                }
            }
        });
    }
    drop(rec_tx);
    let spinner = node
        .spinner()
        .map_err(|e| anyhow::anyhow!("spinner: {e:?}"))?;
    tokio::spawn(async move {
        let _ = spinner.spin().await;
    });
    eprintln!(
        "rotor_twin: node up on ROS domain {domain}; waiting for {}",
        speed_topic_label(&ros)
    );

    // until SIGINT or SIGTERM
    let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
    tokio::select! {
        _ = tokio::signal::ctrl_c() => {},
        _ = term.recv() => {},
    }
    eprintln!("rotor_twin: shutting down");
    stop.store(true, Ordering::Relaxed);
    let _ = model_thread.join();
    let _ = publish_thread.join();
    drop(node);
    if let Some(t) = recorder_thread {
        // the subscription tasks hold senders: end the runtime's tasks by leaving; the recorder
        // stops when every sender is gone or after its last flush
        match t.join() {
            Ok(Ok(dir)) => eprintln!("rotor_twin: recording finished in {}", dir.display()),
            Ok(Err(e)) => eprintln!("rotor_twin: recording failed: {e:#}"),
            Err(_) => eprintln!("rotor_twin: recorder thread panicked"),
        }
    }
    Ok(())
}

fn speed_topic_label(ros: &RosArgs) -> String {
    ros.remaps
        .get(SPEED)
        .cloned()
        .unwrap_or_else(|| SPEED.to_string())
}

fn desc_stations(setup: &NodeSetup) -> anyhow::Result<Vec<String>> {
    let desc = match &setup.config {
        Some(p) => MachineDescription::from_file(p)?,
        None => MachineDescription::builtin_default(),
    };
    Ok(desc.probes.iter().map(|p| p.name.clone()).collect())
}

fn desc_planes(setup: &NodeSetup) -> anyhow::Result<usize> {
    let desc = match &setup.config {
        Some(p) => MachineDescription::from_file(p)?,
        None => MachineDescription::builtin_default(),
    };
    Ok(desc.unbalance.len())
}
