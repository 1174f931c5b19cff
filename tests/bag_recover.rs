//! A recording killed part-way (SIGKILL) or stopped by a full disk: metadata.yaml is there as of
//! the last flush, the write error is reported (not silent), and `rotor-twin bag recover` makes
//! a bag that an independent reader (PyPI rosbags, which needs the summary and end magic) opens
//! with every flushed message.

mod common;

use common::{python, run_cli};
use rotor_twin::bag::Bag;
use rotor_twin::messages::Float64;
use rotor_twin::record::{Recorder, TopicQos};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-recover-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

/// Message counts per topic as rosbags reads the bag directory; Err with its message if it
/// cannot open it.
fn rosbags_counts(dir: &Path) -> Result<Value, String> {
    let script = "import json, sys\nfrom pathlib import Path\nfrom rosbags.highlevel import AnyReader\ncounts = {}\nwith AnyReader([Path(sys.argv[1])]) as r:\n    for c, t, raw in r.messages():\n        r.deserialize(raw, c.msgtype)\n        counts[c.topic] = counts.get(c.topic, 0) + 1\nprint(json.dumps(counts))\n";
    let out = Command::new(python())
        .args(["-c", script, dir.to_str().unwrap()])
        .output()
        .unwrap();
    if out.status.success() {
        Ok(serde_json::from_slice(&out.stdout).unwrap())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).into_owned())
    }
}

#[test]
fn a_killed_recording_is_recovered_into_a_bag_rosbags_opens() {
    let dir = scratch("killed");
    let mut rec = Recorder::create(&dir).unwrap();
    assert!(
        dir.join("metadata.yaml").is_file(),
        "metadata.yaml at start"
    );
    let t = rec.add_topic::<Float64>("/t", TopicQos::sensor(5)).unwrap();
    for i in 0..3200u64 {
        let ns = 1_700_000_000_000_000_000 + i * 1_000_000;
        rec.write(t, &Float64 { data: i as f64 }, ns, ns).unwrap();
        if i % 500 == 499 {
            rec.flush().unwrap();
        }
    }
    // SIGKILL here: 3,000 messages flushed, 200 in the open chunk lost
    std::mem::forget(rec);
    let meta = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
    assert!(meta.contains("  message_count: 3000\n"), "{meta}");
    let e = rosbags_counts(&dir).expect_err("a cut-off file has no end magic");
    assert!(e.contains("magic"), "{e}");
    let out = scratch("killed-out");
    let (ok, stdout, err) = run_cli(&[
        "bag",
        "recover",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("recovered 3000 messages"), "{stdout}");
    assert!(err.contains("cut off"), "the damage is named: {err}");
    let counts = rosbags_counts(&out).unwrap();
    assert_eq!(counts["/t"], 3000, "{counts}");
    let b = Bag::read(&out).unwrap();
    assert!(b.damage.is_empty() && b.notes.is_empty());
    // the QoS survives (rosbags reads nothing if metadata and channel disagree)
    assert_eq!(
        b.topics[0].offered_qos_profiles,
        Some(TopicQos::sensor(5).rosbag2_yaml())
    );
    // the input is not changed, and the output cannot go inside it
    assert!(rosbags_counts(&dir).is_err());
    let (ok, _, err) = run_cli(&[
        "bag",
        "recover",
        dir.to_str().unwrap(),
        "--out",
        dir.join("x").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("inside the input bag"), "{err}");
}

/// A 256 kB file system filled by a recording (a private mount namespace, as the DDS tests use a
/// private network one): the recorder stops with an error naming the file and the cause, the
/// command exits non-zero, and what was written is recovered.
#[test]
fn a_full_disk_stops_the_recording_loudly_and_what_was_written_is_recovered() {
    let work = scratch("full");
    std::fs::create_dir_all(work.join("mnt")).unwrap();
    let bin = env!("CARGO_BIN_EXE_rotor-twin");
    let script = format!(
        "mount -t tmpfs -o size=256k tmpfs {mnt} && {bin} synth-bag --out {mnt}/bag --hold-start 3 --ramp 0 --hold-end 0 --samples-per-rev 64; echo \"rc=$?\"; cp -r {mnt}/bag {work}/bag",
        mnt = work.join("mnt").display(),
        work = work.display()
    );
    let out = Command::new("unshare")
        .args(["-m", "sh", "-c", &script])
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(stdout.contains("rc=1"), "must fail: {stdout}\n{stderr}");
    assert!(
        stderr.contains("No space left on device")
            && stderr.contains("the recording failed")
            && stderr.contains("_0.mcap"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    let bag = work.join("bag");
    let read = Bag::read(&bag).unwrap();
    assert!(
        read.message_count() > 1000,
        "{} messages readable",
        read.message_count()
    );
    let rec = work.join("recovered");
    let (ok, _, err) = run_cli(&[
        "bag",
        "recover",
        bag.to_str().unwrap(),
        "--out",
        rec.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let counts = rosbags_counts(&rec).unwrap();
    let total: u64 = counts
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total as usize, read.message_count(), "{counts}");
}
