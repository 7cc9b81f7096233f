//! What a lobe costs on a GPU, modelled: the instructions of its compiled shader, by the
//! classes GPU vendors publish throughputs for, weighed by those throughputs.
//!
//! The counts ([`ShaderOps`]) come from the shader itself (`specula-gpu` walks the naga IR of
//! the exported lobe, the module naga emits SPIR-V from). The rates ([`GpuFamily::ALL`]) are
//! per clock per multiprocessor (NVIDIA SM, AMD CU), each with its source. A lobe's modelled
//! cost is the busiest resource: each class at its rate, and issue (every instruction takes
//! an issue slot). It ignores latency, registers and occupancy; it is a bound, like the CPU's.

use serde::Serialize;

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
    /// root, counted by [`GpuFamily::ACOS`].
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
        ShaderOps { acos: 0, ..*self } + GpuFamily::ACOS * self.acos
    }

    /// Instructions in all.
    #[must_use]
    pub fn total(&self) -> u32 {
        self.arithmetic + self.compare + self.transcendental + self.conversion + self.integer
    }
}

/// One GPU family's per-clock, per-multiprocessor throughputs (results per clock).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GpuFamily {
    /// The id `recommend` and `bench` use.
    pub id: &'static str,
    /// What it covers.
    pub name: &'static str,
    /// `f32` add, multiply, multiply-add.
    pub arithmetic: f64,
    /// Compares, min, max.
    pub compare: f64,
    /// Special functions.
    pub transcendental: f64,
    /// Conversions.
    pub conversion: f64,
    /// 32-bit integer add, logic, shift.
    pub integer: f64,
    /// Instructions issued per clock (all classes together).
    pub issue: f64,
    /// Where the figures come from.
    pub source: &'static str,
}

/// The busiest resource of a shader on a family.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GpuCost {
    /// Evaluations per clock per multiprocessor, at most.
    pub evals_per_clock: f64,
    /// What bounds it.
    pub limit: &'static str,
}

impl GpuFamily {
    /// `acos` as drivers expand it: NVIDIA's `acosf` (CUDA math library) and Mesa's NIR
    /// lowering both evaluate `sqrt(1 - |x|)` times a short polynomial, with a select for the
    /// sign: counted as 1 square root, 6 multiply-adds and 2 compares/selects.
    pub const ACOS: ShaderOps = ShaderOps {
        arithmetic: 6,
        compare: 2,
        transcendental: 1,
        conversion: 0,
        integer: 0,
        acos: 0,
    };

    /// The families modelled.
    pub const ALL: [GpuFamily; 2] = [
        GpuFamily {
            id: "gpu-nvidia",
            name: "NVIDIA, compute capability 8.6-9.0 (Ampere GA10x, Ada, Hopper), per SM",
            arithmetic: 128.0,
            compare: 64.0,
            transcendental: 16.0,
            conversion: 16.0,
            integer: 64.0,
            issue: 128.0,
            source: "CUDA C++ Programming Guide, 'Arithmetic Instructions': throughput of native \
                     arithmetic instructions, operations per clock per multiprocessor (32-bit \
                     float add/multiply/multiply-add 128; reciprocal, rsqrt, log2, exp2 16; \
                     compare/min/max 64; 32-bit integer add, logic, shift 64; 32-bit \
                     conversions 16); four schedulers issuing one warp instruction per clock",
        },
        GpuFamily {
            id: "gpu-amd",
            name: "AMD RDNA 1-3, per CU (two SIMD32)",
            arithmetic: 64.0,
            compare: 64.0,
            transcendental: 16.0,
            conversion: 64.0,
            integer: 64.0,
            issue: 64.0,
            source: "AMD 'RDNA Architecture' whitepaper (2019) and RDNA ISA guides: two SIMD32 \
                     per CU, one vector instruction per SIMD per clock; transcendentals \
                     (v_exp_f32, v_log_f32, v_sqrt_f32, v_rcp_f32) at a quarter rate; \
                     conversions and integer ops full rate",
        },
    ];

    /// The family with `id`.
    #[must_use]
    pub fn find(id: &str) -> Option<GpuFamily> {
        Self::ALL.into_iter().find(|family| family.id == id)
    }

    /// The modelled bound of a shader executing `ops` per evaluation.
    #[must_use]
    pub fn cost(&self, ops: &ShaderOps) -> GpuCost {
        let ops = ops.expanded();
        let clocks = [
            (f64::from(ops.arithmetic) / self.arithmetic, "arithmetic"),
            (f64::from(ops.compare) / self.compare, "compare"),
            (
                f64::from(ops.transcendental) / self.transcendental,
                "special functions",
            ),
            (f64::from(ops.conversion) / self.conversion, "conversions"),
            (f64::from(ops.integer) / self.integer, "integer"),
            (f64::from(ops.total()) / self.issue, "issue"),
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
        let nvidia = GpuFamily::find("gpu-nvidia").unwrap();
        let cost = nvidia.cost(&pow);
        // Two special-function results at 16 per clock: 8 evaluations per clock.
        assert_eq!(
            (cost.evals_per_clock, cost.limit),
            (8.0, "special functions")
        );
        // Eight multiply-adds: 16 per clock on the FP32 pipes, and issue allows 16 too.
        let horner = ShaderOps {
            arithmetic: 8,
            ..ShaderOps::default()
        };
        assert_eq!(nvidia.cost(&horner).evals_per_clock, 16.0);
        // acos expands to 6 multiply-adds, 2 compares and a square root.
        let angle = ShaderOps {
            acos: 1,
            ..ShaderOps::default()
        };
        assert_eq!(angle.expanded().total(), 9);
        let amd = GpuFamily::find("gpu-amd").unwrap();
        assert_eq!(
            amd.cost(&angle),
            GpuCost {
                evals_per_clock: 64.0 / 9.0,
                limit: "issue"
            }
        );
    }
}
