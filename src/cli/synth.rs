//! `rotor-twin synth-bag`: writes a SYNTHETIC bag for trying the replay. A "plant" (the machine
//! with a finer film grid and a changed lubricant viscosity, i.e. a model that is not the twin)
//! is run through a speed profile with the nonlinear film; its probe displacements, with
//! Gaussian noise, are recorded as a rig would record them, with the speed and the unbalance.
//! The bag says in its metadata that it is synthetic and how it was made.

use crate::dynamics::{Coupling, StepInput, TwinConfig};
use crate::messages::{self, Header, Time};
use crate::record::{Recorder, TopicQos};
use crate::replay::{PROBE_TOPIC, SPEED_TOPIC, UNBALANCE_TOPIC};
use crate::rotor::{BearingModel, MachineDescription, Rotor};
use crate::session::{Session, SessionSettings};
use anyhow::Context;
use clap::Args;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::{PI, TAU};
use std::path::PathBuf;

/// The bag's time zero: 2026-01-01T00:00:00Z (ns since the epoch), fixed so the bag is
/// reproducible.
const EPOCH_NS: i64 = 1_767_225_600_000_000_000;

/// Arguments of `rotor-twin synth-bag`.
#[derive(Debug, Args)]
pub struct SynthArgs {
    /// Bag directory to write (must not exist).
    #[arg(long)]
    pub out: PathBuf,
    /// Machine description (YAML); default: the built-in microturbine.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Speed at the start (rpm), held for --hold-start seconds.
    #[arg(long, default_value_t = 8000.0)]
    pub from_rpm: f64,
    /// Speed at the end of the ramp (rpm), then held for --hold-end seconds.
    #[arg(long, default_value_t = 9000.0)]
    pub to_rpm: f64,
    /// Seconds at the start speed.
    #[arg(long, default_value_t = 0.5)]
    pub hold_start: f64,
    /// Seconds of the linear ramp.
    #[arg(long, default_value_t = 5.0)]
    pub ramp: f64,
    /// Seconds at the end speed.
    #[arg(long, default_value_t = 2.5)]
    pub hold_end: f64,
    /// Probe samples per revolution.
    #[arg(long, default_value_t = 16)]
    pub samples_per_rev: usize,
    /// Standard deviation of the probe noise (µm).
    #[arg(long, default_value_t = 0.3)]
    pub noise_um: f64,
    /// The plant's lubricant viscosity over the machine description's (1.05: a slightly cooler
    /// oil than the twin assumes).
    #[arg(long, default_value_t = 1.05)]
    pub viscosity_factor: f64,
    /// The plant's film grid over the machine description's, in each direction (1: the twin's).
    #[arg(long, default_value_t = 1.5)]
    pub grid_factor: f64,
    /// The plant's film evaluation: direct (the reference, the default) or table (fast, for long
    /// bags such as benchmarks).
    #[arg(long, value_enum, default_value_t = super::simulate::FilmArg::Direct)]
    pub film: super::simulate::FilmArg,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// Runs `rotor-twin synth-bag`.
pub fn run(args: &SynthArgs) -> anyhow::Result<()> {
    for (name, v) in [
        ("--from-rpm", args.from_rpm),
        ("--to-rpm", args.to_rpm),
        ("--viscosity-factor", args.viscosity_factor),
        ("--grid-factor", args.grid_factor),
    ] {
        anyhow::ensure!(v.is_finite() && v > 0.0, "{name} {v}: must be positive");
    }
    for (name, v) in [
        ("--hold-start", args.hold_start),
        ("--ramp", args.ramp),
        ("--hold-end", args.hold_end),
        ("--noise-um", args.noise_um),
    ] {
        anyhow::ensure!(v.is_finite() && v >= 0.0, "{name} {v}: must be ≥ 0");
    }
    anyhow::ensure!(
        (4..=1024).contains(&args.samples_per_rev),
        "--samples-per-rev {}: must be 4 to 1024",
        args.samples_per_rev
    );
    let desc = match &args.config {
        Some(p) => MachineDescription::from_file(p)?,
        None => MachineDescription::builtin_default(),
    };
    let twin_rotor = Rotor::from_description(&desc);
    // the plant: not the twin's model
    let mut plant = twin_rotor.clone();
    for b in &mut plant.bearings {
        if let BearingModel::Film(f) = &mut b.model {
            f.grid.n_theta = (f.grid.n_theta as f64 * args.grid_factor).round() as usize;
            f.grid.n_z = (f.grid.n_z as f64 * args.grid_factor).round() as usize;
            f.lubricant.viscosity_pa_s *= args.viscosity_factor;
        }
    }
    let rpm = |t: f64| {
        if t <= args.hold_start {
            args.from_rpm
        } else if t <= args.hold_start + args.ramp {
            args.from_rpm + (args.to_rpm - args.from_rpm) * (t - args.hold_start) / args.ramp
        } else {
            args.to_rpm
        }
    };
    let accel = |t: f64| {
        if t > args.hold_start && t <= args.hold_start + args.ramp && args.ramp > 0.0 {
            (args.to_rpm - args.from_rpm) / args.ramp * PI / 30.0
        } else {
            0.0
        }
    };
    let total = args.hold_start + args.ramp + args.hold_end;
    let config = TwinConfig {
        film: args.film.into(),
        ..TwinConfig::with_steps_per_rev(Coupling::Nonlinear, plant.rated_speed_rad_s, 128)
    };
    let w0 = args.from_rpm * PI / 30.0;
    let mut session = Session::new(&plant, config, w0, SessionSettings::default(), EPOCH_NS)
        .context("starting the plant model")?;
    let mut rec = Recorder::create(&args.out)?;
    rec.set_custom_data("synthetic", "true");
    rec.set_custom_data(
        "made_by",
        &format!(
            "rotor-twin synth-bag {} (nonlinear film, {:?} evaluation, plant = machine '{}' with film grid ×{} and viscosity ×{}; {} samples/rev; noise {} µm RMS; seed {})",
            env!("CARGO_PKG_VERSION"),
            args.film,
            twin_rotor.name,
            args.grid_factor,
            args.viscosity_factor,
            args.samples_per_rev,
            args.noise_um,
            args.seed
        ),
    );
    rec.set_custom_data(
        "speed_profile",
        &format!(
            "{} rpm for {} s, ramp to {} rpm over {} s, hold {} s",
            args.from_rpm, args.hold_start, args.to_rpm, args.ramp, args.hold_end
        ),
    );
    let h_speed = rec.add_topic::<messages::RotorSpeed>(SPEED_TOPIC, TopicQos::reliable(100))?;
    let h_unb = rec.add_topic::<messages::Unbalance>(UNBALANCE_TOPIC, TopicQos::reliable(10))?;
    let h_probe =
        rec.add_topic::<messages::ProbeDisplacement>(PROBE_TOPIC, TopicQos::sensor(1000))?;
    let stamp = |t: f64| EPOCH_NS + (t * 1e9).round() as i64;
    let header = |ns: i64, frame: &str| Header {
        stamp: Time::from_nanos(ns),
        frame_id: frame.into(),
    };
    // the unbalance as the machine description gives it, once at the start
    for (plane, u) in plant.unbalance.iter().enumerate() {
        let m = messages::Unbalance {
            header: header(EPOCH_NS, "rotor"),
            plane: plane as u32,
            magnitude: u.magnitude_kg_m,
            phase: u.phase_rad,
        };
        rec.write(h_unb, &m, EPOCH_NS as u64, EPOCH_NS as u64)?;
    }
    let noise = Normal::new(0.0, args.noise_um * 1e-6)?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(args.seed);
    let stations: Vec<String> = plant.probes.iter().map(|p| p.name.clone()).collect();
    let speed_period = 0.01;
    let (mut next_speed, mut next_probe) = (0.0, 0.0);
    let mut last_print = std::time::Instant::now();
    while session.twin().time_s() < total {
        // speed messages at 100 Hz and probe samples every 1/samples_per_rev revolution, each at
        // its own time, from the plant's state interpolated within the step just taken
        let now = session.twin().time_s();
        while next_speed <= now {
            let ns = stamp(next_speed);
            let m = messages::RotorSpeed {
                header: header(ns, "rotor"),
                speed: rpm(next_speed) * PI / 30.0,
                acceleration: accel(next_speed),
            };
            rec.write(h_speed, &m, ns as u64, ns as u64)?;
            next_speed += speed_period;
        }
        while next_probe <= now {
            let ns = stamp(next_probe);
            for (k, name) in stations.iter().enumerate() {
                if let Some(([x, y], _)) = session.predicted_probe(k, next_probe) {
                    let m = messages::ProbeDisplacement {
                        header: header(ns, name),
                        station: name.clone(),
                        x: x + noise.sample(&mut rng),
                        y: y + noise.sample(&mut rng),
                    };
                    rec.write(h_probe, &m, ns as u64, ns as u64)?;
                }
            }
            next_probe += TAU / (rpm(next_probe) * PI / 30.0) / args.samples_per_rev as f64;
        }
        let t_mid = now + 0.5 * config.time_step_s;
        session
            .step(
                &StepInput {
                    speed_rad_s: rpm(t_mid) * PI / 30.0,
                    accel_rad_s2: accel(t_mid),
                },
                &mut |_| {},
            )
            .context("the plant model failed")?;
        if last_print.elapsed().as_secs() >= 5 {
            last_print = std::time::Instant::now();
            eprintln!(
                "synth-bag: {:.2} of {total:.2} s, {:.0} rpm",
                session.twin().time_s(),
                rpm(session.twin().time_s())
            );
        }
    }
    let counts = rec.counts();
    let dir = rec.finish()?;
    println!("wrote SYNTHETIC bag {}", dir.display());
    for (topic, n) in counts {
        println!("  {topic}: {n} messages");
    }
    Ok(())
}
