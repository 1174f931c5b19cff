//! `rotor-twin replay`: a recorded bag through the twin, predicted against measured orbits.

use crate::bag::Bag;
use crate::driver::{ModelKind, SpeedUnit};
use crate::record::resolved_path;
use crate::replay::{replay, ReplayOptions};
use crate::rotor::{MachineDescription, Rotor};
use crate::session::SessionSettings;
use anyhow::Context;
use clap::Args;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The bag shipped with the project (a synthetic run-up of the built-in microturbine).
pub const SAMPLE_BAG: &str = "bags/orc_runup_synthetic";

/// Arguments of `rotor-twin replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The bag: a rosbag2 directory (metadata.yaml + .mcap) or a bare .mcap file.
    #[arg(default_value = SAMPLE_BAG)]
    pub bag: PathBuf,
    /// Machine description (YAML); default: the built-in microturbine.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Output directory: the output bag (bag/), report.json and the plots. Default:
    /// replay_<bag name> in the current directory. A previous replay's output there (bag/,
    /// report.json, calibration.json, the plots) is replaced; other files are left alone.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replay at this many times the bag's pace (1 = as recorded).
    #[arg(long, conflicts_with = "fast")]
    pub rate: Option<f64>,
    /// As fast as the model runs (the default).
    #[arg(long)]
    pub fast: bool,
    /// Topic remapping FROM:=TO, e.g. --remap /plant/rpm:=/rotor_twin/speed (repeatable).
    #[arg(long, value_parser = parse_remap)]
    pub remap: Vec<(String, String)>,
    /// Unit of a std_msgs/Float64 speed topic: rpm, rad_s or hz.
    #[arg(long, default_value = "rpm", value_parser = SpeedUnit::from_str)]
    pub speed_unit: SpeedUnit,
    /// A geometry_msgs/PointStamped probe pair (x, y in m): STATION=TOPIC (repeatable).
    #[arg(long, value_parser = parse_probe_point)]
    pub probe_point: Vec<(String, String)>,
    /// A std_msgs/Float64 raw proximity-probe topic, in the probe's unit (machine file's
    /// `proximity_probes`): PROBE=TOPIC (repeatable; issue 12).
    #[arg(long, value_parser = parse_probe_signal)]
    pub probe_signal: Vec<(String, String)>,
    /// Bearing coupling: nonlinear (reference), linear or prehistory.
    #[arg(long, default_value = "nonlinear", value_parser = ModelKind::from_str)]
    pub model: ModelKind,
    /// Film evaluation: table (tabulated finite-length solutions, interpolated; plain bearings)
    /// or direct (the finite solver at every evaluation, the reference).
    #[arg(long, value_enum, default_value_t = super::simulate::FilmArg::Table)]
    pub film: super::simulate::FilmArg,
    /// Prehistory relaxation factor δ in (0, 1].
    #[arg(long, default_value_t = crate::driver::settings::DEFAULT_DELTA)]
    pub delta: f64,
    /// Time steps per revolution at rated speed (64, the node's default: in the whip within
    /// 0.07 % of 128).
    #[arg(long, default_value_t = 64)]
    pub steps_per_rev: usize,
    /// Journal and film states per second of bag time in the output bag (Hz; the node's
    /// default too).
    #[arg(long, default_value_t = 200.0)]
    pub state_rate_hz: f64,
    /// Replay only the first this many seconds of the bag.
    #[arg(long)]
    pub duration: Option<f64>,
    /// No output bag (report and plots only).
    #[arg(long)]
    pub no_bag: bool,
    /// Print the JSON report to standard output instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Fit the oil viscosity and the unbalance to the bag first (issue 12), then replay with the
    /// machine file's values and with the fitted ones, and compare.
    #[arg(long)]
    pub calibrate: bool,
    /// Bag time the fit uses, START:END (s from the bag's first message; default the whole bag;
    /// windows with non-synchronous motion are left out).
    #[arg(long, value_parser = parse_window, requires = "calibrate")]
    pub calibrate_window: Option<(f64, f64)>,
    /// Run the forecast (look-ahead) offline at bag time every --forecast-period-s, and score it
    /// against the plant's observed onset (lead time, false announcements; issue 14).
    #[arg(long)]
    pub forecast: bool,
    /// Bag time between forecasts (s).
    #[arg(long, default_value_t = crate::replay::DEFAULT_REPLAY_FORECAST_PERIOD_S, requires = "forecast")]
    pub forecast_period_s: f64,
    /// How far each forecast looks ahead (s).
    #[arg(long, default_value_t = crate::forecast::DEFAULT_HORIZON_S, requires = "forecast")]
    pub forecast_horizon_s: f64,
    /// Constant speeds probed above the present one (rpm, comma separated, ascending; "none":
    /// the expected path only, no nonlinear margin).
    #[arg(long, default_value = "0,100,250,500", value_parser = parse_offsets, requires = "forecast")]
    pub forecast_offsets_rpm: Offsets,
}

/// The `--forecast-offsets-rpm` list (rpm).
#[derive(Debug, Clone, PartialEq)]
pub struct Offsets(pub Vec<f64>);

fn parse_offsets(s: &str) -> Result<Offsets, String> {
    if s.trim() == "none" {
        return Ok(Offsets(Vec::new()));
    }
    let v = s
        .split(',')
        .map(|v| {
            v.trim()
                .parse::<f64>()
                .map_err(|e| format!("--forecast-offsets-rpm '{v}': {e}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    crate::forecast::ForecastSettings {
        offsets_rpm: v.clone(),
        ..Default::default()
    }
    .check()
    .map_err(|e| format!("--forecast-offsets-rpm: {e}"))?;
    Ok(Offsets(v))
}

/// The forecast the options ask for (None without `--forecast`).
fn forecast_options(args: &ReplayArgs) -> Option<crate::replay::ReplayForecast> {
    args.forecast.then(|| crate::replay::ReplayForecast {
        period_s: args.forecast_period_s,
        settings: crate::forecast::ForecastSettings {
            horizon_s: args.forecast_horizon_s,
            offsets_rpm: args.forecast_offsets_rpm.0.clone(),
            ..Default::default()
        },
    })
}

fn parse_window(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("--calibrate-window '{s}': expected START:END (s)"))?;
    let (a, b): (f64, f64) = (
        a.trim()
            .parse()
            .map_err(|e| format!("--calibrate-window start '{a}': {e}"))?,
        b.trim()
            .parse()
            .map_err(|e| format!("--calibrate-window end '{b}': {e}"))?,
    );
    if !(a.is_finite() && b.is_finite() && 0.0 <= a && a < b) {
        return Err(format!("--calibrate-window '{s}': needs 0 <= START < END"));
    }
    Ok((a, b))
}

fn parse_remap(s: &str) -> Result<(String, String), String> {
    let (from, to) = s
        .split_once(":=")
        .ok_or_else(|| format!("--remap '{s}': expected FROM:=TO"))?;
    if !from.starts_with('/') || !to.starts_with('/') {
        return Err(format!("--remap '{s}': topic names must be absolute (/…)"));
    }
    Ok((from.into(), to.into()))
}

fn parse_probe_point(s: &str) -> Result<(String, String), String> {
    let (station, topic) = s.split_once('=').ok_or_else(|| {
        format!(
            "--probe-point {}: expected STATION=TOPIC",
            crate::rotor::shown(s)
        )
    })?;
    crate::rotor::mapping_name("--probe-point", station)?;
    if !topic.starts_with('/') {
        let topic = crate::rotor::shown(topic);
        return Err(format!(
            "--probe-point: topic {topic} must be absolute (/…)"
        ));
    }
    // stored as (topic, station)
    Ok((topic.into(), station.into()))
}

/// `PROBE=TOPIC` of `--probe-signal`, stored as (topic, probe).
fn parse_probe_signal(s: &str) -> Result<(String, String), String> {
    let (probe, topic) = s.split_once('=').ok_or_else(|| {
        format!(
            "--probe-signal {}: expected PROBE=TOPIC",
            crate::rotor::shown(s)
        )
    })?;
    crate::rotor::mapping_name("--probe-signal", probe)?;
    if !topic.starts_with('/') {
        let topic = crate::rotor::shown(topic);
        return Err(format!(
            "--probe-signal: topic {topic} must be absolute (/…)"
        ));
    }
    Ok((topic.into(), probe.into()))
}

/// The main job: the shipped sample bag through the built-in machine, the summary printed, the
/// output in `replay_orc_runup_synthetic/`.
pub fn run_sample() -> anyhow::Result<()> {
    let mut bag = PathBuf::from(SAMPLE_BAG);
    if !bag.exists() {
        // run from elsewhere than the repository root
        bag = Path::new(env!("CARGO_MANIFEST_DIR")).join(SAMPLE_BAG);
    }
    outln!(
        "rotor-twin: replaying the shipped SYNTHETIC bag {} on the built-in machine",
        bag.display()
    );
    let args = <ReplayArgs as clap::FromArgMatches>::from_arg_matches(
        &<ReplayArgs as clap::Args>::augment_args(clap::Command::new("replay"))
            .get_matches_from(["replay", &bag.to_string_lossy()]),
    )?;
    run(&args)
}

/// With the tabulated film, prepares the tables before the replay and says on stderr where
/// they came from (the disk cache or built), as the node does.
fn say_film_tables(rotor: &Rotor, film: super::simulate::FilmArg) -> anyhow::Result<()> {
    if film != super::simulate::FilmArg::Table {
        return Ok(());
    }
    let start = std::time::Instant::now();
    let origins = crate::dynamics::prepare_film_tables(rotor)?;
    if !origins.is_empty() {
        let said: Vec<String> = origins.iter().map(ToString::to_string).collect();
        eprintln!(
            "film tables ready in {:.2} s ({})",
            start.elapsed().as_secs_f64(),
            said.join("; ")
        );
    }
    Ok(())
}

/// The option values' own rules (the machine's limits are checked by the driver).
fn check_args(args: &ReplayArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.delta > 0.0 && args.delta <= 1.0,
        "--delta {}: must be in (0, 1]",
        args.delta
    );
    if let Some(r) = args.rate {
        anyhow::ensure!(r.is_finite() && r > 0.0, "--rate {r}: must be positive");
    }
    if let Some(d) = args.duration {
        anyhow::ensure!(
            d.is_finite() && d > 0.0,
            "--duration {d}: must be positive (s)"
        );
    }
    anyhow::ensure!(
        args.state_rate_hz.is_finite() && args.state_rate_hz > 0.0,
        "--state-rate-hz {}: must be positive",
        args.state_rate_hz
    );
    anyhow::ensure!(
        (16..=4096).contains(&args.steps_per_rev),
        "--steps-per-rev {}: must be 16 to 4096",
        args.steps_per_rev
    );
    if let Some(f) = forecast_options(args) {
        f.settings.check().map_err(anyhow::Error::msg)?;
        anyhow::ensure!(
            f.period_s.is_finite() && f.period_s >= crate::forecast::MIN_PERIOD_S,
            "--forecast-period-s {}: must be at least {} s",
            f.period_s,
            crate::forecast::MIN_PERIOD_S
        );
    }
    Ok(())
}

/// Runs `rotor-twin replay`: the bag through the twin, the report and the plots.
pub fn run(args: &ReplayArgs) -> anyhow::Result<()> {
    check_args(args)?;
    let desc = MachineDescription::load(args.config.as_deref())?;
    let rotor = Rotor::from_description(&desc);
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(&args.bag));
    refuse_overlap(&args.bag, &out_dir)?;
    let bag = read_bag(&args.bag)?;
    let options = replay_options(args, &out_dir);
    crate::replay::check_mapping(&bag, &rotor, &options)?;
    // after the bag and its mapping are checked: a bad bag is refused before a table build
    // that may take minutes
    say_film_tables(&rotor, args.film)?;
    prepare_out_dir(&out_dir)?;
    if args.calibrate {
        return run_calibrated(args, &bag, &rotor, &options, &out_dir);
    }
    let (mut report, comparisons) = replay_with_progress(&bag, &rotor, &options)?;
    report.add_static_centerline(&rotor)?;
    // chunks that could not be read back during the replay (the file changed under it)
    for n in report.notes.iter().skip(bag.notes.len()) {
        eprintln!("warning: {}: {n}", args.bag.display());
    }
    write_report_json(&out_dir.join("report.json"), &report)?;
    for c in comparisons.iter().filter(|c| c.samples > 0) {
        let locus: Vec<crate::plot::CenterlinePoint> = report
            .stations
            .iter()
            .find(|s| s.station == c.station)
            .map(|s| {
                s.centerline_static_predicted
                    .iter()
                    .map(|p| (p.speed_rpm, p.position_m))
                    .collect()
            })
            .unwrap_or_default();
        write_station_plots(&out_dir, c)?;
        write_station_views(&out_dir, c, &locus)?;
    }
    if let Some(why) = never_started(&report, &options) {
        anyhow::bail!(
            "the twin never started: {why}; nothing was modelled (report.json in {})",
            out_dir.display()
        );
    }
    // a closed standard output (e.g. piped into `head`) is not an error of the replay
    if args.json {
        super::print_out(&serde_json::to_string_pretty(&report)?)?;
        super::print_out("\n")
    } else {
        super::print_out(&format!(
            "{}output: {}\n",
            report.summary(),
            out_dir.display()
        ))
    }
}

/// Writes `report` to `path` as pretty JSON, streamed (not first built as one string: with
/// every block of a long bag it was the replay's largest allocation, issue 17).
fn write_report_json(path: &Path, report: &crate::replay::ReplayReport) -> anyhow::Result<()> {
    use std::io::Write;
    let file = std::fs::File::create(path)
        .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))?;
    let mut w = std::io::BufWriter::new(file);
    serde_json::to_writer_pretty(&mut w, report)?;
    w.flush()
        .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))?;
    Ok(())
}

/// Why the twin never started in the replay that gave `report`, if it did not: a replay that
/// modelled nothing is an error (exit 1), as a `ros2 bag` user scripting it would want to know,
/// not an empty success.
fn never_started(report: &crate::replay::ReplayReport, options: &ReplayOptions) -> Option<String> {
    if report.states.iter().any(|s| s.state == "start") {
        return None;
    }
    if report.messages_in == 0 {
        return Some("the bag has no message to replay".into());
    }
    let refused: Vec<String> = report
        .rejected
        .iter()
        .map(|r| {
            format!(
                "{} refused on {} (last: {})",
                r.count, r.topic, r.last_reason
            )
        })
        .collect();
    Some(format!(
        "of its {} message(s) replayed{}, none was a speed at or above the minimum speed {:.0} rpm that the twin accepted{}",
        report.messages_in,
        options
            .duration_s
            .map_or(String::new(), |d| format!(" (the first {d} s, --duration)")),
        crate::units::rad_s_to_rpm(options.min_speed_rad_s),
        if refused.is_empty() {
            String::new()
        } else {
            format!("; {}", refused.join("; "))
        }
    ))
}

/// `replay_STEM` in the working directory, for bag `bag`.
fn default_out_dir(bag: &Path) -> PathBuf {
    let stem = bag
        .file_stem()
        .map_or("bag".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from(format!("replay_{stem}"))
}

/// The bag, its damaged ranges and notes warned about (the bag's errors name the file).
fn read_bag(path: &Path) -> anyhow::Result<Bag> {
    let bag = Bag::read(path)?;
    for d in &bag.damage {
        eprintln!("warning: {d}; replaying every intact message");
    }
    for n in &bag.notes {
        eprintln!("warning: {}: {n}", path.display());
    }
    Ok(bag)
}

/// The replay core's options from the command line; the output bag goes into `out_dir`.
fn replay_options(args: &ReplayArgs, out_dir: &Path) -> ReplayOptions {
    ReplayOptions {
        coupling: args.model.coupling(args.delta),
        steps_per_rev: args.steps_per_rev,
        film: args.film.into(),
        session: SessionSettings {
            state_rate_hz: args.state_rate_hz,
            ..SessionSettings::default()
        },
        remaps: args.remap.clone(),
        speed_unit: args.speed_unit,
        probe_points: args.probe_point.clone(),
        probe_signals: args.probe_signal.clone(),
        rate: if args.fast { None } else { args.rate },
        duration_s: args.duration,
        out_bag: (!args.no_bag).then(|| out_dir.join("bag")),
        forecast: forecast_options(args),
        ..ReplayOptions::default()
    }
}

/// The replay with a progress bar (share of the bag, times real time) on the terminal.
fn replay_with_progress(
    bag: &Bag,
    rotor: &Rotor,
    options: &ReplayOptions,
) -> anyhow::Result<(
    crate::replay::ReplayReport,
    Vec<crate::replay::compare::StationComparison>,
)> {
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "replay [{elapsed_precise}] {wide_bar} {percent}% of the bag, {msg}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let started = std::time::Instant::now();
    let bag_s = bag
        .time_span_ns()
        .map_or(0.0, |(a, b)| (b - a) as f64 * 1e-9);
    let out = replay(bag, rotor, options, &mut |done| {
        bar.set_position((done * 1000.0) as u64);
        let wall = started.elapsed().as_secs_f64();
        if wall > 0.0 {
            bar.set_message(format!("{:.2}× real time", done * bag_s / wall));
        }
    })?;
    bar.finish_and_clear();
    Ok(out)
}

/// One probe station's plots: predicted over measured orbit, order spectrum, waterfall and
/// amplitude against speed.
fn write_station_plots(
    out_dir: &Path,
    c: &crate::replay::compare::StationComparison,
) -> anyhow::Result<()> {
    let name = &c.station;
    crate::plot::orbit_comparison_svg(
        &out_dir.join(format!("orbit_{name}.svg")),
        &format!("{name}: predicted over measured orbit, last 4 revolutions"),
        &c.recent_samples(4),
        c.clearance_m(),
    )?;
    if let Some((m, p)) = c.summary_spectra() {
        crate::plot::spectrum_comparison_svg(
            &out_dir.join(format!("spectrum_{name}.svg")),
            &format!("{name}: order spectrum, last revolutions of the bag"),
            &m,
            &p,
        )?;
    }
    crate::plot::waterfall_svg(
        &out_dir.join(format!("waterfall_{name}.svg")),
        &format!("{name}: order spectra through the bag (blocks of 8 revolutions)"),
        &c.block_spectra,
    )?;
    crate::plot::amplitude_speed_svg(
        &out_dir.join(format!("amplitude_speed_{name}.svg")),
        &format!("{name}: amplitude against speed (blocks of 8 revolutions)"),
        &c.blocks,
    )
}

/// One probe station's engineering views from the measured data (issue 16): the 1X Bode and
/// polar plots per probe axis, the shaft centerline with the static-equilibrium `locus`, the
/// full-spectrum cascade and the orbit in the probes' frame.
fn write_station_views(
    out_dir: &Path,
    c: &crate::replay::compare::StationComparison,
    locus: &[crate::plot::CenterlinePoint],
) -> anyhow::Result<()> {
    let name = &c.station;
    let axes_deg = c.axes_rad().map(f64::to_degrees);
    crate::plot::one_x_bode_svg(
        &out_dir.join(format!("bode_{name}.svg")),
        &format!("{name}: 1X Bode plot, measured and predicted (blocks of 8 revolutions)"),
        &c.blocks,
        axes_deg,
    )?;
    crate::plot::one_x_polar_svg(
        &out_dir.join(format!("polar_{name}.svg")),
        &format!("{name}: 1X polar plot, measured and predicted"),
        &c.blocks,
        axes_deg,
    )?;
    crate::plot::replay_centerline_svg(
        &out_dir.join(format!("centerline_{name}.svg")),
        &format!("{name}: shaft centerline (mean position), measured and predicted"),
        &c.blocks,
        locus,
        c.clearance_m(),
        c.mean_not_measured.as_deref(),
    )?;
    crate::plot::full_spectrum_cascade_svg(
        &out_dir.join(format!("full_spectrum_{name}.svg")),
        &format!("{name}: full-spectrum cascade of x + iy (blocks of 8 revolutions)"),
        &c.block_spectra,
    )?;
    crate::plot::orbit_probe_frame_svg(
        &out_dir.join(format!("orbit_probe_frame_{name}.svg")),
        &format!("{name}: orbit in the machine frame and in the probes' frame, last 4 revolutions"),
        &c.recent_samples(4),
        c.axes_rad(),
    )
}

/// Refuses an output directory that is the input bag, lies inside it or holds it: the replay
/// writes into `out` and replaces `out/bag`, and must never write into or over its input.
fn refuse_overlap(bag: &Path, out: &Path) -> anyhow::Result<()> {
    let (bag_abs, out_abs) = (resolved_path(bag), resolved_path(out));
    anyhow::ensure!(
        !out_abs.starts_with(&bag_abs) && !bag_abs.starts_with(&out_abs),
        "--out {}: {} the input bag {}; choose an output directory apart from it",
        out.display(),
        if out_abs.starts_with(&bag_abs) {
            "is or lies inside"
        } else {
            "holds"
        },
        bag.display()
    );
    Ok(())
}

/// The files a replay writes beside `bag/`: its report, `--calibrate`'s calibration and the
/// plots of each probe station.
const OUTPUT_FILES: [&str; 2] = ["report.json", "calibration.json"];
const PLOT_PREFIXES: [&str; 8] = [
    "orbit_",
    "spectrum_",
    "waterfall_",
    "amplitude_speed_",
    "bode_",
    "polar_",
    "centerline_",
    "full_spectrum_",
];

/// Creates `dir`, or clears a previous replay's output in it (its bag, report or calibration and
/// plots, so that no file of an earlier run is left beside the new ones; an empty directory, such
/// as a failed run leaves, is used as it is; any other directory holding neither `report.json`
/// nor `calibration.json` is refused, so nothing of the user's is overwritten).
fn prepare_out_dir(dir: &Path) -> anyhow::Result<()> {
    if !dir.exists() {
        return std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()));
    }
    let mut listing =
        std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    if listing.next().is_none() {
        return Ok(());
    }
    anyhow::ensure!(
        OUTPUT_FILES.iter().any(|f| dir.join(f).exists()),
        "--out {}: exists and is not a previous replay's output (no report.json or calibration.json); choose another",
        dir.display()
    );
    let bag = dir.join("bag");
    if bag.exists() {
        std::fs::remove_dir_all(&bag)
            .with_context(|| format!("removing the previous output bag {}", bag.display()))?;
    }
    let listing = std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))?;
    for entry in listing {
        let path = entry?.path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let previous = name.is_some_and(|n| {
            OUTPUT_FILES.contains(&n.as_str())
                || (n.ends_with(".svg") && PLOT_PREFIXES.iter().any(|p| n.starts_with(p)))
        });
        if previous && path.is_file() {
            std::fs::remove_file(&path)
                .with_context(|| format!("removing the previous output {}", path.display()))?;
        }
    }
    Ok(())
}

// --- calibration from measurements (issue 12) ---

/// `--calibrate`: fit on the bag, replay before (machine file) and after (fitted values), write
/// `calibration.json` (estimates and both reports) and print the comparison.
fn run_calibrated(
    args: &ReplayArgs,
    bag: &Bag,
    rotor: &Rotor,
    options: &ReplayOptions,
    out_dir: &Path,
) -> anyhow::Result<()> {
    let span = bag
        .time_span_ns()
        .map_or(0.0, |(a, b)| (b - a) as f64 * 1e-9);
    let window = args.calibrate_window.map_or([0.0, span], |(a, b)| [a, b]);
    let (cal, calibrated) = crate::replay::calibration::calibrate_bag(
        bag,
        rotor,
        &options.remaps,
        &options.probe_signals,
        window,
        options.calibration_refinement(),
    )
    .context("calibration")?;
    let (before, _) = replay(bag, rotor, options, &mut |_| {})?;
    let mut after_options = options.clone();
    after_options.out_bag = None;
    // the fitted unbalance replaces the one the bag carries
    after_options.remaps.insert(
        0,
        (
            crate::topics::UNBALANCE.into(),
            "/rotor_twin/unbalance_recorded".into(),
        ),
    );
    let (after, _) = replay(bag, &calibrated, &after_options, &mut |_| {})?;
    let comparison = crate::replay::calibration::compare_before_after(&before, &after, window);
    let json = serde_json::json!({
        "calibration": cal,
        "comparison": comparison,
        "before": before,
        "after": after
    });
    let text = serde_json::to_string_pretty(&json)?;
    std::fs::write(out_dir.join("calibration.json"), &text)?;
    if args.json {
        return super::print_out(&format!("{text}\n"));
    }
    super::print_out(&format!(
        "{}{}output: {}\n",
        calibration_summary(&cal),
        comparison_summary(&comparison),
        out_dir.display()
    ))
}

/// The estimates, as text.
fn calibration_summary(cal: &crate::replay::calibration::BagCalibration) -> String {
    let mut s = format!(
        "calibration on bag time {:.2}-{:.2} s ({} windows of {} revolutions, {} left out){}\n",
        cal.window_s[0],
        cal.window_s[1],
        cal.windows_used,
        crate::replay::calibration::CALIBRATION_WINDOW_REVS,
        cal.windows_skipped,
        if cal.speed_from_keyphasor {
            "; speed from the keyphasor (no speed topic)"
        } else {
            ""
        }
    );
    match (&cal.viscosity, &cal.viscosity_not_fitted) {
        (Some(v), _) => {
            s += &format!(
                "  viscosity x{:.4} +- {:.4} of the machine file's",
                v.scale, v.scale_std
            );
            if let (Some(t), Some(dt), Some(off)) =
                (v.temperature_c, v.temperature_std_k, v.temperature_offset_k)
            {
                s += &format!(" (oil {t:.1} +- {dt:.1} degC, {off:+.1} K from the design point)");
            }
            s += "\n";
        }
        (None, why) => s += &format!("  viscosity {}\n", why.as_deref().unwrap_or("not fitted")),
    }
    let u = &cal.unbalance;
    for p in &u.planes {
        s += &match &cal.phase_null_reason {
            None => format!(
                "  unbalance at node {}: {:.1} g.mm at {:.1} deg; correction {:.3} g at {:.0} mm, {:.1} deg\n",
                p.node, p.magnitude_g_mm, p.phase_deg, p.correction.mass_g,
                p.correction.radius_m * 1e3, p.correction.angle_deg
            ),
            Some(why) => format!(
                "  unbalance at node {}: {:.1} g.mm, phase null ({why}); correction {:.3} g at {:.0} mm\n",
                p.node, p.magnitude_g_mm, p.correction.mass_g, p.correction.radius_m * 1e3
            ),
        };
    }
    let on = match (u.nonlinear_updates, &u.not_refined) {
        (_, Some(why)) => format!("the linear model (not refined on the nonlinear twin: {why})"),
        (0, None) => "the linear model".to_string(),
        (n, None) => format!("the nonlinear twin, after {n} update(s) of the linear fit"),
    };
    s += &format!(
        "  1X residual {:.3} um RMS ({:.1} %) on {on}, condition number {:.2}\n",
        u.residual_rms_m * 1e6,
        100.0 * u.relative_residual,
        u.condition_number
    );
    for r in &cal.runouts {
        let v = r.vector.map_or(String::new(), |v| {
            format!(
                ": {:.2} um at {:.1} deg",
                v.amplitude_m * 1e6,
                v.phase_lag_deg
            )
        });
        s += &format!("  runout of {}: {}{v}\n", r.probe, r.source);
    }
    s
}

/// The before/after comparison, as text.
fn comparison_summary(c: &crate::replay::calibration::CalibrationComparison) -> String {
    let pct = |x: Option<f64>| x.map_or("-".into(), |e| format!("{:.1} %", 100.0 * e));
    let signed = |x: Option<f64>| x.map_or("-".into(), |e| format!("{:+.1} %", 100.0 * e));
    let deg = |x: Option<[f64; 2]>| x.map_or("null".into(), |[a, b]| format!("{a:.1}/{b:.1} deg"));
    let sdeg =
        |x: Option<[f64; 2]>| x.map_or("null".into(), |[a, b]| format!("{a:+.1}/{b:+.1} deg"));
    let mut s = String::new();
    for st in &c.stations {
        s += &format!(
            "  {}: over the fitted window ({} blocks of 8 revolutions, mean |predicted - measured|) 1X amplitude error before {}, after {}; phase lag error (probe axes) before {}, after {}\n",
            st.station,
            st.blocks_in_window,
            pct(st.amplitude_error_window[0]),
            pct(st.amplitude_error_window[1]),
            deg(st.phase_lag_error_window_deg[0]),
            deg(st.phase_lag_error_window_deg[1]),
        );
        s += &format!(
            "    over the bag's last 32 revolutions (predicted - measured): amplitude before {}, after {}; phase lag before {}, after {}{}\n",
            signed(st.amplitude_error_last[0]),
            signed(st.amplitude_error_last[1]),
            sdeg(st.phase_lag_error_last_deg[0]),
            sdeg(st.phase_lag_error_last_deg[1]),
            st.phase_null_reason
                .as_ref()
                .map_or(String::new(), |w| format!(" (phases null: {w})"))
        );
    }
    let rpm = |x: Option<f64>| x.map_or("-".into(), |v| format!("{v:.0} rpm"));
    s += &format!(
        "  onset: observed {}, predicted before {}, after {}\n",
        rpm(c.onset_observed_rpm),
        rpm(c.onset_predicted_rpm[0]),
        rpm(c.onset_predicted_rpm[1])
    );
    s
}
// --- end calibration from measurements ---

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_names_are_bounded_and_refused_with_the_reason() {
        // issue 15, item 13: an empty or 1 MB station name was taken, and echoed whole
        let huge = format!("{}=/x", "s".repeat(1 << 20));
        for s in [huge.as_str(), "=/x", " =/x"] {
            let point = parse_probe_point(s).unwrap_err();
            let signal = parse_probe_signal(s).unwrap_err();
            assert!(
                point.starts_with("--probe-point") && point.len() < 200,
                "{point:.200}"
            );
            assert!(
                signal.starts_with("--probe-signal") && signal.len() < 200,
                "{signal:.200}"
            );
        }
        assert_eq!(
            parse_probe_point("a=/p"),
            Ok(("/p".to_string(), "a".to_string()))
        );
    }
}
