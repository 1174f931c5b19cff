//! Plots written as SVG files (plotters' SVG backend).

mod campbell;
mod transient;

pub use campbell::campbell_svg;
pub use transient::{orbit_svg, pressure_map_svg, spectrum_svg, sweep_svg};
