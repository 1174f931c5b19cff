//! Plots of a replay: predicted over measured orbit at a probe station, their order spectra,
//! and 1X and sub-synchronous amplitude against speed over the bag.

use super::legend::{draw_side_legend, Entry, Swatch};
use crate::monitor::OrderComponent;
use crate::replay::compare::{BlockSpectra, Sample, WindowComparison, BLOCK_REVS};
use plotters::prelude::*;
use std::path::Path;

const MEASURED: RGBColor = RGBColor(200, 30, 30);
const PREDICTED: RGBColor = RGBColor(30, 60, 200);

/// Predicted over measured orbit (µm), 1:1, inside the clearance circle; the legend in a panel
/// of its own (a whip orbit fills the circle).
pub fn orbit_comparison_svg(
    path: &Path,
    title: &str,
    samples: &[Sample],
    clearance_m: f64,
) -> anyhow::Result<()> {
    let extent = samples
        .iter()
        .flat_map(|s| [s.measured_m, s.predicted_m])
        .map(|p| p[0].hypot(p[1]))
        .fold(clearance_m, f64::max);
    let layout = super::SquareLayout {
        size: (860, 660),
        title_size: 18,
        plot_width: 640,
        y_label: 50,
    };
    let lim = 1.1 * extent * 1e6;
    let (root, mut chart, legend_area) =
        super::square_plot(path, &layout, title, lim, ("x (µm)", "y (µm)"))?;
    let c = clearance_m * 1e6;
    chart.draw_series(LineSeries::new(super::circle(c), BLACK))?;
    type Pick = fn(&Sample) -> [f64; 2];
    let series: [(&str, Pick, RGBColor); 2] = [
        ("measured", |s| s.measured_m, MEASURED),
        ("predicted", |s| s.predicted_m, PREDICTED),
    ];
    let mut entries = vec![Entry::new(
        Swatch::Line(BLACK, 1),
        format!("bearing clearance ({c:.0} µm)"),
    )];
    for (label, pick, color) in series {
        chart.draw_series(LineSeries::new(
            samples.iter().map(|s| (pick(s)[0] * 1e6, pick(s)[1] * 1e6)),
            color,
        ))?;
        // one dot per revolution where the keyphasor fires (Bently/ADRE)
        if let Some(dots) = super::keyphasor_dots(samples, pick) {
            chart.draw_series(
                dots.iter()
                    .map(|d| Circle::new((d[0] * 1e6, d[1] * 1e6), 4, color.filled())),
            )?;
        }
        entries.push(Entry::new(Swatch::Line(color, 1), label));
    }
    entries.extend(super::replay_views::keyphasor_legend(samples));
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// Measured and predicted order spectra (semi-major axis, µm) side by side.
pub fn spectrum_comparison_svg(
    path: &Path,
    title: &str,
    measured: &[OrderComponent],
    predicted: &[OrderComponent],
) -> anyhow::Result<()> {
    let max_order = measured.last().map_or(2.0, |c| c.order) + 0.05;
    let top = measured
        .iter()
        .chain(predicted)
        .map(|c| c.semi_major_m())
        .fold(1e-9, f64::max)
        * 1e6
        * 1.1;
    let root = SVGBackend::new(path, (800, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..max_order, 0.0..top)?;
    chart
        .configure_mesh()
        .x_desc("order (frequency / running frequency)")
        .y_desc("semi-major axis (µm)")
        .draw()?;
    let bin = measured.first().map_or(0.05, |c| c.order);
    for (set, color, offset, label) in [
        (measured, MEASURED, -0.2, "measured"),
        (predicted, PREDICTED, 0.2, "predicted"),
    ] {
        chart
            .draw_series(set.iter().map(|c| {
                let x = c.order + offset * bin;
                Rectangle::new(
                    [
                        (x - 0.15 * bin, 0.0),
                        (x + 0.15 * bin, c.semi_major_m() * 1e6),
                    ],
                    color.filled(),
                )
            }))?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 4), (x + 12, y + 4)], color.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// The four amplitude series of the amplitude plots: label, value, colour, line (or dots).
type AmplitudeSeries = (&'static str, fn(&WindowComparison) -> f64, RGBColor, bool);

const AMPLITUDE_SERIES: [AmplitudeSeries; 4] = [
    (
        "1X measured",
        |b| b.measured.one_x_amplitude_m,
        MEASURED,
        true,
    ),
    (
        "1X predicted",
        |b| b.predicted.one_x_amplitude_m,
        PREDICTED,
        true,
    ),
    (
        "sub-synchronous measured",
        |b| b.measured.subsync_amplitude_m,
        MEASURED,
        false,
    ),
    (
        "sub-synchronous predicted",
        |b| b.predicted.subsync_amplitude_m,
        PREDICTED,
        false,
    ),
];

/// 1X and sub-synchronous semi-major axes (µm), block by block: against speed (rpm; the range
/// padded so that a hold at the top speed stands inside the frame) and, below, against bag time
/// (s), where a hold at one speed — the seed's whip at 9,000 rpm — unfolds. Legend beside.
pub fn amplitude_speed_svg(
    path: &Path,
    title: &str,
    blocks: &[WindowComparison],
) -> anyhow::Result<()> {
    let range = |pick: fn(&WindowComparison) -> f64| {
        let (lo, hi) = blocks
            .iter()
            .map(pick)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| {
                (a.0.min(v), a.1.max(v))
            });
        if lo.is_finite() && hi > lo {
            let pad = 0.04 * (hi - lo);
            (lo - pad, hi + pad)
        } else {
            (lo.min(0.0) - 10.0, hi.max(0.0) + 10.0)
        }
    };
    let top = blocks
        .iter()
        .flat_map(|b| AMPLITUDE_SERIES.map(|s| s.1(b)))
        .fold(1e-9, f64::max)
        * 1e6
        * 1.1;
    let root = SVGBackend::new(path, (1000, 760)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 18))?;
    let (plots, legend_area) = root.split_horizontally(780);
    let (upper, lower) = plots.split_vertically(370);
    type Abscissa = fn(&WindowComparison) -> f64;
    let panels: [(&str, Abscissa); 2] = [
        ("speed (rpm)", |b| b.speed_rpm),
        ("bag time (s)", |b| 0.5 * (b.start_s + b.end_s)),
    ];
    for (area, (x_desc, x_of)) in [&upper, &lower].into_iter().zip(panels) {
        let (lo, hi) = range(x_of);
        let mut chart = ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(lo..hi, 0.0..top)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc("semi-major axis (µm)")
            .draw()?;
        for (_, pick, color, solid) in AMPLITUDE_SERIES {
            let points = blocks.iter().map(|b| (x_of(b), pick(b) * 1e6));
            if solid {
                chart.draw_series(LineSeries::new(points, color.stroke_width(2)))?;
            } else {
                chart.draw_series(points.map(|p| Circle::new(p, 3, color.filled())))?;
            }
        }
    }
    let entries: Vec<Entry> = AMPLITUDE_SERIES
        .iter()
        .map(|(label, _, color, solid)| {
            let swatch = if *solid {
                Swatch::Line(*color, 2)
            } else {
                Swatch::Dot(*color)
            };
            Entry::new(swatch, *label)
        })
        .collect();
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// A round amplitude for a scale bar: 1, 2 or 5 × 10ⁿ, at most `v`.
fn round_down_125(v: f64) -> f64 {
    let e = 10f64.powf(v.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * e)
        .find(|&r| r <= v)
        .unwrap_or(e)
}

/// Waterfall (cascade) of the order spectra of the bag's blocks of 8 revolutions, measured on
/// the left and predicted on the right: one trace per block (at most 60, evenly chosen), raised
/// by its time in the bag, semi-major axis scaled so that the largest peak spans 3 traces; a
/// scale bar of a round amplitude (µm) at the top right of each half.
pub fn waterfall_svg(path: &Path, title: &str, blocks: &[BlockSpectra]) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (1000, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 18))?;
    let picked: Vec<&BlockSpectra> = if blocks.len() > 60 {
        (0..60)
            .map(|i| &blocks[i * (blocks.len() - 1) / 59])
            .collect()
    } else {
        blocks.iter().collect()
    };
    let t_end = picked.last().map_or(1.0, |b| b.end_s).max(1e-9);
    let peak = picked
        .iter()
        .flat_map(|b| b.measured_m.iter().chain(&b.predicted_m))
        .fold(1e-12_f64, |a, &v| a.max(v));
    let spacing = t_end / picked.len().max(1) as f64;
    let scale = 3.0 * spacing / peak;
    let halves = root.split_evenly((1, 2));
    for (area, (label, color, measured)) in halves.iter().zip([
        ("measured", MEASURED, true),
        ("predicted", PREDICTED, false),
    ]) {
        let mut chart = ChartBuilder::on(area)
            .caption(label, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..2.0 + 0.05, 0.0..t_end + 3.5 * spacing)?;
        chart
            .configure_mesh()
            .x_desc("order (frequency / running frequency)")
            .y_desc("bag time (s); trace height: semi-major axis (scale bar)")
            .draw()?;
        // the amplitude scale: a bar of a round amplitude at the top right, labelled in µm
        let bar_m = round_down_125(peak);
        let (x_bar, y_bar) = (1.95, t_end + 0.3 * spacing);
        chart.draw_series(LineSeries::new(
            [(x_bar, y_bar), (x_bar, y_bar + scale * bar_m)],
            BLACK.stroke_width(3),
        ))?;
        chart.draw_series(std::iter::once(Text::new(
            match bar_m * 1e6 {
                um if um >= 1.0 => format!("{um:.0} µm"),
                um => format!("{um:.2} µm"),
            },
            (1.50, y_bar + 0.5 * scale * bar_m),
            ("sans-serif", 13).into_font(),
        )))?;
        for b in &picked {
            let values = if measured {
                &b.measured_m
            } else {
                &b.predicted_m
            };
            chart.draw_series(LineSeries::new(
                values
                    .iter()
                    .enumerate()
                    .map(|(k, v)| ((k + 1) as f64 / BLOCK_REVS as f64, b.end_s + scale * v)),
                color,
            ))?;
        }
    }
    root.present()?;
    Ok(())
}
