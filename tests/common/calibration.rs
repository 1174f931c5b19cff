//! The twin and the synthetic plant of the calibration tests (tests/calibrate.rs,
//! tests/live_calibration.rs): the plant differs from the twin in its unbalance (doubled, 280
//! instead of 140 g·mm, in another plane, stage 7 at node 21, at 120°), its oil (10 % more
//! viscous) and its films' grid (72 × 12 instead of 60 × 10).

use rotor_twin::rotor::{BearingModel, MachineDescription, Rotor, UnbalanceSpec};

/// The twin's machine: the built-in one with a second (empty) unbalance plane at stage 7.
pub fn twin_rotor() -> Rotor {
    let mut d = MachineDescription::builtin_default();
    d.unbalance.push(UnbalanceSpec {
        node: 21,
        magnitude_g_mm: 0.0,
        phase_deg: 0.0,
        correction_radius_m: None,
    });
    Rotor::from_description(&d)
}

/// The plant: `twin` with the unbalance, oil and grid above.
pub fn plant_rotor(twin: &Rotor) -> Rotor {
    let mut p = twin.clone();
    p.unbalance[0].magnitude_kg_m = 0.0;
    p.unbalance[1].magnitude_kg_m = 280e-6;
    p.unbalance[1].phase_rad = 120f64.to_radians();
    for b in &mut p.bearings {
        if let BearingModel::Film(f) = &mut b.model {
            f.lubricant.viscosity_pa_s *= 1.10;
            f.grid.n_theta = 72;
            f.grid.n_z = 12;
        }
    }
    p
}
