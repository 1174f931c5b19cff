//! Plots of a transient run: orbit in the clearance circle, order spectrum, pressure map, and the
//! amplitude–speed characteristic of a sweep.

use crate::monitor::OrderComponent;
use plotters::prelude::*;
use std::path::Path;

/// The orbit (last two revolutions) of a journal inside its clearance circle, 1:1, in µm.
pub fn orbit_svg(
    path: &Path,
    title: &str,
    orbit_m: &[[f64; 2]],
    clearance_m: f64,
) -> anyhow::Result<()> {
    let c = clearance_m * 1e6;
    let root = SVGBackend::new(path, (640, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let lim = 1.1 * c;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(-lim..lim, -lim..lim)?;
    chart
        .configure_mesh()
        .x_desc("x (µm)")
        .y_desc("y (µm)")
        .draw()?;
    let circle: Vec<(f64, f64)> = (0..=360)
        .map(|k| {
            let a = (k as f64).to_radians();
            (c * a.cos(), c * a.sin())
        })
        .collect();
    chart
        .draw_series(LineSeries::new(circle, BLACK))?
        .label("clearance circle")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK));
    chart
        .draw_series(LineSeries::new(
            orbit_m.iter().map(|p| (p[0] * 1e6, p[1] * 1e6)),
            BLUE,
        ))?
        .label("journal centre, last two revolutions")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// The full order spectrum: forward (positive orders) and backward (negative) orbit radii, µm.
pub fn spectrum_svg(path: &Path, title: &str, spectrum: &[OrderComponent]) -> anyhow::Result<()> {
    let max_order = spectrum.last().map_or(2.0, |c| c.order);
    let top = spectrum
        .iter()
        .map(|c| c.forward_m.max(c.backward_m))
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
    root.present()?;
    Ok(())
}

/// Mid-plane film pressure over the last two revolutions: angle against step, colour = pressure.
pub fn pressure_map_svg(path: &Path, title: &str, map_pa: &[Vec<f64>]) -> anyhow::Result<()> {
    let steps = map_pa.len().max(1);
    let points = map_pa.first().map_or(1, Vec::len).max(1);
    let p_max = map_pa.iter().flatten().fold(1e-9, |a: f64, &b| a.max(b));
    let root = SVGBackend::new(path, (800, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let caption = format!("{title} (white 0 → black {:.2} MPa)", p_max * 1e-6);
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..steps as f64, 0.0..360.0)?;
    chart
        .configure_mesh()
        .x_desc("step in the last two revolutions")
        .y_desc("angle from +x (deg)")
        .draw()?;
    let dy = 360.0 / points as f64;
    chart.draw_series(map_pa.iter().enumerate().flat_map(|(t, row)| {
        row.iter().enumerate().map(move |(k, &p)| {
            let shade = (255.0 * (1.0 - (p / p_max).clamp(0.0, 1.0))) as u8;
            Rectangle::new(
                [
                    (t as f64, k as f64 * dy),
                    (t as f64 + 1.0, (k + 1) as f64 * dy),
                ],
                RGBColor(shade, shade, shade).filled(),
            )
        })
    }))?;
    root.present()?;
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
