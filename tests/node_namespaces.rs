//! Two twins on one bus, each in its own namespace (`-r __node:= -r __ns:=`, as launch_ros passes
//! them), against independent Cyclone DDS peers: each twin runs at the speed sent to its own
//! namespace, one fed by a best-effort publisher (REP 2003 sensor QoS), the other by a reliable
//! one; a parameter set on one twin leaves the other alone. All inside `unshare -n`.

mod common;
use common::node::Scenario;

#[test]
fn two_twins_in_two_namespaces_each_follow_their_own_speed() {
    let py = common::python();
    let run = Scenario::new("ns");
    run.run("namespace_scenario.sh", [&py, &run.out]);
    let file = |name: &str| run.file(name);
    let peer = |name: &str| run.json(name, &["a.err", "b.err"]);
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
    run.remove();
}
