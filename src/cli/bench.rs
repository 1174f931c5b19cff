//! `rotor-twin bench`: measures the hot paths and prints the figures (speed is measured here,
//! never in timed tests).

use crate::film::{
    equilibrium_under_load, BearingGeometry, FilmGrid, FilmModel, FiniteFilm, JournalKinematics,
    Lubricant,
};
use crate::units::rpm_to_rad_s;
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::hint::black_box;
use std::time::{Duration, Instant};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Workload {
    /// ORC-9000: the microturbine at 9,000 rpm, 30 elements, 60 × 10 film grids, 128 steps a
    /// revolution, nonlinear coupling: the cost of one twin step.
    #[value(alias = "orc-9000")]
    Orc9000,
    /// One film solve of the seed's bearing (9,000 rpm, 275 N) on a 60 × 10 half-grid.
    Film,
    /// ORC-9000's renewal of the step factor after a speed change (three substep levels), by
    /// the band LU and by faer's dense LU.
    Factor,
    /// The node's model thread without the bus: the driver of the microturbine with the node's
    /// defaults (64 steps a revolution, tabulated film) at 9,000 rpm in developed whip, fed and
    /// woken as the node is; CPU seconds per simulated second (`--seconds`: simulated seconds
    /// measured), split into the step, the monitor, the session's outputs and the driver.
    Node,
    /// The node's model thread through a speed ramp (from 8,000 rpm at `--ramp-rpm-s`, default
    /// 400, for `--seconds`), paced in real time with wakes every 2 ms, on the machine of
    /// `--config` (e.g. `config/orc_microturbine_100kw_thermal.yaml`): each wake's wall time with
    /// the heat balances on the model thread and off it (the node's choice).
    Wakes,
}

mod node;
mod wakes;

/// Measure the cost of the hot paths.
#[derive(Debug, Clone, Args)]
pub struct BenchArgs {
    /// What to measure.
    #[arg(value_enum, default_value_t = Workload::Orc9000)]
    workload: Workload,
    /// ORC-9000: first let the oil whip develop (about 500 revolutions, unmeasured), then measure
    /// in the whip (the hardest case: large orbits, contact near the wall).
    #[arg(long)]
    whip: bool,
    /// ORC-9000: ramp the speed at this rate (rpm/s) from 9,000 rpm while measuring, so that
    /// the step's factor is renewed every 0.2 % of speed (the worst step shows its cost).
    /// wakes: the ramp's rate from 8,000 rpm (default 400).
    #[arg(long)]
    ramp_rpm_s: Option<f64>,
    /// Seconds to spend on each measured case.
    #[arg(long, default_value_t = 2.0)]
    seconds: f64,
    /// ORC-9000, factor and wakes: the machine description (YAML) instead of the built-in one (e.g.
    /// reading (A) of the seed, `config/orc_microturbine_100kw_d55.yaml`, whose whip runs on
    /// the wall), at the same 9,000 rpm and 128 steps a revolution.
    #[arg(long)]
    config: Option<std::path::PathBuf>,
    /// ORC-9000: measure exactly this many steps instead of `--seconds` (a fixed amount of work,
    /// e.g. for counting instructions under `valgrind --tool=callgrind`, which a loaded machine
    /// does not change).
    #[arg(long)]
    steps: Option<usize>,
    /// Film grid over the half bearing.
    #[arg(long, default_value = "60x10", value_parser = FilmGrid::parse)]
    grid: FilmGrid,
    /// Film evaluation for ORC-9000: direct or table.
    #[arg(long, value_enum, default_value_t = super::simulate::FilmArg::Direct)]
    film: super::simulate::FilmArg,
    /// ORC-9000: the films' flow regime (laminar, turbulent or auto; issue 18).
    #[arg(long, default_value = "laminar", value_parser = super::bearing::parse_flow)]
    flow: crate::film::FlowRegime,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// ORC-9000: write every step's journal positions (time, then x and y of each bearing, m;
    /// little-endian f64, whip development included) to this file, to compare two builds step
    /// by step (`scripts/compare_trace.py`).
    #[arg(long)]
    trace: Option<std::path::PathBuf>,
}

/// Timing of one case (µs).
#[derive(Debug, Serialize)]
struct CaseFigures {
    case: &'static str,
    samples: usize,
    median_us: f64,
    p99_us: f64,
    mean_active_set_passes: f64,
}

pub(crate) fn run(args: &BenchArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= 600.0,
        "--seconds {} must be above 0 and at most 600",
        args.seconds
    );
    check_steps(args.steps)?;
    let figures = match args.workload {
        Workload::Film => film_cases(args)?,
        Workload::Orc9000 => return orc_9000(args),
        Workload::Factor => factor_cases(args)?,
        Workload::Node => return node_case(args),
        Workload::Wakes => return wakes_case(args),
    };
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&figures)?);
    } else {
        if args.workload == Workload::Factor {
            outln!("ORC-9000 step factor renewal (K_eff of 124 DOFs, three substep levels):");
        } else {
            outln!(
                "film solve, seed bearing (D 60 mm, L 30 mm, c 40 µm, 9000 rpm, 275 N), grid {}x{}:",
                args.grid.n_theta,
                args.grid.n_z
            );
        }
        for f in &figures {
            outln!(
                "  {:<44} median {:>8.2} µs   p99 {:>8.2} µs   ({} samples, {:.2} active-set passes)",
                f.case, f.median_us, f.p99_us, f.samples, f.mean_active_set_passes
            );
        }
    }
    Ok(())
}

/// ORC-9000 figures.
#[derive(Debug, Serialize)]
struct TwinFigures {
    workload: &'static str,
    /// The machine description: `--config`'s path, or "built-in".
    machine: String,
    phase: &'static str,
    steps: usize,
    time_step_us: f64,
    median_step_us: f64,
    p99_step_us: f64,
    /// The slowest step (µs): with `--ramp-rpm-s`, a factor's renewal (and any preemption).
    max_step_us: f64,
    mean_step_us: f64,
    real_time_factor: f64,
    newton_iterations_per_step: f64,
    /// Share of the measured steps with a journal in contact with the wall (Newton then
    /// iterates to the full tolerance; away from the wall one correction usually suffices).
    contact_step_fraction: f64,
    /// Largest eccentricity ratio of the measured steps.
    max_eccentricity_ratio: f64,
    /// With `oil_heating`: the films' heat balances taken inside the measured steps (a ramp's;
    /// the first, before the twin starts, not counted), the slowest (µs) and their mean (µs).
    heat_balances: usize,
    slowest_heat_balance_us: f64,
    mean_heat_balance_us: f64,
}

/// The microturbine (built-in, or `--config`) on the bench's film grid and flow regime.
fn orc_9000_rotor(args: &BenchArgs) -> anyhow::Result<crate::rotor::Rotor> {
    use crate::rotor::{MachineDescription, Rotor};
    let desc = MachineDescription::load(args.config.as_deref())?;
    let mut rotor = crate::transient::with_grid(&Rotor::from_description(&desc), Some(args.grid));
    for b in &mut rotor.bearings {
        if let crate::rotor::BearingModel::Film(f) = &mut b.model {
            f.flow = args.flow;
        }
    }
    Ok(rotor)
}

fn orc_9000(args: &BenchArgs) -> anyhow::Result<()> {
    use crate::dynamics::{Coupling, StepInput, Twin, TwinConfig};
    let mut rotor = orc_9000_rotor(args)?;
    let omega = rpm_to_rad_s(9000.0);
    let config = TwinConfig {
        film: args.film.into(),
        ..TwinConfig::with_steps_per_rev(Coupling::Nonlinear, omega, 128)
    };
    let mut heat = crate::transient::HeatFollower::of(&mut rotor, config.film, omega)?;
    let mut twin = Twin::new(&rotor, config, omega)?;
    let mut input = StepInput {
        speed_rad_s: omega,
        accel_rad_s2: 0.0,
    };
    let ramp = rpm_to_rad_s(args.ramp_rpm_s.unwrap_or(0.0));
    anyhow::ensure!(
        ramp.is_finite() && (0.0..=rpm_to_rad_s(10_000.0)).contains(&ramp),
        "--ramp-rpm-s {:?} must lie between 0 and 10,000 rpm/s",
        args.ramp_rpm_s
    );
    let mut trace = open_trace(args)?;
    if args.whip {
        eprintln!("bench: letting the whip develop (500 revolutions, not measured)...");
        for _ in 0..500 * 128 {
            let out = twin.step(&input)?;
            write_trace(&mut trace, out)?;
        }
    }
    let window = measure_window(&mut twin, args, (&mut input, ramp), &mut heat, &mut trace)?;
    let Window {
        mut times,
        iterations,
        contact_steps,
        max_eps,
    } = window;
    if let Some(w) = trace.as_mut() {
        std::io::Write::flush(w)?;
    }
    let total_us: f64 = times.iter().sum();
    let n = times.len();
    times.sort_by(f64::total_cmp);
    let pick = |q: f64| times[((n - 1) as f64 * q).round() as usize];
    let h_us = config.time_step_s * 1e6;
    let fig = TwinFigures {
        workload: "ORC-9000",
        machine: args
            .config
            .as_ref()
            .map_or("built-in".into(), |p| p.display().to_string()),
        phase: match (args.whip, ramp > 0.0) {
            (_, true) => "speed ramp from 9,000 rpm",
            (true, false) => "developed oil whip",
            (false, false) => "from the synchronous orbit (first seconds)",
        },
        steps: n,
        time_step_us: h_us,
        median_step_us: pick(0.5),
        p99_step_us: pick(0.99),
        max_step_us: pick(1.0),
        mean_step_us: total_us / n as f64,
        real_time_factor: h_us * n as f64 / total_us,
        newton_iterations_per_step: iterations as f64 / n as f64,
        contact_step_fraction: contact_steps as f64 / n as f64,
        max_eccentricity_ratio: max_eps,
        heat_balances: heat.as_ref().map_or(0, |h| h.balances()),
        slowest_heat_balance_us: heat.as_ref().map_or(0.0, |h| h.slowest_us()),
        mean_heat_balance_us: heat.as_ref().map_or(0.0, |h| h.mean_us()),
    };
    print_twin_figures(args, &fig)
}

/// What the measured window of ORC-9000 gave: each step's time (µs), the Newton iterations,
/// the steps in wall contact and the largest eccentricity ratio.
struct Window {
    times: Vec<f64>,
    iterations: usize,
    contact_steps: usize,
    max_eps: f64,
}

/// The measured steps of ORC-9000 (`--steps`, else `--seconds`), in a function of their own
/// (never inlined) so that a count of instructions can be limited to them:
/// `valgrind --tool=callgrind --collect-atstart=no '--toggle-collect=*bench::measure_window*'`.
#[inline(never)]
fn measure_window(
    twin: &mut crate::dynamics::Twin,
    args: &BenchArgs,
    (input, ramp): (&mut crate::dynamics::StepInput, f64),
    heat: &mut Option<crate::transient::HeatFollower>,
    trace: &mut Option<std::io::BufWriter<std::fs::File>>,
) -> anyhow::Result<Window> {
    let budget = Duration::from_secs_f64(args.seconds);
    let (omega, h) = (input.speed_rad_s, twin.config().time_step_s);
    let mut w = Window {
        times: Vec::with_capacity(1 << 20),
        iterations: 0,
        contact_steps: 0,
        max_eps: 0.0,
    };
    let start = Instant::now();
    let t0 = twin.time_s();
    while measure_more(args.steps, start, budget, w.times.len()) {
        if ramp > 0.0 {
            // at most 1.5× the start speed: the ramp stays below the twin's limit
            let t = twin.time_s() - t0 + h;
            input.speed_rad_s = (omega + ramp * t).min(1.5 * omega);
            input.accel_rad_s2 = ramp;
        }
        let t = Instant::now();
        if let Some(h) = heat.as_mut() {
            h.follow(twin, input.speed_rad_s)?;
        }
        let out = twin.step(input)?;
        w.times.push(t.elapsed().as_secs_f64() * 1e6);
        w.iterations += out.newton_iterations;
        w.contact_steps += usize::from(out.bearings.iter().any(|b| b.contact));
        w.max_eps = (out.bearings.iter()).fold(w.max_eps, |m, b| m.max(b.eccentricity_ratio));
        write_trace(trace, out)?;
    }
    Ok(w)
}

/// ORC-9000's `--steps`, if given: 1 to 2²⁴ measured steps.
fn check_steps(steps: Option<usize>) -> anyhow::Result<()> {
    anyhow::ensure!(
        steps.is_none_or(|n| (1..=1 << 24).contains(&n)),
        "--steps {steps:?} must be 1 to 16,777,216"
    );
    Ok(())
}

/// Whether to measure another step: up to `--steps`, else while the time budget lasts.
fn measure_more(steps: Option<usize>, start: Instant, budget: Duration, done: usize) -> bool {
    match steps {
        Some(n) => done < n,
        None => start.elapsed() < budget && done < (1 << 20),
    }
}

fn print_twin_figures(args: &BenchArgs, fig: &TwinFigures) -> anyhow::Result<()> {
    if args.json {
        outln!("{}", serde_json::to_string_pretty(fig)?);
    } else {
        outln!("ORC-9000 ({}): microturbine ({}) at 9,000 rpm, film {}x{} ({:?}), 128 steps/rev, nonlinear", fig.phase, fig.machine, args.grid.n_theta, args.grid.n_z, args.film);
        outln!(
            "  {} steps: median {:.1} µs, p99 {:.1} µs, max {:.1} µs, mean {:.1} µs per step of {:.1} µs → real-time factor {:.3}; {:.2} Newton iterations a step; largest ε {:.3}, {:.1} % of the steps in wall contact",
            fig.steps, fig.median_step_us, fig.p99_step_us, fig.max_step_us, fig.mean_step_us, fig.time_step_us, fig.real_time_factor, fig.newton_iterations_per_step,
            fig.max_eccentricity_ratio, 100.0 * fig.contact_step_fraction
        );
        if fig.heat_balances > 0 {
            outln!(
                "  oil_heating: {} heat balances inside the measured steps, mean {:.0} µs, slowest {:.0} µs",
                fig.heat_balances, fig.mean_heat_balance_us, fig.slowest_heat_balance_us
            );
        }
    }
    Ok(())
}

/// `bench node`: the figures of [`node::run`], as a table or JSON.
fn node_case(args: &BenchArgs) -> anyhow::Result<()> {
    let f = node::run(9000.0, args.seconds)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&f)?);
        return Ok(());
    }
    outln!(
        "node's model thread without the bus: microturbine at 9,000 rpm in developed whip, {} steps/rev ({:.0} steps/s), tabulated film, {:.2} s simulated per layer",
        f.steps_per_rev, f.steps_per_s, f.simulated_s
    );
    let rows = [
        ("twin step alone", f.twin, None),
        ("+ monitor (Monitor::record)", f.twin_monitor, Some(f.twin)),
        (
            "+ session outputs (Session::step)",
            f.session,
            Some(f.twin_monitor),
        ),
        ("+ driver at the node's wakes", f.driver, Some(f.session)),
    ];
    for (name, c, below) in rows {
        let added = below.map_or(String::new(), |b| {
            format!("   (+{:.4})", c.cpu_s_per_sim_s - b.cpu_s_per_sim_s)
        });
        outln!(
            "  {name:<36} {:.4} CPU s per simulated s{added}; wall {:.4}",
            c.cpu_s_per_sim_s,
            c.wall_s_per_sim_s
        );
    }
    outln!(
        "  messages made {} ({} published without readers of states, orbits and residuals)",
        f.messages,
        f.messages_published
    );
    Ok(())
}

/// The ramp's first speed for `bench wakes` (rpm): below the built-in machine's whip.
const WAKES_FROM_RPM: f64 = 8000.0;

fn wakes_case(args: &BenchArgs) -> anyhow::Result<()> {
    let rotor = crate::rotor::Rotor::from_description(&crate::rotor::MachineDescription::load(
        args.config.as_deref(),
    )?);
    let ramp = wakes::Ramp {
        from_rpm: WAKES_FROM_RPM,
        rpm_per_s: args.ramp_rpm_s.unwrap_or(400.0),
        seconds: args.seconds,
    };
    wakes::check(&rotor, ramp)?;
    if !rotor.has_oil_heating() {
        eprintln!(
            "bench wakes: this machine has no oil_heating: the two runs do the same work (give \
             --config config/orc_microturbine_100kw_thermal.yaml to see a balance's cost)"
        );
    }
    eprintln!("bench wakes: the node's tabulated film (built or read from the cache first), twice");
    let figures = [false, true]
        .into_iter()
        .map(|off| wakes::run(&rotor, ramp, off))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&figures)?);
        return Ok(());
    }
    outln!(
        "node's wakes (every 2 ms, real time) through a ramp {:.0} → {:.0} rpm at {} rpm/s, tabulated film, {}:",
        ramp.from_rpm,
        ramp.from_rpm + ramp.rpm_per_s * ramp.seconds,
        ramp.rpm_per_s,
        args.config.as_ref().map_or("built-in machine".into(), |p| p.display().to_string())
    );
    for f in &figures {
        outln!(
            "  balances on the {:<14} wake median {:>7.1} µs  p99 {:>7.1} µs  slowest {:>8.1} µs  late {:>4} of {}  ({} balances, {} failed)",
            f.heat_balance, f.median_us, f.p99_us, f.max_us, f.late_wakes, f.wakes, f.balances, f.failures
        );
        if let Some(why) = &f.last_failure {
            outln!("    the last failed balance: {why}");
        }
    }
    Ok(())
}

/// The `--trace` file, created (None without the option).
fn open_trace(args: &BenchArgs) -> anyhow::Result<Option<std::io::BufWriter<std::fs::File>>> {
    let Some(path) = &args.trace else {
        return Ok(None);
    };
    let file = std::fs::File::create(path)
        .map_err(|e| anyhow::anyhow!("--trace {}: cannot create: {e}", path.display()))?;
    Ok(Some(std::io::BufWriter::new(file)))
}

/// Appends the step's time and journal positions to the trace, if one is written.
fn write_trace(
    trace: &mut Option<std::io::BufWriter<std::fs::File>>,
    out: &crate::dynamics::StepOutput,
) -> anyhow::Result<()> {
    if let Some(w) = trace {
        use std::io::Write;
        w.write_all(&out.time_s.to_le_bytes())?;
        for b in &out.bearings {
            for v in b.position_m {
                w.write_all(&v.to_le_bytes())?;
            }
        }
    }
    Ok(())
}

fn film_cases(args: &BenchArgs) -> anyhow::Result<Vec<CaseFigures>> {
    let geometry = BearingGeometry::plain(0.06, 0.03, 40e-6)?;
    let lubricant = Lubricant::new(900.0, 0.0008)?;
    let omega = rpm_to_rad_s(9000.0);
    let mut film = FiniteFilm::new(geometry, lubricant, args.grid)?;
    let eq = equilibrium_under_load(&mut film, 0.0008, [275.0, 0.0], omega)?;
    let c = 40e-6;
    let q0 = eq.position_m;
    // a journal move of 1 % of the clearance, across the line of centres
    let moved = [q0[0] - 0.01 * c * 0.6, q0[1] + 0.01 * c * 0.8];
    let at = |q| JournalKinematics::at_position(q, omega);
    let budget = Duration::from_secs_f64(args.seconds);

    let cold = measure("cold (no previous solution)", budget, &mut film, |f, _| {
        f.reset_warm_start();
        f.solve(&at(q0)).map(|r| r.force_n[0])
    })?;
    let warm = measure(
        "warm, after a 1 % c journal move",
        budget,
        &mut film,
        |f, k| {
            let q = if k % 2 == 0 { moved } else { q0 };
            f.solve(&at(q)).map(|r| r.force_n[0])
        },
    )?;
    let warm_same = measure(
        "warm, same position (zone unchanged)",
        budget,
        &mut film,
        |f, _| f.solve(&at(q0)).map(|r| r.force_n[0]),
    )?;
    let coefficients = measure(
        "warm + 8 coefficients, after a 1 % c move",
        budget,
        &mut film,
        |f, k| {
            let q = if k % 2 == 0 { moved } else { q0 };
            f.solve_with_coefficients(&at(q))
                .map(|(r, c)| r.force_n[0] + c.stiffness_n_per_m[(0, 0)])
        },
    )?;
    // the same film tabulated (built before timing): interpolation and chain-rule coefficients
    let table = crate::film::FilmTable::shared(film.geometry(), lubricant, args.grid)?;
    let mut tabulated = crate::film::TabulatedFilm::new(table);
    let mut times = Vec::with_capacity(1 << 20);
    let start = Instant::now();
    let mut k = 0usize;
    while measure_more(args.steps, start, budget, times.len()) {
        let q = if k.is_multiple_of(2) { moved } else { q0 };
        let t = Instant::now();
        let (r, c) = tabulated.solve_with_coefficients(&at(q))?;
        times.push(t.elapsed().as_secs_f64() * 1e6);
        black_box(r.force_n[0] + c.stiffness_n_per_m[(0, 0)]);
        k += 1;
    }
    times.sort_by(f64::total_cmp);
    let pick = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
    let table_case = CaseFigures {
        case: "tabulated film + 8 coefficients, after a 1 % c move",
        samples: times.len(),
        median_us: pick(0.5),
        p99_us: pick(0.99),
        mean_active_set_passes: 0.0,
    };
    Ok(vec![cold, warm, warm_same, coefficients, table_case])
}

fn measure(
    case: &'static str,
    budget: Duration,
    film: &mut FiniteFilm,
    mut once: impl FnMut(&mut FiniteFilm, usize) -> Result<f64, crate::film::FilmError>,
) -> anyhow::Result<CaseFigures> {
    for k in 0..100 {
        black_box(once(film, k)?);
    }
    let mut times = Vec::with_capacity(1 << 20);
    let mut passes = 0usize;
    let start = Instant::now();
    let mut k = 0;
    while start.elapsed() < budget && times.len() < (1 << 20) {
        let t = Instant::now();
        black_box(once(film, k)?);
        times.push(t.elapsed().as_secs_f64() * 1e6);
        passes += film.last_active_set_passes();
        k += 1;
    }
    times.sort_by(f64::total_cmp);
    let pick = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
    Ok(CaseFigures {
        case,
        samples: times.len(),
        median_us: pick(0.5),
        p99_us: pick(0.99),
        mean_active_set_passes: passes as f64 / times.len() as f64,
    })
}

/// The factor renewal of ORC-9000 at speeds alternating by 1 %, band LU then dense LU.
fn factor_cases(args: &BenchArgs) -> anyhow::Result<Vec<CaseFigures>> {
    use crate::dynamics::{Coupling, Twin, TwinConfig};
    use crate::rotor::{MachineDescription, Rotor};
    let rotor = Rotor::from_description(&MachineDescription::load(args.config.as_deref())?);
    let omega = rpm_to_rad_s(9000.0);
    let config = TwinConfig::with_steps_per_rev(Coupling::Nonlinear, omega, 128);
    let mut twin = Twin::new(&rotor, config, omega)?;
    let budget = Duration::from_secs_f64(args.seconds);
    let time = |twin: &mut Twin, case| {
        let mut times = Vec::new();
        let start = Instant::now();
        while start.elapsed() < budget && times.len() < 100_000 {
            let speed = omega * if times.len() % 2 == 0 { 1.01 } else { 1.0 };
            let t = Instant::now();
            twin.renew_factors(speed);
            times.push(t.elapsed().as_secs_f64() * 1e6);
        }
        times.sort_by(f64::total_cmp);
        let pick = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
        CaseFigures {
            case,
            samples: times.len(),
            median_us: pick(0.5),
            p99_us: pick(0.99),
            mean_active_set_passes: 0.0,
        }
    };
    let band = time(&mut twin, "band LU without pivoting, inverse from it");
    twin.use_dense_factors();
    let dense = time(&mut twin, "faer's dense LU with pivoting and inverse");
    Ok(vec![band, dense])
}
