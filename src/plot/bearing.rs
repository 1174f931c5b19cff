//! A bearing over a speed range: its eight coefficients, ε and attitude angle against speed (as
//! bearing codes plot them), and the shaft centerline (the journal's static position in the
//! clearance circle, 1:1).

use super::legend::{draw_side_legend, Entry, Swatch};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// A bearing's equilibrium at each speed of a sweep.
pub struct BearingCurves {
    /// Bearing (and machine) named in the titles.
    pub name: String,
    /// Speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Eccentricity ratio at each speed.
    pub eccentricity: Vec<f64>,
    /// Attitude angle (deg).
    pub attitude_deg: Vec<f64>,
    /// `[[kxx, kxy], [kyx, kyy]]` (N/m), load frame.
    pub stiffness: Vec<nalgebra::Matrix2<f64>>,
    /// `[[cxx, cxy], [cyx, cyy]]` (N·s/m), load frame.
    pub damping: Vec<nalgebra::Matrix2<f64>>,
    /// Journal centre in the machine frame (m).
    pub position_m: Vec<[f64; 2]>,
    /// Radial clearance (m).
    pub clearance_m: f64,
    /// Direction of the static load in the machine frame (deg from +x towards +y).
    pub load_direction_deg: f64,
}

const COEF_COLOURS: [RGBColor; 4] = [
    RGBColor(31, 90, 200),
    RGBColor(220, 90, 20),
    RGBColor(20, 150, 60),
    RGBColor(150, 40, 170),
];
const COEF_NAMES: [&str; 4] = ["xx", "xy", "yx", "yy"];

/// The range of `values` widened by 5 % (and to include 0 when `with_zero`); a flat set gets ±1.
fn padded(values: impl Iterator<Item = f64>, with_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = values.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    if with_zero {
        (lo, hi) = (lo.min(0.0), hi.max(0.0));
    }
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return (lo - 1.0, hi + 1.0);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// One quantity against speed: a line through dots at the computed speeds, one series per
/// entry of `series` (values, colour).
fn speed_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    speeds: &[f64],
    y_desc: &str,
    series: &[(Vec<f64>, RGBColor)],
    with_zero: bool,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let x = padded(speeds.iter().copied(), false);
    let y = padded(series.iter().flat_map(|s| s.0.iter().copied()), with_zero);
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(38)
        .y_label_area_size(70)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    chart
        .configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc(y_desc)
        .draw()?;
    if with_zero && y.0 < 0.0 {
        chart.draw_series(LineSeries::new(
            [(x.0, 0.0), (x.1, 0.0)],
            BLACK.stroke_width(1),
        ))?;
    }
    for (values, colour) in series {
        let pts: Vec<(f64, f64)> = speeds.iter().copied().zip(values.iter().copied()).collect();
        chart.draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(2)))?;
        chart.draw_series(pts.iter().map(|p| Circle::new(*p, 2, colour.filled())))?;
    }
    Ok(())
}

/// ε and φ (top, side by side), the four stiffnesses (MN/m) and the four dampings (kN·s/m)
/// against speed; the legend in a panel of its own.
pub fn bearing_coefficients_svg(path: &Path, b: &BearingCurves) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (1150, 1050)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        &format!("Bearing coefficients against speed: {}", b.name),
        ("sans-serif", 22),
    )?;
    let (plots, legend_area) = root.split_horizontally(880);
    let rows = plots.split_evenly((3, 1));
    let (eps_area, phi_area) = rows[0].split_horizontally(440);
    let blue = COEF_COLOURS[0];
    speed_chart(
        &eps_area,
        &b.speeds_rpm,
        "eccentricity ratio ε",
        &[(b.eccentricity.clone(), blue)],
        false,
    )?;
    speed_chart(
        &phi_area,
        &b.speeds_rpm,
        "attitude angle φ (deg)",
        &[(b.attitude_deg.clone(), blue)],
        false,
    )?;
    let pick = |m: &[nalgebra::Matrix2<f64>], unit: f64| -> Vec<(Vec<f64>, RGBColor)> {
        (0..4)
            .map(|k| {
                let v = m.iter().map(|a| a[(k / 2, k % 2)] * unit).collect();
                (v, COEF_COLOURS[k])
            })
            .collect()
    };
    speed_chart(
        &rows[1],
        &b.speeds_rpm,
        "stiffness k (MN/m)",
        &pick(&b.stiffness, 1e-6),
        true,
    )?;
    speed_chart(
        &rows[2],
        &b.speeds_rpm,
        "damping c (kN·s/m)",
        &pick(&b.damping, 1e-3),
        true,
    )?;
    let mut entries: Vec<Entry> = (0..4)
        .map(|k| {
            Entry::new(
                Swatch::Line(COEF_COLOURS[k], 2),
                format!("k{0}, c{0}", COEF_NAMES[k]),
            )
        })
        .collect();
    entries.push(Entry::new(Swatch::Dot(BLACK), "computed speed"));
    draw_side_legend(&legend_area, &entries, 380)?;
    let note = ("sans-serif", 13).into_font();
    for (i, line) in [
        "x along the static load,",
        "y 90° ahead of it in the",
        "direction of rotation;",
        "ΔF = −k Δq − c Δq̇",
    ]
    .iter()
    .enumerate()
    {
        legend_area.draw(&Text::new(*line, (8, 540 + 18 * i as i32), note.clone()))?;
    }
    root.present()?;
    Ok(())
}

/// The shaft centerline: the journal centre at each speed in the clearance circle (machine
/// frame, µm, 1:1), speeds marked along it, the load direction drawn from the centre.
pub fn centerline_svg(path: &Path, b: &BearingCurves) -> anyhow::Result<()> {
    let c = b.clearance_m * 1e6;
    let (root, mut chart, legend_area) = super::square_plot(
        path,
        &super::SQUARE_1000,
        &format!("Shaft centerline: {}", b.name),
        1.1 * c,
        ("x, journal centre (µm)", "y, journal centre (µm)"),
    )?;
    let grey = RGBColor(120, 120, 120);
    chart.draw_series(LineSeries::new(super::circle(c), grey.stroke_width(2)))?;
    let red = RGBColor(200, 30, 30);
    let la = b.load_direction_deg.to_radians();
    chart.draw_series(std::iter::once(PathElement::new(
        [(0.0, 0.0), (0.5 * c * la.cos(), 0.5 * c * la.sin())],
        red.stroke_width(2),
    )))?;
    let blue = COEF_COLOURS[0];
    let pts: Vec<(f64, f64)> = b
        .position_m
        .iter()
        .map(|p| (p[0] * 1e6, p[1] * 1e6))
        .collect();
    chart.draw_series(LineSeries::new(pts.iter().copied(), blue.stroke_width(2)))?;
    // a speed is marked where the path has moved 6 % of the clearance since the last mark
    let mut marked = Vec::new();
    for (i, p) in pts.iter().enumerate() {
        let far = |j: &usize| (pts[*j].0 - p.0).hypot(pts[*j].1 - p.1) > 0.06 * c;
        if marked.last().is_none_or(far) {
            marked.push(i);
        }
    }
    // the last speed is always marked (in place of a mark too close to it)
    if let Some(&last) = marked.last() {
        let end = pts.len() - 1;
        if last != end {
            if (pts[last].0 - pts[end].0).hypot(pts[last].1 - pts[end].1) <= 0.06 * c && last > 0 {
                marked.pop();
            }
            marked.push(end);
        }
    }
    chart.draw_series(marked.into_iter().map(|i| {
        EmptyElement::at(pts[i])
            + Circle::new((0, 0), 3, blue.filled())
            + Text::new(
                format!("{:.0}", b.speeds_rpm[i]),
                (6, -4),
                ("sans-serif", 12).into_font(),
            )
    }))?;
    let entries = [
        Entry::new(
            Swatch::Line(grey, 2),
            format!("clearance circle, c = {c:.1} µm"),
        ),
        Entry::new(Swatch::Line(blue, 2), "journal centre"),
        Entry::new(Swatch::Dot(blue), "speed (rpm) marks"),
        Entry::new(Swatch::Line(red, 2), "static load direction"),
    ];
    draw_side_legend(&legend_area, &entries, 30)?;
    root.present()?;
    Ok(())
}
