//! The viscosity–temperature law as a table (issue 12): `viscosity_temperature: {table:
//! {temperatures_c, viscosities_pa_s}}`, a monotone cubic of ln µ against −1/T between points.

mod common;
use common::*;
use rotor_twin::film::{ViscosityLaw, ViscosityTable, WaltherLaw, ZERO_CELSIUS_K};
use rotor_twin::rotor::{MachineDescription, Rotor, DEFAULT_MACHINE_YAML};

fn kelvin(c: f64) -> f64 {
    c + ZERO_CELSIUS_K
}

/// Shell Tellus S2 M 32 (ISO VG 32) as its data sheet gives it: 32 mm²/s at 40 °C, 5.4 mm²/s at
/// 100 °C (Walther / ASTM D341 through both: `film::viscosity`'s unit test checks it against the
/// sheet's 338 mm²/s at 0 °C), at an ASSUMED density of 870 kg/m³ (the sheet's 15 °C figure).
fn tellus_s2_m_32() -> WaltherLaw {
    WaltherLaw::through(
        [(kelvin(40.0), 32.0), (kelvin(100.0), 5.4)],
        870.0,
        [kelvin(-10.0), kelvin(130.0)],
    )
    .unwrap()
}

/// Reference: the Walther law the table samples. Six points of it (0, 20, …, 100 °C) as a
/// table reproduce it at the mid-points (10, 30, 50, 70, 90 °C) and at the quarter points
/// within 0.3 % (measured: 0.18 % at worst, near 5 °C where the curve bends most; piecewise
/// linear ln µ against T between the same points misses by 5.7 %), and at the points themselves
/// to 1e-12.
#[test]
fn a_six_point_table_of_tellus_s2_m_32_reproduces_its_walther_law_between_points() {
    let walther = tellus_s2_m_32();
    let points: Vec<(f64, f64)> = (0..6)
        .map(|i| {
            let t = kelvin(20.0 * i as f64);
            (t, walther.viscosity_pa_s(t))
        })
        .collect();
    let table = ViscosityTable::new(&points, [kelvin(0.0), kelvin(100.0)]).unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..5 {
        for f in [0.25, 0.5, 0.75] {
            let t = kelvin(20.0 * (i as f64 + f));
            let e = rel(table.viscosity_pa_s(t), walther.viscosity_pa_s(t));
            if f == 0.5 {
                println!(
                    "{:.0} °C: table {:.3} mPa·s, Walther {:.3} mPa·s ({:+.3} %)",
                    t - ZERO_CELSIUS_K,
                    table.viscosity_pa_s(t) * 1e3,
                    walther.viscosity_pa_s(t) * 1e3,
                    100.0 * (table.viscosity_pa_s(t) / walther.viscosity_pa_s(t) - 1.0)
                );
            }
            worst = worst.max(e);
        }
    }
    println!("worst between points: {:.3} %", 100.0 * worst);
    assert!(worst < 0.003, "worst {worst}");
    for &(t, mu) in &points {
        assert!(rel(table.viscosity_pa_s(t), mu) < 1e-12);
    }
    // monotone: falls at every 0.1 K over the span
    let mut last = f64::INFINITY;
    for k in 0..=1000 {
        let mu = table.viscosity_pa_s(kelvin(0.1 * k as f64));
        assert!(mu < last, "not falling at {} °C", 0.1 * k as f64);
        last = mu;
    }
    // the law's own range checks apply to the table too
    let law = ViscosityLaw::Table(table);
    assert!(law.checked_viscosity_pa_s(kelvin(101.0)).is_err());
    assert!(law.checked_viscosity_pa_s(f64::NAN).is_err());
}

/// The built-in machine's MDM table (both film bearings carry it), as the machine file writes it.
const MDM_TABLE: &str = "        table: {temperatures_c: [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0, 110.0, 120.0],\n                viscosities_pa_s: [1.16888e-3, 1.02439e-3, 0.903011e-3, 0.800000e-3, 0.712838e-3, 0.639124e-3,\n                                   0.575962e-3, 0.520959e-3, 0.472895e-3, 0.431143e-3, 0.394765e-3, 0.362473e-3]}\n";

/// The built-in machine with the pulley-end bearing's law replaced by `law` (YAML lines of a
/// `viscosity_temperature`, 8 spaces in); the outboard bearing keeps the MDM table (each bearing
/// its own law).
fn with_law(law: &str) -> String {
    assert_eq!(DEFAULT_MACHINE_YAML.matches(MDM_TABLE).count(), 2);
    DEFAULT_MACHINE_YAML.replacen(MDM_TABLE, law, 1)
}

/// The built-in machine, its pulley-end law a table `table`.
fn with_table(table: &str) -> String {
    with_law(&format!("        table: {table}\n"))
}

/// The Walther law of sessions 9–13 (ASTM D341-09 through 0.889 mm²/s at 40 °C and an ASSUMED
/// 0.60 at 80 °C), a law the tests below compare a table of its own points with.
const WALTHER_POINTS: &str =
    "        temperatures_c: [40.0, 80.0]\n        kinematic_viscosities_mm2_s: [0.889, 0.60]\n";

/// Points of that Walther law, µ = ρν with ρ 900, at 10, 40, 70, 100, 120 °C (computed apart
/// in Python).
const BUILTIN_TABLE: &str = "{temperatures_c: [10.0, 40.0, 70.0, 100.0, 120.0], viscosities_pa_s: [1.16895e-3, 0.800068e-3, 0.590453e-3, 0.458492e-3, 0.395957e-3]}";

fn error_of(yaml: &str) -> String {
    MachineDescription::from_yaml(yaml, "machine.yaml")
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_tables_are_refused_naming_the_field_and_the_value() {
    assert!(MachineDescription::from_yaml(&with_table(BUILTIN_TABLE), "table.yaml").is_ok());
    let cases = [
        // a viscosity that rises with the temperature
        (
            "{temperatures_c: [10.0, 40.0, 70.0], viscosities_pa_s: [1.07e-3, 0.80e-3, 0.85e-3]}",
            "table.viscosities_pa_s[2]",
            "0.00085",
        ),
        // temperatures not rising
        (
            "{temperatures_c: [10.0, 40.0, 40.0], viscosities_pa_s: [1.07e-3, 0.80e-3, 0.70e-3]}",
            "table.temperatures_c[2]",
            "40",
        ),
        (
            "{temperatures_c: [10.0, 40.0], viscosities_pa_s: [1.07e-3, 0.80e-3, 0.70e-3]}",
            "table.viscosities_pa_s",
            "3 values for 2 temperatures",
        ),
        (
            "{temperatures_c: [10.0, 40.0, 130.0], viscosities_pa_s: [1.07e-3, -0.80e-3, 0.4e-3]}",
            "table.viscosities_pa_s[1]",
            "-0.0008",
        ),
        (
            "{temperatures_c: [10.0, .nan, 130.0], viscosities_pa_s: [1.07e-3, 0.80e-3, 0.4e-3]}",
            "table.temperatures_c[1]",
            "NaN",
        ),
        // the valid range 10–120 °C reaches beyond the table's 20–120 °C: no extrapolation
        (
            "{temperatures_c: [20.0, 40.0, 120.0], viscosities_pa_s: [0.95e-3, 0.80e-3, 0.43e-3]}",
            "table.(table)",
            "range",
        ),
        // 0.9 mPa·s at the 40 °C design point against the lubricant's 0.8
        (
            "{temperatures_c: [10.0, 40.0, 120.0], viscosities_pa_s: [1.07e-3, 0.90e-3, 0.43e-3]}",
            "table.viscosities_pa_s",
            "0.0009",
        ),
    ];
    for (table, field, value) in cases {
        let e = error_of(&with_table(table));
        println!("{e}");
        assert!(e.contains(field), "{field} not named: {e}");
        assert!(e.contains(value), "{value} not named: {e}");
    }
    // a table and Walther's points together: one or the other
    let both = with_law(&format!("{WALTHER_POINTS}        table: {BUILTIN_TABLE}\n"));
    let e = error_of(&both);
    assert!(e.contains("not both"), "{e}");
}

/// A machine file with a table runs `bearing --speeds` and `modes` with `oil_heating`. The
/// table samples the Walther law of sessions 9–13 (5 points, 10–120 °C), so each T_eff the commands
/// print must equal `Rotor::heat_films` on the Walther machine at the same speed within 0.002 K
/// (measured: 1e-4 K; the table's interpolation error, ≈ 0.1 % in µ between points, moves T_eff
/// by far less).
#[test]
fn a_machine_with_a_table_runs_bearing_and_modes() {
    let heating =
        "      oil_heating: {model: effective_temperature, specific_heat_j_per_kg_k: 1900.0}\n";
    let range = "        valid_range_c: [10.0, 120.0]\n";
    let heated = |yaml: &str| yaml.replace(range, &format!("{range}{heating}"));
    let walther_t_eff = |rpm: f64| {
        let desc = MachineDescription::from_yaml(&heated(&with_law(WALTHER_POINTS)), "w").unwrap();
        let mut rotor = Rotor::from_description(&desc);
        let temps = rotor.heat_films(None, rpm * std::f64::consts::PI / 30.0, 1.0);
        temps.unwrap()[0].effective.effective_temperature_k - ZERO_CELSIUS_K
    };
    let path = std::env::temp_dir().join(format!("viscosity_table_{}.yaml", std::process::id()));
    std::fs::write(&path, heated(&with_table(BUILTIN_TABLE))).unwrap();
    let p = path.to_str().unwrap();
    let json = |args: &[&str]| -> serde_json::Value {
        let (ok, out, err) = run_cli(args);
        assert!(ok, "{args:?} failed: {err}");
        serde_json::from_str(&out).unwrap()
    };
    let b = json(&[
        "bearing",
        "--config",
        p,
        "--bearing",
        "bearing_pulley_end",
        "--speeds",
        "9000:9000:1",
        "--json",
    ]);
    let m = json(&["modes", "--config", p, "--json"]);
    let _ = std::fs::remove_file(&path);
    let t_bearing = b["speeds"][0]["effective_temperature_c"].as_f64().unwrap();
    let row = &m["effective_temperatures"][0];
    let (t_modes, at_rpm) = (
        row["effective_temperature_c"].as_f64().unwrap(),
        row["at_speed_rpm"].as_f64().unwrap(),
    );
    for (what, rpm, t) in [
        ("bearing --speeds", 9000.0, t_bearing),
        ("modes", at_rpm, t_modes),
    ] {
        let reference = walther_t_eff(rpm);
        println!("{what}, table, {rpm:.0} rpm: T_eff {t:.4} °C; Walther law {reference:.4} °C");
        assert!((t - reference).abs() < 0.002, "{what}: {t} vs {reference}");
    }
}

/// The built-in machine's law is MDM's curve (issue 12: "for the microturbine's MDM a fit to
/// published data, cited"). Reference: tests/reference/mdm_viscosity.csv, MDM's dynamic
/// viscosity from REFPROP 10 (NIST; Huber, NISTIR 8209, 2018) through the `thermo` library's
/// REFPROP fit, written by tests/reference/mdm_viscosity.py at 10–120 °C (every 10 K and 25 °C,
/// a point between the table's). The machine file scales it to the seed's 0.8 mPa·s at 40 °C, so
/// the law's µ(T)/µ(40 °C) must be MDM's µ(T)/µ(40 °C): within 0.1 % at the table's own points
/// (its 6-digit rounding) and 0.2 % at 25 °C (the interpolation; measured: 0.005 %). The law of
/// sessions 9–13 (Walther through an ASSUMED 0.60 mm²/s at 80 °C) missed by 9 % at 120 °C.
#[test]
fn the_built_in_law_is_mdms_curve_at_the_seeds_level() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/reference/mdm_viscosity.csv"),
    )
    .unwrap();
    let mdm: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("temperature"))
        .map(|l| {
            let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            (f[0], f[1])
        })
        .collect();
    assert_eq!(mdm.len(), 13);
    let mu40 = mdm.iter().find(|(t, _)| *t == 40.0).unwrap().1;
    let desc = MachineDescription::from_yaml(DEFAULT_MACHINE_YAML, "built-in").unwrap();
    let rotor = Rotor::from_description(&desc);
    for site in &rotor.bearings {
        let rotor_twin::rotor::BearingModel::Film(film) = &site.model else {
            continue;
        };
        let law = film.viscosity_law.as_ref().unwrap();
        let law40 = law.viscosity_pa_s(kelvin(40.0));
        assert!(rel(law40, 0.8e-3) < 1e-12, "{law40}");
        for &(t, mu) in &mdm {
            let e = law.viscosity_pa_s(kelvin(t)) / law40 / (mu / mu40) - 1.0;
            println!("{t:5.0} °C: law/MDM − 1 = {:+.4} %", 100.0 * e);
            let tolerance = if t == 25.0 { 2e-3 } else { 1e-3 };
            assert!(e.abs() < tolerance, "{t} °C: {e}");
        }
    }
}
