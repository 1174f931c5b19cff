//! What `simulate --json` must say about the validity of its own run: the linear coupling has
//! no wall, so an orbit beyond the clearance is flagged, not reported as a motion; the
//! prehistory fallback count the README promises is there, and counts what the library counts.

mod common;
use common::run_cli;

/// The linear model of the built-in machine is unstable at 9,000 rpm (growth ≈ 0.019/rev,
/// `transient_orc.rs`), so within 600 revolutions the orbit leaves the clearance circle: the
/// report must say so (`valid` false, the eccentricity ratio named), and label it so: the state
/// of the run, of each bearing beyond its clearance and of each such revolution in
/// `--history-csv` is `beyond_clearance`, not a whirl or whip of the nonlinear model (issue 11:
/// "ε = 970, labelled whip"; main labelled it `whirl`, measured ε 58 and 64, sub-synchronous
/// 2.2 mm, and fails here). The nonlinear model over a few revolutions at 8,000 rpm stays valid
/// and reports `prehistory_fallbacks` (0 without prehistory).
#[test]
fn linear_orbit_beyond_the_clearance_is_flagged() {
    let csv = std::env::temp_dir().join(format!("rotor-twin-linear-{}.csv", std::process::id()));
    // reading (A) (Ø55): its linear model is unstable at 9,000 rpm (threshold 8,471); the built-in
    // reading (B) is linear-stable there
    let (ok, out, err) = run_cli(&[
        "simulate",
        "--config",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/config/orc_microturbine_100kw_d55.yaml"
        ),
        "--speed-rpm",
        "9000",
        "--model",
        "linear",
        "--revs",
        "600",
        "--steps-per-rev",
        "32",
        "--history-csv",
        csv.to_str().unwrap(),
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
    // never a whirl or whip on an eccentricity beyond a clearance that has no wall
    assert_eq!(v["state"], "beyond_clearance", "{}", v["evidence"]);
    for b in v["bearings"].as_array().unwrap() {
        let beyond = b["max_eccentricity_ratio"].as_f64().unwrap() > 1.0;
        assert_eq!(b["beyond_clearance"], beyond, "{b}");
        if beyond {
            assert_eq!(b["state"], "beyond_clearance", "{b}");
        }
    }
    history_labels_beyond_the_clearance(&csv, 600);

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

/// The `--history-csv` at `csv` of a run of `revs` revolutions (removed after): every
/// revolution with a journal beyond ε 1 is labelled `beyond_clearance`, the others not, and
/// there is at least one.
fn history_labels_beyond_the_clearance(csv: &std::path::Path, revs: usize) {
    let text = std::fs::read_to_string(csv).unwrap();
    std::fs::remove_file(csv).ok();
    let header = text.lines().next().unwrap().split(',');
    let eps: Vec<usize> = header
        .enumerate()
        .filter(|(_, h)| h.ends_with("_max_eccentricity_ratio"))
        .map(|(i, _)| i)
        .collect();
    assert_eq!(eps.len(), 2, "two bearings' ε columns");
    let (mut beyond, mut rows) = (0, 0);
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let out_of = eps.iter().any(|&i| f[i].parse::<f64>().unwrap() > 1.0);
        rows += 1;
        if out_of {
            beyond += 1;
            assert_eq!(f[3], "beyond_clearance", "{line}");
        } else {
            assert_ne!(f[3], "beyond_clearance", "{line}");
        }
    }
    println!("history: {beyond} of {rows} revolutions beyond the clearance");
    assert!(beyond > 0 && rows == revs, "{beyond} of {rows}");
}

/// `simulate`'s JSON carries the prehistory fallback count (README "Prehistory": substeps whose
/// relaxed iteration, seed eq. 8, did not converge and fell back to Newton) of the run it
/// reports. A run where the relaxation really falls back: the built-in machine at 8,000 rpm,
/// δ = 0.5, 64 steps a revolution, 6 revolutions, kicked by 1 N·s in x and y at mid-span
/// (node 15) at 1 ms: the fast motion after the kick defeats the relaxed coefficients (the
/// README's "fails in the developed whip", here in 6 revolutions instead of 500). Asserted: the
/// count is above zero (measured 38 of 384 steps) and equals (a) the same run through the library
/// (`run_driven`), (b) the twin's per-step flag summed over the same steps taken by hand, and
/// (c) independently of that flag, the steps of one substep that took more than
/// `max_newton_iterations` iterations (measured 38, 38, 38). A JSON that dropped the field or
/// reported 0 fails here (the old test only asked for the key): run with the JSON's count
/// forced to 0 (a temporary change, reverted) it failed, JSON 0 against the library's 38.
#[test]
fn prehistory_fallbacks_in_the_json_count_the_runs_fallbacks() {
    use rotor_twin::dynamics::{Coupling, FilmEvaluation};
    use rotor_twin::dynamics::{StepInput, Twin, TwinConfig};
    use rotor_twin::rotor::{MachineDescription, Rotor};
    use rotor_twin::transient::{apply_kicks, run_driven, Drive, Kick, TransientSpec};
    use rotor_twin::units::rpm_to_rad_s;
    let (speed, revs, steps, delta) = (8000.0, 6, 64, 0.5);
    let impulse = [1.0, 1.0];
    let kick = format!("0.001:15:{}:{}", impulse[0], impulse[1]);
    let (ok, out, err) = run_cli(&[
        "simulate",
        "--speed-rpm",
        &speed.to_string(),
        "--model",
        "prehistory",
        "--delta",
        &delta.to_string(),
        "--kick",
        &kick,
        "--revs",
        &revs.to_string(),
        "--steps-per-rev",
        &steps.to_string(),
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let json = v["prehistory_fallbacks"]
        .as_u64()
        .expect("the count in the JSON");
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let spec = TransientSpec {
        speed_rpm: speed,
        revolutions: revs,
        coupling: Coupling::Prehistory { delta },
        steps_per_rev: steps,
        grid: None,
        film: FilmEvaluation::Direct,
    };
    let drive = Drive {
        speed: None,
        kicks: vec![Kick {
            time_s: 0.001,
            node: 15,
            impulse_n_s: impulse,
        }],
    };
    let run = run_driven(&rotor, &spec, None, &drive).unwrap();
    // counted a third way, from the iteration counts of the same steps taken by hand: a step
    // of one substep whose relaxed iteration fell back took more than max_newton_iterations
    // (the relaxed tries, then Newton from the predictor); one that converged, at most that
    let omega = rpm_to_rad_s(speed);
    let config = TwinConfig {
        film: FilmEvaluation::Direct,
        ..TwinConfig::with_steps_per_rev(spec.coupling, omega, steps)
    };
    let (h, max_it) = (config.time_step_s, config.max_newton_iterations);
    let mut twin = Twin::new(&rotor, config, omega).unwrap();
    let input = StepInput {
        speed_rad_s: omega,
        accel_rad_s2: 0.0,
    };
    let (mut applied, mut by_iterations, mut by_flag, mut substepped) = ([false], 0, 0, 0);
    for _ in 0..run.steps {
        let t = twin.time_s();
        apply_kicks(&mut twin, &drive.kicks, &mut applied, t, h).unwrap();
        let out = twin.step(&input).unwrap();
        by_flag += out.prehistory_fallbacks;
        if out.substeps == 1 {
            by_iterations += usize::from(out.newton_iterations > max_it);
        } else {
            substepped += 1;
        }
    }
    println!(
        "prehistory δ {delta}, kick {kick} at {speed} rpm: JSON {json} fallbacks, library {} of \
         {} steps, by hand {by_flag} (from the iteration counts {by_iterations}, {substepped} \
         steps substepped); state {}",
        run.prehistory_fallbacks, run.steps, v["state"]
    );
    assert!(json > 0, "{out}");
    assert_eq!(json as usize, run.prehistory_fallbacks);
    assert_eq!(json as usize, by_flag);
    if substepped == 0 {
        assert_eq!(json as usize, by_iterations);
    }
}
