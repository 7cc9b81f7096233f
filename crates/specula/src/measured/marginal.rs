//! A 2D density that linearly interpolates a table on `[0, 1]^2`, conditioned on parameters
//! at which the table was tabulated, sampled by inverting its marginal and conditional CDFs
//! (the "continuous" variant of Mitsuba's `Marginal2D`, which the measured format is defined
//! through: its `eval`, `sample` and `invert` are the paper's warps).
//!
//! The table is `params[0] x ... x params[D-1] x height x width`, the last axis contiguous; a
//! point is `(x, y)` with `x` along the width. Between tabulated parameter values every
//! lookup is the multilinear blend of the neighbouring slices, and so is every CDF. A table
//! built [`Normalised`](Marginal2D::normalised) integrates to 1 over the square per slice;
//! one built [`Raw`](Marginal2D::raw) is only interpolated.

/// A conditional 2D table: bilinear in `(x, y)`, multilinear in its parameters.
#[derive(Clone, Debug)]
pub struct Marginal2D {
    width: usize,
    height: usize,
    parameters: Vec<Vec<f32>>,
    /// Per parameter, the distance between its neighbouring slices, in slices (0 where it
    /// has one value).
    strides: Vec<usize>,
    data: Vec<f32>,
    marginal_cdf: Vec<f32>,
    conditional_cdf: Vec<f32>,
    /// What `eval` multiplies the interpolated value by: the patch count for a density,
    /// 1 for a raw table.
    scale: f64,
}

/// Where a point's parameters fall: per parameter the lower slice's weight and the upper's.
struct Blend {
    slice: usize,
    weights: [(f64, f64); 4],
    dimensions: usize,
}

/// The largest index `i` in `[0, size - 2]` with `below(i)`, for `below` true then false.
fn find_interval(size: usize, below: impl Fn(usize) -> bool) -> usize {
    let (mut first, mut length) = (1usize, size.saturating_sub(2));
    while length > 0 {
        let half = length / 2;
        let middle = first + half;
        if below(middle) {
            first = middle + 1;
            length -= half + 1;
        } else {
            length = half;
        }
    }
    (first - 1).min(size.saturating_sub(2))
}

fn safe_sqrt(x: f64) -> f64 {
    x.max(0.0).sqrt()
}

impl Marginal2D {
    /// A table interpolated as it is (no CDFs: it can be evaluated, not sampled).
    ///
    /// # Panics
    /// If `data`'s length is not the product of the shape (the reader checks it first).
    #[must_use]
    pub fn raw(data: Vec<f32>, width: usize, height: usize, parameters: Vec<Vec<f32>>) -> Self {
        let mut table = Self::shaped(data, width, height, parameters);
        table.scale = 1.0;
        table
    }

    /// A density: each slice scaled to integrate to 1, with the CDFs that sample it; `None`
    /// when a slice's integral is not a finite positive number (in `f32`, as the CDFs are
    /// kept), which no density can be scaled from.
    ///
    /// # Panics
    /// As [`Marginal2D::raw`].
    #[must_use]
    pub fn normalised(
        data: Vec<f32>,
        width: usize,
        height: usize,
        parameters: Vec<Vec<f32>>,
    ) -> Option<Self> {
        let mut table = Self::shaped(data, width, height, parameters);
        let (w, h) = (width, height);
        let slices = table.data.len() / (w * h);
        table.marginal_cdf = vec![0.0; slices * h];
        table.conditional_cdf = vec![0.0; slices * w * h];
        for slice in 0..slices {
            let data = &mut table.data[slice * w * h..(slice + 1) * w * h];
            let conditional = &mut table.conditional_cdf[slice * w * h..(slice + 1) * w * h];
            let marginal = &mut table.marginal_cdf[slice * h..(slice + 1) * h];
            for y in 0..h {
                let mut sum = 0.0f64;
                for x in 0..w - 1 {
                    let i = y * w + x;
                    sum += 0.5 * (f64::from(data[i]) + f64::from(data[i + 1]));
                    conditional[i + 1] = sum as f32;
                }
            }
            let mut sum = 0.0f64;
            for y in 0..h - 1 {
                sum += 0.5
                    * (f64::from(conditional[(y + 1) * w - 1])
                        + f64::from(conditional[(y + 2) * w - 1]));
                marginal[y + 1] = sum as f32;
            }
            let total = marginal[h - 1];
            if !(total.is_finite() && total > 0.0) {
                return None;
            }
            let normalisation = 1.0 / total;
            conditional.iter_mut().for_each(|v| *v *= normalisation);
            marginal.iter_mut().for_each(|v| *v *= normalisation);
            data.iter_mut().for_each(|v| *v *= normalisation);
        }
        table.scale = ((w - 1) * (h - 1)) as f64;
        Some(table)
    }

    fn shaped(data: Vec<f32>, width: usize, height: usize, parameters: Vec<Vec<f32>>) -> Self {
        assert!(width >= 2 && height >= 2 && parameters.len() <= 4);
        let mut strides = vec![0; parameters.len()];
        let mut slices = 1;
        for (dimension, values) in parameters.iter().enumerate().rev() {
            assert!(!values.is_empty());
            strides[dimension] = if values.len() > 1 { slices } else { 0 };
            slices *= values.len();
        }
        assert_eq!(data.len(), slices * width * height, "table shape");
        Self {
            width,
            height,
            parameters,
            strides,
            data,
            marginal_cdf: Vec::new(),
            conditional_cdf: Vec::new(),
            scale: 1.0,
        }
    }

    fn blend(&self, parameters: &[f64]) -> Blend {
        let mut blend = Blend {
            slice: 0,
            weights: [(1.0, 0.0); 4],
            dimensions: self.parameters.len(),
        };
        for (dimension, values) in self.parameters.iter().enumerate() {
            if values.len() == 1 {
                continue;
            }
            let p = parameters[dimension];
            let index = find_interval(values.len(), |i| f64::from(values[i]) < p);
            let (p0, p1) = (f64::from(values[index]), f64::from(values[index + 1]));
            let upper = ((p - p0) / (p1 - p0)).clamp(0.0, 1.0);
            blend.weights[dimension] = (1.0 - upper, upper);
            blend.slice += self.strides[dimension] * index;
        }
        blend
    }

    /// The blend of `table[index + k * slice_size]` over the parameters' neighbouring slices.
    fn lookup(&self, table: &[f32], blend: &Blend, index: usize, slice_size: usize) -> f64 {
        let mut sum = 0.0;
        for corner in 0..1usize << blend.dimensions {
            let (mut weight, mut at) = (1.0, index);
            for dimension in 0..blend.dimensions {
                let (w0, w1) = blend.weights[dimension];
                if corner >> dimension & 1 == 1 {
                    weight *= w1;
                    at += self.strides[dimension] * slice_size;
                } else {
                    weight *= w0;
                }
            }
            if weight != 0.0 {
                sum += weight * f64::from(table[at]);
            }
        }
        sum
    }

    fn patches(&self) -> [f64; 2] {
        [(self.width - 1) as f64, (self.height - 1) as f64]
    }

    /// The value (a density, for a normalised table) at `point`, given the parameters.
    #[must_use]
    pub fn eval(&self, point: [f64; 2], parameters: &[f64]) -> f64 {
        let blend = self.blend(parameters);
        let [px, py] = self.patches();
        let x = point[0].clamp(0.0, 1.0) * px;
        let y = point[1].clamp(0.0, 1.0) * py;
        let (cx, cy) = (
            (x as usize).min(self.width - 2),
            (y as usize).min(self.height - 2),
        );
        let (wx, wy) = (x - cx as f64, y - cy as f64);
        let size = self.width * self.height;
        let index = blend.slice * size + cy * self.width + cx;
        let v = |offset: usize| self.lookup(&self.data, &blend, index + offset, size);
        let (v00, v10, v01, v11) = (v(0), v(1), v(self.width), v(self.width + 1));
        ((1.0 - wy) * ((1.0 - wx) * v00 + wx * v10) + wy * ((1.0 - wx) * v01 + wx * v11))
            * self.scale
    }

    /// Warps a uniform point of the square to one distributed as the density; returns it and
    /// its density. Only for a normalised table.
    #[must_use]
    pub fn sample(&self, uniform: [f64; 2], parameters: &[f64]) -> ([f64; 2], f64) {
        let blend = self.blend(parameters);
        let (w, h) = (self.width, self.height);
        let size = w * h;
        let epsilon = f64::from(f32::EPSILON) / 2.0;
        let mut sx = uniform[0].clamp(epsilon, 1.0 - epsilon);
        let mut sy = uniform[1].clamp(epsilon, 1.0 - epsilon);

        let marginal = |i: usize| self.lookup(&self.marginal_cdf, &blend, blend.slice * h + i, h);
        let row = find_interval(h, |i| marginal(i) < sy);
        sy -= marginal(row);

        let row_start = blend.slice * size + row * w;
        let r0 = self.lookup(&self.conditional_cdf, &blend, row_start + w - 1, size);
        let r1 = self.lookup(&self.conditional_cdf, &blend, row_start + 2 * w - 1, size);
        let constant = (r0 - r1).abs() < 1e-4 * (r0 + r1);
        sy = if constant {
            2.0 * sy / (r0 + r1)
        } else {
            (r0 - safe_sqrt(r0 * r0 - 2.0 * sy * (r0 - r1))) / (r0 - r1)
        };

        sx *= (1.0 - sy) * r0 + sy * r1;
        let conditional = |i: usize| {
            let v0 = self.lookup(&self.conditional_cdf, &blend, row_start + i, size);
            let v1 = self.lookup(&self.conditional_cdf, &blend, row_start + w + i, size);
            (1.0 - sy) * v0 + sy * v1
        };
        let column = find_interval(w, |i| conditional(i) < sx);
        sx -= conditional(column);

        let at = row_start + column;
        let v = |offset: usize| self.lookup(&self.data, &blend, at + offset, size);
        let c0 = (1.0 - sy) * v(0) + sy * v(w);
        let c1 = (1.0 - sy) * v(1) + sy * v(w + 1);
        let constant = (c0 - c1).abs() < 1e-4 * (c0 + c1);
        let divisor = if constant { c0 + c1 } else { c0 - c1 };
        if divisor != 0.0 {
            sx = if constant {
                2.0 * sx
            } else {
                c0 - safe_sqrt(c0 * c0 - 2.0 * sx * (c0 - c1))
            } / divisor;
        }
        let [px, py] = self.patches();
        (
            [(column as f64 + sx) / px, (row as f64 + sy) / py],
            ((1.0 - sx) * c0 + sx * c1) * self.scale,
        )
    }

    /// The inverse of [`Marginal2D::sample`]: the uniform point that warps to `point`, and
    /// the density there. Only for a normalised table.
    #[must_use]
    pub fn invert(&self, point: [f64; 2], parameters: &[f64]) -> ([f64; 2], f64) {
        let blend = self.blend(parameters);
        let (w, h) = (self.width, self.height);
        let size = w * h;
        let [px, py] = self.patches();
        let x = point[0].clamp(0.0, 1.0) * px;
        let y = point[1].clamp(0.0, 1.0) * py;
        let (cx, cy) = ((x as usize).min(w - 2), (y as usize).min(h - 2));
        let (mut sx, mut sy) = (x - cx as f64, y - cy as f64);

        let at = blend.slice * size + cy * w + cx;
        let v = |offset: usize| self.lookup(&self.data, &blend, at + offset, size);
        let (v00, v10, v01, v11) = (v(0), v(1), v(w), v(w + 1));
        let c0 = (1.0 - sy) * v00 + sy * v01;
        let c1 = (1.0 - sy) * v10 + sy * v11;
        let density = (1.0 - sx) * c0 + sx * c1;

        sx *= c0 + 0.5 * sx * (c1 - c0);
        let v0 = self.lookup(&self.conditional_cdf, &blend, at, size);
        let v1 = self.lookup(&self.conditional_cdf, &blend, at + w, size);
        sx += (1.0 - sy) * v0 + sy * v1;

        let row_start = blend.slice * size + cy * w;
        let r0 = self.lookup(&self.conditional_cdf, &blend, row_start + w - 1, size);
        let r1 = self.lookup(&self.conditional_cdf, &blend, row_start + 2 * w - 1, size);
        // A row pair without mass (which sampling never lands in) inverts to its start.
        let row_mass = (1.0 - sy) * r0 + sy * r1;
        sx = if row_mass > 0.0 { sx / row_mass } else { 0.0 };

        sy *= r0 + 0.5 * sy * (r1 - r0);
        sy += self.lookup(&self.marginal_cdf, &blend, blend.slice * h + cy, h);
        ([sx, sy], density * self.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A density with two parameters, neither constant nor separable.
    fn table() -> Marginal2D {
        let (w, h, a, b) = (5, 4, 2, 3);
        let data = (0..a * b * w * h)
            .map(|i| {
                let (x, y, s) = (i % w, (i / w) % h, i / (w * h));
                1.0 + (x * (s + 1)) as f32 * 0.3 + (y * y) as f32 * 0.2 + (x * y) as f32 * 0.1
            })
            .collect();
        Marginal2D::normalised(data, w, h, vec![vec![0.0, 1.0], vec![0.0, 0.5, 2.0]])
            .expect("a positive table")
    }

    #[test]
    fn a_density_integrates_to_one_at_any_parameters() {
        let table = table();
        for parameters in [[0.0, 0.0], [0.3, 0.2], [1.0, 1.7], [0.7, 2.0]] {
            // The midpoint rule is exact enough on a piecewise-bilinear function.
            let m = 400;
            let sum: f64 = (0..m * m)
                .map(|i| {
                    let p = [
                        ((i % m) as f64 + 0.5) / m as f64,
                        ((i / m) as f64 + 0.5) / m as f64,
                    ];
                    table.eval(p, &parameters)
                })
                .sum::<f64>()
                / (m * m) as f64;
            assert!((sum - 1.0).abs() < 1e-4, "{parameters:?}: {sum}");
        }
    }

    #[test]
    fn invert_undoes_sample_and_both_give_the_density() {
        let table = table();
        for parameters in [[0.0, 0.0], [0.3, 0.2], [1.0, 1.7]] {
            for i in 0..97 {
                let u = [
                    (i as f64 * 0.618_034) % 1.0,
                    (i as f64 * 0.754_877 + 0.1) % 1.0,
                ];
                let (point, pdf) = table.sample(u, &parameters);
                let (back, pdf_back) = table.invert(point, &parameters);
                let density = table.eval(point, &parameters);
                assert!(
                    (back[0] - u[0]).abs() < 1e-6 && (back[1] - u[1]).abs() < 1e-6,
                    "{u:?} -> {point:?} -> {back:?}"
                );
                assert!(
                    (pdf - density).abs() < 1e-9 * density.max(1.0),
                    "{pdf} {density}"
                );
                assert!((pdf_back - density).abs() < 1e-9 * density.max(1.0));
            }
        }
    }

    #[test]
    fn raw_tables_interpolate_their_values() {
        let data: Vec<f32> = (0..12).map(|i| i as f32).collect();
        let table = Marginal2D::raw(data, 3, 2, vec![vec![0.0, 1.0]]);
        // Slice 0 is 0..6 (rows 0,1,2 / 3,4,5); slice 1 adds 6.
        assert!((table.eval([0.5, 0.0], &[0.0]) - 1.0).abs() < 1e-12);
        assert!((table.eval([0.25, 1.0], &[0.0]) - 3.5).abs() < 1e-12);
        assert!((table.eval([0.25, 1.0], &[0.5]) - 6.5).abs() < 1e-12);
        assert!((table.eval([1.0, 1.0], &[2.0]) - 11.0).abs() < 1e-12);
    }

    #[test]
    fn find_interval_brackets() {
        let values = [0.0, 1.0, 2.0, 3.0];
        for (x, expected) in [(-1.0, 0), (0.5, 0), (1.0, 0), (1.5, 1), (2.9, 2), (9.0, 2)] {
            assert_eq!(find_interval(4, |i| values[i] < x), expected, "{x}");
        }
    }
}
