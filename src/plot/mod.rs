//! Plots written as SVG files (plotters' SVG backend).

mod bearing;
mod campbell;
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
pub use transient::{orbit_svg, pressure_map_svg, spectrum_svg, sweep_svg};

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
