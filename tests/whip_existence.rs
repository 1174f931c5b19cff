//! The whip's existence range (README "Existence range of the whip (hysteresis, issue #11)"):
//! of reading (A) (config/orc_microturbine_100kw_d55.yaml, Ø55, the built-in default until
//! session 15), the ends of the hysteresis loop below the linear threshold (8,471 rpm direct,
//! 8,458.5 rpm on the table); of the built-in reading (B) (Ø63, threshold 9,291 rpm), the whip's
//! run-down from 9,000 rpm; asserted with margins from measurements.
//! Tabulated film at 64 steps a revolution, as the README's study; whip = the `simulate`
//! verdict `whip` with a sub-synchronous semi-major axis above 25 µm (the README's study counts
//! above 10 µm; a developed whip here is 29–35 µm, a quiet orbit < 0.2 µm).

mod common;
use common::run_cli;
use serde_json::Value;

/// Reading (A)'s machine file.
const D55: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/config/orc_microturbine_100kw_d55.yaml"
);

/// `simulate` of reading (A) with the README's film options and `extra`: its JSON report.
fn simulate(extra: &[&str]) -> Value {
    simulate_on(&["--config", D55], extra)
}

/// `simulate` with `machine` (empty: the built-in one), the README's film options and `extra`.
fn simulate_on(machine: &[&str], extra: &[&str]) -> Value {
    let mut args = vec![
        "simulate",
        "--film",
        "table",
        "--steps-per-rev",
        "64",
        "--json",
    ];
    args.extend_from_slice(machine);
    args.extend_from_slice(extra);
    let (ok, out, err) = run_cli(&args);
    assert!(ok, "{args:?}: {err}");
    serde_json::from_str(&out).unwrap()
}

/// The larger sub-synchronous semi-major axis of the report's bearings (m).
fn subsync_m(v: &Value) -> f64 {
    v["bearings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["subsync_amplitude_m"].as_f64().unwrap())
        .fold(0.0, f64::max)
}

/// The `--history-csv` file's rows, then removed: (revolution, rpm, state, the larger
/// sub-synchronous semi-major axis of the two bearings, m).
fn history(csv: &std::path::Path) -> Vec<(usize, f64, String, f64)> {
    let text = std::fs::read_to_string(csv).unwrap();
    std::fs::remove_file(csv).ok();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let sub: Vec<usize> = (0..header.len())
        .filter(|&i| header[i].ends_with("_subsync_amplitude_m"))
        .collect();
    assert_eq!(sub.len(), 2, "{header:?}");
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let s = sub.iter().map(|&i| f[i].parse::<f64>().unwrap());
            (
                f[0].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].to_string(),
                s.fold(0.0, f64::max),
            )
        })
        .collect()
}

/// The lower end reached from above: a whip started at 7,800 rpm (2 N·s at mid-span, node 15,
/// at 0.05 s; a lasting whip within 50 revolutions, 33.8 µm at 0.50X, the run-down from 9,000
/// of the README reads 33.9 µm at 7,807 rpm: the same limit cycle), held 1 s, then run down at
/// −50 rpm/s to 7,100 rpm (`--speed-history 0:7800,1:7800,15:7100`, 10 revolutions more).
/// Measured (session 14): every revolution from the 100th down to 7,400 rpm `whip`, ≥ 30.8 µm;
/// the whip collapses below 10 µm at **7,242 rpm** (the README's path from 9,000: 7,244 rpm);
/// from 7,150 rpm on ≤ 2e-3 µm, `stable`. Asserted: whip at every speed ≥ 7,400 rpm (a whip
/// that died earlier, as a loop ending at the linear threshold would, fails), and gone, below
/// 1 µm and `stable`, at every revolution ≤ 7,150 rpm (a whip that outlived the range fails).
#[test]
fn a_whip_persists_on_the_run_down_to_7400_rpm_and_is_gone_by_7150() {
    let csv = std::env::temp_dir().join(format!("rotor-twin-rundown-{}.csv", std::process::id()));
    let v = simulate(&[
        "--speed-history",
        "0:7800,1:7800,15:7100",
        "--kick",
        "0.05:15:2:0",
        "--revs",
        "10",
        "--history-csv",
        csv.to_str().unwrap(),
    ]);
    let rows = history(&csv);
    let collapse = rows
        .iter()
        .find(|r| r.0 > 100 && r.3 < 10e-6)
        .map_or(f64::NAN, |r| r.1);
    let held = rows.iter().filter(|r| r.0 >= 100 && r.1 >= 7400.0);
    let weakest = held.clone().map(|r| r.3).fold(f64::INFINITY, f64::min);
    let after = rows.iter().filter(|r| r.1 <= 7150.0);
    let left = after.clone().map(|r| r.3).fold(0.0, f64::max);
    println!(
        "run-down: weakest whip at ≥ 7,400 rpm {:.2} µm, collapse below 10 µm at {collapse:.0} rpm, \
         largest sub-synchronous at ≤ 7,150 rpm {:.2e} µm, final {}",
        weakest * 1e6,
        left * 1e6,
        v["final_speed_rpm"]
    );
    assert!(held.clone().count() > 1000, "{} revolutions", held.count());
    for r in held {
        assert!(r.2 == "whip" && r.3 > 25e-6, "no whip at {r:?}");
    }
    assert!(after.clone().count() > 100, "{} revolutions", after.count());
    for r in after {
        assert!(r.2 == "stable" && r.3 < 1e-6, "whip left at {r:?}");
    }
}

/// The lower end reached by a push: 2 N·s at mid-span (node 15) at 0.05 s, 400 revolutions.
/// README (session 13): whip at 7,500 rpm and above, none at 7,400 and below. Measured
/// (session 14): 7,600 rpm `whip`, 32.9 µm at 0.505X, ε 0.88; 7,300 rpm `stable`, sub-synchronous
/// < 0.001 µm — although the whip exists there when reached from above (previous test: down to
/// 7,242 rpm): the push is too small for its basin. Asserted: whip above 25 µm at 7,600, stable
/// below 1 µm at 7,300.
#[test]
fn a_push_starts_a_whip_at_7600_rpm_not_at_7300() {
    let run = |rpm: &str| simulate(&["--speed-rpm", rpm, "--revs", "400", "--kick", "0.05:15:2:0"]);
    let (whip, none) = (run("7600"), run("7300"));
    println!(
        "kicked: 7600 rpm {} {:.3} µm; 7300 rpm {} {:.3} µm",
        whip["state"],
        subsync_m(&whip) * 1e6,
        none["state"],
        subsync_m(&none) * 1e6
    );
    assert_eq!(whip["state"], "whip", "{}", whip["evidence"]);
    assert!(subsync_m(&whip) > 25e-6);
    assert_eq!(none["state"], "stable", "{}", none["evidence"]);
    assert!(subsync_m(&none) < 1e-6);
}

/// The upper end of the quiet branch: started quietly at 8,400 rpm (71 rpm below the linear
/// threshold, 58 below the table's), 800 revolutions, the rotor stays stable. Measured (session
/// 14): `stable`, sub-synchronous 0.14 µm. Asserted: `stable` and below 1 µm. A threshold
/// 45 rpm below 8,400 fails it: the same run with `--fluid-inertia` (linear threshold 8,355 rpm,
/// README "Fluid-film inertia") reads `whirl`, 7.8 µm growing at +0.0073/rev (measured).
#[test]
fn a_quiet_start_at_8400_rpm_stays_stable() {
    let v = simulate(&["--speed-rpm", "8400", "--revs", "800"]);
    println!(
        "quiet 8400 rpm: {} {:.3} µm",
        v["state"],
        subsync_m(&v) * 1e6
    );
    assert_eq!(v["state"], "stable", "{}", v["evidence"]);
    assert!(subsync_m(&v) < 1e-6);
}

/// The built-in machine, reading (B): from a quiet start it whips at 9,000 rpm only, in a
/// half-speed window (≈ 8,975–9,125 rpm; 8,950 and 9,150 stay stable: README "Two readings of the
/// seed"), but once whipping the whip persists on a −50 rpm/s run-down far below that window
/// (`--speed-history 0:9000,6:9000,16:8500`, 100 revolutions more at 8,500). Measured (session
/// 15's referee, the same run on to 7,000 rpm): `whip` from revolution 315 (2.1 s), 32.05 µm at
/// 9,000, 25.8–31.6 µm through the run-down, collapsing at **8,546 rpm**, 0.01 µm by 8,485.
/// Asserted: `whip` above 20 µm at every revolution from 3 s down to 8,650 rpm (100 rpm above
/// the collapse: a loop confined to the quiet start's window fails), and gone at 8,500 rpm, the
/// last revolution `stable` below 1 µm (a whip that outlived its range fails): (B) is bistable
/// too, between ≈ 8,550 and 8,975 rpm, where its linear model is stable.
#[test]
fn the_default_machines_whip_persists_down_to_8650_rpm_and_is_gone_at_8500() {
    let csv = std::env::temp_dir().join(format!("rotor-twin-rundown-b-{}.csv", std::process::id()));
    let v = simulate_on(
        &[],
        &[
            "--speed-history",
            "0:9000,6:9000,16:8500",
            "--revs",
            "100",
            "--history-csv",
            csv.to_str().unwrap(),
        ],
    );
    let rows = history(&csv);
    let collapse = rows
        .iter()
        .find(|r| r.0 > 400 && r.3 < 10e-6)
        .map_or(f64::NAN, |r| r.1);
    let held: Vec<_> = rows
        .iter()
        .filter(|r| r.0 >= 450 && r.1 >= 8650.0)
        .collect();
    let weakest = held.iter().map(|r| r.3).fold(f64::INFINITY, f64::min);
    println!(
        "(B) run-down: weakest whip at ≥ 8,650 rpm {:.2} µm over {} revolutions, collapse below \
         10 µm at {collapse:.0} rpm, final {} {:.3} µm",
        weakest * 1e6,
        held.len(),
        v["state"],
        subsync_m(&v) * 1e6
    );
    assert!(held.len() > 1000, "{} revolutions", held.len());
    for r in held {
        assert!(r.2 == "whip" && r.3 > 20e-6, "no whip at {r:?}");
    }
    assert_eq!(v["state"], "stable", "{}", v["evidence"]);
    assert!(subsync_m(&v) < 1e-6);
}
