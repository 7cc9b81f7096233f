// specula's lobe functions in WGSL: one function per lobe, named `lobe_<id>` after the Rust
// registry (`-` becomes `_`), each a transcription of its Rust file in crates/specula/src/lobe
// for `t` in (0, 1]. `lobe_eval` applies the rules every lobe shares (t <= 0 or NaN gives 0,
// t > 1 counts as 1) and dispatches on `kind`, the model's index in `LobeKind::ALL`, the way
// the Rust `match` does. Per-material constants arrive prepared (`Lobe::packed` in Rust).

struct Lobe {
    kind: u32,
    // log2 of schlick-mod's power, or cosquad's v.
    squarings: u32,
    n: f32,
    // cosquad's slope a = (n + 1) / (2^v + 1); a spherical Gaussian's rate log2(e) (n + offset).
    slope: f32,
    // A quadratic-in-angle lobe's C, B, A.
    quadratic: vec3<f32>,
    // ... and the angle past which it is 0.
    cutoff: f32,
}

fn lobe_pow(lobe: Lobe, t: f32) -> f32 {
    return pow(t, lobe.n);
}

// `numerator / (n (1 - t) + t)`: Schlick's denominator, without cancellation near the peak.
fn schlick_denominator_ratio(numerator: f32, t: f32, n: f32) -> f32 {
    return numerator / (n * (1.0 - t) + t);
}

fn lobe_schlick(lobe: Lobe, t: f32) -> f32 {
    return schlick_denominator_ratio(t, t, lobe.n);
}

fn lobe_schlick_mod(lobe: Lobe, t: f32) -> f32 {
    var numerator = t;
    for (var i = 0u; i < lobe.squarings; i++) {
        numerator = numerator * numerator;
    }
    return schlick_denominator_ratio(numerator, t, lobe.n);
}

// `C + g (B + A g)` below the cut-off, clamped to 1; 0 past it.
fn angle_quadratic(lobe: Lobe, g: f32) -> f32 {
    if g < lobe.cutoff {
        let q = lobe.quadratic;
        return min(q.x + g * (q.y + q.z * g), 1.0);
    }
    return 0.0;
}

fn lobe_cheb2_thesis(lobe: Lobe, t: f32) -> f32 {
    return angle_quadratic(lobe, acos(t));
}

fn lobe_cheb2(lobe: Lobe, t: f32) -> f32 {
    return angle_quadratic(lobe, acos(t));
}

fn lobe_minimax2(lobe: Lobe, t: f32) -> f32 {
    return angle_quadratic(lobe, acos(t));
}

// The thesis's `2^y ~ 1 - log2(1 - y) / 2` for y <= 0.
fn exp2_by_log2(y: f32) -> f32 {
    return 1.0 - 0.5 * log2(1.0 - y);
}

fn lobe_logexp(lobe: Lobe, t: f32) -> f32 {
    let y = lobe.n * log2(t);
    return max(exp2_by_log2(y), 0.0);
}

// `x 2^k` for an integer-valued k <= 0, built from the exponent field; 0 once 2^k underflows
// the normal range (Rust's `Real::shift`).
fn shift(x: f32, k: f32) -> f32 {
    let biased = i32(k) + 127;
    if biased <= 0 {
        return 0.0;
    }
    return x * bitcast<f32>(u32(biased) << 23u);
}

fn lobe_logexp_rr(lobe: Lobe, t: f32) -> f32 {
    let y = lobe.n * log2(t);
    let k = ceil(y);
    return shift(exp2_by_log2(y - k), k);
}

fn lobe_cosquad(lobe: Lobe, t: f32) -> f32 {
    var value = max(lobe.slope * (t - 1.0) + 1.0, 0.0);
    for (var i = 0u; i < lobe.squarings; i++) {
        value = value * value;
    }
    return value;
}

fn lobe_sg(lobe: Lobe, t: f32) -> f32 {
    return exp2(lobe.slope * (t - 1.0));
}

fn lobe_sg_karis(lobe: Lobe, t: f32) -> f32 {
    return exp2(lobe.slope * (t - 1.0));
}

// t = m 2^e with m in [1/2, 1), read off the bits (Rust's `Real::frexp`).
struct Split {
    mantissa: f32,
    exponent: f32,
}

fn split(t: f32) -> Split {
    let bits = bitcast<u32>(t);
    let mantissa = bitcast<f32>((bits & 0x007fffffu) | 0x3f000000u);
    return Split(mantissa, f32((bits >> 23u) & 0xffu) - 126.0);
}

// The float whose bits, read with 23 fraction bits, are x + 127 (Rust's `Real::bits_exp2`).
fn bits_exp2(x: f32) -> f32 {
    return bitcast<f32>(u32(max(x, -127.0) * 8388608.0 + 1065353216.0));
}

fn lobe_fastpow(lobe: Lobe, t: f32) -> f32 {
    let s = split(t);
    // fastapprox's correction as one fraction expanded around m = 1 (see fastpow.rs).
    let u = s.mantissa - 1.0;
    let numerator = u * (u * 0.501969698 + 1.9551622678) + 5.428491878e-9;
    let p = lobe.n * (numerator / (u + 1.3520887068) + s.exponent);
    let z = p - floor(p);
    let correction = 27.7280233 / (4.84252568 - z);
    return min(bits_exp2((p + correction - 5.7259425) - 1.49012907 * z), 1.0);
}

fn lobe_fasterpow(lobe: Lobe, t: f32) -> f32 {
    let s = split(t);
    let log = (s.mantissa - 1.0) * 2.0 + (s.exponent + 0.05730496);
    return min(bits_exp2(log * lobe.n - 0.05730496), 1.0);
}

fn lobe_eval(lobe: Lobe, t: f32) -> f32 {
    // `!(t > 0)` is also true for NaN.
    if !(t > 0.0) {
        return 0.0;
    }
    let c = min(t, 1.0);
    switch lobe.kind {
        case 0u: { return lobe_pow(lobe, c); }
        case 1u: { return lobe_schlick(lobe, c); }
        case 2u: { return lobe_schlick_mod(lobe, c); }
        case 3u: { return lobe_cheb2_thesis(lobe, c); }
        case 4u: { return lobe_cheb2(lobe, c); }
        case 5u: { return lobe_minimax2(lobe, c); }
        case 6u: { return lobe_logexp(lobe, c); }
        case 7u: { return lobe_logexp_rr(lobe, c); }
        case 8u: { return lobe_cosquad(lobe, c); }
        case 9u: { return lobe_sg(lobe, c); }
        case 10u: { return lobe_sg_karis(lobe, c); }
        case 11u: { return lobe_fastpow(lobe, c); }
        case 12u: { return lobe_fasterpow(lobe, c); }
        // The user's lobes: generated per module (specula_gpu::wgsl::lobes).
        default: { return lobe_formula(lobe, c); }
    }
}
