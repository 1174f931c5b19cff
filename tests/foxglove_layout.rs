//! The Foxglove layouts (config/foxglove_layout.json for the node, config/foxglove_layout_replay.json
//! for a replay's output, which has no /diagnostics) only refer to topics the node publishes,
//! fields their messages have, bearings of the built-in machine and panels they define; the orbit
//! plots are square (equal x and y ranges, the clearance of the built-in machine); every panel has
//! its title where Foxglove and Lichtblick read it (`foxglovePanelTitle`, `lichtblickPanelTitle`:
//! ../shared/notes/foxglove-lichtblick.md; `title` is not read); no plot mixes units on its y axis.

use rotor_twin::messages::{FilmState, JournalState, Orbit, RosMessage};
use rotor_twin::rotor::MachineDescription;
use serde_json::Value;

fn fields_of(topic: &str) -> Option<&'static [(&'static str, &'static str)]> {
    match topic {
        "/rotor_twin/orbit" => Some(Orbit::FIELDS),
        "/rotor_twin/journal_state" => Some(JournalState::FIELDS),
        "/rotor_twin/film_state" => Some(FilmState::FIELDS),
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
