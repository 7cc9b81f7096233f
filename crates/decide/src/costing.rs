//! What a lobe costs on a target (higher is cheaper): on the CPU, its SIMD kernel's measured
//! rate on this machine (every candidate timed beside the others, [`crate::rates::kernel_rates`]);
//! on a GPU generation, the evaluations per clock of the machine code its vendor's compiler
//! writes for the lobe's kernel (`specula-isa`), each class at the generation's published
//! rate, or, where the compiler is missing, of the naga-IR model's counts (said so); on the
//! FPGA, the datapath [`cheapest_datapath`] picks at the width the error needs, synthesized
//! (cached) or, without the tools, estimated. `recommend.rs` ranks by these; a material's
//! verdict (`material.rs`) takes [`lobe_rate`], which refuses the FPGA.

use indicatif::ProgressBar;
use specula::gpus::{Gpu, Vendor};
use specula::{Exponent, Lobe, LobeKind};
use specula_hw::analysis::WidthSweep;
use specula_isa::{IsaError, Work};

use crate::hardware::{cheapest_datapath, hardware_sweeps};
use crate::{Target, Zone};

/// How a target's costs are obtained.
pub(crate) enum Costing {
    /// Timed on this machine's CPU: the rates [`Costing::time_kernels`] took, each lobe's
    /// against every other's in one measurement, and any other lobe timed when costed.
    Measured(Vec<TimedRate>),
    /// One GPU generation, costed on the basis its compilers allow.
    Gpu(Gpu, GpuBasis),
    /// Estimated from the fixed-point datapaths' sweeps, per exponent (without Yosys).
    Estimated(Vec<(Exponent, std::sync::Arc<Vec<WidthSweep>>)>),
    /// Synthesized and placed (Yosys, nextpnr-ice40 on an iCE40 HX8K; cached), at the word
    /// lengths the sweeps choose.
    Synthesized(Vec<(Exponent, std::sync::Arc<Vec<WidthSweep>>)>),
}

/// What a GPU's costs are read off.
#[derive(Clone, Debug)]
pub(crate) enum GpuBasis {
    /// The machine code the vendor's compiler (named, with its version) writes.
    Compiled(String),
    /// The naga-IR model: the compiler is missing (the note says which and how to install
    /// it).
    Modelled,
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
    /// On AMD, ACO's estimated inverse throughput of the lobe's kernel beyond the baseline's,
    /// cycles a wave.
    pub(crate) aco_inverse_throughput: Option<f64>,
    /// On the FPGA, the rate is a bound, not a synthesis: the lobe could not win
    /// (`synthesis_plan`).
    pub(crate) at_most: bool,
}

/// The integer exponent the datapaths take for `n`.
fn datapath_exponent(n: Exponent) -> u32 {
    n.get().round().clamp(1.0, 1000.0) as u32
}

impl Costing {
    /// The costing of `target` (on `gpu`, a GPU target's generation, its vendor's current
    /// one if `None`) at `exponents`, and a note for the user where a tool is missing (the
    /// FPGA's, a GPU's compiler).
    pub(crate) fn new(
        target: Target,
        gpu: Option<Gpu>,
        exponents: &[Exponent],
    ) -> Result<(Self, Option<String>), String> {
        if let Some(gpu) = target.gpu(gpu)? {
            return Ok(match specula_isa::compiler_version(&gpu) {
                Ok(compiler) => (Costing::Gpu(gpu, GpuBasis::Compiled(compiler)), None),
                Err(missing @ IsaError::Missing { .. }) => (
                    Costing::Gpu(gpu, GpuBasis::Modelled),
                    Some(format!(
                        "{missing}; {} costs are the naga-IR model's instead of the compiler's",
                        gpu.id
                    )),
                ),
                Err(error) => return Err(error.to_string()),
            });
        }
        Ok(match target {
            Target::Cpu => (Costing::Measured(Vec::new()), None),
            Target::GpuNvidia | Target::GpuAmd | Target::GpuIntel => {
                unreachable!("a GPU target has a GPU")
            }
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
            Costing::Gpu(gpu, GpuBasis::Compiled(_)) => match gpu.vendor {
                Vendor::Nvidia => "evals/clock/SM (nvcc's SASS)",
                Vendor::Amd => "evals/clock/CU (ACO's ISA)",
                Vendor::Intel => "evals/clock/EU (IGC's ISA)",
            },
            Costing::Gpu(gpu, GpuBasis::Modelled) => match gpu.vendor {
                Vendor::Nvidia => "evals/clock/SM (modelled)",
                Vendor::Amd => "evals/clock/CU (modelled)",
                Vendor::Intel => "evals/clock/EU (modelled)",
            },
            Costing::Estimated(_) => "evals/clock per 1000 logic cells (estimated)",
            Costing::Synthesized(_) => "results/us per 1000 LUTs (synthesized, iCE40 HX8K)",
        }
    }

    /// On the FPGA, `lobe`'s point by its datapath's estimate, synthesizing nothing (`None`
    /// elsewhere, or where it has no datapath).
    pub(crate) fn estimated_point(&self, lobe: &Lobe, zone: Zone, max_error: f64) -> Option<Point> {
        match self {
            Costing::Estimated(hardware) | Costing::Synthesized(hardware) => {
                Costing::Estimated(hardware.clone())
                    .point(lobe, zone, max_error)
                    .ok()
                    .flatten()
            }
            _ => None,
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
                    aco_inverse_throughput: None,
                    at_most: false,
                })
            }
            Costing::Gpu(gpu, basis) => {
                let (rate, aco_inverse_throughput) = gpu_rate(*gpu, basis, lobe)?;
                Some(Point {
                    error: float_error(),
                    rate,
                    datapath: None,
                    spread: None,
                    aco_inverse_throughput,
                    at_most: false,
                })
            }
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
                    aco_inverse_throughput: None,
                    at_most: false,
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
pub(crate) fn synthesized_rate(
    synthesis: &specula_synth::Synthesis,
) -> (f64, Option<&'static str>) {
    match synthesis.logic_ns_per_result() {
        Some(lut_ns) => (1e6 / lut_ns, None),
        None => (0.0, Some(" (does not fit the iCE40 HX8K)")),
    }
}

/// Why a material's verdict refuses the FPGA.
pub const FPGA_MATERIAL_REFUSAL: &str = "a material verdict cannot target fpga: the fixed-point \
    datapaths take an integer n and a word length chosen for an error against t^n, which a \
    material's fit does not give; valid targets: cpu, gpu-nvidia, gpu-amd, gpu-intel";

/// `lobe`'s evaluations per clock per multiprocessor on `gpu`, by the GPU cost model over
/// the instructions of its exported shader (higher is cheaper): the fallback where the
/// vendor's compiler is missing.
pub fn modelled_rate(gpu: &Gpu, lobe: &Lobe) -> Result<f64, String> {
    let ops = specula_gpu::shader_ops::lobe_shader_ops(lobe)?;
    Ok(specula::gpu_cost::modelled(&ops, &gpu.rates).evals_per_clock)
}

/// `lobe`'s evaluations per clock per multiprocessor on `gpu` on `basis`, and on AMD, ACO's
/// estimated inverse throughput beyond the baseline kernel's.
fn gpu_rate(gpu: Gpu, basis: &GpuBasis, lobe: &Lobe) -> Result<(f64, Option<f64>), String> {
    match basis {
        GpuBasis::Compiled(_) => {
            let compiled =
                specula_isa::compile(lobe, gpu, Work::Lobe).map_err(|e| e.to_string())?;
            Ok((
                compiled.evals_per_clock().0,
                compiled.aco_inverse_throughput(),
            ))
        }
        GpuBasis::Modelled => Ok((modelled_rate(&gpu, lobe)?, None)),
    }
}

/// What `target`'s GPU costs are read off, in a sentence for the reader, where the target is
/// a GPU: the compiler and generation, or the model and why.
pub fn gpu_basis(target: Target, gpu: Option<Gpu>) -> Result<Option<String>, String> {
    let (costing, note) = Costing::new(target, gpu, &[])?;
    Ok(match costing {
        Costing::Gpu(gpu, GpuBasis::Compiled(compiler)) => Some(format!(
            "{} ({}): the machine code {compiler} writes for each lobe's kernel beyond a kernel \
             that only loads and stores (specula isa shows it), each class at its published \
             rate ({})",
            gpu.id,
            gpu.name,
            gpu.source_name()
        )),
        Costing::Gpu(gpu, GpuBasis::Modelled) => Some(format!(
            "{} ({}): the naga-IR model of the exported shader, each class at its published \
             rate ({}), because {}",
            gpu.id,
            gpu.name,
            gpu.source_name(),
            note.unwrap_or_default()
        )),
        _ => None,
    })
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
/// CPU, from the compiled machine code (or the model) on a GPU, the vendor's current
/// generation; the FPGA is refused ([`FPGA_MATERIAL_REFUSAL`]) before any costing starts
/// (costing it would run its sweeps).
pub fn lobe_rate(target: Target, lobe: &Lobe) -> Result<f64, String> {
    let target = material_target(target)?;
    match Costing::new(target, None, &[lobe.exponent()])?.0 {
        Costing::Measured(_) => Ok(crate::rates::kernel_rate(lobe)),
        Costing::Gpu(gpu, basis) => Ok(gpu_rate(gpu, &basis, lobe)?.0),
        Costing::Estimated(_) | Costing::Synthesized(_) => Err(FPGA_MATERIAL_REFUSAL.to_owned()),
    }
}

/// [`lobe_rate`] for each of `lobes`, their kernels compiled in one run of the compiler
/// where it is found (a compiler's process is most of a compile's time: a material's
/// verdict costs a dozen lobes, one by one a dozen processes).
pub fn lobe_rates(target: Target, lobes: &[Lobe]) -> Result<Vec<f64>, String> {
    let target = material_target(target)?;
    let (costing, _) = Costing::new(target, None, &[])?;
    if let Costing::Gpu(gpu, GpuBasis::Compiled(_)) = &costing {
        // A failure is left for the lobes' own compiles, which name the one that fails.
        if let Ok(compiled) = specula_isa::compile_all(lobes, *gpu, Work::Lobe) {
            return Ok(compiled.iter().map(|c| c.evals_per_clock().0).collect());
        }
    }
    lobes.iter().map(|lobe| lobe_rate(target, lobe)).collect()
}

/// The unit of [`lobe_rate`] on `target` (empty for the FPGA, which it refuses).
#[must_use]
pub fn rate_unit(target: Target) -> &'static str {
    match target {
        // Costing the FPGA would run its sweeps; material verdicts refuse it anyway.
        Target::Fpga => "",
        _ => Costing::new(target, None, &[]).map_or("", |(costing, _)| costing.unit()),
    }
}

/// Compiles every lobe the ranking will cost on a GPU in one run of the compiler, so that the
/// ranking finds each in the cache (a compiler's process is most of a compile's time, and a
/// range needs dozens of kernels). A failure is left for the ranking, which compiles the lobes
/// one by one and reports the one that fails.
pub(crate) fn compile_ahead(costing: &Costing, lobes: &[LobeKind], exponents: &[Exponent]) {
    let Costing::Gpu(gpu, GpuBasis::Compiled(_)) = costing else {
        return;
    };
    let all: Vec<Lobe> = lobes
        .iter()
        .flat_map(|&kind| exponents.iter().map(move |&n| Lobe::new(kind, n)))
        .collect();
    let _ = specula_isa::compile_all(&all, *gpu, Work::Lobe);
}
