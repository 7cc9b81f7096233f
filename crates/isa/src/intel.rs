//! Intel: the OpenCL C kernel through `ocloc` (the Intel Graphics Compiler, IGC) for the
//! device `ocloc -device` names; the assembly from IGC's own dump (`IGC_ShaderDumpEnable`),
//! the SIMD width it compiled at from the dump's name.
//!
//! The source spells GLSL's relaxed built-ins as OpenCL's `native_` functions and is compiled
//! with `-cl-mad-enable`, not `-cl-fast-relaxed-math`: IGC 1.0.12504 (Debian 12's) rewrites a
//! `pow` of a whole-number constant exponent under fast math to `llvm.powi`, which its code
//! generator then drops (the kernel stores a register nothing wrote; docs/gpu.md).

use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

use crate::tools;
use crate::{Disassembly, IsaError};
use specula::gpus::Gpu;

/// What `ocloc` is given as the kernel's build options.
pub const OPTIONS: &str = "-cl-mad-enable";

/// The driver's version (`ocloc query OCL_DRIVER_VERSION`), asked once per process.
pub fn version() -> Result<String, IsaError> {
    static VERSION: OnceLock<String> = OnceLock::new();
    if let Some(version) = VERSION.get() {
        return Ok(version.clone());
    }
    let ocloc = tools::ocloc()?;
    let scratch = specula_temporaries::dir("isa-intel-").map_err(IsaError::scratch)?;
    let mut command = Command::new(&ocloc);
    command
        .args(["query", "OCL_DRIVER_VERSION"])
        .current_dir(scratch.path());
    tools::run(command, "ocloc query")?;
    let version = std::fs::read_to_string(scratch.path().join("OCL_DRIVER_VERSION"))
        .map_err(|_| IsaError::Unreadable("ocloc's OCL_DRIVER_VERSION".to_owned()))?;
    let version = version.trim_matches(|c: char| c.is_whitespace() || c == '\0');
    Ok(VERSION
        .get_or_init(|| format!("IGC in ocloc (Intel compute runtime {version})"))
        .clone())
}

/// The assembly IGC makes of each OpenCL C kernel of `sources` for `gpu`, in one run.
pub fn compile(sources: &[&str], gpu: &Gpu) -> Result<Vec<Disassembly>, IsaError> {
    let ocloc = tools::ocloc()?;
    let scratch = specula_temporaries::dir("isa-intel-").map_err(IsaError::scratch)?;
    let cl = scratch.path().join("kernels.cl");
    let dump = scratch.path().join("dump");
    let combined: String = sources
        .iter()
        .enumerate()
        .map(|(k, source)| crate::nvidia::renamed(source, k))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&cl, combined).map_err(IsaError::scratch)?;
    let mut command = Command::new(&ocloc);
    command
        .args(["compile", "-q", "-file"])
        .arg(&cl)
        .args([
            "-device",
            gpu.compiler_target,
            "-options",
            OPTIONS,
            "-out_dir",
        ])
        .arg(scratch.path().join("out"))
        .env("IGC_ShaderDumpEnable", "1")
        .env("IGC_DumpToCustomDir", &dump)
        .current_dir(scratch.path());
    tools::run(command, "ocloc")?;
    let dumps = kernel_dumps(&dump)?;
    let compiler = format!("{} ({}, {OPTIONS}", version()?, gpu.compiler_target);
    (0..sources.len())
        .map(|k| {
            let name = format!("specula{k}_evaluate");
            let (simd, text) = dumps
                .iter()
                .filter(|(kernel, _, _)| *kernel == name)
                .max_by_key(|(_, simd, _)| *simd)
                .map(|(_, simd, text)| (*simd, text.clone()))
                .ok_or_else(|| IsaError::Unreadable(format!("IGC's dump of {name}")))?;
            Ok(Disassembly {
                compiler: format!("{compiler}, SIMD{simd})"),
                // Named as it would be compiled alone.
                text: text.replace(&format!("specula{k}_"), "specula_"),
                simd,
                registers: None,
                estimates: Vec::new(),
            })
        })
        .collect()
}

/// Every kernel assembly in IGC's dump (`..._simd32_entry_0001.asm`): its kernel's name (the
/// `//.kernel NAME` line), its SIMD width and its text.
fn kernel_dumps(dump: &Path) -> Result<Vec<(String, u32, String)>, IsaError> {
    let entries = std::fs::read_dir(dump)
        .map_err(|_| IsaError::Unreadable("IGC wrote no shader dump".to_owned()))?;
    let mut kernels = Vec::new();
    for entry in entries.flatten() {
        let Ok(name) = entry.file_name().into_string() else {
            continue;
        };
        let Some(simd) = name
            .strip_suffix(".asm")
            .and_then(|stem| stem.split("_simd").nth(1))
            .and_then(|rest| rest.split('_').next())
            .and_then(|width| width.parse::<u32>().ok())
        else {
            continue;
        };
        let text = std::fs::read_to_string(entry.path()).map_err(IsaError::scratch)?;
        let kernel = text
            .lines()
            .find_map(|line| line.strip_prefix("//.kernel "))
            .map(|name| name.trim().to_owned())
            .ok_or_else(|| IsaError::Unreadable(format!("the kernel's name in {name}")))?;
        kernels.push((kernel, simd, text));
    }
    if kernels.is_empty() {
        return Err(IsaError::Unreadable(
            "IGC's dump holds no kernel assembly".to_owned(),
        ));
    }
    Ok(kernels)
}
