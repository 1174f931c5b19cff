//! Replay: a recorded bag through the twin, in bag time. The bag's topics are mapped to the
//! twin's inputs (after remapping), the twin is stepped up to each message's receive time, and
//! every input and prediction goes to an output bag; measured probe orbits are compared with the
//! predicted ones (see [`compare`]). The same [`Session`] the live node runs does the modelling,
//! so a replay predicts what the node would have published, and two replays of one bag are
//! identical.

pub mod calibration;
pub mod compare;
mod forecast;
pub mod orbit_shape;
mod output;
mod report;

pub use forecast::{observed_whip_s, ReplayForecast, DEFAULT_REPLAY_FORECAST_PERIOD_S};

pub use report::{
    CenterlineStatic, KeyphasorReport, OilReport, OnsetReport, ReplayReport, StateChange,
    StationReport,
};

use crate::bag::{Bag, BagMessage};
use crate::driver::{settings, Driver, DriverSettings, Fed, Input, SpeedUnit};
use crate::dynamics::{Coupling, FilmEvaluation, TwinConfig};
use crate::messages::{self, from_cdr, RosMessage};
use crate::rotor::Rotor;
use crate::session::{Outgoing, SessionSettings};
use compare::{Sample, StationComparison};
use output::{OutputBag, OutputWriter};
use std::path::PathBuf;
use thiserror::Error;

/// The keyphasor and raw-probe input topics (issue 12).
pub use crate::topics::{KEYPHASOR as KEYPHASOR_TOPIC, PROBE_SIGNAL as PROBE_SIGNAL_TOPIC};
/// The twin's input topics (before remapping, the names the node uses).
pub use crate::topics::{PROBE as PROBE_TOPIC, SPEED as SPEED_TOPIC, UNBALANCE as UNBALANCE_TOPIC};

/// How to replay.
#[derive(Debug, Clone)]
pub struct ReplayOptions {
    /// Bearing coupling of the twin.
    pub coupling: Coupling,
    /// Time steps per revolution at rated speed.
    pub steps_per_rev: usize,
    /// Film evaluation.
    pub film: FilmEvaluation,
    /// Output rates and thresholds.
    pub session: SessionSettings,
    /// Below this speed (rad/s) the twin pauses.
    pub min_speed_rad_s: f64,
    /// Topic remappings `from → to`, applied to the bag's topic names.
    pub remaps: Vec<(String, String)>,
    /// Unit of a std_msgs/Float64 speed.
    pub speed_unit: SpeedUnit,
    /// geometry_msgs/PointStamped probe topics (after remapping) → probe station name.
    pub probe_points: Vec<(String, String)>,
    /// std_msgs/Float64 raw-probe topics (after remapping) → raw probe name (issue 12).
    pub probe_signals: Vec<(String, String)>,
    /// Bag time per wall time (None: as fast as the model runs).
    pub rate: Option<f64>,
    /// Replay only the first this many seconds of the bag.
    pub duration_s: Option<f64>,
    /// Where to write the output bag (None: no output bag).
    pub out_bag: Option<PathBuf>,
    /// A gap between messages longer than this (s) stops the twin; it restarts at the next
    /// speed message (a bag spanning a pause is not modelled through the pause).
    pub max_gap_s: f64,
    /// Forecasts at bag time, scored in the report (`--forecast`; None: none).
    pub forecast: Option<ReplayForecast>,
}

impl ReplayOptions {
    /// How a calibration for this replay's twin is refined: on its film and steps a revolution
    /// when it is nonlinear; None for a linear twin (the linear fit is its best).
    pub fn calibration_refinement(&self) -> Option<crate::calibrate::NonlinearRefinement> {
        (self.coupling != Coupling::Linear).then_some(crate::calibrate::NonlinearRefinement {
            film: self.film,
            steps_per_rev: self.steps_per_rev,
        })
    }
}

impl Default for ReplayOptions {
    fn default() -> Self {
        Self {
            coupling: Coupling::Nonlinear,
            steps_per_rev: settings::DEFAULT_STEPS_PER_REV,
            film: FilmEvaluation::Table,
            session: SessionSettings::default(),
            min_speed_rad_s: crate::units::rpm_to_rad_s(settings::DEFAULT_MIN_SPEED_RPM),
            remaps: Vec::new(),
            speed_unit: SpeedUnit::Rpm,
            probe_points: Vec::new(),
            probe_signals: Vec::new(),
            rate: None,
            duration_s: None,
            out_bag: None,
            max_gap_s: 5.0,
            forecast: None,
        }
    }
}

impl ReplayOptions {
    /// The driver's settings for a twin of `rotor`: the node's defaults where the options say
    /// nothing. Speed stamps are not checked (bags from other tools stamp on other clocks; the
    /// receive time orders the samples); probe stamps off the bag's clock fall back to the
    /// receive time.
    pub fn driver_settings(&self, rotor: &Rotor) -> DriverSettings {
        DriverSettings {
            twin: TwinConfig {
                film: self.film,
                ..TwinConfig::with_steps_per_rev(
                    self.coupling,
                    rotor.rated_speed_rad_s,
                    self.steps_per_rev,
                )
            },
            session: self.session,
            min_speed_rad_s: self.min_speed_rad_s,
            max_gap_s: self.max_gap_s,
            check_speed_stamps: false,
            ..DriverSettings::new(Default::default(), self.film, rotor.rated_speed_rad_s)
        }
    }
}

/// Why a replay cannot run.
#[derive(Debug, Error)]
pub enum ReplayError {
    /// A required topic is not in the bag.
    #[error("the bag has no topic {topic} ({why}); its topics: {present}")]
    MissingTopic {
        /// The topic (after remapping).
        topic: String,
        /// Why it is needed.
        why: String,
        /// The topics the bag has.
        present: String,
    },
    /// A mapped topic has a type the replay cannot use.
    #[error("topic {topic} has type '{found}'; expected {expected}")]
    WrongType {
        /// The topic.
        topic: String,
        /// Its type in the bag.
        found: String,
        /// What would do.
        expected: String,
    },
    /// An option names a probe station the machine does not have.
    #[error("probe station '{0}' is not in the machine description (its stations: {1})")]
    UnknownStation(String, String),
    /// The forecast's settings are refused.
    #[error("{0}")]
    Forecast(String),
    /// The output bag could not be written.
    #[error("output bag: {0}")]
    Record(#[from] crate::record::RecordError),
}

/// What a bag topic feeds.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    SpeedRotor,
    SpeedFloat,
    Unbalance,
    Probe,
    ProbePoint(usize),
    /// sensor_msgs/Temperature on the oil temperature topic (issue 12).
    OilTemperature,
    // plant signals (issue 12)
    Keyphasor,
    KeyphasorHeader,
    ProbeSignal,
    ProbeValue(usize),
    Other,
}

/// Replays `bag` through a twin of `rotor`. `progress` is called now and then with the share of
/// the bag done (0–1). Returns the report (with `wall_time_s` measured here) and the comparison
/// at each probe station (for plots).
pub fn replay(
    bag: &Bag,
    rotor: &Rotor,
    options: &ReplayOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<(ReplayReport, Vec<StationComparison>), ReplayError> {
    let wall = std::time::Instant::now();
    let (roles, comparisons) = roles_and_comparisons(bag, rotor, options)?;
    let mut out = match &options.out_bag {
        Some(dir) => Some(OutputWriter::start(
            OutputBag::create(dir, bag, rotor, &roles, options)?,
            dir,
        )?),
        None => None,
    };
    let Some((t0, t_last)) = bag.time_span_ns() else {
        return Ok((
            ReplayReport::empty(bag, wall.elapsed().as_secs_f64()),
            comparisons,
        ));
    };
    let t_end = match options.duration_s {
        Some(d) => t_last.min(t0.saturating_add((d * 1e9) as u64)),
        None => t_last,
    };
    let mut report = ReplayReport::empty(bag, 0.0);
    report.bag_duration_s = (t_end - t0) as f64 * 1e-9;
    let mut run = Replaying {
        driver: driver_for(bag, rotor, options, &roles),
        report,
        comparisons,
        emitted: Vec::new(),
        t0_ns: t0 as i64,
        forecasting: forecast::Forecasting::for_options(rotor, options, t0 as i64)?,
    };
    let mut last_progress = std::time::Instant::now();
    let mut messages = bag.messages();
    for m in messages.by_ref() {
        if m.log_time_ns > t_end {
            break;
        }
        run.message(bag, &m, roles[m.topic], options.speed_unit);
        run.forecast();
        let since_t0_ns = m.log_time_ns.saturating_sub(t0);
        run.write_out(m, out.as_mut())?;
        if let Some(rate) = options.rate {
            pace(since_t0_ns, rate, wall);
        }
        if last_progress.elapsed().as_millis() >= 200 {
            last_progress = std::time::Instant::now();
            progress(since_t0_ns as f64 / (t_end - t0).max(1) as f64);
        }
    }
    progress(1.0);
    run.report.notes.extend(messages.problems().iter().cloned());
    run.finish(out, wall)
}

/// The topic roles of `bag` for a twin of `rotor`, and an empty comparison for each of the
/// machine's probe stations.
fn roles_and_comparisons(
    bag: &Bag,
    rotor: &Rotor,
    options: &ReplayOptions,
) -> Result<(Vec<Role>, Vec<StationComparison>), ReplayError> {
    let stations: Vec<String> = rotor.probes.iter().map(|p| p.name.clone()).collect();
    let raw: Vec<String> = rotor
        .proximity_probes
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let roles = map_topics(bag, options, &stations, &raw)?;
    let clearance = rotor
        .bearings
        .iter()
        .filter_map(|b| match &b.model {
            crate::rotor::BearingModel::Film(f) => Some(f.geometry.radial_clearance_m),
            _ => None,
        })
        .fold(f64::INFINITY, f64::min);
    let raw_read = roles
        .iter()
        .any(|r| matches!(r, Role::ProbeSignal | Role::ProbeValue(_)));
    let comparisons = stations
        .iter()
        .zip(&rotor.probes)
        .enumerate()
        .map(|(k, (s, p))| {
            let mut c = StationComparison::new(s, clearance).with_axes(p.angles_rad);
            let ac = rotor.proximity_probes.iter().any(|r| {
                r.station == k && r.coupling == crate::signals::probes::ProbeCoupling::Ac
            });
            if raw_read && ac {
                c.mean_not_measured = Some(
                    "AC-coupled probes: the measured mean is the twin's, not the plant's (DC-coupled probes or displacement pairs keep it)".into(),
                );
            }
            c
        })
        .collect();
    Ok((roles, comparisons))
}

/// Sleeps until bag time `since_t0_ns` is due at `rate` times the bag's pace (`--rate`).
fn pace(since_t0_ns: u64, rate: f64, wall: std::time::Instant) {
    let due = since_t0_ns as f64 * 1e-9 / rate;
    let ahead = due - wall.elapsed().as_secs_f64();
    if ahead > 0.0 {
        std::thread::sleep(std::time::Duration::from_secs_f64(ahead));
    }
}

/// The driver of a replay of `bag` (topic roles `roles`) on `rotor`: the linear threshold
/// known, and, when the bag has keyphasor events, waiting for the first to start the twin.
fn driver_for(bag: &Bag, rotor: &Rotor, options: &ReplayOptions, roles: &[Role]) -> Driver {
    let mut driver = Driver::new(rotor.clone(), options.driver_settings(rotor));
    driver.set_threshold(crate::session::linear_threshold(rotor));
    let keyphasor_role = |r: &Role| matches!(r, Role::Keyphasor | Role::KeyphasorHeader);
    let has_messages = |t: usize| bag.topic_message_count(t) > 0;
    if (0..roles.len()).any(|t| keyphasor_role(&roles[t]) && has_messages(t)) {
        driver.expect_keyphasor();
    }
    driver
}

/// A replay under way: the driver, what it emitted for the message at hand, and the report and
/// comparisons being filled.
struct Replaying {
    driver: Driver,
    report: ReplayReport,
    comparisons: Vec<StationComparison>,
    emitted: Vec<Outgoing>,
    t0_ns: i64,
    /// `--forecast` (issue 14)
    forecasting: Option<forecast::Forecasting>,
}

impl Replaying {
    /// What the driver emitted for message `m` into the report and the output bag, then `m`
    /// itself into the output bag.
    fn write_out(
        &mut self,
        m: BagMessage,
        mut out: Option<&mut OutputWriter>,
    ) -> Result<(), ReplayError> {
        // exact: t0_ns is the bag's u64 start time cast to i64
        let t0 = self.t0_ns as u64;
        for o in self.emitted.drain(..) {
            self.report.note_output(&o, t0, self.driver.session_slot());
            if let Some(out) = out.as_deref_mut() {
                out.outgoing(o)?;
            }
        }
        if let Some(out) = out {
            out.input(m)?;
        }
        Ok(())
    }

    /// The finished report (wall time `wall`, up to the output bag closed; the forecast's score,
    /// the output bag's count) and the comparisons.
    fn finish(
        self,
        out: Option<OutputWriter>,
        wall: std::time::Instant,
    ) -> Result<(ReplayReport, Vec<StationComparison>), ReplayError> {
        let Replaying {
            mut report,
            mut comparisons,
            forecasting,
            driver,
            ..
        } = self;
        for c in &mut comparisons {
            c.finish(Some(driver.keyphasor_events()));
        }
        // the writer's backlog and the bag's summary count in the wall time
        if let Some(out) = out {
            report.messages_out = out.finish()?;
        }
        report.finish(&comparisons, wall.elapsed().as_secs_f64());
        report.heat_balance = driver.heat_balance_report();
        report.oil = driver.oil_temperature_k().map(|t| report::OilReport {
            supply_temperature_c: t - crate::film::ZERO_CELSIUS_K,
            viscosity_scales: (driver.film_oil().into_iter())
                .map(|f| (f.name, f.viscosity_scale))
                .collect(),
        });
        report.keyphasor = driver.expects_keyphasor().then(|| report::KeyphasorReport {
            relocks: driver.counts().relocks,
            speed_mismatches: driver.counts().speed_mismatches,
            speed_topic_scale: driver.speed_scale(),
        });
        report.forecast = forecasting.map(|f| f.finish(report.onset.observed_time_s, &comparisons));
        Ok((report, comparisons))
    }

    /// A forecast from the twin's present state, when one is due (`--forecast`).
    fn forecast(&mut self) {
        if let Some(f) = self.forecasting.as_mut() {
            f.after_message(&self.driver, &mut |o| self.emitted.push(o));
        }
    }

    /// One bag message of role `role` through the driver, at its receive time.
    fn message(&mut self, bag: &Bag, m: &BagMessage, role: Role, unit: SpeedUnit) {
        let t_ns = m.log_time_ns.min(i64::MAX as u64) as i64;
        let since_t0 = |t_ns: i64| (t_ns - self.t0_ns) as f64 * 1e-9;
        self.report.messages_in += 1;
        let topic = &bag.topics[m.topic].name;
        let emitted = &mut self.emitted;
        let fed = match decode(role, m.payload(), unit) {
            Ok(None) => {
                self.driver
                    .advance_to(t_ns, usize::MAX, &mut |o| emitted.push(o));
                return;
            }
            Ok(Some(input)) => self.driver.feed(t_ns, input, &mut |o| emitted.push(o)),
            Err(why) => {
                let why = format!("{topic}: {why}");
                self.driver
                    .advance_to(t_ns, usize::MAX, &mut |o| emitted.push(o));
                self.driver.refuse(t_ns, &why, &mut |o| emitted.push(o));
                Fed::Refused(why)
            }
        };
        match fed {
            Fed::Started { speed_rad_s } => self
                .report
                .note_start(since_t0(t_ns), crate::units::rad_s_to_rpm(speed_rad_s)),
            Fed::Compared(c) => self.comparisons[c.station].push(
                Sample::of(&c, since_t0(c.time_ns)),
                Some(self.driver.keyphasor_events()),
            ),
            Fed::Refused(why) => self.report.note_rejection(topic, &why),
            Fed::Taken | Fed::Unused => {}
        }
    }
}

/// The twin's input in a bag message of role `role` (None: a topic the twin does not use), or
/// why it cannot be decoded.
fn decode(role: Role, payload: &[u8], unit: SpeedUnit) -> Result<Option<Input>, String> {
    Ok(Some(match role {
        Role::SpeedRotor => Input::from(&from_cdr::<messages::RotorSpeed>(payload)?),
        Role::SpeedFloat => Input::speed_value(from_cdr::<messages::Float64>(payload)?.data, unit),
        Role::Unbalance => Input::from(&from_cdr::<messages::Unbalance>(payload)?),
        Role::Probe => Input::from(&from_cdr::<messages::ProbeDisplacement>(payload)?),
        Role::ProbePoint(k) => Input::probe_point(&from_cdr::<messages::PointStamped>(payload)?, k),
        Role::OilTemperature => Input::from(&from_cdr::<messages::Temperature>(payload)?),
        Role::Keyphasor => Input::from(&from_cdr::<messages::Keyphasor>(payload)?),
        Role::KeyphasorHeader => Input::from(&from_cdr::<messages::Header>(payload)?),
        Role::ProbeSignal => Input::from(&from_cdr::<messages::ProbeSignal>(payload)?),
        Role::ProbeValue(k) => Input::probe_value(from_cdr::<messages::Float64>(payload)?.data, k),
        Role::Other => return Ok(None),
    }))
}

/// Checks, before anything is written, that `bag` can drive a twin of `rotor` with `options`:
/// the speed topic is there (after remapping), mapped topics have usable types, named probe
/// stations exist.
pub fn check_mapping(bag: &Bag, rotor: &Rotor, options: &ReplayOptions) -> Result<(), ReplayError> {
    let stations: Vec<String> = rotor.probes.iter().map(|p| p.name.clone()).collect();
    let raw: Vec<String> = rotor
        .proximity_probes
        .iter()
        .map(|p| p.name.clone())
        .collect();
    map_topics(bag, options, &stations, &raw).map(|_| ())
}

/// The role of each bag topic, checking that the speed topic is there and the types fit.
fn map_topics(
    bag: &Bag,
    options: &ReplayOptions,
    stations: &[String],
    rotor_probes: &[String],
) -> Result<Vec<Role>, ReplayError> {
    check_probe_signal_names(options, rotor_probes)?;
    let remap = |name: &str| -> String {
        options
            .remaps
            .iter()
            .find(|(from, _)| from == name)
            .map_or(name.to_string(), |(_, to)| to.clone())
    };
    for (station, _) in options.probe_points.iter().map(|(t, s)| (s, t)) {
        if !stations.contains(station) {
            return Err(ReplayError::UnknownStation(
                station.clone(),
                stations.join(", "),
            ));
        }
    }
    let roles = bag
        .topics
        .iter()
        .map(|t| topic_role(t, &remap(&t.name), options, stations, rotor_probes))
        .collect::<Result<Vec<Role>, ReplayError>>()?;
    check_named_topics_exist(bag, options, &remap)?;
    check_speed_source(bag, &roles)?;
    Ok(roles)
}

/// The role of bag topic `t`, named `name` after remapping, or why its type or encoding does
/// not fit that role.
fn topic_role(
    t: &crate::bag::BagTopic,
    name: &str,
    options: &ReplayOptions,
    stations: &[String],
    rotor_probes: &[String],
) -> Result<Role, ReplayError> {
    let wrong = |expected: &str| ReplayError::WrongType {
        topic: t.name.clone(),
        found: t.type_name.clone(),
        expected: expected.into(),
    };
    // a topic whose single accepted type is `type_name`
    let typed = |type_name: &str, role: Role| {
        if t.type_name == type_name {
            Ok(role)
        } else {
            Err(wrong(type_name))
        }
    };
    let role = if name == SPEED_TOPIC {
        match t.type_name.as_str() {
            messages::RotorSpeed::TYPE_NAME => Role::SpeedRotor,
            messages::Float64::TYPE_NAME => Role::SpeedFloat,
            _ => {
                return Err(wrong(
                    "rotor_twin_msgs/msg/RotorSpeed or std_msgs/msg/Float64",
                ))
            }
        }
    } else if name == UNBALANCE_TOPIC {
        typed(messages::Unbalance::TYPE_NAME, Role::Unbalance)?
    } else if name == PROBE_TOPIC {
        typed(messages::ProbeDisplacement::TYPE_NAME, Role::Probe)?
    } else if name == crate::topics::OIL_TEMPERATURE {
        typed(messages::Temperature::TYPE_NAME, Role::OilTemperature)?
    } else if let Some(role) = plant_signal_role(name, t, options, rotor_probes)? {
        role
    } else if let Some((_, station)) = options.probe_points.iter().find(|(tp, _)| tp == name) {
        let k = stations.iter().position(|s| s == station).unwrap_or(0);
        typed(messages::PointStamped::TYPE_NAME, Role::ProbePoint(k))?
    } else {
        Role::Other
    };
    if role != Role::Other && t.message_encoding != "cdr" {
        return Err(wrong("a CDR-encoded message"));
    }
    Ok(role)
}

/// Some topic drives the twin's speed: a speed topic, or a keyphasor whose intervals give the
/// speed where no speed topic does.
fn check_speed_source(bag: &Bag, roles: &[Role]) -> Result<(), ReplayError> {
    let drives = |r: &Role| {
        use Role::*;
        matches!(r, SpeedRotor | SpeedFloat | Keyphasor | KeyphasorHeader)
    };
    if roles.iter().any(drives) {
        return Ok(());
    }
    let present = bag
        .topics
        .iter()
        .map(|t| format!("{} [{}]", t.name, t.type_name))
        .collect::<Vec<_>>()
        .join(", ");
    Err(ReplayError::MissingTopic {
        topic: SPEED_TOPIC.into(),
        why: "the rotor speed drives the twin; map the bag's speed topic with --remap FROM:=/rotor_twin/speed (or a keyphasor to /rotor_twin/keyphasor)".into(),
        present: if present.is_empty() {
            "none".into()
        } else {
            present
        },
    })
}

/// Every `--remap` source and `--probe-point` topic is a topic of the bag (issue 15, item 21:
/// they were ignored silently, the station just missing from the summary).
fn check_named_topics_exist(
    bag: &Bag,
    options: &ReplayOptions,
    remap: &impl Fn(&str) -> String,
) -> Result<(), ReplayError> {
    let present = || {
        bag.topics
            .iter()
            .map(|t| format!("{} [{}]", t.name, t.type_name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let missing = |topic: &str, why: &str| ReplayError::MissingTopic {
        topic: topic.into(),
        why: why.into(),
        present: present(),
    };
    for (from, _) in &options.remaps {
        if !bag.topics.iter().any(|t| t.name == *from) {
            return Err(missing(from, "--remap names it as the topic to map from"));
        }
    }
    for (topic, _) in &options.probe_points {
        if !bag.topics.iter().any(|t| remap(&t.name) == *topic) {
            return Err(missing(topic, "--probe-point names it as a probe's topic"));
        }
    }
    Ok(())
}

/// The raw probes `--probe-signal` names exist in the machine.
fn check_probe_signal_names(
    options: &ReplayOptions,
    rotor_probes: &[String],
) -> Result<(), ReplayError> {
    match options
        .probe_signals
        .iter()
        .find(|(_, p)| !rotor_probes.contains(p))
    {
        Some((_, probe)) => Err(ReplayError::UnknownStation(
            format!("raw probe {probe}"),
            rotor_probes.join(", "),
        )),
        None => Ok(()),
    }
}

/// The role of a keyphasor or raw-probe topic (issue 12), None for any other, or why its type
/// does not fit.
fn plant_signal_role(
    name: &str,
    t: &crate::bag::BagTopic,
    options: &ReplayOptions,
    rotor_probes: &[String],
) -> Result<Option<Role>, ReplayError> {
    let wrong = |expected: &str| ReplayError::WrongType {
        topic: t.name.clone(),
        found: t.type_name.clone(),
        expected: expected.into(),
    };
    if name == KEYPHASOR_TOPIC {
        return match t.type_name.as_str() {
            messages::Keyphasor::TYPE_NAME => Ok(Some(Role::Keyphasor)),
            messages::Header::TYPE_NAME => Ok(Some(Role::KeyphasorHeader)),
            _ => Err(wrong(
                "rotor_twin_msgs/msg/Keyphasor or std_msgs/msg/Header",
            )),
        };
    }
    if name == PROBE_SIGNAL_TOPIC {
        if t.type_name != messages::ProbeSignal::TYPE_NAME {
            return Err(wrong(messages::ProbeSignal::TYPE_NAME));
        }
        return Ok(Some(Role::ProbeSignal));
    }
    if let Some((_, probe)) = options.probe_signals.iter().find(|(tp, _)| tp == name) {
        if t.type_name != messages::Float64::TYPE_NAME {
            return Err(wrong(messages::Float64::TYPE_NAME));
        }
        let k = rotor_probes.iter().position(|p| p == probe).unwrap_or(0);
        return Ok(Some(Role::ProbeValue(k)));
    }
    Ok(None)
}
