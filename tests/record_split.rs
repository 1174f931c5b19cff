//! A recording split into files of bounded size or duration (rosbag2's max_bagfile_size /
//! max_bagfile_duration; issue 15, soak): several complete .mcap files DIR_0.mcap, DIR_1.mcap …,
//! metadata.yaml listing them all, and every message once, none lost or doubled at a boundary,
//! as our reader and an independent one (PyPI rosbags) both read the directory.

mod common;

use common::python;
use rotor_twin::bag::Bag;
use rotor_twin::messages::{from_cdr, Float64};
use rotor_twin::record::{Recorder, SplitLimits, TopicQos};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

const T0_NS: u64 = 1_700_000_000_000_000_000;
const MS: u64 = 1_000_000;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-split-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

/// Records `n` messages 1 ms apart on /a and /b alternately, value i (scrambled in its low
/// digits so that the chunks do not compress to nothing) , flushed every 500 as the node does.
fn record(dir: &Path, n: u64, split: SplitLimits) -> Vec<PathBuf> {
    let mut rec = Recorder::create_split(dir, split).unwrap();
    let a = rec.add_topic::<Float64>("/a", TopicQos::sensor(5)).unwrap();
    let b = rec
        .add_topic::<Float64>("/b", TopicQos::reliable(5))
        .unwrap();
    for i in 0..n {
        let ns = T0_NS + i * MS;
        let v = i as f64 + ((i * 2_654_435_761) % 1000) as f64 * 1e-6;
        rec.write(if i % 2 == 0 { a } else { b }, &Float64 { data: v }, ns, ns)
            .unwrap();
        if i % 500 == 499 {
            rec.flush_if_due(Duration::ZERO).unwrap();
        }
    }
    let files = rec.files();
    rec.finish().unwrap();
    files
}

/// The index i of each message as rosbags reads the directory, in its order, and the topics.
fn rosbags_values(dir: &Path) -> Vec<(String, u64)> {
    let script = "import sys\nfrom pathlib import Path\nfrom rosbags.highlevel import AnyReader\nwith AnyReader([Path(sys.argv[1])]) as r:\n    for c, t, raw in r.messages():\n        m = r.deserialize(raw, c.msgtype)\n        print(c.topic, int(m.data), t)\n";
    let out = Command::new(python())
        .args(["-c", script, dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "rosbags: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split(' ').collect();
            let i: u64 = f[1].parse().unwrap();
            assert_eq!(f[2].parse::<u64>().unwrap(), T0_NS + i * MS, "{l}");
            (f[0].to_string(), i)
        })
        .collect()
}

/// Every message 0..n exactly once, in order, on its topic.
fn check_complete(values: &[(String, u64)], n: u64, who: &str) {
    assert_eq!(values.len() as u64, n, "{who}: message count");
    for (k, (topic, i)) in values.iter().enumerate() {
        assert_eq!(*i, k as u64, "{who}: message {k} is {i}");
        assert_eq!(topic, if i % 2 == 0 { "/a" } else { "/b" }, "{who}");
    }
}

fn check_bag(dir: &Path, files: &[PathBuf], n: u64) {
    let stem = dir.file_name().unwrap().to_string_lossy().into_owned();
    for (k, f) in files.iter().enumerate() {
        assert_eq!(*f, dir.join(format!("{stem}_{k}.mcap")));
        // each file complete on its own: its summary read by the mcap crate
        let bytes = std::fs::read(f).unwrap();
        assert!(
            mcap::Summary::read(&bytes).unwrap().is_some(),
            "{}",
            f.display()
        );
    }
    let meta = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
    assert!(meta.contains(&format!("  message_count: {n}\n")), "{meta}");
    let bag = Bag::read(dir).unwrap();
    assert_eq!(bag.files, files, "metadata.yaml lists every file, in order");
    assert!(
        bag.notes.is_empty() && bag.damage.is_empty(),
        "{:?}",
        bag.notes
    );
    let ours: Vec<(String, u64)> = bag
        .messages()
        .map(|m| {
            let v = from_cdr::<Float64>(m.payload()).unwrap().data;
            assert_eq!(m.log_time_ns, T0_NS + v as u64 * MS);
            (bag.topics[m.topic].name.clone(), v as u64)
        })
        .collect();
    check_complete(&ours, n, "rotor-twin's reader");
    check_complete(&rosbags_values(dir), n, "rosbags");
}

#[test]
fn a_recording_with_a_small_size_limit_is_split_and_read_whole() {
    let dir = scratch("size");
    let n = 40_000;
    let split = SplitLimits {
        max_bytes: Some(64 << 10),
        max_duration_ns: None,
    };
    let files = record(&dir, n, split);
    assert!(files.len() >= 4, "{} files", files.len());
    // bounded: no file much beyond the limit (one chunk and the summary over it)
    for f in &files {
        let len = std::fs::metadata(f).unwrap().len();
        assert!(len < 3 * (64 << 10), "{}: {len} bytes", f.display());
    }
    check_bag(&dir, &files, n);
}

#[test]
fn a_recording_with_a_duration_limit_has_a_file_per_span() {
    let dir = scratch("duration");
    // 12 s of messages, files of 2.5 s: 0–2.499, 2.5–4.999, … → 5 files
    let n = 12_000;
    let split = SplitLimits {
        max_bytes: None,
        max_duration_ns: Some(2_500 * MS),
    };
    let files = record(&dir, n, split);
    assert_eq!(files.len(), 5);
    let meta = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
    assert_eq!(
        meta.matches("    message_count: 2500\n").count(),
        4,
        "{meta}"
    );
    assert!(meta.contains("    message_count: 2000\n"), "{meta}");
    check_bag(&dir, &files, n);
}

#[test]
fn the_limits_of_the_command_line_are_checked() {
    assert_eq!(
        SplitLimits::from_options(0, 0.0).unwrap(),
        SplitLimits::NONE
    );
    let e = SplitLimits::from_options(1000, 0.0).unwrap_err();
    assert!(e.contains("--record-max-bag-size 1000"), "{e}");
    let e = SplitLimits::from_options(0, -1.0).unwrap_err();
    assert!(e.contains("--record-max-bag-duration -1"), "{e}");
    assert!(SplitLimits::from_options(0, f64::NAN).is_err());
    let s = SplitLimits::from_options(1 << 20, 60.0).unwrap();
    assert_eq!(s.max_bytes, Some(1 << 20));
    assert_eq!(s.max_duration_ns, Some(60_000_000_000));
}

/// Without metadata.yaml the directory's files are read in the order of their number, as
/// rosbag2 names them (DIR_2 before DIR_10), and still every message once.
#[test]
fn a_split_recording_without_metadata_reads_its_files_by_number() {
    let dir = scratch("nometa");
    let split = SplitLimits {
        max_bytes: None,
        max_duration_ns: Some(1_000 * MS),
    };
    let files = record(&dir, 12_000, split);
    assert_eq!(files.len(), 12);
    std::fs::remove_file(dir.join("metadata.yaml")).unwrap();
    let bag = Bag::read(&dir).unwrap();
    assert_eq!(bag.files, files);
    assert_eq!(bag.message_count(), 12_000);
}
