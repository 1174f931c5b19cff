//! The `rotor-twin` command line: one subcommand per job.

use clap::{Parser, Subcommand};

/// Standard output was closed by its reader (`rotor-twin modes | head`, `| true`): the command
/// ends there, quietly and successfully, as a Unix filter does.
#[derive(Debug, thiserror::Error)]
#[error("standard output closed by its reader")]
pub struct StdoutClosed;

/// Writes `text` to standard output. A closed standard output gives [`StdoutClosed`], which
/// [`run`] treats as the normal end of the command (`print!` would panic); any other write error
/// is an error.
pub fn print_out(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        Err(e) => Err(anyhow::Error::new(e).context("writing to standard output")),
    }
}

/// `println!` through [`print_out`]: returns from the enclosing function (which gives an
/// `anyhow::Result`) when standard output is closed.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::print_out(&format!("{}\n", format_args!($($arg)*)))?
    };
}

mod bag;
mod bearing;
mod bearing_speeds;
mod bearing_thermal;
mod bench;
mod mode_shapes;
mod modes;
#[cfg(feature = "ros")]
mod node;
mod replay;
mod response;
mod simulate;
mod synth;

/// rotor-twin: a live digital twin of a rotor on fluid-film bearings.
#[derive(Debug, Parser)]
#[command(name = "rotor-twin", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Directory of the film-table cache [default: $ROTOR_TWIN_CACHE_DIR, else
    /// $XDG_CACHE_HOME/rotor-twin, else ~/.cache/rotor-twin].
    #[arg(long, global = true, value_name = "DIR")]
    film_cache_dir: Option<std::path::PathBuf>,
    /// Build the film tables at every start, without reading or writing the cache.
    #[arg(long, global = true)]
    no_film_cache: bool,
}

impl Cli {
    /// A command that only computes and prints (every one but `node` and `param`, which talk to
    /// the bus): a closed standard output may end it by SIGPIPE, as it ends a Unix filter.
    pub fn is_filter(&self) -> bool {
        #[cfg(feature = "ros")]
        let bus = matches!(self.command, Some(Command::Node(_) | Command::Param(_)));
        #[cfg(not(feature = "ros"))]
        let bus = false;
        !bus
    }
}

/// The film-table cache the command line asks for (None: off, or no directory to put it in).
fn film_cache(cli: &Cli) -> Option<crate::film::TableCache> {
    if cli.no_film_cache {
        return None;
    }
    let dir = cli
        .film_cache_dir
        .clone()
        .or_else(crate::film::TableCache::default_dir);
    if dir.is_none() {
        eprintln!(
            "warning: no film-table cache directory (set ROTOR_TWIN_CACHE_DIR, XDG_CACHE_HOME or \
             HOME, or --film-cache-dir): tables are built at every start"
        );
    }
    dir.map(crate::film::TableCache::new)
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Static analysis of one journal bearing: equilibrium, film, eight coefficients.
    Bearing(bearing::BearingArgs),
    /// Linear rotordynamics: natural frequencies, Campbell diagram, stability threshold.
    Modes(modes::ModesArgs),
    /// Unbalance response of the linear model (API 684): Bode/polar, peaks, AF, separation margins.
    Response(response::ResponseArgs),
    /// Nonlinear transient at constant speed or along a speed history (ramp, run-up, run-down),
    /// with kicks: orbits, spectrum, instability classification.
    Simulate(simulate::SimulateArgs),
    /// Amplitude–speed characteristic: a transient at each speed, in parallel.
    Sweep(simulate::SweepArgs),
    /// The live ROS 2 node: the twin beside a plant or rig, recorded to MCAP.
    #[cfg(feature = "ros")]
    Node(node::NodeArgs),
    /// A running node's parameters: get, or set where the node allows it at run time.
    #[cfg(feature = "ros")]
    Param(node::ParamArgs),
    /// A recorded bag through the twin: predictions, warnings, predicted vs measured orbits.
    Replay(replay::ReplayArgs),
    /// Write a SYNTHETIC bag (a plant model run through a speed profile, noisy probes) to try
    /// the replay on.
    SynthBag(synth::SynthArgs),
    /// Measure the cost of the hot paths (prints its figures).
    Bench(bench::BenchArgs),
    /// Tools for recorded bags: `bag recover DIR` makes a cut-off recording a complete bag.
    Bag(bag::BagArgs),
}

/// Runs the command line; with no subcommand, the main job: the shipped sample bag replayed on
/// the built-in default machine.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    crate::film::set_disk_cache(film_cache(&cli));
    match run_command(cli) {
        Err(e) if e.downcast_ref::<StdoutClosed>().is_some() => Ok(()),
        result => result,
    }
}

fn run_command(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Some(Command::Bearing(args)) => bearing::run(&args),
        Some(Command::Modes(args)) => modes::run(&args),
        Some(Command::Response(args)) => response::run(&args),
        Some(Command::Simulate(args)) => simulate::run_simulate(&args),
        Some(Command::Sweep(args)) => simulate::run_sweep(&args),
        #[cfg(feature = "ros")]
        Some(Command::Node(args)) => node::run(args),
        Some(Command::Replay(args)) => replay::run(&args),
        #[cfg(feature = "ros")]
        Some(Command::Param(args)) => node::run_param(args),
        Some(Command::SynthBag(args)) => synth::run(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::Bag(args)) => bag::run(&args),
        None => replay::run_sample(),
    }
}

/// The command line with every negative number that follows a long option joined to it
/// (`--speed-rpm -inf` → `--speed-rpm=-inf`): the one home of the rule that a word starting
/// with `-` which reads as a number (`-5`, `-1e3`, `-inf`, `-NaN`) or starts as one
/// (`--kick -0.1:15:1:0`) is that option's value, not a
/// flag, in every subcommand (clap's `allow_negative_numbers` knows digits only and read `-inf`
/// as the flags `-i -n -f`). The value then meets the option's own check, which names it. Stops at
/// `--` and `--ros-args` (what follows is not ours to parse).
pub fn numbers_as_values(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    let mut joinable = false;
    let mut ours = true;
    for arg in args {
        let text = arg.to_str().unwrap_or("");
        let number = text.strip_prefix('-').is_some_and(|rest| {
            text.parse::<f64>().is_ok()
                || rest.starts_with(|c: char| c.is_ascii_digit() || c == '.')
        });
        match out.last_mut() {
            Some(option) if ours && joinable && number => {
                option.push("=");
                option.push(&arg);
                joinable = false;
                continue;
            }
            _ => {}
        }
        if text == "--" || text == "--ros-args" {
            ours = false;
        }
        joinable = text.starts_with("--") && text.len() > 2 && !text.contains('=');
        out.push(arg);
    }
    out
}

/// A machine and a range of speeds: the arguments `modes` and `response` share.
#[derive(Debug, Clone, clap::Args)]
pub struct MachineSpeedRange {
    /// Machine description (YAML); the built-in ORC microturbine if absent.
    #[arg(long)]
    pub config: Option<std::path::PathBuf>,
    /// Lowest speed (rpm); default 10 % of rated.
    #[arg(long)]
    pub from_rpm: Option<f64>,
    /// Highest speed (rpm); default 150 % of rated.
    #[arg(long)]
    pub to_rpm: Option<f64>,
    /// Speed step (rpm); default a fraction of the range (`modes` 1/40, `response` 1/200).
    #[arg(long)]
    pub step_rpm: Option<f64>,
}

impl MachineSpeedRange {
    /// The machine description (`--config`, or the built-in one).
    pub(crate) fn machine(&self) -> anyhow::Result<crate::rotor::MachineDescription> {
        Ok(crate::rotor::MachineDescription::load(
            self.config.as_deref(),
        )?)
    }

    /// [`speed_grid_rpm`] of these flags.
    pub(crate) fn grid(
        &self,
        rated: f64,
        steps: f64,
        max_steps: f64,
    ) -> anyhow::Result<(Vec<f64>, f64, f64, f64)> {
        speed_grid_rpm(
            [self.from_rpm, self.to_rpm, self.step_rpm],
            rated,
            steps,
            max_steps,
        )
    }
}

/// The speeds (rpm) of `[--from-rpm, --to-rpm, --step-rpm]`, checked: by default from 10 % of
/// the rated speed `rated` (at least 100 rpm) to 150 % of it in `steps` steps; at most
/// `max_steps` steps. Returns (speeds, from, to, step), the last speed capped at `to`.
pub(crate) fn speed_grid_rpm(
    [from, to, step]: [Option<f64>; 3],
    rated: f64,
    steps: f64,
    max_steps: f64,
) -> anyhow::Result<(Vec<f64>, f64, f64, f64)> {
    use crate::units::shown_value as v;
    let from = from.unwrap_or((0.1 * rated).max(100.0));
    let to = to.unwrap_or(1.5 * rated);
    let max_rpm = crate::dynamics::MAX_SPEED_OVER_RATED * rated;
    for (name, n) in [("--from-rpm", from), ("--to-rpm", to)] {
        anyhow::ensure!(
            n.is_finite() && n > 0.0 && n <= max_rpm,
            "invalid {name} {}: must lie in (0, {max_rpm:.0}] rpm, above zero and at most {}× \
             the rated speed",
            v(n),
            crate::dynamics::MAX_SPEED_OVER_RATED
        );
    }
    anyhow::ensure!(
        to > from,
        "invalid --to-rpm {}: must exceed --from-rpm {}",
        v(to),
        v(from)
    );
    let step = step.unwrap_or((to - from) / steps);
    anyhow::ensure!(
        step.is_finite() && step > 0.0 && (to - from) / step <= max_steps,
        "invalid --step-rpm {}: must be above zero, at most {max_steps} speeds",
        v(step)
    );
    let n = ((to - from) / step).round() as usize;
    let speeds = (0..=n).map(|k| (from + k as f64 * step).min(to)).collect();
    Ok((speeds, from, to, step))
}

/// Where a command writes: a directory of files, or one file (a plot prefix is a file whose
/// name the command extends).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Output {
    Directory,
    File,
}

/// An output of `option`, checked before anything is computed (issue 15, item 20: `simulate
/// --plot`, `modes --plot`, … found an unwritable path only after the computation): the missing
/// directories are made (as `sweep --out` always did) and a file is created and removed where the
/// output will go; an existing output file must open for writing. The error names the option and
/// the path, once.
pub(crate) fn check_output(
    option: &str,
    path: &std::path::Path,
    kind: Output,
) -> anyhow::Result<()> {
    use anyhow::Context;
    let dir = match kind {
        Output::Directory => path,
        Output::File => {
            anyhow::ensure!(
                !path.is_dir(),
                "{option} {}: is a directory, not a file",
                path.display()
            );
            match path.parent() {
                Some(p) if !p.as_os_str().is_empty() => p,
                _ => std::path::Path::new("."),
            }
        }
    };
    anyhow::ensure!(
        !dir.exists() || dir.is_dir(),
        "{option}: cannot write into {}: not a directory",
        dir.display()
    );
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{option}: creating {}", dir.display()))?;
    if kind == Output::File && path.exists() {
        std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .with_context(|| format!("{option}: cannot write {}", path.display()))?;
        return Ok(());
    }
    let probe = dir.join(format!(".rotor-twin-write-check-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .with_context(|| format!("{option}: cannot write into {}", dir.display()))?;
    std::fs::remove_file(&probe).ok();
    Ok(())
}

/// The error as the command line prints it: each cause after the context that names it, a
/// cause whose text the line already holds left out (issue 15, item 21: plotters' "backend
/// error" wraps the I/O error and repeats its text, so `{:#}` printed it twice).
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}
