//! Bag directories whose metadata.yaml is wrong or hostile, and receive-time outliers: the files
//! that exist are read once each, nothing outside the bag directory is read, and every problem
//! is said in a note.

use rotor_twin::bag::Bag;
use rotor_twin::messages::Float64;
use rotor_twin::record::{Recorder, TopicQos};
use std::path::{Path, PathBuf};

const N: usize = 500;
const T0_NS: u64 = 1_700_000_000_000_000_000;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-bagmeta-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

/// A bag of N Float64 messages 1 ms apart, plus one message received at `outlier_ns` if given.
fn bag(name: &str, outlier_ns: Option<u64>) -> (PathBuf, String) {
    let dir = scratch(name);
    let mut rec = Recorder::create(&dir).unwrap();
    let t = rec
        .add_topic::<Float64>("/t", TopicQos::reliable(10))
        .unwrap();
    for i in 0..N as u64 {
        let stamp = T0_NS + i * 1_000_000;
        rec.write(t, &Float64 { data: i as f64 }, stamp, stamp)
            .unwrap();
    }
    if let Some(at) = outlier_ns {
        rec.write(t, &Float64 { data: -1.0 }, at, at).unwrap();
    }
    let dir = rec.finish().unwrap();
    let file = format!("{}_0.mcap", dir.file_name().unwrap().to_string_lossy());
    assert!(dir.join(&file).is_file());
    (dir, file)
}

/// Rewrites the bag's relative_file_paths to `names`.
fn list_in_metadata(dir: &Path, names: &[&str]) {
    let path = dir.join("metadata.yaml");
    let text = std::fs::read_to_string(&path).unwrap();
    let (head, rest) = text.split_once("  relative_file_paths:\n").unwrap();
    let tail = &rest[rest.find("  files:").unwrap()..];
    let list: String = names.iter().map(|n| format!("  - '{n}'\n")).collect();
    std::fs::write(&path, format!("{head}  relative_file_paths:\n{list}{tail}")).unwrap();
}

fn notes(bag: &Bag) -> String {
    bag.notes.join("\n")
}

#[test]
fn a_missing_file_in_the_metadata_is_named_and_the_existing_one_read() {
    let (dir, file) = bag("missing", None);
    list_in_metadata(&dir, &["gone_0.mcap", &file]);
    let b = Bag::read(&dir).unwrap();
    assert_eq!(b.message_count(), N);
    assert!(
        notes(&b).contains("gone_0.mcap") && notes(&b).contains("does not exist"),
        "{}",
        notes(&b)
    );
    // only missing files listed: the directory's .mcap file is read, and that is said
    list_in_metadata(&dir, &["gone_0.mcap"]);
    let b = Bag::read(&dir).unwrap();
    assert_eq!(b.message_count(), N);
    assert!(notes(&b).contains("read instead"), "{}", notes(&b));
}

#[test]
fn a_file_listed_three_times_is_read_once() {
    let (dir, file) = bag("thrice", None);
    list_in_metadata(&dir, &[&file, &file, &format!("./{file}")]);
    let b = Bag::read(&dir).unwrap();
    assert_eq!(b.message_count(), N, "{}", notes(&b));
    assert!(notes(&b).contains("more than once"), "{}", notes(&b));
}

#[test]
fn paths_outside_the_bag_directory_and_devices_are_never_read() {
    let (dir, file) = bag("outside", None);
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.mcap")).unwrap();
    std::os::unix::fs::symlink("/etc/passwd", dir.join("passwd.mcap")).unwrap();
    let hostile = [
        "/etc/passwd",
        "../../../../../../etc/passwd",
        "/dev/zero",
        "zero.mcap",
        "passwd.mcap",
        ".",
        "",
    ];
    let mut names: Vec<&str> = hostile.to_vec();
    names.push(&file);
    list_in_metadata(&dir, &names);
    let b = Bag::read(&dir).unwrap();
    assert_eq!(b.files, vec![dir.join(&file)]);
    assert_eq!(b.message_count(), N);
    let n = notes(&b);
    for h in hostile {
        assert!(n.contains(&format!("{h:?}")), "{h} not named in:\n{n}");
    }
    // the symbolic links in the directory are not picked up as .mcap files either
    list_in_metadata(&dir, &["gone.mcap"]);
    let b = Bag::read(&dir).unwrap();
    assert_eq!(b.files, vec![dir.join(&file)]);
    // a device given as the bag: refused, not read
    let e = Bag::read(Path::new("/dev/zero")).unwrap_err().to_string();
    assert!(e.contains("not a regular file"), "{e}");
}

/// One message received at the epoch's start (a clock not yet set) in a bag of 2023: it must not
/// become the bag's start. Reference: the bag's true span is (N − 1) ms.
#[test]
fn one_outlier_receive_time_is_left_out_of_the_span_and_said() {
    let (dir, _) = bag("outlier", Some(1_000_000_000));
    let b = Bag::read(&dir).unwrap();
    let (a, z) = b.time_span_ns().unwrap();
    assert_eq!((a, z), (T0_NS, T0_NS + (N as u64 - 1) * 1_000_000));
    assert_eq!(b.excluded_count(), 1);
    assert_eq!(b.message_count(), N);
    assert!(notes(&b).contains("1.000 s"), "{}", notes(&b));
    // one far in the future too
    let (dir, _) = bag("outlier-late", Some(T0_NS + 2_770_000_000 * 1_000_000_000));
    let b = Bag::read(&dir).unwrap();
    assert_eq!(
        b.time_span_ns().unwrap().1,
        T0_NS + (N as u64 - 1) * 1_000_000
    );
    // a long bag with an ordinary pause keeps every message
    let (dir, _) = bag("no-outlier", Some(T0_NS + 1_800_000_000_000));
    let b = Bag::read(&dir).unwrap();
    assert!(
        (b.excluded_count() == 0) && b.message_count() == N + 1,
        "{}",
        notes(&b)
    );
}
