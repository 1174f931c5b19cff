//! The seed's two readings with the film's own inertia (issue 11; README "Two readings of the
//! seed"): (A) the Ø55 rotor of config/orc_microturbine_100kw_d55.yaml (a threshold crossing; the
//! built-in default until session 15) and (B) the Ø63, 56 kg rotor of
//! config/orc_microturbine_100kw.yaml, the built-in default since session 15 (linear-stable,
//! whipping in a half-speed window without film inertia). With `fluid_inertia: full` (Re* = 1.7 at 9,000 rpm; eq. I1 of
//! `src/film/inertia.rs`) the two trade places at the seed's 9,000 rpm: (A) whips from a quiet
//! start, later, and (B) settles.

use rotor_twin::dynamics::{Coupling, FilmEvaluation};
use rotor_twin::film::FluidInertia;
use rotor_twin::monitor::{RevolutionReport, RotorState};
use rotor_twin::rotor::{MachineDescription, Rotor};
use rotor_twin::transient::{run_transient, TransientResult, TransientSpec};

mod common;

fn rotor(config: Option<&str>, inertia: FluidInertia) -> Rotor {
    let desc = MachineDescription::load(config.map(std::path::Path::new)).unwrap();
    let mut r = Rotor::from_description(&desc);
    r.set_fluid_inertia(inertia);
    r
}

/// 9,000 rpm from the quiet start (static equilibrium, the machine's 140 g·mm unbalance),
/// nonlinear coupling on the tabulated film at 64 steps a revolution (both checked against the
/// direct film at 128 in the README: "The seed's case", "The convective inertia").
fn at_9000(rotor: &Rotor, revolutions: usize) -> TransientResult {
    rotor_twin::film::set_disk_cache(Some(rotor_twin::film::TableCache::new(
        common::test_cache_dir(),
    )));
    let spec = TransientSpec {
        speed_rpm: 9000.0,
        revolutions,
        coupling: Coupling::Nonlinear,
        steps_per_rev: 64,
        grid: None,
        film: FilmEvaluation::Table,
    };
    run_transient(rotor, &spec).unwrap()
}

/// The larger sub-synchronous amplitude of the two bearings in one revolution (m).
fn subsync(rev: &RevolutionReport) -> f64 {
    rev.bearings
        .iter()
        .map(|b| b.subsync_amplitude_m)
        .fold(0.0, f64::max)
}

/// Least-squares slope of ln(sub-synchronous amplitude) over revolutions `from..to` (1/rev).
fn subsync_growth(run: &TransientResult, from: usize, to: usize) -> f64 {
    let pts: Vec<(f64, f64)> = run.history[from..to]
        .iter()
        .map(|r| (r.revolution as f64, subsync(r).ln()))
        .collect();
    let m = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / m;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / m;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    sxy / sxx
}

/// The decisive fact of the 2 × 2 count (README "Two readings of the seed"), 9,000 rpm, `full`:
/// * (A) Ø55: the sub-synchronous motion grows from the quiet start at +0.00384/rev (fit over
///   revolutions 100–500; measured 0.00384 on both bearings at 64 steps, 0.00385–0.00395 at 128
///   in the README; the linear rate about the static equilibrium, zone following, is 0.0047
///   without unbalance): asserted within 10 %. It passes 10 µm at revolution 1,143 (the onset
///   follows ln(10 µm / 0.08 µm) / growth, so 10 % on the rate is 10 % here) and is a `whip`
///   above 30 µm by revolution 1,250 (measured 39.7 µm; at 0.500X).
/// * (B) Ø63, 56 kg: the sub-synchronous motion decays, −0.0208/rev over revolutions 100–300
///   (both bearings), asserted within 10 %, and the rotor is `stable` at revolution 400 with
///   less than 0.01 µm of it (measured 4.5·10⁻⁵ µm).
/// * Control: (B) without film inertia, the same run, is a `whip` above 30 µm by revolution 400
///   (measured 31.3 / 32.1 µm, `whip` from revolution 315): the film's inertia is what removes
///   it, so the test fails if `full` does nothing.
#[test]
fn with_full_film_inertia_the_shipped_rotor_whips_at_9000_and_the_d63_one_settles() {
    let a = at_9000(
        &rotor(
            Some("config/orc_microturbine_100kw_d55.yaml"),
            FluidInertia::Full,
        ),
        1250,
    );
    let d63 = None; // the built-in machine, reading (B)
    let b = at_9000(&rotor(d63, FluidInertia::Full), 400);
    let b_bare = at_9000(&rotor(d63, FluidInertia::None), 400);
    let (ga, gb) = (subsync_growth(&a, 100, 500), subsync_growth(&b, 100, 300));
    let onset = a
        .history
        .iter()
        .find(|r| subsync(r) > 10e-6)
        .map(|r| r.revolution);
    let last = |r: &TransientResult| subsync(r.history.last().unwrap());
    println!(
        "9,000 rpm, full, table 64: (A) growth {ga:+.5}/rev, 10 µm at revolution {onset:?}, end \
         {:?} {:.2} µm; (B) growth {gb:+.5}/rev, end {:?} {:.2e} µm; (B) bare: {:?} {:.2} µm",
        a.report.state,
        last(&a) * 1e6,
        b.report.state,
        last(&b) * 1e6,
        b_bare.report.state,
        last(&b_bare) * 1e6
    );
    assert!((ga / 0.00384 - 1.0).abs() < 0.1, "{ga}");
    let onset = onset.expect("(A) never reached 10 µm") as f64;
    assert!((onset / 1143.0 - 1.0).abs() < 0.1, "{onset}");
    assert_eq!(a.report.state, RotorState::Whip, "{}", a.report.evidence());
    assert!(last(&a) > 30e-6);
    assert!((gb / -0.0208 - 1.0).abs() < 0.1, "{gb}");
    assert_eq!(
        b.report.state,
        RotorState::Stable,
        "{}",
        b.report.evidence()
    );
    assert!(last(&b) < 0.01e-6);
    assert_eq!(b_bare.report.state, RotorState::Whip);
    assert!(last(&b_bare) > 30e-6);
}
