//! The solver's two passes over the observations, on the widest vectors the CPU has: the
//! error with the model's cube roots ([`cost_sum`]) and the Gauss-Newton step's sums
//! ([`step_sums`]), the rows stored by column so that every loop loads whole vectors.

/// The most coefficients a channel has: `kd` and two specular columns.
pub(super) const MAX_COEFFICIENTS: usize = 3;

/// Lanes of the sums over the observations: a whole AVX-512 register of `f64`, two of AVX2's.
const LANES: usize = 8;

/// `sum_j w_j (target_j - cbrt(row_j . x))^2`, each cube root left in `roots`: [`LANES`]
/// observations at a time into as many running sums (which the compiler vectorises), then
/// the remainder. Written out, not with `array::from_fn`: a library closure is compiled
/// without the target features the dispatch enables.
#[inline(always)]
pub(super) fn cost_sum(
    columns: &[Vec<f64>; MAX_COEFFICIENTS],
    target: &[f64],
    weight: &[f64],
    x: [f64; MAX_COEFFICIENTS],
    roots: &mut [f64],
) -> f64 {
    let [a0, a1, a2] = columns;
    let count = target.len();
    let whole = count / LANES * LANES;
    let mut sums = [0.0; LANES];
    for start in (0..whole).step_by(LANES) {
        let end = start + LANES;
        let (a0, a1, a2) = (&a0[start..end], &a1[start..end], &a2[start..end]);
        let (target, weight) = (&target[start..end], &weight[start..end]);
        let mut model = [0.0; LANES];
        for k in 0..LANES {
            model[k] = a0[k] * x[0] + a1[k] * x[1] + a2[k] * x[2];
        }
        let root = cube_roots(model);
        roots[start..end].copy_from_slice(&root);
        for k in 0..LANES {
            let r = target[k] - root[k];
            sums[k] += weight[k] * r * r;
        }
    }
    let mut rest = 0.0;
    for j in whole..count {
        let root = cube_roots([a0[j] * x[0] + a1[j] * x[1] + a2[j] * x[2]; LANES])[0];
        roots[j] = root;
        let r = target[j] - root;
        rest += weight[j] * r * r;
    }
    sums.iter().sum::<f64>() + rest
}

/// The Gauss-Newton system's sums over the observations: `sum w s^2 a_i a_k` for the upper
/// triangle (`i <= k`) and `sum w s a_i r`, with `a` the row, `s = 1 / (3 root^2)` the cube
/// root's slope (the root at least `1e-4`) and `r = target - root`; [`LANES`] running sums
/// each, so the compiler vectorises the loop. Unused columns are 0 and sum to 0.
#[inline(always)]
pub(super) fn step_sums(
    columns: &[Vec<f64>; MAX_COEFFICIENTS],
    target: &[f64],
    weight: &[f64],
    roots: &[f64],
) -> [f64; 9] {
    let [a0, a1, a2] = columns;
    let count = target.len();
    let whole = count / LANES * LANES;
    let mut sums = [[0.0; LANES]; 9];
    let lanes = |values: &[f64], start: usize| -> [f64; LANES] {
        values[start..start + LANES]
            .try_into()
            .expect("a whole chunk of lanes")
    };
    for start in (0..whole).step_by(LANES) {
        let rows = [lanes(a0, start), lanes(a1, start), lanes(a2, start)];
        let observed = [
            lanes(target, start),
            lanes(weight, start),
            lanes(roots, start),
        ];
        add_step_terms(&mut sums, rows, observed);
    }
    // The remainder padded with weight 0.
    let padded = |values: &[f64]| -> [f64; LANES] {
        let mut lanes = [0.0; LANES];
        lanes[..count - whole].copy_from_slice(&values[whole..count]);
        lanes
    };
    let rows = [padded(a0), padded(a1), padded(a2)];
    add_step_terms(
        &mut sums,
        rows,
        [padded(target), padded(weight), padded(roots)],
    );
    let mut out = [0.0; 9];
    for (total, lanes) in out.iter_mut().zip(&sums) {
        *total = lanes.iter().sum();
    }
    out
}

/// [`step_sums`]' terms of [`LANES`] observations (`rows` by column; target, weight and root)
/// into the sums' lanes: each sum in its own lanes, each line a loop over the lanes alone,
/// the form the compiler turns into one vector instruction per line.
#[inline(always)]
fn add_step_terms(
    sums: &mut [[f64; LANES]; 9],
    [a0, a1, a2]: [[f64; LANES]; MAX_COEFFICIENTS],
    [target, weight, roots]: [[f64; LANES]; 3],
) {
    let (mut s0, mut s1, mut s2, mut residual) =
        ([0.0; LANES], [0.0; LANES], [0.0; LANES], [0.0; LANES]);
    for k in 0..LANES {
        let bounded = if roots[k] > 1e-4 { roots[k] } else { 1e-4 };
        let slope = 1.0 / (3.0 * bounded * bounded);
        s0[k] = slope * a0[k];
        s1[k] = slope * a1[k];
        s2[k] = slope * a2[k];
        residual[k] = target[k] - roots[k];
    }
    for k in 0..LANES {
        let (w0, w1, w2) = (weight[k] * s0[k], weight[k] * s1[k], weight[k] * s2[k]);
        sums[0][k] += w0 * s0[k];
        sums[1][k] += w0 * s1[k];
        sums[2][k] += w0 * s2[k];
        sums[3][k] += w1 * s1[k];
        sums[4][k] += w1 * s2[k];
        sums[5][k] += w2 * s2[k];
        sums[6][k] += w0 * residual[k];
        sums[7][k] += w1 * residual[k];
        sums[8][k] += w2 * residual[k];
    }
}

/// The cube roots of [`LANES`] values `>= 0` (0 for 0), each to a relative `1e-13` (see the
/// test): a first guess from the `f32` bits (Kahan's: the exponent divided by three, within
/// 3.5 %) and two Halley steps, each tripling the correct digits. The fit compares roots
/// whose residuals are `1e-2` and more, so a third step (full `f64` precision) would change
/// no fit and cost a third of the loop. No branch and no 64-bit integer division, so the
/// lanes run on vector registers: the fit takes hundreds of millions, and this is several
/// times faster than `f64::cbrt`. For the model's values, `f cos` of a BRDF within `f32`'s
/// normal range (below it the guess is that of `f32`'s smallest normal, and a value under
/// `1e-38` is 0 for the fit's purposes).
#[inline(always)]
fn cube_roots(x: [f64; LANES]) -> [f64; LANES] {
    let mut y = [0.0; LANES];
    for k in 0..LANES {
        let single = (x[k] as f32).clamp(f32::MIN_POSITIVE, f32::MAX);
        y[k] = f64::from(f32::from_bits(single.to_bits() / 3 + 0x2A51_37A0));
    }
    for _ in 0..2 {
        for k in 0..LANES {
            let cube = y[k] * y[k] * y[k];
            y[k] *= (cube + 2.0 * x[k]) / (2.0 * cube + x[k]);
        }
    }
    for k in 0..LANES {
        // 0 for 0 (and for a NaN, which no model gives).
        if x[k].partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            y[k] = 0.0;
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::{cube_roots, MAX_COEFFICIENTS};

    fn cube_root(x: f64) -> f64 {
        cube_roots([x; super::LANES])[0]
    }

    /// The bounded minimiser meets Karush, Kuhn and Tucker's conditions, the second method:
    /// the gradient `2 (N x - r)` vanishes in every unknown off its bound and points up
    /// (is non-negative) in every unknown at it, on random positive definite systems with
    /// random bounds, the unknowns' scales apart by up to eight orders (as a dark channel's
    /// cube-root weights make them).
    /// The vector passes agree with plain loops (within rounding of the sums' order) at
    /// every remainder of the lanes, and at counts below one chunk: the padded lanes add
    /// nothing, and the cube roots left behind are the model's.
    #[test]
    fn the_vector_sums_are_the_plain_sums_at_every_remainder() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for count in (0..20).chain([8 * 7 + 3, 8 * 40, 8 * 40 + 7]) {
            let columns: [Vec<f64>; MAX_COEFFICIENTS] =
                core::array::from_fn(|_| (0..count).map(|_| uniform()).collect());
            let target: Vec<f64> = (0..count).map(|_| uniform()).collect();
            let weight: Vec<f64> = (0..count).map(|_| uniform() / 50.0).collect();
            let x = [0.3, 1.7, 0.02];
            let mut roots = vec![f64::NAN; count];
            let cost = super::cost_sum(&columns, &target, &weight, x, &mut roots);
            let row = |j: usize| [columns[0][j], columns[1][j], columns[2][j]];
            let model = |j: usize| row(j).iter().zip(x).map(|(a, x)| a * x).sum::<f64>();
            let mut plain = 0.0;
            for j in 0..count {
                let root = model(j).cbrt();
                assert!((roots[j] - root).abs() <= 1e-13 * root, "{count}: root {j}");
                plain += weight[j] * (target[j] - root).powi(2);
            }
            assert!(
                (cost - plain).abs() <= 1e-12 * plain,
                "{count}: {cost} {plain}"
            );
            let sums = super::step_sums(&columns, &target, &weight, &roots);
            let (mut expected, mut magnitude) = ([0.0; 9], [0.0_f64; 9]);
            for j in 0..count {
                let slope = 1.0 / (3.0 * roots[j].max(1e-4).powi(2));
                let a = row(j).map(|a| slope * a);
                let residual = target[j] - roots[j];
                let pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
                let terms = pairs
                    .map(|(p, q)| weight[j] * a[p] * a[q])
                    .into_iter()
                    .chain((0..3).map(|p| weight[j] * a[p] * residual));
                for (k, term) in terms.enumerate() {
                    expected[k] += term;
                    magnitude[k] += term.abs();
                }
            }
            for k in 0..9 {
                assert!(
                    (sums[k] - expected[k]).abs() <= 1e-12 * magnitude[k],
                    "{count}: sum {k}: {} {}",
                    sums[k],
                    expected[k]
                );
            }
        }
    }

    /// Two Halley steps from Kahan's guess: within `1e-13` of the library's root (relative)
    /// over the range of a model's `f cos`, `f32`'s normal numbers, at every scale of the
    /// mantissa; a residual of the fit is `1e-2` and more.
    #[test]
    fn the_cube_root_agrees_with_the_library_within_its_stated_precision() {
        let mut worst: f64 = 0.0;
        let mut x = 1e-37_f64;
        while x < 1e37 {
            for step in 0..64 {
                let v = x * 2f64.powf(f64::from(step) / 64.0 * 3.0);
                let (ours, reference) = (cube_root(v), v.cbrt());
                worst = worst.max((ours - reference).abs() / reference);
            }
            x *= 10.0;
        }
        assert!(worst < 1e-13, "{worst}");
        assert_eq!(cube_root(0.0), 0.0);
    }
}
