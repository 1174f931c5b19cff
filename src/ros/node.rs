//! The DDS side of the node (ros2-client): participant, publishers, subscriptions, parameter services;
//! built only with the `ros` feature.

use super::model::{now_ns, Inbox, NodeClock, Outgoing, Published};
use super::recording::ToRecord;
use super::*;
use crate::driver::Input;
use crate::messages::{self, RosMessage};
use crate::record::TopicQos;
use crate::rotor::{MachineDescription, Rotor};
use crate::topics::{
    CLOCK, DIAGNOSTICS, FILM, JOURNAL, MARGIN, ORBIT, PROBE, RESIDUAL, SPEED, UNBALANCE, WARNING,
};
use anyhow::Context as _;
use futures::StreamExt;
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions, ParameterValue,
};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};

/// Everything `rotor-twin node` needs.
#[derive(Debug, Clone)]
pub struct NodeSetup {
    /// Machine description file; the built-in microturbine if None.
    pub config: Option<PathBuf>,
    /// Bag directory to record into.
    pub record: Option<PathBuf>,
    /// When the recording goes on in a new file (`--record-max-bag-size`, `…-duration`).
    pub record_split: crate::record::SplitLimits,
    /// Arguments after `--ros-args`.
    pub ros_args: Vec<String>,
}

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

/// A topic of the node, as a ros2-client Name: the twin's own topics (`/rotor_twin/…` in
/// [`crate::topics`]) live in the node's namespace, `<ns>/rotor_twin/…` (so two twins in two
/// namespaces do not share a speed); /diagnostics and /clock are global, as ROS 2 tools expect.
/// Remaps apply after expansion ([`RosArgs::topic`]).
fn topic_name(ros: &RosArgs, default: &str) -> anyhow::Result<Name> {
    let relative = default
        .strip_prefix('/')
        .filter(|r| r.starts_with("rotor_twin/"))
        .unwrap_or(default);
    let name = ros.topic(relative);
    Name::parse(&name).map_err(|e| anyhow::anyhow!("topic name '{name}': {e:?}"))
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

/// What the node cannot honour of ROS 2's discovery settings, said at start (REP 2000 / the ROS 2
/// Jazzy "Improved discovery" design): RustDDS 0.15 has no static (initial) peers and no
/// discovery-off mode.
fn discovery_notices(var: impl Fn(&str) -> Option<String>) -> Vec<String> {
    let set = |name: &str| var(name).filter(|v| !v.trim().is_empty());
    let mut notices = Vec::new();
    if let Some(peers) = set("ROS_STATIC_PEERS") {
        notices.push(format!(
            "ROS_STATIC_PEERS '{peers}' not honoured: RustDDS 0.15 has no static peers; this node \
             is found by multicast (or by peers that list its host as theirs)"
        ));
    }
    if set("ROS_AUTOMATIC_DISCOVERY_RANGE")
        .as_deref()
        .map(str::trim)
        == Some("OFF")
    {
        notices.push(
            "ROS_AUTOMATIC_DISCOVERY_RANGE OFF taken as LOCALHOST: RustDDS cannot turn \
             discovery off"
                .into(),
        );
    }
    notices
}

/// Largest ROS domain id (REP 2000 / the ROS 2 docs: 0–232 with Fast DDS and Cyclone's port
/// mapping; higher ids map to ports beyond 65535).
pub const MAX_DOMAIN_ID: u16 = 232;

/// ROS_DOMAIN_ID (default 0), checked against [`MAX_DOMAIN_ID`].
fn domain_id() -> anyhow::Result<u16> {
    match std::env::var("ROS_DOMAIN_ID") {
        Ok(v) if !v.trim().is_empty() => {
            let id: u16 = v
                .trim()
                .parse()
                .with_context(|| format!("ROS_DOMAIN_ID '{v}' is not a domain number"))?;
            anyhow::ensure!(
                id <= MAX_DOMAIN_ID,
                "ROS_DOMAIN_ID {id}: must be 0 to {MAX_DOMAIN_ID}"
            );
            Ok(id)
        }
        _ => Ok(0),
    }
}

/// Runs the node until SIGINT or SIGTERM.
pub fn run(setup: NodeSetup) -> anyhow::Result<()> {
    let started = std::time::Instant::now();
    let ros = parse_ros_args(&setup.ros_args).map_err(anyhow::Error::msg)?;
    log::set_level(ros.log_level);
    let mut params = NodeParams::default();
    for (k, v) in &ros.params {
        params.set(k, v).map_err(anyhow::Error::msg)?;
    }
    let desc = MachineDescription::load(setup.config.as_deref())?;
    let rotor = Rotor::from_description(&desc);
    prepare_tables(&params, &ros, &rotor)?;
    let domain = domain_id()?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    runtime.block_on(run_async(setup, ros, params, rotor, domain, started))
}

/// The film tables, before the node joins the bus (so that the first speed starts the twin at
/// once): from the cache (`film_cache`, `film_cache_dir`) or built and stored there.
fn prepare_tables(params: &NodeParams, ros: &RosArgs, rotor: &Rotor) -> anyhow::Result<()> {
    if !params.film_cache {
        crate::film::set_disk_cache(None);
    } else if !params.film_cache_dir.is_empty() {
        let dir = crate::film::TableCache::new(&params.film_cache_dir);
        crate::film::set_disk_cache(Some(dir));
    }
    if params.film != crate::dynamics::FilmEvaluation::Table
        || params.model == crate::driver::ModelKind::Linear
    {
        return Ok(());
    }
    let info = ros.log_level <= LogLevel::Info;
    if info {
        let cache = crate::film::disk_cache().map(|c| c.dir().display().to_string());
        log::info(&format!(
            "film tables (cache: {}): read, or built in about 11 s on 2 idle cores…",
            cache.as_deref().unwrap_or("off")
        ));
    }
    let start = std::time::Instant::now();
    let origins = crate::dynamics::prepare_film_tables(rotor)?;
    if info {
        let said: Vec<String> = origins.iter().map(ToString::to_string).collect();
        log::info(&format!(
            "film tables ready in {:.2} s ({})",
            start.elapsed().as_secs_f64(),
            said.join("; ")
        ));
    }
    Ok(())
}

/// The node's life: DDS participant, readers and writers, model thread, until a signal.
async fn run_async(
    setup: NodeSetup,
    ros: RosArgs,
    params: NodeParams,
    rotor: Rotor,
    domain: u16,
    started: std::time::Instant,
) -> anyhow::Result<()> {
    let context = dds_context(domain)?;
    // parameters that may change at run time are shared with the model thread
    let live: model::LiveParams = (
        Arc::new(Mutex::new(params.clone())),
        Arc::new(std::sync::atomic::AtomicU64::new(0)),
    );
    let mut node = context
        .new_node(
            NodeName::new(&ros.namespace, &ros.node_name)
                .map_err(|e| anyhow::anyhow!("node name {}: {e:?}", ros.fully_qualified_name()))?,
            node_options(),
        )
        .map_err(|e| anyhow::anyhow!("node: {e:?}"))?;
    let publishers = Publishers::create(&mut node, &ros, &rotor)?;
    let counters = Arc::new(model::NodeCounters::default());
    follow_readers(&setup, &context, &publishers, &counters);

    let stop = Arc::new(AtomicBool::new(false));
    let (recorder_thread, rec) = start_recorder(&setup, &params, &rotor, &stop)?;

    // the model thread and the publishing thread
    let inbox = Arc::new(Mutex::new(Inbox::default()));
    let clock = Arc::new(NodeClock {
        sim: params.use_sim_time,
        ..NodeClock::default()
    });
    let (out_tx, out_rx) = mpsc::sync_channel::<model::Published>(4096);
    let mut model = model::ModelLoop::new(
        rotor.clone(),
        params.clone(),
        live.clone(),
        inbox.clone(),
        clock.clone(),
    );
    model.set_node_name(&ros.fully_qualified_name());
    model.set_counters(counters.clone());
    let model_thread = spawn_model(model, out_tx, &stop)?;
    let publish_thread = publishers.spawn(out_rx, rec.clone(), counters.clone())?;

    let route = InputRoute {
        inbox,
        clock: clock.clone(),
        rec,
        counters: counters.clone(),
        model: model_thread.thread().clone(),
    };
    subscribe_inputs(&mut node, &ros, &params, &rotor, &route)?;
    drop(route);
    // no ros2-client Spinner: it would add a builtin_interfaces/Time reader on /clock
    let store = param_services::ParameterStore::declare(
        &mut node,
        &ros.fully_qualified_name(),
        declared_parameters(&params),
        live,
        clock,
    )?;
    let services =
        param_services::ParameterServices::create(&mut node, &ros.fully_qualified_name(), store)?;
    log::to_rosout(node.logging_handle(), &ros.fully_qualified_name());
    announce_up(&ros, domain, started);
    until_stopped(&services, &counters, &recorder_thread).await?;
    log::info("shutting down");
    drop(services);
    stop.store(true, Ordering::Relaxed);
    join_reporting_panic(model_thread, "model");
    join_reporting_panic(publish_thread, "publishing");
    drop(node);
    match recorder_thread {
        Some(t) => finish_recording(t, &ros),
        None => Ok(()),
    }
}

/// The model thread: steps the twin and sends what it publishes to `out` until `stop`.
fn spawn_model(
    model: model::ModelLoop,
    out: mpsc::SyncSender<model::Published>,
    stop: &Arc<AtomicBool>,
) -> std::io::Result<std::thread::JoinHandle<()>> {
    let stop = stop.clone();
    std::thread::Builder::new()
        .name("rotor_twin model".into())
        .spawn(move || model.run(out, stop))
}

/// The start-up line (at log level info) and the ROS arguments that have no effect.
fn announce_up(ros: &RosArgs, domain: u16, started: std::time::Instant) {
    log::info(&format!(
        "node {} up on ROS domain {domain} {:.2} s after start; waiting for {}",
        ros.fully_qualified_name(),
        started.elapsed().as_secs_f64(),
        speed_topic_label(ros)
    ));
    if !ros.ignored.is_empty() {
        log::warn(&format!(
            "ROS argument(s) without effect here, ignored: {}",
            ros.ignored.join(", ")
        ));
    }
}

/// Joins a node thread at shutdown; a panic in it is reported (it was dropped with `let _`).
fn join_reporting_panic(thread: std::thread::JoinHandle<()>, name: &str) {
    if thread.join().is_err() {
        log::error(&format!("the {name} thread panicked before shutdown"));
    }
}

/// Serves the parameters until SIGINT or SIGTERM; a recording that stops before (a full disk)
/// is an ERROR, and the twin keeps running: the bus still gets its outputs.
async fn until_stopped(
    services: &param_services::ParameterServices,
    counters: &model::NodeCounters,
    recorder_thread: &Option<std::thread::JoinHandle<anyhow::Result<PathBuf>>>,
) -> anyhow::Result<()> {
    let watch = watch_recording(counters, recorder_thread);
    let serve = services.serve();
    tokio::pin!(serve);
    let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
    tokio::select! {
        _ = tokio::signal::ctrl_c() => {},
        _ = term.recv() => {},
        _ = &mut serve => {},
        _ = watch => {
            tokio::select! {
                _ = tokio::signal::ctrl_c() => {},
                _ = term.recv() => {},
                _ = &mut serve => {},
            }
        }
    }
    Ok(())
}

/// Resolves when the recorder thread has ended before the node (its error is reported when the
/// node stops): the diagnostics turn ERROR and the log says so at once. Never resolves without a
/// recording.
async fn watch_recording(
    counters: &model::NodeCounters,
    thread: &Option<std::thread::JoinHandle<anyhow::Result<PathBuf>>>,
) {
    if thread.is_none() {
        return futures::future::pending().await;
    }
    loop {
        tokio::time::sleep(std::time::Duration::from_millis(200)).await;
        if thread.as_ref().is_some_and(|t| t.is_finished()) {
            counters.recording_failed.store(true, Ordering::Relaxed);
            log::error("the recording stopped before the node; nothing more is recorded");
            return;
        }
    }
}

/// The recorder thread and its queue, when `--record` asks for one.
type Recording = (
    Option<std::thread::JoinHandle<anyhow::Result<PathBuf>>>,
    Option<mpsc::SyncSender<ToRecord>>,
);

fn start_recorder(
    setup: &NodeSetup,
    params: &NodeParams,
    rotor: &Rotor,
    stop: &Arc<AtomicBool>,
) -> anyhow::Result<Recording> {
    let Some(dir) = &setup.record else {
        return Ok((None, None));
    };
    let (tx, rx) = mpsc::sync_channel::<ToRecord>(65_536);
    let orbits = crate::viewer::BearingOrbits::new(rotor);
    let thread = recording::spawn(dir, setup.record_split, params, orbits, rx, stop.clone())?;
    Ok((Some(thread), Some(tx)))
}

/// Waits for the recorder: the subscription tasks hold senders, so it stops after its last
/// flush once the runtime's tasks are gone. A failed recording is the node's error (non-zero
/// exit): data was lost.
fn finish_recording(
    t: std::thread::JoinHandle<anyhow::Result<PathBuf>>,
    ros: &RosArgs,
) -> anyhow::Result<()> {
    match t.join() {
        Ok(Ok(dir)) => {
            if ros.log_level <= LogLevel::Info {
                log::info(&format!("recording finished in {}", dir.display()));
            }
            Ok(())
        }
        Ok(Err(e)) => Err(e.context("the recording failed (what was written stays readable; `rotor-twin bag recover` completes it)")),
        Err(_) => anyhow::bail!("the recorder thread panicked"),
    }
}

/// The DDS context on `domain`: on the loopback interface only when the environment asks for
/// discovery on this host.
fn dds_context(domain: u16) -> anyhow::Result<Context> {
    for notice in discovery_notices(|name| std::env::var(name).ok()) {
        log::warn(&notice);
    }
    if discovery_localhost_only()? {
        // only the loopback interface for multicast and advertised locators
        let participant = ros2_client::dds::rustdds::DomainParticipantBuilder::new(domain)
            .with_only_networks([std::net::IpAddr::from([127, 0, 0, 1])])
            .build()
            .map_err(|e| anyhow::anyhow!("DDS participant: {e:?}"))?;
        Context::from_domain_participant(participant)
    } else {
        Context::with_options(ContextOptions::new().domain_id(domain))
    }
    .map_err(|e| anyhow::anyhow!("DDS context: {e:?}"))
}

/// A parameter value as the text [`NodeParams::set`] reads.
pub(super) fn parameter_text(v: &ParameterValue) -> Option<String> {
    match v {
        ParameterValue::Double(d) => Some(d.to_string()),
        ParameterValue::Integer(i) => Some(i.to_string()),
        ParameterValue::Boolean(b) => Some(b.to_string()),
        ParameterValue::String(s) => Some(s.clone()),
        _ => None,
    }
}

/// The node's options: /rosout on, no parameter services of ros2-client's and no parameters in
/// its store (ours are in [`param_services::ParameterStore`], declared by
/// [`declared_parameters`]).
fn node_options() -> NodeOptions {
    NodeOptions::new()
        .enable_rosout(true)
        .start_parameter_services(false)
}

/// Every parameter of the node with its start value, in declaration order.
fn declared_parameters(params: &NodeParams) -> Vec<(&'static str, ParameterValue)> {
    let probe_points = params
        .probe_point_topics
        .iter()
        .map(|(s, t)| format!("{s}={t}"))
        .collect::<Vec<_>>()
        .join(",");
    let text = |s: String| ParameterValue::String(s);
    let mut declared = vec![
        ("model", text(params.model.to_string())),
        ("delta", ParameterValue::Double(params.delta)),
        ("film", text(params.film_text().into())),
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
        ("speed_type", text(params.speed_type.to_string())),
        ("speed_unit", text(params.speed_unit.to_string())),
        ("probe_point_topics", text(probe_points)),
        ("use_sim_time", ParameterValue::Boolean(params.use_sim_time)),
        ("film_cache", ParameterValue::Boolean(params.film_cache)),
        ("film_cache_dir", text(params.film_cache_dir.clone())),
        (
            "warning_amplitude_ratio",
            ParameterValue::Double(params.warning_amplitude_ratio),
        ),
    ];
    declared.extend(forecast_parameters(params));
    declared.extend(plant_signal_parameters(params));
    declared
}

/// The plant-signal parameters (issue 12) as declared.
fn plant_signal_parameters(params: &NodeParams) -> Vec<(&'static str, ParameterValue)> {
    let signals = params
        .probe_signal_topics
        .iter()
        .map(|(p, t)| format!("{p}={t}"))
        .collect::<Vec<_>>()
        .join(",");
    vec![
        (
            "keyphasor_type",
            ParameterValue::String(params.keyphasor_type.to_string()),
        ),
        ("probe_signal_topics", ParameterValue::String(signals)),
        (
            "calibration_period_s",
            ParameterValue::Double(params.calibration_period_s),
        ),
        (
            "calibration_apply",
            ParameterValue::Boolean(params.calibration_apply),
        ),
    ]
}

/// The forecast's parameters (issue 14) as declared.
fn forecast_parameters(params: &NodeParams) -> [(&'static str, ParameterValue); 3] {
    let offsets = params
        .forecast_offsets_rpm
        .iter()
        .map(f64::to_string)
        .collect::<Vec<_>>()
        .join(",");
    [
        (
            "forecast_period_s",
            ParameterValue::Double(params.forecast_period_s),
        ),
        (
            "forecast_horizon_s",
            ParameterValue::Double(params.forecast_horizon_s),
        ),
        ("forecast_offsets_rpm", ParameterValue::String(offsets)),
    ]
}

/// The node's publishers, one per output topic (QoS from [`crate::topics`]).
struct Publishers {
    journal: ros2_client::Publisher<messages::JournalState>,
    film: ros2_client::Publisher<messages::FilmState>,
    orbit: ros2_client::Publisher<messages::Orbit>,
    /// each bearing's orbit for viewers, at most `VIEWER_MAX_HZ` (crate::viewer)
    bearing_orbits: Vec<ros2_client::Publisher<messages::Orbit>>,
    orbit_routes: crate::viewer::BearingOrbits,
    warning: ros2_client::Publisher<messages::InstabilityWarning>,
    diagnostics: ros2_client::Publisher<messages::DiagnosticArray>,
    residual: ros2_client::Publisher<messages::OrbitResidual>,
    margin: ros2_client::Publisher<messages::StabilityMargin>,
    forecast: ros2_client::Publisher<messages::Forecast>,
    one_x: ros2_client::Publisher<messages::OneXVectors>,
    calibration: ros2_client::Publisher<messages::CalibrationEstimate>,
}

fn publisher<M: RosMessage>(
    node: &mut ros2_client::Node,
    ros: &RosArgs,
    name: &str,
    qos: TopicQos,
) -> anyhow::Result<ros2_client::Publisher<M>> {
    let topic = node
        .create_topic(&topic_name(ros, name)?, type_name::<M>(), &qos_profile(qos))
        .map_err(|e| anyhow::anyhow!("topic {name}: {e:?}"))?;
    node.create_publisher::<M>(&topic, None)
        .map_err(|e| anyhow::anyhow!("publisher {name}: {e:?}"))
}

/// Without a recording (which wants every output), only the outputs with a reader are published
/// from now on ([`model::Audience`]), followed by [`watch_readers`].
fn follow_readers(
    setup: &NodeSetup,
    context: &Context,
    publishers: &Publishers,
    counters: &Arc<model::NodeCounters>,
) {
    if setup.record.is_some() {
        return;
    }
    counters.audience.watch();
    tokio::spawn(watch_readers(
        context.domain_participant(),
        publishers.gated(),
        counters.clone(),
    ));
}

/// Follows which readers on the bus are matched to the writers of the gated outputs (`gated`:
/// writer and output) from the participant's status events (the node runs no
/// ros2-client Spinner, which would keep this count), and tells the model thread.
async fn watch_readers(
    participant: ros2_client::dds::rustdds::DomainParticipant,
    gated: Vec<(ros2_client::dds::rustdds::GUID, model::Gated)>,
    counters: Arc<model::NodeCounters>,
) {
    use ros2_client::dds::rustdds::{DomainParticipantStatusEvent as Event, StatusEvented};
    let listener = participant.status_listener();
    let mut events = listener.as_async_status_stream();
    let mut readers = vec![std::collections::BTreeSet::new(); gated.len()];
    while let Some(event) = events.next().await {
        match event {
            Event::RemoteReaderMatched {
                local_writer,
                remote_reader,
            } => {
                if let Some(k) = gated.iter().position(|g| g.0 == local_writer) {
                    readers[k].insert(remote_reader);
                }
            }
            Event::ReaderLost { guid, .. } => readers.iter_mut().for_each(|r| {
                r.remove(&guid);
            }),
            _ => continue,
        }
        // an output has an audience if any of its writers has a reader
        for (_, g) in &gated {
            let heard = gated
                .iter()
                .zip(&readers)
                .any(|((_, h), r)| h == g && !r.is_empty());
            counters.audience.set(*g, heard);
        }
    }
}

impl Publishers {
    /// The writers of the outputs published only to a reader (the per-bearing orbit topics
    /// are made from the orbits: a reader of any of them is a reader of the orbits).
    fn gated(&self) -> Vec<(ros2_client::dds::rustdds::GUID, model::Gated)> {
        use model::Gated;
        let mut gated = vec![
            (self.journal.guid(), Gated::Journal),
            (self.film.guid(), Gated::Film),
            (self.orbit.guid(), Gated::Orbit),
            (self.residual.guid(), Gated::Residual),
        ];
        gated.extend(self.bearing_orbits.iter().map(|w| (w.guid(), Gated::Orbit)));
        gated
    }

    fn create(node: &mut ros2_client::Node, ros: &RosArgs, rotor: &Rotor) -> anyhow::Result<Self> {
        use crate::topics as qos;
        let orbit_routes = crate::viewer::BearingOrbits::new(rotor);
        let bearing_orbits = orbit_routes
            .topics()
            .iter()
            .map(|t| publisher(node, ros, t, qos::STATE))
            .collect::<anyhow::Result<_>>()?;
        Ok(Self {
            bearing_orbits,
            orbit_routes,
            journal: publisher(node, ros, JOURNAL, qos::STATE)?,
            film: publisher(node, ros, FILM, qos::STATE)?,
            orbit: publisher(node, ros, ORBIT, qos::STATE)?,
            warning: publisher(node, ros, WARNING, qos::WARNING_QOS)?,
            diagnostics: publisher(node, ros, DIAGNOSTICS, qos::STATE)?,
            residual: publisher(node, ros, RESIDUAL, qos::STATE)?,
            margin: publisher(node, ros, MARGIN, qos::MARGIN_QOS)?,
            forecast: publisher(node, ros, qos::FORECAST, qos::FORECAST_QOS)?,
            one_x: publisher(node, ros, qos::ONE_X, qos::STATE)?,
            calibration: publisher(node, ros, qos::CALIBRATION, qos::CALIBRATION_QOS)?,
        })
    }

    /// The publishing thread: publishes what the model sends (a full send window drops the
    /// sample: the model is never blocked) and hands it to the recorder.
    fn spawn(
        mut self,
        out: mpsc::Receiver<Published>,
        rec: Option<mpsc::SyncSender<ToRecord>>,
        counters: Arc<model::NodeCounters>,
    ) -> std::io::Result<std::thread::JoinHandle<()>> {
        std::thread::Builder::new()
            .name("rotor_twin publish".into())
            .spawn(move || {
                for item in out {
                    let t = now_ns();
                    let sent = match &item {
                        Published::Twin(o) => self.publish_twin(o),
                        Published::OneX(m) => self.one_x.publish(m.clone()).is_ok(),
                        Published::Calibration(m) => {
                            self.calibration.publish((**m).clone()).is_ok()
                        }
                    };
                    if !sent {
                        counters.publish_failed.fetch_add(1, Ordering::Relaxed);
                    }
                    if let Some(rec) = &rec {
                        counters.record(rec, ToRecord::Out(item, t));
                    }
                }
            })
    }
}

impl Publishers {
    /// Publishes one of the twin's messages; false if the bus refused it.
    fn publish_twin(&mut self, item: &Outgoing) -> bool {
        // each bearing's orbit also on its viewer topic, when the rate rule keeps it
        let viewer_sent = match item {
            Outgoing::Orbit(m) => match self.orbit_routes.route(m) {
                Some(k) => self.bearing_orbits[k].publish(m.clone()).is_ok(),
                None => true,
            },
            _ => true,
        };
        let sent = match item {
            Outgoing::Journal(m) => self.journal.publish(m.clone()).is_ok(),
            Outgoing::Film(m) => self.film.publish(m.clone()).is_ok(),
            Outgoing::Orbit(m) => self.orbit.publish(m.clone()).is_ok(),
            Outgoing::Warning(m) => self.warning.publish(m.clone()).is_ok(),
            Outgoing::Diagnostics(m) => self.diagnostics.publish(m.clone()).is_ok(),
            Outgoing::Residual(m) => self.residual.publish(m.clone()).is_ok(),
            Outgoing::Margin(m) => self.margin.publish(m.clone()).is_ok(),
            Outgoing::Forecast(m) => self.forecast.publish((**m).clone()).is_ok(),
        };
        viewer_sent && sent
    }
}

/// Every input subscription: the speed (of the configured type), the unbalance, the probes and
/// the PointStamped probe pairs; /clock under use_sim_time.
fn subscribe_inputs(
    node: &mut ros2_client::Node,
    ros: &RosArgs,
    params: &NodeParams,
    rotor: &Rotor,
    route: &InputRoute,
) -> anyhow::Result<()> {
    use crate::topics as qos;
    let speed_topic = topic_name(ros, SPEED)?;
    if params.speed_type == SpeedType::Float64 {
        let unit = params.speed_unit;
        route.subscribe::<messages::Float64>(
            node,
            &speed_topic,
            qos::SENSOR_READER,
            move |m| Ok(Input::speed_value(m.data, unit)),
            ToRecord::Speed64,
        )?;
    } else {
        route.subscribe::<messages::RotorSpeed>(
            node,
            &speed_topic,
            qos::SENSOR_READER,
            |m| Ok(Input::from(m)),
            ToRecord::Speed,
        )?;
    }
    route.subscribe::<messages::Unbalance>(
        node,
        &topic_name(ros, UNBALANCE)?,
        qos::COMMAND_READER,
        |m| Ok(Input::from(m)),
        ToRecord::Unbalance,
    )?;
    route.subscribe::<messages::ProbeDisplacement>(
        node,
        &topic_name(ros, PROBE)?,
        qos::SENSOR_READER,
        |m| Ok(Input::from(m)),
        ToRecord::Probe,
    )?;
    // --- oil supply temperature (issue 12): sensor_msgs/Temperature (°C), best effort ---
    route.subscribe::<messages::Temperature>(
        node,
        &topic_name(ros, crate::topics::OIL_TEMPERATURE)?,
        qos::SENSOR_READER,
        |m| Ok(Input::from(m)),
        ToRecord::Temperature,
    )?;
    // --- end oil supply temperature ---
    // probe pairs as geometry_msgs/PointStamped (x, y in m), one topic per station
    let stations = rotor.probes.iter().map(|p| p.name.as_str());
    let mapped = mapped_topics(&params.probe_point_topics, stations, &POINT_TOPICS)?;
    for (i, k, name) in mapped {
        route.subscribe::<messages::PointStamped>(
            node,
            &name,
            qos::SENSOR_READER,
            move |m| Ok(Input::probe_point(m, k)),
            move |m, t| ToRecord::Point(i, m, t),
        )?;
    }
    subscribe_plant_signals(node, ros, params, rotor, route)?;
    if params.use_sim_time {
        // rosgraph_msgs/Clock on /clock (ros2-client's own /clock handling uses another type)
        subscribe_clock(node, &topic_name(ros, CLOCK)?, route)?;
    }
    Ok(())
}

/// The plant's signals (issue 12), best effort: keyphasor events (rotor_twin_msgs/Keyphasor, or
/// std_msgs/Header with `keyphasor_type:=header`), raw probe readings (rotor_twin_msgs/ProbeSignal,
/// and one std_msgs/Float64 topic per probe named in `probe_signal_topics`).
fn subscribe_plant_signals(
    node: &mut ros2_client::Node,
    ros: &RosArgs,
    params: &NodeParams,
    rotor: &Rotor,
    route: &InputRoute,
) -> anyhow::Result<()> {
    use crate::topics as qos;
    let keyphasor = topic_name(ros, qos::KEYPHASOR)?;
    match params.keyphasor_type {
        KeyphasorType::Keyphasor => route.subscribe::<messages::Keyphasor>(
            node,
            &keyphasor,
            qos::SENSOR_READER,
            |m| Ok(Input::from(m)),
            ToRecord::Keyphasor,
        )?,
        KeyphasorType::Header => route.subscribe::<messages::Header>(
            node,
            &keyphasor,
            qos::SENSOR_READER,
            |m| Ok(Input::from(m)),
            ToRecord::KeyphasorHeader,
        )?,
    }
    route.subscribe::<messages::ProbeSignal>(
        node,
        &topic_name(ros, qos::PROBE_SIGNAL)?,
        qos::SENSOR_READER,
        |m| Ok(Input::from(m)),
        ToRecord::ProbeSignal,
    )?;
    let probes = rotor.proximity_probes.iter().map(|p| p.name.as_str());
    let mapped = mapped_topics(&params.probe_signal_topics, probes, &SIGNAL_TOPICS)?;
    for (i, k, name) in mapped {
        route.subscribe::<messages::Float64>(
            node,
            &name,
            qos::SENSOR_READER,
            move |m| Ok(Input::probe_value(m.data, k)),
            move |m, t| ToRecord::ProbeValue(i, m, t),
        )?;
    }
    Ok(())
}

/// A topic-mapping parameter, for its errors: its name, what it maps, where those are listed.
struct Mapping(&'static str, &'static str, &'static str);

const POINT_TOPICS: Mapping = Mapping("probe_point_topics", "station", "the machine description");
const SIGNAL_TOPICS: Mapping = Mapping(
    "probe_signal_topics",
    "probe",
    "the machine description's proximity_probes",
);

/// The `name=/topic` pairs of a topic-mapping parameter (`probe_point_topics`,
/// `probe_signal_topics`) as (pair index, index of the name among `known`, topic); a name not
/// known or a topic that does not parse is an error naming the parameter and the value.
fn mapped_topics<'a>(
    pairs: &[(String, String)],
    known: impl Iterator<Item = &'a str> + Clone,
    mapping: &Mapping,
) -> anyhow::Result<Vec<(usize, usize, Name)>> {
    let Mapping(parameter, what, where_known) = mapping;
    let mut mapped = Vec::with_capacity(pairs.len());
    for (i, (entry, topic_text)) in pairs.iter().enumerate() {
        let k = known.clone().position(|n| n == entry).ok_or_else(|| {
            anyhow::anyhow!("parameter {parameter}: {what} '{entry}' is not in {where_known}")
        })?;
        let name = Name::parse(topic_text)
            .map_err(|e| anyhow::anyhow!("topic name '{topic_text}': {e:?}"))?;
        mapped.push((i, k, name));
    }
    Ok(mapped)
}

fn speed_topic_label(ros: &RosArgs) -> String {
    topic_name(ros, SPEED).map_or_else(|_| SPEED.to_string(), |n| n.to_string())
}

/// Where a subscription's samples go: decoded, recorded as received, queued with the receive
/// time on the node's clock for the model thread. A sample that does not decode is queued as a
/// refusal (counted and warned about by the driver) and the subscription lives on.
struct InputRoute {
    inbox: Arc<Mutex<Inbox>>,
    clock: Arc<NodeClock>,
    rec: Option<mpsc::SyncSender<ToRecord>>,
    counters: Arc<model::NodeCounters>,
    /// the model thread, woken at once by a speed or unbalance (issue 17: it otherwise wakes
    /// every [`model::WAKE_PERIOD`])
    model: std::thread::Thread,
}

impl InputRoute {
    fn subscribe<M>(
        &self,
        node: &mut ros2_client::Node,
        name: &Name,
        qos: TopicQos,
        to_input: impl Fn(&M) -> Result<Input, String> + Send + 'static,
        to_record: impl Fn(M, i64) -> ToRecord + Send + 'static,
    ) -> anyhow::Result<()>
    where
        M: RosMessage + Send + Sync + 'static,
    {
        let topic = node
            .create_topic(name, type_name::<M>(), &qos_profile(qos))
            .map_err(|e| anyhow::anyhow!("topic {name:?}: {e:?}"))?;
        let sub = node
            .create_subscription::<M>(&topic, Some(qos_profile(qos)))
            .map_err(|e| anyhow::anyhow!("subscription {name:?}: {e:?}"))?;
        let (inbox, clock, rec) = (self.inbox.clone(), self.clock.clone(), self.rec.clone());
        let counters = self.counters.clone();
        let model = self.model.clone();
        let label = name.to_string();
        let topic_index = counters.add_topic(&label);
        tokio::spawn(async move {
            let mut stream = Box::pin(sub.async_stream());
            let mut gaps = loss::SequenceGaps::default();
            while let Some(item) = stream.next().await {
                let at = clock.now_ns();
                let queued = match item {
                    Ok((m, info)) => {
                        let lost = gaps.sample(info.publisher_gid(), info.sequence_number());
                        counters.lost(topic_index, lost);
                        let input = to_input(&m);
                        if let Some(rec) = &rec {
                            counters.record(rec, to_record(m, now_ns()));
                        }
                        input
                    }
                    Err(e) => {
                        gaps.undecoded();
                        Err(format!("{label}: a sample that does not decode ({e:?})"))
                    }
                };
                let command = matches!(queued, Ok(Input::Speed { .. } | Input::Unbalance { .. }));
                inbox
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(model::Queued {
                        received_ns: at,
                        input: queued,
                    });
                if command {
                    model.unpark();
                }
            }
        });
        Ok(())
    }
}

/// The /clock subscription under use_sim_time: the node's clock follows it as
/// [`crate::driver::SimClock`] decides; a refused sample is queued as a refusal (counted, warned
/// about and shown in /diagnostics by the driver), a jump is logged.
fn subscribe_clock(
    node: &mut ros2_client::Node,
    name: &Name,
    route: &InputRoute,
) -> anyhow::Result<()> {
    use crate::driver::ClockSample;
    let qos = crate::topics::CLOCK_READER;
    let topic = node
        .create_topic(name, type_name::<messages::Clock>(), &qos_profile(qos))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let sub = node
        .create_subscription::<messages::Clock>(&topic, Some(qos_profile(qos)))
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let (clock, inbox) = (route.clock.clone(), route.inbox.clone());
    tokio::spawn(async move {
        let mut stream = Box::pin(sub.async_stream());
        while let Some(item) = stream.next().await {
            let Ok((m, _info)) = item else { continue };
            let ns = m.clock.as_nanos();
            let s = |t: i64| t as f64 * 1e-9;
            let taken = clock
                .sim_clock
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .offer(ns);
            match taken {
                ClockSample::Taken => {}
                ClockSample::Refused { clock_ns } => {
                    let why = format!(
                        "/clock {:.6} s refused: {:+.3} s from the clock at {:.6} s (more than {} s ahead, or back; {} samples that agree make it jump)",
                        s(ns),
                        s(ns - clock_ns),
                        s(clock_ns),
                        crate::driver::CLOCK_JUMP_S,
                        crate::driver::CLOCK_CONFIRM
                    );
                    let mut inbox = inbox.lock().unwrap_or_else(|e| e.into_inner());
                    inbox.push(model::Queued {
                        received_ns: Some(clock_ns),
                        input: Err(why),
                    });
                }
                ClockSample::Jumped { from_ns } => log::info(&format!(
                    "/clock jumped from {:.6} s to {:.6} s",
                    s(from_ns),
                    s(ns)
                )),
            }
        }
    });
    Ok(())
}

#[cfg(test)]
mod discovery_tests {
    #[test]
    fn static_peers_and_off_are_said_not_honoured() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |name: &str| {
                pairs
                    .iter()
                    .find(|(n, _)| *n == name)
                    .map(|(_, v)| v.to_string())
            }
        };
        assert!(super::discovery_notices(env(&[])).is_empty());
        let n = super::discovery_notices(env(&[
            ("ROS_STATIC_PEERS", "10.0.0.2;host-b"),
            ("ROS_AUTOMATIC_DISCOVERY_RANGE", "OFF"),
        ]));
        assert_eq!(n.len(), 2, "{n:?}");
        assert!(n[0].contains("10.0.0.2;host-b") && n[1].contains("OFF"));
        let n = super::discovery_notices(env(&[("ROS_AUTOMATIC_DISCOVERY_RANGE", "SUBNET")]));
        assert!(n.is_empty());
    }
}
