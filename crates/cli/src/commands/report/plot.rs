//! Line charts as SVG text (plotters' SVG back end: text stays text, no fonts needed).

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

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

/// A chart: axes, curves and shaded bands along `x`.
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
const LEGEND_WIDTH: u32 = 150;

/// plotters' SVG back end writes whole-pixel coordinates, which turns a steep curve into
/// stairs; charts are drawn this many times larger and shown at their size through the
/// `viewBox`, so points land on quarter pixels. Every size in a drawing is multiplied by it.
const SUPERSAMPLE: u32 = 4;

/// `pixels` in the supersampled drawing.
const fn px(pixels: u32) -> u32 {
    pixels * SUPERSAMPLE
}

/// A signed coordinate offset of `pixels` in the supersampled drawing.
const fn offset(pixels: i32) -> i32 {
    pixels * SUPERSAMPLE as i32
}

/// The font size for text shown `points` high.
fn font(points: u32) -> (&'static str, u32) {
    ("sans-serif", px(points))
}

/// Tick labels: plain decimals in `[1e-3, 1e4)`, powers of ten outside, and 0 for the
/// rounding residue a linear axis computes for its zero tick (`2e-18`).
fn tick(value: &f64) -> String {
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
        let drawn = format!(r#"<svg width="{drawn_width}" height="{drawn_height}""#);
        let shown = format!(r#"<svg width="{}" height="{height}""#, width + LEGEND_WIDTH);
        if !svg.starts_with(&drawn) {
            return Err(format!(
                "plotters wrote an unexpected SVG header: {:.80}",
                svg
            ));
        }
        Ok(svg.replacen(&drawn, &shown, 1))
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
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, font(18))
            .margin(px(10))
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
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
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
                let name = series.name.clone();
                chart.draw_series(clipped.map(|p| {
                    EmptyElement::at(p)
                        + Circle::new((0, 0), px(5), series.colour.filled())
                        + Text::new(name.clone(), (offset(8), offset(-6)), font(12))
                }))
            } else if series.dashed {
                chart.draw_series(DashedLineSeries::new(clipped, px(7), px(4), style))
            } else {
                chart.draw_series(LineSeries::new(clipped, style))
            };
            drawn.map_err(error)?;
        }
        // The legend, drawn beside the plotting area (plotters keeps its own inside, on the
        // data): one row per band and series, a swatch and the name.
        let (x_range, y_range) = chart.plotting_area().get_pixel_range();
        let entries = self.bands.len() + self.series.len();
        let row = offset(18);
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

#[cfg(test)]
mod tests {
    use super::*;

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
            log_x: false,
            log_y: false,
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
            bands: Vec::new(),
            legend_below: false,
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
