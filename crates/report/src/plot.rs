//! Line charts as SVG text (plotters' SVG back end: text stays text, no fonts needed).

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor;

mod labels;

/// One curve.
#[derive(Clone)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub colour: RGBColor,
    pub width: u32,
    /// Draw the points as dots instead of joining them.
    pub markers: bool,
    /// A dashed line (a lobe family's variant; see `LobeKind::line_style`).
    pub dashed: bool,
}

/// A chart: axes, curves and shaded bands along `x`. Its default (linear axes, no bands,
/// the legend at the top) fills what a chart leaves unsaid (`..Chart::default()`); every
/// chart names its title, labels, ranges and curves.
#[derive(Default)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
    /// `(from, to, colour, label)` bands over the whole height.
    pub bands: Vec<(f64, f64, RGBColor, &'static str)>,
    /// Align the legend with the bottom of the plot instead of its top (it sits to the right
    /// of the plotting area either way, never on the data).
    pub legend_below: bool,
}

/// Pixels to the right of the plotting area, for the legend.
pub(crate) const LEGEND_WIDTH: u32 = 150;

/// The room above the plot: the title and a gap below it, in displayed pixels.
const TITLE_ROOM: u32 = 38;

/// The title's size and every other text's (ticks, legend, the markers' names), in pixels at
/// the chart's own size: the page shows charts at their own size, and the smallest text a
/// reader is asked to read there is 10 pixels (`.ci/explorer/report.mjs` measures it).
const TITLE_SIZE: u32 = 15;
pub(crate) const TEXT_SIZE: u32 = labels::NAME_SIZE;

/// plotters' SVG back end writes whole-pixel coordinates, which turns a steep curve into
/// stairs; charts are drawn this many times larger and shown at their size through the
/// `viewBox`, so points land on quarter pixels. Every size in a drawing is multiplied by it.
pub(crate) const SUPERSAMPLE: u32 = 4;

/// `pixels` in the supersampled drawing.
pub(crate) const fn px(pixels: u32) -> u32 {
    pixels * SUPERSAMPLE
}

/// A signed coordinate offset of `pixels` in the supersampled drawing.
pub(crate) const fn offset(pixels: i32) -> i32 {
    pixels * SUPERSAMPLE as i32
}

/// The font for text shown `pixels` high at the chart's own size: plotters' SVG back end
/// writes a font's size divided by 1.24, which this undoes (rounded up, so that text asked
/// for at 10 pixels is never drawn under 10).
pub(crate) fn font(pixels: u32) -> (&'static str, u32) {
    ("sans-serif", (px(pixels) * 124).div_ceil(100))
}

/// A log axis's tick labels: [`tick`]'s at 1, 2 and 5 times a power of ten, none between
/// (plotters marks every integer multiple, whose labels would run into each other).
fn log_tick(value: &f64) -> String {
    let mantissa = *value / 10f64.powf(value.abs().log10().floor());
    if [1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-6) {
        tick(value)
    } else {
        String::new()
    }
}

/// Tick labels: plain decimals in `[1e-3, 1e4)`, powers of ten outside, and 0 for the
/// rounding residue a linear axis computes for its zero tick (`2e-18`).
pub(crate) fn tick(value: &f64) -> String {
    let v = *value;
    if v.abs() < 1e-12 {
        "0".to_owned()
    } else if (1e-3..1e4).contains(&v.abs()) {
        let text = format!("{v:.3}");
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        format!("{v:.0e}")
    }
}

/// Colours for series that are not lobes (exponents, references), in order: Okabe and Ito's
/// colour-blind-safe set. Lobes take theirs from `LobeKind::line_style`.
pub const SEQUENCE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// The SVG without a text element that repeats one before it, the same text at the same place:
/// plotters marks a log axis's decade boundary twice (the end of one decade, the start of the
/// next), and the label drawn twice reads as overlapping text.
fn without_repeated_text(svg: &str) -> String {
    let mut seen = std::collections::HashSet::new();
    let mut kept = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(start) = rest.find("<text") {
        let Some(length) = rest[start..].find("</text>") else {
            break;
        };
        let element = &rest[start..start + length + "</text>".len()];
        kept.push_str(&rest[..start]);
        if seen.insert(element) {
            kept.push_str(element);
        }
        rest = &rest[start + element.len()..];
    }
    kept.push_str(rest);
    kept
}

/// An SVG drawn [`SUPERSAMPLE`] times larger, declared at its displayed size (`viewBox`
/// keeps the drawing's coordinates).
pub(crate) fn shown_at(svg: &str, (width, height): (u32, u32)) -> Result<String, String> {
    let drawn = format!(r#"<svg width="{}" height="{}""#, px(width), px(height));
    let shown = format!(r#"<svg width="{width}" height="{height}""#);
    if !svg.starts_with(&drawn) {
        return Err(format!(
            "plotters wrote an unexpected SVG header: {:.80}",
            svg
        ));
    }
    Ok(svg.replacen(&drawn, &shown, 1))
}

impl Chart {
    /// The chart as an SVG document: a `width x height` plot and, to its right, the legend.
    pub fn to_svg(&self, width: u32, height: u32) -> Result<String, String> {
        let mut svg = String::new();
        let markers;
        let (drawn_width, drawn_height) = (px(width + LEGEND_WIDTH), px(height));
        {
            let root =
                SVGBackend::with_string(&mut svg, (drawn_width, drawn_height)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let mut low = self.y.0;
            if self.log_y {
                // Start the axis at the decade below the smallest value drawn.
                let smallest = self
                    .series
                    .iter()
                    .flat_map(|s| s.points.iter().map(|p| p.1))
                    .filter(|&v| v > 0.0)
                    .fold(f64::INFINITY, f64::min);
                if smallest.is_finite() {
                    low = low.max(10f64.powf(smallest.log10().floor()));
                }
            }
            let (x, y) = (self.x.0..self.x.1, low..self.y.1);
            markers = match (self.log_x, self.log_y) {
                (false, false) => self.draw(&root, x, y),
                (true, false) => self.draw(&root, x.log_scale(), y),
                (false, true) => self.draw(&root, x, y.log_scale()),
                (true, true) => self.draw(&root, x.log_scale(), y.log_scale()),
            }?;
            root.present().map_err(|e| e.to_string())?;
        }
        let drawn = without_repeated_text(&svg);
        let end = drawn
            .rfind("</svg>")
            .ok_or("plotters wrote an SVG without its end")?;
        let drawn = format!("{}{markers}{}", &drawn[..end], &drawn[end..]);
        shown_at(&drawn, (width + LEGEND_WIDTH, height))
    }

    fn draw<X, Y>(
        &self,
        root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
        x: X,
        y: Y,
    ) -> Result<String, String>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let error = |e: DrawingAreaErrorKind<_>| e.to_string();
        let (root_width, _) = root.dim_in_pixel();
        let title = font(TITLE_SIZE)
            .into_font()
            .color(&BLACK)
            .pos(text_anchor::Pos::new(
                text_anchor::HPos::Center,
                text_anchor::VPos::Top,
            ));
        root.draw(&Text::new(
            self.title.clone(),
            ((root_width - px(LEGEND_WIDTH)) as i32 / 2, offset(8)),
            title,
        ))
        .map_err(error)?;
        let mut chart = ChartBuilder::on(root)
            .margin(px(10))
            // The title, drawn below, and a gap under it for the top tick's label.
            .margin_top(px(TITLE_ROOM))
            .margin_right(px(10 + LEGEND_WIDTH))
            .x_label_area_size(px(40))
            .y_label_area_size(px(60))
            .build_cartesian_2d(x, y)
            .map_err(error)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .light_line_style(RGBColor(235, 235, 235).stroke_width(px(1)))
            .bold_line_style(BLACK.mix(0.2).stroke_width(px(1)))
            .axis_style(BLACK.stroke_width(px(1)))
            .label_style(font(TEXT_SIZE))
            .axis_desc_style(font(TEXT_SIZE + 1))
            .set_all_tick_mark_size(px(5))
            .x_label_formatter(if self.log_x { &log_tick } else { &tick })
            .y_label_formatter(if self.log_y { &log_tick } else { &tick })
            .draw()
            .map_err(error)?;
        for &(from, to, colour, _) in &self.bands {
            chart
                .draw_series([Rectangle::new(
                    [(from, self.y.0), (to, self.y.1)],
                    colour.mix(0.12).filled(),
                )])
                .map_err(error)?;
        }
        // Markers are drawn after plotters' drawing, with their names (`labels`).
        for series in self.series.iter().filter(|series| !series.markers) {
            let style = series.colour.stroke_width(px(series.width));
            let clipped = series
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|&(x, y)| (x.clamp(self.x.0, self.x.1), y.clamp(self.y.0, self.y.1)));
            let drawn = if series.dashed {
                chart.draw_series(DashedLineSeries::new(clipped, px(7), px(4), style))
            } else {
                chart.draw_series(LineSeries::new(clipped, style))
            };
            drawn.map_err(error)?;
        }
        let (x_range, y_range) = chart.plotting_area().get_pixel_range();
        let coordinates = &chart;
        let dots: Vec<labels::Dot> = self
            .series
            .iter()
            .filter(|series| series.markers)
            .flat_map(|series| {
                let RGBColor(r, g, b) = series.colour;
                series
                    .points
                    .iter()
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .map(move |&(x, y)| {
                        let at = (x.clamp(self.x.0, self.x.1), y.clamp(self.y.0, self.y.1));
                        labels::Dot {
                            name: series.name.clone(),
                            colour: format!("#{r:02X}{g:02X}{b:02X}"),
                            at: coordinates.backend_coord(&at),
                        }
                    })
            })
            .collect();
        let area = (x_range.start, y_range.start, x_range.end, y_range.end);
        let markers = labels::svg(&dots, &labels::place(&dots, area));
        // The legend, drawn beside the plotting area (plotters keeps its own inside, on the
        // data): one row per band and series, a swatch and the name.
        let entries = self.bands.len() + self.series.len();
        // Rows 18 pixels apart, closer where that would run past the plot's height.
        let room = (y_range.end - y_range.start) / entries.max(1) as i32;
        let row = offset(18).min(room.max(offset(13)));
        let height = row * entries as i32;
        let x0 = x_range.end + offset(14);
        let y0 = if self.legend_below {
            (y_range.end - height).max(y_range.start)
        } else {
            y_range.start + offset(4)
        };
        let text = font(TEXT_SIZE).into_font().color(&BLACK);
        let (swatch, half, gap) = (offset(16), offset(5), offset(22));
        for (k, &(_, _, colour, label)) in self.bands.iter().enumerate() {
            let y = y0 + row * k as i32 + row / 2;
            root.draw(&Rectangle::new(
                [(x0, y - half), (x0 + swatch, y + half)],
                colour.mix(0.3).filled(),
            ))
            .map_err(error)?;
            root.draw(&Text::new(label, (x0 + gap, y - offset(7)), text.clone()))
                .map_err(error)?;
        }
        for (k, series) in self.series.iter().enumerate() {
            let y = y0 + row * (self.bands.len() + k) as i32 + row / 2;
            let style = series.colour.stroke_width(px(series.width));
            if series.markers {
                root.draw(&Circle::new(
                    (x0 + swatch / 2, y),
                    px(4),
                    series.colour.filled(),
                ))
                .map_err(error)?;
            } else if series.dashed {
                root.draw(&PathElement::new([(x0, y), (x0 + offset(6), y)], style))
                    .map_err(error)?;
                root.draw(&PathElement::new(
                    [(x0 + offset(10), y), (x0 + swatch, y)],
                    style,
                ))
                .map_err(error)?;
            } else {
                root.draw(&PathElement::new([(x0, y), (x0 + swatch, y)], style))
                    .map_err(error)?;
            }
            root.draw(&Text::new(
                series.name.clone(),
                (x0 + gap, y - offset(7)),
                text.clone(),
            ))
            .map_err(error)?;
        }
        Ok(markers)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A text element repeated at its place is dropped; the same text elsewhere is kept.
    #[test]
    fn a_repeated_label_is_drawn_once() {
        let svg =
            "<svg><text x=\"1\" y=\"2\">10</text><line/><text x=\"1\" y=\"2\">10</text><text \
            x=\"1\" y=\"9\">10</text></svg>";
        assert_eq!(
            without_repeated_text(svg),
            "<svg><text x=\"1\" y=\"2\">10</text><line/><text x=\"1\" y=\"9\">10</text></svg>"
        );
    }

    /// A diagonal drawn at 580 x 360 must resolve finer than whole pixels: with whole-pixel
    /// coordinates its 2,000 points could take at most one height per displayed pixel row.
    #[test]
    fn curves_are_placed_finer_than_whole_pixels_at_the_displayed_size() {
        let chart = Chart {
            title: "diagonal".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x: (0.0, 1.0),
            y: (0.0, 1.0),
            series: vec![Series {
                name: "y = x".into(),
                points: (0..=2000)
                    .map(|i| f64::from(i) / 2000.0)
                    .map(|v| (v, v))
                    .collect(),
                colour: SEQUENCE[0],
                width: 1,
                markers: false,
                dashed: false,
            }],
            ..Chart::default()
        };
        let svg = chart.to_svg(580, 360).unwrap();
        let header = format!(
            r#"<svg width="{}" height="360" viewBox="0 0 {} {}""#,
            580 + LEGEND_WIDTH,
            px(580 + LEGEND_WIDTH),
            px(360)
        );
        assert!(svg.starts_with(&header), "{:.120}", svg);
        let polyline = svg
            .split("<polyline")
            .find(|element| element.contains(r##"stroke="#0072B2""##))
            .expect("the curve's polyline");
        let points = polyline.split("points=\"").nth(1).unwrap();
        let heights: std::collections::BTreeSet<u32> = points
            .split('"')
            .next()
            .unwrap()
            .split_whitespace()
            .map(|pair| pair.split(',').nth(1).unwrap().parse().unwrap())
            .collect();
        let rows = 360;
        assert!(
            heights.len() > rows,
            "{} distinct heights for at most {rows} displayed rows",
            heights.len()
        );
    }
}
