//! The GPUs specula costs lobes on, by their vendors' names, and what each generation executes
//! per clock: the published rates that instructions are weighed by, whether a vendor's
//! compiler wrote them (`specula-isa`) or the model counted them (`gpu_cost`).

use serde::Serialize;

/// Whose compiler a GPU's code comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Vendor {
    /// NVIDIA: CUDA C through `nvcc -use_fast_math` (NVVM, then `ptxas`), SASS by `nvdisasm`.
    Nvidia,
    /// AMD: the exported SPIR-V through Mesa's RADV on a null device (ACO, the compiler Linux
    /// games run on), the assembly and statistics by `VK_KHR_pipeline_executable_properties`.
    Amd,
    /// Intel: OpenCL C through `ocloc` with `-cl-fast-relaxed-math` (IGC), the assembly from
    /// IGC's own dump.
    Intel,
}

impl Vendor {
    /// Every vendor.
    pub const ALL: [Vendor; 3] = [Vendor::Nvidia, Vendor::Amd, Vendor::Intel];

    /// The id `recommend --target gpu-<id>` names.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Vendor::Nvidia => "nvidia",
            Vendor::Amd => "amd",
            Vendor::Intel => "intel",
        }
    }

    /// The vendor's name as a reader knows it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Vendor::Nvidia => "NVIDIA",
            Vendor::Amd => "AMD",
            Vendor::Intel => "Intel",
        }
    }

    /// The generation a vendor's target is costed for when none is named: a current one.
    #[must_use]
    pub fn default_gpu(self) -> Gpu {
        let id = match self {
            Vendor::Nvidia => "sm_89",
            Vendor::Amd => "gfx1100",
            Vendor::Intel => "dg2",
        };
        Gpu::find(id).unwrap_or_else(|| unreachable!("{id} is in Gpu::ALL"))
    }
}

/// Results per clock on one multiprocessor (NVIDIA SM, AMD CU, Intel EU), per class: lanes of
/// work, so an instruction executing `k` lanes costs `k / rate` clocks there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Rates {
    /// `f32` add, multiply, multiply-add.
    pub arithmetic: f64,
    /// Compares, minimum, maximum, selects.
    pub compare: f64,
    /// The special-function unit: `exp2`, `log2`, reciprocal, square root.
    pub transcendental: f64,
    /// Conversions and roundings.
    pub conversion: f64,
    /// 32-bit integer add, multiply-add, logic, shifts.
    pub integer: f64,
    /// Lanes of instructions issued per clock, every class together.
    pub issue: f64,
}

/// One GPU generation: its compiler's target name, its vendor and its rates.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Gpu {
    /// The vendor's own name for the target: `sm_89`, `gfx1100`, `tgllp`.
    pub id: &'static str,
    /// Whose compiler.
    pub vendor: Vendor,
    /// The generation and some of its cards.
    pub name: &'static str,
    /// What the compiler is told: `nvcc -arch`, `RADV_FORCE_FAMILY`, `ocloc -device`.
    pub compiler_target: &'static str,
    /// The multiprocessor the rates are per.
    pub unit: &'static str,
    /// Its rates.
    pub rates: Rates,
    /// Where the rates come from.
    pub source: &'static str,
}

const CUDA_GUIDE: &str = "CUDA C++ Programming Guide, 'Arithmetic Instructions': results per \
    clock per multiprocessor (32-bit float add, multiply, multiply-add; reciprocal, rsqrt, \
    log2, exp2, sine, cosine 16; compare, minimum, maximum 64; 32-bit integer add, \
    multiply-add, shift, logic 64; conversions 16); four schedulers issuing one warp \
    instruction per clock";

/// NVIDIA from Ampere GA10x on: 128 `f32` lanes per SM.
const NVIDIA_128: Rates = Rates {
    arithmetic: 128.0,
    compare: 64.0,
    transcendental: 16.0,
    conversion: 16.0,
    integer: 64.0,
    issue: 128.0,
};

/// GCN and RDNA move 64 lanes of vector work per CU per clock (four SIMD16 a quarter of a
/// wave64 each, or two SIMD32), transcendentals at a quarter of that.
const AMD_64: Rates = Rates {
    arithmetic: 64.0,
    compare: 64.0,
    transcendental: 16.0,
    conversion: 64.0,
    integer: 64.0,
    issue: 64.0,
};

const RDNA: &str = "AMD 'RDNA Architecture' whitepaper (2019) and the RDNA, RDNA 2 and RDNA 3 \
    ISA guides: two SIMD32 per CU, one vector instruction per SIMD per clock (a wave64 \
    instruction over two); transcendentals (v_exp, v_log, v_rcp, v_rsq, v_sqrt) on a \
    quarter-rate unit; conversions and integer operations full rate. RDNA 3's dual issue \
    (VOPD) is not counted: Mesa 22.3's ACO does not emit it";

/// Xe's execution unit: an 8-lane FP/integer ALU and a 2-lane extended-math ALU.
const XE: Rates = Rates {
    arithmetic: 8.0,
    compare: 8.0,
    transcendental: 2.0,
    conversion: 8.0,
    integer: 8.0,
    issue: 8.0,
};

impl Gpu {
    /// Every GPU, by vendor, oldest first.
    pub const ALL: [Gpu; 11] = [
        Gpu {
            id: "sm_75",
            vendor: Vendor::Nvidia,
            name: "NVIDIA Turing (RTX 20, T4)",
            compiler_target: "sm_75",
            unit: "SM",
            rates: Rates {
                arithmetic: 64.0,
                ..NVIDIA_128
            },
            source: CUDA_GUIDE,
        },
        Gpu {
            id: "sm_86",
            vendor: Vendor::Nvidia,
            name: "NVIDIA Ampere GA10x (RTX 30, A40)",
            compiler_target: "sm_86",
            unit: "SM",
            rates: NVIDIA_128,
            source: CUDA_GUIDE,
        },
        Gpu {
            id: "sm_89",
            vendor: Vendor::Nvidia,
            name: "NVIDIA Ada (RTX 40, L4, L40)",
            compiler_target: "sm_89",
            unit: "SM",
            rates: NVIDIA_128,
            source: CUDA_GUIDE,
        },
        Gpu {
            id: "sm_90",
            vendor: Vendor::Nvidia,
            name: "NVIDIA Hopper (H100, H200)",
            compiler_target: "sm_90",
            unit: "SM",
            rates: NVIDIA_128,
            source: CUDA_GUIDE,
        },
        Gpu {
            id: "sm_120",
            vendor: Vendor::Nvidia,
            name: "NVIDIA Blackwell (RTX 50)",
            compiler_target: "sm_120",
            unit: "SM",
            rates: NVIDIA_128,
            source: "taken as compute capability 8.9's (the CUDA guide's figures above): \
                     Blackwell's SM keeps four partitions of 32 FP32 lanes and one \
                     special-function quad each",
        },
        Gpu {
            id: "gfx900",
            vendor: Vendor::Amd,
            name: "AMD GCN 5 Vega 10 (RX Vega 56/64)",
            compiler_target: "vega10",
            unit: "CU",
            rates: AMD_64,
            source: "AMD 'Vega' ISA reference guide and the GCN architecture whitepaper: four \
                     SIMD16 per CU, a wave64 vector instruction over four clocks; \
                     transcendentals at a quarter rate",
        },
        Gpu {
            id: "gfx1010",
            vendor: Vendor::Amd,
            name: "AMD RDNA 1 Navi 10 (RX 5700)",
            compiler_target: "navi10",
            unit: "CU",
            rates: AMD_64,
            source: RDNA,
        },
        Gpu {
            id: "gfx1030",
            vendor: Vendor::Amd,
            name: "AMD RDNA 2 Navi 21 (RX 6800, 6900)",
            compiler_target: "navi21",
            unit: "CU",
            rates: AMD_64,
            source: RDNA,
        },
        Gpu {
            id: "gfx1100",
            vendor: Vendor::Amd,
            name: "AMD RDNA 3 Navi 31 (RX 7900)",
            compiler_target: "gfx1100",
            unit: "CU",
            rates: AMD_64,
            source: RDNA,
        },
        Gpu {
            id: "tgllp",
            vendor: Vendor::Intel,
            name: "Intel Xe-LP (Tiger Lake, Iris Xe)",
            compiler_target: "tgllp",
            unit: "EU",
            rates: XE,
            source: "Intel Xe-LP architecture (Architecture Day 2020, as AnandTech's 'Intel \
                     Xe-LP GPU Architecture Deep Dive' reports it): each EU an 8-lane FP/INT \
                     ALU and a 2-lane extended-math ALU",
        },
        Gpu {
            id: "dg2",
            vendor: Vendor::Intel,
            name: "Intel Xe-HPG DG2-512 (Arc A770, A750)",
            compiler_target: "dg2-g10",
            unit: "vector engine",
            rates: XE,
            source: "taken as Xe-LP's EU (8 FP/INT lanes, 2 extended-math lanes per clock): \
                     Xe-HPG's vector engine keeps the 8-lane FP ALU",
        },
    ];

    /// Where the rates come from, named without the figures (the source up to its first
    /// colon).
    #[must_use]
    pub fn source_name(&self) -> &'static str {
        self.source.split(':').next().unwrap_or(self.source)
    }

    /// The GPU named `id`.
    #[must_use]
    pub fn find(id: &str) -> Option<Gpu> {
        Self::ALL.into_iter().find(|gpu| gpu.id == id)
    }

    /// The GPU named `id`, or a message naming the valid ones.
    pub fn parse(id: &str) -> Result<Gpu, String> {
        Self::find(id).ok_or_else(|| {
            format!(
                "unknown GPU '{id}'; valid GPUs: {}",
                Self::ALL.map(|gpu| gpu.id).join(", ")
            )
        })
    }

    /// A vendor's GPUs.
    pub fn of(vendor: Vendor) -> impl Iterator<Item = Gpu> {
        Self::ALL
            .into_iter()
            .filter(move |gpu| gpu.vendor == vendor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_vendor_has_its_default_among_its_gpus_and_ids_are_unique() {
        for vendor in Vendor::ALL {
            assert_eq!(vendor.default_gpu().vendor, vendor);
        }
        let mut ids: Vec<_> = Gpu::ALL.iter().map(|gpu| gpu.id).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), Gpu::ALL.len());
        assert!(Gpu::parse("navi31").unwrap_err().contains("gfx1100"));
    }
}
