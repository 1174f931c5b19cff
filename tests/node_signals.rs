//! The live node with a plant's own signals (issue 12) and the count of every input sample lost
//! (issue 15, item 8), against an independent Cyclone DDS peer (tests/interop/signal_peer.py) in a
//! private network namespace (`unshare -n`, loopback only): the keyphasor as std_msgs/Header and
//! the raw probes as std_msgs/Float64 topics, selected by node parameters (`keyphasor_type`,
//! `probe_signal_topics`), all best effort.

mod common;
use common::node::Scenario;
use rotor_twin::rotor::DEFAULT_MACHINE_YAML;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The built-in machine with raw probes in µm at 45° and 135° at probe_outboard, AC-coupled, or
/// DC-coupled about a 1,000 µm gap with `dc`.
fn machine(out: &Path, dc: bool) -> PathBuf {
    let coupling = if dc {
        "dc, reference_gap: 1000.0"
    } else {
        "ac"
    };
    let mut yaml = format!("{DEFAULT_MACHINE_YAML}\nproximity_probes:\n");
    for (suffix, angle) in [("x", 45.0), ("y", 135.0)] {
        yaml += &format!(
            "  - {{name: probe_outboard_{suffix}, station: probe_outboard, angle_deg: {angle}, unit: um, coupling: {coupling}}}\n"
        );
    }
    let path = out.join("machine.yaml");
    std::fs::write(&path, yaml).unwrap();
    path
}

/// Runs tests/interop/signal_scenario.sh (SECONDS RPM STOP_KEYPHASOR_AFTER LOSS_PER_MILLE
/// UNAPPLY_AFTER OIL) and
/// returns (peer.json, recorded.json, the node's log).
fn scenario(name: &str, args: [&str; 6]) -> (Value, Value, String) {
    scenario_with(name, args, None)
}

/// [`scenario`] with DC-coupled probes and the peer's plant (signal_peer.py `--plant`) when
/// `plant` (its JSON) is given.
fn scenario_with(name: &str, args: [&str; 6], plant: Option<Value>) -> (Value, Value, String) {
    // one scenario at a time: two nodes and two peers side by side starve the pairing of
    // unstamped Float64 readings on two cores
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let py = common::python();
    let run = Scenario::new(name);
    let mut all = vec![py.into_os_string(), run.out.clone().into_os_string()];
    all.push(machine(&run.out, plant.is_some()).into_os_string());
    all.extend(args.map(Into::into));
    if let Some(p) = plant {
        let path = run.out.join("plant.json");
        std::fs::write(&path, p.to_string()).unwrap();
        all.push(path.into_os_string());
    }
    run.run("signal_scenario.sh", all);
    let read = |file: &str| run.json(file, &["node.err", "peer.err"]);
    let got = (
        read("peer.json"),
        read("recorded.json"),
        run.file("node.err"),
    );
    run.remove();
    got
}

fn lag_gap(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A forward 1X circle of 2 µm lagging the keyphasor by 50° at 1,500 rpm, read by probes at 45°
/// and 135°: the node publishes, per block of 8 revolutions, each axis's phase lag β + α (95°,
/// 185°) and amplitude. The peer computes each value for the instant it sends it, and a Float64
/// is timed by its receive time, so the lag reads late by ω × the transport latency (1° is
/// 0.11 ms here) and the scheduling jitter of both processes is phase noise: the median over the
/// blocks within 5° (the tolerance) and 3 %, each block within 15° and 10 % but one
/// (a stalled block; a loaded machine: 3.6° and 3 % seen with another test running). When the keyphasor stops at 4 s (the
/// speed topic goes on), the blocks after it have empty phase lags with the reason and the node
/// warns "keyphasor stopped"; the amplitudes go on.
#[test]
fn the_node_publishes_phase_lags_from_a_header_keyphasor_and_float64_probes() {
    let (peer, rec, log) = scenario("signals", ["6", "1500", "4", "0", "4.5", "0"]);
    let blocks = peer["one_x"].as_array().unwrap();
    let stop = peer["keyphasor_stopped_at_s"].as_f64().unwrap();
    let (mut gaps, mut amps, mut null) = ([Vec::new(), Vec::new()], Vec::new(), 0);
    let (mut outliers, mut amp_outliers) = (0, 0);
    for b in blocks {
        let t = b["t_s"].as_f64().unwrap();
        for a in b["measured_amplitudes"].as_array().unwrap() {
            let r = a.as_f64().unwrap() / 2e-6 - 1.0;
            if r.abs() >= 0.1 {
                // the same stall as a phase outlier (below): a block's samples timed late
                println!("block at {t:.3} s: an amplitude outlier beyond 10 %: {b}");
                amp_outliers += 1;
            }
            amps.push(r);
        }
        let lags = b["measured_phase_lags_deg"].as_array().unwrap();
        if t < stop {
            assert_eq!(lags.len(), 2, "{b}");
            for (j, want) in [95.0, 185.0].iter().enumerate() {
                let d = lag_gap(lags[j].as_f64().unwrap(), *want);
                println!(
                    "block at {t:.3} s: axis {j} lag {} against {want} ({d:+.2}°)",
                    lags[j]
                );
                if d.abs() >= 15.0 {
                    // a Float64 is timed by its receive time: a scheduling stall of either
                    // process while a block fills shifts its phase (seen once in a full-suite
                    // run: −20° / +38° in one block of 104 samples, the others within 3.3°)
                    println!("block at {t:.3} s: an outlier beyond 15°: {b}");
                    outliers += 1;
                }
                gaps[j].push(d);
            }
        } else if t > stop + 0.1 {
            assert!(lags.is_empty(), "{b}");
            assert!(b["reason"].as_str().unwrap().contains("stopped"), "{b}");
            null += 1;
        }
    }
    let locked = gaps[0].len();
    let (g0, g1, a) = (
        median(gaps[0].clone()),
        median(gaps[1].clone()),
        median(amps),
    );
    println!(
        "{locked} locked blocks: median lag error {g0:+.2}° / {g1:+.2}°, amplitude {:+.2} %; {null} null after the stop; {}",
        100.0 * a,
        rec["diagnostics"]
    );
    assert!(locked >= 6 && null >= 4, "{peer}");
    // at most one block (both its axes) beyond 15°: the rest of the blocks hold the lag
    assert!(outliers <= 2, "{outliers} axis readings beyond 15°");
    assert!(amp_outliers <= 2, "{amp_outliers} amplitudes beyond 10 %");
    assert!(g0.abs() < 5.0 && g1.abs() < 5.0 && a.abs() < 0.03);
    let stale = peer["warnings"]["stale_input"].to_string();
    assert!(stale.contains("keyphasor stopped"), "{stale}");
    assert_eq!(rec["diagnostics"]["keyphasor"], "stopped");
    // a true speed topic: no relock, no mismatch, no scale (the counts are in `/diagnostics`)
    assert_eq!(
        rec["diagnostics"]["keyphasor_relocks"], "0",
        "{}",
        rec["diagnostics"]
    );
    assert_eq!(rec["diagnostics"]["speed_mismatches"], "0");
    assert_eq!(rec["diagnostics"]["speed_topic_scale"], "none");
    // recorded as received, in their own types
    let c = &rec["counts"];
    assert_eq!(
        c["/plant/probe_outboard_x"],
        peer["sent"]["/plant/probe_outboard_x"]
    );
    assert_eq!(c["/rotor_twin/keyphasor"], peer["sent"]["/plant/keyphasor"]);
    assert_eq!(
        c["/rotor_twin/one_x"].as_u64().unwrap(),
        blocks.len() as u64
    );
    assert_eq!(rec["diagnostics"]["lost_samples"], "0");
    // the live calibration (calibration_period_s:=2, calibration_apply:=true): the unbalance
    // from the keyphasor-referenced 1X vectors, published, recorded and applied (logged); no
    // viscosity from AC-coupled probes, with the reason; `param set calibration_apply:=false`
    // at 4.5 s takes it back (logged), and the last estimate recorded says it is not applied
    let cal = &rec["calibration"];
    println!("calibration: {cal}");
    assert_eq!(cal["unbalance_valid"], true, "{cal}");
    assert_eq!(cal["applied_before"], true, "{cal}");
    assert_eq!(cal["applied"], false, "{cal}");
    assert!(log.contains("calibration taken back"), "{log}");
    assert_eq!(cal["viscosity_valid"], false, "{cal}");
    assert!(
        cal["viscosity_reason"]
            .as_str()
            .unwrap()
            .contains("mean position"),
        "{cal}"
    );
    assert!(log.contains("calibration applied to the twin"), "{log}");
}

/// The peer's Cyclone DDS drops 5 % of the datagrams it sends (its XmitLossiness test option): a
/// lossy best-effort link. Every sample sent is recorded or counted lost (the sequence gaps of
/// /diagnostics' `lost_samples <topic>`), per topic, up to 2 (a loss before a writer's first
/// or after its last delivered sample shows no gap), and losses were counted on every topic.
/// Before, such losses were invisible (`dropped_messages 0`).
#[test]
fn every_sample_lost_on_a_best_effort_link_is_counted() {
    let (peer, rec, _) = scenario("signal-loss", ["6", "1500", "100", "50", "0", "0"]);
    let d = &rec["diagnostics"];
    println!("{d}");
    let mut lost_all = 0;
    for (sent_topic, recorded_topic) in [
        ("/plant/probe_outboard_x", "/plant/probe_outboard_x"),
        ("/plant/probe_outboard_y", "/plant/probe_outboard_y"),
        ("/rotor_twin/speed", "/rotor_twin/speed"),
        ("/plant/keyphasor", "/rotor_twin/keyphasor"),
    ] {
        let sent = peer["sent"][sent_topic].as_u64().unwrap();
        let recorded = rec["counts"][recorded_topic].as_u64().unwrap();
        let lost: u64 = d[format!("lost_samples {sent_topic}")]
            .as_str()
            .unwrap_or("0")
            .parse()
            .unwrap();
        println!("{sent_topic}: sent {sent}, recorded {recorded}, counted lost {lost}");
        assert!(
            recorded + lost <= sent && recorded + lost + 2 >= sent,
            "{sent_topic}"
        );
        if sent > 500 {
            assert!(lost > 0, "{sent_topic}: 5 % of {sent} lost, none counted");
        }
        lost_all += lost;
    }
    assert_eq!(d["lost_samples"].as_str().unwrap(), lost_all.to_string());
}

/// The viscosity scale the driver sets for an oil supply temperature (°C) on the node's machine
/// (the built-in law, config/orc_microturbine_100kw.yaml), fed offline as tests/oil_temperature.rs
/// feeds it: the reference for the node's /diagnostics.
fn offline_scale(celsius: f64) -> f64 {
    use rotor_twin::driver::{Driver, DriverSettings, Fed, Input, ModelKind};
    use rotor_twin::messages::{Header, Temperature, Time};
    let rotor = rotor_twin::rotor::Rotor::from_description(
        &rotor_twin::rotor::MachineDescription::builtin_default(),
    );
    let settings = DriverSettings::new(
        ModelKind::Linear,
        rotor_twin::dynamics::FilmEvaluation::Direct,
        rotor.rated_speed_rad_s,
    );
    let mut d = Driver::new(rotor, settings);
    let t = Input::from(&Temperature {
        header: Header {
            stamp: Time::from_nanos(0),
            frame_id: String::new(),
        },
        temperature: celsius,
        variance: 0.0,
    });
    assert_eq!(d.feed(0, t, &mut |_| {}), Fed::Taken);
    d.viscosity_scale()
}

/// Issue 12 (referee's gap 2): sensor_msgs/Temperature (°C) through DDS from the independent
/// Cyclone peer, best effort, on /plant/oil_temperature (the node's rotor_twin/oil_temperature
/// remapped): 60 °C for the first 3 s, then 50 °C, then one NaN and one 1,000 °C and nothing
/// more. The node's viscosity in force, as its /diagnostics (status `<node>: model`) reports it
/// per film bearing, moves to the driver's scale for 60 °C (× 0.7989 on the built-in law) and
/// then 50 °C, each equal to the offline driver's to the 5 decimals printed; the NaN and the
/// absurd value are refused, counted (`refused_inputs` ≥ 2) and warned about (`bad_input`
/// naming the temperature), and the last good 50 °C stays in force; every Temperature sent is
/// recorded as received.
#[test]
fn a_best_effort_temperature_on_the_bus_sets_the_viscosity_and_bad_ones_are_refused() {
    let (peer, rec, _) = scenario("signal-oil", ["6", "1500", "100", "0", "0", "1"]);
    let oil = rec["oil"].as_array().unwrap();
    println!("oil in force over the run: {oil:?}");
    println!(
        "inputs: {}; warnings: {}",
        rec["diagnostics"], peer["warnings"]
    );
    let key = "viscosity_scale bearing_pulley_end";
    let scale = |v: &Value| v[key].as_str().unwrap().parse::<f64>().unwrap();
    let (hot, warm) = (offline_scale(60.0), offline_scale(50.0));
    println!("offline driver: × {hot:.5} at 60 °C, × {warm:.5} at 50 °C");
    let seen = |c: &str, s: f64| {
        oil.iter().any(|v| {
            v["oil_supply_temperature_c"].as_str() == Some(c) && (scale(v) - s).abs() < 1e-5
        })
    };
    assert!(seen("60.00", hot), "60 °C never in force: {oil:?}");
    assert!(seen("50.00", warm), "50 °C never in force: {oil:?}");
    let last = oil.last().unwrap();
    assert_eq!(last["oil_supply_temperature_c"], "50.00", "{oil:?}");
    assert!((scale(last) - warm).abs() < 1e-5, "{last}");
    assert!(
        (hot - 1.0).abs() > 0.1,
        "60 °C must move the viscosity: × {hot}"
    );
    let refused: u64 = rec["diagnostics"]["refused_inputs"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!(refused >= 2, "{refused} refused");
    let bad = peer["warnings"]["bad_input"].to_string();
    assert!(bad.contains("temperature"), "{bad}");
    // recorded under the node's topic name (the remap's target), as the keyphasor is
    assert_eq!(
        rec["counts"]["/rotor_twin/oil_temperature"],
        peer["sent"]["/plant/oil_temperature"]
    );
}

/// Issue 12 (referee's gap 1), what a short run through the bus reaches: the live viscosity
/// calibration from DC-coupled raw probes published BEST EFFORT by the independent Cyclone peer
/// (std_msgs/Float64, µm, about a 1,000 µm gap at 45° and 135° at probe_outboard). The plant is
/// the one of tests/live_calibration.rs statically (oil × 1.10, films on 72 × 12 instead of the
/// twin's 60 × 10): its journal's mean position at 1,500, 2,500 and 3,500 rpm
/// (`calibrate::static_probe_positions` of the plant's machine), 2.5 s each, is the probes' DC
/// part; a forward 1X circle of 2 µm (the peer's) rides on it, and the keyphasor marks each
/// revolution. The node (`calibration_period_s:=2`) publishes its estimate on
/// /rotor_twin/calibration (recorded): the viscosity × 1.10 within 3 % (the issue's), from at least
/// 3 mean positions. Not asserted: the unbalance (the peer's 1X circle is not the plant's
/// unbalance response: a Float64 is timed by its receive time, so the plant's own 1X at its
/// 5,000–8,000 rpm would need stamped samples, and its nonlinear transient a minute of solving
/// per speed; tests/live_calibration.rs checks it through the driver, tests/node_bus_unbalance.rs
/// through the bus from stamped samples of the solved plant); the speeds are low for the
/// same reason (16 samples a revolution from Python: 930 Hz at 3,500 rpm).
#[test]
fn the_node_calibrates_the_viscosity_from_best_effort_dc_probes_of_an_independent_peer() {
    use common::calibration::{plant_rotor, twin_rotor};
    let plant = plant_rotor(&twin_rotor());
    let station = plant
        .probes
        .iter()
        .position(|p| p.name == "probe_outboard")
        .unwrap();
    let mut segments = Vec::new();
    for (k, rpm) in [1500.0f64, 2500.0, 3500.0].into_iter().enumerate() {
        let w = rpm * std::f64::consts::PI / 30.0;
        let xy = rotor_twin::calibrate::static_probe_positions(&plant, 1.0, w).unwrap()[station];
        let along = |deg: f64| {
            let a = deg.to_radians();
            1e6 * (xy[0] * a.cos() + xy[1] * a.sin())
        };
        println!(
            "plant at {rpm} rpm: mean position {:.3} / {:.3} µm along the probes",
            along(45.0),
            along(135.0)
        );
        segments.push(serde_json::json!({
            "t_s": 2.5 * k as f64, "rpm": rpm, "dc_um": [along(45.0), along(135.0)]
        }));
    }
    let plant_json = serde_json::json!({ "segments": segments });
    let (peer, rec, log) = scenario_with(
        "signal-calib",
        ["8", "1500", "100", "0", "0", "0"],
        Some(plant_json),
    );
    let cal = &rec["calibration"];
    println!("calibration: {cal}; inputs {}", rec["diagnostics"]);
    println!(
        "{} 1X blocks received by the peer",
        peer["one_x"].as_array().unwrap().len()
    );
    assert_eq!(cal["viscosity_valid"], true, "{cal}\n{log}");
    let (s, sigma) = (
        cal["viscosity_scale"].as_f64().unwrap(),
        cal["viscosity_scale_std"].as_f64().unwrap(),
    );
    println!(
        "viscosity × {s:.4} ± {sigma:.4} for the plant's × 1.10 ({:+.2} %, {:+.2} σ), from {} mean positions",
        100.0 * (s / 1.10 - 1.0),
        (s - 1.10) / sigma,
        cal["positions"]
    );
    assert!(cal["positions"].as_u64().unwrap() >= 3, "{cal}");
    assert!((s / 1.10 - 1.0).abs() < 0.03, "{cal}");
    // the reported σ (fit and model floor) covers it at k = 2 (tests/calibrate.rs)
    assert!((s - 1.10).abs() <= 2.0 * sigma, "{cal}");
}
