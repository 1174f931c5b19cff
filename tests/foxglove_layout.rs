//! The Foxglove layouts (config/foxglove_layout.json for the node, config/foxglove_layout_replay.json
//! for a replay's output, which has no /diagnostics) only refer to topics the node publishes,
//! fields their messages have, bearings of the built-in machine and panels they define; the orbit
//! plots are square (equal x and y ranges, the clearance of the built-in machine); every panel has
//! its title where Foxglove and Lichtblick read it (`foxglovePanelTitle`, `lichtblickPanelTitle`:
//! ../shared/notes/foxglove-lichtblick.md; `title` is not read); no plot mixes units on its y axis.
//! The XY orbit plots read one bearing's own topic (`/rotor_twin/orbit/<bearing>`) without a
//! filter: an XY plot of the latest message filtered by bearing draws nothing for the bearing
//! whose orbit comes first on the shared topic (seen in Lichtblick). The per-bearing topics
//! exist in the replay's output bag, hold the shared topic's orbits of their bearing, and stay
//! at ≤ 50 Hz (Lichtblick warns above 60 Hz, FREQUENCY_LIMIT).

mod common;

use rotor_twin::messages::{FilmState, JournalState, Orbit, RosMessage};
use rotor_twin::rotor::{MachineDescription, Rotor};
use rotor_twin::topics;
use rotor_twin::viewer::BearingOrbits;
use serde_json::Value;

/// The fields of a topic the node publishes (for the built-in machine), None if it does not.
fn fields_of(topic: &str) -> Option<&'static [(&'static str, &'static str)]> {
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let per_bearing = BearingOrbits::new(&rotor).topics();
    match topic {
        topics::ORBIT => Some(Orbit::FIELDS),
        topics::JOURNAL => Some(JournalState::FIELDS),
        topics::FILM => Some(FilmState::FIELDS),
        t if per_bearing.iter().any(|p| p == t) => Some(Orbit::FIELDS),
        _ => None,
    }
}

/// Checks a message path `/topic{bearing=="name"}.field[:]`.
fn check_path(path: &str, bearings: &[String]) {
    let (topic_part, field) = path.rsplit_once('.').expect("a field");
    let field = field.trim_end_matches("[:]");
    let (topic, filter) = match topic_part.split_once('{') {
        Some((t, f)) => (t, Some(f.trim_end_matches('}'))),
        None => (topic_part, None),
    };
    let fields =
        fields_of(topic).unwrap_or_else(|| panic!("{path}: the node does not publish {topic}"));
    assert!(
        fields.iter().any(|(n, _)| *n == field),
        "{path}: no field {field}"
    );
    if let Some(f) = filter {
        let name = f.trim_start_matches("bearing==").trim_matches('"');
        assert!(
            bearings.iter().any(|b| b == name),
            "{path}: no bearing {name}"
        );
    }
}

/// The unit of a plotted field, from the naming rule of the messages (`msg/*.msg`): `*_ratio`
/// fields are ratios (1), the amplitudes and coordinates plotted here metres.
fn unit_of(path: &str) -> &'static str {
    if path.trim_end_matches("[:]").ends_with("_ratio") {
        "1"
    } else {
        "m"
    }
}

fn load(name: &str) -> Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Titles where the viewers read them, and one unit per plot axis.
fn check_titles_and_units(v: &Value) {
    for (id, cfg) in v["configById"].as_object().unwrap() {
        assert!(cfg.get("title").is_none(), "{id}: `title` is not read");
        let title = cfg["foxglovePanelTitle"].as_str().unwrap_or("");
        assert!(!title.is_empty(), "{id}: no foxglovePanelTitle");
        assert_eq!(cfg["lichtblickPanelTitle"], title, "{id}");
        if id.starts_with("Plot!") {
            let mut units: Vec<&str> = cfg["paths"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| unit_of(p["value"].as_str().unwrap()))
                .collect();
            units.dedup();
            assert_eq!(units.len(), 1, "{id}: y axis mixes units {units:?}");
        }
    }
}

#[test]
fn layouts_have_titles_and_one_unit_per_axis() {
    let node = load("config/foxglove_layout.json");
    let replay = load("config/foxglove_layout_replay.json");
    check_titles_and_units(&node);
    check_titles_and_units(&replay);
    // the replay's output has no /diagnostics: no panel waits for it
    let text = replay.to_string();
    assert!(!text.contains("DiagnosticSummary") && !text.contains("/diagnostics"));
    assert!(node.to_string().contains("DiagnosticSummary"));
    check_layout(&replay);
}

#[test]
fn layout_refers_to_what_the_node_publishes() {
    check_layout(&load("config/foxglove_layout.json"));
}

fn check_layout(v: &Value) {
    let desc = MachineDescription::builtin_default();
    let bearings: Vec<String> = desc.bearings.iter().map(|b| b.name.clone()).collect();
    let configs = v["configById"].as_object().unwrap();
    for (id, cfg) in configs {
        if id.starts_with("Plot!") {
            for p in cfg["paths"].as_array().unwrap() {
                check_path(p["value"].as_str().unwrap(), &bearings);
            }
            if let Some(x) = cfg.get("xAxisPath") {
                check_path(x["value"].as_str().unwrap(), &bearings);
            }
        }
        if cfg["xAxisVal"] == "currentCustom" {
            // the latest message is drawn: it must be the bearing's own, unfiltered
            for p in cfg["paths"]
                .as_array()
                .unwrap()
                .iter()
                .chain([&cfg["xAxisPath"]])
            {
                let path = p["value"].as_str().unwrap();
                assert!(
                    !path.contains('{'),
                    "{id}: {path} filters the latest message"
                );
                let topic = path.rsplit_once('.').unwrap().0;
                assert!(
                    bearings.iter().any(|b| topics::bearing_orbit(b) == topic),
                    "{id}: {topic} is not one bearing's orbit topic"
                );
            }
        }
        if id.starts_with("Plot!orbit") {
            let c = desc.bearings[0].film().unwrap().geometry.radial_clearance_m;
            for key in ["minXValue", "minYValue"] {
                assert_eq!(cfg[key].as_f64().unwrap(), -c, "{id} {key}");
            }
            for key in ["maxXValue", "maxYValue"] {
                assert_eq!(cfg[key].as_f64().unwrap(), c, "{id} {key}");
            }
        }
    }
    assert_eq!(
        configs["RawMessages!warning"]["topicPath"],
        "/rotor_twin/warning"
    );
    // every panel in the layout tree is defined
    fn leaves(v: &Value, out: &mut Vec<String>) {
        match v {
            Value::String(s) => out.push(s.clone()),
            Value::Object(o) => {
                for k in ["first", "second"] {
                    if let Some(c) = o.get(k) {
                        leaves(c, out);
                    }
                }
            }
            _ => {}
        }
    }
    let mut ids = Vec::new();
    leaves(&v["layout"], &mut ids);
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), configs.len());
    assert!(ids.iter().all(|i| configs.contains_key(i)));
}

/// The configuration keys each panel type reads, from Lichtblick's panel config types
/// (lichtblick-suite/lichtblick, packages/suite-base/src/panels/: Plot/utils/config.ts
/// `PlotConfig`, `PlotPath`, `BasePlotPath`, `PlotXAxisVal`; RawMessages/types.ts
/// `RawMessagesPanelConfig`; diagnostics/types.ts `DiagnosticSummaryConfig`; util/layout.ts
/// `PANEL_TITLE_CONFIG_KEY` = `lichtblickPanelTitle`; util/time.ts `TimestampMethod`), plus
/// Foxglove's title key `foxglovePanelTitle` (Foxglove Studio's `PANEL_TITLE_CONFIG_KEY`,
/// ../shared/notes/foxglove-lichtblick.md). Read through the search tool, not run: a key outside
/// these lists is silently ignored by the viewer (as `title` was).
const TITLE_KEYS: [&str; 2] = ["lichtblickPanelTitle", "foxglovePanelTitle"];
const PLOT_KEYS: &[&str] = &[
    "paths",
    "minXValue",
    "maxXValue",
    "minYValue",
    "maxYValue",
    "showLegend",
    "legendDisplay",
    "showPlotValuesInLegend",
    "showXAxisLabels",
    "showYAxisLabels",
    "isSynced",
    "xAxisVal",
    "xAxisPath",
    "followingViewWidth",
    "sidebarDimension",
];
const PLOT_PATH_KEYS: &[&str] = &[
    "value",
    "enabled",
    "color",
    "label",
    "timestampMethod",
    "showLine",
    "lineSize",
];
const X_AXIS_PATH_KEYS: &[&str] = &["value", "enabled"];
const X_AXIS_VALUES: &[&str] = &["timestamp", "index", "custom", "currentCustom"];
const TIMESTAMP_METHODS: &[&str] = &["receiveTime", "headerStamp"];
const RAW_MESSAGES_KEYS: &[&str] = &[
    "diffEnabled",
    "diffMethod",
    "diffTopicPath",
    "expansion",
    "showFullMessageForDiff",
    "topicPath",
    "fontSize",
];
const DIAGNOSTIC_SUMMARY_KEYS: &[&str] = &[
    "minLevel",
    "pinnedIds",
    "topicToRender",
    "hardwareIdFilter",
    "sortByLevel",
    "secondsUntilStale",
];

/// Every key of `obj` is in `known`.
fn keys_known(what: &str, obj: &Value, known: &[&str]) {
    for key in obj.as_object().unwrap().keys() {
        assert!(
            known.contains(&key.as_str()) || TITLE_KEYS.contains(&key.as_str()),
            "{what}: `{key}` is not read by the panel"
        );
    }
}

fn check_panel_keys(v: &Value) {
    for (id, cfg) in v["configById"].as_object().unwrap() {
        let (kind, _) = id.split_once('!').expect("panel id Type!name");
        match kind {
            "Plot" => {
                keys_known(id, cfg, PLOT_KEYS);
                for p in cfg["paths"].as_array().unwrap() {
                    keys_known(id, p, PLOT_PATH_KEYS);
                    let method = p["timestampMethod"].as_str().unwrap();
                    assert!(TIMESTAMP_METHODS.contains(&method), "{id}: {method}");
                    assert_eq!(p["enabled"], true, "{id}");
                }
                if let Some(x) = cfg.get("xAxisPath") {
                    keys_known(id, x, X_AXIS_PATH_KEYS);
                }
                let x = cfg["xAxisVal"].as_str().unwrap();
                assert!(X_AXIS_VALUES.contains(&x), "{id}: xAxisVal {x}");
                assert!(cfg["showLegend"].is_boolean(), "{id}");
            }
            "RawMessages" => {
                keys_known(id, cfg, RAW_MESSAGES_KEYS);
                assert!(["all", "none"].contains(&cfg["expansion"].as_str().unwrap_or("")));
            }
            "DiagnosticSummary" => {
                keys_known(id, cfg, DIAGNOSTIC_SUMMARY_KEYS);
                // diagnostic_msgs/DiagnosticStatus levels: 0 OK … 3 STALE
                assert!((0..=3).contains(&cfg["minLevel"].as_u64().unwrap()), "{id}");
                assert!(cfg["hardwareIdFilter"].is_string() && cfg["pinnedIds"].is_array());
            }
            other => panic!("{id}: panel type {other} not checked"),
        }
    }
}

#[test]
fn every_panel_key_is_one_the_viewer_reads() {
    check_panel_keys(&load("config/foxglove_layout.json"));
    check_panel_keys(&load("config/foxglove_layout_replay.json"));
    // the check itself: a key the viewer ignores is refused
    let mut bad = load("config/foxglove_layout.json");
    bad["configById"]["Plot!spectrum"]["title"] = "Spectrum".into();
    assert!(std::panic::catch_unwind(|| check_panel_keys(&bad)).is_err());
}

/// Topic names are ROS 2 name tokens whatever the bearing is called.
#[test]
fn bearing_orbit_topics_are_ros_names() {
    assert_eq!(
        topics::bearing_orbit("bearing_outboard"),
        "/rotor_twin/orbit/bearing_outboard"
    );
    assert_eq!(
        topics::bearing_orbit("2-drive end"),
        "/rotor_twin/orbit/_2_drive_end"
    );
}

fn orbit(bearing: &str, stamp_ns: i64) -> Orbit {
    Orbit {
        header: rotor_twin::session::header(stamp_ns, bearing),
        bearing: bearing.into(),
        ..Orbit::default()
    }
}

/// 9,000 rpm: 150 revolutions a second; two bearings; 1 s of orbits. The viewer topics get
/// every third revolution (50 Hz, 20 ms apart; the 6.67 ms revolution period · 3), each bearing
/// its own; a stamp going back (a restarted twin) is kept at once.
#[test]
fn viewer_topics_keep_one_orbit_in_twenty_ms_per_bearing() {
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let mut r = BearingOrbits::new(&rotor);
    let names: Vec<String> = rotor.bearings.iter().map(|b| b.name.clone()).collect();
    assert_eq!(r.topics().len(), 2);
    let period_ns = 1e9 / 150.0;
    let mut kept = vec![Vec::new(); 2];
    for rev in 0..150 {
        let stamp = (rev as f64 * period_ns).round() as i64;
        for (i, name) in names.iter().enumerate() {
            if let Some(k) = r.route(&orbit(name, stamp)) {
                assert_eq!(k, i);
                kept[k].push(stamp);
            }
        }
    }
    for k in kept {
        assert_eq!(k.len(), 50, "one in three of 150 revolutions");
        let rate = (k.len() - 1) as f64 / ((k[k.len() - 1] - k[0]) as f64 * 1e-9);
        assert!(rate <= 50.5, "{rate} Hz");
    }
    assert_eq!(r.route(&orbit("no_such_bearing", 0)), None);
    assert_eq!(r.route(&orbit(&names[0], 0)), Some(0));
}

/// A replay's output bag (3 s of the shipped run-up, machine by default the built-in one, 8,000
/// to 9,500 rpm) has every topic the replay layout names, each bearing's orbit topic holds
/// that bearing's orbits of the shared topic only, at ≤ 50 Hz, while the shared topic keeps
/// every revolution of both bearings (the consumers that rely on it lose nothing).
#[test]
fn the_replay_output_has_the_layout_topics_at_viewer_rates() {
    let dir = std::env::temp_dir().join(format!("rotor-twin-layout-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("bags/orc_runup_synthetic");
    let out = dir.join("out");
    let (ok, stdout, stderr) = common::run_cli(&[
        "replay",
        sample.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--duration",
        "3",
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let bag = rotor_twin::bag::Bag::read(&out.join("bag")).unwrap();
    let layout = load("config/foxglove_layout_replay.json").to_string();
    let names: Vec<&str> = bag.topics.iter().map(|t| t.name.as_str()).collect();
    let mut per_topic: std::collections::HashMap<String, Vec<Orbit>> = Default::default();
    for m in bag.messages() {
        let name = &bag.topics[m.topic].name;
        if name.starts_with(topics::ORBIT) {
            let o: Orbit = rotor_twin::messages::from_cdr(m.payload()).unwrap();
            per_topic.entry(name.clone()).or_default().push(o);
        }
    }
    let shared = &per_topic[topics::ORBIT];
    for b in ["bearing_pulley_end", "bearing_outboard"] {
        let t = topics::bearing_orbit(b);
        assert!(names.contains(&t.as_str()), "{t} not in {names:?}");
        assert!(layout.contains(&t), "the layout reads {t}");
        let own = &per_topic[&t];
        let all: Vec<&Orbit> = shared.iter().filter(|o| o.bearing == b).collect();
        assert!(own.iter().all(|o| o.bearing == b && all.contains(&o)));
        let span = (own[own.len() - 1].header.stamp.as_nanos() - own[0].header.stamp.as_nanos())
            as f64
            * 1e-9;
        let (rate, all_rate) = ((own.len() - 1) as f64 / span, (all.len() - 1) as f64 / span);
        println!(
            "{t}: {} orbits, {rate:.1} Hz; shared: {} ({all_rate:.1} Hz)",
            own.len(),
            all.len()
        );
        assert!(rate <= 50.5 && rate > 35.0, "{rate} Hz");
        assert!(
            all_rate > 120.0,
            "every revolution on the shared topic: {all_rate} Hz"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
