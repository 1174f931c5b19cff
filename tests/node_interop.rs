//! The live node against an independent DDS peer (a burst of 10,000 speed messages with NaNs and a
//! stale stamp among them included) (Cyclone DDS from PyPI), in a private network
//! namespace with loopback only (`unshare -n`): the twin reacts to the speed it is sent, refuses
//! bad speeds and says so, raises instability warnings that a late subscriber still gets, never
//! publishes a non-finite number, answers measured probe displacements with residuals, and leaves
//! a recording that independent readers open after
//! SIGINT.

mod common;
use common::node::Scenario;

#[test]
fn node_talks_to_an_independent_peer_and_records() {
    let py = common::python();
    let run = Scenario::new("node");
    run.run("node_scenario.sh", [&py, &run.out]);
    let read = |name: &str| run.json(name, &["node.err"]);
    let peer = read("peer.json");
    println!(
        "peer: {} journal states, first after {} s",
        peer["journal"], peer["first_journal_after_s"]
    );
    assert!(peer["journal"].as_u64().unwrap() > 100, "{peer}");
    assert_eq!(peer["nonfinite"], 0);
    // the twin runs at the speed it was sent
    assert!(
        peer["speeds"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| (s.as_f64().unwrap() - 963.42).abs() < 1e-9),
        "{peer}"
    );
    let kinds: Vec<&str> = peer["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"bad_input"), "{kinds:?}");
    assert!(
        kinds.iter().any(|k| *k == "whirl" || *k == "whip"),
        "{kinds:?}"
    );
    // measured probe displacements come back as predicted − measured residuals
    assert!(peer["residuals"].as_u64().unwrap() > 10, "{peer}");
    assert_eq!(peer["residual_ok"], true);
    // both probe routes: rotor_twin_msgs/ProbeDisplacement and a plant's geometry_msgs/PointStamped
    let stations = peer["stations"].as_array().unwrap();
    assert!(
        stations.iter().any(|s| s == "probe_outboard")
            && stations.iter().any(|s| s == "probe_pulley_end"),
        "{peer}"
    );
    // the stability margin: the linear threshold of `rotor-twin modes` on the node's machine,
    // reading (A), config/orc_microturbine_100kw_d55.yaml (8,471 rpm = 887.1 rad/s)
    let m = &peer["margin"];
    assert_eq!(m["threshold_found"], true, "{peer}");
    let threshold = m["threshold_speed"].as_f64().unwrap();
    assert!((threshold - 887.1).abs() < 0.01 * 887.1, "{m}");
    assert!(
        (m["margin"].as_f64().unwrap() - (threshold - 963.42)).abs() < 1e-6,
        "{m}"
    );
    let late = read("late.json");
    assert!(
        !late["warnings"].as_array().unwrap().is_empty(),
        "the late subscriber got no latched warning: {late}"
    );
    let node_err = run.file("node.err");
    assert!(node_err.contains("recording finished"), "{node_err}");
    assert!(node_err.contains("node exit 0"), "{node_err}");
    // the recording opens in rosbags and mcap-ros2-support with every topic
    let v = run.read_bag("bag");
    for reader in ["rosbags", "mcap_ros2"] {
        let c = &v[reader]["counts"];
        for topic in [
            "/rotor_twin/speed",
            "/rotor_twin/journal_state",
            "/rotor_twin/film_state",
            "/rotor_twin/orbit",
            "/rotor_twin/warning",
            "/diagnostics",
        ] {
            assert!(
                c[topic].as_u64().unwrap_or(0) > 0,
                "{reader}: no {topic} in the recording: {v}"
            );
        }
    }
    assert_eq!(
        v["rosbags"]["types"]["/rotor_twin/journal_state"],
        "rotor_twin_msgs/msg/JournalState"
    );
    // the burst of 10,000 speeds (100 of them NaN, one 10 s stale) is recorded whole: nothing lost
    let recorded = v["rosbags"]["counts"]["/rotor_twin/speed"]
        .as_u64()
        .unwrap();
    println!("speed messages recorded: {recorded} (burst of 10,000 plus the steady stream)");
    assert_eq!(
        recorded,
        peer["sent"].as_u64().unwrap(),
        "every message the peer sent is recorded"
    );
    let evidence: Vec<&str> = peer["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["kind"] == "bad_input")
        .map(|w| w["evidence"].as_str().unwrap())
        .collect();
    assert!(
        evidence.iter().any(|e| e.contains("rejected")),
        "{evidence:?}"
    );
    run.remove();
}

/// Malformed samples on the bus (the right type name, a 1-byte body: the node cannot decode them)
/// on the speed, probe and PointStamped probe topics, every 2 s among a speed ramp 400 → 900 →
/// 400 rad/s and 4 kHz probes (tests/interop/load_peer.py --bad --no-nan, 6 s): each is counted
/// (the diagnostics' refused_inputs), reported (a bad_input warning that names the topic), skipped, and the subscriptions live on: the twin follows the ramp after
/// them and every valid sample is recorded (issue 15, item 1: one such sample ended the input's
/// subscription, 4 of 524 speeds were recorded).
#[test]
fn malformed_samples_are_counted_and_the_inputs_live_on() {
    let py = common::python();
    let run = Scenario::new("load");
    run.run(
        "load_scenario.sh",
        [py.as_os_str(), run.out.as_os_str(), "6".as_ref()],
    );
    let read = |name: &str| run.json(name, &[]);
    let peer = read("peer.json");
    let malformed = peer["malformed"].as_u64().unwrap();
    println!("load peer: {peer}");
    assert!(malformed >= 6, "{peer}");
    assert_eq!(peer["nonfinite"], 0);
    let evidence = peer["warnings"]["bad_input"].to_string();
    assert!(evidence.contains("does not decode"), "{evidence}");
    // the twin follows the ramp after the first malformed sample: 400 → 900 → 400 rad/s in 6 s
    let after = peer["speed_after_malformed"].as_array().unwrap();
    let (lo, hi) = (after[0].as_f64().unwrap(), after[1].as_f64().unwrap());
    assert!(
        hi - lo > 300.0,
        "speeds after the first malformed sample: {lo}…{hi}"
    );
    // counted: the diagnostics' refused_inputs (1 s apart: the last may miss the last second,
    // 3 malformed samples at most)
    let refused = read("diagnostics.json")["refused_inputs"].as_u64().unwrap();
    println!("refused_inputs {refused} of {malformed} malformed samples sent");
    assert!(
        refused <= malformed && refused + 3 >= malformed,
        "refused {refused}, malformed {malformed}"
    );
    // every sample that decodes is recorded
    let v = run.read_bag("bag");
    let c = &v["rosbags"]["counts"];
    assert_eq!(c["/rotor_twin/speed"], peer["sent_speeds"], "{c}");
    assert_eq!(c["/plant/probe_b"], peer["sent_points"], "{c}");
    assert_eq!(c["/rotor_twin/probe"], peer["sent_probes"], "{c}");
    run.remove();
}

/// With use_sim_time the model follows `/clock` (rosgraph_msgs/Clock), not the wall clock: a peer
/// runs the simulation clock at half real time from 1,000 s for 6 s, and the node's journal states
/// are stamped from 1,000 s on and span half the wall time, 3 s (±20 %: start-up and the peer's
/// 10 ms loop), where the wall clock would have given 6 s. One /clock sample 1 h ahead, 2 s in,
/// is refused and said so (a bad_input warning naming /clock); before, it moved the node's clock
/// an hour ahead for good (issue 15, item 10), and the last stamp was 3,600 s later.
#[test]
fn node_follows_simulation_time() {
    let py = common::python();
    let run = Scenario::new("sim");
    run.run("sim_time_scenario.sh", [&py, &run.out]);
    let peer = run.json("peer.json", &[]);
    let stamps = peer["stamps"].as_array().unwrap();
    let (first, last) = (stamps[0].as_f64().unwrap(), stamps[1].as_f64().unwrap());
    println!("sim time: journal stamps {first:.3} … {last:.3} s over 6 s of wall time at rate 0.5");
    assert!((1000.0..1001.0).contains(&first), "{first}");
    let span = last - first;
    assert!((span - 3.0).abs() < 0.6, "span {span} s");
    assert_eq!(peer["outlier_sent"], true, "{peer}");
    assert!(
        peer["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w["evidence"].as_str().unwrap_or("").contains("/clock")),
        "no warning names the refused /clock sample: {peer}"
    );
    run.remove();
}

/// The parameter services over the bus (`rotor-twin param`, ros2-client's rcl_interfaces
/// client, as `ros2 param` would call them): a run-time parameter is set and reads back, a
/// start-only one is refused with the node's reason, and so is a bad value. The node runs with
/// ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST; an unknown range is refused, naming it.
#[test]
fn parameters_are_set_over_the_bus_where_safe() {
    let run = Scenario::new("param");
    run.run("param_scenario.sh", [&run.out]);
    let text = run.file("param.out");
    let lines: Vec<&str> = text.lines().collect();
    let expect = [
        "state_rate_hz:=50: set",
        "rc=0",
        "state_rate_hz: Double value is: 50.0",
        "model: String value is: nonlinear",
        "rc=0",
        "model:=linear: REFUSED: parameter model can only be set at start",
        "rc=1",
        "state_rate_hz:=-1: REFUSED: parameter state_rate_hz: -1 must be a rate above zero",
        "rc=1",
        "error: ROS_AUTOMATIC_DISCOVERY_RANGE 'NEARBY': must be SUBNET, LOCALHOST, OFF or SYSTEM_DEFAULT",
        "rc=1",
    ];
    let mut at = 0;
    for e in expect {
        let found = lines[at..].iter().position(|l| l.starts_with(e));
        assert!(found.is_some(), "missing '{e}' in:\n{text}");
        at += found.unwrap() + 1;
    }
    run.remove();
}
