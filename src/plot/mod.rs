//! Plots written as SVG files (plotters' SVG backend).

mod campbell;
mod legend;
mod replay;
mod response;
mod transient;

pub use campbell::campbell_svg;
pub use replay::{
    amplitude_speed_svg, orbit_comparison_svg, spectrum_comparison_svg, waterfall_svg,
};
pub use response::{bode_svg, polar_svg, ResponseCurve};
pub use transient::{orbit_svg, pressure_map_svg, spectrum_svg, sweep_svg};
