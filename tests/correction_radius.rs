//! The balancing correction mass of each unbalance plane at the plane's own radius
//! (`unbalance[i].correction_radius_m` in the machine file; 100 mm when absent).

use rotor_twin::calibrate::{estimate_unbalance, OneXVector};
use rotor_twin::rotor::{
    influence_coefficients, static_solution, MachineDescription, Rotor, DEFAULT_MACHINE_YAML,
};

fn rotor(entry: &str) -> Result<Rotor, String> {
    let yaml = DEFAULT_MACHINE_YAML.replace(
        "  - {node: 15, magnitude_g_mm: 140.0, phase_deg: 0.0}\n",
        &format!("{entry}\n"),
    );
    MachineDescription::from_yaml(&yaml, "radius")
        .map(|d| Rotor::from_description(&d))
        .map_err(|e| e.to_string())
}

/// Reference: the definition of the correction, m_c r_c = m e (same m·e, opposite angle). Two
/// planes, 200 g·mm at 30° (radius 50 mm given) and 90 g·mm at 250° (no radius: 100 mm),
/// measured as the twin's own linear 1X response at 6,000 and 8,000 rpm (exact vectors): the
/// masses must be 4.0 g and 0.9 g, at 210° and 70°.
#[test]
fn each_plane_takes_its_own_correction_radius() {
    let r = rotor(
        "  - {node: 15, magnitude_g_mm: 200.0, phase_deg: 30.0, correction_radius_m: 0.05}\n  - {node: 21, magnitude_g_mm: 90.0, phase_deg: 250.0}",
    )
    .unwrap();
    let st = static_solution(&r).unwrap();
    let truth = [(200e-6, 30f64.to_radians()), (90e-6, 250f64.to_radians())];
    let mut vectors = Vec::new();
    for rpm in [6000.0, 8000.0] {
        let h = influence_coefficients(&r, &st, rpm).unwrap();
        for station in 0..r.probes.len() {
            for axis in 0..2 {
                let x = h
                    .iter()
                    .zip(&truth)
                    .fold([0.0, 0.0], |acc, (hp, &(me, ph))| {
                        let c = hp[station][axis] * faer::c64::new(me * ph.cos(), me * ph.sin());
                        [acc[0] + c.re, acc[1] + c.im]
                    });
                let w = rpm * std::f64::consts::PI / 30.0;
                vectors.push(OneXVector::from_complex(station, axis, w, x));
            }
        }
    }
    let est = estimate_unbalance(&r, &vectors, 0.1).unwrap();
    let [a, b] = [&est.planes[0], &est.planes[1]];
    println!("{a:?}\n{b:?}");
    assert_eq!((a.correction.radius_m, b.correction.radius_m), (0.05, 0.1));
    assert!(
        (a.correction.mass_g - 4.0).abs() < 1e-6,
        "{}",
        a.correction.mass_g
    );
    assert!(
        (b.correction.mass_g - 0.9).abs() < 1e-6,
        "{}",
        b.correction.mass_g
    );
    assert!((a.correction.angle_deg - 210.0).abs() < 1e-6);
    assert!((b.correction.angle_deg - 70.0).abs() < 1e-6);
}

#[test]
fn a_bad_correction_radius_is_refused_naming_the_field() {
    for bad in ["0.0", "-0.1", "25.0"] {
        let err = rotor(&format!(
            "  - {{node: 15, magnitude_g_mm: 140.0, correction_radius_m: {bad}}}"
        ))
        .unwrap_err();
        assert!(err.contains("unbalance[0].correction_radius_m"), "{err}");
    }
}
