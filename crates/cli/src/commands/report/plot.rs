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
        {
            let root = SVGBackend::with_string(&mut svg, (width + LEGEND_WIDTH, height))
                .into_drawing_area();
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
        Ok(svg)
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
            .caption(&self.title, ("sans-serif", 18))
            .margin(10)
            .margin_right(10 + LEGEND_WIDTH)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(x, y)
            .map_err(error)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .light_line_style(RGBColor(235, 235, 235))
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
            let style = series.colour.stroke_width(series.width);
            let clipped = series
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|&(x, y)| (x.clamp(self.x.0, self.x.1), y.clamp(self.y.0, self.y.1)));
            let drawn = if series.markers {
                let name = series.name.clone();
                chart.draw_series(clipped.map(|p| {
                    EmptyElement::at(p)
                        + Circle::new((0, 0), 5, series.colour.filled())
                        + Text::new(name.clone(), (8, -6), ("sans-serif", 12))
                }))
            } else if series.dashed {
                chart.draw_series(DashedLineSeries::new(clipped, 7, 4, style))
            } else {
                chart.draw_series(LineSeries::new(clipped, style))
            };
            drawn.map_err(error)?;
        }
        // The legend, drawn beside the plotting area (plotters keeps its own inside, on the
        // data): one row per band and series, a swatch and the name.
        let (x_range, y_range) = chart.plotting_area().get_pixel_range();
        let entries = self.bands.len() + self.series.len();
        let row = 18;
        let height = row * entries as i32;
        let x0 = x_range.end + 14;
        let y0 = if self.legend_below {
            (y_range.end - height).max(y_range.start)
        } else {
            y_range.start + 4
        };
        let font = ("sans-serif", 12).into_font().color(&BLACK);
        for (k, &(_, _, colour, label)) in self.bands.iter().enumerate() {
            let y = y0 + row * k as i32 + row / 2;
            root.draw(&Rectangle::new(
                [(x0, y - 5), (x0 + 16, y + 5)],
                colour.mix(0.3).filled(),
            ))
            .map_err(error)?;
            root.draw(&Text::new(label, (x0 + 22, y - 7), font.clone()))
                .map_err(error)?;
        }
        for (k, series) in self.series.iter().enumerate() {
            let y = y0 + row * (self.bands.len() + k) as i32 + row / 2;
            let style = series.colour.stroke_width(series.width);
            if series.markers {
                root.draw(&Circle::new((x0 + 8, y), 4, series.colour.filled()))
                    .map_err(error)?;
            } else if series.dashed {
                root.draw(&PathElement::new([(x0, y), (x0 + 6, y)], style))
                    .map_err(error)?;
                root.draw(&PathElement::new([(x0 + 10, y), (x0 + 16, y)], style))
                    .map_err(error)?;
            } else {
                root.draw(&PathElement::new([(x0, y), (x0 + 16, y)], style))
                    .map_err(error)?;
            }
            root.draw(&Text::new(
                series.name.clone(),
                (x0 + 22, y - 7),
                font.clone(),
            ))
            .map_err(error)?;
        }
        Ok(())
    }
}
