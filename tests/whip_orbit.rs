//! In whip a one-revolution orbit is half a whirl loop; the Orbit message holds whole whirl
//! periods when a sub-synchronous component is present (`session::orbit_revolutions`: the
//! whole number of revolutions nearest 1/ratio, at most 4), one revolution otherwise.
//! Reference: kinematics of a circular whirl at order r: after n revolutions its phase has
//! advanced 2π·n·r, so the gap between the orbit's first and last point is |sin(π·n·r)| of the
//! whirl's diameter: ≈1 after one revolution at 0.5X, ≈0 after two.

mod common;

use rotor_twin::messages::Orbit;
use rotor_twin::session::{orbit_revolutions, Outgoing};

/// The gap between the first and last point of `x`, `y` over the largest extent.
fn closure_gap(x: &[f64], y: &[f64]) -> f64 {
    let extent = |v: &[f64]| {
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    let d = extent(x).max(extent(y));
    let n = x.len() - 1;
    (x[n] - x[0]).hypot(y[n] - y[0]) / d
}

#[test]
fn rule_is_one_revolution_or_whole_whirl_periods() {
    assert_eq!(orbit_revolutions(0.0), 1, "no sub-synchronous component");
    assert_eq!(orbit_revolutions(0.48), 2);
    assert_eq!(orbit_revolutions(0.5), 2);
    assert_eq!(orbit_revolutions(0.33), 3);
    assert_eq!(orbit_revolutions(0.1), 4, "capped");
    assert_eq!(orbit_revolutions(f64::NAN), 1);
}

/// The built-in machine at its rated 9,000 rpm whips (threshold 8,471 rpm). Once the monitor
/// reports the sub-synchronous order r, every Orbit holds orbit_revolutions(r) revolutions (64
/// steps, 64 samples each). After 400 such orbits (the whip grown, the 1X part small beside it)
/// the last orbit closes as a whirl of order r does: its first-to-last gap within 0.2 of
/// |sin(π·n·r)| of its extent, its first revolution alone within 0.2 of |sin(π·r)|, and the
/// whole orbit's gap under half the single revolution's (the 1X part and the growth of the
/// whirl account for the tolerance).
#[test]
fn a_whip_orbit_holds_whole_whirl_loops() {
    let (_, config, mut session, input) = common::rated_nonlinear_session();
    let mut whirl: Vec<Orbit> = Vec::new();
    let mut single: Vec<usize> = Vec::new();
    let steps = (8.0 / config.time_step_s).round() as usize;
    for _ in 0..steps {
        session
            .step(&input, &mut |o| {
                if let Outgoing::Orbit(m) = o {
                    if m.subsync_ratio > 0.0 {
                        whirl.push(m);
                    } else {
                        single.push(m.x.len());
                    }
                }
            })
            .unwrap();
        if whirl.len() >= 400 {
            break;
        }
    }
    // samples of one revolution (the monitor stores both ends of a revolution)
    let per_rev = single[single.len() - 1];
    assert!(
        (64..=65).contains(&per_rev),
        "{per_rev} samples a revolution"
    );
    let settled = &single[single.len().saturating_sub(10)..];
    assert!(
        settled.iter().all(|&l| l == per_rev),
        "one revolution without a whirl"
    );
    assert!(whirl.len() >= 400, "whirl found in {} orbits", whirl.len());
    let last = &whirl[whirl.len() - 1];
    let (r, n) = (last.subsync_ratio, orbit_revolutions(last.subsync_ratio));
    println!(
        "whirl order {r:.3}, {n} revolutions, {} samples",
        last.x.len()
    );
    assert_eq!(n, 2, "oil whip near 0.5X");
    for m in &whirl {
        let n = orbit_revolutions(m.subsync_ratio);
        assert!(
            m.x.len().abs_diff(n * per_rev) <= n,
            "{} for {n} revolutions",
            m.x.len()
        );
        assert_eq!(m.y.len(), m.x.len());
    }
    let pi = std::f64::consts::PI;
    let whole = closure_gap(&last.x, &last.y);
    let half = closure_gap(&last.x[..per_rev], &last.y[..per_rev]);
    println!("gap after {n} revolutions {whole:.3}, after one {half:.3}");
    assert!(
        (whole - (pi * n as f64 * r).sin().abs()).abs() < 0.2,
        "{whole}"
    );
    assert!((half - (pi * r).sin().abs()).abs() < 0.2, "{half}");
    assert!(whole < 0.5 * half, "{whole} {half}");
}
