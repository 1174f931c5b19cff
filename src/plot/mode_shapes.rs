//! Damped mode shapes along the rotor: per mode the deflected line (normalised, signed, with
//! the orbit envelope ±semi-major axis) and, below it on the same axial scale, the orbit ellipse
//! of each station seen along the axis (x right, y up), drawn in the colour of its whirl sense.

use super::legend::{draw_side_legend, Entry, Swatch};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

const FORWARD: RGBColor = RGBColor(31, 90, 200);
const BACKWARD: RGBColor = RGBColor(20, 150, 60);
const BEARING: RGBColor = RGBColor(220, 120, 20);
const GREY: RGBColor = RGBColor(150, 150, 150);

/// One node of a mode shape (normalised so that the largest semi-major axis is 1).
#[derive(Debug, Clone, Copy)]
pub struct ShapeNode {
    /// Axial position (m).
    pub z_m: f64,
    /// Signed deflection along the reference major axis at the reference instant.
    pub deflection: f64,
    /// Semi-major axis of the node's orbit.
    pub semi_major: f64,
    /// Forward and backward phasors at the reference instant (re, im):
    /// orbit p(τ) = A e^{iτ} + B e^{−iτ}.
    pub forward: [f64; 2],
    pub backward: [f64; 2],
}

/// One mode's panel.
pub struct ShapePanel {
    /// "mode 1: 31.44 Hz, forward, log dec 0.000".
    pub title: String,
    /// Every node.
    pub nodes: Vec<ShapeNode>,
}

/// A station whose orbit is drawn (disc, bearing, probe, or a plain node with no name): name
/// and node index. The plot takes them in the order given, as priority.
pub struct ShapeStation {
    pub name: String,
    pub node: usize,
    /// A bearing (marked on the deflected line).
    pub bearing: bool,
}

/// The mode shapes at one speed, two panels a row, the legend in a panel of its own.
pub fn mode_shapes_svg(
    path: &Path,
    title: &str,
    panels: &[ShapePanel],
    stations: &[ShapeStation],
) -> anyhow::Result<()> {
    let (pw, ph) = (640u32, 470u32);
    let rows = panels.len().div_ceil(2).max(1) as u32;
    let root = SVGBackend::new(path, (2 * pw + 250, 50 + rows * ph)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    let (grid, legend_area) = root.split_horizontally(2 * pw);
    let cells = grid.split_evenly((rows as usize, 2));
    for (panel, cell) in panels.iter().zip(&cells) {
        draw_panel(cell, panel, stations)?;
    }
    let entries = [
        Entry::new(Swatch::Line(BLACK, 2), "deflected line"),
        Entry::new(Swatch::Line(GREY, 1), "± orbit semi-major axis"),
        Entry::new(Swatch::Line(FORWARD, 2), "orbit, forward whirl"),
        Entry::new(Swatch::Line(BACKWARD, 2), "orbit, backward whirl"),
        Entry::new(Swatch::Dot(BLACK), "position at the drawn instant"),
        Entry::new(Swatch::Dot(BEARING), "bearing"),
    ];
    draw_side_legend(&legend_area, &entries, 30)?;
    let note = ("sans-serif", 13).into_font();
    for (i, line) in [
        "normalised: largest orbit 1;",
        "the line at the instant the",
        "largest orbit is at its major",
        "axis; thick arc: the next 40°",
        "of the whirl; orbits seen",
        "along the axis, x right, y up",
    ]
    .iter()
    .enumerate()
    {
        legend_area.draw(&Text::new(*line, (8, 200 + 18 * i as i32), note.clone()))?;
    }
    root.present()?;
    Ok(())
}

/// Axial range of a panel, padded 3 %.
fn z_range(nodes: &[ShapeNode]) -> (f64, f64) {
    let (z0, z1) = (
        nodes.first().map_or(0.0, |n| n.z_m),
        nodes.last().map_or(1.0, |n| n.z_m),
    );
    let pad = 0.03 * (z1 - z0).max(1e-6);
    (z0 - pad, z1 + pad)
}

/// One mode: title, deflected line with its envelope (upper 62 %), orbits (lower part).
fn draw_panel<DB: DrawingBackend>(
    cell: &DrawingArea<DB, Shift>,
    panel: &ShapePanel,
    stations: &[ShapeStation],
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let cell = cell.titled(&panel.title, ("sans-serif", 16))?;
    let (_, h) = cell.dim_in_pixel();
    let (upper, lower) = cell.split_vertically((h as f64 * 0.62) as u32);
    let (z0, z1) = z_range(&panel.nodes);
    // right margin: room for the last orbit glyph (radius 22 px) inside the panel
    let mut chart = ChartBuilder::on(&upper)
        .margin(10)
        .margin_right(36)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(z0..z1, -1.15..1.15)?;
    chart
        .configure_mesh()
        .x_desc("axial position z (m)")
        .y_desc("deflection (normalised)")
        .draw()?;
    chart.draw_series(LineSeries::new(
        [(z0, 0.0), (z1, 0.0)],
        BLACK.stroke_width(1),
    ))?;
    for sign in [1.0, -1.0] {
        chart.draw_series(LineSeries::new(
            panel.nodes.iter().map(|n| (n.z_m, sign * n.semi_major)),
            GREY.stroke_width(1),
        ))?;
    }
    let line: Vec<(f64, f64)> = panel.nodes.iter().map(|n| (n.z_m, n.deflection)).collect();
    chart.draw_series(LineSeries::new(line.iter().copied(), BLACK.stroke_width(2)))?;
    chart.draw_series(line.iter().map(|p| Circle::new(*p, 2, BLACK.filled())))?;
    for s in stations.iter().filter(|s| s.bearing) {
        if let Some(n) = panel.nodes.get(s.node) {
            chart.draw_series(std::iter::once(
                EmptyElement::at((n.z_m, 0.0)) + Circle::new((0, 0), 5, BEARING.filled()),
            ))?;
        }
    }
    draw_orbits(&lower, panel, stations, (z0, z1))
}

/// The orbit ellipses of the stations, on the deflection chart's axial scale, skipping a
/// station closer than one glyph to the one drawn before.
fn draw_orbits<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &ShapePanel,
    stations: &[ShapeStation],
    (z0, z1): (f64, f64),
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let mut strip = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(36)
        .y_label_area_size(60)
        .build_cartesian_2d(z0..z1, -1.0..1.0)?;
    let radius = 22.0;
    // in the stations' order of priority, each where it keeps a glyph's width from the others
    let mut taken: Vec<(i32, &ShapeNode, &str)> = Vec::new();
    for s in stations {
        let Some(n) = panel.nodes.get(s.node) else {
            continue;
        };
        let px = strip.backend_coord(&(n.z_m, 0.0)).0;
        if taken
            .iter()
            .any(|t| (px - t.0).abs() < (2.0 * radius) as i32 + 6)
        {
            continue;
        }
        taken.push((px, n, &s.name));
    }
    // names in two rows, alternating along the axis, so that neighbours' names do not collide
    taken.sort_by_key(|t| t.0);
    let mut named = 0;
    for (_, n, name) in taken {
        let row = if named % 2 == 0 { 6 } else { 20 };
        named += usize::from(!name.is_empty());
        draw_orbit(&mut strip, n, radius, name, row)?;
    }
    Ok(())
}

/// One station's orbit p(τ) = A e^{iτ} + B e^{−iτ} (radius `radius` px for semi-major 1), its
/// drawn instant (τ = 0) as a dot, the next 40° thick, its name `name_row_px` below.
fn draw_orbit<DB: DrawingBackend>(
    strip: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    n: &ShapeNode,
    radius: f64,
    name: &str,
    name_row_px: i32,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let forward = n.forward[0].hypot(n.forward[1]) >= n.backward[0].hypot(n.backward[1]);
    let colour = if forward { FORWARD } else { BACKWARD };
    let at = |tau: f64| {
        let (c, s) = (tau.cos(), tau.sin());
        let x = n.forward[0] * c - n.forward[1] * s + n.backward[0] * c + n.backward[1] * s;
        let y = n.forward[0] * s + n.forward[1] * c - n.backward[0] * s + n.backward[1] * c;
        ((radius * x).round() as i32, (-radius * y).round() as i32)
    };
    let ring: Vec<(i32, i32)> = (0..=72)
        .map(|k| at(f64::from(k) * 5f64.to_radians()))
        .collect();
    let arc: Vec<(i32, i32)> = (0..=8)
        .map(|k| at(f64::from(k) * 5f64.to_radians()))
        .collect();
    let centre = (n.z_m, 0.0);
    strip.draw_series(std::iter::once(
        EmptyElement::at(centre)
            + PathElement::new([(-3, 0), (3, 0)], GREY.stroke_width(1))
            + PathElement::new([(0, -3), (0, 3)], GREY.stroke_width(1))
            + PathElement::new(ring, colour.stroke_width(1))
            + PathElement::new(arc, colour.stroke_width(3))
            + Circle::new(at(0.0), 3, BLACK.filled())
            + Text::new(
                name.to_string(),
                (
                    -3 * name.chars().count() as i32,
                    radius as i32 + name_row_px,
                ),
                ("sans-serif", 11).into_font(),
            ),
    ))?;
    Ok(())
}
