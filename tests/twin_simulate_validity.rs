//! What `simulate --json` must say about the validity of its own run: the linear coupling has
//! no wall, so an orbit beyond the clearance is flagged, not reported as a motion; the
//! prehistory fallback count the README promises is there.

mod common;
use common::run_cli;

/// The linear model of the built-in machine is unstable at 9,000 rpm (growth ≈ 0.019/rev,
/// `transient_orc.rs`), so within 600 revolutions the orbit leaves the clearance circle: the
/// report must say so (`valid` false, the eccentricity ratio named). The nonlinear model over a
/// few revolutions at 8,000 rpm stays valid and reports `prehistory_fallbacks` (0 without
/// prehistory).
#[test]
fn linear_orbit_beyond_the_clearance_is_flagged() {
    let (ok, out, err) = run_cli(&[
        "simulate",
        "--speed-rpm",
        "9000",
        "--model",
        "linear",
        "--revs",
        "600",
        "--steps-per-rev",
        "32",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let worst = v["bearings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["max_eccentricity_ratio"].as_f64().unwrap())
        .fold(0.0, f64::max);
    println!(
        "linear 9000 rpm: max eccentricity {worst}, valid {}",
        v["valid"]
    );
    assert!(
        worst > 1.0,
        "the linear orbit did not leave the clearance: {worst}"
    );
    assert_eq!(v["valid"], false, "{out}");
    assert!(v["validity"]
        .as_str()
        .unwrap()
        .contains("beyond the clearance"));
    assert_eq!(v["prehistory_fallbacks"], 0);
    // never a whip on an eccentricity beyond a clearance that has no wall
    assert_ne!(v["state"], "whip", "{}", v["evidence"]);
    assert!(v["bearings"]
        .as_array()
        .unwrap()
        .iter()
        .all(|b| b["state"] != "whip"));

    let (ok, out, err) = run_cli(&[
        "simulate",
        "--speed-rpm",
        "8000",
        "--revs",
        "4",
        "--steps-per-rev",
        "32",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["valid"], true, "{out}");
    assert!(v["prehistory_fallbacks"].is_u64(), "{out}");
}
