//! Recordings open in independent readers (PyPI `rosbags`, `mcap` + `mcap-ros2-support`) with
//! every message and the right types, and a recording cut off without its summary is still
//! readable up to the last flush.

use rotor_twin::messages::{Header, InstabilityWarning, JournalState, RotorSpeed, Time};
use rotor_twin::record::{Recorder, TopicQos};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Duration;

mod common;

fn read_bag(path: &Path, stream: bool) -> Value {
    let mut args = vec![path.as_os_str()];
    if stream {
        args.push("--stream".as_ref());
    }
    common::interop_json("read_bag.py", args)
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

fn header(ns: i64, frame: &str) -> Header {
    Header {
        stamp: Time::from_nanos(ns),
        frame_id: frame.into(),
    }
}

#[test]
fn a_finished_bag_opens_in_rosbags_and_mcap_ros2() {
    let dir = scratch("bag");
    let mut rec = Recorder::create(&dir).unwrap();
    let speed = rec
        .add_topic::<RotorSpeed>("/rotor_twin/speed", TopicQos::reliable(10))
        .unwrap();
    let state = rec
        .add_topic::<JournalState>("/rotor_twin/journal_state", TopicQos::reliable(10))
        .unwrap();
    let warn = rec
        .add_topic::<InstabilityWarning>("/rotor_twin/warning", TopicQos::latched(1))
        .unwrap();
    let t0 = 1_700_000_000_000_000_000u64;
    for k in 0..25u64 {
        let t = t0 + k * 1_000_000;
        rec.write(
            speed,
            &RotorSpeed {
                header: header(t as i64, ""),
                speed: 942.48,
                acceleration: 0.0,
            },
            t,
            t,
        )
        .unwrap();
        let js = JournalState {
            header: header(t as i64, "bearing_outboard"),
            bearing: "bearing_outboard".into(),
            x: 1e-5,
            y: -2e-5,
            eccentricity_ratio: 0.55,
            ..Default::default()
        };
        rec.write(state, &js, t, t).unwrap();
    }
    rec.write(
        warn,
        &InstabilityWarning {
            header: header(t0 as i64, ""),
            level: InstabilityWarning::WARN,
            kind: "whirl".into(),
            whirl_ratio: 0.45,
            ..Default::default()
        },
        t0,
        t0,
    )
    .unwrap();
    rec.finish().unwrap();
    let v = read_bag(&dir, false);
    assert_eq!(v["profile"], "ros2");
    for reader in ["mcap_ros2", "rosbags"] {
        let c = &v[reader]["counts"];
        assert_eq!(c["/rotor_twin/speed"], 25, "{reader}: {v}");
        assert_eq!(c["/rotor_twin/journal_state"], 25, "{reader}: {v}");
        assert_eq!(c["/rotor_twin/warning"], 1, "{reader}: {v}");
    }
    assert_eq!(
        v["rosbags"]["types"]["/rotor_twin/journal_state"],
        "rotor_twin_msgs/msg/JournalState"
    );
    let first = &v["mcap_ros2"]["first"]["/rotor_twin/journal_state"];
    assert_eq!(first["eccentricity_ratio"], 0.55);
    assert_eq!(first["bearing"], "bearing_outboard");
    assert_eq!(
        v["mcap_ros2"]["first"]["/rotor_twin/warning"]["kind"],
        "whirl"
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_recording_cut_off_after_a_flush_is_readable() {
    let dir = scratch("cut");
    let mut rec = Recorder::create(&dir).unwrap();
    let speed = rec
        .add_topic::<RotorSpeed>("/rotor_twin/speed", TopicQos::reliable(10))
        .unwrap();
    for k in 0..40u64 {
        rec.write(
            speed,
            &RotorSpeed {
                header: header(k as i64, ""),
                speed: 900.0 + k as f64,
                acceleration: 0.0,
            },
            k,
            k,
        )
        .unwrap();
    }
    rec.flush_if_due(Duration::ZERO).unwrap();
    // the process dies here: no summary; metadata.yaml as of the last flush
    std::mem::forget(rec);
    let meta = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
    assert!(meta.contains("  message_count: 40\n"), "{meta}");
    let v = read_bag(
        &dir.join(format!(
            "{}_0.mcap",
            dir.file_name().unwrap().to_string_lossy()
        )),
        true,
    );
    assert_eq!(v["mcap_stream"]["counts"]["/rotor_twin/speed"], 40, "{v}");
    std::fs::remove_dir_all(dir).ok();
}
