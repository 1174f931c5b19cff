//! RIHS01 type hashes (REP 2016) in a recording: every type rotor-twin records gets the hash in
//! its MCAP channel metadata (`topic_type_hash`) and in metadata.yaml (`type_description_hash`),
//! as rosbag2 Jazzy writes them, and the hash equals the one rosbags 0.11 computes independently
//! (from the `.msg` files for our types; from its Jazzy store for the standard ones).

mod common;

use rotor_twin::messages::{self, RosMessage};
use rotor_twin::record::{Recorder, TopicQos};
use serde_json::Value;
use std::path::PathBuf;

/// Adds a topic of type `T` named after it.
fn add<T: RosMessage>(rec: &mut Recorder) -> String {
    let name = format!("/t/{}", T::TYPE_NAME.rsplit('/').next().unwrap_or_default());
    rec.add_topic::<T>(&name, TopicQos::reliable(10)).unwrap();
    name
}

#[test]
fn recorded_type_hashes_equal_rosbags_hashes() {
    let dir = std::env::temp_dir().join(format!("rotor_twin_type_hashes_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut rec = Recorder::create(&dir).unwrap();
    let topics = [
        add::<messages::RotorSpeed>(&mut rec),
        add::<messages::Unbalance>(&mut rec),
        add::<messages::ProbeDisplacement>(&mut rec),
        add::<messages::JournalState>(&mut rec),
        add::<messages::FilmState>(&mut rec),
        add::<messages::Orbit>(&mut rec),
        add::<messages::InstabilityWarning>(&mut rec),
        add::<messages::StabilityMargin>(&mut rec),
        add::<messages::OrbitResidual>(&mut rec),
        add::<messages::Keyphasor>(&mut rec),
        add::<messages::ProbeSignal>(&mut rec),
        add::<messages::Forecast>(&mut rec),
        add::<messages::OneXVectors>(&mut rec),
        add::<messages::CalibrationEstimate>(&mut rec),
        add::<messages::Header>(&mut rec),
        add::<messages::Float64>(&mut rec),
        add::<messages::PointStamped>(&mut rec),
        add::<messages::Clock>(&mut rec),
        add::<messages::DiagnosticArray>(&mut rec),
        add::<messages::Temperature>(&mut rec),
    ];
    rec.finish().unwrap();

    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let v = common::interop_json("type_hashes.py", [dir.clone(), root.join("msg/msg")]);

    // every .msg file of the package is among the types checked here
    let ours: Vec<&str> = v["_our_types"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(Value::as_str)
        .collect();
    for t in &ours {
        let topic = format!("/t/{}", t.rsplit('/').next().unwrap());
        assert!(topics.contains(&topic), "{t} is not recorded by this test");
    }
    for topic in &topics {
        let t = &v[topic.as_str()];
        let rosbags = t["rosbags"].as_str().unwrap();
        assert!(
            rosbags.starts_with("RIHS01_") && rosbags.len() == 71,
            "{topic}: {t}"
        );
        assert_eq!(t["mcap"], rosbags, "{topic}: MCAP channel metadata");
        assert_eq!(t["yaml"], rosbags, "{topic}: metadata.yaml");
    }
    std::fs::remove_dir_all(dir).ok();
}
