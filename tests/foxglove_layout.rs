//! The Foxglove layout (config/foxglove_layout.json) only refers to topics the node publishes,
//! fields their messages have, bearings of the built-in machine and panels it defines; the orbit
//! plots are square (equal x and y ranges, the clearance of the built-in machine).

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

#[test]
fn layout_refers_to_what_the_node_publishes() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/foxglove_layout.json");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
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
    assert_eq!(ids.len(), configs.len());
    assert!(ids.iter().all(|i| configs.contains_key(i)));
}
