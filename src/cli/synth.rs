//! `rotor-twin synth-bag`: writes a SYNTHETIC bag for trying the replay (the plant model and the
//! bag are [`crate::plant`]'s).

use crate::plant::{write_bag, PlantSpec, SpeedProfile};
use crate::rotor::{MachineDescription, Rotor};
use clap::Args;
use std::path::PathBuf;

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
    /// Seconds at the end speed (10 s: the built-in machine, reading (B), whips at 9,000 rpm
    /// some 5 s after reaching it, out of its half-speed resonance; the sample bag's profile).
    #[arg(long, default_value_t = 10.0)]
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
    /// The plant's shaft angle (deg) at which its keyphasor fires, once a revolution (issue 12):
    /// the keyphasor topic is written, best effort, and the unbalance phase is published from
    /// the mark. Default 0.
    #[arg(long, default_value_t = 0.0)]
    pub keyphasor_deg: f64,
    /// Write no keyphasor topic (phases are then null in a replay).
    #[arg(long)]
    pub no_keyphasor: bool,
    /// Write raw proximity-probe readings (ProbeSignal, V at 7.87 V/mm, DC, 1 mm gap, named
    /// <station>_x and <station>_y along the station's two angles) instead of probe pairs.
    #[arg(long)]
    pub raw_probes: bool,
    /// Runout of each raw probe (µm, zero to peak; high spot 30° from the keyphasor mark).
    #[arg(long, default_value_t = 0.0)]
    pub runout_um: f64,
    /// Write no speed topic: a rig with only the once-per-revolution keyphasor (the replay and
    /// `--calibrate` take the speed from its intervals). Needs the keyphasor.
    #[arg(long, conflicts_with = "no_keyphasor")]
    pub no_speed: bool,
    /// Raw probes AC-coupled: readings without the DC gap (a 0.1 s high pass takes the gap and
    /// the journal's static position out), so no mean position. Needs --raw-probes.
    #[arg(long, requires = "raw_probes")]
    pub ac_coupled: bool,
    /// The speed topic's error (%): it reports (1 + e/100) times the shaft's speed (a
    /// tachometer's scale error; the keyphasor keeps the truth). Default 0; within ±50.
    #[arg(long, default_value_t = 0.0, conflicts_with = "no_speed")]
    pub speed_error_pct: f64,
}

/// Runs `rotor-twin synth-bag`: checks the arguments, writes the bag, prints what it holds.
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
        ("--runout-um", args.runout_um),
    ] {
        anyhow::ensure!(v.is_finite() && v >= 0.0, "{name} {v}: must be ≥ 0");
    }
    anyhow::ensure!(
        (4..=1024).contains(&args.samples_per_rev),
        "--samples-per-rev {}: must be 4 to 1024",
        args.samples_per_rev
    );
    let rotor = Rotor::from_description(&MachineDescription::load(args.config.as_deref())?);
    let spec = PlantSpec {
        profile: SpeedProfile {
            from_rpm: args.from_rpm,
            to_rpm: args.to_rpm,
            hold_start_s: args.hold_start,
            ramp_s: args.ramp,
            hold_end_s: args.hold_end,
        },
        samples_per_rev: args.samples_per_rev,
        noise_m: args.noise_um * 1e-6,
        viscosity_factor: args.viscosity_factor,
        grid_factor: args.grid_factor,
        film: args.film.into(),
        seed: args.seed,
        signals: crate::plant::PlantSignals {
            keyphasor_angle_deg: (!args.no_keyphasor).then_some(args.keyphasor_deg),
            raw_probes: args.raw_probes,
            runout_m: args.runout_um * 1e-6,
            no_speed_topic: args.no_speed,
            ac_coupled: args.ac_coupled,
            speed_topic_error: args.speed_error_pct / 100.0,
        },
    };
    anyhow::ensure!(
        args.speed_error_pct.is_finite() && args.speed_error_pct.abs() <= 50.0,
        "--speed-error-pct {}: must be within ±50",
        args.speed_error_pct
    );
    anyhow::ensure!(
        args.keyphasor_deg.is_finite(),
        "--keyphasor-deg {}: must be finite",
        args.keyphasor_deg
    );
    let total = spec.profile.duration_s();
    let (dir, counts, _truth) = write_bag(&rotor, &spec, &args.out, &mut |t| {
        eprintln!("synth-bag: {t:.2} of {total:.2} s")
    })?;
    println!("wrote SYNTHETIC bag {}", dir.display());
    for (topic, n) in counts {
        println!("  {topic}: {n} messages");
    }
    Ok(())
}
