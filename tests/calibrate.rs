//! Calibration from measurements (issue 12) against a synthetic plant that differs from the
//! twin: its unbalance is doubled (280 instead of 140 g·mm) and sits in another plane (stage 7,
//! node 21, instead of stage 4, node 15) at another phase (120° instead of 0°), its oil is 10 %
//! more viscous, and its films are solved on a finer grid (72 × 12 instead of 60 × 10). The
//! plant runs the nonlinear transient (direct film) at three speeds below the onset; its probe
//! displacements (static position included, as DC-coupled probes see it) get 0.3 µm of noise.
//! The twin first fits the viscosity to the mean positions, then the unbalance to the 1X
//! vectors with its own influence coefficients at the fitted viscosity. Targets (the issue's):
//! viscosity within 3 %, unbalance within 10 % and 10°.

mod common;

use common::calibration::{builtin_with_raw_probes, plant_rotor, twin_rotor, twin_rotor_d55};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rotor_twin::calibrate::{
    estimate_unbalance, estimate_viscosity, fit_windows, AngleSample, WindowFit,
};
use rotor_twin::dynamics::{Coupling, StepInput, Twin, TwinConfig};
use rotor_twin::rotor::{MachineDescription, Rotor};

/// The plant at `rpm` for 8 revolutions to settle, then 16 measured: one window fit per station.
fn measure(plant: &Rotor, rpm: f64, noise: &mut impl FnMut() -> f64) -> Vec<WindowFit> {
    let w = rpm * std::f64::consts::PI / 30.0;
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, 64);
    let mut twin = Twin::new(plant, config, w).unwrap();
    let input = StepInput {
        speed_rad_s: w,
        accel_rad_s2: 0.0,
    };
    let mut samples = vec![Vec::new(); plant.probes.len()];
    for k in 0..64 * 24 {
        twin.step(&input).unwrap();
        if k >= 64 * 8 && k % 2 == 0 {
            let out = twin.output();
            for (s, p) in samples.iter_mut().zip(&out.probes) {
                s.push(AngleSample {
                    angle_rad: out.angle_rad,
                    speed_rad_s: out.speed_rad_s,
                    displacement_m: [p.displacement_m[0] + noise(), p.displacement_m[1] + noise()],
                });
            }
        }
    }
    samples
        .iter()
        .map(|s| fit_windows(s, 15.9).remove(0))
        .collect()
}

/// Issue 12 (referee's gap 3): the reported standard uncertainty must cover the true viscosity
/// scale, model error included: |s − s_true| ≤ 2σ (k = 2, GUM's expanded uncertainty, about
/// 95 %). σ is the fit's own and the model floor (`calibrate::VISCOSITY_MODEL_FLOOR`, 0.5 %) in
/// quadrature; the fit's own σ alone (the ± reported before) is printed beside it: on the sample
/// bag it read × 1.0514 ± 0.0002 for 1.05, 7σ off.
fn assert_covers(what: &str, v: &rotor_twin::calibrate::ViscosityEstimate, truth: f64) {
    let err = v.scale - truth;
    println!(
        "{what}: × {:.4} ± {:.4} (fit alone ± {:.4}) for × {truth}: error {:+.4} = {:+.2} σ ({:+.1} fit σ)",
        v.scale,
        v.scale_std,
        v.fit_std,
        err,
        err / v.scale_std,
        err / v.fit_std
    );
    assert!(err.abs() <= 2.0 * v.scale_std, "{what}: {v:?}");
}

/// On reading (A) (config/orc_microturbine_100kw_d55.yaml), where the targets were set. On the
/// default (B) the same plant and speeds (5,000 / 6,500 / 8,000 rpm, also 6,000 / 7,000 / 8,000,
/// also 40 revolutions to settle) read × 1.175 ± 0.040 for × 1.10 (7 % off, covered at 1.9σ;
/// residual 0.8 µm against 0.3 µm of noise): a bias of the 6-point static fit on the stiffer
/// rotor, open (README Next steps 2); (B)'s sample bag, 78 windows, reads × 1.0518 for × 1.05.
#[test]
fn viscosity_then_unbalance_are_recovered_from_a_plant_that_differs() {
    let mut twin = twin_rotor_d55();
    let plant = plant_rotor(&twin);
    let normal = Normal::new(0.0, 0.3e-6).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
    let mut noise = || normal.sample(&mut rng);
    let mut means = Vec::new();
    let mut vectors = Vec::new();
    // away from the first critical (reading (B), the default: the bearings' 1X peaks at
    // 4,575–4,598 rpm, `response`), where 8 revolutions settle the 1X and the orbit's bias on
    // the mean position is small; (A)'s 3,665 rpm critical allowed 5,000
    for rpm in [6000.0, 7000.0, 8000.0] {
        for (station, fit) in measure(&plant, rpm, &mut noise).iter().enumerate() {
            means.push(fit.mean_position(station));
            vectors.extend(fit.one_x(station));
        }
    }
    let v = estimate_viscosity(&twin, &means).unwrap();
    eprintln!("viscosity: {v:?}");
    assert!(
        (v.scale / 1.10 - 1.0).abs() < 0.03,
        "scale {} (plant 1.10)",
        v.scale
    );
    assert!(v.scale_std > 0.0 && v.scale_std < 0.03, "σ {}", v.scale_std);
    // covered at 1.3σ, by the fit's own σ: 6 mean positions whose residual carries the orbit
    // bias (the replay test below, 21 positions, shows the static fit uncovered)
    assert_covers("static fit, plant × 1.10", &v, 1.10);
    // the built-in law: 10 % more viscous is a cooler oil, about 9 K below the 40 °C design
    let offset = v.temperature_offset_k.unwrap();
    assert!(offset < -5.0 && offset > -15.0, "offset {offset} K");

    twin.set_viscosity_scale(v.scale).unwrap();
    let u = estimate_unbalance(&twin, &vectors, 0.1).unwrap();
    eprintln!("unbalance: {u:?}");
    let (p15, p21) = (u.planes[0], u.planes[1]);
    assert!((p21.magnitude_g_mm / 280.0 - 1.0).abs() < 0.10, "{p21:?}");
    let dphi = (p21.phase_deg - 120.0 + 180.0).rem_euclid(360.0) - 180.0;
    assert!(dphi.abs() < 10.0, "phase {} (plant 120°)", p21.phase_deg);
    assert!(p15.magnitude_g_mm < 28.0, "stage-4 plane: {p15:?}");
    // the balancing weight: the same m·e opposite, at 100 mm
    assert!((p21.correction.mass_g - p21.magnitude_g_mm / 100.0).abs() < 1e-9);
    let opposite = (p21.correction.angle_deg - p21.phase_deg).rem_euclid(360.0);
    assert!((opposite - 180.0).abs() < 1e-9);
    assert!(u.condition_number.is_finite() && u.condition_number >= 1.0);
    assert!(
        u.relative_residual < 0.2,
        "relative residual {}",
        u.relative_residual
    );
}

/// The shipped sample bag (bags/README.md: the plant's oil 5 % more viscous, 140 g·mm at 0° at
/// node 15, films on 90 × 15), its stable first 4.5 s: the shaft angle integrated from the speed
/// messages, the viscosity within 3 % of 1.05 and the unbalance within 10 % and 10°.
#[test]
fn the_sample_bag_gives_its_plant_viscosity_and_unbalance() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("bags/orc_runup_synthetic");
    let bag = rotor_twin::bag::Bag::read(&dir).unwrap();
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let (cal, calibrated) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.0, 4.5], None)
            .unwrap();
    eprintln!("{cal:?}");
    assert!(
        (cal.viscosity.unwrap().scale / 1.05 - 1.0).abs() < 0.03,
        "{:?}",
        cal.viscosity
    );
    assert_covers(
        "sample bag, plant × 1.05",
        cal.viscosity.as_ref().unwrap(),
        1.05,
    );
    let p = cal.unbalance.planes[0];
    assert!((p.magnitude_g_mm / 140.0 - 1.0).abs() < 0.10, "{p:?}");
    let dphi = (p.phase_deg + 180.0).rem_euclid(360.0) - 180.0;
    assert!(dphi.abs() < 10.0, "{p:?}");
    assert!((calibrated.viscosity_scale() - cal.viscosity.unwrap().scale).abs() < 1e-12);
}

/// `replay --calibrate` on a nonlinear twin refines the unbalance on it (session 17,
/// `calibrate::refine_unbalance`, the direct film at 64 steps a revolution here, the table in the
/// CLI): on the sample bag's first 4.5 s the refined estimate fits the nonlinear twin better than
/// the linear fit does (its relative 1X residual on the twin against the linear fit's on the
/// linear model: measured 1.4 % against 1.7 %) and keeps the plant's unbalance (140 g·mm at 0°):
/// measured 140.1 g·mm at 0.0° (the linear fit 359.7°), asserted within 1 % and 0.5°.
#[test]
fn the_sample_bag_s_unbalance_refined_on_the_nonlinear_twin() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("bags/orc_runup_synthetic");
    let bag = rotor_twin::bag::Bag::read(&dir).unwrap();
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let how = rotor_twin::calibrate::NonlinearRefinement {
        film: rotor_twin::dynamics::FilmEvaluation::Direct,
        steps_per_rev: 64,
    };
    let fit = |refine| {
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.0, 4.5], refine)
            .unwrap()
            .0
            .unbalance
    };
    let (linear, refined) = (fit(None), fit(Some(how)));
    eprintln!("linear {linear:?}\nrefined {refined:?}");
    assert!(refined.nonlinear_updates >= 1 && refined.not_refined.is_none());
    assert!(refined.relative_residual < linear.relative_residual);
    let p = refined.planes[0];
    assert!((p.magnitude_g_mm / 140.0 - 1.0).abs() < 0.01, "{p:?}");
    let dphi = (p.phase_deg + 180.0).rem_euclid(360.0) - 180.0;
    assert!(dphi.abs() < 0.5, "{p:?}");
}

/// A synthetic bag whose keyphasor mark sits 123° round the shaft from the plant's angle zero
/// (`synth-bag --keyphasor-deg 123`; 1.5 s at 8,000 rpm): the fitted unbalance phase is measured
/// from the mark, so it equals the phase the bag publishes (the plant's, from the mark) within
/// 10°, and the magnitude within 10 % of the plant's 140 g·mm. Without the keyphasor reference
/// the fit would give the phase from the plant's angle zero, 123° away.
#[test]
fn with_a_keyphasor_the_unbalance_phase_is_measured_from_the_mark() {
    let (dir, bag, published) = bag_at_8000_rpm("kp", &[]);
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let (cal, _) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.3, 1.5], None)
            .unwrap();
    let p = cal.unbalance.planes[0];
    assert!((p.magnitude_g_mm / 140.0 - 1.0).abs() < 0.10, "{p:?}");
    let dphi = (p.phase_deg - published.phase.to_degrees() + 180.0).rem_euclid(360.0) - 180.0;
    assert!(
        dphi.abs() < 10.0,
        "{p:?} against {:.1}°",
        published.phase.to_degrees()
    );
    std::fs::remove_dir_all(dir).ok();
}

/// `replay --calibrate` on the plant's own signals (issue 12): a synthetic bag (`synth-bag
/// --raw-probes --runout-um 5 --keyphasor-deg 123`; 1.5 s at 8,000 rpm, oil 5 % more viscous,
/// films on 90 × 15) whose probes are raw readings at 45°/135° in volts, DC-coupled, with 5 µm
/// of runout (high spot 30° from the mark) and 0.3 µm of noise. The machine file names the raw
/// probes and their runout vectors; the fit pairs the readings, subtracts the runout and gives
/// the unbalance within 10 % and 10° of the published 140 g·mm (phase from the mark) and the
/// viscosity within 3 % of × 1.05 (the DC gap keeps the mean position). The same bag with the
/// runout not subtracted (the machine file without it) misses the unbalance: the 5 µm runout
/// is larger than the 1X motion, so the test can fail.
#[test]
fn replay_calibrate_takes_raw_probes_with_runout() {
    let (dir, bag, published) = bag_at_8000_rpm("raw", &["--raw-probes", "--runout-um", "5"]);
    let rotor = Rotor::from_description(&builtin_with_raw_probes(5e-6));
    let (cal, _) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.3, 1.5], None)
            .unwrap();
    let p = cal.unbalance.planes[0];
    let v = cal.viscosity.as_ref().unwrap();
    println!(
        "raw probes: {} windows; viscosity × {:.4} ± {:.4}; unbalance {:.1} g·mm at {:.1}° (published 140 at {:.1}°)",
        cal.windows_used,
        v.scale,
        v.scale_std,
        p.magnitude_g_mm,
        p.phase_deg,
        published.phase.to_degrees()
    );
    let gap = |a: f64, b: f64| (a - b + 180.0).rem_euclid(360.0) - 180.0;
    assert!(cal.windows_used >= 4, "{cal:?}");
    assert!((v.scale / 1.05 - 1.0).abs() < 0.03, "{v:?}");
    assert_covers("raw-probe bag, plant × 1.05", v, 1.05);
    assert!((p.magnitude_g_mm / 140.0 - 1.0).abs() < 0.10, "{p:?}");
    assert!(
        gap(p.phase_deg, published.phase.to_degrees()).abs() < 10.0,
        "{p:?}"
    );
    // the runout left in: the fit reads the runout as unbalance
    let no_runout = Rotor::from_description(&builtin_with_raw_probes(0.0));
    let (cal0, _) = rotor_twin::replay::calibration::calibrate_bag(
        &bag,
        &no_runout,
        &[],
        &[],
        [0.3, 1.5],
        None,
    )
    .unwrap();
    let q = cal0.unbalance.planes[0];
    println!(
        "runout not subtracted: {:.1} g·mm at {:.1}°",
        q.magnitude_g_mm, q.phase_deg
    );
    assert!(
        (q.magnitude_g_mm / 140.0 - 1.0).abs() > 0.10
            || gap(q.phase_deg, published.phase.to_degrees()).abs() > 10.0,
        "{q:?}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// A synthetic bag (`synth-bag`, 1.5 s at 8,000 rpm, keyphasor mark 123° from the plant's angle
/// zero, and `extra` arguments) in a scratch directory named by `tag`, read back, with the
/// unbalance it publishes (the plant's, phase from the mark).
fn bag_at_8000_rpm(
    tag: &str,
    extra: &[&str],
) -> (
    std::path::PathBuf,
    rotor_twin::bag::Bag,
    rotor_twin::messages::Unbalance,
) {
    let mut args = vec![
        "--from-rpm",
        "8000",
        "--to-rpm",
        "8000",
        "--hold-start",
        "1.5",
        "--ramp",
        "0.01",
        "--hold-end",
        "0.01",
    ];
    args.extend_from_slice(extra);
    synth_bag(tag, &args)
}

/// `synth-bag --keyphasor-deg 123` with `args` (the profile among them) in a scratch directory
/// named by `tag`, read back, with the unbalance it publishes (the plant's, phase from the mark).
fn synth_bag(
    tag: &str,
    extra: &[&str],
) -> (
    std::path::PathBuf,
    rotor_twin::bag::Bag,
    rotor_twin::messages::Unbalance,
) {
    let dir = std::env::temp_dir().join(format!("rotor_twin_cal_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut args = vec![
        "synth-bag",
        "--out",
        dir.to_str().unwrap(),
        "--keyphasor-deg",
        "123",
    ];
    args.extend_from_slice(extra);
    let (ok, _, err) = common::run_cli(&args);
    assert!(ok, "{err}");
    let bag = rotor_twin::bag::Bag::read(&dir).unwrap();
    let published = bag
        .messages()
        .find(|m| bag.topics[m.topic].name == rotor_twin::topics::UNBALANCE)
        .map(|m| {
            rotor_twin::messages::from_cdr::<rotor_twin::messages::Unbalance>(m.payload()).unwrap()
        })
        .expect("the bag publishes its unbalance");
    (dir, bag, published)
}

/// `replay --calibrate` fits as the live calibration does (session 12): the viscosity refitted
/// to the mean positions under the journal orbits of the fitted unbalance
/// (`calibrate::estimate_viscosity_and_unbalance`), not the static equilibrium alone. The plant
/// is tests/live_calibration.rs's (common::calibration): oil × 1.10, 280 g·mm at stage 7 (node
/// 21) at 120°, films 72 × 12 (grid × 1.2), direct film, 0.3 µm of noise, keyphasor at its angle
/// 0; its bag holds 0.8 s at 5,000 rpm, a 0.3 s ramp and 0.8 s at 8,000 rpm (`plant::write_bag`).
/// The fit takes 0.3 s on. Targets (the issue's): viscosity within 3 % of 1.10, unbalance within
/// 10 % and 10°; and the orbit-averaged viscosity nearer 1.10 than the static fit on the same
/// windows (printed: the before/after of the README).
#[test]
fn replay_calibrate_fits_the_viscosity_under_the_orbits() {
    use rotor_twin::dynamics::FilmEvaluation;
    use rotor_twin::plant::{write_bag, PlantSignals, PlantSpec, SpeedProfile};
    use rotor_twin::replay::calibration::{bag_measurements, calibrate_bag};
    let twin = twin_rotor();
    let mut plant = twin.clone();
    plant.unbalance[0].magnitude_kg_m = 0.0;
    plant.unbalance[1].magnitude_kg_m = 280e-6;
    plant.unbalance[1].phase_rad = 120f64.to_radians();
    let spec = PlantSpec {
        profile: SpeedProfile {
            from_rpm: 5000.0,
            to_rpm: 8000.0,
            hold_start_s: 0.8,
            ramp_s: 0.3,
            hold_end_s: 0.8,
        },
        samples_per_rev: 16,
        noise_m: 0.3e-6,
        viscosity_factor: 1.10,
        grid_factor: 1.2,
        film: FilmEvaluation::Direct,
        seed: 12,
        signals: PlantSignals {
            keyphasor_angle_deg: Some(0.0),
            raw_probes: false,
            runout_m: 0.0,
            ..PlantSignals::default()
        },
    };
    let dir = std::env::temp_dir().join(format!("rotor_twin_cal_orbits_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let started = std::time::Instant::now();
    let (dir, ..) = write_bag(&plant, &spec, &dir, &mut |_| {}).unwrap();
    println!("plant bag: {:.1} s", started.elapsed().as_secs_f64());
    let bag = rotor_twin::bag::Bag::read(&dir).unwrap();
    let window = [0.3, 1.9];
    let m = bag_measurements(&bag, &twin, &[], &[], window);
    let (means, vectors) = (m.means, m.vectors);
    let before = estimate_viscosity(&twin, &means).unwrap();
    let (cal, calibrated) = calibrate_bag(&bag, &twin, &[], &[], window, None).unwrap();
    let v = cal.viscosity.as_ref().unwrap();
    let p = cal.unbalance.planes[1];
    println!(
        "{} windows ({} left out): static fit × {:.4} ± {:.4}, orbit-averaged × {:.4} ± {:.4} (plant × 1.10); unbalance {:.1} g·mm at {:.1}° (plant 280 at 120°), stage 4 {:.1} g·mm",
        cal.windows_used,
        cal.windows_skipped,
        before.scale,
        before.scale_std,
        v.scale,
        v.scale_std,
        p.magnitude_g_mm,
        p.phase_deg,
        cal.unbalance.planes[0].magnitude_g_mm
    );
    assert!(vectors.len() >= 8, "{} 1X vectors", vectors.len());
    assert!((v.scale / 1.10 - 1.0).abs() < 0.03, "{v:?}");
    // the static fit alone (no orbit model; no longer what `--calibrate` reports) is not
    // covered here: its orbit bias, +2.6 %, is beyond the model floor (printed, not asserted)
    let e = before.scale - 1.10;
    println!(
        "replay, static fit: error {e:+.4} = {:+.2} σ (not covered: the orbit bias)",
        e / before.scale_std
    );
    assert_covers("replay, orbit-averaged fit, plant × 1.10", v, 1.10);
    assert!(
        (v.scale - 1.10).abs() < (before.scale - 1.10).abs(),
        "orbit-averaged × {} no nearer 1.10 than the static × {}",
        v.scale,
        before.scale
    );
    assert!((p.magnitude_g_mm / 280.0 - 1.0).abs() < 0.10, "{p:?}");
    let dphi = (p.phase_deg - 120.0 + 180.0).rem_euclid(360.0) - 180.0;
    assert!(dphi.abs() < 10.0, "{p:?}");
    assert!((calibrated.viscosity_scale() - v.scale).abs() < 1e-12);
    std::fs::remove_dir_all(dir).ok();
}

// --- plant-shaped bags (session 13, issue 12's referee) ---

/// The built-in machine with raw probes `<station>_x` / `_y` at 45° and 135° in V at 7.87 V/mm
/// (the plant's of `synth-bag --raw-probes`), `coupling` ("dc, reference_gap: 7.87" or "ac"),
/// no runout vector, and `slow_roll_rpm` as the machine file's `slow_roll_speed_rpm`.
fn raw_machine(coupling: &str, slow_roll_rpm: Option<f64>) -> Rotor {
    let mut yaml = format!("{}\n", rotor_twin::rotor::DEFAULT_MACHINE_YAML.trim_end());
    if let Some(rpm) = slow_roll_rpm {
        yaml += &format!("slow_roll_speed_rpm: {rpm}\n");
    }
    yaml += "proximity_probes:\n";
    for station in ["probe_pulley_end", "probe_outboard"] {
        for (suffix, angle) in [("x", 45.0), ("y", 135.0)] {
            yaml += &format!(
                "  - {{name: {station}_{suffix}, station: {station}, angle_deg: {angle}, unit: V, sensitivity_v_per_m: 7870.0, coupling: {coupling}}}\n"
            );
        }
    }
    Rotor::from_description(&MachineDescription::from_yaml(&yaml, "raw.yaml").unwrap())
}

/// The signed difference a − b of two angles (deg), in [−180, 180).
fn angle_gap(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

/// A rig with only the once-per-revolution mark (`synth-bag --no-speed --keyphasor-deg 123`;
/// 1.5 s at 8,000 rpm, oil 5 % more viscous, films 90 × 15): `--calibrate` takes the speed and
/// the angle from the keyphasor's intervals and gives the unbalance within 10 % and 10° of the
/// published 140 g·mm (phase from the mark), and the viscosity within 3 % of × 1.05 (the
/// issue's targets). Before, the fit had no speed, hence no sample, and failed.
#[test]
fn replay_calibrate_takes_the_speed_from_the_keyphasor() {
    let (dir, bag, published) = bag_at_8000_rpm("nospeed", &["--no-speed"]);
    assert!(
        !bag.topics
            .iter()
            .any(|t| t.name == rotor_twin::topics::SPEED),
        "the bag has a speed topic"
    );
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let (cal, _) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.3, 1.5], None)
            .unwrap();
    let (p, v) = (cal.unbalance.planes[0], cal.viscosity.unwrap());
    println!(
        "keyphasor only: {} windows; viscosity × {:.4} ± {:.4}; unbalance {:.1} g·mm at {:.1}° (published 140 at {:.1}°)",
        cal.windows_used, v.scale, v.scale_std, p.magnitude_g_mm, p.phase_deg,
        published.phase.to_degrees()
    );
    assert!(
        cal.speed_from_keyphasor && cal.phase_null_reason.is_none(),
        "{cal:?}"
    );
    assert!(cal.windows_used >= 8, "{cal:?}");
    assert!((v.scale / 1.05 - 1.0).abs() < 0.03, "{v:?}");
    assert!((p.magnitude_g_mm / 140.0 - 1.0).abs() < 0.10, "{p:?}");
    let dphi = angle_gap(p.phase_deg, published.phase.to_degrees());
    assert!(dphi.abs() < 10.0, "{p:?}");
    std::fs::remove_dir_all(dir).ok();
}

/// AC-coupled raw probes (`synth-bag --raw-probes --ac-coupled --keyphasor-deg 123`: no DC gap,
/// a 0.1 s high pass; 1.5 s at 8,000 rpm) and a machine file saying `coupling: ac`: no mean
/// position, so `--calibrate` fits the unbalance alone (within 10 % and 10° of the published
/// 140 g·mm) at the machine file's viscosity (scale 1 kept) and says why the viscosity is not
/// fitted. Before, the missing viscosity failed the whole calibration.
#[test]
fn replay_calibrate_with_ac_coupled_probes_fits_the_unbalance_alone() {
    let (dir, bag, published) = bag_at_8000_rpm("ac", &["--raw-probes", "--ac-coupled"]);
    let rotor = raw_machine("ac", None);
    let (cal, calibrated) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.3, 1.5], None)
            .unwrap();
    let p = cal.unbalance.planes[0];
    println!(
        "AC-coupled: {} windows; viscosity {:?}; unbalance {:.1} g·mm at {:.1}° (published 140 at {:.1}°)",
        cal.windows_used, cal.viscosity_not_fitted, p.magnitude_g_mm, p.phase_deg,
        published.phase.to_degrees()
    );
    assert!(cal.viscosity.is_none(), "{cal:?}");
    let why = cal.viscosity_not_fitted.as_deref().unwrap_or("");
    assert!(
        why.starts_with("not fitted: no mean positions (AC-coupled)"),
        "{why}"
    );
    assert_eq!(calibrated.viscosity_scale(), 1.0);
    assert!(cal.windows_used >= 8, "{cal:?}");
    assert!((p.magnitude_g_mm / 140.0 - 1.0).abs() < 0.10, "{p:?}");
    let dphi = angle_gap(p.phase_deg, published.phase.to_degrees());
    assert!(dphi.abs() < 10.0, "{p:?}");
    std::fs::remove_dir_all(dir).ok();
}

/// Slow-roll runout measured in the bag: raw DC probes with 5 µm of runout (high spot 30° from
/// the mark), 0.45 s of slow roll at 800 rpm (6 revolutions), a 0.2 s ramp and 0.85 s at 8,000
/// rpm (`synth-bag --raw-probes --runout-um 5 --from-rpm 800 --hold-start 0.45`), and a machine
/// file with `slow_roll_speed_rpm: 1500` but no runout vector. `--calibrate` measures each
/// probe's runout at slow roll (within 0.3 µm and 5° of the plant's 5 µm; the 1X response to
/// 140 g·mm at 800 rpm is a few per cent of a µm) and subtracts it: the unbalance within 10 %
/// and 10° of the published 140 g·mm. The runout left in reads about 278 g·mm at 210° (README),
/// so the test fails without the measurement; calibration.json says which runout was used.
#[test]
fn replay_calibrate_measures_the_runout_at_slow_roll() {
    let (dir, bag, published) = synth_bag(
        "slowroll",
        &[
            "--to-rpm",
            "8000",
            "--raw-probes",
            "--runout-um",
            "5",
            "--from-rpm",
            "800",
            "--hold-start",
            "0.45",
            "--ramp",
            "0.2",
            "--hold-end",
            "0.85",
        ],
    );
    let rotor = raw_machine("dc, reference_gap: 7.87", Some(1500.0));
    let (cal, _) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.9, 1.5], None)
            .unwrap();
    for (r, angle) in cal.runouts.iter().zip([45.0f64, 135.0, 45.0, 135.0]) {
        let truth = rotor_twin::plant::plant_runout(5e-6, angle.to_radians());
        let v = r.vector.unwrap_or_default();
        println!(
            "{}: {} over {:?} s ({:.1} revolutions): {:.3} µm at {:.1}° (plant {:.3} µm at {:.1}°)",
            r.probe,
            r.source,
            r.slow_roll_s,
            r.slow_roll_revolutions.unwrap_or(0.0),
            v.amplitude_m * 1e6,
            v.phase_lag_deg,
            truth.amplitude_m * 1e6,
            truth.phase_lag_deg
        );
        assert_eq!(r.source, "measured at slow roll", "{r:?}");
        assert!((v.amplitude_m - truth.amplitude_m).abs() < 0.3e-6, "{r:?}");
        assert!(
            angle_gap(v.phase_lag_deg, truth.phase_lag_deg).abs() < 5.0,
            "{r:?}"
        );
    }
    let json = serde_json::to_value(&cal).unwrap();
    assert_eq!(json["runouts"][0]["source"], "measured at slow roll");
    let p = cal.unbalance.planes[0];
    println!(
        "measured runout subtracted: {:.1} g·mm at {:.1}° (published 140 at {:.1}°)",
        p.magnitude_g_mm,
        p.phase_deg,
        published.phase.to_degrees()
    );
    assert!((p.magnitude_g_mm / 140.0 - 1.0).abs() < 0.10, "{p:?}");
    let dphi = angle_gap(p.phase_deg, published.phase.to_degrees());
    assert!(dphi.abs() < 10.0, "{p:?}");
    // the same bag and machine without slow_roll_speed_rpm: nothing measures the runout, the
    // fit reads it as unbalance and misses
    let blind = raw_machine("dc, reference_gap: 7.87", None);
    let (cal0, _) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &blind, &[], &[], [0.9, 1.5], None)
            .unwrap();
    let q = cal0.unbalance.planes[0];
    println!(
        "runout left in: {:.1} g·mm at {:.1}° ({})",
        q.magnitude_g_mm, q.phase_deg, cal0.runouts[0].source
    );
    assert!(
        (q.magnitude_g_mm / 140.0 - 1.0).abs() > 0.10
            || angle_gap(q.phase_deg, published.phase.to_degrees()).abs() > 10.0,
        "{q:?}"
    );
    std::fs::remove_dir_all(dir).ok();
}

/// No keyphasor in the bag (`synth-bag --no-keyphasor`; 1.5 s at 8,000 rpm): the unbalance's
/// phase and the correction's angle are null in calibration.json with the reason (the issue:
/// never a number relative to an arbitrary start); the amplitude is still given, within 10 % of
/// the plant's 140 g·mm (it needs no phase reference).
#[test]
fn without_a_keyphasor_the_unbalance_phase_is_null_with_the_reason() {
    let (dir, bag, _) = bag_at_8000_rpm("nokp", &["--no-keyphasor"]);
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let (cal, _) =
        rotor_twin::replay::calibration::calibrate_bag(&bag, &rotor, &[], &[], [0.3, 1.5], None)
            .unwrap();
    let json = serde_json::to_value(&cal).unwrap();
    let plane = &json["unbalance"]["planes"][0];
    println!("no keyphasor: {plane} ({})", json["phase_null_reason"]);
    assert!(plane["phase_deg"].is_null(), "{plane}");
    assert!(plane["correction"]["angle_deg"].is_null(), "{plane}");
    let why = json["phase_null_reason"].as_str().unwrap_or("");
    assert!(why.contains("no keyphasor"), "{why}");
    let magnitude = plane["magnitude_g_mm"].as_f64().unwrap();
    assert!((magnitude / 140.0 - 1.0).abs() < 0.10, "{plane}");
    std::fs::remove_dir_all(dir).ok();
}

/// `replay --calibrate` end to end on the keyphasor-only bag of
/// [`replay_calibrate_takes_the_speed_from_the_keyphasor`] (the replay, too, takes the speed
/// from the keyphasor): calibration.json's `comparison` gives, per probe station, the 1X
/// amplitude error and the 1X phase lag error per probe axis before and after, next to the
/// onset. After calibration the phase lag error over the fitted window is within 5° and the
/// amplitude error within 5 % (the targets); the printout says both.
#[test]
fn replay_calibrate_compares_the_phase_lag_before_and_after() {
    let (dir, _, _) = bag_at_8000_rpm("cmp", &["--no-speed"]);
    let out = dir.with_extension("out");
    let _ = std::fs::remove_dir_all(&out);
    let (ok, text, err) = common::run_cli(&[
        "replay",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--fast",
        "--no-bag",
        "--calibrate",
        "--calibrate-window",
        "0.3:1.5",
    ]);
    assert!(ok, "{err}");
    println!("{text}");
    assert!(
        text.contains("phase lag error (probe axes) before"),
        "{text}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("calibration.json")).unwrap())
            .unwrap();
    let stations = json["comparison"]["stations"].as_array().unwrap();
    assert_eq!(stations.len(), 2, "{}", json["comparison"]);
    for s in stations {
        assert!(s["blocks_in_window"].as_u64().unwrap() >= 4, "{s}");
        for when in 0..2 {
            let lags = &s["phase_lag_error_window_deg"][when];
            assert!(lags.is_array(), "{s}");
            let amp = s["amplitude_error_window"][when].as_f64().unwrap();
            if when == 1 {
                for lag in lags.as_array().unwrap() {
                    assert!(lag.as_f64().unwrap() < 5.0, "{s}");
                }
                assert!(amp < 0.05, "{s}");
            }
        }
    }
    assert!(json["comparison"].get("onset_predicted_rpm").is_some());
    std::fs::remove_dir_all(&out).ok();
    std::fs::remove_dir_all(dir).ok();
}
