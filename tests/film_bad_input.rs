//! Bad input gets a clear error naming the parameter; nothing panics; nothing NaN comes out.

mod common;
use common::*;
use rotor_twin::film::{
    equilibrium_at_eccentricity, equilibrium_under_load, BearingGeometry, FilmError, FilmGrid,
    FilmModel, FiniteFilm, JournalKinematics, Lubricant, ShortFilm,
};

fn names(e: FilmError, word: &str) {
    let text = e.to_string();
    assert!(text.contains(word), "error '{text}' does not name '{word}'");
}

#[test]
fn non_positive_or_non_finite_dimensions_are_named() {
    names(
        BearingGeometry::plain(-0.06, 0.03, 40e-6).unwrap_err(),
        "diameter",
    );
    names(
        BearingGeometry::plain(0.06, 0.0, 40e-6).unwrap_err(),
        "length",
    );
    names(
        BearingGeometry::plain(0.06, 0.03, f64::NAN).unwrap_err(),
        "clearance",
    );
    names(
        BearingGeometry::plain(0.06, 0.03, 0.01).unwrap_err(),
        "clearance",
    );
    names(Lubricant::new(900.0, -1e-3).unwrap_err(), "viscosity");
    names(Lubricant::new(f64::INFINITY, 1e-3).unwrap_err(), "density");
    names(
        BearingGeometry::two_axial_grooves(0.06, 0.03, 40e-6, -0.1, 0.0).unwrap_err(),
        "groove",
    );
    names(
        BearingGeometry::two_axial_grooves(0.06, 0.03, 40e-6, 0.3, f64::NAN).unwrap_err(),
        "supply pressure",
    );
}

#[test]
fn absurd_grids_are_refused() {
    names(FilmGrid::new(3, 10).unwrap_err(), "circumference");
    names(FilmGrid::new(60, 100_000).unwrap_err(), "half length");
    names(FilmGrid::new(60, 0).unwrap_err(), "half length");
    assert!(FilmGrid::parse("60by10").unwrap_err().contains("NTHxNZ"));
    assert!(FilmGrid::parse("60x-1").unwrap_err().contains("-1"));
    assert!(FilmGrid::parse("60x10").is_ok());
}

#[test]
fn journal_states_outside_the_film_or_not_finite_are_named() {
    let mut finite = FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::DEFAULT).unwrap();
    let mut short = ShortFilm::new(seed_bearing(0.5), mdm()).unwrap();
    let w = OMEGA_9000_RPM;
    for model in [&mut finite as &mut dyn FilmModel, &mut short] {
        let outside = JournalKinematics::at_position([40e-6, 0.0], w);
        assert!(matches!(
            model.solve(&outside),
            Err(FilmError::JournalOutsideFilm { .. })
        ));
        let beyond = JournalKinematics::at_position([30e-6, 30e-6], w);
        assert!(matches!(
            model.solve(&beyond),
            Err(FilmError::JournalOutsideFilm { .. })
        ));
        let mut nan_velocity = JournalKinematics::at_position([10e-6, 0.0], w);
        nan_velocity.velocity_m_s[1] = f64::NAN;
        names(model.solve(&nan_velocity).unwrap_err(), "velocity y");
        let inf_speed = JournalKinematics::at_position([10e-6, 0.0], f64::INFINITY);
        names(model.solve(&inf_speed).unwrap_err(), "speed");
        names(
            equilibrium_under_load(model, 0.0008, [275.0, 0.0], 0.0).unwrap_err(),
            "speed",
        );
        names(
            equilibrium_under_load(model, 0.0008, [f64::NAN, 0.0], w).unwrap_err(),
            "load",
        );
        names(
            equilibrium_at_eccentricity(model, 0.0008, 1.0, w).unwrap_err(),
            "eccentricity",
        );
        names(
            equilibrium_at_eccentricity(model, 0.0008, -0.2, w).unwrap_err(),
            "eccentricity",
        );
    }
}

/// Property: over many journal states (seeded, positions up to ε = 0.995, squeeze velocities up to
/// 2 c ω, either direction of rotation, at rest), every output is finite.
#[test]
fn no_nan_ever_comes_out() {
    let mut finite = FiniteFilm::new(seed_bearing(0.5), mdm(), FilmGrid::DEFAULT).unwrap();
    let mut short = ShortFilm::new(seed_bearing(0.5), mdm()).unwrap();
    let c = 40e-6;
    let mut seed = 0x2545F4914F6CDD1Du64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for n in 0..400 {
        let eps = 0.995 * rnd().sqrt();
        let a = std::f64::consts::TAU * rnd();
        let w = match n % 4 {
            0 => 0.0,
            1 => -OMEGA_9000_RPM,
            _ => OMEGA_9000_RPM * 2.0 * rnd(),
        };
        let v = 2.0 * c * OMEGA_9000_RPM;
        let kin = JournalKinematics {
            position_m: [eps * c * a.cos(), eps * c * a.sin()],
            velocity_m_s: [v * (2.0 * rnd() - 1.0), v * (2.0 * rnd() - 1.0)],
            speed_rad_s: w,
        };
        for model in [&mut finite as &mut dyn FilmModel, &mut short] {
            let (r, k) = model.solve_with_coefficients(&kin).unwrap();
            let values = [
                r.force_n[0],
                r.force_n[1],
                r.max_pressure_pa,
                r.max_pressure_angle_rad,
                r.film_start_rad,
                r.film_end_rad,
                r.friction_torque_n_m,
                r.power_loss_w,
                r.side_flow_m3_s,
                r.inflow_m3_s,
            ];
            assert!(values.iter().all(|v| v.is_finite()), "state {n}: {r:?}");
            assert!(k.is_finite(), "state {n}: {k:?}");
            assert!(r.max_pressure_pa >= 0.0);
        }
    }
}
