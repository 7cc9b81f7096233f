//! NVIDIA: the CUDA C kernel through `nvcc -use_fast_math` (NVVM, then `ptxas`) to a cubin,
//! SASS by `nvdisasm`, registers by `ptxas -v`.
//!
//! Fast math is what a shader gets: without it `powf` is a library routine of a hundred
//! instructions and more, where GLSL's `pow` is `lg2`, a multiply and `ex2` (`-use_fast_math`
//! makes it `__powf`, and `exp2f`, `log2f`, `sqrtf` the `.approx` instructions).

use std::process::Command;
use std::sync::OnceLock;

use crate::listing::{instruction, Instruction};
use crate::tools;
use crate::{Disassembly, IsaError};
use specula::gpus::{Gpu, Vendor};

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

/// `source` with every `specula_` name made `specula{k}_`, so that several kernels share one
/// file (the compiler's process is most of a compile's time).
pub(crate) fn renamed(source: &str, k: usize) -> String {
    source.replace("specula_", &format!("specula{k}_"))
}

/// The SASS `nvcc` makes of each CUDA C kernel of `sources` for `gpu`, in one run.
pub fn compile(sources: &[&str], gpu: &Gpu) -> Result<Vec<Disassembly>, IsaError> {
    let [nvcc, nvdisasm] = tools::cuda()?;
    let scratch = specula_temporaries::dir("isa-nvidia-").map_err(IsaError::scratch)?;
    let cu = scratch.path().join("kernels.cu");
    let cubin = scratch.path().join("kernels.cubin");
    let combined: String = sources
        .iter()
        .enumerate()
        .map(|(k, source)| renamed(source, k))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&cu, combined).map_err(IsaError::scratch)?;
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
    let registers = registers(&report);
    let mut command = Command::new(&nvdisasm);
    command.arg("-c").arg(&cubin);
    let disassembled = tools::run(command, "nvdisasm")?;
    let text = String::from_utf8_lossy(&disassembled.stdout);
    let compiler = format!("{} ({}, {})", version()?, gpu.compiler_target, FLAGS[0]);
    (0..sources.len())
        .map(|k| {
            let name = format!("specula{k}_evaluate");
            let section = function(&text, &name)
                .ok_or_else(|| IsaError::Unreadable(format!("nvdisasm's listing of {name}")))?;
            Ok(Disassembly {
                compiler: compiler.clone(),
                // Named as it would be compiled alone.
                text: section.replace(&format!("specula{k}_"), "specula_"),
                simd: 32,
                registers: registers.iter().find(|(n, _)| *n == name).map(|(_, r)| *r),
                estimates: Vec::new(),
            })
        })
        .collect()
}

/// Each entry function's registers from `ptxas -v` (`Compiling entry function 'NAME' for
/// 'sm_89'`, then `Used 10 registers, ...`).
fn registers(report: &str) -> Vec<(String, u32)> {
    let mut found = Vec::new();
    let mut function = None;
    for line in report.lines() {
        if let Some((_, after)) = line.split_once("entry function '") {
            function = after.split('\'').next().map(str::to_owned);
        } else if let Some((_, after)) = line.split_once("Used ") {
            if let (Some(name), Some(count)) = (
                function.take(),
                after.split_whitespace().next().and_then(|n| n.parse().ok()),
            ) {
                found.push((name, count));
            }
        }
    }
    found
}

/// The part of nvdisasm's listing that is the function `name`: from its section header
/// (`//------- .text.NAME -------`) to the next.
fn function<'a>(listing: &'a str, name: &str) -> Option<&'a str> {
    let header = format!(".text.{name} ");
    let start = listing.find(&header)?;
    let body = &listing[start + header.len()..];
    let end = body.find("//----").unwrap_or(body.len());
    Some(&body[..end])
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

    #[test]
    fn a_batchs_registers_and_functions_are_found_by_name() {
        let report = "ptxas info    : Compiling entry function 'specula1_evaluate' for 'sm_89'
ptxas info    : Function properties for specula1_evaluate
ptxas info    : Used 12 registers, used 0 barriers, 364 bytes cmem[0]
ptxas info    : Compiling entry function 'specula0_evaluate' for 'sm_89'
ptxas info    : Used 10 registers, used 0 barriers, 364 bytes cmem[0]";
        assert_eq!(
            registers(report),
            [
                ("specula1_evaluate".to_owned(), 12),
                ("specula0_evaluate".to_owned(), 10)
            ]
        );
        let listing = "//--------------------- .text.specula1_evaluate --------------------------
        /*0000*/ MUFU.EX2 R0, R0 ;
//--------------------- .text.specula0_evaluate --------------------------
        /*0000*/ FMUL R0, R0, R0 ;
";
        assert!(function(listing, "specula0_evaluate")
            .unwrap()
            .contains("FMUL"));
        assert!(!function(listing, "specula1_evaluate")
            .unwrap()
            .contains("FMUL"));
        assert_eq!(
            renamed("void specula_evaluate(", 3),
            "void specula3_evaluate("
        );
    }
}
