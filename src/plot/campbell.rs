//! The Campbell diagram.

use super::labels::{placed_text, LabelPlacer};
use super::legend::{draw_side_legend, Entry, Swatch};
use crate::rotor::{CampbellPoint, CriticalSpeed, Mode, WhirlDirection};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

const FORWARD: RGBColor = RGBColor(31, 90, 200);
const BACKWARD: RGBColor = RGBColor(20, 150, 60);
const UNSTABLE: RGBColor = RGBColor(220, 30, 30);
const DAMPED_CROSSING: RGBColor = RGBColor(120, 120, 120);

/// Log decrement below which a point is drawn unstable: below the round-off of an undamped
/// model's zero (the threshold search uses the same, `rotor::stability_threshold`).
const UNSTABLE_LOG_DEC: f64 = -1e-6;

fn colour(m: &Mode) -> RGBColor {
    if m.log_dec < UNSTABLE_LOG_DEC {
        UNSTABLE
    } else if m.direction == WhirlDirection::Forward {
        FORWARD
    } else {
        BACKWARD
    }
}

/// The points of one mode track: (speed rpm, mode) where the track is present.
fn track(points: &[CampbellPoint], id: usize) -> Vec<(f64, Mode)> {
    points
        .iter()
        .filter_map(|p| {
            let j = p.tracks.iter().position(|&t| t == id)?;
            Some((p.speed_rpm, p.modes[j]))
        })
        .collect()
}

/// The extent of the diagram: speeds (rpm), frequencies (Hz), log decrements, mode tracks.
struct Extent {
    x0: f64,
    x1: f64,
    f_max: f64,
    d_lo: f64,
    d_hi: f64,
    ids: Vec<usize>,
}

impl Extent {
    fn of(points: &[CampbellPoint]) -> Self {
        let (x0, x1) = (
            points.first().map_or(0.0, |p| p.speed_rpm),
            points.last().map_or(1.0, |p| p.speed_rpm),
        );
        let modes = || points.iter().flat_map(|p| p.modes.iter());
        let f_max = modes().map(|m| m.frequency_hz).fold(x1 / 60.0, f64::max) * 1.05;
        let (d_min, d_max) = modes()
            .map(|m| m.log_dec)
            .fold((0.0_f64, 0.1_f64), |(a, b), d| (a.min(d), b.max(d)));
        let span = (d_max - d_min).max(0.1);
        let mut ids: Vec<usize> = points
            .iter()
            .flat_map(|p| p.tracks.iter().copied())
            .collect();
        ids.sort_unstable();
        ids.dedup();
        Self {
            x0,
            x1,
            f_max,
            d_lo: d_min - 0.05 * span,
            d_hi: d_max + 0.05 * span,
            ids,
        }
    }
}

/// Writes a Campbell diagram to `path`: damped natural frequencies against speed, each mode a line
/// (followed by shape) with its points, forward whirl in blue, backward in green, unstable points
/// (negative log decrement) in red; the running frequency 1X and 0.5X as labelled lines; the
/// forward critical speeds as diamonds on 1X, each labelled with its speed where the label finds
/// room clear of the others; the forward modes that cross 1X critically damped (API 684:
/// AF < 2.5, `damped_crossings`) as grey rings, unlabelled; the stability threshold (rpm) as a
/// vertical line. The lower panel shows the logarithmic decrements, unclipped. The legend has
/// its own panel.
pub fn campbell_svg(
    path: &Path,
    title: &str,
    points: &[CampbellPoint],
    threshold_rpm: Option<f64>,
    critical_speeds: &[CriticalSpeed],
    damped_crossings: &[CriticalSpeed],
) -> anyhow::Result<()> {
    let e = Extent::of(points);
    let root = SVGBackend::new(path, (1100, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (plots, legend_area) = root.split_horizontally(860);
    let (upper, lower) = plots.split_vertically(560);
    frequency_panel(
        &upper,
        &e,
        points,
        threshold_rpm,
        [critical_speeds, damped_crossings],
    )?;
    log_dec_panel(&lower, &e, points, threshold_rpm)?;
    let mut entries = vec![
        Entry::new(Swatch::Dot(FORWARD), "forward whirl"),
        Entry::new(Swatch::Dot(BACKWARD), "backward whirl"),
        Entry::new(Swatch::Dot(UNSTABLE), "unstable (log dec < 0)"),
        Entry::new(Swatch::Line(BLACK, 2), "1X running speed"),
        Entry::new(Swatch::Line(RGBColor(140, 140, 140), 1), "0.5X"),
        Entry::new(Swatch::Diamond(BLACK), "forward critical speed"),
        Entry::new(Swatch::Text, "(API 684: AF = 1/(2ζ) ≥ 2.5)"),
    ];
    if !damped_crossings.is_empty() {
        entries.push(Entry::new(
            Swatch::Ring(DAMPED_CROSSING),
            "crossing of 1X, critically damped",
        ));
        entries.push(Entry::new(Swatch::Text, "(AF < 2.5: not a critical speed)"));
    }
    if let Some(t) = threshold_rpm {
        entries.push(Entry::new(
            Swatch::Line(UNSTABLE, 2),
            format!("threshold {t:.0} rpm"),
        ));
    }
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

type Area<'a> = DrawingArea<SVGBackend<'a>, plotters::coord::Shift>;

/// The upper panel: frequencies, the 1X and 0.5X lines, critical speeds and critically damped
/// crossings (`crossings`), the threshold.
fn frequency_panel(
    area: &Area,
    e: &Extent,
    points: &[CampbellPoint],
    threshold_rpm: Option<f64>,
    crossings: [&[CriticalSpeed]; 2],
) -> anyhow::Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(e.x0..e.x1, 0.0..e.f_max)?;
    chart
        .configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc("damped natural frequency (Hz)")
        .draw()?;
    let mut placer = LabelPlacer::in_chart(&chart);
    for (ratio, label, shade) in [(1.0, "1X", 0.9), (0.5, "0.5X", 0.45)] {
        // the line ends where it leaves the frame; its label sits at its end
        let x_end = e.x1.min(e.f_max * 60.0 / ratio);
        chart.draw_series(LineSeries::new(
            [(e.x0, e.x0 * ratio / 60.0), (x_end, x_end * ratio / 60.0)],
            BLACK
                .mix(shade)
                .stroke_width(if ratio == 1.0 { 2 } else { 1 }),
        ))?;
        let at = (0.97 * x_end, 0.97 * x_end * ratio / 60.0);
        let px = chart.backend_coord(&at);
        let (x, y) = (px.0 as f64, px.1 as f64);
        placer.reserve([x - 40.0, y - 16.0, x, y]);
        chart.draw_series(std::iter::once(Text::new(
            label,
            at,
            ("sans-serif", 16)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Right, VPos::Bottom)),
        )))?;
    }
    draw_tracks(&mut chart, &e.ids, points, |m| m.frequency_hz)?;
    // the labels keep clear of the modes' points
    for p in points {
        for m in &p.modes {
            placer.reserve_marker(chart.backend_coord(&(p.speed_rpm, m.frequency_hz)), 3.0);
        }
    }
    let [critical, damped] = crossings;
    chart.draw_series(damped.iter().map(|c| {
        Circle::new(
            (c.speed_rpm, c.speed_rpm / 60.0),
            6,
            DAMPED_CROSSING.stroke_width(2),
        )
    }))?;
    for c in critical {
        let at = (c.speed_rpm, c.speed_rpm / 60.0);
        placer.reserve_marker(chart.backend_coord(&at), 8.0);
        chart.draw_series(std::iter::once(EmptyElement::at(at) + diamond(8)))?;
    }
    for c in critical {
        let at = (c.speed_rpm, c.speed_rpm / 60.0);
        let text = format!("{:.0} rpm", c.speed_rpm);
        if let Some(o) = placer.place(chart.backend_coord(&at), 8.0, &text, 14.0) {
            chart.draw_series(std::iter::once(
                EmptyElement::at(at) + placed_text(text, o, 14.0, &BLACK),
            ))?;
        }
    }
    if let Some(t) = threshold_rpm {
        chart.draw_series(LineSeries::new(
            [(t, 0.0), (t, e.f_max)],
            UNSTABLE.stroke_width(2),
        ))?;
    }
    Ok(())
}

/// The lower panel: logarithmic decrements, the zero line, the threshold.
fn log_dec_panel(
    area: &Area,
    e: &Extent,
    points: &[CampbellPoint],
    threshold_rpm: Option<f64>,
) -> anyhow::Result<()> {
    let mut decs = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(e.x0..e.x1, e.d_lo..e.d_hi)?;
    decs.configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc("logarithmic decrement (–)")
        .draw()?;
    decs.draw_series(LineSeries::new([(e.x0, 0.0), (e.x1, 0.0)], BLACK))?;
    if let Some(t) = threshold_rpm {
        decs.draw_series(LineSeries::new(
            [(t, e.d_lo), (t, e.d_hi)],
            UNSTABLE.stroke_width(2),
        ))?;
    }
    draw_tracks(&mut decs, &e.ids, points, |m| m.log_dec)?;
    Ok(())
}

/// Each mode track as a line through its points, the value `y` of each mode against speed.
fn draw_tracks<'a>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    ids: &[usize],
    points: &[CampbellPoint],
    y: fn(&Mode) -> f64,
) -> anyhow::Result<()> {
    for &id in ids {
        let t = track(points, id);
        chart.draw_series(t.windows(2).map(|w| {
            PathElement::new(
                [(w[0].0, y(&w[0].1)), (w[1].0, y(&w[1].1))],
                colour(&w[1].1).mix(0.6).stroke_width(1),
            )
        }))?;
        chart.draw_series(
            t.iter()
                .map(|(s, m)| Circle::new((*s, y(m)), 3, colour(m).filled())),
        )?;
    }
    Ok(())
}

/// A hollow diamond marker of half-width `r` px.
fn diamond(r: i32) -> PathElement<(i32, i32)> {
    PathElement::new(
        [(0, -r), (r, 0), (0, r), (-r, 0), (0, -r)],
        BLACK.stroke_width(2),
    )
}
