//! The thesis's hardware claim, by synthesis: does the cosine-quadratic lobe "simplify the
//! hardware implementation"?
//!
//! **Equal error.** A datapath is cheaper only at the same accuracy, so each is taken at the
//! smallest word length whose epicentre max relative error at `n = 64` reaches a common
//! target: [`TARGET_OVER_COSQUAD`] times the `cosquad` float model's own error (the model's
//! error plus a quarter for its fixed point). A datapath whose float model cannot reach it
//! (Schlick's, Mitchell's log2) is listed as not reaching it.
//!
//! **Cost.** Each is synthesized and placed on an iCE40 HX8K, which has no multiplier blocks,
//! so every operator is in LUT4s and the area is one number; the cost per result is
//! `LUTs x clock period` (the pipelines take one input per clock). The claim holds if
//! `cosquad` costs less than both baselines, the exact `pow` and the engines' spherical
//! Gaussian `sg`; with qualification if it beats only `pow`.

use rayon::prelude::*;
use serde::Serialize;
use specula::claims::{Figure, Verdict};
use specula_hw::analysis::WidthSweep;
use specula_hw::HwLobe;

use crate::cache::Cache;
use crate::{synthesize_or, Ice40Device, OnMiss, SynthError, Synthesis, Target};

/// The exponent the designs are compared at.
pub const CLAIM_N: u32 = 64;
/// The common error target, as a multiple of the `cosquad` float model's epicentre error.
pub const TARGET_OVER_COSQUAD: f64 = 1.25;
/// Where the designs are synthesized.
pub const CLAIM_TARGET: Target = Target::Ice40(Ice40Device::Hx8k);
/// The claim's statement.
pub const STATEMENT: &str = "8: the cosine-quadratic lobe simplifies the hardware implementation";

/// One datapath at the common target.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Design {
    /// The datapath.
    pub lobe: HwLobe,
    /// The smallest word length reaching the target, if one in the sweep does.
    pub bits: Option<u32>,
    /// Its epicentre max relative error there.
    pub epicentre_max_rel: Option<f64>,
    /// The synthesized, placed design.
    pub synthesis: Option<Synthesis>,
}

/// The claim's outcome, shaped like the core's claim results.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HardwareClaim {
    /// The number and statement.
    pub claim: &'static str,
    /// The reading under which it was tested.
    pub reading: String,
    /// The result in one sentence.
    pub measured: String,
    /// The verdict.
    pub verdict: Verdict,
    /// The figures behind it: each design's `LUT x ns` per result.
    pub figures: Vec<Figure>,
    /// The target error.
    pub target_epicentre_max_rel: f64,
    /// Every datapath at the target.
    pub designs: Vec<Design>,
}

/// The designs at equal error, chosen from `sweeps` (every datapath at [`CLAIM_N`]), not
/// yet synthesized; and the target error.
///
/// # Panics
/// If `sweeps` has no `cosquad` sweep.
#[must_use]
pub fn designs(sweeps: &[WidthSweep]) -> (f64, Vec<Design>) {
    let cosquad = sweeps
        .iter()
        .find(|sweep| sweep.lobe == HwLobe::CosQuad)
        .expect("the sweeps include cosquad");
    let target = TARGET_OVER_COSQUAD * cosquad.float.epicentre_max_rel;
    let designs = sweeps
        .iter()
        .map(|sweep| {
            let row = sweep
                .rows
                .iter()
                .find(|row| row.errors.epicentre_max_rel <= target);
            Design {
                lobe: sweep.lobe,
                bits: row.map(|row| row.bits),
                epicentre_max_rel: row.map(|row| row.errors.epicentre_max_rel),
                synthesis: None,
            }
        })
        .collect();
    (target, designs)
}

/// Synthesizes every design that reaches the target (`on_each` after each; with
/// [`OnMiss::Skip`], only those the cache holds) and judges the claim.
pub fn evaluate(
    sweeps: &[WidthSweep],
    cache: Option<&Cache>,
    on_miss: OnMiss,
    on_each: &(dyn Fn() + Sync),
) -> Result<HardwareClaim, SynthError> {
    let (target, mut designs) = designs(sweeps);
    // One tool run per core at a time, as `specula hw synth` runs them.
    let results: Vec<Result<Option<Synthesis>, SynthError>> = designs
        .par_iter()
        .map(|design| {
            let result = design.bits.map_or(Ok(None), |bits| {
                synthesize_or(design.lobe, bits, CLAIM_TARGET, cache, on_miss)
            });
            on_each();
            result
        })
        .collect();
    for (design, result) in designs.iter_mut().zip(results) {
        design.synthesis = result?;
    }
    Ok(judge(target, designs))
}

/// The cost per result of `lobe`'s design, if it was synthesized and placed.
fn cost(designs: &[Design], lobe: HwLobe) -> Option<f64> {
    designs
        .iter()
        .find(|design| design.lobe == lobe)
        .and_then(|design| design.synthesis.as_ref())
        .and_then(Synthesis::logic_ns_per_result)
}

fn judge(target: f64, designs: Vec<Design>) -> HardwareClaim {
    let figures: Vec<Figure> = designs
        .iter()
        .filter_map(|design| {
            let value = design.synthesis.as_ref()?.logic_ns_per_result()?;
            Some(Figure {
                name: format!("{} LUT x ns per result", design.lobe.id()),
                value,
            })
        })
        .collect();
    let (cosquad, pow, sg) = (
        cost(&designs, HwLobe::CosQuad),
        cost(&designs, HwLobe::Pow),
        cost(&designs, HwLobe::Sg),
    );
    let describe = |lobe: HwLobe| {
        designs
            .iter()
            .find(|design| design.lobe == lobe)
            .and_then(|design| Some((design.bits?, design.synthesis.as_ref()?)))
            .map_or_else(
                || format!("{} not placed", lobe.id()),
                |(bits, s)| {
                    format!(
                        "{} at {bits} bits: {} LUTs at {:.1} MHz = {:.0} LUT x ns",
                        lobe.id(),
                        s.cells.logic,
                        s.fmax_mhz.unwrap_or(f64::NAN),
                        s.logic_ns_per_result().unwrap_or(f64::NAN)
                    )
                },
            )
    };
    let verdict = match (cosquad, pow, sg) {
        (Some(c), Some(p), Some(s)) if c < p && c < s => Verdict::Holds,
        (Some(c), Some(p), _) if c < p => Verdict::HoldsWithQualification,
        _ => Verdict::DoesNotHold,
    };
    let tools = designs
        .iter()
        .find_map(|design| design.synthesis.as_ref())
        .map_or_else(String::new, |s| s.tools.describe());
    HardwareClaim {
        claim: STATEMENT,
        reading: format!(
            "each datapath at the smallest word length whose epicentre max relative error at n = \
                {CLAIM_N} is at most {:.3} % ({TARGET_OVER_COSQUAD} x the cosquad model's), \
                synthesized and placed on an iCE40 HX8K (every operator in LUT4s; {tools}); cost = \
                LUTs x clock period per result; holds if cosquad is cheaper than both pow and sg, \
                with qualification if only than pow",
            target * 100.0
        ),
        measured: format!(
            "{}; {}; {}",
            describe(HwLobe::CosQuad),
            describe(HwLobe::Pow),
            describe(HwLobe::Sg)
        ),
        verdict,
        figures,
        target_epicentre_max_rel: target,
        designs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::Cells;
    use crate::ToolVersions;

    fn placed(lobe: HwLobe, luts: u64, mhz: f64) -> Design {
        Design {
            lobe,
            bits: Some(12),
            epicentre_max_rel: Some(0.01),
            synthesis: Some(Synthesis {
                lobe: lobe.id().to_owned(),
                bits: 12,
                target: CLAIM_TARGET,
                tools: ToolVersions {
                    yosys: "Yosys test".to_owned(),
                    nextpnr: None,
                },
                cells: Cells {
                    logic: luts,
                    ..Cells::default()
                },
                fmax_mhz: Some(mhz),
                fmax_note: None,
                logic_cells_placed: Some(luts),
                latency: 4,
            }),
        }
    }

    /// The verdict follows the costs: 100 LUTs at 100 MHz is 1,000 LUT x ns.
    #[test]
    fn the_verdict_follows_the_area_delay_products() {
        let verdict = |c: u64, p: u64, s: u64| {
            judge(
                0.02,
                vec![
                    placed(HwLobe::CosQuad, c, 100.0),
                    placed(HwLobe::Pow, p, 100.0),
                    placed(HwLobe::Sg, s, 100.0),
                ],
            )
            .verdict
        };
        assert_eq!(verdict(100, 200, 150), Verdict::Holds);
        assert_eq!(verdict(100, 200, 50), Verdict::HoldsWithQualification);
        assert_eq!(verdict(300, 200, 50), Verdict::DoesNotHold);
        let claim = judge(0.02, vec![placed(HwLobe::CosQuad, 100, 50.0)]);
        assert_eq!(claim.figures[0].value, 2000.0);
        assert_eq!(claim.verdict, Verdict::DoesNotHold, "no baseline, no claim");
    }
}
