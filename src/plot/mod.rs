//! Plots written as SVG files (plotters' SVG backend).

mod bearing;
mod campbell;
mod labels;
mod legend;
mod mode_shapes;
mod replay;
mod replay_views;
mod response;
mod rotor;
mod transient;

pub use bearing::{bearing_coefficients_svg, centerline_svg, BearingCurves};
pub use campbell::campbell_svg;
pub use mode_shapes::{mode_shapes_svg, ShapeNode, ShapePanel, ShapeStation};
pub use replay::{
    amplitude_speed_svg, orbit_comparison_svg, spectrum_comparison_svg, waterfall_svg,
};
pub use replay_views::{
    full_spectrum_cascade_svg, keyphasor_dots, one_x_bode_svg, one_x_polar_svg,
    orbit_probe_frame_svg, replay_centerline_svg, CenterlinePoint,
};
pub use response::{bode_svg, polar_svg, ResponseCurve};
pub use rotor::{rotor_svg, BearingGlyph, DiscGlyph, RotorDrawing, SectionGlyph};
pub use transient::{fluid_fraction_map_svg, orbit_svg, pressure_map_svg, spectrum_svg, sweep_svg};

use plotters::coord::Shift;
use plotters::prelude::*;

/// The part of `area` in which a chart with `margin` on every side and label areas of
/// `x_label` px (below) and `y_label` px (left) has a square plotting region: equal pixels per
/// unit on both axes when both axes span the same range (orbits, polar plots). Centred.
pub(crate) fn square_chart_area<DB: DrawingBackend>(
    area: DrawingArea<DB, Shift>,
    margin: u32,
    x_label: u32,
    y_label: u32,
) -> DrawingArea<DB, Shift> {
    let (w, h) = area.dim_in_pixel();
    let extra_w = 2 * margin + y_label;
    let extra_h = 2 * margin + x_label;
    let side = w
        .saturating_sub(extra_w)
        .min(h.saturating_sub(extra_h))
        .max(10);
    let left = (w.saturating_sub(side + extra_w)) / 2;
    let top = (h.saturating_sub(side + extra_h)) / 2;
    area.shrink((left, top), (side + extra_w, side + extra_h))
}

/// A drawing area of an SVG picture.
pub(crate) type SvgArea<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// A chart with f64 axes on the SVG backend.
pub(crate) type Chart2d<'a> = ChartContext<
    'a,
    SVGBackend<'a>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The layout of a square (1:1) plot beside a legend panel: picture size (px), title font
/// size, width of the plot's part (the legend gets the rest), the y label area's width (px).
pub(crate) struct SquareLayout {
    pub size: (u32, u32),
    pub title_size: u32,
    pub plot_width: u32,
    pub y_label: u32,
}

/// 1000 × 760 px, title 22, the legend right of 730 px.
pub(crate) const SQUARE_1000: SquareLayout = SquareLayout {
    size: (1000, 760),
    title_size: 22,
    plot_width: 730,
    y_label: 70,
};

/// A titled picture at `path` with a square chart of ±`lim` on both axes (equal pixels per unit,
/// margin 15 px, x labels 40 px) and its axis descriptions, left of a legend panel: the
/// picture's root (to present), the chart, the legend's area.
pub(crate) fn square_plot<'a>(
    path: &'a std::path::Path,
    layout: &SquareLayout,
    title: &str,
    lim: f64,
    (x_desc, y_desc): (&str, &str),
) -> anyhow::Result<(SvgArea<'a>, Chart2d<'a>, SvgArea<'a>)> {
    let root = SVGBackend::new(path, layout.size).into_drawing_area();
    root.fill(&WHITE)?;
    let titled = root.titled(title, ("sans-serif", layout.title_size))?;
    let (plot_area, legend_area) = titled.split_horizontally(layout.plot_width);
    let plot_area = square_chart_area(plot_area, 15, 40, layout.y_label);
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(layout.y_label)
        .build_cartesian_2d(-lim..lim, -lim..lim)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()?;
    Ok((root, chart, legend_area))
}

/// A circle of radius `r` about the origin, 361 points (the clearance circle).
pub(crate) fn circle(r: f64) -> impl Iterator<Item = (f64, f64)> {
    (0..=360).map(move |k| {
        let a = f64::from(k).to_radians();
        (r * a.cos(), r * a.sin())
    })
}

/// The layout of a Bode plot beside a legend panel: picture size (px), title font size, width
/// of the plots' part, height of the amplitude panel (the phase panel gets the rest).
pub(crate) struct BodeLayout {
    pub size: (u32, u32),
    pub title_size: u32,
    pub plot_width: u32,
    pub amplitude_height: u32,
}

/// The two charts of a Bode plot and its legend panel.
pub(crate) struct BodeCharts<'a> {
    /// The picture's root (to present).
    pub root: DrawingArea<SVGBackend<'a>, Shift>,
    /// Amplitude (µm) against speed (rpm), from 0 to the given top.
    pub amplitude: Chart2d<'a>,
    /// Phase lag (deg, 0–360) against speed.
    pub phase: Chart2d<'a>,
    /// The legend's panel.
    pub legend: DrawingArea<SVGBackend<'a>, Shift>,
}

/// A titled Bode plot at `path`: amplitude (0 to `top` µm) above phase lag (0–360°, labels
/// every 45°), both against speed `x` (rpm), with the axis descriptions `(amplitude, phase)`.
pub(crate) fn bode_plot<'a>(
    path: &'a std::path::Path,
    layout: &BodeLayout,
    title: &str,
    x: (f64, f64),
    top: f64,
    (amp_desc, phase_desc): (&str, &str),
) -> anyhow::Result<BodeCharts<'a>> {
    let root = SVGBackend::new(path, layout.size).into_drawing_area();
    root.fill(&WHITE)?;
    let titled = root.titled(title, ("sans-serif", layout.title_size))?;
    let (plots, legend) = titled.split_horizontally(layout.plot_width);
    let (upper, lower) = plots.split_vertically(layout.amplitude_height);
    let chart = |area: &DrawingArea<SVGBackend<'a>, Shift>, y: std::ops::Range<f64>| {
        ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x.0..x.1, y)
    };
    let mut amplitude = chart(&upper, 0.0..top)?;
    amplitude
        .configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc(amp_desc)
        .draw()?;
    let mut phase = chart(&lower, 0.0..360.0)?;
    phase
        .configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc(phase_desc)
        .y_labels(9)
        .draw()?;
    Ok(BodeCharts {
        root,
        amplitude,
        phase,
        legend,
    })
}
