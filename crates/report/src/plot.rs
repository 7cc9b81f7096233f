//! Line charts as SVG text (plotters' SVG back end: text stays text, no fonts needed).

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor;

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

/// The room above the plot: the title (18 points) and a gap below it, in displayed pixels.
const TITLE_ROOM: u32 = 38;

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

/// The font size for text shown `points` high.
pub(crate) fn font(points: u32) -> (&'static str, u32) {
    ("sans-serif", px(points))
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
            match (self.log_x, self.log_y) {
                (false, false) => self.draw(&root, x, y),
                (true, false) => self.draw(&root, x.log_scale(), y),
                (false, true) => self.draw(&root, x, y.log_scale()),
                (true, true) => self.draw(&root, x.log_scale(), y.log_scale()),
            }?;
            root.present().map_err(|e| e.to_string())?;
        }
        shown_at(&without_repeated_text(&svg), (width + LEGEND_WIDTH, height))
    }

    fn draw<X, Y>(
        &self,
        root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
        x: X,
        y: Y,
    ) -> Result<(), String>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let error = |e: DrawingAreaErrorKind<_>| e.to_string();
        let (root_width, _) = root.dim_in_pixel();
        let title = font(18)
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
            .label_style(font(12))
            .axis_desc_style(font(13))
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
        for series in &self.series {
            let style = series.colour.stroke_width(px(series.width));
            let clipped = series
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|&(x, y)| (x.clamp(self.x.0, self.x.1), y.clamp(self.y.0, self.y.1)));
            let drawn = if series.markers {
                chart.draw_series(clipped.map(|p| Circle::new(p, px(5), series.colour.filled())))
            } else if series.dashed {
                chart.draw_series(DashedLineSeries::new(clipped, px(7), px(4), style))
            } else {
                chart.draw_series(LineSeries::new(clipped, style))
            };
            drawn.map_err(error)?;
        }
        let (x_range, y_range) = chart.plotting_area().get_pixel_range();
        // The markers' names, each where it overlaps no other name nor marker.
        let markers: Vec<(String, (i32, i32))> = self
            .series
            .iter()
            .filter(|series| series.markers)
            .flat_map(|series| {
                series
                    .points
                    .iter()
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .map(|&(x, y)| {
                        let at = (x.clamp(self.x.0, self.x.1), y.clamp(self.y.0, self.y.1));
                        (series.name.clone(), chart.backend_coord(&at))
                    })
            })
            .collect();
        let area = (x_range.start, y_range.start, x_range.end, y_range.end);
        for (name, at) in place_labels(&markers, area) {
            root.draw(&Text::new(name, at, font(12))).map_err(error)?;
        }
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
        let text = font(12).into_font().color(&BLACK);
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
        Ok(())
    }
}

/// Where each marker's name goes (its top-left corner, drawn pixels): the first of the places
/// around the marker, nearest first, where the name's box stays inside `area` (left, top,
/// right, bottom) and overlaps no name already placed and no marker; where none is free, the
/// place that overlaps least (12-point text about 7 pixels a character, 14 high).
fn place_labels(
    markers: &[(String, (i32, i32))],
    area: (i32, i32, i32, i32),
) -> Vec<(String, (i32, i32))> {
    type Box = (i32, i32, i32, i32);
    let overlap = |a: Box, b: Box| {
        let width = (a.2.min(b.2) - a.0.max(b.0)).max(0);
        let height = (a.3.min(b.3) - a.1.max(b.1)).max(0);
        i64::from(width) * i64::from(height)
    };
    let radius = offset(6);
    let dots: Vec<Box> = markers
        .iter()
        .map(|(_, (x, y))| (x - radius, y - radius, x + radius, y + radius))
        .collect();
    let mut placed: Vec<Box> = Vec::new();
    let mut labels = Vec::new();
    for (name, (x, y)) in markers {
        let (width, height) = (offset(7) * name.chars().count() as i32, offset(14));
        // Beside, then above and below, then farther out in rings.
        let mut places = Vec::new();
        for ring in 0..4 {
            let (near, step) = (offset(8) + ring * height, ring * height);
            places.extend([
                (near, -height / 2 - step),
                (near, -height / 2 + step),
                (-near - width, -height / 2 - step),
                (-near - width, -height / 2 + step),
                (-width / 2, -near - height - step),
                (-width / 2, near + step),
            ]);
        }
        let boxed = |(dx, dy): (i32, i32)| (x + dx, y + dy, x + dx + width, y + dy + height);
        let inside = |b: Box| b.0 >= area.0 && b.1 >= area.1 && b.2 <= area.2 && b.3 <= area.3;
        let cost = |place: (i32, i32)| {
            let candidate = boxed(place);
            let covered: i64 = placed
                .iter()
                .chain(&dots)
                .map(|&other| overlap(candidate, other))
                .sum();
            // Outside the plot counts as much as covering a whole name.
            covered
                + if inside(candidate) {
                    0
                } else {
                    i64::from(width) * i64::from(height)
                }
        };
        let best = places
            .iter()
            .copied()
            .min_by_key(|&place| cost(place))
            .unwrap_or((offset(8), -height / 2));
        placed.push(boxed(best));
        labels.push((name.clone(), (x + best.0, y + best.1)));
    }
    labels
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

    /// Markers at one place and close by (sg and sg-karis share a point; the quadratics
    /// nearly do): no two names' boxes overlap, nor a name a marker.
    #[test]
    fn marker_names_do_not_overlap() {
        // fasterpow at the right edge: its name goes to the left, inside the plot.
        let names = [
            "sg",
            "sg-karis",
            "minimax2",
            "cheb2",
            "cheb2-thesis",
            "pow",
            "fasterpow",
        ];
        let at = [
            (400, 300),
            (400, 300),
            (480, 380),
            (490, 380),
            (500, 382),
            (900, 900),
            (990, 500),
        ];
        let markers: Vec<(String, (i32, i32))> = names
            .iter()
            .zip(at)
            .map(|(name, (x, y))| ((*name).to_owned(), (x * 4, y * 4)))
            .collect();
        let placed = place_labels(&markers, (0, 0, 4000, 4000));
        let boxed =
            |(name, (x, y)): &(String, (i32, i32))| (*x, *y, x + 28 * name.len() as i32, y + 56);
        let overlaps = |a: (i32, i32, i32, i32), b: (i32, i32, i32, i32)| {
            a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
        };
        for (k, a) in placed.iter().enumerate() {
            for b in &placed[k + 1..] {
                assert!(!overlaps(boxed(a), boxed(b)), "{} and {} overlap", a.0, b.0);
            }
            let (left, top, right, bottom) = boxed(a);
            assert!(
                left >= 0 && top >= 0 && right <= 4000 && bottom <= 4000,
                "{} leaves the plot",
                a.0
            );
            for (_, (x, y)) in &markers {
                let dot = (x - 24, y - 24, x + 24, y + 24);
                assert!(!overlaps(boxed(a), dot), "{} covers a marker", a.0);
            }
        }
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
