//! The guide's rule "the time step allocates nothing", checked with a counting allocator: after
//! the twin is built, a thousand steps of the microturbine (direct and tabulated film, in oil
//! whip with wall contact for the tabulated one) make no heap allocation, a change of the films'
//! viscosity (a live oil temperature) among them.

use rotor_twin::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig};
use rotor_twin::film::FluidInertia;
use rotor_twin::rotor::{MachineDescription, Rotor};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_in_steps(
    film: FilmEvaluation,
    inertia: FluidInertia,
    warmup: usize,
    steps: usize,
) -> usize {
    let mut rotor = Rotor::from_description(&MachineDescription::builtin_default());
    rotor.set_fluid_inertia(inertia);
    let omega = 9000.0 * std::f64::consts::PI / 30.0;
    let config = TwinConfig {
        film,
        ..TwinConfig::with_steps_per_rev(Coupling::Nonlinear, omega, 128)
    };
    let mut twin = Twin::new(&rotor, config, omega).unwrap();
    let input = StepInput {
        speed_rad_s: omega,
        accel_rad_s2: 0.0,
    };
    for _ in 0..warmup {
        twin.step(&input).unwrap();
    }
    let before = ALLOCATIONS.load(Ordering::SeqCst);
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
        twin.step(&input).unwrap();
    }
    ALLOCATIONS.load(Ordering::SeqCst) - before
}

/// One test only: the counter is global to the process, and tests run in parallel threads.
#[test]
fn the_time_step_allocates_nothing() {
    assert_eq!(
        allocations_in_steps(FilmEvaluation::Direct, FluidInertia::None, 10, 1000),
        0
    );
    // 500 revolutions into the whip (the journal touches the wall), then a thousand steps
    assert_eq!(
        allocations_in_steps(FilmEvaluation::Table, FluidInertia::None, 500 * 128, 1000),
        0
    );
    // with the film's fluid inertia (added mass at every iteration)
    assert_eq!(
        allocations_in_steps(
            FilmEvaluation::Table,
            FluidInertia::Temporal,
            300 * 128,
            1000
        ),
        0
    );
    // with its convective inertia too (eq. I1's force and Jacobian at every iteration)
    assert_eq!(
        allocations_in_steps(FilmEvaluation::Table, FluidInertia::Full, 300 * 128, 1000),
        0
    );
}
