//! A legend drawn in its own panel beside a chart, so that it can never cover data.

use plotters::coord::Shift;
use plotters::prelude::*;

/// How a legend entry is drawn.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Swatch {
    /// A line in this colour (width, px).
    Line(RGBColor, u32),
    /// A filled dot.
    Dot(RGBColor),
    /// A hollow diamond marker.
    Diamond(RGBColor),
    /// A hollow ring marker.
    Ring(RGBColor),
    /// No swatch: a line of text (a note under the entries).
    Text,
}

/// One entry: swatch and text.
pub(crate) struct Entry {
    pub swatch: Swatch,
    pub label: String,
}

impl Entry {
    pub(crate) fn new(swatch: Swatch, label: impl Into<String>) -> Self {
        Self {
            swatch,
            label: label.into(),
        }
    }
}

/// Draws `entries` top-down in `area` (a panel of its own), headed "legend", 22 px a line,
/// starting `top_px` below the panel's top.
pub(crate) fn draw_side_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    top_px: i32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", 14).into_font();
    let mut y = top_px;
    area.draw(&Text::new(
        "legend",
        (8, y),
        font.clone().style(FontStyle::Bold),
    ))?;
    y += 24;
    for e in entries {
        let (x0, yc) = (10, y + 7);
        match e.swatch {
            Swatch::Line(c, w) => {
                area.draw(&PathElement::new(
                    [(x0, yc), (x0 + 24, yc)],
                    c.stroke_width(w),
                ))?;
            }
            Swatch::Dot(c) => area.draw(&Circle::new((x0 + 12, yc), 4, c.filled()))?,
            Swatch::Ring(c) => area.draw(&Circle::new((x0 + 12, yc), 4, c.stroke_width(1)))?,
            Swatch::Text => {}
            Swatch::Diamond(c) => {
                area.draw(&PathElement::new(
                    [
                        (x0 + 12, yc - 6),
                        (x0 + 18, yc),
                        (x0 + 12, yc + 6),
                        (x0 + 6, yc),
                        (x0 + 12, yc - 6),
                    ],
                    c.stroke_width(2),
                ))?;
            }
        }
        area.draw(&Text::new(e.label.clone(), (x0 + 32, y), font.clone()))?;
        y += 22;
    }
    Ok(())
}
