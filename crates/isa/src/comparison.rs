//! A lobe's machine code beside `pow`'s on one GPU: what `specula isa` prints and the
//! explorer shows, one description for every face.

use serde::Serialize;
use specula::{Lobe, LobeKind};

use crate::listing::Class;
use crate::{compile, Compiled, Gpu, IsaError, Work};

/// One kernel, as a reader is shown it.
#[derive(Clone, Debug, Serialize)]
pub struct KernelView {
    /// The lobe's id.
    pub lobe: String,
    /// The compiler, its version and what it was told.
    pub compiler: String,
    /// What the kernel executes beyond the baseline (loads and stores alone), per class.
    pub counts: Vec<(&'static str, i64)>,
    /// Those instructions in all.
    pub total: i64,
    /// The instructions the baseline kernel has (what `counts` leaves out).
    pub baseline_total: i64,
    /// Vector registers per thread, where the compiler says.
    pub registers: Option<u32>,
    /// The compiler's own estimates, where it makes them (ACO's latency and inverse
    /// throughput, of the whole kernel).
    pub estimates: Vec<(String, f64)>,
    /// Evaluations per clock per multiprocessor of the counted instructions at the
    /// generation's rates.
    pub evals_per_clock: f64,
    /// What bounds that rate.
    pub bound: &'static str,
    /// The whole kernel's machine code: each instruction's class and text.
    pub listing: Vec<(&'static str, String)>,
    /// The baseline kernel's, what `counts` is beyond.
    pub baseline_listing: Vec<(&'static str, String)>,
    /// The source the compiler was given (CUDA C, OpenCL C, or the WGSL the SPIR-V was
    /// written from).
    pub source: String,
}

impl KernelView {
    fn of(compiled: &Compiled, lobe: &Lobe) -> KernelView {
        let counts = compiled.counts();
        let (evals_per_clock, bound) = compiled.evals_per_clock();
        KernelView {
            lobe: lobe.kind().to_string(),
            compiler: compiled.kernel.compiler.clone(),
            counts: Class::ALL
                .into_iter()
                .filter(|&class| class != Class::Memory)
                .map(|class| (class.id(), counts.get(class)))
                .collect(),
            total: counts.total(),
            baseline_total: compiled.baseline.counts().total(),
            registers: compiled.kernel.registers,
            estimates: compiled
                .kernel
                .estimates
                .iter()
                .map(|e| (e.name.clone(), e.value))
                .collect(),
            evals_per_clock,
            bound,
            listing: compiled
                .kernel
                .instructions
                .iter()
                .map(|i| (i.class.id(), i.text.clone()))
                .collect(),
            baseline_listing: compiled
                .baseline
                .instructions
                .iter()
                .map(|i| (i.class.id(), i.text.clone()))
                .collect(),
            source: compiled.source.text().to_owned(),
        }
    }
}

/// A lobe beside `pow` on one GPU.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The GPU.
    pub gpu: Gpu,
    /// The exponent.
    pub n: f64,
    /// What the kernels compute: `lobe`, or `shading` (the specular term).
    pub context: String,
    /// The lobe's kernel.
    pub lobe: KernelView,
    /// `pow`'s kernel at the same exponent and context.
    pub pow: KernelView,
    /// The lobe's evaluations per clock over `pow`'s.
    pub throughput_vs_pow: f64,
    /// ACO's estimated inverse throughput beyond the baseline, the lobe's over `pow`'s
    /// (cycles per wave; AMD only).
    pub aco_inverse_throughput: Option<[f64; 2]>,
    /// In the shading context: the lobe's own instructions (compiled alone) over the specular
    /// term's.
    pub lobe_share: Option<f64>,
}

/// `lobe` and `pow` at its exponent compiled for `gpu` computing `work`.
pub fn compare(lobe: &Lobe, gpu: Gpu, work: Work) -> Result<Comparison, IsaError> {
    let pow = Lobe::new(LobeKind::Pow, lobe.exponent());
    let compiled = compile(lobe, gpu, work)?;
    let compiled_pow = compile(&pow, gpu, work)?;
    let lobe_share = match work {
        Work::Shading(..) => {
            let alone = compile(lobe, gpu, Work::Lobe)?.counts().total();
            let whole = compiled.counts().total();
            (whole > 0).then(|| alone as f64 / whole as f64)
        }
        Work::Lobe | Work::Baseline => None,
    };
    let view = KernelView::of(&compiled, lobe);
    let pow_view = KernelView::of(&compiled_pow, &pow);
    Ok(Comparison {
        gpu,
        n: lobe.exponent().get(),
        context: match work {
            Work::Shading(geometry, normalisation) => format!(
                "shading (geometry {}, normalisation {})",
                geometry.id(),
                normalisation.id()
            ),
            _ => "lobe".to_owned(),
        },
        throughput_vs_pow: view.evals_per_clock / pow_view.evals_per_clock,
        aco_inverse_throughput: compiled
            .aco_inverse_throughput()
            .zip(compiled_pow.aco_inverse_throughput())
            .map(|(a, b)| [a, b]),
        lobe: view,
        pow: pow_view,
        lobe_share,
    })
}

/// One lobe on one GPU: the compiler's rate and the naga-IR model's, each over `pow`'s on the
/// same basis, and the transcendental instructions each counts.
#[derive(Clone, Debug, Serialize)]
pub struct Against {
    /// The GPU's id.
    pub gpu: &'static str,
    /// The compiled kernel's evaluations per clock over `pow`'s.
    pub compiled_vs_pow: f64,
    /// The model's over `pow`'s.
    pub modelled_vs_pow: f64,
    /// Transcendental instructions per work item in the compiled kernel (beyond the baseline).
    pub compiled_transcendentals: f64,
    /// Transcendental instructions the model counts (`acos` expanded).
    pub modelled_transcendentals: u32,
    /// Instructions per work item in the compiled kernel beyond the baseline, every class
    /// that issues.
    pub compiled_instructions: f64,
    /// Instructions the model counts.
    pub modelled_instructions: u32,
}

/// Every one of `lobes` at `n` on every GPU of `gpus`: the compilers beside the model
/// (docs/gpu.md's table). Each GPU's kernels are compiled in one run.
pub fn model_against_compilers(
    lobes: &[Lobe],
    gpus: &[Gpu],
) -> Result<Vec<(String, Vec<Against>)>, IsaError> {
    let modelled = |lobe: &Lobe| {
        specula_gpu::shader_ops::lobe_shader_ops(lobe)
            .map_err(IsaError::Source)
            .map(|ops| (ops, ops.expanded()))
    };
    let mut rows: Vec<(String, Vec<Against>)> = lobes
        .iter()
        .map(|l| (l.kind().to_string(), Vec::new()))
        .collect();
    for &gpu in gpus {
        let Some(first) = lobes.first() else { break };
        let pow = Lobe::new(LobeKind::Pow, first.exponent());
        let mut all = lobes.to_vec();
        all.push(pow);
        let compiled = crate::compile_all(&all, gpu, Work::Lobe)?;
        let pow_compiled = compiled
            .last()
            .map(|c| c.evals_per_clock().0)
            .unwrap_or(f64::NAN);
        let (pow_ops, _) = modelled(&pow)?;
        let pow_model = specula::gpu_cost::modelled(&pow_ops, &gpu.rates).evals_per_clock;
        for ((lobe, compiled), row) in lobes.iter().zip(&compiled).zip(&mut rows) {
            let (ops, expanded) = modelled(lobe)?;
            let counts = compiled.counts();
            let at = |class: Class| {
                counts.per_item[Class::ALL.iter().position(|&c| c == class).unwrap_or(0)]
            };
            row.1.push(Against {
                gpu: gpu.id,
                compiled_vs_pow: compiled.evals_per_clock().0 / pow_compiled,
                modelled_vs_pow: specula::gpu_cost::modelled(&ops, &gpu.rates).evals_per_clock
                    / pow_model,
                compiled_transcendentals: at(Class::Transcendental),
                modelled_transcendentals: expanded.transcendental,
                compiled_instructions: Class::ALL
                    .iter()
                    .filter(|&&c| !matches!(c, Class::Scalar | Class::Memory | Class::Other))
                    .map(|&c| at(c))
                    .sum(),
                modelled_instructions: expanded.total(),
            });
        }
    }
    Ok(rows)
}
