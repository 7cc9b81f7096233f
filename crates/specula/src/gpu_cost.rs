//! What a lobe costs on a GPU, modelled: the instructions of its shader, by the classes GPU
//! vendors publish throughputs for, weighed by those throughputs. The fallback where a
//! vendor's compiler is missing: `specula-isa` reads the same classes off the machine code the
//! compilers write, and weighs them by the same rates.
//!
//! The counts ([`ShaderOps`]) come from the shader itself (`specula-gpu` walks the naga IR of
//! the exported lobe, the module naga emits SPIR-V from). The rates are a generation's
//! ([`crate::gpus::Gpu::rates`]), per clock per multiprocessor, each with its source. A lobe's
//! modelled cost is the busiest resource: each class at its rate, and issue (every
//! instruction takes an issue slot). It ignores latency, registers and occupancy; it is a
//! bound, like the CPU's.

use serde::Serialize;

use crate::gpus::Rates;

/// A shader's instructions per evaluation, by throughput class.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ShaderOps {
    /// `f32` add, subtract, multiply, multiply-add.
    pub arithmetic: u32,
    /// Compares, `min`, `max`, `clamp`, selects.
    pub compare: u32,
    /// The special-function unit: `exp2`, `log2`, `sqrt`, `inverseSqrt`, and the reciprocal
    /// of every `f32` divide (a divide is a reciprocal and a multiply in graphics shaders).
    pub transcendental: u32,
    /// Float/integer conversions and roundings (`floor`, `ceil`, `trunc`, `u32(x)`, `f32(u)`).
    pub conversion: u32,
    /// Integer add, logic and shifts.
    pub integer: u32,
    /// `acos`: not a hardware instruction anywhere; drivers call a polynomial with a square
    /// root, counted by [`ACOS`].
    pub acos: u32,
}

impl core::ops::Add for ShaderOps {
    type Output = ShaderOps;
    fn add(self, other: ShaderOps) -> ShaderOps {
        ShaderOps {
            arithmetic: self.arithmetic + other.arithmetic,
            compare: self.compare + other.compare,
            transcendental: self.transcendental + other.transcendental,
            conversion: self.conversion + other.conversion,
            integer: self.integer + other.integer,
            acos: self.acos + other.acos,
        }
    }
}

impl core::ops::Mul<u32> for ShaderOps {
    type Output = ShaderOps;
    /// The counts of `k` executions.
    fn mul(self, k: u32) -> ShaderOps {
        ShaderOps {
            arithmetic: self.arithmetic * k,
            compare: self.compare * k,
            transcendental: self.transcendental * k,
            conversion: self.conversion * k,
            integer: self.integer * k,
            acos: self.acos * k,
        }
    }
}

impl ShaderOps {
    /// Every count, `acos` expanded as drivers expand it.
    #[must_use]
    pub fn expanded(&self) -> ShaderOps {
        ShaderOps { acos: 0, ..*self } + ACOS * self.acos
    }

    /// Instructions in all.
    #[must_use]
    pub fn total(&self) -> u32 {
        self.arithmetic + self.compare + self.transcendental + self.conversion + self.integer
    }
}

/// The modelled bound of a shader: evaluations per clock per multiprocessor, and what bounds
/// it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GpuCost {
    /// Evaluations per clock per multiprocessor, at most.
    pub evals_per_clock: f64,
    /// What bounds it.
    pub limit: &'static str,
}

/// `acos` as drivers expand it: NVIDIA's `acosf` (CUDA math library) and Mesa's NIR lowering
/// both evaluate `sqrt(1 - |x|)` times a short polynomial, with a select for the sign: counted
/// as 1 square root, 6 multiply-adds and 2 compares/selects.
pub const ACOS: ShaderOps = ShaderOps {
    arithmetic: 6,
    compare: 2,
    transcendental: 1,
    conversion: 0,
    integer: 0,
    acos: 0,
};

/// The modelled bound of a shader executing `ops` per evaluation on a GPU of `rates` (one
/// instruction a lane, as on every GPU's scalar lanes).
#[must_use]
pub fn modelled(ops: &ShaderOps, rates: &Rates) -> GpuCost {
    let ops = ops.expanded();
    let clocks = [
        (f64::from(ops.arithmetic) / rates.arithmetic, "arithmetic"),
        (f64::from(ops.compare) / rates.compare, "compare"),
        (
            f64::from(ops.transcendental) / rates.transcendental,
            "transcendental",
        ),
        (f64::from(ops.conversion) / rates.conversion, "conversion"),
        (f64::from(ops.integer) / rates.integer, "integer"),
        (f64::from(ops.total()) / rates.issue, "issue"),
    ];
    let (most, limit) =
        clocks.into_iter().fold(
            (0.0, "issue"),
            |best, c| if c.0 > best.0 { c } else { best },
        );
    GpuCost {
        evals_per_clock: if most > 0.0 {
            1.0 / most
        } else {
            f64::INFINITY
        },
        limit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hand_counted_shader_is_bound_by_what_it_saturates() {
        // pow as drivers compile it: log2, multiply, exp2.
        let pow = ShaderOps {
            arithmetic: 1,
            transcendental: 2,
            ..ShaderOps::default()
        };
        let ada = crate::gpus::Gpu::find("sm_89").unwrap().rates;
        let cost = modelled(&pow, &ada);
        // Two special-function results at 16 per clock: 8 evaluations per clock.
        assert_eq!((cost.evals_per_clock, cost.limit), (8.0, "transcendental"));
        // Eight multiply-adds: 16 per clock on the FP32 pipes, and issue allows 16 too.
        let horner = ShaderOps {
            arithmetic: 8,
            ..ShaderOps::default()
        };
        assert_eq!(modelled(&horner, &ada).evals_per_clock, 16.0);
        // acos expands to 6 multiply-adds, 2 compares and a square root.
        let angle = ShaderOps {
            acos: 1,
            ..ShaderOps::default()
        };
        assert_eq!(angle.expanded().total(), 9);
        let rdna3 = crate::gpus::Gpu::find("gfx1100").unwrap().rates;
        assert_eq!(
            modelled(&angle, &rdna3),
            GpuCost {
                evals_per_clock: 64.0 / 9.0,
                limit: "issue"
            }
        );
    }
}
