//! The guide's rule "the time step allocates nothing", checked with a counting allocator: after
//! the twin is built, a thousand steps of the microturbine (direct and tabulated film, in oil
//! whip with wall contact for the tabulated one: checked, the steps are counted) make no heap
//! allocation, a change of the films' viscosity (a live oil temperature) among them; nor does
//! the monitor recording each of them (its per-revolution analysis included: it records from
//! the first step, so the counted steps hold full spectrum windows and path distances).

use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use rotor_twin::film::FluidInertia;
use rotor_twin::monitor::{ClassifierSettings, Monitor};
use rotor_twin::rotor::{MachineDescription, Rotor};

#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

/// How the counted steps are reached.
#[derive(Clone, Copy)]
enum Warmup {
    /// this many steps
    Steps(usize),
    /// at this speed (rpm), until a journal touches the wall (at most this many steps): the
    /// whip's contact phase
    Contact(f64, usize),
}

/// (Heap allocations, steps with a journal in wall contact) over `steps` steps after `warmup`.
fn allocations_in_steps(
    film: FilmEvaluation,
    inertia: FluidInertia,
    warmup: Warmup,
    steps: usize,
) -> (usize, usize) {
    // the contact phase on reading (A) (config/orc_microturbine_100kw_d55.yaml, Ø55), whose whip
    // runs on the wall at 9,500 rpm; the built-in (B)'s whip stays clear of it (ε ≈ 0.85)
    let desc = match warmup {
        Warmup::Contact(..) => MachineDescription::load(Some(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/config/orc_microturbine_100kw_d55.yaml"
        ))))
        .unwrap(),
        Warmup::Steps(_) => MachineDescription::builtin_default(),
    };
    let mut rotor = Rotor::from_description(&desc);
    rotor.set_fluid_inertia(inertia);
    let rpm = match warmup {
        Warmup::Contact(rpm, _) => rpm,
        Warmup::Steps(_) => 9000.0,
    };
    let omega = rpm * std::f64::consts::PI / 30.0;
    let config = TwinConfig {
        film,
        ..TwinConfig::with_steps_per_rev(Coupling::Nonlinear, omega, 128)
    };
    let mut twin = Twin::new(&rotor, config, omega).unwrap();
    let mut monitor = Monitor::new(&twin, 2 * 128, ClassifierSettings::default());
    let input = StepInput {
        speed_rad_s: omega,
        accel_rad_s2: 0.0,
    };
    match warmup {
        Warmup::Steps(n) => {
            for _ in 0..n {
                twin.step(&input).unwrap();
                monitor.record(&twin);
            }
        }
        Warmup::Contact(_, most) => {
            let mut touches = |twin: &mut Twin| {
                let touch = twin
                    .step(&input)
                    .unwrap()
                    .bearings
                    .iter()
                    .any(|b| b.contact);
                monitor.record(twin);
                touch
            };
            assert!(
                (0..most).any(|_| touches(&mut twin)),
                "no wall contact within {most} steps"
            );
        }
    }
    let before = allocations();
    let mut contact_steps = 0;
    for k in 0..steps {
        if k % 250 == 100 {
            // a live oil temperature changes the films' viscosity (issue 12): no allocation
            // one scale per film bearing (each its own law or effective temperature)
            let scales = if k % 500 == 100 {
                [1.05, 0.98]
            } else {
                [1.0, 1.0]
            };
            twin.set_viscosity_scales(&scales).unwrap();
        }
        let out = twin.step(&input).unwrap();
        contact_steps += usize::from(out.bearings.iter().any(|b| b.contact));
        monitor.record(&twin);
    }
    (allocations() - before, contact_steps)
}

/// One test only: the counter is global to the process, and tests run in parallel threads.
#[test]
fn the_time_step_allocates_nothing() {
    assert_eq!(
        allocations_in_steps(
            FilmEvaluation::Direct,
            FluidInertia::None,
            Warmup::Steps(10),
            1000
        )
        .0,
        0
    );
    // into the whip until the journal runs on the wall, then a thousand steps: the wall's
    // Newton iterations (to the full tolerance) allocate nothing. At 9,500 rpm: at 9,000 the
    // whip of the session-10 table (κ-corrected) stays just inside the contact onset ε 0.99
    // for 600 revolutions (before it, revolutions 306–471 ran on the wall: `bench --whip
    // --trace`); at 10,000 rpm the journal leaves the wall again within the thousand steps
    let (allocations, contact_steps) = allocations_in_steps(
        FilmEvaluation::Table,
        FluidInertia::None,
        Warmup::Contact(9500.0, 600 * 128),
        1000,
    );
    assert_eq!(allocations, 0);
    assert!(
        contact_steps >= 500,
        "only {contact_steps} of 1000 steps in wall contact"
    );
    // with the film's fluid inertia (added mass at every iteration)
    assert_eq!(
        allocations_in_steps(
            FilmEvaluation::Table,
            FluidInertia::Temporal,
            Warmup::Steps(300 * 128),
            1000
        )
        .0,
        0
    );
    // with its convective inertia too (eq. I1's force and Jacobian at every iteration)
    assert_eq!(
        allocations_in_steps(
            FilmEvaluation::Table,
            FluidInertia::Full,
            Warmup::Steps(300 * 128),
            1000
        )
        .0,
        0
    );
}
