//! The twin and the synthetic plant of the calibration tests (tests/calibrate.rs,
//! tests/live_calibration.rs): the plant differs from the twin in its unbalance (doubled, 280
//! instead of 140 g·mm, in another plane, stage 7 at node 21, at 120°), its oil (10 % more
//! viscous) and its films' grid (72 × 12 instead of 60 × 10).

use rotor_twin::rotor::{
    BearingModel, MachineDescription, Rotor, UnbalanceSpec, DEFAULT_MACHINE_YAML,
};

/// The twin's machine: the built-in one with a second (empty) unbalance plane at stage 7.
pub fn twin_rotor() -> Rotor {
    twin_of(MachineDescription::builtin_default())
}

/// Reading (A) of the seed (config/orc_microturbine_100kw_d55.yaml, Ø55; the default until session
/// 15) as [`twin_rotor`] makes it.
pub fn twin_rotor_d55() -> Rotor {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/config/orc_microturbine_100kw_d55.yaml"
    );
    twin_of(MachineDescription::load(Some(std::path::Path::new(path))).unwrap())
}

/// [`twin_rotor`] with raw proximity probes `<station>_x` / `_y` at 45° and 135° (API 670's
/// pair either side of vertical) in V at 7.87 V/mm, DC-coupled about a 1 mm (7.87 V) gap, each
/// with the plant's slow-roll runout vector of `runout_m` (`plant::plant_runout`).
pub fn twin_rotor_with_raw_probes(runout_m: f64) -> Rotor {
    twin_of(builtin_with_raw_probes(runout_m))
}

/// The built-in machine with the raw probes of [`twin_rotor_with_raw_probes`] (the plant's of
/// `synth-bag --raw-probes --runout-um`).
pub fn builtin_with_raw_probes(runout_m: f64) -> MachineDescription {
    let mut yaml = format!("{DEFAULT_MACHINE_YAML}\nproximity_probes:\n");
    for station in ["probe_pulley_end", "probe_outboard"] {
        for (suffix, angle) in [("x", 45.0f64), ("y", 135.0)] {
            let r = rotor_twin::plant::plant_runout(runout_m, angle.to_radians());
            yaml += &format!(
                "  - {{name: {station}_{suffix}, station: {station}, angle_deg: {angle}, unit: V, sensitivity_v_per_m: 7870.0, coupling: dc, reference_gap: 7.87, runout: {{amplitude_m: {}, phase_lag_deg: {}}}}}\n",
                r.amplitude_m, r.phase_lag_deg
            );
        }
    }
    MachineDescription::from_yaml(&yaml, "raw.yaml").expect("a valid machine")
}

fn twin_of(mut d: MachineDescription) -> Rotor {
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
