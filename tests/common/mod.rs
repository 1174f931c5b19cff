//! Helpers shared by the integration tests: reference tables and the seed's bearing.
#![allow(dead_code)]

pub mod calibration;
pub mod heating;
pub mod model_loop;
pub mod node;
pub mod onset;

use rotor_twin::film::{
    BearingGeometry, FilmCoefficients, FilmModel, JournalKinematics, Lubricant,
};
use std::f64::consts::PI;
use std::path::PathBuf;
use std::process::Command;

/// Rows of a reference CSV under tests/reference/ (copied from ../shared/reference/), `#`
/// comment lines skipped, header used to name the columns.
pub fn reference_table(name: &str) -> Vec<std::collections::HashMap<String, f64>> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/reference")
        .join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(
                    l.split(',')
                        .map(|v| v.trim().parse::<f64>().expect("number")),
                )
                .collect()
        })
        .collect()
}

/// The seed's bearing: D 60 mm, c 40 µm; `l_over_d` sets the length.
pub fn seed_bearing(l_over_d: f64) -> BearingGeometry {
    BearingGeometry::plain(0.06, 0.06 * l_over_d, 40e-6).unwrap()
}

/// The seed's lubricant (MDM): ρ 900 kg/m³, µ 0.0008 Pa·s.
pub fn mdm() -> Lubricant {
    Lubricant::new(900.0, 0.0008).unwrap()
}

/// 9000 rpm in rad/s.
pub const OMEGA_9000_RPM: f64 = 9000.0 * std::f64::consts::PI / 30.0;

/// Relative difference |a − b| / |b|.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Closed-form dimensionless short-bearing K and B, x along the load, y ahead (Friswell et al.
/// 2010, ch. 5; ../shared/reference/closed_forms.md): the reference formulas of several tests.
pub fn short_bearing_coefficients(e: f64) -> ([[f64; 2]; 2], [[f64; 2]; 2]) {
    let pi2 = PI * PI;
    let q = 1.0 - e * e;
    let s = q.sqrt();
    let h0 = 1.0 / (pi2 * q + 16.0 * e * e).powf(1.5);
    let k = [
        [
            4.0 * h0 * (pi2 * (1.0 + 2.0 * e * e) + 32.0 * e * e * (1.0 + e * e) / q),
            h0 * PI * (pi2 * q * (1.0 + 2.0 * e * e) + 32.0 * e * e * (1.0 + e * e)) / (e * s),
        ],
        [
            -h0 * PI * (pi2 * q * q - 16.0 * e.powi(4)) / (e * s),
            4.0 * h0 * (pi2 * (2.0 - e * e) + 16.0 * e * e),
        ],
    ];
    let bxy = 8.0 * h0 * (pi2 * (1.0 + 2.0 * e * e) - 16.0 * e * e);
    let b = [
        [2.0 * PI * h0 * (pi2 * q * q + 48.0 * e * e) / (e * s), bxy],
        [
            bxy,
            2.0 * PI * h0 * s * (pi2 * (1.0 + 2.0 * e * e) - 16.0 * e * e) / e,
        ],
    ];
    (k, b)
}

/// Runs the rotor-twin binary: (success, stdout, stderr).
pub fn run_cli(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_rotor-twin"))
        .args(args)
        .env("ROTOR_TWIN_CACHE_DIR", test_cache_dir())
        .output()
        .expect("run rotor-twin");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The film-table cache of the CLI runs of the tests: in the build's own temporary directory
/// (never the user's home), shared by the test runs.
pub fn test_cache_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("film-cache")
}

/// Runs `program tests/interop/<script> <args…>`, asserts that it succeeded (its standard
/// error in the message if not) and returns its standard output.
fn run_interop<I, S>(program: &std::ffi::OsStr, script: &str, args: I) -> Vec<u8>
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = Command::new(program)
        .arg(root.join("tests/interop").join(script))
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("{script}: {e}"));
    assert!(
        out.status.success(),
        "{script} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// Runs the venv set-up script `tests/interop/<script>` (it creates the venv on first use) and
/// returns its standard output.
pub fn set_up_venv(script: &str) -> String {
    let out = run_interop("bash".as_ref(), script, [] as [&str; 0]);
    String::from_utf8_lossy(&out).into_owned()
}

/// The interop venv's Python (Cyclone DDS, rosbags, mcap: tests/interop/setup-venv.sh).
pub fn python() -> PathBuf {
    set_up_venv("setup-venv.sh");
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/.venv/bin/python")
}

/// Runs the interop venv's Python on `tests/interop/<script>` with `args` (as
/// [`run_interop`]).
pub fn interop_script<I, S>(script: &str, args: I) -> Vec<u8>
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    run_interop(python().as_os_str(), script, args)
}

/// [`interop_script`]'s output read as JSON.
pub fn interop_json<I, S>(script: &str, args: I) -> serde_json::Value
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let out = interop_script(script, args);
    serde_json::from_slice(&out)
        .unwrap_or_else(|e| panic!("{script}: {e}: '{}'", String::from_utf8_lossy(&out)))
}

/// The eight coefficients by central differences of the film force `solve` (a second method
/// for the perturbation equations, seed eq. 3–4), steps `dq` (m) and `dv` (m/s).
pub fn finite_difference(
    model: &mut dyn FilmModel,
    kin: JournalKinematics,
    dq: f64,
    dv: f64,
) -> FilmCoefficients {
    let mut out = FilmCoefficients::default();
    for j in 0..2 {
        let mut force = |shift: f64, velocity: bool| {
            let mut k = kin;
            if velocity {
                k.velocity_m_s[j] += shift;
            } else {
                k.position_m[j] += shift;
            }
            model.solve(&k).unwrap().force_n
        };
        let (fp, fm) = (force(dq, false), force(-dq, false));
        let (gp, gm) = (force(dv, true), force(-dv, true));
        for i in 0..2 {
            out.stiffness_n_per_m[(i, j)] = -(fp[i] - fm[i]) / (2.0 * dq);
            out.damping_n_s_per_m[(i, j)] = -(gp[i] - gm[i]) / (2.0 * dv);
        }
    }
    out
}

/// The built-in machine and its twin at the rated speed (nonlinear, film table cached in
/// [`test_cache_dir`], 64 steps a revolution) from the static equilibrium, with the step input
/// that holds that speed.
pub fn rated_nonlinear_session() -> (
    rotor_twin::rotor::Rotor,
    rotor_twin::dynamics::TwinConfig,
    rotor_twin::session::Session,
    rotor_twin::dynamics::StepInput,
) {
    use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, TwinConfig};
    use rotor_twin::session::{Session, SessionSettings};
    rotor_twin::film::set_disk_cache(Some(rotor_twin::film::TableCache::new(test_cache_dir())));
    let rotor = rotor_twin::rotor::Rotor::from_description(
        &rotor_twin::rotor::MachineDescription::builtin_default(),
    );
    let w = rotor.rated_speed_rad_s;
    let config = TwinConfig {
        film: FilmEvaluation::Table,
        ..TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, 64)
    };
    let session = Session::new(&rotor, config, w, SessionSettings::default(), 0).unwrap();
    let input = StepInput {
        speed_rad_s: w,
        accel_rad_s2: 0.0,
    };
    (rotor, config, session, input)
}

/// A journal state at eccentricity ratio ε, attitude φ (rad), radial and tangential velocities
/// (fractions of c ω) in a clearance `c` (m), turning at `w` (rad/s).
pub fn journal_state(c: f64, w: f64, eps: f64, phi: f64, vr: f64, vt: f64) -> JournalKinematics {
    let (vr, vt) = (vr * c * w, vt * c * w);
    JournalKinematics {
        position_m: [eps * c * phi.cos(), eps * c * phi.sin()],
        velocity_m_s: [
            vr * phi.cos() - vt * phi.sin(),
            vr * phi.sin() + vt * phi.cos(),
        ],
        speed_rad_s: w,
    }
}

/// The largest difference between two sets of eight coefficients, over the coefficient scale
/// of `reference`: max over the 8 entries of |k|, |c ω| (N/m). The scale is the state's own
/// (so the wall's stiff film and the centre's soft one are each measured against themselves)
/// and finite everywhere, also at ε = 0, where the centred journal's direct stiffnesses vanish
/// but its cross-coupled stiffness ±c_d ω/2 and direct damping c_d do not; an entry's own
/// magnitude would not do, as entries pass through zero.
pub fn coefficient_error(
    reference: &FilmCoefficients,
    other: &FilmCoefficients,
    omega: f64,
) -> f64 {
    let (mut scale, mut e) = (0.0_f64, 0.0_f64);
    for i in 0..2 {
        for j in 0..2 {
            let (ka, kb) = (
                reference.stiffness_n_per_m[(i, j)],
                other.stiffness_n_per_m[(i, j)],
            );
            let (ca, cb) = (
                reference.damping_n_s_per_m[(i, j)] * omega,
                other.damping_n_s_per_m[(i, j)] * omega,
            );
            scale = scale.max(ka.abs()).max(ca.abs());
            e = e.max((ka - kb).abs()).max((ca - cb).abs());
        }
    }
    e / scale
}

/// The ε bands of the film table's study and accuracy tests (laminar and turbulent): the centre,
/// the small orbits, the static equilibria, the whip's approach and the wall.
pub const ECC_BANDS: [(f64, f64); 8] = [
    (0.0, 0.03),
    (0.03, 0.3),
    (0.3, 0.5),
    (0.5, 0.8),
    (0.8, 0.9),
    (0.9, 0.95),
    (0.95, 0.98),
    (0.98, 0.995),
];

/// A journal whirling forward at half the shaft speed `w` (rad/s) on a circle of 0.3 c about
/// ε 0.5 (c = `clearance_m`), at time `t_s`: the mass-conserving film tests' orbit.
pub fn half_speed_whirl(clearance_m: f64, w: f64, t_s: f64) -> JournalKinematics {
    let c = clearance_m;
    let (s, k) = (0.5 * w * t_s).sin_cos();
    JournalKinematics {
        position_m: [c * (0.5 + 0.3 * k), c * 0.3 * s],
        velocity_m_s: [-c * 0.3 * 0.5 * w * s, c * 0.3 * 0.5 * w * k],
        speed_rad_s: w,
    }
}
