//! NVIDIA: the CUDA C kernel through `nvcc -use_fast_math` (NVVM, then `ptxas`) to a cubin,
//! SASS by `nvdisasm`, registers by `ptxas -v`.
//!
//! Fast math is what a shader gets: without it `powf` is a library routine of a hundred
//! instructions and more, where GLSL's `pow` is `lg2`, a multiply and `ex2` (`-use_fast_math`
//! makes it `__powf`, and `exp2f`, `log2f`, `sqrtf` the `.approx` instructions).

use std::process::Command;
use std::sync::OnceLock;

use crate::gpus::{Gpu, Vendor};
use crate::listing::{instruction, Instruction};
use crate::tools;
use crate::{Disassembly, IsaError};

/// What `nvcc` is given besides the source.
pub const FLAGS: [&str; 4] = ["-use_fast_math", "-cubin", "-Xptxas", "-v"];

/// `nvcc --version`'s release line (`release 13.5, V13.5.37`), asked once per process.
pub fn version() -> Result<String, IsaError> {
    static VERSION: OnceLock<String> = OnceLock::new();
    if let Some(version) = VERSION.get() {
        return Ok(version.clone());
    }
    let [nvcc, _] = tools::cuda()?;
    let mut command = Command::new(&nvcc);
    command.arg("--version");
    let output = tools::run(command, "nvcc --version")?;
    let text = String::from_utf8_lossy(&output.stdout);
    let release = text
        .lines()
        .find_map(|line| line.split_once("release "))
        .map_or_else(
            || text.trim().to_owned(),
            |(_, release)| release.trim().to_owned(),
        );
    Ok(VERSION.get_or_init(|| format!("nvcc {release}")).clone())
}

/// The SASS `nvcc` makes of the CUDA C `source` for `gpu`.
pub fn compile(source: &str, gpu: &Gpu) -> Result<Disassembly, IsaError> {
    let [nvcc, nvdisasm] = tools::cuda()?;
    let scratch = specula_temporaries::dir("isa-nvidia-").map_err(IsaError::scratch)?;
    let cu = scratch.path().join("kernel.cu");
    let cubin = scratch.path().join("kernel.cubin");
    std::fs::write(&cu, source).map_err(IsaError::scratch)?;
    let mut command = Command::new(&nvcc);
    command
        .arg(format!("-arch={}", gpu.compiler_target))
        .args(FLAGS)
        .arg("-o")
        .arg(&cubin)
        .arg(&cu)
        .current_dir(scratch.path());
    let compiled = tools::run(command, "nvcc")?;
    let report = String::from_utf8_lossy(&compiled.stderr).into_owned()
        + &String::from_utf8_lossy(&compiled.stdout);
    // `ptxas info    : Used 10 registers, used 0 barriers, ...`
    let registers = report.lines().find_map(|line| {
        let (_, after) = line.split_once("Used ")?;
        after.split_whitespace().next()?.parse().ok()
    });
    let mut command = Command::new(&nvdisasm);
    command.arg("-c").arg(&cubin);
    let disassembled = tools::run(command, "nvdisasm")?;
    let text = String::from_utf8_lossy(&disassembled.stdout);
    Ok(Disassembly {
        compiler: format!("{} ({}, {})", version()?, gpu.compiler_target, FLAGS[0]),
        text: text.into_owned(),
        simd: 32,
        registers,
        estimates: Vec::new(),
    })
}

/// The instructions up to the last `EXIT`: what follows it (a branch to itself, `NOP`s) pads
/// the function to its alignment and never runs.
pub(crate) fn executed(disassembly: &str) -> Vec<Instruction> {
    let mut instructions: Vec<Instruction> = disassembly
        .lines()
        .filter_map(|line| instruction(Vendor::Nvidia, line, 32))
        .collect();
    if let Some(last_exit) = instructions
        .iter()
        .rposition(|instruction| instruction.mnemonic == "EXIT")
    {
        instructions.truncate(last_exit + 1);
    }
    instructions
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_padding_after_the_last_exit_is_not_counted() {
        let text = "
        /*00b0*/                   MUFU.EX2 R7, R0 ;
        /*00c0*/                   STG.E [R4.64], R7 ;
.L_x_1:
        /*00d0*/                   EXIT ;
.L_x_0:
        /*00e0*/                   BRA `(.L_x_0);
        /*00f0*/                   NOP;
";
        let mnemonics: Vec<_> = executed(text).into_iter().map(|i| i.mnemonic).collect();
        assert_eq!(mnemonics, ["MUFU.EX2", "STG.E", "EXIT"]);
    }
}
