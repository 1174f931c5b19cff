//! `rotor-twin bench node`: the node's model thread without the bus. A [`Driver`] of the
//! built-in microturbine with the node's defaults (tabulated film, 64 steps a revolution, the
//! session's output rates) is fed 9,000 rpm at 20 Hz (the fleet peer's rate) and woken every
//! 2 ms ([`WAKE_PERIOD_NS`], the node's `WAKE_PERIOD`), stepping one step per `advance_to` call
//! as the node's `step_until` does; the journal and film states, orbits and residuals are made
//! and then dropped, as for a node without readers of them. The CPU time of the thread
//! (`CLOCK_THREAD_CPUTIME_ID`) per simulated second is the core a twin costs.
//!
//! The same trajectory (the same start, speed and steps) is run four times, each adding one
//! layer: the twin step alone, + the monitor, + the session's outputs (the full
//! [`Session::step`]), + the driver at the node's wakes. The differences are the breakdown.
//! Under callgrind the four measured windows are the functions `measure_twin`,
//! `measure_monitor`, `measure_session` and `measure_driver` (`--toggle-collect`), whose
//! instruction counts do not depend on the machine's load.

use crate::driver::{Driver, DriverSettings, Input, ModelKind};
use crate::dynamics::{FilmEvaluation, StepInput, Twin, TwinError};
use crate::monitor::{ClassifierSettings, Monitor};
use crate::rotor::{MachineDescription, Rotor};
use crate::session::{Outgoing, Session};
use crate::units::rpm_to_rad_s;
use serde::Serialize;
use std::hint::black_box;

/// The node's wake period (ns): `WAKE_PERIOD` of the model thread.
pub const WAKE_PERIOD_NS: i64 = 2_000_000;
/// The fleet peer's speed rate: one speed every 50 ms (20 Hz).
pub const SPEED_PERIOD_NS: i64 = 50_000_000;
/// Revolutions run before measuring (not measured): the whip is developed by then (the
/// `--whip` warm-up of the ORC-9000 bench).
pub const WARMUP_REVOLUTIONS: usize = 500;

/// One layer's cost over the measured window.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct LayerCost {
    /// CPU seconds of the thread per simulated second (cores a twin).
    pub cpu_s_per_sim_s: f64,
    /// Wall seconds per simulated second.
    pub wall_s_per_sim_s: f64,
}

/// The figures of `bench node`.
#[derive(Debug, Serialize)]
pub struct NodeFigures {
    /// Simulated seconds measured (after the warm-up).
    pub simulated_s: f64,
    /// Steps a revolution and steps a simulated second.
    pub steps_per_rev: usize,
    /// Steps in one simulated second.
    pub steps_per_s: f64,
    /// Twin step alone.
    pub twin: LayerCost,
    /// Twin step + `Monitor::record`.
    pub twin_monitor: LayerCost,
    /// `Session::step` (twin, monitor, probe history, the outputs made).
    pub session: LayerCost,
    /// The driver at the node's wakes and inputs (what the model thread does but publish).
    pub driver: LayerCost,
    /// Messages the driver emitted in the measured window, and how many of them a node without
    /// readers publishes (warnings, margins).
    pub messages: u64,
    /// Of those, the ones a node without readers of states, orbits and residuals publishes.
    pub messages_published: u64,
}

/// The thread's CPU time (s).
fn thread_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: ts is a valid timespec to write to; the clock id is a constant of the platform
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Times `f` on this thread: (CPU s, wall s).
fn timed(f: impl FnOnce() -> Result<(), TwinError>) -> Result<(f64, f64), TwinError> {
    let (cpu0, wall0) = (thread_cpu_s(), std::time::Instant::now());
    f()?;
    Ok((thread_cpu_s() - cpu0, wall0.elapsed().as_secs_f64()))
}

/// The node's driver settings for `rotor`: the node's defaults (tabulated film, 64 steps a
/// revolution, nonlinear coupling, the session's default rates).
pub fn node_settings(rotor: &Rotor) -> DriverSettings {
    DriverSettings::new(
        ModelKind::default(),
        FilmEvaluation::Table,
        rotor.rated_speed_rad_s,
    )
}

/// Runs the four layers for `simulated_s` seconds each after the warm-up, at `rpm`.
pub fn run(rpm: f64, simulated_s: f64) -> anyhow::Result<NodeFigures> {
    let rotor = Rotor::from_description(&MachineDescription::builtin_default());
    let settings = node_settings(&rotor);
    let omega = rpm_to_rad_s(rpm);
    let h = settings.twin.time_step_s;
    let warmup = (WARMUP_REVOLUTIONS as f64 * std::f64::consts::TAU / omega / h).round() as usize;
    let measured = (simulated_s / h).round().max(1.0) as usize;
    let input = StepInput {
        speed_rad_s: omega,
        accel_rad_s2: 0.0,
    };
    eprintln!(
        "bench node: {rpm} rpm, {warmup} steps of warm-up then {measured} measured, four times"
    );
    let per_sim = |(cpu, wall): (f64, f64)| LayerCost {
        cpu_s_per_sim_s: cpu / (measured as f64 * h),
        wall_s_per_sim_s: wall / (measured as f64 * h),
    };

    let mut twin = Twin::new(&rotor, settings.twin, omega)?;
    for _ in 0..warmup {
        twin.step(&input)?;
    }
    let twin_cost = per_sim(timed(|| measure_twin(&mut twin, &input, measured))?);

    let mut twin = Twin::new(&rotor, settings.twin, omega)?;
    let classifier = ClassifierSettings {
        alarm_levels: rotor.alarm_levels.as_ref().map(Into::into),
        ..ClassifierSettings::default()
    };
    let steps_per_rev = (std::f64::consts::TAU / rotor.rated_speed_rad_s / h).round() as usize;
    let mut monitor = Monitor::new(&twin, 2 * steps_per_rev, classifier);
    for _ in 0..warmup {
        twin.step(&input)?;
        monitor.record(&twin);
    }
    let monitor_cost = per_sim(timed(|| {
        measure_monitor(&mut twin, &mut monitor, &input, measured)
    })?);

    let mut session = Session::new(&rotor, settings.twin, omega, settings.session, 0)?;
    for _ in 0..warmup {
        session.step(&input, &mut |o| drop(black_box(o)))?;
    }
    let session_cost = per_sim(timed(|| measure_session(&mut session, &input, measured))?);

    let mut driver = Driver::new(rotor.clone(), settings);
    driver.set_threshold(crate::session::linear_threshold(&rotor));
    let mut wakes = Wakes {
        now: 0,
        omega,
        counts: (0, 0),
    };
    wakes.run(&mut driver, warmup);
    wakes.counts = (0, 0);
    let mut driver_steps = 0;
    let (cpu, wall) = timed(|| {
        driver_steps = measure_driver(&mut wakes, &mut driver, measured);
        Ok(())
    })?;
    let counts = wakes.counts;
    let sim = driver_steps as f64 * h;
    let driver_cost = LayerCost {
        cpu_s_per_sim_s: cpu / sim,
        wall_s_per_sim_s: wall / sim,
    };
    Ok(NodeFigures {
        simulated_s: measured as f64 * h,
        steps_per_rev,
        steps_per_s: 1.0 / h,
        twin: twin_cost,
        twin_monitor: monitor_cost,
        session: session_cost,
        driver: driver_cost,
        messages: counts.0,
        messages_published: counts.1,
    })
}

#[inline(never)]
fn measure_twin(twin: &mut Twin, input: &StepInput, steps: usize) -> Result<(), TwinError> {
    for _ in 0..steps {
        black_box(twin.step(input)?);
    }
    Ok(())
}

#[inline(never)]
fn measure_monitor(
    twin: &mut Twin,
    monitor: &mut Monitor,
    input: &StepInput,
    steps: usize,
) -> Result<(), TwinError> {
    for _ in 0..steps {
        twin.step(input)?;
        black_box(monitor.record(twin));
    }
    Ok(())
}

#[inline(never)]
fn measure_session(
    session: &mut Session,
    input: &StepInput,
    steps: usize,
) -> Result<(), TwinError> {
    for _ in 0..steps {
        session.step(input, &mut |o| drop(black_box(o)))?;
    }
    Ok(())
}

#[inline(never)]
fn measure_driver(wakes: &mut Wakes, driver: &mut Driver, steps: usize) -> usize {
    wakes.run(driver, steps)
}

/// The node's wakes of a driver: its clock (ns), the speed fed (rad/s), and the messages
/// emitted and of those the ones published without readers.
struct Wakes {
    now: i64,
    omega: f64,
    counts: (u64, u64),
}

/// Wakes the driver as the node's model thread does until it has taken `steps` steps (a wake's
/// worth more at most): every [`SPEED_PERIOD_NS`] a speed input received half a wake before
/// the wake (fed at its receive time: the steps up to it in one call, as the node's
/// `feed_inputs`), and every [`WAKE_PERIOD_NS`] the steps due, one `advance_to` call each,
/// each timed with two clock reads as the node's `step_until`. Returns the steps taken;
/// `counts`: messages emitted, and of those the ones published without readers.
impl Wakes {
    fn run(&mut self, driver: &mut Driver, steps: usize) -> usize {
        let (now, omega, counts) = (&mut self.now, self.omega, &mut self.counts);
        feed_wakes(driver, now, omega, steps, counts)
    }
}

fn feed_wakes(
    driver: &mut Driver,
    now: &mut i64,
    omega: f64,
    steps: usize,
    counts: &mut (u64, u64),
) -> usize {
    let first = driver.counts().steps;
    let taken = |d: &Driver| (d.counts().steps - first) as usize;
    let mut emit = |o: Outgoing| {
        counts.0 += 1;
        let gated = matches!(
            o,
            Outgoing::Journal(_) | Outgoing::Film(_) | Outgoing::Orbit(_) | Outgoing::Residual(_)
        );
        counts.1 += u64::from(!gated);
        drop(black_box(o));
    };
    while taken(driver) < steps {
        *now += WAKE_PERIOD_NS;
        if *now % SPEED_PERIOD_NS < WAKE_PERIOD_NS || driver.session().is_none() {
            let received = *now - WAKE_PERIOD_NS / 2;
            let speed = Input::Speed {
                speed_rad_s: omega,
                accel_rad_s2: 0.0,
                stamp_ns: received,
            };
            driver.feed(received, speed, &mut emit);
        }
        loop {
            let started = std::time::Instant::now();
            if driver.advance_to(*now, 1, &mut emit) == 0 {
                break;
            }
            black_box(started.elapsed());
        }
    }
    taken(driver)
}
