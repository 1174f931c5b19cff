//! Unbalance-response plots: Bode (1X amplitude and phase lag against speed) and polar (the 1X
//! vector of x in the complex plane, 1:1).

use super::legend::{draw_side_legend, Entry, Swatch};
use crate::rotor::{ResponsePeak, StationResponse};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

/// One station's curve.
pub struct ResponseCurve<'a> {
    /// Station name.
    pub name: &'a str,
    /// Response at each speed.
    pub response: &'a [StationResponse],
    /// Its peaks.
    pub peaks: &'a [ResponsePeak],
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 90, 200),
    RGBColor(220, 90, 20),
    RGBColor(20, 150, 60),
    RGBColor(150, 40, 170),
    RGBColor(120, 90, 40),
    RGBColor(200, 30, 80),
];

/// The Bode plot: the 1X semi-major axis (µm) and the phase lag of x (deg) against speed, one
/// colour per station, peaks marked with their speed and amplification factor.
pub fn bode_svg(
    path: &Path,
    title: &str,
    speeds_rpm: &[f64],
    curves: &[ResponseCurve],
) -> anyhow::Result<()> {
    let (x0, x1) = (
        speeds_rpm.first().copied().unwrap_or(0.0),
        speeds_rpm.last().copied().unwrap_or(1.0),
    );
    let top = curves
        .iter()
        .flat_map(|c| c.response.iter().map(|r| r.major_semi_axis_m))
        .fold(1e-12, f64::max)
        * 1e6
        * 1.1;
    let root = SVGBackend::new(path, (1100, 850)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (plots, legend_area) = root.split_horizontally(860);
    let (upper, lower) = plots.split_vertically(480);
    let mut amp = ChartBuilder::on(&upper)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, 0.0..top)?;
    amp.configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc("1X semi-major axis (µm)")
        .draw()?;
    let mut phase = ChartBuilder::on(&lower)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, 0.0..360.0)?;
    phase
        .configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc("phase lag of x (deg)")
        .y_labels(9)
        .draw()?;
    let mut entries = Vec::new();
    for (c, colour) in curves.iter().zip(COLOURS.iter().cycle()) {
        amp.draw_series(LineSeries::new(
            speeds_rpm
                .iter()
                .zip(c.response)
                .map(|(s, r)| (*s, r.major_semi_axis_m * 1e6)),
            colour.stroke_width(2),
        ))?;
        // phase as points: it wraps at 360°
        phase.draw_series(
            speeds_rpm
                .iter()
                .zip(c.response)
                .map(|(s, r)| Circle::new((*s, r.x_phase_lag_deg), 2, colour.filled())),
        )?;
        draw_peaks(&mut amp, c.peaks, colour)?;
        entries.push(Entry::new(Swatch::Line(*colour, 2), c.name));
    }
    entries.push(Entry::new(
        Swatch::Dot(BLACK),
        "peak (speed, half-power AF)",
    ));
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// Each peak of one station on the amplitude chart: a ring with its speed and amplification
/// factor (µm on the y axis).
fn draw_peaks(
    amp: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    peaks: &[ResponsePeak],
    colour: &RGBColor,
) -> anyhow::Result<()> {
    for p in peaks {
        let label = match p.amplification_factor {
            Some(af) => format!("{:.0} rpm, AF {af:.1}", p.speed_rpm),
            None => format!("{:.0} rpm", p.speed_rpm),
        };
        let text = Text::new(
            label,
            (6, -16),
            ("sans-serif", 13).into_font().color(colour),
        );
        amp.draw_series(std::iter::once(
            EmptyElement::at((p.speed_rpm, p.amplitude_m * 1e6))
                + Circle::new((0, 0), 5, colour.stroke_width(2))
                + text,
        ))?;
    }
    Ok(())
}

/// The polar plot: the 1X vector of x, X = A e^{−i·lag}, in the complex plane (µm), 1:1, one
/// colour per station, speeds labelled along each curve.
pub fn polar_svg(
    path: &Path,
    title: &str,
    speeds_rpm: &[f64],
    curves: &[ResponseCurve],
) -> anyhow::Result<()> {
    let lim = curves
        .iter()
        .flat_map(|c| c.response.iter().map(|r| r.x_amplitude_m))
        .fold(1e-12, f64::max)
        * 1e6
        * 1.1;
    let root = SVGBackend::new(path, (1000, 760)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (plot_area, legend_area) = root.split_horizontally(730);
    // a square plotting area: equal pixels per µm on both axes
    let plot_area = super::square_chart_area(plot_area, 15, 40, 70);
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(-lim..lim, -lim..lim)?;
    chart
        .configure_mesh()
        .x_desc("Re X, in phase with the keyphasor (µm)")
        .y_desc("Im X (µm)")
        .draw()?;
    let mut entries = Vec::new();
    let every = (speeds_rpm.len() / 6).max(1);
    for (c, colour) in curves.iter().zip(COLOURS.iter().cycle()) {
        let pts: Vec<(f64, f64)> = c
            .response
            .iter()
            .map(|r| {
                let a = r.x_amplitude_m * 1e6;
                let lag = r.x_phase_lag_deg.to_radians();
                (a * lag.cos(), -a * lag.sin())
            })
            .collect();
        chart.draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(2)))?;
        chart.draw_series(pts.iter().zip(speeds_rpm).step_by(every).map(|(p, s)| {
            EmptyElement::at(*p)
                + Circle::new((0, 0), 3, colour.filled())
                + Text::new(format!("{s:.0}"), (5, 3), ("sans-serif", 12).into_font())
        }))?;
        entries.push(Entry::new(Swatch::Line(*colour, 2), c.name));
    }
    entries.push(Entry::new(Swatch::Dot(BLACK), "speed (rpm) marks"));
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}
