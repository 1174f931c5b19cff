//! Reading an SVG written by rotor-twin's plots back (plotters' SVG backend): its texts with their
//! positions, its data markers and lines, so that a test can check titles, axis labels, legends
//! and aspect ratios.
#![allow(dead_code)]

/// A `<text>` element: anchor position (px) and content.
#[derive(Debug, Clone)]
pub struct SvgText {
    pub x: f64,
    pub y: f64,
    pub text: String,
    /// Font size (px).
    pub font_size: f64,
    /// `text-anchor`: start, middle or end.
    pub anchor: String,
    /// `dy`: how the baseline stands to y (plotters: "0.76em" top, "0.5ex" centre, "-0.5ex"
    /// bottom, none for the baseline).
    pub dy: String,
}

/// Advance of a character (em) assumed for a text's box: DejaVu Sans' lower case and digits
/// average 0.55–0.64 em.
const CHAR_EM: f64 = 0.6;

impl SvgText {
    /// The text's box (px): left, top, right, bottom, its width estimated at 0.6 em a character,
    /// its height one em.
    pub fn bbox(&self) -> [f64; 4] {
        let fs = self.font_size;
        let w = CHAR_EM * fs * self.text.chars().count() as f64;
        let left = match self.anchor.as_str() {
            "middle" => self.x - 0.5 * w,
            "end" => self.x - w,
            _ => self.x,
        };
        let top = match self.dy.as_str() {
            "0.76em" => self.y,
            "0.5ex" => self.y - 0.5 * fs,
            "-0.5ex" => self.y - fs,
            _ => self.y - 0.8 * fs,
        };
        [left, top, left + w, top + fs]
    }
}

/// Asserts that no two of `texts` overlap (boxes of [`SvgText::bbox`], shrunk by half a pixel
/// each side for the rounding of positions to whole pixels).
pub fn assert_no_overlap(texts: &[&SvgText]) {
    for (i, a) in texts.iter().enumerate() {
        for b in &texts[i + 1..] {
            let (p, q) = (a.bbox(), b.bbox());
            let clear = p[2] - 0.5 <= q[0] + 0.5
                || q[2] - 0.5 <= p[0] + 0.5
                || p[3] - 0.5 <= q[1] + 0.5
                || q[3] - 0.5 <= p[1] + 0.5;
            assert!(clear, "labels overlap: {a:?} {p:?} and {b:?} {q:?}");
        }
    }
}

/// The parts of a plot's SVG that the checks need.
#[derive(Debug, Default)]
pub struct Svg {
    pub texts: Vec<SvgText>,
    /// `<circle>` elements: centre x, y and radius (px).
    pub circles: Vec<(f64, f64, f64)>,
    /// Points of `<polyline>` elements (px), one list each.
    pub polylines: Vec<Vec<(f64, f64)>>,
    /// `<rect>` elements: x, y, width, height (px).
    pub rects: Vec<[f64; 4]>,
}

fn attr(tag: &str, name: &str) -> Option<f64> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    tag[start..end].parse().ok()
}

/// Parses the file at `path`.
pub fn read(path: &std::path::Path) -> Svg {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    assert!(text.starts_with("<svg"), "{} is not an SVG", path.display());
    let mut svg = Svg::default();
    let mut rest = text.as_str();
    while let Some(i) = rest.find('<') {
        rest = &rest[i..];
        let Some(close) = rest.find('>') else { break };
        let tag = &rest[..=close];
        if tag.starts_with("<text") {
            let body_end = rest.find("</text>").unwrap_or(close + 1);
            let body = rest[close + 1..body_end].trim().to_string();
            let word = |name: &str| {
                let key = format!(" {name}=\"");
                tag.find(&key)
                    .and_then(|s| {
                        let s = s + key.len();
                        tag[s..].find('"').map(|e| tag[s..s + e].to_string())
                    })
                    .unwrap_or_default()
            };
            svg.texts.push(SvgText {
                x: attr(tag, "x").unwrap_or(0.0),
                y: attr(tag, "y").unwrap_or(0.0),
                font_size: attr(tag, "font-size").unwrap_or(0.0),
                anchor: word("text-anchor"),
                dy: word("dy"),
                text: body
                    .replace("&lt;", "<")
                    .replace("&gt;", ">")
                    .replace("&amp;", "&"),
            });
        } else if tag.starts_with("<circle") {
            svg.circles.push((
                attr(tag, "cx").unwrap_or(0.0),
                attr(tag, "cy").unwrap_or(0.0),
                attr(tag, "r").unwrap_or(0.0),
            ));
        } else if tag.starts_with("<polyline") {
            let key = " points=\"";
            if let Some(s) = tag.find(key) {
                let s = s + key.len();
                let e = tag[s..].find('"').map_or(tag.len(), |e| e + s);
                let pts = tag[s..e]
                    .split_whitespace()
                    .filter_map(|p| {
                        let (a, b) = p.split_once(',')?;
                        Some((a.parse().ok()?, b.parse().ok()?))
                    })
                    .collect();
                svg.polylines.push(pts);
            }
        } else if tag.starts_with("<rect") {
            svg.rects.push([
                attr(tag, "x").unwrap_or(0.0),
                attr(tag, "y").unwrap_or(0.0),
                attr(tag, "width").unwrap_or(0.0),
                attr(tag, "height").unwrap_or(0.0),
            ]);
        }
        rest = &rest[close + 1..];
    }
    svg
}

impl Svg {
    /// The text element whose content is exactly `s`, if any.
    pub fn text(&self, s: &str) -> Option<&SvgText> {
        self.texts.iter().find(|t| t.text == s)
    }

    /// Asserts that each of `labels` is a text of the plot.
    pub fn assert_texts(&self, labels: &[&str]) {
        for l in labels {
            assert!(
                self.text(l).is_some(),
                "no text '{l}' in the plot; texts: {:?}",
                self.texts.iter().map(|t| &t.text).collect::<Vec<_>>()
            );
        }
    }

    /// Pixels per unit of the x and y axes, from the numeric tick labels (plotters puts the x-axis
    /// labels on one row and the y-axis labels in one column).
    pub fn px_per_unit(&self) -> (f64, f64) {
        let ticks: Vec<(f64, f64, f64)> = self
            .texts
            .iter()
            .filter_map(|t| Some((t.x, t.y, t.text.parse::<f64>().ok()?)))
            .collect();
        let row_y = ticks.iter().map(|t| t.1).fold(f64::MIN, f64::max);
        let col_x = ticks.iter().map(|t| t.0).fold(f64::MAX, f64::min);
        let slope = |pts: Vec<(f64, f64)>| {
            let (a, b) = (pts.first().unwrap(), pts.last().unwrap());
            ((b.0 - a.0) / (b.1 - a.1)).abs()
        };
        let mut xs: Vec<(f64, f64)> = ticks
            .iter()
            .filter(|t| t.1 == row_y)
            .map(|t| (t.0, t.2))
            .collect();
        let mut ys: Vec<(f64, f64)> = ticks
            .iter()
            .filter(|t| t.0 == col_x)
            .map(|t| (t.1, t.2))
            .collect();
        xs.sort_by(|a, b| a.1.total_cmp(&b.1));
        ys.sort_by(|a, b| a.1.total_cmp(&b.1));
        assert!(xs.len() >= 3 && ys.len() >= 3, "ticks {xs:?} {ys:?}");
        (slope(xs), slope(ys))
    }

    /// Asserts that the text "legend" stands right of every data curve (polylines of more than
    /// two points; a legend swatch has two) and data dot (circles under 3.5 px; the legend's
    /// dots are 4 px).
    pub fn assert_legend_right_of_data(&self) {
        let curves = self
            .polylines
            .iter()
            .filter(|l| l.len() > 2)
            .flatten()
            .map(|p| p.0);
        let dots = self.circles.iter().filter(|c| c.2 < 3.5).map(|c| c.0);
        let data_right = curves.chain(dots).fold(f64::MIN, f64::max);
        let legend_x = self.text("legend").expect("a legend").x;
        assert!(
            legend_x > data_right,
            "legend {legend_x} px, data to {data_right} px"
        );
    }
}
