//! The twin core's contract: explicit state, checkpoints that replay exactly, bad input refused
//! with the state untouched, and a rigid rotor that settles where the film model alone puts it.

use rotor_twin::dynamics::{Coupling, StepInput, Twin, TwinConfig, TwinError};
use rotor_twin::film::equilibrium_under_load;
use rotor_twin::rotor::{static_solution, BearingModel, MachineDescription, Rotor};

fn orc() -> Rotor {
    Rotor::from_description(&MachineDescription::builtin_default())
}

fn omega(rpm: f64) -> f64 {
    rpm * std::f64::consts::PI / 30.0
}

#[test]
fn checkpoint_restore_replays_exactly() {
    let rotor = orc();
    let w = omega(8500.0);
    let mut twin = Twin::new(
        &rotor,
        TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, 128),
        w,
    )
    .unwrap();
    let input = StepInput {
        speed_rad_s: w,
        accel_rad_s2: 0.0,
    };
    for _ in 0..50 {
        twin.step(&input).unwrap();
    }
    let cp = twin.checkpoint();
    let first: Vec<_> = (0..100)
        .map(|_| twin.step(&input).unwrap().bearings.clone())
        .collect();
    twin.restore(&cp);
    let second: Vec<_> = (0..100)
        .map(|_| twin.step(&input).unwrap().bearings.clone())
        .collect();
    assert_eq!(first, second);
}

#[test]
fn bad_input_is_refused_and_the_state_is_untouched() {
    let rotor = orc();
    let w = omega(8000.0);
    let mut twin = Twin::new(
        &rotor,
        TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, 128),
        w,
    )
    .unwrap();
    twin.step(&StepInput {
        speed_rad_s: w,
        accel_rad_s2: 0.0,
    })
    .unwrap();
    let before = twin.state_vectors().0.to_vec();
    let t = twin.time_s();
    for bad in [f64::NAN, f64::INFINITY, -w, 0.0, 100.0 * w] {
        let e = twin
            .step(&StepInput {
                speed_rad_s: bad,
                accel_rad_s2: 0.0,
            })
            .unwrap_err();
        assert!(
            matches!(
                e,
                TwinError::InvalidInput {
                    name: "speed (rad/s)",
                    ..
                }
            ),
            "{e}"
        );
    }
    assert!(twin
        .step(&StepInput {
            speed_rad_s: w,
            accel_rad_s2: f64::NAN
        })
        .is_err());
    assert!(twin.set_unbalance(0, f64::NAN, 0.0).is_err());
    assert!(twin.set_unbalance(0, 5.0, 0.0).is_err());
    assert!(twin.set_unbalance(7, 1e-4, 0.0).is_err());
    assert!(twin.set_external_force(3, [f64::INFINITY, 0.0]).is_err());
    let nan_state = vec![f64::NAN; before.len()];
    assert!(twin
        .set_state_vectors(&nan_state, &before, &before)
        .is_err());
    assert_eq!(twin.state_vectors().0, &before[..]);
    assert_eq!(twin.time_s(), t);
    let bad_config = TwinConfig {
        time_step_s: -1.0,
        ..TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, 128)
    };
    assert!(Twin::new(&rotor, bad_config, w).is_err());
    let bad_delta = TwinConfig::with_steps_per_rev(Coupling::Prehistory { delta: 0.0 }, w, 128);
    assert!(Twin::new(&rotor, bad_delta, w).is_err());
}

/// A rigid rotor below its threshold with the unbalance off, started 15 % of the clearance away
/// from equilibrium, settles where the film model alone puts each journal: the static
/// equilibrium under its share of the weight (statically determinate: the shaft's two bearings
/// share it by the lever rule), within 0.1 % of the clearance.
#[test]
fn rigid_rotor_settles_at_the_film_equilibrium() {
    let yaml = r#"
name: rigid rotor on two film bearings
rated_speed_rpm: 6000
materials: {rigid: {youngs_modulus_pa: 2.1e14, poisson_ratio: 0.3, density_kg_m3: 1.0}}
shaft: [{length_m: 0.4, outer_diameter_m: 0.1, material: rigid, elements: 4}]
discs: [{node: 2, mass_kg: 40.0, polar_inertia_kg_m2: 0.05, diametral_inertia_kg_m2: 0.1}]
bearings:
  - {name: left, node: 0, model: finite, diameter_m: 0.05, length_m: 0.025, radial_clearance_m: 50.0e-6,
     lubricant: {density_kg_m3: 870, viscosity_pa_s: 0.01}, grid: 48x8}
  - {name: right, node: 4, model: finite, diameter_m: 0.05, length_m: 0.025, radial_clearance_m: 50.0e-6,
     lubricant: {density_kg_m3: 870, viscosity_pa_s: 0.01}, grid: 48x8}
"#;
    let rotor = Rotor::from_description(&MachineDescription::from_yaml(yaml, "test").unwrap());
    let w = omega(3000.0);
    let mut twin = Twin::new(
        &rotor,
        TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w, 64),
        w,
    )
    .unwrap();
    let c = 50e-6;
    // push the whole rotor 15 % of the clearance sideways
    let (q, qd, qdd) = twin.state_vectors();
    let mut q = q.to_vec();
    for node in 0..5 {
        q[4 * node] += 0.15 * c;
    }
    let (qd, qdd) = (qd.to_vec(), qdd.to_vec());
    twin.set_state_vectors(&q, &qd, &qdd).unwrap();
    let input = StepInput {
        speed_rad_s: w,
        accel_rad_s2: 0.0,
    };
    for _ in 0..64 * 150 {
        twin.step(&input).unwrap();
    }
    let loads = static_solution(&rotor).unwrap().bearing_loads_n;
    for (k, b) in rotor.bearings.iter().enumerate() {
        let BearingModel::Film(f) = &b.model else {
            unreachable!()
        };
        let mut film = f.solver();
        let eq = equilibrium_under_load(film.as_mut(), 0.01, loads[k], w).unwrap();
        let got = twin.output().bearings[k].position_m;
        let miss = (got[0] - eq.position_m[0]).hypot(got[1] - eq.position_m[1]) / c;
        println!(
            "{}: twin ({:.3}, {:.3}) µm, film equilibrium ({:.3}, {:.3}) µm, miss {miss:.2e} c",
            b.name,
            got[0] * 1e6,
            got[1] * 1e6,
            eq.position_m[0] * 1e6,
            eq.position_m[1] * 1e6
        );
        assert!(miss < 1e-3);
    }
}

/// A run-up: the speed follows the input, the rotor angle is the trapezoidal integral of the
/// speed, the gyroscopic part is refactored as the speed moves, and nothing non-finite appears.
#[test]
fn run_up_tracks_speed_and_angle() {
    let rotor = orc();
    let (w0, w1) = (omega(3000.0), omega(4500.0));
    let mut twin = Twin::new(
        &rotor,
        TwinConfig::with_steps_per_rev(Coupling::Nonlinear, w1, 128),
        w0,
    )
    .unwrap();
    let h = twin.config().time_step_s;
    let steps = 4000;
    let accel = (w1 - w0) / (steps as f64 * h);
    let mut angle = 0.0;
    let mut previous = w0;
    for k in 1..=steps {
        let w = w0 + (w1 - w0) * k as f64 / steps as f64;
        let out = twin
            .step(&StepInput {
                speed_rad_s: w,
                accel_rad_s2: accel,
            })
            .unwrap();
        angle += 0.5 * h * (previous + w);
        previous = w;
        assert!((out.speed_rad_s - w).abs() < 1e-12 * w);
        assert!(out.bearings.iter().all(|b| b
            .position_m
            .iter()
            .chain(&b.force_n)
            .all(|v| v.is_finite())));
    }
    assert!((twin.output().angle_rad - angle).abs() < 1e-9 * angle);
    assert!((twin.time_s() - steps as f64 * h).abs() < 1e-12);
}

/// The unbalance force is the d'Alembert force −m r̈ of the mass point r = e (cos ψ, sin ψ) on
/// a rotor that accelerates, ψ(t) = ψ0 + ω0 t + ½ α t²: checked against r̈ by central
/// differences of the position (an independent computation, kinematics only), tangential part
/// included. The tangential part had the wrong sign (it pushed the shaft forwards).
#[test]
fn unbalance_force_is_minus_m_times_the_acceleration_of_the_mass() {
    use rotor_twin::rotor::unbalance_force;
    let (me, psi0, w0, alpha) = (140e-6, 0.7, 900.0, 2.0e4);
    let psi = |t: f64| psi0 + w0 * t + 0.5 * alpha * t * t;
    let r = |t: f64| [me * psi(t).cos(), me * psi(t).sin()];
    let dt = 1e-6;
    let (a, b, c) = (r(-dt), r(0.0), r(dt));
    let accel = [
        (a[0] - 2.0 * b[0] + c[0]) / (dt * dt),
        (a[1] - 2.0 * b[1] + c[1]) / (dt * dt),
    ];
    let f = unbalance_force(me, psi0, w0, alpha);
    let scale = me * w0 * w0;
    for i in 0..2 {
        assert!(
            (f[i] + accel[i]).abs() < 1e-5 * scale,
            "component {i}: {} vs −m r̈ {}",
            f[i],
            -accel[i]
        );
    }
    // and against the analytic second derivative of r: r̈ = e [−ω² cos ψ − α sin ψ,
    // −ω² sin ψ + α cos ψ], so −m r̈ = m e (ω² cos ψ + α sin ψ, ω² sin ψ − α cos ψ)
    let exact = [
        me * (w0 * w0 * psi0.cos() + alpha * psi0.sin()),
        me * (w0 * w0 * psi0.sin() - alpha * psi0.cos()),
    ];
    for i in 0..2 {
        assert!(
            (f[i] - exact[i]).abs() < 1e-12 * scale,
            "{i}: {} vs {}",
            f[i],
            exact[i]
        );
    }
    // the tangential part alone: m e α against the rotation (ψ̂ = (−sin ψ, cos ψ))
    let tangential = unbalance_force(me, psi0, 0.0, alpha);
    let along = -tangential[0] * psi0.sin() + tangential[1] * psi0.cos();
    assert!((along + me * alpha).abs() < 1e-12, "{along}");
}
