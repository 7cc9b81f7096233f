//! Polar plots of measured materials against their fits: half-discs of the plane of
//! incidence side by side on one radial scale, drawn with plotters' primitives on the same
//! supersampled SVG as the charts (`plot.rs`).

use plotters::prelude::*;
use plotters::style::text_anchor;

use super::plot::{font, offset, px, shown_at, tick, LEGEND_WIDTH};

/// A dashed line's pattern in displayed pixels: dash, gap (the charts' dashes).
pub const DASHED: &[u32] = &[7, 4];

/// A dash-dot pattern in displayed pixels: dash, gap, dot, gap.
pub const DASH_DOT: &[u32] = &[10, 3, 2, 3];

/// One curve of a polar plot.
#[derive(Clone)]
pub struct PolarCurve {
    pub name: String,
    /// `(angle from the normal in radians, signed: positive toward the viewer's side;
    /// radius >= 0)`.
    pub points: Vec<(f64, f64)>,
    pub colour: RGBColor,
    /// 1 opaque; less lets the curves drawn after it show through.
    pub opacity: f64,
    pub width: u32,
    /// Dash lengths, alternately drawn and skipped, in displayed pixels; empty for a solid line.
    pub dash: &'static [u32],
}

/// One half-disc of a polar plot: the plane of incidence seen from `viewer` (radians).
pub struct PolarPanel {
    pub title: String,
    pub viewer: f64,
    pub curves: Vec<PolarCurve>,
}

/// Polar plots side by side on one radial scale; the legend (the first panel's curves) to
/// their right.
pub struct Polar {
    pub panels: Vec<PolarPanel>,
    /// The largest radius shown is at most this many times the largest of the first curves'
    /// (the reference's): a wild curve is clipped at the rim instead of shrinking the others.
    pub headroom: f64,
}

/// A polar panel's displayed width and height.
const PANEL: (u32, u32) = (300, 205);

/// The smallest of 1, 2, 2.5 and 5 times a power of ten that is at least `value`.
fn nice_step(value: f64) -> f64 {
    let decade = 10f64.powf(value.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&step| step >= value * (1.0 - 1e-12))
        .unwrap_or(10.0 * decade)
}

/// Draws `points` (supersampled pixels) as a polyline, solid or in `dash`'s pattern.
fn draw_polyline(
    root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    points: &[(i32, i32)],
    style: ShapeStyle,
    dash: &[u32],
) -> Result<(), String> {
    let error = |e: DrawingAreaErrorKind<_>| e.to_string();
    if dash.is_empty() {
        return root
            .draw(&PathElement::new(points.to_vec(), style))
            .map_err(error);
    }
    // Walk the polyline by length, cutting it where the pattern switches.
    let pattern: Vec<f64> = dash.iter().map(|&d| f64::from(px(d))).collect();
    let (mut k, mut left) = (0, pattern[0]);
    let mut piece = vec![points[0]];
    for pair in points.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
        let length = dx.hypot(dy);
        let mut at = 0.0;
        while length - at > left {
            at += left;
            let cut = (
                a.0 + (dx * at / length).round() as i32,
                a.1 + (dy * at / length).round() as i32,
            );
            if k % 2 == 0 {
                piece.push(cut);
                root.draw(&PathElement::new(std::mem::take(&mut piece), style))
                    .map_err(error)?;
            } else {
                piece = vec![cut];
            }
            k = (k + 1) % pattern.len();
            left = pattern[k];
        }
        left -= length - at;
        if k % 2 == 0 {
            piece.push(b);
        }
    }
    if k % 2 == 0 && piece.len() > 1 {
        root.draw(&PathElement::new(piece, style)).map_err(error)?;
    }
    Ok(())
}

impl Polar {
    /// The panels as one SVG document.
    pub fn to_svg(&self) -> Result<String, String> {
        let (panel_width, panel_height) = PANEL;
        let count = self.panels.len() as u32;
        let entries = self.panels.first().map_or(0, |p| p.curves.len()) as u32;
        let (width, height) = (
            panel_width * count + LEGEND_WIDTH + 20,
            panel_height.max(16 + 14 * entries),
        );
        let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
        let largest = |curves: &mut dyn Iterator<Item = &PolarCurve>| {
            curves
                .flat_map(|c| c.points.iter().filter(finite).map(|p| p.1))
                .fold(0.0, f64::max)
        };
        let reference = largest(&mut self.panels.iter().filter_map(|p| p.curves.first()));
        let all = largest(&mut self.panels.iter().flat_map(|p| &p.curves));
        let wanted = all.min(self.headroom * reference);
        if wanted.is_nan() || wanted <= 0.0 {
            return Err("a polar plot with nothing to draw".to_owned());
        }
        // Two to four rings, the last at or just beyond the largest radius wanted.
        let step = nice_step(wanted / 4.0);
        let rings = (wanted / step * (1.0 - 1e-12)).ceil().max(1.0) as u32;
        let rim = step * f64::from(rings);
        let mut svg = String::new();
        {
            let root =
                SVGBackend::with_string(&mut svg, (px(width), px(height))).into_drawing_area();
            let error = |e: DrawingAreaErrorKind<_>| e.to_string();
            root.fill(&WHITE).map_err(error)?;
            let centred = |size| {
                font(size)
                    .into_font()
                    .color(&BLACK)
                    .pos(text_anchor::Pos::new(
                        text_anchor::HPos::Center,
                        text_anchor::VPos::Center,
                    ))
            };
            let radius = f64::from(px(panel_width / 2 - 34));
            for (index, panel) in self.panels.iter().enumerate() {
                let centre = (
                    offset((panel_width * index as u32 + panel_width / 2) as i32),
                    offset(panel_height as i32 - 24),
                );
                let at = |angle: f64, r: f64| {
                    let scaled = radius * (r / rim).clamp(0.0, 1.0);
                    (
                        centre.0 + (scaled * angle.sin()).round() as i32,
                        centre.1 - (scaled * angle.cos()).round() as i32,
                    )
                };
                root.draw(&Text::new(
                    panel.title.clone(),
                    (centre.0, offset(12)),
                    centred(14),
                ))
                .map_err(error)?;
                // Rings every `step`, labelled below the surface; spokes every 30 degrees.
                let grid = RGBColor(215, 215, 215).stroke_width(px(1));
                for ring in 1..=rings {
                    let r = step * f64::from(ring);
                    let arc: Vec<(i32, i32)> = (0..=90)
                        .map(|k| at((f64::from(k) / 90.0 - 0.5) * std::f64::consts::PI, r))
                        .collect();
                    root.draw(&PathElement::new(arc, grid)).map_err(error)?;
                    let (x, y) = at(std::f64::consts::FRAC_PI_2, r);
                    root.draw(&Text::new(tick(&r), (x, y + offset(10)), centred(10)))
                        .map_err(error)?;
                }
                for degrees in (-90i32..=90).step_by(30) {
                    let angle = f64::from(degrees).to_radians();
                    root.draw(&PathElement::new(vec![centre, at(angle, rim)], grid))
                        .map_err(error)?;
                    let label = at(angle, rim * 1.12);
                    root.draw(&Text::new(
                        format!("{}°", degrees.abs()),
                        label,
                        centred(10),
                    ))
                    .map_err(error)?;
                }
                let surface = BLACK.stroke_width(px(1));
                root.draw(&PathElement::new(
                    vec![
                        at(-std::f64::consts::FRAC_PI_2, rim),
                        at(std::f64::consts::FRAC_PI_2, rim),
                    ],
                    surface,
                ))
                .map_err(error)?;
                // The viewer's direction.
                let viewer = RGBColor(120, 120, 120).stroke_width(px(1));
                draw_polyline(&root, &[centre, at(panel.viewer, rim)], viewer, &[2, 2])?;
                for curve in &panel.curves {
                    let mut points: Vec<(i32, i32)> = Vec::with_capacity(curve.points.len());
                    for p in curve.points.iter().filter(finite) {
                        let point = at(p.0, p.1);
                        if points.last() != Some(&point) {
                            points.push(point);
                        }
                    }
                    if points.len() < 2 {
                        continue;
                    }
                    let style = curve
                        .colour
                        .mix(curve.opacity)
                        .stroke_width(px(curve.width));
                    draw_polyline(&root, &points, style, curve.dash)?;
                }
            }
            // The legend.
            let x0 = offset((panel_width * count + 14) as i32);
            let row = offset(14);
            let text = font(11).into_font().color(&BLACK);
            let legend = self.panels.first().map_or(&[][..], |p| &p.curves[..]);
            for (k, curve) in legend.iter().enumerate() {
                let y = offset(8) + row * k as i32 + row / 2;
                let style = curve
                    .colour
                    .mix(curve.opacity)
                    .stroke_width(px(curve.width));
                draw_polyline(&root, &[(x0, y), (x0 + offset(20), y)], style, curve.dash)?;
                root.draw(&Text::new(
                    curve.name.clone(),
                    (x0 + offset(26), y - offset(6)),
                    text.clone(),
                ))
                .map_err(error)?;
            }
            root.present().map_err(error)?;
        }
        shown_at(&svg, (width, height))
    }
}
