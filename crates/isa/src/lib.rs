//! # specula-isa: what the GPU vendors' compilers make of a lobe
//!
//! Every GPU figure specula gives is read off machine code a vendor's production compiler
//! wrote, not off a model of the shader: a lobe's kernel (from its one recorded expression:
//! CUDA C and OpenCL C written by [`specula_targets::compute`], SPIR-V by
//! [`specula_gpu::export::compute_kernel_spirv`]) goes through
//! - NVIDIA's `nvcc -use_fast_math` and `nvdisasm` (SASS, registers from `ptxas -v`),
//! - AMD's ACO in Mesa's RADV on a null device (assembly, registers, ACO's latency and inverse
//!   throughput estimates),
//! - Intel's IGC through `ocloc` (assembly from IGC's dump),
//!
//! none of which needs the GPU. The instructions are classed ([`listing`]) as the GPU cost
//! model classes them; a kernel that only loads and stores is compiled beside every kernel,
//! and what the lobe's kernel has beyond it is the lobe's ([`Compiled::counts`]), weighed by
//! the generation's published rates ([`specula::gpus`]). Results are cached like the syntheses
//! (`$SPECULA_CACHE_DIR/isa`), keyed by the source and the compiler's version.

pub mod comparison;
pub mod listing;

mod amd;
mod intel;
mod nvidia;
mod tools;

use serde::{Deserialize, Serialize};
use specula::Lobe;
pub use specula_synth::cache::Cache;
use specula_synth::cache::{key, key_of_bytes};
use thiserror::Error;

pub use comparison::{compare, model_against_compilers, Against, Comparison, KernelView};
pub use listing::{Class, Counts, Instruction};
pub use specula::gpus::{Gpu, Rates, Vendor};
pub use specula_targets::compute::Work;

/// Why a lobe could not be compiled for a GPU.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum IsaError {
    /// A compiler (or what runs it) is not installed.
    #[error("{tool} is not installed: {install}")]
    Missing {
        /// What is missing.
        tool: String,
        /// How to install it.
        install: String,
    },
    /// A compiler ran and failed.
    #[error("{what} failed: {message}")]
    Failed {
        /// What ran.
        what: String,
        /// Its message.
        message: String,
    },
    /// A compiler's output could not be read.
    #[error("cannot read {0}")]
    Unreadable(String),
    /// The source could not be written.
    #[error("the kernel's source: {0}")]
    Source(String),
    /// A scratch file could not be written.
    #[error("a scratch file: {0}")]
    Scratch(String),
}

impl IsaError {
    fn scratch(error: std::io::Error) -> Self {
        IsaError::Scratch(error.to_string())
    }
}

/// One of the compiler's own estimates (ACO's latency, inverse throughput, ...).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// What it is.
    pub name: String,
    /// Its value.
    pub value: f64,
}

/// A compiled kernel: its machine code, registers and the compiler's estimates.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Listing {
    /// The compiler, its version and what it was told.
    pub compiler: String,
    /// The instructions, in order (what never runs, such as alignment padding, left out).
    pub instructions: Vec<Instruction>,
    /// Vector registers per thread (NVIDIA's registers, AMD's VGPRs), where the compiler says.
    pub registers: Option<u32>,
    /// The compiler's own estimates.
    pub estimates: Vec<Estimate>,
}

impl Listing {
    /// The counts of its instructions by class.
    #[must_use]
    pub fn counts(&self) -> Counts {
        Counts::of(&self.instructions)
    }

    /// The estimate named `name`.
    #[must_use]
    pub fn estimate(&self, name: &str) -> Option<f64> {
        self.estimates
            .iter()
            .find(|e| e.name.starts_with(name))
            .map(|e| e.value)
    }
}

/// What a compiler returned, as it wrote it: what the cache keeps, so that reading it (the
/// classes of [`listing`]) can change without compiling again.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct Disassembly {
    compiler: String,
    /// The disassembly's text.
    text: String,
    /// The kernel's SIMD width (Intel), wave size (AMD) or warp size (NVIDIA).
    simd: u32,
    registers: Option<u32>,
    estimates: Vec<Estimate>,
}

impl Disassembly {
    /// Its instructions read and classed.
    fn listing(self, vendor: Vendor) -> Listing {
        let instructions = match vendor {
            Vendor::Nvidia => nvidia::executed(&self.text),
            Vendor::Amd => listing::amd_listing(&self.text, self.simd),
            Vendor::Intel => self
                .text
                .lines()
                .filter_map(|line| listing::instruction(vendor, line, self.simd))
                .collect(),
        };
        Listing {
            compiler: self.compiler,
            instructions,
            registers: self.registers,
            estimates: self.estimates,
        }
    }
}

/// The source a vendor's compiler is given.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// CUDA C or OpenCL C.
    Text(String),
    /// SPIR-V, with the WGSL it was written from (what a reader is shown).
    SpirV {
        /// The module.
        words: Vec<u32>,
        /// Its WGSL.
        wgsl: String,
    },
}

impl Source {
    /// What a reader is shown of it.
    #[must_use]
    pub fn text(&self) -> &str {
        match self {
            Source::Text(text) => text,
            Source::SpirV { wgsl, .. } => wgsl,
        }
    }
}

/// The source `vendor`'s compiler is given for `lobe`'s kernel computing `work`.
pub fn source(lobe: &Lobe, vendor: Vendor, work: Work) -> Result<Source, IsaError> {
    use specula_targets::compute::{kernel, ComputeLanguage};
    Ok(match vendor {
        Vendor::Nvidia => Source::Text(kernel(lobe, ComputeLanguage::Cuda, work)),
        Vendor::Intel => Source::Text(kernel(lobe, ComputeLanguage::OpenCl, work)),
        Vendor::Amd => Source::SpirV {
            words: specula_gpu::export::compute_kernel_spirv(lobe, work)
                .map_err(|e| IsaError::Source(e.to_string()))?,
            wgsl: specula_gpu::export::compute_kernel_wgsl(lobe, work),
        },
    })
}

/// A lobe's kernel and the baseline kernel, compiled for one GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct Compiled {
    /// The GPU.
    pub gpu: Gpu,
    /// What the kernel computes.
    pub work: Work,
    /// The source the compiler was given.
    pub source: Source,
    /// The kernel's machine code.
    pub kernel: Listing,
    /// The baseline's: the same loads and stores, no lobe.
    pub baseline: Listing,
}

impl Compiled {
    /// What the kernel executes beyond the baseline, class by class: the lobe's (or the
    /// specular term's) instructions.
    #[must_use]
    pub fn counts(&self) -> Counts {
        self.kernel.counts().beyond(&self.baseline.counts())
    }

    /// Evaluations per clock per multiprocessor of what [`Compiled::counts`] holds, at the
    /// generation's rates, and what bounds it.
    #[must_use]
    pub fn evals_per_clock(&self) -> (f64, &'static str) {
        self.counts().evals_per_clock(&self.gpu.rates)
    }

    /// ACO's estimated inverse throughput of the kernel beyond the baseline's, in cycles per
    /// wave (AMD only).
    #[must_use]
    pub fn aco_inverse_throughput(&self) -> Option<f64> {
        let name = "ACO's estimated inverse throughput";
        Some(self.kernel.estimate(name)? - self.baseline.estimate(name)?)
    }
}

/// The compiler's version for `gpu`, which keys the cache.
pub fn compiler_version(gpu: &Gpu) -> Result<String, IsaError> {
    match gpu.vendor {
        Vendor::Nvidia => nvidia::version(),
        Vendor::Amd => amd::version(gpu),
        Vendor::Intel => intel::version(),
    }
}

/// `lobe`'s kernel computing `work` and the baseline kernel, compiled for `gpu` (cached).
pub fn compile(lobe: &Lobe, gpu: Gpu, work: Work) -> Result<Compiled, IsaError> {
    let mut compiled = compile_all(std::slice::from_ref(lobe), gpu, work)?;
    Ok(compiled.remove(0))
}

/// Every one of `lobes`' kernels computing `work`, and the baseline, compiled for `gpu`:
/// what the cache lacks in one run of the compiler (its process is most of a compile's time),
/// each kernel still cached on its own.
pub fn compile_all(lobes: &[Lobe], gpu: Gpu, work: Work) -> Result<Vec<Compiled>, IsaError> {
    compile_all_in(lobes, gpu, work, Cache::default_for("isa").as_ref())
}

/// [`compile_all`] with the results kept in `cache` (none: every kernel compiled).
pub fn compile_all_in(
    lobes: &[Lobe],
    gpu: Gpu,
    work: Work,
    cache: Option<&Cache>,
) -> Result<Vec<Compiled>, IsaError> {
    let Some(first) = lobes.first() else {
        return Ok(Vec::new());
    };
    let version = compiler_version(&gpu)?;
    let mut sources = lobes
        .iter()
        .map(|lobe| source(lobe, gpu.vendor, work))
        .collect::<Result<Vec<_>, _>>()?;
    // The baseline kernel is the same for every lobe.
    sources.push(source(first, gpu.vendor, Work::Baseline)?);
    let keys: Vec<String> = sources
        .iter()
        .map(|s| cache_key(s, &gpu, &version))
        .collect();
    let mut found: Vec<Option<Disassembly>> = keys
        .iter()
        .map(|key| cache.and_then(|cache| cache.load::<Disassembly>(key)))
        .collect();
    // What the cache lacks, each key once.
    let mut missing: Vec<usize> = Vec::new();
    for (k, entry) in found.iter().enumerate() {
        if entry.is_none() && !missing.iter().any(|&m| keys[m] == keys[k]) {
            missing.push(k);
        }
    }
    if !missing.is_empty() {
        // One compile of a GPU's kernels at a time in this process: a caller beside this one
        // (the report's sections, a design's bounds) waits, then finds them in the cache,
        // rather than compiling the same kernels again beside it. No rayon work runs under
        // the lock, so a waiting pool thread cannot hold what the holder needs.
        let _compiling = compile_lock(&gpu);
        if let Some(cache) = cache {
            for &k in &missing {
                found[k] = cache.load::<Disassembly>(&keys[k]);
            }
            missing.retain(|&k| found[k].is_none());
        }
        let compiled = compile_in_parallel(
            &missing.iter().map(|&k| &sources[k]).collect::<Vec<_>>(),
            &gpu,
        )?;
        for (&k, disassembly) in missing.iter().zip(compiled) {
            if let Some(cache) = cache {
                // A cache that cannot be written costs the next run a compile, nothing more.
                let _ = cache.store(&keys[k], &disassembly);
            }
            for (slot, key) in found.iter_mut().zip(&keys) {
                if slot.is_none() && *key == keys[k] {
                    *slot = Some(disassembly.clone());
                }
            }
        }
    }
    let mut listings = found
        .into_iter()
        .map(|d| d.map(|d| d.listing(gpu.vendor)))
        .collect::<Option<Vec<Listing>>>()
        .ok_or_else(|| IsaError::Unreadable("a kernel the compiler was given".to_owned()))?;
    let baseline = listings
        .pop()
        .unwrap_or_else(|| unreachable!("the baseline was pushed"));
    sources.pop();
    Ok(listings
        .into_iter()
        .zip(sources)
        .map(|(kernel, source)| Compiled {
            gpu,
            work,
            source,
            kernel,
            baseline: baseline.clone(),
        })
        .collect())
}

/// The cache key of `source` compiled for `gpu` by the compiler of `version`.
fn cache_key(source: &Source, gpu: &Gpu, version: &str) -> String {
    let flags = match gpu.vendor {
        Vendor::Nvidia => nvidia::FLAGS.join(" "),
        // llvm-mca's estimate is kept with ACO's listing: whether it ran keys the entry.
        Vendor::Amd => amd::llvm_mca().map_or_else(String::new, |(_, version)| version.clone()),
        Vendor::Intel => intel::OPTIONS.to_owned(),
    };
    match source {
        Source::Text(text) => key(&["isa 1", gpu.id, gpu.compiler_target, version, &flags, text]),
        Source::SpirV { words, .. } => {
            let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
            key_of_bytes(&[
                b"isa 1",
                gpu.id.as_bytes(),
                gpu.compiler_target.as_bytes(),
                version.as_bytes(),
                flags.as_bytes(),
                &bytes,
            ])
        }
    }
}

/// `sources`, all of `gpu`'s vendor, compiled in one run.
/// The in-process lock on compiling for `gpu`'s generation.
fn compile_lock(gpu: &Gpu) -> std::sync::MutexGuard<'static, ()> {
    static LOCKS: std::sync::Mutex<Vec<(&'static str, &'static std::sync::Mutex<()>)>> =
        std::sync::Mutex::new(Vec::new());
    let lock = {
        let mut locks = LOCKS
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        match locks.iter().find(|(id, _)| *id == gpu.id) {
            Some((_, lock)) => *lock,
            None => {
                // One per generation for the process's life: a dozen at most.
                let lock: &'static std::sync::Mutex<()> =
                    Box::leak(Box::new(std::sync::Mutex::new(())));
                locks.push((gpu.id, lock));
                lock
            }
        }
    };
    lock.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Kernels per compiler process below which a batch is not split: a process's start-up is
/// most of a small batch's time.
const KERNELS_PER_PROCESS: usize = 24;

/// [`compile_sources`] split across the machine's cores, one compiler process a share (each
/// compiler compiles its kernels one after the other: a report's first run hands it hundreds).
fn compile_in_parallel(sources: &[&Source], gpu: &Gpu) -> Result<Vec<Disassembly>, IsaError> {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    let processes = sources.len().div_ceil(KERNELS_PER_PROCESS).clamp(1, cores);
    if sources.is_empty() {
        return Ok(Vec::new());
    }
    if processes == 1 {
        return compile_sources(sources, gpu);
    }
    let share = sources.len().div_ceil(processes);
    let results: Vec<Result<Vec<Disassembly>, IsaError>> = std::thread::scope(|scope| {
        let running: Vec<_> = sources
            .chunks(share)
            .map(|chunk| scope.spawn(move || compile_sources(chunk, gpu)))
            .collect();
        running
            .into_iter()
            .map(|process| {
                process.join().unwrap_or_else(|_| {
                    Err(IsaError::Failed {
                        what: "a compiler's run".to_owned(),
                        message: "its thread panicked".to_owned(),
                    })
                })
            })
            .collect()
    });
    let mut all = Vec::with_capacity(sources.len());
    for result in results {
        all.extend(result?);
    }
    Ok(all)
}

fn compile_sources(sources: &[&Source], gpu: &Gpu) -> Result<Vec<Disassembly>, IsaError> {
    let texts = || {
        sources
            .iter()
            .map(|source| match source {
                Source::Text(text) => Ok(text.as_str()),
                Source::SpirV { .. } => Err(IsaError::Source("C source expected".to_owned())),
            })
            .collect::<Result<Vec<&str>, IsaError>>()
    };
    match gpu.vendor {
        Vendor::Nvidia => nvidia::compile(&texts()?, gpu),
        Vendor::Intel => intel::compile(&texts()?, gpu),
        Vendor::Amd => {
            let modules = sources
                .iter()
                .map(|source| match source {
                    Source::SpirV { words, .. } => Ok(words.as_slice()),
                    Source::Text(_) => Err(IsaError::Source("SPIR-V expected".to_owned())),
                })
                .collect::<Result<Vec<&[u32]>, IsaError>>()?;
            amd::compile(&modules, specula_targets::compute::KERNEL, gpu)
        }
    }
}

/// Runs `lobe`'s SPIR-V kernel computing `work` on Mesa's lavapipe over `inputs`
/// ([`Work::inputs_per_thread`] floats a thread): the module ACO compiles, computing on the
/// CPU (its test that the source computes the lobe).
pub fn run_spirv_on_lavapipe(
    lobe: &Lobe,
    work: Work,
    inputs: &[f32],
) -> Result<Vec<f32>, IsaError> {
    let Source::SpirV { words, .. } = source(lobe, Vendor::Amd, work)? else {
        unreachable!("AMD's source is SPIR-V")
    };
    amd::run_on_lavapipe(
        &words,
        specula_targets::compute::KERNEL,
        inputs,
        work.inputs_per_thread(),
    )
}
