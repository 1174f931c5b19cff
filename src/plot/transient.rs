//! Plots of a transient run: orbit in the clearance circle, order spectrum, pressure map, the
//! fluid-fraction map (mass-conserving cavitation), and the amplitude–speed characteristic of a
//! sweep.

use super::legend::{draw_side_legend, Entry, Swatch};
use crate::monitor::OrderComponent;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// The orbit (last two revolutions) of a journal inside its clearance circle, 1:1, in µm, with
/// the legend in a panel of its own (a whip orbit fills the clearance circle).
pub fn orbit_svg(
    path: &Path,
    title: &str,
    orbit_m: &[[f64; 2]],
    clearance_m: f64,
) -> anyhow::Result<()> {
    let c = clearance_m * 1e6;
    let layout = super::SquareLayout {
        size: (900, 660),
        title_size: 18,
        plot_width: 640,
        y_label: 50,
    };
    let (root, mut chart, legend_area) =
        super::square_plot(path, &layout, title, 1.1 * c, ("x (µm)", "y (µm)"))?;
    chart.draw_series(LineSeries::new(super::circle(c), BLACK))?;
    chart.draw_series(LineSeries::new(
        orbit_m.iter().map(|p| (p[0] * 1e6, p[1] * 1e6)),
        BLUE,
    ))?;
    let entries = [
        Entry::new(
            Swatch::Line(BLACK, 1),
            format!("clearance circle ({c:.0} µm)"),
        ),
        Entry::new(Swatch::Line(BLUE, 1), "journal centre,"),
        Entry::new(Swatch::Line(WHITE, 1), "last two revolutions"),
    ];
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}

/// The full order spectrum: forward (positive orders) and backward (negative) orbit radii, µm,
/// as computed (Hann window over whole revolutions, radii corrected for its coherent gain); the
/// 1X and largest sub-synchronous components marked at their interpolated order and radius
/// (corrected for the scalloping loss a tone between bins suffers, up to 15 %), the legend and
/// the window stated in a panel of their own.
pub fn spectrum_svg(path: &Path, title: &str, spectrum: &[OrderComponent]) -> anyhow::Result<()> {
    let max_order = spectrum.last().map_or(2.0, |c| c.order);
    // orders are k / resolution, k = 1, 2, …
    let resolution = spectrum
        .first()
        .map_or(1, |c| (1.0 / c.order.max(1e-9)).round().max(1.0) as usize);
    let peaks = [
        (
            "1X",
            crate::monitor::spectrum::one_x_component(spectrum, resolution),
        ),
        (
            "sub-synchronous",
            crate::monitor::spectrum::subsynchronous_peak(spectrum, resolution),
        ),
    ];
    let top = spectrum
        .iter()
        .chain(peaks.iter().map(|p| &p.1))
        .map(|c| c.forward_m.max(c.backward_m))
        .fold(1e-9, f64::max)
        * 1e6
        * 1.15;
    let root = SVGBackend::new(path, (1000, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 18))?;
    let (plot_area, legend_area) = root.split_horizontally(740);
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(-max_order..max_order, 0.0..top)?;
    chart
        .configure_mesh()
        .x_desc("order (backward < 0 < forward)")
        .y_desc("orbit radius (µm)")
        .draw()?;
    for c in spectrum {
        chart.draw_series(LineSeries::new(
            [(c.order, 0.0), (c.order, c.forward_m * 1e6)],
            BLUE.stroke_width(3),
        ))?;
        chart.draw_series(LineSeries::new(
            [(-c.order, 0.0), (-c.order, c.backward_m * 1e6)],
            GREEN.stroke_width(3),
        ))?;
    }
    let red = RGBColor(200, 30, 30);
    draw_spectrum_peaks(&mut chart, &peaks, red)?;
    let entries = [
        Entry::new(Swatch::Line(BLUE, 3), "forward bins"),
        Entry::new(Swatch::Line(GREEN, 3), "backward bins"),
        Entry::new(Swatch::Dot(red), "peak, interpolated"),
    ];
    draw_side_legend(&legend_area, &entries, 30)?;
    draw_window_note(&legend_area, resolution)?;
    root.present()?;
    Ok(())
}

/// The interpolated peaks (name, component) on the spectrum chart, each at its order (negative
/// if it whirls backward) and corrected radius, labelled.
fn draw_spectrum_peaks(
    chart: &mut ChartContext<
        '_,
        SVGBackend<'_>,
        plotters::coord::cartesian::Cartesian2d<
            plotters::coord::types::RangedCoordf64,
            plotters::coord::types::RangedCoordf64,
        >,
    >,
    peaks: &[(&str, OrderComponent)],
    red: RGBColor,
) -> anyhow::Result<()> {
    for (name, p) in peaks {
        if p.semi_major_m() <= 0.0 {
            continue;
        }
        let (order, radius, sense) = if p.forward_m >= p.backward_m {
            (p.order, p.forward_m, "forward")
        } else {
            (-p.order, p.backward_m, "backward")
        };
        chart.draw_series(std::iter::once(
            EmptyElement::at((order, radius * 1e6))
                + Circle::new((0, 0), 5, red.filled())
                + Text::new(
                    format!("{name} {:.3}X: {sense} {:.3} µm", p.order, radius * 1e6),
                    (8, -14),
                    ("sans-serif", 12).into_font().color(&red),
                ),
        ))?;
    }
    Ok(())
}

/// The window the spectrum was computed with, and what its bins and marks mean.
fn draw_window_note(
    legend_area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    resolution: usize,
) -> anyhow::Result<()> {
    let note = ("sans-serif", 13).into_font();
    for (i, line) in [
        format!("Hann window over {resolution} revolutions,"),
        format!("bins 1/{resolution} order apart;"),
        "radii corrected for the window's".to_string(),
        "coherent gain (exact on a bin);".to_string(),
        "between bins a bin reads up to".to_string(),
        "15 % low (scalloping, −1.42 dB".to_string(),
        "at half a bin): the marked peaks".to_string(),
        "are interpolated and corrected".to_string(),
    ]
    .iter()
    .enumerate()
    {
        legend_area.draw(&Text::new(
            line.clone(),
            (8, 130 + 18 * i as i32),
            note.clone(),
        ))?;
    }
    Ok(())
}

/// Quantile of the pressure map that sets the colour scale when the map holds spikes.
const PRESSURE_SCALE_QUANTILE: f64 = 0.995;

/// A map whose maximum exceeds its [`PRESSURE_SCALE_QUANTILE`] by this factor holds spikes
/// (contact: a node or two near ε → 1 at several times the film's working pressure) that would
/// set the scale and wash the film's field out: the scale then tops at the quantile and the
/// cells above are drawn red and counted. Otherwise the scale tops at the maximum.
const PRESSURE_SPIKE_FACTOR: f64 = 1.5;

/// Cells above the colour scale.
const ABOVE_SCALE: RGBColor = RGBColor(220, 30, 30);

/// The grey of pressure `p` on a scale topping out at `top` (white 0 → black `top`).
fn pressure_shade(p: f64, top: f64) -> RGBColor {
    let g = (255.0 * (1.0 - (p / top).clamp(0.0, 1.0))) as u8;
    RGBColor(g, g, g)
}

/// Mid-plane film pressure over the last two revolutions at constant speed: bearing angle
/// against shaft rotation (degrees), grey = pressure, with a colour bar in MPa. With
/// `not_valid` (why the pressures are not physical figures) the title begins "PRESSURES NOT
/// VALID" and the reason stands in red under it.
pub fn pressure_map_svg(
    path: &Path,
    title: &str,
    map_pa: &[Vec<f64>],
    not_valid: Option<&str>,
) -> anyhow::Result<()> {
    let mut sorted: Vec<f64> = map_pa
        .iter()
        .flatten()
        .copied()
        .filter(|p| p.is_finite())
        .collect();
    sorted.sort_by(f64::total_cmp);
    let p_max = sorted.last().copied().unwrap_or(0.0).max(1e-9);
    let quantile = sorted
        .get(((sorted.len() as f64 - 1.0) * PRESSURE_SCALE_QUANTILE) as usize)
        .copied()
        .unwrap_or(p_max)
        .max(1e-9);
    let top = if p_max > PRESSURE_SPIKE_FACTOR * quantile {
        quantile
    } else {
        p_max
    };
    let above = sorted.iter().filter(|&&p| p > top).count();
    let caption = if above > 0 {
        format!(
            "{title}: red = {above} cells above the scale, up to {:.1} MPa",
            p_max * 1e-6
        )
    } else {
        title.to_string()
    };
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = titled_with_validity(root, &caption, not_valid)?;
    let (map_area, bar_area) = root.split_horizontally(790);
    draw_map(&map_area, map_pa, None, |p| {
        if p > top {
            ABOVE_SCALE
        } else {
            pressure_shade(p, top)
        }
    })?;
    colour_bar(&bar_area, ("pressure (MPa)", top * 1e-6), |v| {
        pressure_shade(v * 1e6, top)
    })?;
    root.present()?;
    Ok(())
}

/// The grey of fluid fraction `phi`: white 0 (no oil) → black 1 (full film).
fn fraction_shade(phi: f64) -> RGBColor {
    pressure_shade(phi, 1.0)
}

/// Mid-plane fluid fraction φ over the last two revolutions (mass-conserving cavitation, issue
/// 18): bearing angle against shaft rotation (degrees), grey = φ (black: full film, φ = 1;
/// lighter: the ruptured zone's streamers), with a colour bar 0–1; a plain bearing's feed line
/// (`feed_deg`, degrees from +x), where the film is held full, drawn across it.
pub fn fluid_fraction_map_svg(
    path: &Path,
    title: &str,
    map: &[Vec<f64>],
    feed_deg: Option<f64>,
) -> anyhow::Result<()> {
    let lowest = (map.iter().flatten().copied())
        .filter(|v| v.is_finite())
        .fold(1.0_f64, f64::min);
    let caption = format!("{title}: φ down to {lowest:.2}");
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(&caption, ("sans-serif", 18))?;
    let (map_area, bar_area) = root.split_horizontally(790);
    draw_map(&map_area, map, feed_deg, fraction_shade)?;
    colour_bar(&bar_area, ("fluid fraction φ", 1.0), fraction_shade)?;
    root.present()?;
    Ok(())
}

/// The colour of the feed line drawn on a fluid-fraction map (over black and grey cells).
const FEED_LINE: RGBColor = RGBColor(230, 80, 20);

/// A map of rows (one a time step, over 720° of shaft rotation) of values around the bearing
/// (0–360° from +x), each cell filled with `shade(value)`; with `feed_deg`, a line across it
/// at that bearing angle, labelled.
fn draw_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    map: &[Vec<f64>],
    feed_deg: Option<f64>,
    shade: impl Fn(f64) -> RGBColor,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let steps = map.len().max(1);
    let points = map.first().map_or(1, Vec::len).max(1);
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..720.0, 0.0..360.0)?;
    chart
        .configure_mesh()
        .x_desc("shaft rotation over the last two revolutions (deg)")
        .y_desc("bearing angle from +x (deg)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()?;
    let (dx, dy) = (720.0 / steps as f64, 360.0 / points as f64);
    // one rectangle for each run of cells of one grey along the bearing (a film full over half
    // the bearing is one cell, not 45: the SVG stays small)
    let mut cells = Vec::new();
    for (t, row) in map.iter().enumerate() {
        let x = t as f64 * dx;
        let mut k = 0;
        while k < row.len() {
            let colour = shade(row[k]);
            let run = row[k..].iter().take_while(|&&v| shade(v) == colour).count();
            cells.push(Rectangle::new(
                [(x, k as f64 * dy), (x + dx, (k + run) as f64 * dy)],
                colour.filled(),
            ));
            k += run;
        }
    }
    chart.draw_series(cells)?;
    if let Some(a) = feed_deg {
        chart.draw_series(LineSeries::new(
            [(0.0, a), (720.0, a)],
            FEED_LINE.stroke_width(2),
        ))?;
        // above the line (below it near the top edge)
        let (y, v) = if a > 340.0 {
            (a - 3.0, VPos::Top)
        } else {
            (a + 3.0, VPos::Bottom)
        };
        let label = ("sans-serif", 15)
            .into_font()
            .color(&FEED_LINE)
            .pos(Pos::new(HPos::Left, v));
        chart.draw_series(std::iter::once(Text::new(
            format!("feed line {a:.0}°"),
            (8.0, y),
            label,
        )))?;
    }
    Ok(())
}

/// `root` under its title `caption`; with `not_valid`, the title begins "PRESSURES NOT VALID"
/// and the reason stands in red on a line under it. Returns the area left for the plot.
fn titled_with_validity<'a>(
    root: DrawingArea<SVGBackend<'a>, plotters::coord::Shift>,
    caption: &str,
    not_valid: Option<&str>,
) -> anyhow::Result<DrawingArea<SVGBackend<'a>, plotters::coord::Shift>> {
    let Some(why) = not_valid else {
        return Ok(root.titled(caption, ("sans-serif", 18))?);
    };
    let root = root.titled(
        &format!("PRESSURES NOT VALID — {caption}"),
        ("sans-serif", 18),
    )?;
    let (notice, rest) = root.split_vertically(22);
    notice.draw(&Text::new(
        why.to_string(),
        (15, 2),
        ("sans-serif", 13).into_font().color(&ABOVE_SCALE),
    ))?;
    Ok(rest)
}

/// The scale beside a map: `label`, from 0 to `top` (in the label's unit), each value's grey
/// by `shade`.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (label, top): (&str, f64),
    shade: impl Fn(f64) -> RGBColor,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let mut bar = ChartBuilder::on(area)
        .margin_top(15)
        .margin_bottom(55)
        .margin_right(10)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..1.0, 0.0..top)?;
    bar.configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 13))
        .draw()?;
    let n = 100;
    bar.draw_series((0..n).map(|i| {
        let (v0, v1) = (top * i as f64 / n as f64, top * (i + 1) as f64 / n as f64);
        Rectangle::new([(0.0, v0), (1.0, v1)], shade(v0).filled())
    }))?;
    Ok(())
}

/// Amplitude–speed characteristic of a sweep (seed Fig. 8): per bearing, the largest orbit
/// semi-axis and the sub-synchronous semi-axis (µm) against speed (rpm).
pub fn sweep_svg(
    path: &Path,
    title: &str,
    speeds_rpm: &[f64],
    series: &[(String, Vec<f64>, Vec<f64>)],
) -> anyhow::Result<()> {
    let (x0, x1) = (
        speeds_rpm.first().copied().unwrap_or(0.0),
        speeds_rpm
            .last()
            .copied()
            .unwrap_or(1.0)
            .max(speeds_rpm.first().copied().unwrap_or(0.0) + 1.0),
    );
    let top = series
        .iter()
        .flat_map(|s| s.1.iter().chain(&s.2))
        .fold(1e-9, |a: f64, &b| a.max(b))
        * 1e6
        * 1.1;
    let root = SVGBackend::new(path, (800, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, 0.0..top)?;
    chart
        .configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc("amplitude (µm)")
        .draw()?;
    let colours = [BLUE, RED, GREEN, MAGENTA, CYAN, BLACK];
    for (i, (name, amplitude, subsync)) in series.iter().enumerate() {
        let colour = colours[i % colours.len()];
        chart
            .draw_series(LineSeries::new(
                speeds_rpm
                    .iter()
                    .zip(amplitude)
                    .map(|(&s, &a)| (s, a * 1e6)),
                colour.stroke_width(2),
            ))?
            .label(format!("{name}: half peak-to-peak orbit"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(
                speeds_rpm.iter().zip(subsync).map(|(&s, &a)| (s, a * 1e6)),
                colour.mix(0.5),
            ))?
            .label(format!("{name}: sub-synchronous"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.mix(0.5)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
