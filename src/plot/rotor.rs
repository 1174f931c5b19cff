//! A drawing of the rotor model from its machine file, to scale (1:1, mm): the shaft sections
//! with their diameters (and bores), the discs as their equivalent uniform annuli, the bearings
//! at their journals (film bearings as pads of their length, rigid ones as pinned supports), the
//! probe stations and the unbalances, each named.

use super::legend::{draw_side_legend, Entry, Swatch};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

const STEEL: RGBColor = RGBColor(185, 190, 200);
const EDGE: RGBColor = RGBColor(60, 60, 70);
const DISC: RGBColor = RGBColor(120, 150, 200);
const PAD: RGBColor = RGBColor(230, 140, 40);
const PROBE: RGBColor = RGBColor(150, 40, 170);
const UNBALANCE: RGBColor = RGBColor(210, 30, 30);

/// A shaft section of constant diameter (m).
#[derive(Debug, Clone, Copy)]
pub struct SectionGlyph {
    pub z0_m: f64,
    pub z1_m: f64,
    pub outer_diameter_m: f64,
    pub inner_diameter_m: f64,
}

/// A disc drawn as its equivalent uniform annulus (m).
#[derive(Debug, Clone)]
pub struct DiscGlyph {
    pub name: String,
    pub z_m: f64,
    pub outer_diameter_m: f64,
    pub width_m: f64,
}

/// A bearing at its journal (m); `pad_length_m` 0 for a support with no length (rigid, linear).
#[derive(Debug, Clone)]
pub struct BearingGlyph {
    pub label: String,
    pub z_m: f64,
    pub journal_diameter_m: f64,
    pub pad_length_m: f64,
    pub rigid: bool,
}

/// The rotor model as drawn.
#[derive(Debug, Clone)]
pub struct RotorDrawing {
    pub title: String,
    pub sections: Vec<SectionGlyph>,
    /// Axial position of every node (m): the FE mesh, ticked on the axis.
    pub node_z_m: Vec<f64>,
    pub discs: Vec<DiscGlyph>,
    pub bearings: Vec<BearingGlyph>,
    /// Probe stations: name, z (m), shaft diameter there (m).
    pub probes: Vec<(String, f64, f64)>,
    /// Unbalances: label, z (m), shaft diameter there (m).
    pub unbalances: Vec<(String, f64, f64)>,
}

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The half-height (mm) the drawing needs above and below the axis.
fn half_height_mm(d: &RotorDrawing) -> f64 {
    let shaft = d
        .sections
        .iter()
        .map(|s| s.outer_diameter_m)
        .fold(0.0, f64::max);
    let discs = d
        .discs
        .iter()
        .map(|s| s.outer_diameter_m)
        .fold(0.0, f64::max);
    let pads = d
        .bearings
        .iter()
        .map(|b| 1.6 * b.journal_diameter_m)
        .fold(0.0, f64::max);
    500.0 * shaft.max(discs).max(pads)
}

/// The drawing, 1:1 in mm, the legend in a panel of its own.
pub fn rotor_svg(path: &Path, d: &RotorDrawing) -> anyhow::Result<()> {
    let z1 = 1e3 * d.node_z_m.last().copied().unwrap_or(1.0);
    let (x0, x1) = (-0.04 * z1, 1.04 * z1);
    let plot_w = 1000.0;
    let px_per_mm = plot_w / (x1 - x0);
    // room for the labels: 70 px above and below the tallest part
    let half = half_height_mm(d) + 70.0 / px_per_mm;
    let plot_h = 2.0 * half * px_per_mm;
    let (margin, x_lab, y_lab) = (15u32, 40u32, 70u32);
    let (w, h) = (
        plot_w as u32 + y_lab + 2 * margin,
        plot_h.round() as u32 + x_lab + 2 * margin,
    );
    let root = SVGBackend::new(path, (w + 250, h + 40)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(&d.title, ("sans-serif", 22))?;
    let (area, legend_area) = root.split_horizontally(w);
    // the y range that fills the plotting height the title left, at the x axis' px per mm
    let h_plot = f64::from(area.dim_in_pixel().1.saturating_sub(x_lab + 2 * margin));
    let half = 0.5 * h_plot / px_per_mm;
    let mut chart = ChartBuilder::on(&area)
        .margin(margin)
        .x_label_area_size(x_lab)
        .y_label_area_size(y_lab)
        .build_cartesian_2d(x0..x1, -half..half)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("axial position z (mm)")
        .y_desc("radius (mm)")
        .draw()?;
    draw_shaft(&mut chart, d)?;
    draw_discs(&mut chart, d)?;
    draw_bearings(&mut chart, d)?;
    draw_probes(&mut chart, d)?;
    draw_unbalances(&mut chart, d)?;
    let entries = [
        Entry::new(Swatch::Line(STEEL, 8), "shaft section"),
        Entry::new(Swatch::Line(DISC, 8), "disc (uniform annulus)"),
        Entry::new(Swatch::Line(PAD, 8), "film bearing (pad length)"),
        Entry::new(Swatch::Line(EDGE, 2), "rigid support"),
        Entry::new(Swatch::Diamond(PROBE), "probe station"),
        Entry::new(Swatch::Dot(UNBALANCE), "unbalance"),
    ];
    draw_side_legend(&legend_area, &entries, 30)?;
    let note = ("sans-serif", 13).into_font();
    for (i, line) in [
        "to scale, 1:1;",
        "disc diameter and width",
        "from m, Ip, Id: R² = 2Ip/m − r²,",
        "t² = (12 Id − 6 Ip)/m;",
        "ticks on the axis: FE nodes",
    ]
    .iter()
    .enumerate()
    {
        legend_area.draw(&Text::new(*line, (8, 200 + 18 * i as i32), note.clone()))?;
    }
    root.present()?;
    Ok(())
}

/// Shaft sections (bores hatched lighter), the centre line and the node ticks.
fn draw_shaft(chart: &mut Chart, d: &RotorDrawing) -> anyhow::Result<()> {
    for s in &d.sections {
        let (a, b) = (1e3 * s.z0_m, 1e3 * s.z1_m);
        let (ro, ri) = (500.0 * s.outer_diameter_m, 500.0 * s.inner_diameter_m);
        chart.draw_series([
            Rectangle::new([(a, -ro), (b, ro)], STEEL.filled()),
            Rectangle::new([(a, -ro), (b, ro)], EDGE.stroke_width(1)),
        ])?;
        if ri > 0.0 {
            chart.draw_series(std::iter::once(Rectangle::new(
                [(a, -ri), (b, ri)],
                WHITE.mix(0.7).filled(),
            )))?;
        }
    }
    let (z0, z1) = (
        1e3 * d.node_z_m.first().copied().unwrap_or(0.0),
        1e3 * d.node_z_m.last().copied().unwrap_or(1.0),
    );
    chart.draw_series(std::iter::once(PathElement::new(
        [(z0 - 10.0, 0.0), (z1 + 10.0, 0.0)],
        EDGE.stroke_width(1),
    )))?;
    chart.draw_series(d.node_z_m.iter().map(|z| {
        EmptyElement::at((1e3 * z, 0.0)) + PathElement::new([(0, -3), (0, 3)], EDGE.stroke_width(1))
    }))?;
    Ok(())
}

/// Discs as annuli of their width, names above the tallest (two rows, alternating, so that
/// neighbours do not collide).
fn draw_discs(chart: &mut Chart, d: &RotorDrawing) -> anyhow::Result<()> {
    let top = 500.0
        * d.discs
            .iter()
            .map(|s| s.outer_diameter_m)
            .fold(0.0, f64::max);
    for (i, disc) in d.discs.iter().enumerate() {
        let (z, r, t) = (
            1e3 * disc.z_m,
            500.0 * disc.outer_diameter_m,
            500.0 * disc.width_m,
        );
        chart.draw_series([
            Rectangle::new([(z - t, -r), (z + t, r)], DISC.filled()),
            Rectangle::new([(z - t, -r), (z + t, r)], EDGE.stroke_width(1)),
        ])?;
        // a common baseline above the tallest disc, two rows alternating
        let row = if i % 2 == 0 { -10 } else { -26 };
        chart.draw_series(std::iter::once(
            EmptyElement::at((z, top))
                + Text::new(
                    format!("{} Ø{:.0}", disc.name, 1e3 * disc.outer_diameter_m),
                    (-3 * disc.name.chars().count() as i32 - 12, row),
                    ("sans-serif", 11).into_font(),
                ),
        ))?;
    }
    Ok(())
}

/// Film bearings as pads above and below the journal over their length; rigid supports as a
/// pinned triangle; the label below.
fn draw_bearings(chart: &mut Chart, d: &RotorDrawing) -> anyhow::Result<()> {
    for b in &d.bearings {
        let (z, r) = (1e3 * b.z_m, 500.0 * b.journal_diameter_m);
        let half_l = (500.0 * b.pad_length_m).max(4.0);
        let depth = 0.6 * r;
        if b.rigid {
            chart.draw_series(std::iter::once(
                EmptyElement::at((z, -r))
                    + PathElement::new([(0, 0), (10, 16), (-10, 16), (0, 0)], EDGE.stroke_width(2))
                    + PathElement::new([(-14, 18), (14, 18)], EDGE.stroke_width(2)),
            ))?;
        } else {
            for sign in [1.0, -1.0] {
                let (inner, outer) = (sign * r, sign * (r + depth));
                chart.draw_series([
                    Rectangle::new([(z - half_l, inner), (z + half_l, outer)], PAD.filled()),
                    Rectangle::new(
                        [(z - half_l, inner), (z + half_l, outer)],
                        EDGE.stroke_width(1),
                    ),
                ])?;
            }
        }
        chart.draw_series(std::iter::once(
            EmptyElement::at((z, -(r + depth)))
                + Text::new(
                    b.label.clone(),
                    (-3 * b.label.chars().count() as i32, 24),
                    ("sans-serif", 11).into_font(),
                ),
        ))?;
    }
    Ok(())
}

/// Probe stations: a diamond above the shaft (above the pads at a bearing), named above it.
fn draw_probes(chart: &mut Chart, d: &RotorDrawing) -> anyhow::Result<()> {
    for (name, z, dia) in &d.probes {
        let z = 1e3 * z;
        let top = d
            .bearings
            .iter()
            .filter(|b| (1e3 * b.z_m - z).abs() < 1e3 * b.pad_length_m.max(1e-3))
            .map(|b| 800.0 * b.journal_diameter_m)
            .fold(500.0 * dia, f64::max);
        chart.draw_series(std::iter::once(
            EmptyElement::at((z, top))
                + PathElement::new(
                    [(0, -4), (6, -10), (0, -16), (-6, -10), (0, -4)],
                    PROBE.stroke_width(2),
                )
                + Text::new(
                    name.clone(),
                    (-3 * name.chars().count() as i32, -32),
                    ("sans-serif", 11).into_font().color(&PROBE),
                ),
        ))?;
    }
    Ok(())
}

/// Unbalances: a dot on the shaft surface at their node, labelled.
fn draw_unbalances(chart: &mut Chart, d: &RotorDrawing) -> anyhow::Result<()> {
    for (label, z, dia) in &d.unbalances {
        chart.draw_series(std::iter::once(
            EmptyElement::at((1e3 * z, 500.0 * dia))
                + Circle::new((0, 0), 4, UNBALANCE.filled())
                + Text::new(
                    label.clone(),
                    (6, 2),
                    ("sans-serif", 11).into_font().color(&UNBALANCE),
                ),
        ))?;
    }
    Ok(())
}
