//! What a lobe costs on a target (higher is cheaper): on the CPU, its SIMD kernel's measured
//! rate on this machine (every candidate timed beside the others, [`crate::rates::kernel_rates`]);
//! on a GPU family, the modelled
//! evaluations per clock of its exported shader; on the FPGA, the datapath
//! [`cheapest_datapath`] picks at the width the error needs, synthesized (cached) or, without
//! the tools, estimated. `recommend.rs` ranks by these; a material's verdict
//! (`material.rs`) takes [`lobe_rate`], which refuses the FPGA.

use indicatif::ProgressBar;
use specula::gpu_cost::GpuFamily;
use specula::{Exponent, Lobe, LobeKind};
use specula_hw::analysis::WidthSweep;

use crate::hardware::{cheapest_datapath, hardware_sweeps};
use crate::{Target, Zone};

/// How a target's costs are obtained.
pub(crate) enum Costing {
    /// Timed on this machine's CPU: the rates [`Costing::time_kernels`] took, each lobe's
    /// against every other's in one measurement, and any other lobe timed when costed.
    Measured(Vec<TimedRate>),
    /// The GPU cost model of one family.
    Modelled(GpuFamily),
    /// Estimated from the fixed-point datapaths' sweeps, per exponent (without Yosys).
    Estimated(Vec<(Exponent, std::sync::Arc<Vec<WidthSweep>>)>),
    /// Synthesized and placed (Yosys, nextpnr-ice40 on an iCE40 HX8K; cached), at the word
    /// lengths the sweeps choose.
    Synthesized(Vec<(Exponent, std::sync::Arc<Vec<WidthSweep>>)>),
}

/// A kernel's rates timed beside the others', one a pass ([`crate::rates::kernel_rates`]).
pub(crate) struct TimedRate {
    kind: LobeKind,
    n: Exponent,
    passes: Vec<f64>,
}

/// Where the FPGA's costs are synthesized: every operator in LUTs, one area figure.
pub(crate) const FPGA_TARGET: specula_synth::Target =
    specula_synth::Target::Ice40(specula_synth::Ice40Device::Hx8k);

/// One lobe at one exponent: its error, its cost figure (higher is cheaper), and on the FPGA
/// the datapath costed.
#[derive(Clone)]
pub(crate) struct Point {
    pub(crate) error: f64,
    pub(crate) rate: f64,
    pub(crate) datapath: Option<String>,
    /// Measured on the CPU: the median and the fastest of the timing's passes (the rate is
    /// the fastest: noise only ever slows a kernel down).
    pub(crate) spread: Option<[f64; 2]>,
}

/// The integer exponent the datapaths take for `n`.
fn datapath_exponent(n: Exponent) -> u32 {
    n.get().round().clamp(1.0, 1000.0) as u32
}

impl Costing {
    /// The costing of `target` at `exponents`, and a note for the user where the FPGA's tools
    /// are missing.
    pub(crate) fn new(
        target: Target,
        exponents: &[Exponent],
    ) -> Result<(Self, Option<String>), String> {
        let family = |id: &str| {
            GpuFamily::find(id).ok_or_else(|| format!("no GPU family '{id}' in the model"))
        };
        Ok(match target {
            Target::Cpu => (Costing::Measured(Vec::new()), None),
            Target::GpuNvidia => (Costing::Modelled(family("gpu-nvidia")?), None),
            Target::GpuAmd => (Costing::Modelled(family("gpu-amd")?), None),
            Target::Fpga => {
                let sweeps = exponents
                    .iter()
                    .map(|&n| Ok((n, hardware_sweeps(datapath_exponent(n))?)))
                    .collect::<Result<Vec<_>, String>>()?;
                match specula_synth::ToolVersions::find(FPGA_TARGET) {
                    Ok(_) => (Costing::Synthesized(sweeps), None),
                    Err(missing) => (
                        Costing::Estimated(sweeps),
                        Some(format!(
                            "{missing}; FPGA costs are the formula estimate instead"
                        )),
                    ),
                }
            }
        })
    }

    /// On the CPU, times every one of `lobes` at every one of `exponents` together
    /// ([`crate::rates::kernel_rates`]), so that their rates compare like with like; elsewhere
    /// nothing. A lobe's exponents whose kernels execute the same instructions (every `n` of
    /// most lobes: `n` enters as a constant; `cosquad` and `schlick-mod` change shape at
    /// powers of two) are timed once, at the first of them: the same kernel over the same
    /// cosines, so a range costs a few timings a lobe, not one an exponent, and its slowest
    /// exponent is not the unluckiest of a dozen timings of one kernel. `progress` is set to
    /// count the passes.
    pub(crate) fn time_kernels(
        &mut self,
        lobes: &[LobeKind],
        exponents: &[Exponent],
        progress: &ProgressBar,
    ) {
        let Costing::Measured(timed) = self else {
            return;
        };
        progress.set_length((lobes.len() * crate::rates::PASSES) as u64);
        progress.set_message("timing the kernels");
        // Per lobe, each exponent's representative: the first exponent whose kernel executes
        // the same instructions.
        let representatives: Vec<Vec<usize>> = lobes
            .iter()
            .map(|&kind| {
                let instructions: Vec<_> = exponents
                    .iter()
                    .map(|&n| Lobe::new(kind, n).batch_instructions())
                    .collect();
                instructions
                    .iter()
                    .map(|i| instructions.iter().position(|j| j == i).unwrap_or(0))
                    .collect()
            })
            .collect();
        let prepared: Vec<Vec<Lobe>> = lobes
            .iter()
            .zip(&representatives)
            .map(|(&kind, firsts)| {
                // Each representative is the first of its kind, so they are the exponents that
                // are their own.
                (0..exponents.len())
                    .filter(|&k| firsts[k] == k)
                    .map(|k| Lobe::new(kind, exponents[k]))
                    .collect()
            })
            .collect();
        let rates = crate::rates::kernel_rates(&prepared, progress);
        *timed = lobes
            .iter()
            .zip(&representatives)
            .zip(prepared.iter().zip(rates))
            .flat_map(|((&kind, firsts), (timed_at, rates))| {
                exponents.iter().zip(firsts).map(move |(&n, &first)| {
                    let at = timed_at
                        .iter()
                        .position(|lobe| lobe.exponent() == exponents[first])
                        .unwrap_or(0);
                    TimedRate {
                        kind,
                        n,
                        passes: rates[at].clone(),
                    }
                })
            })
            .collect();
        progress.reset();
    }

    pub(crate) fn unit(&self) -> &'static str {
        match self {
            Costing::Measured(_) => "evals/s, 1 thread",
            Costing::Modelled(_) => "evals/clock/multiprocessor (modelled)",
            Costing::Estimated(_) => "evals/clock per 1000 logic cells (estimated)",
            Costing::Synthesized(_) => "results/us per 1000 LUTs (synthesized, iCE40 HX8K)",
        }
    }

    /// `lobe` at its exponent, or `None` where the target cannot run it (no datapath).
    pub(crate) fn point(
        &self,
        lobe: &Lobe,
        zone: Zone,
        max_error: f64,
    ) -> Result<Option<Point>, String> {
        let float_error = || zone.error(&crate::figures::f64_figures(lobe));
        Ok(match self {
            Costing::Measured(timed) => {
                let passes = timed
                    .iter()
                    .find(|r| r.kind == lobe.kind() && r.n == lobe.exponent())
                    .map(|r| r.passes.clone());
                let spread = passes
                    .as_deref()
                    .map(|passes| [median(passes), passes.iter().copied().fold(0.0, f64::max)]);
                Some(Point {
                    error: float_error(),
                    rate: spread.map_or_else(|| crate::rates::kernel_rate(lobe), |[_, best]| best),
                    datapath: None,
                    spread,
                })
            }
            Costing::Modelled(family) => Some(Point {
                error: float_error(),
                rate: modelled_rate(family, lobe)?,
                datapath: None,
                spread: None,
            }),
            Costing::Estimated(hardware) | Costing::Synthesized(hardware) => {
                let Some(chosen) = hardware
                    .iter()
                    .find(|(at, _)| *at == lobe.exponent())
                    .and_then(|(_, sweeps)| {
                        cheapest_datapath(sweeps, lobe.kind(), zone, max_error)
                    })
                else {
                    return Ok(None);
                };
                let mut datapath = format!("{} at {} bits", chosen.lobe.id(), chosen.bits);
                let rate = match self {
                    // A datapath that cannot reach the error is not worth the tools' minutes:
                    // it is listed, with its error, as not meeting.
                    Costing::Synthesized(_) if chosen.error > max_error => {
                        datapath += " (not synthesized: short of the error)";
                        0.0
                    }
                    Costing::Synthesized(_) => {
                        let cache = specula_synth::cache::Cache::default_location();
                        let synthesis = specula_synth::synthesize(
                            chosen.lobe,
                            chosen.bits,
                            FPGA_TARGET,
                            cache.as_ref(),
                        )
                        .map_err(|e| e.to_string())?;
                        let (rate, unfit) = synthesized_rate(&synthesis);
                        datapath += unfit.unwrap_or_default();
                        rate
                    }
                    _ => 1e3 / chosen.cells as f64,
                };
                Some(Point {
                    error: chosen.error,
                    rate,
                    datapath: Some(datapath),
                    spread: None,
                })
            }
        })
    }
}

/// The median of `values` (the mean of the middle two for an even count; NaN for none).
#[must_use]
pub(crate) fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    match sorted.len() {
        0 => f64::NAN,
        len if len % 2 == 1 => sorted[len / 2],
        len => 0.5 * (sorted[len / 2 - 1] + sorted[len / 2]),
    }
}

/// A synthesized datapath's rate in results per microsecond per 1000 LUTs, and what its name
/// gains where nextpnr placed it nowhere: it does not fit the part (the synthesis's note says
/// why), and a rate of 0 keeps it from meeting any request.
fn synthesized_rate(synthesis: &specula_synth::Synthesis) -> (f64, Option<&'static str>) {
    match synthesis.logic_ns_per_result() {
        Some(lut_ns) => (1e6 / lut_ns, None),
        None => (0.0, Some(" (does not fit the iCE40 HX8K)")),
    }
}

/// Why a material's verdict refuses the FPGA.
pub const FPGA_MATERIAL_REFUSAL: &str = "a material verdict cannot target fpga: the fixed-point \
    datapaths take an integer n and a word length chosen for an error against t^n, which a \
    material's fit does not give; valid targets: cpu, gpu-nvidia, gpu-amd";

/// `lobe`'s evaluations per clock per multiprocessor on `family`, by the GPU cost model over
/// the instructions of its exported shader (higher is cheaper).
pub fn modelled_rate(family: &GpuFamily, lobe: &Lobe) -> Result<f64, String> {
    let ops = specula_gpu::shader_ops::lobe_shader_ops(lobe)?;
    Ok(family.cost(&ops).evals_per_clock)
}

/// `target` if a material's verdict can be given on it: every target but the FPGA
/// ([`FPGA_MATERIAL_REFUSAL`]).
pub(crate) fn material_target(target: Target) -> Result<Target, String> {
    match target {
        Target::Fpga => Err(FPGA_MATERIAL_REFUSAL.to_owned()),
        _ => Ok(target),
    }
}

/// A lobe's rate on `target` for a material's verdict (higher is cheaper): measured on the
/// CPU, modelled on a GPU; the FPGA is refused ([`FPGA_MATERIAL_REFUSAL`]) before any
/// costing starts (costing it would run its sweeps).
pub fn lobe_rate(target: Target, lobe: &Lobe) -> Result<f64, String> {
    let target = material_target(target)?;
    match Costing::new(target, &[lobe.exponent()])?.0 {
        Costing::Measured(_) => Ok(crate::rates::kernel_rate(lobe)),
        Costing::Modelled(family) => modelled_rate(&family, lobe),
        Costing::Estimated(_) | Costing::Synthesized(_) => Err(FPGA_MATERIAL_REFUSAL.to_owned()),
    }
}

/// The unit of [`lobe_rate`] on `target` (empty for the FPGA, which it refuses).
#[must_use]
pub fn rate_unit(target: Target) -> &'static str {
    match target {
        // Costing the FPGA would run its sweeps; material verdicts refuse it anyway.
        Target::Fpga => "",
        _ => Costing::new(target, &[]).map_or("", |(costing, _)| costing.unit()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn synthesis(fmax_mhz: Option<f64>) -> specula_synth::Synthesis {
        specula_synth::Synthesis {
            lobe: "schlick-mod".to_owned(),
            bits: 16,
            target: FPGA_TARGET,
            tools: specula_synth::ToolVersions {
                yosys: "Yosys 0.23".to_owned(),
                nextpnr: Some("nextpnr-ice40 0.4".to_owned()),
            },
            cells: specula_synth::report::Cells {
                logic: 2000,
                ..Default::default()
            },
            fmax_mhz,
            fmax_note: fmax_mhz
                .is_none()
                .then(|| "does not fit the HX8K once packed".to_owned()),
            logic_cells_placed: None,
            latency: 11,
        }
    }

    /// 2000 LUTs at 10 MHz cost 2000 x 100 ns = 200,000 LUT x ns per result: 5 results per
    /// microsecond per 1000 LUTs. Placed nowhere, the datapath costs nothing it could run.
    #[test]
    fn a_placed_datapath_is_costed_by_its_area_and_clock_and_an_unplaced_one_not_at_all() {
        let (rate, unfit) = synthesized_rate(&synthesis(Some(10.0)));
        assert!((rate - 5.0).abs() < 1e-12 && unfit.is_none(), "{rate}");
        let (rate, unfit) = synthesized_rate(&synthesis(None));
        assert_eq!(rate, 0.0);
        assert!(unfit.unwrap().contains("does not fit the iCE40 HX8K"));
    }
}
