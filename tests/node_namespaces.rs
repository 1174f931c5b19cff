//! Two twins on one bus, each in its own namespace (`-r __node:= -r __ns:=`, as launch_ros passes
//! them), against independent Cyclone DDS peers: each twin runs at the speed sent to its own
//! namespace, one fed by a best-effort publisher (REP 2003 sensor QoS), the other by a reliable
//! one; a parameter set on one twin leaves the other alone. All inside `unshare -n`.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

#[test]
fn two_twins_in_two_namespaces_each_follow_their_own_speed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let setup = Command::new("bash")
        .arg(root.join("tests/interop/setup-venv.sh"))
        .output()
        .expect("setup-venv.sh");
    assert!(
        setup.status.success(),
        "{}",
        String::from_utf8_lossy(&setup.stderr)
    );
    let py = root.join("tests/.venv/bin/python");
    let out = std::env::temp_dir().join(format!("rotor-twin-ns-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    let status = Command::new("unshare")
        .env(
            "ROTOR_TWIN_CACHE_DIR",
            concat!(env!("CARGO_TARGET_TMPDIR"), "/film-cache"),
        )
        .args(["-n", "bash"])
        .arg(root.join("tests/interop/namespace_scenario.sh"))
        .arg(env!("CARGO_BIN_EXE_rotor-twin"))
        .arg(&py)
        .arg(&out)
        .status()
        .expect("unshare (needs root: every DDS test runs in a private network namespace)");
    assert!(status.success());
    let file = |name: &str| std::fs::read_to_string(out.join(name)).unwrap_or_default();
    let peer = |name: &str| -> Value {
        serde_json::from_str(&file(name)).unwrap_or_else(|e| {
            panic!(
                "{name}: {e}\nnode a: {}\nnode b: {}",
                file("a.err"),
                file("b.err")
            )
        })
    };
    for (name, speed) in [("peer_a.json", 837.76), ("peer_b.json", 890.12)] {
        let p = peer(name);
        assert!(p["journal"].as_u64().unwrap_or(0) > 100, "{name}: {p}");
        let speeds: Vec<f64> = p["speeds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_f64().unwrap())
            .collect();
        // every journal state in this namespace carries this namespace's speed, never the other's
        assert!(
            speeds.iter().all(|s| (s - speed).abs() < 1e-9),
            "{name}: speeds {speeds:?}, expected only {speed}"
        );
    }
    let params = file("param.out");
    let lines: Vec<&str> = params.lines().collect();
    assert_eq!(
        lines,
        [
            "state_rate_hz:=50: set",
            "rc=0",
            "state_rate_hz: Double value is: 50.0",
            "rc=0",
            "state_rate_hz: Double value is: 200.0",
            "rc=0",
        ],
        "{params}"
    );
    let a = file("a.err");
    assert!(a.contains("ignored: --enclave /x"), "{a}");
    assert!(
        !a.contains("node /line1/twin_a up"),
        "--log-level warn quiets the notes: {a}"
    );
    assert!(
        file("b.err").contains("node /line2/twin_b up"),
        "{}",
        file("b.err")
    );
    assert!(a.contains("node exit 0") && file("b.err").contains("node exit 0"));
    std::fs::remove_dir_all(&out).ok();
}
