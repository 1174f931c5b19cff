//! `rotor-twin response`: the unbalance response of the linear model (API 684): Bode and polar
//! plots at the bearings and probe stations, peaks, amplification factors, separation margins.

use crate::rotor::{
    response_peaks, static_solution, unbalance_response, unbalance_response_zone_following,
    ResponsePeak, Rotor, Station, StationResponse,
};
use anyhow::Context;
use clap::Args;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Unbalance response of the linear model: 1X amplitude and phase lag against speed.
#[derive(Debug, Clone, Args)]
pub struct ResponseArgs {
    /// Machine and speeds.
    #[command(flatten)]
    range: super::MachineSpeedRange,
    /// Minimum operating speed for the separation margins (rpm); default the rated speed.
    #[arg(long)]
    min_operating_rpm: Option<f64>,
    /// Maximum continuous speed for the separation margins (rpm); default the rated speed.
    #[arg(long)]
    max_continuous_rpm: Option<f64>,
    /// Print one JSON object instead of tables.
    #[arg(long)]
    json: bool,
    /// Write the Bode plot to PREFIX_bode.svg and the polar plot to PREFIX_polar.svg.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// The film's inertia (as `modes`).
    #[command(flatten)]
    inertia: super::modes::FilmInertiaArgs,
}

/// One station of the report.
#[derive(Debug, Serialize)]
struct StationReport {
    #[serde(flatten)]
    station: Station,
    peaks: Vec<ResponsePeak>,
    response: Vec<StationResponse>,
}

/// The `--json` report.
#[derive(Debug, Serialize)]
struct ResponseReport {
    machine: String,
    /// The film's inertia of the linearisation (added mass in the mass matrix; with `full` the
    /// convective inertia's stiffness and damping, zone held or following).
    film_inertia: String,
    /// Unbalances applied: node, m·e (g·mm), heavy-spot angle (deg).
    unbalance_g_mm: Vec<(usize, f64, f64)>,
    min_operating_rpm: f64,
    max_continuous_rpm: f64,
    speeds_rpm: Vec<f64>,
    stations: Vec<StationReport>,
}

fn speed_grid(args: &ResponseArgs, rated: f64) -> anyhow::Result<Vec<f64>> {
    Ok(args.range.grid(rated, 200.0, 5000.0)?.0)
}

/// The file `--plot PREFIX` writes for `suffix` (`_bode.svg`, `_polar.svg`).
fn plot_path(prefix: &Path, suffix: &str) -> PathBuf {
    let mut p = prefix.as_os_str().to_owned();
    p.push(suffix);
    PathBuf::from(p)
}

/// The operating speed range (rpm; default the rated speed) and the plot files, checked before
/// anything is computed.
fn operating_range(args: &ResponseArgs, rated: f64) -> anyhow::Result<(f64, f64)> {
    let n_min = args.min_operating_rpm.unwrap_or(rated);
    let n_max = args.max_continuous_rpm.unwrap_or(rated);
    anyhow::ensure!(
        n_min.is_finite() && n_min > 0.0 && n_max >= n_min,
        "invalid --min-operating-rpm {} / --max-continuous-rpm {}: need 0 < min ≤ max",
        crate::units::shown_value(n_min),
        crate::units::shown_value(n_max)
    );
    if let Some(prefix) = &args.plot {
        for suffix in ["_bode.svg", "_polar.svg"] {
            super::check_output("--plot", &plot_path(prefix, suffix), super::Output::File)?;
        }
    }
    Ok((n_min, n_max))
}

pub(crate) fn run(args: &ResponseArgs) -> anyhow::Result<()> {
    let desc = args.range.machine()?;
    let mut rotor = Rotor::from_description(&desc);
    let follow = args.inertia.apply(&mut rotor)?;
    let rated = desc.rated_speed_rpm;
    let speeds = speed_grid(args, rated)?;
    let (n_min, n_max) = operating_range(args, rated)?;
    anyhow::ensure!(
        !rotor.unbalance.is_empty(),
        "the machine has no unbalance: add one under `unbalance:` in the machine file"
    );
    let statics = static_solution(&rotor).context("static deflection")?;
    let r = match follow {
        Some(step) => unbalance_response_zone_following(&rotor, &statics, &speeds, step),
        None => unbalance_response(&rotor, &statics, &speeds),
    }
    .context("unbalance response")?;
    let stations = r
        .stations
        .iter()
        .zip(&r.response)
        .map(|(st, resp)| {
            let amp: Vec<f64> = resp.iter().map(|s| s.major_semi_axis_m).collect();
            StationReport {
                station: st.clone(),
                peaks: response_peaks(&speeds, &amp, n_min, n_max),
                response: resp.clone(),
            }
        })
        .collect();
    let report = ResponseReport {
        machine: desc.name.clone(),
        film_inertia: super::modes::FilmInertiaArgs::model(&rotor, follow),
        unbalance_g_mm: desc
            .unbalance
            .iter()
            .map(|u| (u.node, u.magnitude_g_mm, u.phase_deg))
            .collect(),
        min_operating_rpm: n_min,
        max_continuous_rpm: n_max,
        speeds_rpm: speeds,
        stations,
    };
    write_plots(args, &report)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_tables(&report);
    }
    Ok(())
}

/// The `--plot PREFIX` Bode and polar plots.
fn write_plots(args: &ResponseArgs, report: &ResponseReport) -> anyhow::Result<()> {
    if let Some(prefix) = &args.plot {
        let with = |suffix: &str| plot_path(prefix, suffix);
        let curves: Vec<crate::plot::ResponseCurve> = report
            .stations
            .iter()
            .map(|s| crate::plot::ResponseCurve {
                name: &s.station.name,
                response: &s.response,
                peaks: &s.peaks,
            })
            .collect();
        for (path, bode) in [(with("_bode.svg"), true), (with("_polar.svg"), false)] {
            let mut title = format!(
                "Unbalance response ({}): {}",
                if bode { "Bode" } else { "polar, x" },
                report.machine
            );
            if report.film_inertia != super::modes::NO_FILM_INERTIA {
                title.push_str(&format!(" — {}", report.film_inertia));
            }
            let written = if bode {
                crate::plot::bode_svg(&path, &title, &report.speeds_rpm, &curves)
            } else {
                crate::plot::polar_svg(&path, &title, &report.speeds_rpm, &curves)
            };
            written.with_context(|| format!("writing {}", path.display()))?;
        }
    }
    Ok(())
}

fn print_tables(r: &ResponseReport) {
    println!(
        "rotor-twin response: {} (linear model, film bearings linearised at each speed; {})",
        r.machine, r.film_inertia
    );
    for (node, me, deg) in &r.unbalance_g_mm {
        println!("  unbalance {me:.1} g·mm at node {node}, {deg:.0}°");
    }
    println!(
        "  operating range {:.0}–{:.0} rpm; peaks of the 1X semi-major axis per station:",
        r.min_operating_rpm, r.max_continuous_rpm
    );
    println!(
        "    {:<22} {:>9} {:>11} {:>7} {:>10} {:>12}",
        "station", "peak rpm", "1X µm", "AF", "margin %", "API 684 %"
    );
    for s in &r.stations {
        if s.peaks.is_empty() {
            println!("    {:<22} no peak in the range", s.station.name);
        }
        for p in &s.peaks {
            let af = p
                .amplification_factor
                .map_or("—".to_string(), |a| format!("{a:.2}"));
            println!(
                "    {:<22} {:>9.0} {:>11.3} {:>7} {:>10.1} {:>12.1}{}",
                s.station.name,
                p.speed_rpm,
                p.amplitude_m * 1e6,
                af,
                p.separation_margin_pct,
                p.required_margin_pct,
                if p.meets_api_684 { "" } else { "  NOT MET" }
            );
        }
    }
}
