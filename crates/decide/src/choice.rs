//! The closed sets a request chooses from: where the lobe runs ([`Target`]) and where its
//! error is measured ([`Zone`]). Each has its ids (what every face parses and prints), a
//! one-line summary (what `--help` lists) and a `FromStr` whose refusal names the valid ids.

use core::fmt;
use core::str::FromStr;

use serde::{Deserialize, Serialize};
use specula::analysis::ErrorFigures;

/// Where the lobe will run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    /// This machine's CPU: measured SIMD throughput.
    Cpu,
    /// NVIDIA GPUs (compute capability 8.6-9.0): modelled from the shader's instructions.
    GpuNvidia,
    /// AMD RDNA GPUs: modelled from the shader's instructions.
    GpuAmd,
    /// FPGA: the fixed-point datapaths synthesized on an iCE40 HX8K (Yosys, nextpnr; cached),
    /// or estimated from their operators where the tools are missing.
    Fpga,
}

impl Target {
    /// Every target, in the order faces list them.
    pub const ALL: [Target; 4] = [Target::Cpu, Target::GpuNvidia, Target::GpuAmd, Target::Fpga];

    /// The id every face parses and prints: `cpu`, `gpu-nvidia`, `gpu-amd`, `fpga`.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Target::Cpu => "cpu",
            Target::GpuNvidia => "gpu-nvidia",
            Target::GpuAmd => "gpu-amd",
            Target::Fpga => "fpga",
        }
    }

    /// How the target's costs are obtained, in one line (a face's help text).
    #[must_use]
    pub fn summary(self) -> &'static str {
        match self {
            Target::Cpu => "This machine's CPU: measured SIMD throughput",
            Target::GpuNvidia => {
                "NVIDIA GPUs (compute capability 8.6-9.0): modelled from the shader's instructions"
            }
            Target::GpuAmd => "AMD RDNA GPUs: modelled from the shader's instructions",
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

    /// `cpu`, `gpu-nvidia`, `gpu-amd` or `fpga`.
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
            Err("unknown target 'tpu'; valid targets: cpu, gpu-nvidia, gpu-amd, fpga".to_owned())
        );
        let refusal = "x\ny".parse::<Zone>().unwrap_err();
        assert_eq!(refusal.lines().count(), 1, "{refusal}");
        assert!(
            refusal.ends_with("valid zones: epicentre, bloom, whole"),
            "{refusal}"
        );
    }
}
