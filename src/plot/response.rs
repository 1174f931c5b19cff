//! Unbalance-response plots: Bode (1X amplitude and phase lag against speed) and polar (the 1X
//! vector of x in the complex plane, 1:1).

use super::labels::{placed_text, LabelPlacer};
use super::legend::{draw_side_legend, Entry, Swatch};
use crate::rotor::{ResponsePeak, StationResponse};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

/// The Bode plot's layout.
const BODE: super::BodeLayout = super::BodeLayout {
    size: (1100, 850),
    title_size: 22,
    plot_width: 860,
    amplitude_height: 480,
};

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

/// Stations whose responses are the same to round-off (a probe at a bearing's node) are one
/// curve on the plots: drawn once, named together, said to coincide. Returns, per curve drawn,
/// the indices of `curves` it stands for.
fn coincident_groups(curves: &[ResponseCurve]) -> Vec<Vec<usize>> {
    let scale = curves
        .iter()
        .flat_map(|c| c.response.iter().map(|r| r.major_semi_axis_m))
        .fold(1e-30, f64::max);
    let same = |a: &ResponseCurve, b: &ResponseCurve| {
        a.response.len() == b.response.len()
            && a.response.iter().zip(b.response).all(|(p, q)| {
                (p.x_amplitude_m - q.x_amplitude_m).abs() <= 1e-9 * scale
                    && (p.major_semi_axis_m - q.major_semi_axis_m).abs() <= 1e-9 * scale
                    && (p.x_phase_lag_deg - q.x_phase_lag_deg).abs() <= 1e-6
            })
    };
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        match groups.iter_mut().find(|g| same(&curves[g[0]], c)) {
            Some(g) => g.push(i),
            None => groups.push(vec![i]),
        }
    }
    groups
}

/// The legend entries of the drawn curves: one line per group, coinciding stations named
/// together.
fn curve_entries(curves: &[ResponseCurve], groups: &[Vec<usize>]) -> Vec<Entry> {
    let mut entries = Vec::new();
    for (g, colour) in groups.iter().zip(COLOURS.iter().cycle()) {
        entries.push(Entry::new(Swatch::Line(*colour, 2), curves[g[0]].name));
        for &i in &g[1..] {
            entries.push(Entry::new(
                Swatch::Text,
                format!("= {} (coincide)", curves[i].name),
            ));
        }
    }
    entries
}

/// The Bode plot: the 1X semi-major axis (µm) and the phase lag of x (deg) against speed, one
/// colour per station (stations that coincide drawn once and named together), peaks marked with
/// their speed and amplification factor, the labels placed clear of one another.
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
    let super::BodeCharts {
        root,
        amplitude: mut amp,
        mut phase,
        legend: legend_area,
    } = super::bode_plot(
        path,
        &BODE,
        title,
        (x0, x1),
        top,
        ("1X semi-major axis (µm)", "phase lag of x (deg)"),
    )?;
    let groups = coincident_groups(curves);
    let mut placer = LabelPlacer::in_chart(&amp);
    for (g, colour) in groups.iter().zip(COLOURS.iter().cycle()) {
        let c = &curves[g[0]];
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
        draw_peaks(&mut amp, &mut placer, c.peaks, colour)?;
    }
    let mut entries = curve_entries(curves, &groups);
    entries.push(Entry::new(
        Swatch::Dot(BLACK),
        "peak (speed, half-power AF)",
    ));
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// Each peak of one station on the amplitude chart: a ring with its speed and amplification
/// factor (µm on the y axis), the label where `placer` finds room.
fn draw_peaks(
    amp: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    placer: &mut LabelPlacer,
    peaks: &[ResponsePeak],
    colour: &RGBColor,
) -> anyhow::Result<()> {
    for p in peaks {
        let at = (p.speed_rpm, p.amplitude_m * 1e6);
        placer.reserve_marker(amp.backend_coord(&at), 6.0);
        amp.draw_series(std::iter::once(
            EmptyElement::at(at) + Circle::new((0, 0), 5, colour.stroke_width(2)),
        ))?;
    }
    for p in peaks {
        let at = (p.speed_rpm, p.amplitude_m * 1e6);
        let label = match p.amplification_factor {
            Some(af) => format!("{:.0} rpm, AF {af:.1}", p.speed_rpm),
            None => format!("{:.0} rpm", p.speed_rpm),
        };
        if let Some(o) = placer.place(amp.backend_coord(&at), 6.0, &label, 13.0) {
            amp.draw_series(std::iter::once(
                EmptyElement::at(at) + placed_text(label, o, 13.0, colour),
            ))?;
        }
    }
    Ok(())
}

/// The polar plot: the 1X vector of x, X = A e^{−i·lag}, in the complex plane (µm), 1:1, one
/// colour per station (stations that coincide drawn once and named together), speeds labelled
/// along each curve where a label finds room clear of the others and of the markers.
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
    // a square plotting area: equal pixels per µm on both axes
    let (root, mut chart, legend_area) = super::square_plot(
        path,
        &super::SQUARE_1000,
        title,
        lim,
        ("Re X, in phase with the keyphasor (µm)", "Im X (µm)"),
    )?;
    let every = (speeds_rpm.len() / 6).max(1);
    let groups = coincident_groups(curves);
    let mut placer = LabelPlacer::in_chart(&chart);
    let mut marks = Vec::new();
    for (g, colour) in groups.iter().zip(COLOURS.iter().cycle()) {
        let pts: Vec<(f64, f64)> = curves[g[0]]
            .response
            .iter()
            .map(|r| {
                let a = r.x_amplitude_m * 1e6;
                let lag = r.x_phase_lag_deg.to_radians();
                (a * lag.cos(), -a * lag.sin())
            })
            .collect();
        chart.draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(2)))?;
        for (p, s) in pts.iter().zip(speeds_rpm).step_by(every) {
            chart.draw_series(std::iter::once(Circle::new(*p, 3, colour.filled())))?;
            placer.reserve_marker(chart.backend_coord(p), 3.0);
            marks.push((*p, *s));
        }
    }
    for (p, s) in marks {
        let text = format!("{s:.0}");
        if let Some(o) = placer.place(chart.backend_coord(&p), 3.0, &text, 12.0) {
            chart.draw_series(std::iter::once(
                EmptyElement::at(p) + placed_text(text, o, 12.0, &BLACK),
            ))?;
        }
    }
    let mut entries = curve_entries(curves, &groups);
    entries.push(Entry::new(Swatch::Dot(BLACK), "speed (rpm) marks"));
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}
