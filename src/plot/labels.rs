//! Labels placed so that they do not overprint one another: each label tries a few positions
//! around its anchor point and takes the first whose box is clear of every box already taken
//! (other labels, markers, reserved regions) and inside the plotting region; a label with no
//! clear position is left out (its marker stays). Boxes are in backend pixels; a text's box is
//! estimated from plotters' SVG font size (0.806 of the nominal size, measured on its output)
//! and a sans-serif advance of 0.64 em a character (DejaVu Sans' digits are 0.636 em).

/// A box in backend pixels: left, top, right, bottom.
pub(crate) type PxBox = [f64; 4];

/// Rendered font size over nominal in plotters' SVG backend (a nominal 12 is written 9.677).
const SVG_FONT_SCALE: f64 = 0.806_451_6;

/// Advance width of a character (em): DejaVu Sans' digits, wider than most lower case.
const CHAR_EM: f64 = 0.64;

/// Gap between a marker and its label (px).
const GAP_PX: f64 = 4.0;

/// The boxes taken so far and the region labels must stay inside.
pub(crate) struct LabelPlacer {
    taken: Vec<PxBox>,
    bounds: PxBox,
}

impl LabelPlacer {
    /// A placer for labels inside `bounds` (backend px).
    pub(crate) fn new(bounds: PxBox) -> Self {
        Self {
            taken: Vec::new(),
            bounds,
        }
    }

    /// A placer inside a chart's plotting region.
    pub(crate) fn in_chart<DB: plotters::prelude::DrawingBackend, CT>(
        chart: &plotters::prelude::ChartContext<'_, DB, CT>,
    ) -> Self
    where
        CT: plotters::coord::CoordTranslate,
    {
        let (x, y) = chart.plotting_area().get_pixel_range();
        Self::new([x.start as f64, y.start as f64, x.end as f64, y.end as f64])
    }

    /// Marks a square of half-width `r` px about `at` as taken (a marker).
    pub(crate) fn reserve_marker(&mut self, at: (i32, i32), r: f64) {
        let (x, y) = (at.0 as f64, at.1 as f64);
        self.taken.push([x - r, y - r, x + r, y + r]);
    }

    /// Marks `b` as taken.
    pub(crate) fn reserve(&mut self, b: PxBox) {
        self.taken.push(b);
    }

    /// The offset (px, from `at` to the text's top-left corner) of a clear place for `text` in
    /// a font of nominal size `size` beside a marker of half-width `r` px at `at`, trying right,
    /// above right, below right, above, below, left, above left, below left, then the same
    /// twice as far out; None if every place is taken. The place found is taken.
    pub(crate) fn place(
        &mut self,
        at: (i32, i32),
        r: f64,
        text: &str,
        size: f64,
    ) -> Option<(i32, i32)> {
        let h = size * SVG_FONT_SCALE;
        let w = CHAR_EM * h * text.chars().count() as f64;
        let d = r + GAP_PX;
        let candidates = |k: f64| {
            let d = k * d;
            [
                (d, -0.5 * h),
                (d, -d - h),
                (d, d),
                (-0.5 * w, -d - h),
                (-0.5 * w, d),
                (-d - w, -0.5 * h),
                (-d - w, -d - h),
                (-d - w, d),
            ]
        };
        let (x, y) = (at.0 as f64, at.1 as f64);
        for (dx, dy) in candidates(1.0).into_iter().chain(candidates(2.5)) {
            let b = [x + dx, y + dy, x + dx + w, y + dy + h];
            let inside = b[0] >= self.bounds[0]
                && b[1] >= self.bounds[1]
                && b[2] <= self.bounds[2]
                && b[3] <= self.bounds[3];
            if inside && !self.taken.iter().any(|t| overlap(t, &b)) {
                self.taken.push(b);
                return Some((dx.round() as i32, dy.round() as i32));
            }
        }
        None
    }
}

/// True if two boxes share more than a point.
pub(crate) fn overlap(a: &PxBox, b: &PxBox) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// A text element whose top-left corner is `offset` px from its anchor, for a placed label.
pub(crate) fn placed_text<'a, C>(
    text: String,
    offset: (i32, i32),
    size: f64,
    colour: &'a C,
) -> plotters::element::Text<'a, (i32, i32), String>
where
    C: plotters::style::Color,
{
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    use plotters::style::IntoFont;
    plotters::element::Text::new(
        text,
        offset,
        ("sans-serif", size)
            .into_font()
            .color(colour)
            .pos(Pos::new(HPos::Left, VPos::Top)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ten labels at one point: each placed one is clear of the others and of the marker, and
    /// at most the 16 candidate places are used.
    #[test]
    fn labels_at_one_point_do_not_overlap() {
        let mut p = LabelPlacer::new([0.0, 0.0, 400.0, 400.0]);
        p.reserve_marker((200, 200), 3.0);
        let placed: Vec<PxBox> = (0..10)
            .filter_map(|k| {
                let text = format!("{} rpm", 1000 + k);
                let o = p.place((200, 200), 3.0, &text, 12.0)?;
                let h = 12.0 * SVG_FONT_SCALE;
                let w = CHAR_EM * h * text.len() as f64;
                let (x, y) = (200.0 + o.0 as f64, 200.0 + o.1 as f64);
                Some([x, y, x + w, y + h])
            })
            .collect();
        assert!(placed.len() >= 8, "{placed:?}");
        for (i, a) in placed.iter().enumerate() {
            assert!(!overlap(a, &[197.0, 197.0, 203.0, 203.0]), "{a:?}");
            for b in &placed[i + 1..] {
                // rounding to whole pixels may bring two boxes within half a pixel
                let shrunk = [b[0] + 0.5, b[1] + 0.5, b[2] - 0.5, b[3] - 0.5];
                assert!(!overlap(a, &shrunk), "{a:?} {b:?}");
            }
        }
    }
}
