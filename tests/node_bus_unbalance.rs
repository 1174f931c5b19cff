//! Issue 12's unbalance calibration end to end through DDS (session 14): the live node fitted
//! from a plant's own stamped signals, published BEST EFFORT by an independent Cyclone DDS peer
//! (tests/interop/stamped_plant_peer.py) in a private network namespace (`unshare -n`).
//!
//! The plant is the one of tests/live_calibration.rs (`common::calibration::plant_rotor`):
//! unbalance 280 g·mm at stage 7 (node 21) at 120° of its shaft angle instead of the twin's
//! 140 g·mm at stage 4, oil × 1.10, films 72 × 12 instead of 60 × 10, the nonlinear transient
//! with the direct film at 64 steps a revolution of 8,000 rpm. It is solved here first, stepped
//! 5,000 → 6,500 → 8,000 rpm (8 revolutions to settle, then 16.5 measured at each), and what
//! its instruments deliver is written to a CSV that the peer streams: the keyphasor
//! (rotor_twin_msgs/Keyphasor, stamped with the instant the mark passed, the mark 123° round
//! the shaft from its angle 0), raw probe readings (rotor_twin_msgs/ProbeSignal, stamped, V at
//! 7.87 V/mm, DC-coupled about a 1 mm gap, at 45° and 135°, API 670's pair either side of
//! vertical, at both probe stations, 5 µm of slow-roll runout and 0.3 µm of noise) every 4th
//! step of the plant (25.6, 19.7 and 16 samples a revolution), and the speed at 100 Hz. The
//! peer sets the pace by `/clock` (rosgraph_msgs/Clock; the node runs with `use_sim_time`),
//! streaming the plant's 0.7 s at a quarter of real time (2.8 s; at real time the Python peer
//! falls behind, 1.0–2.5 s for the 0.7 s with 16 samples a revolution, and the node follows its
//! clock), then runs the clock on at real time until two estimates asked after the last sample
//! are out (every `calibration_period_s` = 1 s of the node's clock).

mod common;

use common::calibration::plant_rotor;
use common::node::Scenario;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rotor_twin::dynamics::{Coupling, StepInput, Twin, TwinConfig};
use rotor_twin::plant::plant_runout;
use rotor_twin::rotor::{MachineDescription, Rotor, DEFAULT_MACHINE_YAML};
use rotor_twin::signals::probes::runout_at;
use serde_json::Value;
use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;

/// The plant's time zero on the shared clock (ns): 1,000 s, as tests/interop/peer.py's clock.
const T0_NS: i64 = 1_000_000_000_000;
/// The keyphasor mark's angle round the plant's shaft from its angle 0 (deg).
const MARK_DEG: f64 = 123.0;
/// Slow-roll runout of each probe (m), its high spot 30° from the mark (`plant::plant_runout`).
const RUNOUT_M: f64 = 5e-6;
/// Plant steps between probe samples: 4, i.e. 25.6, 19.7 and 16 samples a revolution at 5,000,
/// 6,500 and 8,000 rpm (8: half as many, README).
const SAMPLE_EVERY_STEPS: u64 = 4;
/// Sensitivity (V/m) and gap with the shaft centred (m) of the raw probes.
const VOLTS_PER_M: f64 = 7870.0;
const GAP_M: f64 = 1e-3;

/// The twin's machine file: the built-in machine with an empty second unbalance plane at stage
/// 7 (node 21) and raw probes `<station>_x` / `_y` at 45° and 135° in V, DC-coupled, each with
/// the plant's runout vector (what `common::calibration::twin_rotor_with_raw_probes` builds).
fn machine_yaml() -> String {
    let plane = "  - {node: 15, magnitude_g_mm: 140.0, phase_deg: 0.0}\n";
    assert!(DEFAULT_MACHINE_YAML.contains(plane));
    let mut yaml = DEFAULT_MACHINE_YAML.replace(
        plane,
        &format!("{plane}  - {{node: 21, magnitude_g_mm: 0.0, phase_deg: 0.0}}\n"),
    );
    yaml += "\nproximity_probes:\n";
    for station in ["probe_pulley_end", "probe_outboard"] {
        for (suffix, angle) in [("x", 45.0f64), ("y", 135.0)] {
            let r = plant_runout(RUNOUT_M, angle.to_radians());
            writeln!(
                yaml,
                "  - {{name: {station}_{suffix}, station: {station}, angle_deg: {angle}, unit: V, sensitivity_v_per_m: {VOLTS_PER_M}, coupling: dc, reference_gap: 7.87, runout: {{amplitude_m: {}, phase_lag_deg: {}}}}}",
                r.amplitude_m, r.phase_lag_deg
            )
            .unwrap();
        }
    }
    yaml
}

/// The plant's instruments as CSV rows `send_ns,kind,name,stamp_ns,value` in the order a rig
/// sends them (kind: speed in rad/s, keyphasor, probe in V).
struct Instruments {
    csv: String,
    noise: Normal<f64>,
    rng: rand_chacha::ChaCha8Rng,
    /// the mark's angle (rad) and the mark passes counted
    mark_rad: f64,
    revolutions: i64,
    next_speed_ns: i64,
}

impl Instruments {
    fn row(&mut self, send_ns: i64, kind: &str, name: &str, stamp_ns: i64, value: f64) {
        writeln!(self.csv, "{send_ns},{kind},{name},{stamp_ns},{value:.9e}").unwrap();
    }

    /// The speed (every 10 ms, at once after a step) and a keyphasor event if the mark passed
    /// within the step just taken (its instant from the speed and the angle past it).
    fn after_step(&mut self, plant: &Twin, stepped: bool) {
        let o = plant.output();
        let t = T0_NS + (o.time_s * 1e9).round() as i64;
        if stepped || t >= self.next_speed_ns {
            self.row(t, "speed", "", t, o.speed_rad_s);
            self.next_speed_ns = t + 10_000_000;
        }
        let rev = ((o.angle_rad - self.mark_rad) / TAU).floor() as i64;
        if rev > self.revolutions {
            let past = (o.angle_rad - self.mark_rad - rev as f64 * TAU) / o.speed_rad_s;
            self.revolutions = rev;
            self.row(t, "keyphasor", "", t - (past * 1e9).round() as i64, 0.0);
        }
    }

    /// Each raw probe's reading now: the journal's displacement along its axis, the runout at
    /// the shaft angle from the mark and the noise, as volts of gap.
    fn measure(&mut self, plant: &Twin, twin: &Rotor) {
        let o = plant.output();
        let t = T0_NS + (o.time_s * 1e9).round() as i64;
        let psi = o.angle_rad - self.mark_rad;
        for (station, p) in o.probes.iter().enumerate() {
            let s = &twin.probes[station];
            for (j, suffix) in ["x", "y"].iter().enumerate() {
                let a = s.angles_rad[j];
                let d = p.displacement_m[0] * a.cos()
                    + p.displacement_m[1] * a.sin()
                    + runout_at(&plant_runout(RUNOUT_M, a), psi)
                    + self.noise.sample(&mut self.rng);
                let name = format!("{}_{suffix}", s.name);
                self.row(t, "probe", &name, t, VOLTS_PER_M * (GAP_M - d));
            }
        }
    }
}

/// The plant of `twin` solved through the three speeds; its instruments' CSV.
fn plant_csv(twin: &Rotor) -> String {
    let plant = plant_rotor(twin);
    let w8 = 8000.0 * PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w8, 64);
    let mut plant = Twin::new(&plant, config, 5000.0 * PI / 30.0).unwrap();
    let mark_rad = MARK_DEG.to_radians();
    let mut io = Instruments {
        csv: String::new(),
        noise: Normal::new(0.0, 0.3e-6).unwrap(),
        rng: rand_chacha::ChaCha8Rng::seed_from_u64(12),
        mark_rad,
        revolutions: (-mark_rad / TAU).floor() as i64,
        next_speed_ns: 0,
    };
    for rpm in [5000.0f64, 6500.0, 8000.0] {
        let w = rpm * PI / 30.0;
        for (revs, measure) in [(8.0, false), (16.5, true)] {
            let end = plant.time_s() + revs * TAU / w;
            let mut k = 0u64;
            while plant.time_s() < end {
                let input = StepInput {
                    speed_rad_s: w,
                    accel_rad_s2: 0.0,
                };
                plant.step(&input).unwrap();
                io.after_step(&plant, k == 0 && !measure);
                k += 1;
                if measure && k.is_multiple_of(SAMPLE_EVERY_STEPS) {
                    io.measure(&plant, twin);
                }
            }
        }
    }
    io.csv
}

/// The same rows fed to a driver of `twin` in the node's order (no bus): the speed, keyphasor
/// and probe inputs at their send times, the compared samples into the node's 1X blocks and live
/// calibration (ros/model.rs `after_feed`); the estimate on all of them. Returns (stage 7 g·mm,
/// its phase in degrees from the mark, viscosity scale, vectors).
fn offline_estimate(twin: &Rotor, csv: &str) -> (f64, f64, f64, usize) {
    use rotor_twin::driver::calibration::estimate;
    use rotor_twin::driver::{
        Driver, DriverSettings, Fed, Input, LiveCalibration, ModelKind, OneXBlocks, ProbeRef,
    };
    use rotor_twin::dynamics::FilmEvaluation;
    let settings = DriverSettings::new(
        ModelKind::Linear,
        FilmEvaluation::Direct,
        twin.rated_speed_rad_s,
    );
    let mut d = Driver::new(twin.clone(), settings);
    let mut blocks = OneXBlocks::new(d.probe_axes());
    let mut calibration = LiveCalibration::default();
    for line in csv.lines() {
        let f: Vec<&str> = line.split(',').collect();
        let (t, stamp_ns, value) = (
            f[0].parse::<i64>().unwrap(),
            f[3].parse::<i64>().unwrap(),
            f[4].parse::<f64>().unwrap(),
        );
        let input = match f[1] {
            "speed" => Input::Speed {
                speed_rad_s: value,
                accel_rad_s2: 0.0,
                stamp_ns,
            },
            "keyphasor" => Input::Keyphasor { stamp_ns },
            _ => Input::ProbeSignal {
                probe: ProbeRef::Name(f[2].to_string()),
                value,
                stamp_ns,
            },
        };
        match d.feed(t, input, &mut |_| {}) {
            Fed::Compared(c) => blocks.add(&c, d.keyphasor_events()),
            Fed::Refused(why) => {
                println!(
                    "offline: refused at {:.4} s: {why}",
                    (t - T0_NS) as f64 * 1e-9
                )
            }
            _ => {}
        }
        let newest = d.newest_sample_ns().unwrap_or(i64::MIN);
        while let Some(b) = blocks.take_ready(d.keyphasor_events(), newest) {
            calibration.add(&b, !d.station_is_ac(b.station));
        }
    }
    let measured = calibration.measurements();
    let vectors = measured.0.len();
    let e = estimate(twin, &measured, d.calibration_refinement());
    let u = e.unbalance.expect("an unbalance offline");
    let v = e.viscosity.expect("a viscosity offline");
    let p = u.planes[1];
    (p.magnitude_g_mm, p.phase_deg, v.scale, vectors)
}

fn lag_gap(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

/// Runs tests/interop/unbalance_scenario.sh on the CSV; returns the peer's JSON, the node's last
/// input diagnostics as recorded and its log.
fn through_the_bus(csv: &str, yaml: &str) -> (Value, Value, String) {
    let run = Scenario::new("bus-unbalance");
    std::fs::write(run.out.join("plant.csv"), csv).unwrap();
    std::fs::write(run.out.join("machine.yaml"), yaml).unwrap();
    let py = common::python();
    run.run(
        "unbalance_scenario.sh",
        [
            py.into_os_string(),
            run.out.clone().into_os_string(),
            run.out.join("machine.yaml").into_os_string(),
            run.out.join("plant.csv").into_os_string(),
        ],
    );
    let peer = run.json("peer.json", &["node.err", "peer.err"]);
    let diagnostics = run.json("recorded.json", &["node.err"])["diagnostics"].clone();
    let log = run.file("node.err");
    run.remove();
    (peer, diagnostics, log)
}

/// The node's last estimate, asked after every sample was in, against the plant: 280 g·mm at
/// 243° from the mark (120° + 123°) at stage 7 within the 10 % and 10°, stage 4 under
/// 10 % of it; the viscosity × 1.10 within 3 % (DC-coupled probes give the mean positions).
/// Measured: 276.1 g·mm at 242.2° (−1.4 %, −0.8°), 2.0 g·mm at stage 4, condition number 1.92,
/// 1X residual 0.130 µm (3.0 %), viscosity × 1.1037 ± 0.0058, from 12 1X vectors (3 speeds × 2
/// stations × 2 machine axes) and 6 mean positions; 17 s. Then the transport alone: the same
/// rows fed to a driver in order (no bus, no clock) give the same estimate, the vector count
/// equal and the rest within 0.5 % and 0.5° (measured: the unbalance equal to the digits
/// printed, the viscosity within 0.03 %, varying by 1e-4 from run to run). At each
/// station one 1X block of six is null in both (the one closed across the 6,500 → 8,000 rpm
/// step, whose keyphasor interval is refused); the node refuses nothing else.
#[test]
fn the_node_recovers_the_plants_unbalance_from_stamped_best_effort_probe_samples() {
    let yaml = machine_yaml();
    let twin = Rotor::from_description(&MachineDescription::from_yaml(&yaml, "m.yaml").unwrap());
    assert_eq!(twin.unbalance.len(), 2);
    assert_eq!(twin.proximity_probes.len(), 4);
    let started = std::time::Instant::now();
    let csv = plant_csv(&twin);
    println!(
        "plant solved in {:.1} s: {} rows",
        started.elapsed().as_secs_f64(),
        csv.lines().count()
    );
    let started = std::time::Instant::now();
    let (peer, diagnostics, log) = through_the_bus(&csv, &yaml);
    println!("the node's input diagnostics: {diagnostics}");
    // the keyphasor interval across each of the two speed steps contradicts the speed in force
    // and is refused (tests/live_calibration.rs); nothing else is
    let refused: u64 = diagnostics["refused_inputs"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!(refused <= 2, "{diagnostics}\n{log}");
    println!(
        "through the bus in {:.1} s (the plant's data streamed in {:.1} s, then {:.1} s of clock until two estimates); sent {}",
        started.elapsed().as_secs_f64(),
        peer["streamed_wall_s"].as_f64().unwrap_or(f64::NAN),
        peer["tail_wall_s"].as_f64().unwrap_or(f64::NAN),
        peer["sent"]
    );
    for b in peer["one_x"].as_array().unwrap() {
        println!(
            "1X block at {:.4} s: {} at {:.0} rpm, {} revolutions, {} samples {}",
            (b["t_ns"].as_i64().unwrap() - T0_NS) as f64 * 1e-9,
            b["station"],
            b["speed"].as_f64().unwrap() * 30.0 / PI,
            b["revolutions"],
            b["samples"],
            b["reason"]
        );
    }
    let all = peer["estimates"].as_array().unwrap();
    let e = all
        .last()
        .unwrap_or_else(|| panic!("no estimate: {peer}\n{log}"));
    println!("{} estimates, the last: {e}", all.len());
    assert!(
        peer["after_end"].as_u64().unwrap() >= 2,
        "no estimate asked after the last sample: {peer}\n{log}"
    );
    assert_eq!(e["unbalance_valid"], true, "{e}");
    let f = |k: &str, i: usize| e[k][i].as_f64().unwrap();
    let (m7, phi7) = (
        f("unbalance_magnitudes", 1) * 1e6,
        f("unbalance_phases", 1).to_degrees(),
    );
    let m4 = f("unbalance_magnitudes", 0) * 1e6;
    let s = e["viscosity_scale"].as_f64().unwrap();
    println!(
        "unbalance {m7:.1} g·mm at {:.1}° at stage 7 (plant 280 at 243: {:+.1} %, {:+.1}°), {m4:.1} g·mm at stage 4; condition {:.3}, 1X residual {:.3} µm ({:.1} %); viscosity × {s:.4} ± {:.4}; {} vectors, {} positions",
        phi7.rem_euclid(360.0),
        100.0 * (m7 / 280.0 - 1.0),
        lag_gap(phi7, 243.0),
        e["condition_number"].as_f64().unwrap(),
        e["unbalance_residual"].as_f64().unwrap() * 1e6,
        e["unbalance_relative_residual"].as_f64().unwrap() * 100.0,
        e["viscosity_scale_std"].as_f64().unwrap(),
        e["vectors"],
        e["positions"]
    );
    assert!((m7 / 280.0 - 1.0).abs() < 0.10, "{e}");
    assert!(lag_gap(phi7, 243.0).abs() < 10.0, "{e}");
    assert!(m4 < 28.0, "{e}");
    assert_eq!(e["viscosity_valid"], true, "{e}");
    assert!((s / 1.10 - 1.0).abs() < 0.03, "{e}");
    // the bus lost or moved nothing the fit sees: the same rows through the driver alone (no
    // bus, no clock) give the same estimate, within 0.5 % and 0.5° (a twentieth of the issue's
    // tolerance; measured 0.01 % and 0.00°, the viscosity 0.03 %)
    let (m_off, phi_off, s_off, n_off) = offline_estimate(&twin, &csv);
    println!(
        "the same rows through the driver alone: {m_off:.2} g·mm at {phi_off:.2}°, viscosity × {s_off:.5}, {n_off} vectors; the bus's {m7:.2} g·mm at {:.2}°, × {s:.5}",
        phi7.rem_euclid(360.0)
    );
    assert_eq!(e["vectors"].as_u64().unwrap(), n_off as u64, "{e}");
    assert!((m7 / m_off - 1.0).abs() < 0.005, "{e}");
    assert!(lag_gap(phi7, phi_off).abs() < 0.5, "{e}");
    assert!((s / s_off - 1.0).abs() < 0.005, "{e}");
}
