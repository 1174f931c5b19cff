//! The engineering views of `rotor-twin replay` from measured data (issue 16): the measured 1X
//! Bode and polar plots per probe axis, the shaft centerline, the full-spectrum cascade, the
//! orbit with keyphasor dots and in the probes' frame. A run-up bag written by an independent
//! writer (PyPI rosbags, `tests/interop/write_runup_signal_bag.py`) with a known 1X amplitude
//! and phase lag against speed reads back block by block; every SVG reads back with its title,
//! axis labels, legend beside the data and, where geometry needs it, 1:1. Without a keyphasor
//! the Bode plot has the amplitudes and says why the phase is missing.

mod common;
mod svg_check;

use common::run_cli;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-views-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

/// The built-in machine with raw probes `<station>_x` / `_y` at 45° and 135°, in µm, AC.
fn raw_probe_machine(dir: &Path) -> PathBuf {
    let mut yaml = format!(
        "{}\nproximity_probes:\n",
        rotor_twin::rotor::DEFAULT_MACHINE_YAML
    );
    for station in ["probe_pulley_end", "probe_outboard"] {
        for (suffix, angle) in [("x", 45.0), ("y", 135.0)] {
            yaml += &format!(
                "  - {{name: {station}_{suffix}, station: {station}, angle_deg: {angle}, unit: um, coupling: ac}}\n"
            );
        }
    }
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("raw.yaml");
    std::fs::write(&path, yaml).unwrap();
    path
}

/// The lag of `lag_deg` minus `truth`, wrapped into (−180, 180].
fn lag_gap(lag_deg: f64, truth: f64) -> f64 {
    (lag_deg - truth + 180.0).rem_euclid(360.0) - 180.0
}

/// The script's truth at speed `n` (rpm) for a run-up from `n0` to `n1`: amplitude (µm) and the
/// lag of the forward circle (deg); the probe at α reads the lag + α.
fn truth(n: f64, n0: f64, n1: f64) -> (f64, f64) {
    let s = (n - n0) / (n1 - n0);
    (2.0 + 2.0 * s, 30.0 + 90.0 * s)
}

/// The script's run-up bag (`seconds`, `n0` → `n1` rpm) replayed on the raw-probe machine into
/// `dir`/out: the JSON report and the output directory.
fn replay_run_up(dir: &Path, seconds: f64, n0: f64, n1: f64) -> (Value, PathBuf) {
    let bag = dir.join("bag");
    let (secs, n0s, n1s) = (seconds.to_string(), n0.to_string(), n1.to_string());
    common::interop_script(
        "write_runup_signal_bag.py",
        [bag.as_os_str(), secs.as_ref(), n0s.as_ref(), n1s.as_ref()],
    );
    let config = raw_probe_machine(dir);
    let out = dir.join("out");
    let mut args: Vec<String> = [
        "replay",
        bag.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--no-bag",
        "--json",
        "--remap",
        "/plant/keyphasor:=/rotor_twin/keyphasor",
    ]
    .map(String::from)
    .to_vec();
    for station in ["probe_pulley_end", "probe_outboard"] {
        for suffix in ["x", "y"] {
            args.push("--probe-signal".into());
            args.push(format!("{station}_{suffix}=/plant/{station}_{suffix}"));
        }
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (ok, stdout, stderr) = run_cli(&args);
    assert!(ok, "{stdout}\n{stderr}");
    (serde_json::from_str(&stdout).unwrap(), out)
}

/// Every block's measured 1X on both probe axes of both stations against the script's truth at
/// the block's mean speed: (relative amplitude error, lag read − truth in degrees, speed rpm).
fn block_gaps(report: &Value, n0: f64, n1: f64) -> Vec<(f64, f64, f64)> {
    let mut gaps = Vec::new();
    let stations = report["stations"].as_array().unwrap();
    assert_eq!(stations.len(), 2);
    for st in stations {
        for b in st["blocks"].as_array().unwrap() {
            let n = b["speed_rpm"].as_f64().unwrap();
            let (a, beta) = truth(n, n0, n1);
            let axes = b["measured"]["one_x_probe_axes"]
                .as_array()
                .unwrap_or_else(|| panic!("no phase in block at {n} rpm: {b}"));
            for (j, alpha) in [45.0, 135.0].iter().enumerate() {
                let amp = axes[j]["amplitude_m"].as_f64().unwrap() * 1e6;
                let lag = axes[j]["phase_lag_deg"].as_f64().unwrap();
                gaps.push((amp / a - 1.0, lag_gap(lag, beta + alpha), n));
                // the amplitude needs no keyphasor: given beside the vector
                let plain = b["measured"]["one_x_probe_amplitudes_m"][j]
                    .as_f64()
                    .unwrap();
                assert!((plain * 1e6 - amp).abs() < 1e-9);
            }
        }
    }
    gaps
}

/// The script's run-up (`seconds`, `n0` → `n1` rpm) replayed in a scratch directory `name`,
/// every block read back ([`assert_blocks_read_back`]): the directory, the report, the output.
fn run_up_read_back(
    name: &str,
    seconds: f64,
    (n0, n1): (f64, f64),
    readings: usize,
    amp_tol: f64,
) -> (PathBuf, Value, PathBuf) {
    let dir = scratch(name);
    let (report, out) = replay_run_up(&dir, seconds, n0, n1);
    assert_blocks_read_back(&report, (n0, n1), readings, amp_tol);
    (dir, report, out)
}

/// Every block of `report` (a run-up `n0` → `n1` rpm) within `amp_tol` (relative) of the
/// script's amplitude and 1° of its lag, at least `readings` of them; the worst and the mean
/// lag error printed.
fn assert_blocks_read_back(report: &Value, (n0, n1): (f64, f64), readings: usize, amp_tol: f64) {
    let gaps = block_gaps(report, n0, n1);
    assert!(gaps.len() >= readings, "{} block readings", gaps.len());
    let worst_amp = gaps.iter().map(|g| g.0.abs()).fold(0.0, f64::max);
    let worst_lag = gaps.iter().map(|g| g.1.abs()).fold(0.0, f64::max);
    let mean_lag = gaps.iter().map(|g| g.1).sum::<f64>() / gaps.len() as f64;
    let first = gaps.iter().min_by(|a, b| a.2.total_cmp(&b.2)).unwrap();
    eprintln!(
        "run-up {n0}–{n1} rpm: {} block readings, worst amplitude {:.2} %, worst lag {:.2}°, mean lag {:+.2}°, \
         lowest-speed block {:.0} rpm lag {:+.2}°",
        gaps.len(),
        100.0 * worst_amp,
        worst_lag,
        mean_lag,
        first.2,
        first.1
    );
    assert!(worst_amp < amp_tol, "amplitude off by {worst_amp}");
    assert!(worst_lag < 1.0, "lag off by {worst_lag}°");
}

/// A run-up from 6,000 to 8,000 rpm in 2 s (1,000 rpm/s), keyphasor and four raw probes (µm,
/// AC) in standard types, no speed topic; the 1X is a forward circle of 2 → 4 µm lagging by
/// 30° → 120° (linear in speed), with a 0.5 µm forward 0.5X circle beside it. Each block of 8
/// revolutions reads the script's amplitude at its mean speed within 1 % and the lag within 1°
/// on both probe axes of both stations (the lag read against the plant's keyphasor events, as
/// the node does; measured 0.38 % and 0.43°, mean lag −0.04°). The report has the blocks' full
/// spectra, the static centerline locus inside the clearance, and says why an AC probe gives no
/// measured centerline; each plot reads back.
#[test]
fn a_run_up_with_a_known_1x_reads_back_its_bode_and_every_view() {
    // 25 blocks or more at each station, 2 axes each
    let (dir, report, out) = run_up_read_back("runup", 2.0, (6000.0, 8000.0), 4 * 25, 0.01);
    for st in report["stations"].as_array().unwrap() {
        let blocks = st["blocks"].as_array().unwrap();
        // the report's view numbers
        let spectra = st["block_spectra"].as_array().unwrap();
        assert_eq!(spectra.len(), blocks.len());
        assert_eq!(
            spectra[0]["measured_full_m"].as_array().unwrap().len(),
            2,
            "forward and reverse"
        );
        let locus = st["centerline_static_predicted"].as_array().unwrap();
        assert_eq!(locus.len(), 12);
        for p in locus {
            let xy = &p["position_m"];
            let r = xy[0].as_f64().unwrap().hypot(xy[1].as_f64().unwrap());
            assert!(r > 1e-6 && r < 40e-6, "static position {r} m");
        }
        assert!(st["mean_position_null_reason"]
            .as_str()
            .unwrap()
            .starts_with("AC-coupled"));
        // the 1X ellipse of a forward circle: forward, semi-minor = semi-major within 2 %
        for b in blocks {
            let e = &b["measured"]["one_x_ellipse"];
            assert_eq!(e["precession"], "forward", "{e}");
            let (major, minor) = (
                e["semi_major_m"].as_f64().unwrap(),
                e["semi_minor_m"].as_f64().unwrap(),
            );
            assert!(minor / major > 0.98, "{e}");
        }
    }
    check_views(&out, "probe_outboard", true);
    std::fs::remove_dir_all(&dir).ok();
}

/// A fast run-up, 3,000 → 5,000 rpm in 0.8 s (2,500 rpm/s: a·T² = 5.3° at 3,189 rpm): the
/// measured lag of every block within 1° of the script's truth on both axes of both stations,
/// because the samples are read against the plant's own keyphasor events (the parabola through
/// three, `signals::keyphasor_one_x`), not the twin's keyphasor-locked angle, which trails the
/// accelerating shaft (read against it, as before session 10, the lag was −4.9° off at
/// 3,189 rpm, mean −3.5°: this test failed on main). Measured: worst 0.34°, mean −0.04°. The
/// amplitude within 1.5 % (measured 0.96 %: it grows 10 % within a block here; the lag was also
/// read at the twin's block speed, which trailed the plant's by about one revolution's gain of
/// speed, 2 % of amplitude and 2° of lag here, before the block's speed became the plant's).
#[test]
fn a_fast_run_up_reads_its_lag_against_the_plants_keyphasor() {
    // 53 revolutions: 6 blocks of 8 at each station, 2 axes each
    let (dir, ..) = run_up_read_back("fast-runup", 0.8, (3000.0, 5000.0), 4 * 6, 0.015);
    std::fs::remove_dir_all(&dir).ok();
}

/// Reads back the views of `station` in `out`: titles, axis labels, legends beside the data,
/// 1:1 where geometry needs it, keyphasor dots (with a keyphasor, `locked`) or the reason.
fn check_views(out: &Path, station: &str, locked: bool) {
    let svg = |kind: &str| svg_check::read(&out.join(format!("{kind}_{station}.svg")));
    let bode = svg("bode");
    bode.assert_texts(&[
        &format!("{station}: 1X Bode plot, measured and predicted (blocks of 8 revolutions)"),
        "speed (rpm)",
        "1X amplitude along the probe (µm, 0-pk)",
        "1X phase lag (deg, API 670)",
        "legend",
        "measured, probe axis 1 (45°)",
        "predicted, probe axis 2 (135°)",
    ]);
    bode.assert_legend_right_of_data();
    // measured markers (3 px): amplitude on both axes, and the phase with a keyphasor
    let measured_dots = bode.circles.iter().filter(|c| c.2 == 3.0).count();
    assert_eq!(bode.text("no 1X phase lag:").is_none(), locked);
    assert!(measured_dots >= if locked { 4 * 25 } else { 2 * 25 });

    let polar = svg("polar");
    polar.assert_texts(&[
        "Re X, in phase with the keyphasor (µm)",
        "Im X (µm); lag clockwise from +Re",
        "legend",
    ]);
    polar.assert_legend_right_of_data();
    let (px, py) = polar.px_per_unit();
    assert!((px / py - 1.0).abs() < 0.01, "polar {px} vs {py} px/µm");

    let centre = svg("centerline");
    centre.assert_texts(&[
        "x (µm)",
        "y (µm)",
        "static equilibrium, predicted",
        "legend",
    ]);
    centre.assert_legend_right_of_data();
    let (px, py) = centre.px_per_unit();
    assert!(
        (px / py - 1.0).abs() < 0.01,
        "centerline {px} vs {py} px/µm"
    );
    // the static locus (3 px line) is drawn after, so over, every block's mean (4 px rings, half
    // transparent): it used to be hidden under them
    let raw = std::fs::read_to_string(out.join(format!("centerline_{station}.svg"))).unwrap();
    let locus_at = raw.find("stroke-width=\"3\"").expect("the static locus");
    let last_ring = raw
        .rfind("r=\"4\" opacity=\"0.5\"")
        .expect("the twin's means");
    assert!(last_ring < locus_at, "the locus is under the markers");

    let cascade = svg("full_spectrum");
    cascade.assert_texts(&[
        "measured",
        "predicted",
        "+1X",
        "−1X",
        "order: reverse < 0 < forward (frequency / running frequency)",
        "speed of each trace (rpm), in bag order",
    ]);

    let frame = svg("orbit_probe_frame");
    frame.assert_texts(&[
        "machine frame",
        "probe frame",
        "x − mean (µm)",
        "probe 1 at 45°, about its mean (µm)",
        "probe 2 at 135°, about its mean (µm)",
        "legend",
    ]);
    frame.assert_legend_right_of_data();

    let orbit = svg("orbit");
    orbit.assert_texts(&["x (µm)", "y (µm)", "legend"]);
    orbit.assert_legend_right_of_data();
    // one dot a revolution for each orbit over the last 4 revolutions, and the legend's
    let dots = orbit.circles.iter().filter(|c| c.2 == 4.0).count();
    if locked {
        assert!(orbit.text("keyphasor (once a revolution)").is_some());
        assert!((9..=11).contains(&dots), "{dots} keyphasor dots");
    } else {
        assert!(orbit.text("no keyphasor dots:").is_some());
        assert_eq!(dots, 0);
    }
}

/// The shipped sample bag with its keyphasor remapped away (`--remap /rotor_twin/keyphasor:=/unused`:
/// a rig without one; the bag has one since session 15): the Bode plot has the measured and predicted
/// amplitudes and says why the phase is missing; the orbits have no keyphasor dots and say why;
/// the displacement pairs keep the mean, so the centerline is measured.
#[test]
fn without_a_keyphasor_the_views_say_why_the_phase_is_missing() {
    let dir = scratch("no-keyphasor");
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("bags/orc_runup_synthetic");
    let (ok, stdout, stderr) = run_cli(&[
        "replay",
        sample.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--no-bag",
        "--json",
        "--duration",
        "3",
        "--remap",
        "/rotor_twin/keyphasor:=/unused",
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    let report: Value = serde_json::from_str(&stdout).unwrap();
    for st in report["stations"].as_array().unwrap() {
        assert!(st["mean_position_null_reason"].is_null());
        for b in st["blocks"].as_array().unwrap() {
            assert!(b["measured"]["one_x_probe_axes"].is_null());
            assert!(
                b["measured"]["one_x_probe_amplitudes_m"][0]
                    .as_f64()
                    .unwrap()
                    > 0.0
            );
        }
    }
    check_views(&dir, "probe_outboard", false);
    let bode = svg_check::read(&dir.join("bode_probe_outboard.svg"));
    assert!(bode
        .texts
        .iter()
        .any(|t| t.text.starts_with("no keyphasor")));
    let centre = svg_check::read(&dir.join("centerline_probe_outboard.svg"));
    assert!(centre.text("measured mean, per block").is_some());
    std::fs::remove_dir_all(&dir).ok();
}
