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

use crate::gpus::Gpu;
use crate::tools;
use crate::{Disassembly, IsaError};

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
    Ok(VERSION
        .get_or_init(|| format!("ocloc (Intel compute runtime {})", version.trim()))
        .clone())
}

/// The assembly IGC makes of the OpenCL C `source` for `gpu`.
pub fn compile(source: &str, gpu: &Gpu) -> Result<Disassembly, IsaError> {
    let ocloc = tools::ocloc()?;
    let scratch = specula_temporaries::dir("isa-intel-").map_err(IsaError::scratch)?;
    let cl = scratch.path().join("kernel.cl");
    let dump = scratch.path().join("dump");
    std::fs::write(&cl, source).map_err(IsaError::scratch)?;
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
    let (simd, assembly) = widest_dump(&dump)?;
    Ok(Disassembly {
        compiler: format!(
            "IGC in {} ({}, {OPTIONS}, SIMD{simd})",
            version()?,
            gpu.compiler_target
        ),
        text: assembly,
        simd,
        registers: None,
        estimates: Vec::new(),
    })
}

/// The dump of the widest SIMD the kernel was compiled at (`..._simd32_entry_0001.asm`), and
/// that width.
fn widest_dump(dump: &Path) -> Result<(u32, String), IsaError> {
    let entries = std::fs::read_dir(dump)
        .map_err(|_| IsaError::Unreadable("IGC wrote no shader dump".to_owned()))?;
    let widest = entries
        .flatten()
        .filter_map(|entry| {
            let name = entry.file_name().into_string().ok()?;
            let simd: u32 = name
                .strip_suffix(".asm")?
                .split("_simd")
                .nth(1)?
                .split('_')
                .next()?
                .parse()
                .ok()?;
            Some((simd, entry.path()))
        })
        .max_by_key(|(simd, _)| *simd)
        .ok_or_else(|| IsaError::Unreadable("IGC's dump holds no kernel assembly".to_owned()))?;
    let text = std::fs::read_to_string(&widest.1).map_err(IsaError::scratch)?;
    Ok((widest.0, text))
}
