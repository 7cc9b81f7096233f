//! Triangle rasterization in fixed point: edge functions, the top-left fill rule.
//!
//! Vertices are snapped to a grid of 1/256 pixel (D3D's 16.8 convention) and the edge functions
//! are evaluated exactly in `i64` at pixel centres. Exactness is what makes the fill rule
//! watertight: two triangles sharing an edge compute the same edge function with opposite signs,
//! so a centre on the edge belongs to exactly one of them (the one for which it is a top or a
//! left edge), and a centre off it to exactly one side.
//!
//! Screen space: `x` right, `y` down, pixel `(i, j)` covers `[i, i + 1) x [j, j + 1)` and is
//! sampled at its centre.

/// Fractional bits of the snapped vertex coordinates.
const SUBPIXEL_BITS: u32 = 8;
const ONE: i64 = 1 << SUBPIXEL_BITS;
const HALF: i64 = ONE / 2;

/// The largest |coordinate| in pixels the rasterizer is given (clipping keeps triangles within
/// it), chosen so that edge functions of snapped coordinates cannot overflow `i64`.
pub(crate) const MAX_COORDINATE: f32 = (1 << 20) as f32;

/// A vertex after projection: pixel coordinates and depth in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ScreenVertex {
    pub x: f32,
    pub y: f32,
    pub z: f32,
}

/// Which faces are dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Culling {
    /// Keep only faces that are counter-clockwise on screen (front faces).
    Back,
    /// Keep every face.
    None,
}

/// An inclusive rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    /// The overlap of two rectangles, if any.
    pub fn intersect(self, other: PixelRect) -> Option<PixelRect> {
        let rect = PixelRect {
            x0: self.x0.max(other.x0),
            y0: self.y0.max(other.y0),
            x1: self.x1.min(other.x1),
            y1: self.y1.min(other.y1),
        };
        (rect.x0 <= rect.x1 && rect.y0 <= rect.y1).then_some(rect)
    }
}

/// `E(P) = (x1 - x0)(Py - y0) - (y1 - y0)(Px - x0)` for the edge from `v0` to `v1`, positive on
/// the triangle's side.
#[derive(Clone, Copy, Debug)]
struct Edge {
    origin: (i64, i64),
    dx: i64,
    dy: i64,
    /// 0 for a top or left edge, 1 otherwise: a centre exactly on the edge is inside only for
    /// top and left edges.
    bias: i64,
}

impl Edge {
    fn new(from: (i64, i64), to: (i64, i64)) -> Self {
        let (dx, dy) = (to.0 - from.0, to.1 - from.1);
        // With positive area and y down, the interior lies to the right of each directed edge:
        // a left edge goes up (dy < 0), a top edge goes right along a row (dy = 0, dx > 0).
        let top_left = dy < 0 || (dy == 0 && dx > 0);
        Self {
            origin: from,
            dx,
            dy,
            bias: i64::from(!top_left),
        }
    }

    fn at(&self, x: i64, y: i64) -> i64 {
        self.dx * (y - self.origin.1) - self.dy * (x - self.origin.0)
    }
}

/// A triangle ready to rasterize: snapped, oriented, with its pixel bounds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Setup {
    /// Edge `k` is opposite vertex `k` of the oriented triangle.
    edges: [Edge; 3],
    /// Twice the signed area in fixed-point units squared (positive).
    area: i64,
    /// `order[k]` is the caller's index of oriented vertex `k`.
    order: [usize; 3],
    depth: [f32; 3],
    bounds: PixelRect,
}

/// To the nearest 1/256 pixel, halves away from zero. Written with the truncating conversion
/// rather than `f32::round`, which is a library call on baseline x86-64 (measured: 5 % of a
/// frame).
fn snap(value: f32) -> i64 {
    let scaled = value * ONE as f32;
    (scaled + 0.5_f32.copysign(scaled)) as i64
}

impl Setup {
    /// Sets a triangle up within a `width x height` target; `None` when it is culled, has no
    /// area after snapping, covers no pixel centre's row or column, or has a non-finite or
    /// out-of-range coordinate.
    pub fn new(
        vertices: [ScreenVertex; 3],
        culling: Culling,
        width: u32,
        height: u32,
    ) -> Option<Self> {
        let in_range = |v: &ScreenVertex| {
            v.x.abs() <= MAX_COORDINATE && v.y.abs() <= MAX_COORDINATE && v.z.is_finite()
        };
        if !vertices.iter().all(in_range) || width == 0 || height == 0 {
            return None;
        }
        let snapped = vertices.map(|v| (snap(v.x), snap(v.y)));
        let signed_area = Edge::new(snapped[0], snapped[1]).at(snapped[2].0, snapped[2].1);
        // Positive area with y down is clockwise on screen: a back face.
        let order = match signed_area {
            0 => return None,
            a if a > 0 && culling == Culling::Back => return None,
            a if a > 0 => [0, 1, 2],
            _ => [0, 2, 1],
        };
        let p = order.map(|k| snapped[k]);
        let edges = [
            Edge::new(p[1], p[2]),
            Edge::new(p[2], p[0]),
            Edge::new(p[0], p[1]),
        ];
        let (min_x, max_x) = (
            p[0].0.min(p[1].0).min(p[2].0),
            p[0].0.max(p[1].0).max(p[2].0),
        );
        let (min_y, max_y) = (
            p[0].1.min(p[1].1).min(p[2].1),
            p[0].1.max(p[1].1).max(p[2].1),
        );
        // Pixels whose centre `i + 1/2` can lie in [min, max].
        let first = |min: i64| (min - HALF + ONE - 1).div_euclid(ONE);
        let last = |max: i64| (max - HALF).div_euclid(ONE);
        let x0 = first(min_x).max(0);
        let y0 = first(min_y).max(0);
        let x1 = last(max_x).min(i64::from(width) - 1);
        let y1 = last(max_y).min(i64::from(height) - 1);
        if x0 > x1 || y0 > y1 {
            return None;
        }
        Some(Self {
            edges,
            area: signed_area.abs(),
            order,
            depth: order.map(|k| vertices[k].z),
            bounds: PixelRect {
                x0: x0 as u32,
                y0: y0 as u32,
                x1: x1 as u32,
                y1: y1 as u32,
            },
        })
    }

    /// The pixels the triangle may cover.
    pub fn bounds(&self) -> PixelRect {
        self.bounds
    }

    /// Calls `visit(x, y, depth)` for every pixel of `rect` whose centre the triangle covers.
    /// Depth is the plane through the vertices' depths, stepped along the row; barycentric
    /// weights are left to [`Setup::edge_weights_near`], for the samples that survive the depth
    /// test.
    pub fn for_each_covered(&self, rect: PixelRect, mut visit: impl FnMut(u32, u32, f32)) {
        let Some(rect) = self.bounds.intersect(rect) else {
            return;
        };
        let inverse_area = 1.0 / self.area as f64;
        let centre = |i: u32| i64::from(i) * ONE + HALF;
        let steps = self.edges.map(|e| -e.dy * ONE);
        let depth_step = (0..3)
            .map(|k| f64::from(self.depth[k]) * steps[k] as f64 * inverse_area)
            .sum::<f64>();
        for y in rect.y0..=rect.y1 {
            let exact = self.edges.map(|e| e.at(centre(rect.x0), centre(y)));
            let mut depth = (0..3)
                .map(|k| f64::from(self.depth[k]) * exact[k] as f64 * inverse_area)
                .sum::<f64>();
            let mut values = [0, 1, 2].map(|k| exact[k] - self.edges[k].bias);
            for x in rect.x0..=rect.x1 {
                if (values[0] | values[1] | values[2]) >= 0 {
                    visit(x, y, depth as f32);
                }
                for (value, step) in values.iter_mut().zip(steps) {
                    *value += step;
                }
                depth += depth_step;
            }
        }
    }

    /// The edge functions around pixel `(x0, y0)`, for the caller's vertices (the one opposite
    /// each): the screen-space barycentric weights times twice the area, a scale the
    /// perspective divide's own normalisation cancels. Exact at `(x0, y0)`'s centre; elsewhere
    /// a plane in `f32`, accurate while the offset from `(x0, y0)` stays small (a tile).
    pub fn edge_weights_near(&self, x0: u32, y0: u32) -> EdgeWeights {
        let centre = |i: u32| i64::from(i) * ONE + HALF;
        let mut weights = EdgeWeights::default();
        for (k, edge) in self.edges.iter().enumerate() {
            let caller = self.order[k];
            weights.at_origin[caller] = edge.at(centre(x0), centre(y0)) as f32;
            weights.step_x[caller] = (-edge.dy * ONE) as f32;
            weights.step_y[caller] = (edge.dx * ONE) as f32;
        }
        weights.origin = (x0, y0);
        weights
    }
}

/// A triangle's edge functions as planes around a pixel: see [`Setup::edge_weights_near`].
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct EdgeWeights {
    origin: (u32, u32),
    at_origin: [f32; 3],
    step_x: [f32; 3],
    step_y: [f32; 3],
}

impl EdgeWeights {
    /// The three edge functions at pixel `(x, y)`'s centre.
    #[inline]
    pub fn at(&self, x: u32, y: u32) -> [f32; 3] {
        let (dx, dy) = (
            x as f32 - self.origin.0 as f32,
            y as f32 - self.origin.1 as f32,
        );
        core::array::from_fn(|k| self.at_origin[k] + self.step_x[k] * dx + self.step_y[k] * dy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f32, y: f32) -> ScreenVertex {
        ScreenVertex { x, y, z: 0.5 }
    }

    fn covered(setup: &Setup, width: u32, height: u32) -> Vec<(u32, u32)> {
        let mut pixels = Vec::new();
        let all = PixelRect {
            x0: 0,
            y0: 0,
            x1: width - 1,
            y1: height - 1,
        };
        setup.for_each_covered(all, |x, y, _| pixels.push((x, y)));
        pixels
    }

    #[test]
    fn a_pixel_aligned_square_covers_exactly_its_pixels() {
        // Two triangles of the square [1, 3] x [1, 3]; its edges pass between pixel centres.
        let front = |a, b, c| Setup::new([a, b, c], Culling::Back, 8, 8).expect("front face");
        let lower = front(v(1.0, 1.0), v(1.0, 3.0), v(3.0, 3.0));
        let upper = front(v(1.0, 1.0), v(3.0, 3.0), v(3.0, 1.0));
        let mut all = covered(&lower, 8, 8);
        all.extend(covered(&upper, 8, 8));
        all.sort_unstable();
        assert_eq!(all, vec![(1, 1), (1, 2), (2, 1), (2, 2)]);
    }

    #[test]
    fn centres_on_a_shared_edge_go_to_one_side_only() {
        // The diagonal passes through the centres (0.5, 0.5), (1.5, 1.5), ...
        let a = Setup::new([v(0.0, 0.0), v(0.0, 4.0), v(4.0, 4.0)], Culling::Back, 4, 4);
        let b = Setup::new([v(0.0, 0.0), v(4.0, 4.0), v(4.0, 0.0)], Culling::Back, 4, 4);
        let mut all = covered(&a.unwrap(), 4, 4);
        all.extend(covered(&b.unwrap(), 4, 4));
        all.sort_unstable();
        let expected: Vec<_> = (0..4).flat_map(|x| (0..4).map(move |y| (x, y))).collect();
        assert_eq!(all, expected);
    }

    #[test]
    fn back_faces_are_culled_unless_asked_not_to() {
        let clockwise = [v(0.0, 0.0), v(4.0, 0.0), v(0.0, 4.0)];
        assert!(Setup::new(clockwise, Culling::Back, 4, 4).is_none());
        let kept = Setup::new(clockwise, Culling::None, 4, 4).expect("kept");
        // Centres with i + j <= 2 are inside; those on the hypotenuse (i + j = 3) lie on a
        // bottom-right edge and belong to the neighbour across it.
        assert_eq!(covered(&kept, 4, 4).len(), 6);
    }

    #[test]
    fn weights_are_barycentric_in_the_callers_order() {
        let setup = Setup::new([v(0.0, 0.0), v(0.0, 8.0), v(8.0, 8.0)], Culling::None, 8, 8)
            .expect("front");
        setup.for_each_covered(setup.bounds(), |x, y, depth| {
            let edges = setup.edge_weights_near(1, 2).at(x, y);
            let sum: f32 = edges.iter().sum();
            // Twice the area of the 8 x 8 right triangle, in 1/256-pixel units squared.
            assert!((sum / (64.0 * 256.0 * 256.0) - 1.0).abs() < 1e-6);
            let w = edges.map(|e| e / sum);
            assert!((depth - 0.5).abs() < 1e-6, "constant depth plane");
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let interpolated = (w[1] * 8.0 + w[2] * 8.0, w[2] * 8.0);
            assert!((interpolated.0 - py).abs() < 1e-5 && (interpolated.1 - px).abs() < 1e-5);
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        });
    }

    #[test]
    fn degenerate_and_non_finite_triangles_are_refused() {
        let line = [v(0.0, 0.0), v(1.0, 1.0), v(2.0, 2.0)];
        assert!(Setup::new(line, Culling::None, 4, 4).is_none());
        let nan = [v(f32::NAN, 0.0), v(1.0, 1.0), v(0.0, 2.0)];
        assert!(Setup::new(nan, Culling::None, 4, 4).is_none());
    }

    /// A jittered grid of vertices covering the target, each cell split along a random
    /// diagonal, vertices on a 1/4-pixel lattice so that many edges pass exactly through pixel
    /// centres: every pixel is covered exactly once.
    #[test]
    fn random_triangulations_cover_every_pixel_exactly_once() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let (width, height, cells) = (37_u32, 23_u32, 9_usize);
        for _ in 0..20 {
            let point = |i: usize, j: usize, rng: &mut rand_pcg::Pcg64| {
                let jitter = |k: usize, size: u32, rng: &mut rand_pcg::Pcg64| {
                    let cell = size as f32 / cells as f32;
                    let base = k as f32 * cell;
                    if k == 0 || k == cells {
                        base
                    } else {
                        // Less than half a cell, so that no cell folds over.
                        ((base + 0.3 * cell * rng.random_range(-1.0..1.0)) * 4.0).round() / 4.0
                    }
                };
                v(jitter(i, width, rng), jitter(j, height, rng))
            };
            let grid: Vec<Vec<ScreenVertex>> = (0..=cells)
                .map(|i| (0..=cells).map(|j| point(i, j, &mut rng)).collect())
                .collect();
            let mut counts = vec![0_u32; (width * height) as usize];
            let all = PixelRect {
                x0: 0,
                y0: 0,
                x1: width - 1,
                y1: height - 1,
            };
            for i in 0..cells {
                for j in 0..cells {
                    let [a, b, c, d] = [
                        grid[i][j],
                        grid[i + 1][j],
                        grid[i + 1][j + 1],
                        grid[i][j + 1],
                    ];
                    let halves = if rng.random_bool(0.5) {
                        [[a, b, c], [a, c, d]]
                    } else {
                        [[a, b, d], [b, c, d]]
                    };
                    for triangle in halves {
                        if let Some(setup) = Setup::new(triangle, Culling::None, width, height) {
                            setup.for_each_covered(all, |x, y, _| {
                                counts[(y * width + x) as usize] += 1;
                            });
                        }
                    }
                }
            }
            assert!(counts.iter().all(|&c| c == 1), "{counts:?}");
        }
    }
}
