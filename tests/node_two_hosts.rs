//! Two hosts: the node in one network namespace, Cyclone DDS peers in another, joined only by a
//! veth pair (tests/interop/two_hosts_scenario.sh, all inside `unshare -n`): discovery by
//! multicast across the link, the speed in, journal states and the latched warning out.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

#[test]
fn node_and_peer_on_two_hosts_find_each_other() {
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
    let out = std::env::temp_dir().join(format!("rotor-twin-hosts-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    let status = Command::new("unshare")
        .env(
            "ROTOR_TWIN_CACHE_DIR",
            concat!(env!("CARGO_TARGET_TMPDIR"), "/film-cache"),
        )
        .args(["-n", "bash"])
        .arg(root.join("tests/interop/two_hosts_scenario.sh"))
        .arg(env!("CARGO_BIN_EXE_rotor-twin"))
        .arg(&py)
        .arg(&out)
        .status()
        .expect("unshare (needs root: every DDS test runs in a private network namespace)");
    assert!(status.success());
    let file = |name: &str| std::fs::read_to_string(out.join(name)).unwrap_or_default();
    let log = format!("node:\n{}\npeer:\n{}", file("node.err"), file("peer.err"));
    let json = |name: &str| -> Value {
        serde_json::from_str(&file(name)).unwrap_or_else(|e| panic!("{name}: {e}\n{log}"))
    };
    // host B has loopback and its end of the link only: whatever it got crossed the veth pair
    let addrs = file("b_addr.txt");
    let ifaces: Vec<&str> = addrs
        .lines()
        .filter(|l| l.contains(" inet "))
        .map(|l| l.split_whitespace().nth(1).unwrap_or(""))
        .collect();
    assert_eq!(ifaces, ["lo", "vb"], "{addrs}");
    let peer = json("peer.json");
    assert!(peer["journal"].as_u64().unwrap_or(0) > 100, "{peer}\n{log}");
    let speeds = peer["speeds"].as_array().unwrap();
    assert!(!speeds.is_empty(), "{peer}");
    // 9,200 rpm sent from host B is the speed of every journal state from host A
    assert!(speeds
        .iter()
        .all(|s| (s.as_f64().unwrap() - 963.42).abs() < 1e-9));
    // a late subscriber on host B gets the latched warning (transient local) across
    let late = json("late.json");
    assert!(!late["warnings"].as_array().unwrap().is_empty(), "{late}");
    assert!(
        log.contains("host b exit 0") && log.contains("node exit 0"),
        "{log}"
    );
    std::fs::remove_dir_all(&out).ok();
}
