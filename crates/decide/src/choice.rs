//! The closed sets a request chooses from: where the lobe runs ([`Target`]) and where its
//! error is measured ([`Zone`]). Each has its ids (what every face parses and prints), a
//! one-line summary (what `--help` lists) and a `FromStr` whose refusal names the valid ids.

use core::fmt;
use core::str::FromStr;

use serde::{Deserialize, Serialize};
use specula::analysis::ErrorFigures;
use specula::gpus::{Gpu, Vendor};

/// Where the lobe will run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    /// This machine's CPU: measured SIMD throughput.
    Cpu,
    /// NVIDIA GPUs: the SASS `nvcc` compiles for a generation (`sm_89` unless named).
    GpuNvidia,
    /// AMD GPUs: the ISA ACO compiles for a chip (`gfx1100` unless named).
    GpuAmd,
    /// Intel GPUs: the ISA IGC compiles for a device (`dg2` unless named).
    GpuIntel,
    /// FPGA: the fixed-point datapaths synthesized on an iCE40 HX8K (Yosys, nextpnr; cached),
    /// or estimated from their operators where the tools are missing.
    Fpga,
}

impl Target {
    /// Every target, in the order faces list them.
    pub const ALL: [Target; 5] = [
        Target::Cpu,
        Target::GpuNvidia,
        Target::GpuAmd,
        Target::GpuIntel,
        Target::Fpga,
    ];

    /// The GPU targets, in the order faces list them.
    pub const GPUS: [Target; 3] = [Target::GpuNvidia, Target::GpuAmd, Target::GpuIntel];

    /// The id every face parses and prints: `cpu`, `gpu-nvidia`, `gpu-amd`, `gpu-intel`,
    /// `fpga`.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Target::Cpu => "cpu",
            Target::GpuNvidia => "gpu-nvidia",
            Target::GpuAmd => "gpu-amd",
            Target::GpuIntel => "gpu-intel",
            Target::Fpga => "fpga",
        }
    }

    /// A GPU target's vendor.
    #[must_use]
    pub fn vendor(self) -> Option<Vendor> {
        match self {
            Target::GpuNvidia => Some(Vendor::Nvidia),
            Target::GpuAmd => Some(Vendor::Amd),
            Target::GpuIntel => Some(Vendor::Intel),
            Target::Cpu | Target::Fpga => None,
        }
    }

    /// The GPU a GPU target is costed on: `gpu` where given (refused where it is another
    /// vendor's), else the vendor's current generation ([`Vendor::default_gpu`]).
    pub fn gpu(self, gpu: Option<Gpu>) -> Result<Option<Gpu>, String> {
        let Some(vendor) = self.vendor() else {
            return match gpu {
                Some(gpu) => Err(format!(
                    "--gpu {} names a GPU and the target is {}; choose gpu-{} with it",
                    gpu.id,
                    self.id(),
                    gpu.vendor.id()
                )),
                None => Ok(None),
            };
        };
        match gpu {
            Some(gpu) if gpu.vendor != vendor => Err(format!(
                "--gpu {} is an {} GPU, not for --target {}; valid GPUs: {}",
                gpu.id,
                gpu.vendor.name(),
                self.id(),
                Gpu::of(vendor).map(|g| g.id).collect::<Vec<_>>().join(", ")
            )),
            Some(gpu) => Ok(Some(gpu)),
            None => Ok(Some(vendor.default_gpu())),
        }
    }

    /// How the target's costs are obtained, in one line (a face's help text).
    #[must_use]
    pub fn summary(self) -> &'static str {
        match self {
            Target::Cpu => "This machine's CPU: measured SIMD throughput",
            Target::GpuNvidia => {
                "NVIDIA GPUs: the SASS nvcc compiles for --gpu (sm_75 to sm_120; sm_89 unless \
                 named), each class at its published rate"
            }
            Target::GpuAmd => {
                "AMD GPUs: the ISA ACO (Mesa RADV) compiles for --gpu (gfx900 to gfx1100; \
                 gfx1100 unless named), each class at its published rate, and ACO's estimate"
            }
            Target::GpuIntel => {
                "Intel GPUs: the ISA IGC (ocloc) compiles for --gpu (tgllp, dg2; dg2 unless \
                 named), each class at its published rate"
            }
            Target::Fpga => {
                "FPGA: the fixed-point datapaths synthesized on an iCE40 HX8K (Yosys and \
                 nextpnr, cached), or estimated from their operators without the tools"
            }
        }
    }
}

/// Where the error is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Zone {
    /// The epicentre's largest relative error (where `t^n >= 1/2`).
    Epicentre,
    /// The bloom's largest absolute error, as a fraction of the peak.
    Bloom,
    /// The largest absolute error anywhere, as a fraction of the peak.
    Whole,
}

impl Zone {
    /// Every zone, in the order faces list them.
    pub const ALL: [Zone; 3] = [Zone::Epicentre, Zone::Bloom, Zone::Whole];

    /// The id every face parses and prints: `epicentre`, `bloom`, `whole`.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Zone::Epicentre => "epicentre",
            Zone::Bloom => "bloom",
            Zone::Whole => "whole",
        }
    }

    /// What the zone's error is, in one line (a face's help text).
    #[must_use]
    pub fn summary(self) -> &'static str {
        match self {
            Zone::Epicentre => "The epicentre's largest relative error (where `t^n >= 1/2`)",
            Zone::Bloom => "The bloom's largest absolute error, as a fraction of the peak",
            Zone::Whole => "The largest absolute error anywhere, as a fraction of the peak",
        }
    }

    /// The zone's error among `figures`.
    #[must_use]
    pub fn error(self, figures: &ErrorFigures) -> f64 {
        match self {
            Zone::Epicentre => figures.epicentre_max_rel,
            Zone::Bloom => figures.bloom_max_abs,
            Zone::Whole => figures
                .epicentre_max_abs
                .max(figures.bloom_max_abs)
                .max(figures.tail_max_abs),
        }
    }
}

impl FromStr for Target {
    type Err = String;

    /// `cpu`, `gpu-nvidia`, `gpu-amd`, `gpu-intel` or `fpga`.
    fn from_str(text: &str) -> Result<Self, String> {
        specula::choose(&Target::ALL, Target::id, text, "target", "targets")
    }
}

impl FromStr for Zone {
    type Err = String;

    /// `epicentre`, `bloom` or `whole`.
    fn from_str(text: &str) -> Result<Self, String> {
        specula::choose(&Zone::ALL, Zone::id, text, "zone", "zones")
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id())
    }
}

impl fmt::Display for Zone {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_round_trip_and_a_bad_one_names_the_valid_ones() {
        for target in Target::ALL {
            assert_eq!(target.id().parse::<Target>(), Ok(target));
            assert_eq!(target.to_string(), target.id());
        }
        for zone in Zone::ALL {
            assert_eq!(zone.id().parse::<Zone>(), Ok(zone));
        }
        assert_eq!(
            "tpu".parse::<Target>(),
            Err(
                "unknown target 'tpu'; valid targets: cpu, gpu-nvidia, gpu-amd, gpu-intel, fpga"
                    .to_owned()
            )
        );
        let refusal = "x\ny".parse::<Zone>().unwrap_err();
        assert_eq!(refusal.lines().count(), 1, "{refusal}");
        assert!(
            refusal.ends_with("valid zones: epicentre, bloom, whole"),
            "{refusal}"
        );
    }
}
