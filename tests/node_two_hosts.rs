//! Two hosts: the node in one network namespace, Cyclone DDS peers in another, joined only by a
//! veth pair (tests/interop/two_hosts_scenario.sh, all inside `unshare -n`): discovery by
//! multicast across the link, the speed in, journal states and the latched warning out.

mod common;
use common::node::Scenario;

#[test]
fn node_and_peer_on_two_hosts_find_each_other() {
    let py = common::python();
    let run = Scenario::new("hosts");
    run.run("two_hosts_scenario.sh", [&py, &run.out]);
    let file = |name: &str| run.file(name);
    let log = format!("node:\n{}\npeer:\n{}", file("node.err"), file("peer.err"));
    let json = |name: &str| run.json(name, &["node.err", "peer.err"]);
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
    run.remove();
}
