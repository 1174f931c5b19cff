//! Studies of the nonlinear run-up onset (issue 12, session 13; README, "The onset after a live
//! calibration"): not checks, every one ignored, printing `TRACE` and `RESULT` lines. Each run is
//! set by environment variables so that one build serves all of them (`cargo test --release
//! --test onset_study -- --ignored --nocapture --exact onset_study`):
//! ONSET_ROTOR = plant | calibrated | machine; ONSET_GRID = 60x10; ONSET_FILM = table | direct;
//! ONSET_MODE = ramp | const | updown; ONSET_RATE (rpm/s); ONSET_FROM, ONSET_TO (rpm);
//! ONSET_RPM (const speed); ONSET_VISC (a further viscosity factor); ONSET_KICK (N·s in x and y
//! at the stage-7 node at ONSET_KICK_T s, 0 = none); ONSET_REVS (revolutions after the ramp);
//! ONSET_SPR (time steps a revolution at ONSET_TO, 64). `onset_switch` (the calibration applied
//! mid-run): ONSET_APPLY, ONSET_BLEND, ONSET_HOLD, ONSET_PRE, ONSET_STAIR_MS, ONSET_LOCK (its doc).
//! The film tables go to the disk cache (`ROTOR_TWIN_CACHE_DIR`).

mod common;

use common::calibration::{plant_rotor, twin_rotor};
use common::onset::onset_by_rule;
use rotor_twin::dynamics::{Coupling, FilmEvaluation};
use rotor_twin::film::{set_disk_cache, FilmGrid, TableCache};
use rotor_twin::monitor::ClassifierSettings;
use rotor_twin::transient::{run_driven, Drive, Kick, SpeedHistory, TransientSpec};

fn env(name: &str, default: &str) -> String {
    std::env::var(name).unwrap_or_else(|_| default.to_string())
}

fn num(name: &str, default: f64) -> f64 {
    env(name, &default.to_string()).parse().expect("a number")
}

#[test]
#[ignore]
fn onset_study() {
    if let Some(dir) = TableCache::default_dir() {
        set_disk_cache(Some(TableCache::new(dir)));
    }
    let twin = twin_rotor();
    let mut rotor = match env("ONSET_ROTOR", "plant").as_str() {
        "plant" => plant_rotor(&twin),
        "calibrated" => {
            // the live estimate of tests/live_calibration.rs from the start
            let mut r = twin.clone();
            r.unbalance[0].magnitude_kg_m = 0.0;
            r.unbalance[1].magnitude_kg_m = 275.4e-6;
            r.unbalance[1].phase_rad = 118.6f64.to_radians();
            r.set_viscosity_scale(1.1042).unwrap();
            r
        }
        _ => twin.clone(),
    };
    if let Ok(s) = std::env::var("ONSET_VISC") {
        let s: f64 = s.parse().expect("a number");
        for b in &mut rotor.bearings {
            if let rotor_twin::rotor::BearingModel::Film(f) = &mut b.model {
                f.lubricant.viscosity_pa_s *= s;
            }
        }
    }
    let g = env("ONSET_GRID", "60x10");
    let (nt, nz) = g.split_once('x').expect("NTxNZ");
    let grid = FilmGrid {
        n_theta: nt.parse().unwrap(),
        n_z: nz.parse().unwrap(),
    };
    let film = match env("ONSET_FILM", "table").as_str() {
        "direct" => FilmEvaluation::Direct,
        _ => FilmEvaluation::Table,
    };
    let rate = num("ONSET_RATE", 400.0);
    let mode = env("ONSET_MODE", "ramp");
    let (lo, hi) = (num("ONSET_FROM", 8000.0), num("ONSET_TO", 9400.0));
    let hold = 16.0 * 60.0 / lo;
    let up = (hi - lo) / rate;
    let speed = match mode.as_str() {
        "ramp" => Some(vec![(0.0, lo), (hold, lo), (hold + up, hi)]),
        "updown" => Some(vec![
            (0.0, lo),
            (hold, lo),
            (hold + up, hi),
            (hold + up + 0.3, hi),
            (hold + 2.0 * up + 0.3, lo),
        ]),
        _ => None,
    };
    let kick = num("ONSET_KICK", 0.0);
    let drive = Drive {
        speed: speed.map(|p| SpeedHistory::new(p).unwrap()),
        kicks: if kick > 0.0 {
            vec![Kick {
                time_s: num("ONSET_KICK_T", 0.01),
                node: 21,
                impulse_n_s: [kick, kick],
            }]
        } else {
            Vec::new()
        },
    };
    let spec = TransientSpec {
        speed_rpm: num("ONSET_RPM", lo),
        revolutions: num("ONSET_REVS", 8.0) as usize,
        coupling: Coupling::Nonlinear,
        steps_per_rev: num("ONSET_SPR", 64.0) as usize,
        grid: Some(grid),
        film,
    };
    let t0 = std::time::Instant::now();
    let r = run_driven(&rotor, &spec, None, &drive).unwrap();
    let wall = t0.elapsed().as_secs_f64();
    let cls = ClassifierSettings::default();
    let c = r.clearances_m[0];
    // per revolution: the largest sub-synchronous amplitude over the bearings, and whether it
    // counts (the replay's rule, on the bearings: > 2 % c and > 0.5 × 1X)
    let per_rev: Vec<(f64, f64, bool)> = r
        .history
        .iter()
        .map(|h| {
            let rpm = h.speed_rad_s * 30.0 / std::f64::consts::PI;
            let a = h
                .bearings
                .iter()
                .map(|b| b.subsync_amplitude_m)
                .fold(0.0, f64::max);
            let counts = h
                .bearings
                .iter()
                .any(|b| cls.subsync_counts(b.subsync_amplitude_m, b.one_x_amplitude_m, c));
            (rpm, a, counts)
        })
        .collect();
    let onset = (0..per_rev.len())
        .find(|&k| k + 24 <= per_rev.len() && per_rev[k..k + 24].iter().all(|p| p.2));
    let label = format!(
        "{} {g} {:?} {mode} rate {rate} rpm {} kick {kick} spr {}",
        env("ONSET_ROTOR", "plant"),
        film,
        spec.speed_rpm,
        spec.steps_per_rev
    );
    // the growth per revolution over 16-revolution windows (ln A slope) while A is above the
    // floor and below 20 % c
    let every = num("ONSET_EVERY", 16.0) as usize;
    for k in (0..per_rev.len()).step_by(every) {
        let w = &per_rev[k..(k + every).min(per_rev.len())];
        let pts: Vec<(f64, f64)> = w
            .iter()
            .enumerate()
            .filter(|(_, p)| p.1 > 0.0)
            .map(|(j, p)| (j as f64, p.1.ln()))
            .collect();
        let m = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / m,
            pts.iter().map(|p| p.1).sum::<f64>() / m,
        );
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        println!(
            "TRACE {label} | rev {k} {:.0} rpm: subsync {:.3} µm ({:.4} c), growth {slope:+.4}/rev, counts {}",
            w[0].0,
            w[0].1 * 1e6,
            w[0].1 / c,
            w[0].2
        );
    }
    match onset {
        Some(k) => println!(
            "RESULT {label}: onset {:.0} rpm (rev {k}), by the replay's rule {:?}; wall {wall:.0} s",
            per_rev[k].0,
            onset_by_rule(&per_rev).map(f64::round)
        ),
        None => println!("RESULT {label}: no onset; wall {wall:.0} s"),
    }
    if mode == "updown" {
        // the last revolution that counts on the way down
        let top = per_rev
            .iter()
            .enumerate()
            .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
            .map_or(0, |m| m.0);
        let last = (top..per_rev.len()).rev().find(|&k| per_rev[k].2);
        println!(
            "RESULT {label}: on the way down the whirl counts last at {:?} rpm",
            last.map(|k| per_rev[k].0.round())
        );
    }
}

/// The twin (machine file, 60 × 10 table) at 8,000 rpm for ONSET_HOLD revolutions, then the
/// live estimate (275.4 g·mm at 118.6° at stage 7, none at stage 4, viscosity × 1.1042) applied
/// as ONSET_APPLY = step | start (from t = 0) | blend (linearly over ONSET_BLEND revolutions,
/// from the hold's end on) | none, then the run-up at ONSET_RATE to 9,400 rpm. ONSET_UNB_ONLY /
/// ONSET_VISC_ONLY apply one of the two; ONSET_PRE (rpm): 24.5 revolutions there first, then
/// 8,000 rpm at once; ONSET_STAIR_MS: the speed held between updates (the driver's input);
/// ONSET_LOCK: the twin's angle shifted onto the continuous ramp's once a revolution (the
/// keyphasor lock).
#[test]
#[ignore]
fn onset_switch() {
    use rotor_twin::dynamics::{StepInput, Twin, TwinConfig};
    use rotor_twin::monitor::Monitor;
    use std::f64::consts::PI;
    if let Some(dir) = TableCache::default_dir() {
        set_disk_cache(Some(TableCache::new(dir)));
    }
    let twin_r = twin_rotor();
    let apply = env("ONSET_APPLY", "step");
    let (u0, u1, s1) = (
        (
            twin_r.unbalance[0].magnitude_kg_m,
            twin_r.unbalance[0].phase_rad,
        ),
        (275.4e-6, 118.6f64.to_radians()),
        1.1042,
    );
    let unb = std::env::var("ONSET_VISC_ONLY").is_err();
    let vis = std::env::var("ONSET_UNB_ONLY").is_err();
    let rate = num("ONSET_RATE", 400.0);
    let hold_revs = num("ONSET_HOLD", 24.5);
    let blend_revs = num("ONSET_BLEND", 100.0);
    let w8 = 8000.0 * PI / 30.0;
    let hi = 9400.0;
    let mut config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, hi * PI / 30.0, 64);
    config.film = FilmEvaluation::Table;
    let w0 = if std::env::var("ONSET_PRE").is_ok() {
        num("ONSET_PRE", 8000.0) * PI / 30.0
    } else {
        w8
    };
    let mut twin = Twin::new(&twin_r, config, w0).unwrap();
    // the values at fraction f of the way from the machine file's to the estimate's
    let set = |twin: &mut Twin, f: f64| {
        if unb {
            twin.set_unbalance(0, u0.0 * (1.0 - f), u0.1).unwrap();
            twin.set_unbalance(1, u1.0 * f, u1.1).unwrap();
        }
        if vis {
            twin.set_viscosity_scale(1.0 + (s1 - 1.0) * f).unwrap();
        }
    };
    if apply == "start" {
        set(&mut twin, 1.0);
    }
    let mut monitor = Monitor::new(&twin, 128, ClassifierSettings::default());
    let cls = ClassifierSettings::default();
    let c = twin.bearing_clearances_m()[0];
    // ONSET_PRE: first 24.5 revolutions at that speed, then 8,000 rpm at once (the speed steps
    // of tests/live_calibration.rs's plant)
    let pre = num("ONSET_PRE", 0.0);
    let stair = num("ONSET_STAIR_MS", 0.0) * 1e-3;
    let lock = std::env::var("ONSET_LOCK").is_ok();
    let (mut plant_angle, mut plant_revs, mut largest_shift) = (0.0f64, 0.0f64, 0.0f64);
    let t_pre = if pre > 0.0 { 24.5 * 60.0 / pre } else { 0.0 };
    let t_hold = t_pre + hold_revs * 60.0 / 8000.0;
    let t_blend = blend_revs * 60.0 / 8000.0;
    let t_end = t_hold + (hi - 8000.0) / rate;
    let h = twin.config().time_step_s;
    let mut per_rev: Vec<(f64, f64, bool)> = Vec::new();
    while twin.time_s() < t_end {
        let t = twin.time_s();
        match apply.as_str() {
            "step" if t >= t_hold && t < t_hold + h => set(&mut twin, 1.0),
            "blend" if t >= t_hold => set(&mut twin, ((t - t_hold) / t_blend).min(1.0)),
            _ => {}
        }
        let rpm = if t < t_pre {
            pre
        } else if t < t_hold {
            8000.0
        } else {
            8000.0 + rate * (t + 0.5 * h - t_hold)
        };
        let accel = if t < t_hold { 0.0 } else { rate * PI / 30.0 };
        // ONSET_STAIR_MS: the speed held between updates every that many ms (the driver's
        // speed input), the rate given with it
        let rpm = if stair > 0.0 && t >= t_hold {
            let tu = t_hold + ((t - t_hold) / stair).floor() * stair;
            8000.0 + rate * (tu - t_hold)
        } else {
            rpm
        };
        twin.step(&StepInput {
            speed_rad_s: rpm * PI / 30.0,
            accel_rad_s2: accel,
        })
        .unwrap();
        // ONSET_LOCK: the plant's angle (the continuous ramp) kept alongside, and at each of its
        // revolutions the twin's angle shifted onto it, as the keyphasor lock does
        let rpm_true = if t < t_pre {
            pre
        } else if t < t_hold {
            8000.0
        } else {
            8000.0 + rate * (t + 0.5 * h - t_hold)
        };
        plant_angle += h * rpm_true * PI / 30.0;
        if lock && (plant_angle / std::f64::consts::TAU).floor() > plant_revs {
            plant_revs = (plant_angle / std::f64::consts::TAU).floor();
            let d = plant_angle - twin.output().angle_rad;
            twin.shift_angle(d);
            largest_shift = largest_shift.max(d.abs());
        }
        if let Some(r) = monitor.record(&twin) {
            let a = r
                .bearings
                .iter()
                .map(|b| b.subsync_amplitude_m)
                .fold(0.0, f64::max);
            let counts = r
                .bearings
                .iter()
                .any(|b| cls.subsync_counts(b.subsync_amplitude_m, b.one_x_amplitude_m, c));
            per_rev.push((r.speed_rad_s * 30.0 / PI, a, counts));
        }
    }
    let label = format!(
        "switch {apply} unb {unb} visc {vis} rate {rate} hold {hold_revs} blend {blend_revs} pre {pre} stair {stair} lock {lock}"
    );
    for k in (0..per_rev.len()).step_by(16) {
        println!(
            "TRACE {label} | rev {k} {:.0} rpm: subsync {:.4} µm, counts {}",
            per_rev[k].0,
            per_rev[k].1 * 1e6,
            per_rev[k].2
        );
    }
    let onset = (0..per_rev.len())
        .find(|&k| k + 24 <= per_rev.len() && per_rev[k..k + 24].iter().all(|p| p.2));
    println!("largest angle correction {largest_shift:.2e} rad");
    println!(
        "RESULT {label}: onset {:?} rpm, by the replay's rule {:?}",
        onset.map(|k| per_rev[k].0.round()),
        onset_by_rule(&per_rev).map(f64::round)
    );
}
