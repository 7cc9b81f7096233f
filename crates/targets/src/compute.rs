//! CUDA C and OpenCL C: a lobe as a compute kernel, the source NVIDIA's and Intel's compilers
//! are given (`specula-isa` runs them; AMD's gets the SPIR-V `specula-gpu` exports).
//!
//! A kernel reads `input[i]` and writes `output[i]`, one evaluation per thread, as the
//! SPIR-V kernel does, so that three vendors' compilers see the same work:
//! - [`Work::Lobe`]: `output[i] = specula_lobe(input[i])`, the lobe with the export's rules
//!   (`t <= 0` or NaN gives 0, `t` above 1 counts as 1), its constants baked in;
//! - [`Work::Shading`]: the specular term the engines' drop-ins replace, `N(n) lobe(t)` with
//!   `t` from a unit normal and two unit directions (nine floats per thread, `input[9 i..]`);
//! - [`Work::Baseline`]: `output[i] = input[i]`, the loads and stores alone, which the
//!   kernels of the first two are compared against (a kernel that evaluates one lobe per
//!   thread is mostly its memory traffic).
//!
//! The lobe is its recorded expression written by [`crate::code`], in each language's
//! spelling of the operations; the bit tricks are bit casts, as in WGSL. The geometry is the
//! core's (`Geometry::cos_lobe`) and the export's (`geometry.wgsl`) written in C.

use core::fmt::Write as _;

use specula::{Geometry, Lobe, Normalisation};

use crate::code::{body, float_literal, straight_line, Dialect, Parameters};

/// A C-family compute language.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ComputeLanguage {
    /// CUDA C++ (NVIDIA's `nvcc`), the kernel `extern "C"`.
    Cuda,
    /// OpenCL C 1.2 (Intel's `ocloc`).
    OpenCl,
}

/// What a kernel computes per thread.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Work {
    /// The lobe at the cosine it reads.
    Lobe,
    /// The specular term per unit `ks` from the normal and directions it reads.
    Shading(Geometry, Normalisation),
    /// Its input copied to its output.
    Baseline,
}

impl Work {
    /// The floats a thread reads.
    #[must_use]
    pub fn inputs_per_thread(self) -> usize {
        match self {
            Work::Shading(..) => 9,
            Work::Lobe | Work::Baseline => 1,
        }
    }
}

/// The kernel's name in every language (and the SPIR-V entry point's).
pub const KERNEL: &str = "specula_evaluate";

impl Dialect for ComputeLanguage {
    fn local(&self, name: &str, value: &str) -> String {
        format!("const float {name} = {value};")
    }

    fn call(&self, function: &str, arguments: &[String]) -> String {
        let name = match (self, function) {
            (_, "specula_shift" | "specula_mantissa" | "specula_exponent")
            | (_, "specula_bits_exp2") => function.to_owned(),
            (ComputeLanguage::Cuda, "max") => "fmaxf".to_owned(),
            (ComputeLanguage::Cuda, "min") => "fminf".to_owned(),
            (ComputeLanguage::Cuda, _) => format!("{function}f"),
            // GLSL's pow is undefined below 0, as OpenCL's `powr` is (its `pow` handles a
            // negative base, which costs a test and a select); GLSL's transcendental
            // functions have the relaxed precision of OpenCL's `native_` ones.
            (ComputeLanguage::OpenCl, "pow") => "native_powr".to_owned(),
            (ComputeLanguage::OpenCl, "exp2" | "log2" | "sqrt" | "exp" | "log" | "sin" | "cos") => {
                format!("native_{function}")
            }
            (ComputeLanguage::OpenCl, _) => function.to_owned(),
        };
        format!("{name}({})", arguments.join(", "))
    }

    fn log1p(&self, x: &str) -> String {
        self.call("log1p", &[x.to_owned()])
    }

    fn expm1(&self, x: &str) -> String {
        self.call("expm1", &[x.to_owned()])
    }

    fn divide(&self, a: &str, b: &str) -> String {
        match self {
            // With -use_fast_math a CUDA division is already the approximate one.
            ComputeLanguage::Cuda => format!("({a} / {b})"),
            ComputeLanguage::OpenCl => format!("native_divide({a}, {b})"),
        }
    }

    fn select_less(&self, a: &str, b: &str, then: &str, otherwise: &str) -> String {
        format!("({a} < {b} ? {then} : {otherwise})")
    }

    fn constant(&self, value: f64) -> String {
        format!("{}f", float_literal(value as f32))
    }
}

impl ComputeLanguage {
    /// Both languages.
    pub const ALL: [ComputeLanguage; 2] = [ComputeLanguage::Cuda, ComputeLanguage::OpenCl];

    /// What a function is declared with.
    fn function(self) -> &'static str {
        match self {
            ComputeLanguage::Cuda => "static __device__ __forceinline__ float",
            ComputeLanguage::OpenCl => "static inline float",
        }
    }

    /// The bit casts.
    fn casts(self) -> [&'static str; 2] {
        match self {
            ComputeLanguage::Cuda => ["__uint_as_float", "__float_as_uint"],
            ComputeLanguage::OpenCl => ["as_float", "as_uint"],
        }
    }

    /// The bit-trick helpers, as `Real`'s `f32` implementation (and WGSL's) computes them.
    fn bit_tricks(self) -> String {
        let f = self.function();
        let [as_float, as_uint] = self.casts();
        let max = self.call("max", &["x".to_owned(), "-127.0f".to_owned()]);
        format!(
            "
/* t = m 2^e with m in [1/2, 1), read off the bits (specula's Real::frexp). */
{f} specula_mantissa(float t) {{
    return {as_float}(({as_uint}(t) & 0x007fffffu) | 0x3f000000u);
}}

{f} specula_exponent(float t) {{
    return (float)(({as_uint}(t) >> 23) & 0xffu) - 126.0f;
}}

/* The float whose bits, read with 23 fraction bits, are x + 127 (Real::bits_exp2). */
{f} specula_bits_exp2(float x) {{
    return {as_float}((unsigned int)({max} * 8388608.0f + 1065353216.0f));
}}

/* x 2^k for an integer-valued k; 0 once 2^k underflows the normal range (Real::shift). */
{f} specula_shift(float x, float k) {{
    const int biased = (int)k + 127;
    if (biased <= 0) {{
        return 0.0f;
    }}
    return x * {as_float}((unsigned int)biased << 23);
}}
"
        )
    }

    /// The kernel's signature, up to its opening brace, and the thread's index.
    fn kernel_head(self) -> String {
        match self {
            ComputeLanguage::Cuda => format!(
                "extern \"C\" __global__ void {KERNEL}(const float* __restrict__ input, \
                 float* __restrict__ output) {{\n    \
                 const unsigned int i = blockIdx.x * blockDim.x + threadIdx.x;\n"
            ),
            ComputeLanguage::OpenCl => format!(
                "__kernel void {KERNEL}(__global const float* restrict input, \
                 __global float* restrict output) {{\n    \
                 const size_t i = get_global_id(0);\n"
            ),
        }
    }
}

/// The source of `lobe`'s kernel in `language` computing `work`.
#[must_use]
pub fn kernel(lobe: &Lobe, language: ComputeLanguage, work: Work) -> String {
    if work == Work::Baseline {
        // The same text whatever the lobe, so that one baseline serves every lobe.
        return format!(
            "/* specula: the loads and stores alone. */\n\n{}    output[i] = input[i];\n}}\n",
            language.kernel_head()
        );
    }
    let mut out = format!(
        "/* specula: {}, n = {}; {}, generated from specula's description of the lobe. */\n",
        lobe.kind(),
        lobe.exponent(),
        match work {
            Work::Lobe => "the lobe, one evaluation per thread".to_owned(),
            Work::Shading(geometry, normalisation) => format!(
                "the specular term per unit ks (geometry {}, normalisation {}) per thread",
                geometry.id(),
                normalisation.id()
            ),
            Work::Baseline => unreachable!("written above"),
        }
    );
    out.push_str(&lobe_functions(lobe, language));
    if let Work::Shading(geometry, normalisation) = work {
        out.push_str(&specular_function(lobe, language, geometry, normalisation));
    }
    out.push('\n');
    out.push_str(&language.kernel_head());
    out.push_str(match work {
        Work::Lobe => "    output[i] = specula_lobe(input[i]);\n",
        Work::Shading(..) => {
            "    const float* v = input + 9 * i;\n    \
             output[i] = specula_specular(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]);\n"
        }
        Work::Baseline => unreachable!("written above"),
    });
    out.push_str("}\n");
    if language == ComputeLanguage::OpenCl {
        // OpenCL C spells a pointer into global memory with its address space.
        out = out.replace("const float* v =", "__global const float* v =");
    }
    out
}

/// `specula_lobe_unit(t)` and `specula_lobe(t)` with the export's rules.
fn lobe_functions(lobe: &Lobe, language: ComputeLanguage) -> String {
    let expression = lobe.expression();
    let (statements, result) = straight_line(&expression, "t", &language, Parameters::Baked);
    let f = language.function();
    let mut out = String::new();
    if expression.has_bit_tricks() {
        out.push_str(&language.bit_tricks());
    }
    let min = language.call("min", &["t".to_owned(), "1.0f".to_owned()]);
    let _ = write!(
        out,
        "
/* {kind} at cosine t in (0, 1] (n = {n}). */
{f} specula_lobe_unit(float t) {{
{body}}}

/* {kind} at cosine t: 0 for t <= 0 or NaN, t above 1 counts as 1. */
{f} specula_lobe(float t) {{
    if (!(t > 0.0f)) {{
        return 0.0f;
    }}
    return specula_lobe_unit({min});
}}
",
        kind = lobe.kind(),
        n = lobe.exponent(),
        body = body(&statements, &result, "    ", |r| format!("return {r};")),
    );
    out
}

/// `specula_specular(normal, wo, wi)` (nine floats): `N(n) lobe(t)`.
fn specular_function(
    lobe: &Lobe,
    language: ComputeLanguage,
    geometry: Geometry,
    normalisation: Normalisation,
) -> String {
    let f = language.function();
    let sqrt = language.call("sqrt", &["length_squared".to_owned()]);
    let quotient = language.divide("(nx * sx + ny * sy + nz * sz)", &sqrt);
    let cosine = match geometry {
        Geometry::Phong => {
            "    /* 2 (N.wi)(N.wo) - wi.wo: symmetric in wi and wo by construction. */
    const float t = 2.0f * (nx * ix + ny * iy + nz * iz) * (nx * ox + ny * oy + nz * oz)
        - (ix * ox + iy * oy + iz * oz);\n"
                .to_owned()
        }
        Geometry::Blinn => format!(
            "    const float sx = ix + ox, sy = iy + oy, sz = iz + oz;
    const float length_squared = sx * sx + sy * sy + sz * sz;
    const float t = length_squared > 0.0f ? {quotient} : 0.0f;\n"
        ),
    };
    format!(
        "
/* N(n) lobe(t), t = {name} from a unit normal and unit directions away from the surface. */
{f} specula_specular(float nx, float ny, float nz, float ox, float oy, float oz,
    float ix, float iy, float iz) {{
{cosine}    return {scale} * specula_lobe(t);
}}
",
        name = geometry.cosine_name(),
        scale = language.constant(normalisation.constant_for(lobe)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use specula::{Exponent, LobeKind};

    #[test]
    fn each_language_spells_the_operations_its_own_way() {
        let lobe = Lobe::new(LobeKind::Pow, Exponent::new(64.0));
        let cuda = kernel(&lobe, ComputeLanguage::Cuda, Work::Lobe);
        let opencl = kernel(&lobe, ComputeLanguage::OpenCl, Work::Lobe);
        assert!(
            cuda.contains("powf(t, 64.0f)") && cuda.contains("fminf(t, 1.0f)"),
            "{cuda}"
        );
        assert!(
            opencl.contains("native_powr(t, 64.0f)") && opencl.contains("min(t, 1.0f)"),
            "{opencl}"
        );
        assert!(cuda.contains("extern \"C\" __global__ void specula_evaluate"));
        assert!(opencl.contains("__kernel void specula_evaluate"));
        let baseline = kernel(&lobe, ComputeLanguage::Cuda, Work::Baseline);
        assert!(!baseline.contains("specula_lobe") && baseline.contains("output[i] = input[i]"));
    }
}
