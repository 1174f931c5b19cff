//! The engineering views of a replay from the bag's measured data (issue 16), each measured
//! beside predicted: the 1X Bode and polar plots per probe axis (API 670 phase lag, from the
//! keyphasor), the shaft centerline (mean journal position in the clearance circle, with the
//! static-equilibrium locus), the full-spectrum cascade (forward and reverse orders of x + iy)
//! and the orbit in the probes' own frame beside the machine frame, with keyphasor dots.

use super::labels::{placed_text, LabelPlacer};
use super::legend::{draw_side_legend, Entry, Swatch};
use crate::replay::compare::{BlockSpectra, Sample, WindowComparison, BLOCK_REVS};
use crate::signals::PhaseReference;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::f64::consts::TAU;
use std::path::Path;

const MEASURED: RGBColor = RGBColor(200, 30, 30);
const MEASURED_Y: RGBColor = RGBColor(240, 140, 20);
const PREDICTED: RGBColor = RGBColor(30, 60, 200);
const PREDICTED_Y: RGBColor = RGBColor(20, 170, 190);

/// The square plots of this module: 1100 × 760 px, the legend right of 730 px.
const WIDE_SQUARE: super::SquareLayout = super::SquareLayout {
    size: (1100, 760),
    title_size: 20,
    plot_width: 730,
    y_label: 70,
};

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The four 1X series of the Bode and polar plots: (measured?, axis, colour, label).
fn one_x_series(axes_deg: [f64; 2]) -> [(bool, usize, RGBColor, String); 4] {
    let l = |what: &str, j: usize| format!("{what}, probe axis {} ({:.0}°)", j + 1, axes_deg[j]);
    [
        (true, 0, MEASURED, l("measured", 0)),
        (true, 1, MEASURED_Y, l("measured", 1)),
        (false, 0, PREDICTED, l("predicted", 0)),
        (false, 1, PREDICTED_Y, l("predicted", 1)),
    ]
}

/// The legend entries of the four 1X series, measured a dot, predicted a ring, and the note of
/// one point per block.
fn series_entries(series: &[(bool, usize, RGBColor, String)]) -> Vec<Entry> {
    let mut entries: Vec<Entry> = series
        .iter()
        .map(|(m, _, c, l)| {
            let s = if *m {
                Swatch::Dot(*c)
            } else {
                Swatch::Ring(*c)
            };
            Entry::new(s, l.clone())
        })
        .collect();
    entries.push(Entry::new(
        Swatch::Text,
        format!("one point per {BLOCK_REVS} revolutions"),
    ));
    entries
}

/// A marker of a series: measured filled, predicted hollow.
fn marker(p: (f64, f64), colour: RGBColor, measured: bool) -> Circle<(f64, f64), u32> {
    if measured {
        Circle::new(p, 3, colour.filled())
    } else {
        Circle::new(p, 4, colour.stroke_width(1))
    }
}

/// The speed range of `blocks` (rpm), padded so that a hold stands inside the frame.
fn speed_range(blocks: &[WindowComparison]) -> (f64, f64) {
    let (lo, hi) = blocks
        .iter()
        .map(|b| b.speed_rpm)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| {
            (a.0.min(v), a.1.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = (0.04 * (hi - lo)).max(0.01 * hi.abs()).max(1.0);
    (lo - pad, hi + pad)
}

/// Why the phases of `blocks` are missing (None if some block has them).
fn phase_missing(blocks: &[WindowComparison]) -> Option<String> {
    if blocks.iter().any(|b| b.measured.one_x_probe_axes.is_some()) {
        return None;
    }
    Some(
        blocks
            .iter()
            .find_map(|b| b.phase_null_reason)
            .unwrap_or("no 8-revolution block was compared")
            .to_string(),
    )
}

/// Measured 1X Bode plot from a replay: per probe axis, the 1X amplitude (µm, zero to peak)
/// and, below, the phase lag (deg, API 670: keyphasor to the next positive peak) against speed,
/// one point per block of 8 revolutions, measured (filled) beside predicted (hollow). Without a
/// keyphasor the amplitudes only, and the phase panel says why the phase is missing.
pub fn one_x_bode_svg(
    path: &Path,
    title: &str,
    blocks: &[WindowComparison],
    axes_deg: [f64; 2],
) -> anyhow::Result<()> {
    let (x0, x1) = speed_range(blocks);
    let top = blocks
        .iter()
        .flat_map(|b| {
            [b.measured, b.predicted]
                .into_iter()
                .flat_map(|f| f.one_x_probe_amplitudes_m)
        })
        .fold(1e-9, f64::max)
        * 1e6
        * 1.1;
    let mut bode = super::bode_plot(
        path,
        &super::BodeLayout {
            size: (1150, 850),
            title_size: 20,
            plot_width: 840,
            amplitude_height: 420,
        },
        title,
        (x0, x1),
        top,
        (
            "1X amplitude along the probe (µm, 0-pk)",
            "1X phase lag (deg, API 670)",
        ),
    )?;
    let series = one_x_series(axes_deg);
    for (measured, j, colour, _) in &series {
        let pick = |b: &WindowComparison| if *measured { b.measured } else { b.predicted };
        bode.amplitude.draw_series(blocks.iter().map(|b| {
            let a = pick(b).one_x_probe_amplitudes_m[*j] * 1e6;
            marker((b.speed_rpm, a), *colour, *measured)
        }))?;
        bode.phase.draw_series(blocks.iter().filter_map(|b| {
            let v = pick(b).one_x_probe_axes?[*j];
            Some(marker((b.speed_rpm, v.phase_lag_deg), *colour, *measured))
        }))?;
    }
    if let Some(why) = phase_missing(blocks) {
        let area = bode.phase.plotting_area().strip_coord_spec();
        draw_notice(&area, "no 1X phase lag:", &why)?;
    }
    draw_side_legend(&bode.legend, &series_entries(&series), 30)?;
    bode.root.present()?;
    Ok(())
}

/// A two-line notice in the middle of `area`, wrapped at about 60 characters.
fn draw_notice(
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    head: &str,
    text: &str,
) -> anyhow::Result<()> {
    let (w, h) = area.dim_in_pixel();
    let mut lines = vec![head.to_string()];
    let mut line = String::new();
    for word in text.split_whitespace() {
        if line.len() + word.len() > 60 {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    lines.push(line);
    let y0 = h as i32 / 2 - 11 * lines.len() as i32;
    for (k, l) in lines.iter().enumerate() {
        area.draw(&Text::new(
            l.clone(),
            (w as i32 / 6, y0 + 22 * k as i32),
            ("sans-serif", 16).into_font().color(&BLACK),
        ))?;
    }
    Ok(())
}

/// Measured 1X polar plot from a replay: per probe axis the 1X vector X = A e^{−i·lag} (µm) in
/// the complex plane, 1:1, one point per block of 8 revolutions, measured (filled, joined in
/// time order) beside predicted (hollow), speeds labelled. Without a keyphasor there is no
/// vector to draw: the plot says why.
pub fn one_x_polar_svg(
    path: &Path,
    title: &str,
    blocks: &[WindowComparison],
    axes_deg: [f64; 2],
) -> anyhow::Result<()> {
    let lim = blocks
        .iter()
        .flat_map(|b| [b.measured, b.predicted])
        .flat_map(|f| f.one_x_probe_amplitudes_m)
        .fold(1e-9, f64::max)
        * 1e6
        * 1.15;
    let (root, mut chart, legend_area) = super::square_plot(
        path,
        &WIDE_SQUARE,
        title,
        lim,
        (
            "Re X, in phase with the keyphasor (µm)",
            "Im X (µm); lag clockwise from +Re",
        ),
    )?;
    let series = one_x_series(axes_deg);
    let every = (blocks.len() / 8).max(1);
    let mut placer = LabelPlacer::in_chart(&chart);
    let mut marks = Vec::new();
    for (measured, j, colour, _) in &series {
        let pts: Vec<(f64, f64, f64)> = blocks
            .iter()
            .filter_map(|b| {
                let f = if *measured { b.measured } else { b.predicted };
                let p = f.one_x_probe_axes?[*j].phasor_m();
                Some((p[0] * 1e6, p[1] * 1e6, b.speed_rpm))
            })
            .collect();
        if *measured {
            chart.draw_series(LineSeries::new(
                pts.iter().map(|p| (p.0, p.1)),
                colour.mix(0.5),
            ))?;
        }
        chart.draw_series(pts.iter().map(|p| marker((p.0, p.1), *colour, *measured)))?;
        for p in &pts {
            placer.reserve_marker(chart.backend_coord(&(p.0, p.1)), 4.0);
        }
        if *measured {
            marks.extend(pts.iter().step_by(every).copied());
        }
    }
    // the speeds of the measured points, where a label finds room
    for (x, y, rpm) in marks {
        let text = format!("{rpm:.0}");
        if let Some(o) = placer.place(chart.backend_coord(&(x, y)), 4.0, &text, 12.0) {
            chart.draw_series(std::iter::once(
                EmptyElement::at((x, y)) + placed_text(text, o, 12.0, &BLACK),
            ))?;
        }
    }
    if let Some(why) = phase_missing(blocks) {
        let area = chart.plotting_area().strip_coord_spec();
        draw_notice(&area, "no 1X vector (needs the phase):", &why)?;
    }
    let mut entries = series_entries(&series);
    entries.push(Entry::new(Swatch::Text, "numbers: speed (rpm)"));
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// Full-spectrum cascade of the bag's blocks of 8 revolutions, measured on the left and
/// predicted on the right: the spectrum of x + iy, forward orders (whirl with the rotation)
/// positive, reverse orders negative, one trace per block (at most 50, evenly chosen in time),
/// each at the height of its place in the bag and labelled on the left with its speed;
/// amplitude (circle radius) scaled so that the largest peak spans 3 traces, with a scale bar.
pub fn full_spectrum_cascade_svg(
    path: &Path,
    title: &str,
    blocks: &[BlockSpectra],
) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (1150, 700)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let picked: Vec<&BlockSpectra> = if blocks.len() > 50 {
        (0..50)
            .map(|i| &blocks[i * (blocks.len() - 1) / 49])
            .collect()
    } else {
        blocks.iter().collect()
    };
    let n = picked.len().max(1) as f64;
    let peak = picked
        .iter()
        .flat_map(|b| {
            b.measured_full_m
                .iter()
                .chain(&b.predicted_full_m)
                .flatten()
        })
        .fold(1e-12_f64, |a, &v| a.max(v));
    let scale = 3.0 / peak;
    let labels: Vec<f64> = picked.iter().map(|b| b.speed_rpm).collect();
    let halves = root.split_evenly((1, 2));
    let max_order = 2.0 + 0.1;
    for (area, (label, colour, measured)) in halves.iter().zip([
        ("measured", MEASURED, true),
        ("predicted", PREDICTED, false),
    ]) {
        let mut chart = ChartBuilder::on(area)
            .caption(label, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(-max_order..max_order, -2.0..n + 3.0)?;
        let speed_of = |v: &f64| {
            let k = v.round();
            if (v - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < labels.len() {
                format!("{:.0}", labels[k as usize])
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .x_desc("order: reverse < 0 < forward (frequency / running frequency)")
            .y_desc("speed of each trace (rpm), in bag order")
            .y_labels(12)
            .y_label_formatter(&speed_of)
            .x_labels(9)
            .draw()?;
        draw_order_lines(&mut chart, n)?;
        draw_scale_bar(&mut chart, peak, scale, n)?;
        for (k, b) in picked.iter().enumerate() {
            let full = if measured {
                &b.measured_full_m
            } else {
                &b.predicted_full_m
            };
            chart.draw_series(LineSeries::new(full_trace(full, k as f64, scale), colour))?;
        }
    }
    root.present()?;
    Ok(())
}

/// One cascade trace at height `y`: reverse orders −2 … −1/8 (the backward radii), 0, then
/// forward orders 1/8 … 2, each radius (m) times `scale` above `y`.
fn full_trace(
    full: &[[f64; 2 * BLOCK_REVS]; 2],
    y: f64,
    scale: f64,
) -> impl Iterator<Item = (f64, f64)> + '_ {
    let order = |i: usize| (i + 1) as f64 / BLOCK_REVS as f64;
    (0..2 * BLOCK_REVS)
        .rev()
        .map(move |i| (-order(i), y + scale * full[1][i]))
        .chain(std::iter::once((0.0, y)))
        .chain((0..2 * BLOCK_REVS).map(move |i| (order(i), y + scale * full[0][i])))
}

/// Grey guides at ±1X and ±0.5X, labelled below the first trace.
fn draw_order_lines(chart: &mut Chart<'_, '_>, n: f64) -> anyhow::Result<()> {
    for (o, l) in [(1.0, "+1X"), (-1.0, "−1X"), (0.5, "+½X"), (-0.5, "−½X")] {
        chart.draw_series(LineSeries::new(
            [(o, -0.5), (o, n + 0.5)],
            RGBColor(170, 170, 170),
        ))?;
        chart.draw_series(std::iter::once(Text::new(
            l,
            (o - 0.08, -0.8),
            ("sans-serif", 12).into_font(),
        )))?;
    }
    Ok(())
}

/// A bar of a round amplitude at the top right, labelled in µm.
fn draw_scale_bar(chart: &mut Chart<'_, '_>, peak: f64, scale: f64, n: f64) -> anyhow::Result<()> {
    let e = 10f64.powf(peak.log10().floor());
    let bar = [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * e)
        .find(|&r| r <= peak)
        .unwrap_or(e);
    let (x, y) = (1.95, n + 0.2);
    chart.draw_series(LineSeries::new(
        [(x, y), (x, y + scale * bar)],
        BLACK.stroke_width(3),
    ))?;
    let um = bar * 1e6;
    chart.draw_series(std::iter::once(Text::new(
        if um >= 1.0 {
            format!("{um:.0} µm")
        } else {
            format!("{um:.2} µm")
        },
        (1.35, y + 0.5 * scale * bar),
        ("sans-serif", 13).into_font(),
    )))?;
    Ok(())
}

/// A predicted static-equilibrium point of the centerline: speed (rpm) and position `[x, y]` (m).
pub type CenterlinePoint = (f64, [f64; 2]);

/// The shaft centerline of a replay: the mean position of each block of 8 revolutions in the
/// clearance circle (µm, machine frame, 1:1), measured (filled) and the twin's (hollow), and the
/// predicted static-equilibrium locus (line, speeds labelled), drawn over the markers. With AC-coupled probes the
/// measured mean is not the plant's: it is left out and the plot says so.
pub fn replay_centerline_svg(
    path: &Path,
    title: &str,
    blocks: &[WindowComparison],
    static_locus: &[CenterlinePoint],
    clearance_m: f64,
    mean_not_measured: Option<&str>,
) -> anyhow::Result<()> {
    let c = clearance_m * 1e6;
    let (root, mut chart, legend_area) =
        super::square_plot(path, &WIDE_SQUARE, title, 1.1 * c, ("x (µm)", "y (µm)"))?;
    chart.draw_series(LineSeries::new(super::circle(c), BLACK))?;
    let mut entries = vec![Entry::new(
        Swatch::Line(BLACK, 1),
        format!("bearing clearance ({c:.0} µm)"),
    )];
    let um = |p: [f64; 2]| (p[0] * 1e6, p[1] * 1e6);
    if mean_not_measured.is_none() {
        chart.draw_series(
            blocks
                .iter()
                .map(|b| Circle::new(um(b.measured.mean_m), 3, MEASURED.mix(0.5).filled())),
        )?;
        entries.push(Entry::new(
            Swatch::Dot(MEASURED),
            "measured mean, per block",
        ));
    }
    chart.draw_series(blocks.iter().map(|b| {
        Circle::new(
            um(b.predicted.mean_m),
            4,
            PREDICTED.mix(0.5).stroke_width(1),
        )
    }))?;
    entries.push(Entry::new(
        Swatch::Ring(PREDICTED),
        "twin's mean, per block",
    ));
    // the locus last, over the markers that gather on it
    draw_static_locus(&mut chart, static_locus)?;
    entries.push(Entry::new(
        Swatch::Line(BLACK, 3),
        "static equilibrium, predicted",
    ));
    entries.push(Entry::new(
        Swatch::Text,
        format!("one point per {BLOCK_REVS} revolutions"),
    ));
    if let Some(why) = mean_not_measured {
        entries.push(Entry::new(Swatch::Text, "no measured centerline:"));
        entries.extend(wrapped(why, 36));
    }
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// The static-equilibrium locus (µm), its two ends labelled with their speeds, each label on
/// its own side (a short locus would crowd more labels).
fn draw_static_locus(
    chart: &mut Chart<'_, '_>,
    static_locus: &[CenterlinePoint],
) -> anyhow::Result<()> {
    let um = |p: [f64; 2]| (p[0] * 1e6, p[1] * 1e6);
    chart.draw_series(LineSeries::new(
        static_locus.iter().map(|(_, p)| um(*p)),
        BLACK.stroke_width(3),
    ))?;
    // the ends of the locus labelled with their speeds (a short locus would crowd more)
    let ends = [static_locus.first(), static_locus.last()];
    let ends = if static_locus.len() > 1 {
        &ends[..]
    } else {
        &ends[..1]
    };
    // each end's label on its own side (pixels grow downwards)
    let first_lower = match (static_locus.first(), static_locus.last()) {
        (Some(a), Some(b)) => a.1[1] <= b.1[1],
        _ => true,
    };
    let offsets = if first_lower {
        [(8, 6), (8, -14)]
    } else {
        [(8, -14), (8, 6)]
    };
    chart.draw_series(ends.iter().flatten().zip(offsets).map(|((s, p), at)| {
        EmptyElement::at(um(*p))
            + Circle::new((0, 0), 3, BLACK.filled())
            + Text::new(format!("{s:.0} rpm"), at, ("sans-serif", 12).into_font())
    }))?;
    Ok(())
}

/// The keyphasor dots of an orbit: where the keyphasor-locked shaft angle passes a whole
/// revolution (the plant's keyphasor event, shaft angle 0), interpolated between samples.
/// None when some sample is not locked (there is no keyphasor to mark).
pub fn keyphasor_dots(samples: &[Sample], pick: fn(&Sample) -> [f64; 2]) -> Option<Vec<[f64; 2]>> {
    if samples
        .iter()
        .any(|s| s.phase_reference != PhaseReference::Locked)
    {
        return None;
    }
    let dots = samples
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let k = (b.angle_rad / TAU).floor();
            let at = k * TAU;
            if a.angle_rad >= at || b.angle_rad <= a.angle_rad {
                return None;
            }
            let f = (at - a.angle_rad) / (b.angle_rad - a.angle_rad);
            let (pa, pb) = (pick(a), pick(b));
            Some([0, 1].map(|i| pa[i] + f * (pb[i] - pa[i])))
        })
        .collect();
    Some(dots)
}

/// The orbit in the probes' own frame beside the machine frame (µm, each 1:1): left, x and y of
/// the machine with the two probes drawn at their angles; right, the readings along probe 1
/// (horizontal) and probe 2 (vertical), d_j = x cos α_j + y sin α_j. Measured and predicted,
/// last revolutions, each about its own mean (the motion, as an orbit display shows it), with a
/// keyphasor dot per revolution.
pub fn orbit_probe_frame_svg(
    path: &Path,
    title: &str,
    samples: &[Sample],
    axes_rad: [f64; 2],
) -> anyhow::Result<()> {
    let to_probe = |p: [f64; 2]| axes_rad.map(|a| p[0] * a.cos() + p[1] * a.sin());
    type Pick = fn(&Sample) -> [f64; 2];
    let series: [(Pick, RGBColor); 2] =
        [(|s| s.measured_m, MEASURED), (|s| s.predicted_m, PREDICTED)];
    // each orbit about its own mean, as an orbit display shows the motion
    let n = samples.len().max(1) as f64;
    let means = series.map(|(pick, _)| {
        let sum = samples.iter().fold([0.0, 0.0], |a, s| {
            let p = pick(s);
            [a[0] + p[0], a[1] + p[1]]
        });
        [sum[0] / n, sum[1] / n]
    });
    let extent = samples
        .iter()
        .flat_map(|s| {
            series
                .iter()
                .zip(&means)
                .map(|((pick, _), m)| (pick(s)[0] - m[0]).hypot(pick(s)[1] - m[1]))
        })
        .fold(1e-9, f64::max);
    let lim = 1.15 * extent * 1e6;
    let root = SVGBackend::new(path, (1300, 700)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let (panels, legend_area) = root.split_horizontally(1020);
    let halves = panels.split_evenly((1, 2));
    let deg = axes_rad.map(f64::to_degrees);
    let descs = [
        (
            "machine frame".to_string(),
            "x − mean (µm)".to_string(),
            "y − mean (µm)".to_string(),
        ),
        (
            "probe frame".to_string(),
            format!("probe 1 at {:.0}°, about its mean (µm)", deg[0]),
            format!("probe 2 at {:.0}°, about its mean (µm)", deg[1]),
        ),
    ];
    for (k, (area, (caption, xd, yd))) in halves.iter().zip(descs).enumerate() {
        let area = area.titled(&caption, ("sans-serif", 16))?;
        let area = super::square_chart_area(area, 10, 40, 60);
        let mut chart = ChartBuilder::on(&area)
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(-lim..lim, -lim..lim)?;
        chart.configure_mesh().x_desc(xd).y_desc(yd).draw()?;
        let frame = move |p: [f64; 2]| {
            let q = if k == 0 { p } else { to_probe(p) };
            (q[0] * 1e6, q[1] * 1e6)
        };
        if k == 0 {
            for (j, a) in axes_rad.iter().enumerate() {
                let tip = (0.95 * lim * a.cos(), 0.95 * lim * a.sin());
                chart.draw_series(LineSeries::new([(0.0, 0.0), tip], BLACK.mix(0.6)))?;
                chart.draw_series(std::iter::once(Text::new(
                    format!("probe {}", j + 1),
                    tip,
                    ("sans-serif", 13).into_font(),
                )))?;
            }
        }
        for ((pick, colour), m) in series.iter().zip(&means) {
            let about = |p: [f64; 2]| frame([p[0] - m[0], p[1] - m[1]]);
            chart.draw_series(LineSeries::new(
                samples.iter().map(|s| about(pick(s))),
                colour,
            ))?;
            if let Some(dots) = keyphasor_dots(samples, *pick) {
                chart.draw_series(
                    dots.iter()
                        .map(|d| Circle::new(about(*d), 4, colour.filled())),
                )?;
            }
        }
    }
    let mut entries = vec![
        Entry::new(Swatch::Line(MEASURED, 1), "measured"),
        Entry::new(Swatch::Line(PREDICTED, 1), "predicted"),
    ];
    entries.extend(keyphasor_legend(samples));
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// The legend entries of the keyphasor dots: the dot, or why there is none.
pub(crate) fn keyphasor_legend(samples: &[Sample]) -> Vec<Entry> {
    match samples.iter().find_map(|s| s.phase_reference.null_reason()) {
        None => vec![Entry::new(
            Swatch::Dot(BLACK),
            "keyphasor (once a revolution)",
        )],
        Some(why) => {
            let mut v = vec![Entry::new(Swatch::Text, "no keyphasor dots:")];
            v.extend(wrapped(why, 24));
            v
        }
    }
}

/// `text` as legend lines of at most about `width` characters.
fn wrapped(text: &str, width: usize) -> Vec<Entry> {
    let mut v = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.chars().count() + word.chars().count() > width {
            v.push(Entry::new(Swatch::Text, std::mem::take(&mut line)));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    v.push(Entry::new(Swatch::Text, line));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A forward 1X circle of 3 µm lagging the keyphasor by 40°, sampled 37 times a revolution
    /// (no sample at a revolution's start): the dots are where ψ passes 2πk, interpolated along
    /// the chord, at (3 cos 40°, −3 sin 40°) µm within the chord's sagitta (r(1 − cos(π/37)),
    /// 0.36 %); one a revolution. An unlocked sample leaves no dots.
    #[test]
    fn keyphasor_dots_sit_at_shaft_angle_zero() {
        let (r, lag) = (3e-6, 40f64.to_radians());
        let mut samples: Vec<Sample> = (0..5 * 37)
            .map(|i| {
                let psi = TAU * (i as f64 + 0.3) / 37.0;
                Sample {
                    angle_rad: psi,
                    measured_m: [r * (psi - lag).cos(), r * (psi - lag).sin()],
                    phase_reference: PhaseReference::Locked,
                    ..Sample::default()
                }
            })
            .collect();
        let dots = keyphasor_dots(&samples, |s| s.measured_m).unwrap();
        assert_eq!(dots.len(), 4);
        let tol = r * (1.0 - (std::f64::consts::PI / 37.0).cos()) * 1.01;
        for d in &dots {
            assert!((d[0] - r * lag.cos()).abs() < tol, "{d:?}");
            assert!((d[1] + r * lag.sin()).abs() < tol, "{d:?}");
        }
        samples[3].phase_reference = PhaseReference::NotLocked;
        assert!(keyphasor_dots(&samples, |s| s.measured_m).is_none());
    }
}
