//! The Campbell diagram.

use crate::rotor::{CampbellPoint, WhirlDirection};
use plotters::prelude::*;
use std::path::Path;

/// Writes a Campbell diagram to `path`: damped natural frequencies against speed, forward modes
/// in blue, backward in green, unstable points (negative log decrement) in red, the running
/// frequency 1X and 0.5X as lines, the stability threshold (rpm) as a vertical line; a lower panel
/// shows the logarithmic decrements.
pub fn campbell_svg(
    path: &Path,
    title: &str,
    points: &[CampbellPoint],
    threshold_rpm: Option<f64>,
) -> anyhow::Result<()> {
    let (x0, x1) = (
        points.first().map_or(0.0, |p| p.speed_rpm),
        points.last().map_or(1.0, |p| p.speed_rpm),
    );
    let f_max = points
        .iter()
        .flat_map(|p| p.modes.iter().map(|m| m.frequency_hz))
        .fold(x1 / 60.0, f64::max)
        * 1.05;
    let (d_min, d_max) = points
        .iter()
        .flat_map(|p| p.modes.iter().map(|m| m.log_dec))
        .fold((0.0_f64, 0.1_f64), |(a, b), d| (a.min(d), b.max(d)));
    let d_max = d_max.min(5.0);
    let root = SVGBackend::new(path, (900, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let (upper, lower) = root.split_vertically(600);
    let mut chart = ChartBuilder::on(&upper)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, 0.0..f_max)?;
    chart
        .configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc("frequency (Hz)")
        .draw()?;
    for (ratio, label) in [(1.0, "1X"), (0.5, "0.5X")] {
        chart
            .draw_series(LineSeries::new(
                [(x0, x0 * ratio / 60.0), (x1, x1 * ratio / 60.0)],
                BLACK.mix(if ratio == 1.0 { 0.8 } else { 0.4 }),
            ))?
            .label(label)
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
    }
    let colour = |dir: WhirlDirection, log_dec: f64| {
        if log_dec < 0.0 {
            RED
        } else if dir == WhirlDirection::Forward {
            BLUE
        } else {
            GREEN
        }
    };
    chart.draw_series(points.iter().flat_map(|p| {
        p.modes.iter().map(move |m| {
            Circle::new(
                (p.speed_rpm, m.frequency_hz),
                3,
                colour(m.direction, m.log_dec).filled(),
            )
        })
    }))?;
    if let Some(t) = threshold_rpm {
        chart
            .draw_series(LineSeries::new([(t, 0.0), (t, f_max)], RED))?
            .label(format!("stability threshold {t:.0} rpm"))
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;

    let mut decs = ChartBuilder::on(&lower)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, (d_min * 1.1 - 0.05)..(d_max * 1.05))?;
    decs.configure_mesh()
        .x_desc("speed (rpm)")
        .y_desc("log decrement")
        .draw()?;
    decs.draw_series(LineSeries::new([(x0, 0.0), (x1, 0.0)], BLACK))?;
    decs.draw_series(points.iter().flat_map(|p| {
        p.modes.iter().filter(|m| m.log_dec <= d_max).map(move |m| {
            Circle::new(
                (p.speed_rpm, m.log_dec),
                3,
                colour(m.direction, m.log_dec).filled(),
            )
        })
    }))?;
    root.present()?;
    Ok(())
}
