//! The node against real ROS 2 Jazzy: rclpy on Fast DDS (third-party wheels from PyPI, set up on
//! first use into tests/.venv-ros by tests/interop/setup-venv-ros.sh; ~30 s of pip here), a second
//! DDS implementation beside the Cyclone peers. What a ROS 2 user checks first: the graph (node
//! name and namespace, one type per topic, /clock included), /rosout, a best-effort and a
//! reliable publisher both driving the twin, simulation time from a rosgraph_msgs/Clock
//! publisher, and the six parameter services with descriptors. All inside `unshare -n`.

mod common;
use common::node::Scenario;
use serde_json::Value;

fn run_scenario() -> (Value, String) {
    let venv = common::node::ros_venv();
    let run = Scenario::new("rclpy");
    run.run("rclpy_scenario.sh", [&venv, &run.out]);
    let log = format!(
        "node:\n{}\npeer:\n{}",
        run.file("node.err"),
        run.file("peer.err")
    );
    let peer = run.json("peer.json", &["node.err", "peer.err"]);
    run.remove();
    (peer, log)
}

/// The `inputs` diagnostics levels seen between `from` + 1.5 s (a diagnostics period and the
/// 1 s input timeout) and `to` (s since the peer started).
fn input_levels(p: &Value, from: f64, to: f64) -> Vec<u64> {
    p["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["name"].as_str().unwrap_or("").ends_with(": inputs"))
        .filter(|d| (from + 1.5..to).contains(&d["t"].as_f64().unwrap()))
        .map(|d| d["level"].as_u64().unwrap())
        .collect()
}

#[test]
fn rclpy_peer_sees_a_ros2_node() {
    let (p, log) = run_scenario();
    assert!(
        log.contains("peer exit 0") && log.contains("node exit 0"),
        "{log}"
    );

    // graph: name and namespace from -r __node:= -r __ns:=, one type per topic
    let nodes = p["nodes"].as_array().unwrap();
    assert!(
        nodes.contains(&serde_json::json!(["twin_r", "/line1"])),
        "{nodes:?}"
    );
    let topics = p["topics"].as_object().unwrap();
    for (topic, ty) in [
        // only the node's rosgraph_msgs reader: ros2-client's Spinner added builtin_interfaces/Time
        ("/clock", "rosgraph_msgs/msg/Clock"),
        ("/line1/rotor_twin/speed", "std_msgs/msg/Float64"),
        (
            "/line1/rotor_twin/journal_state",
            "rotor_twin_msgs/msg/JournalState",
        ),
        ("/rosout", "rcl_interfaces/msg/Log"),
        ("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray"),
    ] {
        assert_eq!(
            topics[topic],
            serde_json::json!([ty]),
            "{topic}: {topics:?}"
        );
    }
    for (topic, types) in topics {
        assert_eq!(types.as_array().unwrap().len(), 1, "{topic}: {types}");
    }

    // /rosout: the start-up line, logger named as rcl names it, INFO (20)
    let rosout = p["rosout"].as_array().unwrap();
    assert!(
        rosout.iter().any(|l| l["name"] == "line1.twin_r"
            && l["level"] == 20
            && l["msg"].as_str().unwrap_or("").contains("up on ROS domain")),
        "{rosout:?}"
    );

    // both publishers drive the twin: fresh (0) with each, stale (3) in the pause between
    let m = &p["phase_marks"];
    let t = |k: &str| m[k].as_f64().unwrap();
    let best_effort = input_levels(&p, t("best_effort_from"), t("pause_from"));
    let pause = input_levels(&p, t("pause_from"), t("reliable_from"));
    let reliable = input_levels(&p, t("reliable_from"), t("end"));
    assert!(
        !best_effort.is_empty() && best_effort.iter().all(|&l| l == 0),
        "{best_effort:?}"
    );
    assert!(
        !pause.is_empty() && pause.iter().all(|&l| l == 3),
        "{pause:?}"
    );
    assert!(
        !reliable.is_empty() && reliable.iter().all(|&l| l == 0),
        "{reliable:?}"
    );

    // simulation time: every diagnostics stamp is the peer's clock (1000 s + elapsed), within
    // one clock period and the delivery time; the wall clock would read 1.8e9 s
    for d in p["diagnostics"].as_array().unwrap() {
        let (stamp, at) = (d["stamp"].as_f64().unwrap(), d["t"].as_f64().unwrap());
        assert!((stamp - (1000.0 + at)).abs() < 0.3, "{d}");
    }
    check_parameters(&p);
}

fn check_parameters(p: &Value) {
    // list: exactly the documented parameters
    let mut listed: Vec<&str> = p["list"]
        .as_array()
        .expect("list_parameters answered")
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let mut documented: Vec<&str> = rotor_twin::ros::PARAMETER_DOCS
        .iter()
        .map(|d| d.name)
        .collect();
    listed.sort_unstable();
    documented.sort_unstable();
    assert_eq!(listed, documented);

    // describe: type, description, range, read_only (rcl_interfaces/ParameterType: 2 integer,
    // 3 double, 0 not set)
    let d = p["describe"]
        .as_array()
        .expect("describe_parameters answered");
    assert_eq!(d[0]["type"], 3);
    assert_eq!(d[0]["read_only"], false);
    assert!(d[0]["description"].as_str().unwrap().contains("(Hz)"));
    assert_eq!(d[1]["type"], 2);
    assert_eq!(d[1]["read_only"], true);
    assert_eq!(d[1]["integer_range"], serde_json::json!([[16, 4096, 1]]));
    assert_eq!(
        d[2]["floating_point_range"],
        serde_json::json!([[0.0, 1.0]])
    );
    assert_eq!(d[3]["type"], 0);
    assert_eq!(p["types"], serde_json::json!([3, 4, 1]));

    // set: a double accepted, an integer for a double refused (as rclcpp without dynamic
    // typing), a start-only parameter refused; the atomic set refused whole for one bad value
    let set = &p["set"];
    assert_eq!(set[0][0], true, "{set}");
    assert_eq!(set[1][0], false, "{set}");
    assert!(set[1][1].as_str().unwrap().contains("type"), "{set}");
    assert_eq!(set[2][0], false, "{set}");
    assert!(
        set[2][1].as_str().unwrap().contains("only be set at start"),
        "{set}"
    );
    assert_eq!(p["atomic"][0], false, "{}", p["atomic"]);
    assert!(p["atomic"][1].as_str().unwrap().contains("min_speed_rpm"));
    assert_eq!(p["set_one"], serde_json::json!([[true, ""]]));
    assert_eq!(p["atomic_two"], serde_json::json!([true, ""]));
    let got = &p["get"];
    assert_eq!(
        got[0],
        serde_json::json!([3, 40.0, ""]),
        "40.0 of the accepted atomic set, 25.0 of the refused one not applied"
    );
    assert_eq!(got[1][1], 1000.0, "{got}");
    assert_eq!(got[2][2], "float64", "{got}");
    check_parameter_events(&p["parameter_events"]);
}

/// /parameter_events as rclcpp publishes them (rclcpp node_parameters.cpp): a plain set of N
/// values is N atomic sets of one, so one event per accepted value (the set of three had one
/// accepted); `ros2 param set` of one value, one event; an atomic set of two, ONE event with both;
/// a refused atomic set, none. Every stamp is the node's clock, i.e. the peer's /clock (1000 s +
/// elapsed) within 0.3 s (clock period 10 ms + delivery); ros2-client's own events were one per
/// value, stamped 0 under use_sim_time.
fn check_parameter_events(e: &Value) {
    let changed = |label: &str| -> Vec<Value> {
        let events = e[label]
            .as_array()
            .unwrap_or_else(|| panic!("{label}: {e}"));
        for ev in events {
            let (stamp, at) = (
                ev["stamp"].as_f64().unwrap(),
                ev["sim_at"].as_f64().unwrap(),
            );
            assert!(
                (at - stamp).abs() < 0.3,
                "{label}: stamp {stamp} at {at}: {ev}"
            );
            assert_eq!(ev["new"], serde_json::json!([]), "{label}: {ev}");
            assert_eq!(ev["deleted"], serde_json::json!([]), "{label}: {ev}");
        }
        events.iter().map(|ev| ev["changed"].clone()).collect()
    };
    assert_eq!(
        changed("set_three"),
        [serde_json::json!([["state_rate_hz", 50.0]])]
    );
    assert_eq!(
        changed("set_one"),
        [serde_json::json!([["input_timeout_s", 2.0]])]
    );
    assert_eq!(
        changed("atomic_two"),
        [serde_json::json!([
            ["state_rate_hz", 40.0],
            ["pressure_map_rate_hz", 5.0]
        ])]
    );
    assert!(changed("atomic_refused").is_empty(), "{e}");
}
