//! AMD: the exported SPIR-V kernel through Mesa's RADV on a null device (no GPU needed), which
//! compiles it with ACO for the chip `RADV_FORCE_FAMILY` names; the assembly, ACO's statistics
//! (its estimated latency and inverse throughput among them) and the registers come back
//! through `VK_KHR_pipeline_executable_properties`, asked by a small Vulkan program
//! (`vulkan_helper.c`, built here with `gcc` once a process). The same program runs a kernel
//! on Mesa's lavapipe, which is how the SPIR-V is tested to compute the lobe.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

use specula_synth::cache::{key, Cache};

use crate::tools;
use crate::{Disassembly, Estimate, IsaError};
use specula::gpus::Gpu;

/// The helper's source.
const HELPER: &str = include_str!("vulkan_helper.c");

/// The built helper: beside the cached results (`vulkan_helper-<hash of its source>`), built
/// once with `gcc` and renamed into place, so a process finds it built.
fn helper() -> Result<PathBuf, IsaError> {
    static BUILT: OnceLock<Result<PathBuf, IsaError>> = OnceLock::new();
    BUILT.get_or_init(build_helper).clone()
}

fn build_helper() -> Result<PathBuf, IsaError> {
    let folder = Cache::default_for("isa")
        .map_or_else(std::env::temp_dir, |cache| cache.directory().to_owned());
    let program = folder.join(format!("vulkan_helper-{}", key(&[HELPER])));
    if program.is_file() {
        return Ok(program);
    }
    std::fs::create_dir_all(&folder).map_err(IsaError::scratch)?;
    let scratch =
        specula_temporaries::dir_in(&folder, "vulkan-helper-").map_err(IsaError::scratch)?;
    let source = scratch.path().join("vulkan_helper.c");
    let built = scratch.path().join("vulkan_helper");
    std::fs::write(&source, HELPER).map_err(IsaError::scratch)?;
    let mut command = Command::new("gcc");
    command
        .arg("-O1")
        .arg("-o")
        .arg(&built)
        .arg(&source)
        .arg("-lvulkan");
    tools::run(command, "building the Vulkan helper with gcc").map_err(|error| match error {
        IsaError::Failed { message, .. }
            if message.contains("vulkan/vulkan.h") || message.contains("-lvulkan") =>
        {
            IsaError::Missing {
                tool: "the Vulkan headers and loader".to_owned(),
                install: "apt-get install libvulkan-dev".to_owned(),
            }
        }
        IsaError::Failed { message, .. } if message.contains("No such file") => IsaError::Missing {
            tool: "gcc".to_owned(),
            install: "apt-get install gcc".to_owned(),
        },
        other => other,
    })?;
    std::fs::rename(&built, &program).map_err(IsaError::scratch)?;
    Ok(program)
}

/// The helper run on `driver`'s ICD (`radeon` for ACO, `lvp` for lavapipe) with `family`
/// forced where given.
fn helper_command(driver: &Path, family: Option<&str>) -> Result<Command, IsaError> {
    let mut command = Command::new(helper()?);
    command
        .env("VK_ICD_FILENAMES", driver)
        .env("VK_DRIVER_FILES", driver)
        // Compiled afresh every time, and no cache written into the user's home.
        .env("MESA_SHADER_CACHE_DISABLE", "true")
        .env_remove("RADV_DEBUG")
        .env_remove("RADV_PERFTEST");
    if let Some(family) = family {
        command.env("RADV_FORCE_FAMILY", family);
    }
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        command.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    Ok(command)
}

/// RADV's device line for `gpu` (`Null hardware (RADV NAVI21) (Mesa driver 22.3.6)`), asked
/// once per process: the compiler's version in a cache key.
pub fn version(gpu: &Gpu) -> Result<String, IsaError> {
    static VERSIONS: std::sync::Mutex<Vec<(&'static str, String)>> =
        std::sync::Mutex::new(Vec::new());
    let mut known = VERSIONS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((_, version)) = known.iter().find(|(id, _)| *id == gpu.id) {
        return Ok(version.clone());
    }
    let radeon = tools::vulkan_driver("radeon", "mesa-vulkan-drivers")?;
    let mut command = helper_command(&radeon, Some(gpu.compiler_target))?;
    command.arg("device");
    let output = tools::run(command, "RADV's null device")?;
    let line = String::from_utf8_lossy(&output.stdout);
    let version = format!(
        "ACO in {}",
        line.trim().strip_prefix("device ").unwrap_or(line.trim())
    );
    known.push((gpu.id, version.clone()));
    Ok(version)
}

/// LLVM's machine-code analyser (`llvm-mca-19`, else `llvm-mca`, from Debian's `llvm-19`) and
/// its version line, where it runs: its estimate stands beside ACO's own, and its presence
/// keys the cache (installing it changes the next answer).
pub fn llvm_mca() -> Option<&'static (String, String)> {
    static FOUND: OnceLock<Option<(String, String)>> = OnceLock::new();
    FOUND
        .get_or_init(|| {
            ["llvm-mca-19", "llvm-mca"].into_iter().find_map(|program| {
                let output = Command::new(program).arg("--version").output().ok()?;
                let text = String::from_utf8_lossy(&output.stdout);
                let version = text.lines().find(|line| line.contains("LLVM version"))?;
                Some((program.to_owned(), version.trim().to_owned()))
            })
        })
        .as_ref()
}

/// llvm-mca's figures for the kernel's vector instructions (the scalar unit, memory and waits
/// left out: llvm-mca 19 cannot take ACO's buffer instructions), run as a loop: the block's
/// reciprocal throughput and the cycles an iteration takes, in cycles of a wave.
fn mca_estimates(text: &str, gpu: &Gpu, wave: u32) -> Vec<Estimate> {
    let Some((program, _)) = llvm_mca() else {
        return Vec::new();
    };
    let vector: Vec<String> = crate::listing::amd_listing(text, wave)
        .into_iter()
        .filter(|instruction| instruction.mnemonic.starts_with("v_"))
        .map(|instruction| instruction.text)
        .collect();
    let Ok(scratch) = specula_temporaries::dir("isa-mca-") else {
        return Vec::new();
    };
    let file = scratch.path().join("kernel.s");
    if vector.is_empty() || std::fs::write(&file, vector.join("\n") + "\n").is_err() {
        return Vec::new();
    }
    let mut command = Command::new(program);
    command
        .args(["-mtriple=amdgcn", &format!("-mcpu={}", gpu.id)])
        .arg(&file);
    if wave == 64 && gpu.id.starts_with("gfx1") {
        command.arg("-mattr=+wavefrontsize64");
    }
    let Ok(output) = command.output() else {
        return Vec::new();
    };
    let report = String::from_utf8_lossy(&output.stdout);
    let figure = |name: &str| {
        report
            .lines()
            .find_map(|line| line.strip_prefix(name))
            .and_then(|value| value.trim().parse::<f64>().ok())
    };
    let mut estimates = Vec::new();
    if let Some(value) = figure("Block RThroughput:") {
        estimates.push(Estimate {
            name: "llvm-mca's block reciprocal throughput of the vector instructions, cycles"
                .to_owned(),
            value,
        });
    }
    if let (Some(cycles), Some(iterations)) = (figure("Total Cycles:"), figure("Iterations:")) {
        estimates.push(Estimate {
            name: "llvm-mca's cycles per iteration of the vector instructions".to_owned(),
            value: cycles / iterations,
        });
    }
    estimates
}

/// The assembly and statistics ACO makes of each of `modules` (entry point `entry`) for
/// `gpu`, in one run of the helper (one device for all: the process is most of the time).
pub fn compile(modules: &[&[u32]], entry: &str, gpu: &Gpu) -> Result<Vec<Disassembly>, IsaError> {
    let radeon = tools::vulkan_driver("radeon", "mesa-vulkan-drivers")?;
    let scratch = specula_temporaries::dir("isa-amd-").map_err(IsaError::scratch)?;
    let mut command = helper_command(&radeon, Some(gpu.compiler_target))?;
    command.arg("isa").arg(entry);
    for (k, words) in modules.iter().enumerate() {
        let file = scratch.path().join(format!("kernel{k}.spv"));
        let bytes: Vec<u8> = words.iter().flat_map(|word| word.to_le_bytes()).collect();
        std::fs::write(&file, bytes).map_err(IsaError::scratch)?;
        command.arg(file);
    }
    let output = tools::run(command, "RADV (ACO)")?;
    let (device, reports) = Report::read(&String::from_utf8_lossy(&output.stdout))?;
    if reports.len() != modules.len() {
        return Err(IsaError::Unreadable(format!(
            "RADV's report: {} kernels for {} modules",
            reports.len(),
            modules.len()
        )));
    }
    reports
        .into_iter()
        .map(|report| {
            let mut disassembly = report.disassembly(&device)?;
            let mca = mca_estimates(&disassembly.text, gpu, disassembly.simd);
            disassembly.estimates.extend(mca);
            Ok(disassembly)
        })
        .collect()
}

/// Runs `spirv`'s kernel on Mesa's lavapipe over `inputs`, `per_thread` floats a thread: one
/// output a thread.
pub fn run_on_lavapipe(
    spirv: &[u32],
    entry: &str,
    inputs: &[f32],
    per_thread: usize,
) -> Result<Vec<f32>, IsaError> {
    let lavapipe = tools::vulkan_driver("lvp", "mesa-vulkan-drivers")?;
    let scratch = specula_temporaries::dir("isa-run-").map_err(IsaError::scratch)?;
    let file = scratch.path().join("kernel.spv");
    let bytes: Vec<u8> = spirv.iter().flat_map(|word| word.to_le_bytes()).collect();
    std::fs::write(&file, bytes).map_err(IsaError::scratch)?;
    let mut command = helper_command(&lavapipe, None)?;
    command
        .arg("run")
        .arg(&file)
        .arg(entry)
        .arg(per_thread.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let failed = |message: String| IsaError::Failed {
        what: "the kernel on lavapipe".to_owned(),
        message,
    };
    let mut child = command.spawn().map_err(|e| failed(e.to_string()))?;
    let input: Vec<u8> = inputs.iter().flat_map(|v| v.to_le_bytes()).collect();
    child
        .stdin
        .take()
        .ok_or_else(|| failed("no standard input".to_owned()))?
        .write_all(&input)
        .map_err(|e| failed(e.to_string()))?;
    let output = child
        .wait_with_output()
        .map_err(|e| failed(e.to_string()))?;
    if !output.status.success() {
        return Err(failed(
            String::from_utf8_lossy(&output.stderr).trim().to_owned(),
        ));
    }
    Ok(output
        .stdout
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}

/// One kernel of the helper's `isa` output read back.
#[derive(Default)]
struct Report {
    statistics: Vec<(String, f64)>,
    representations: Vec<(String, String)>,
}

impl Report {
    /// The device line and each kernel's report, in order.
    fn read(text: &str) -> Result<(String, Vec<Report>), IsaError> {
        let unreadable = |what: &str| IsaError::Unreadable(format!("the Vulkan helper's {what}"));
        let mut device = String::new();
        let mut reports: Vec<Report> = Vec::new();
        let mut rest = text;
        while let Some((line, after)) = rest.split_once('\n') {
            rest = after;
            if let Some(name) = line.strip_prefix("device ") {
                name.clone_into(&mut device);
            } else if line.starts_with("kernel ") {
                reports.push(Report::default());
            } else if let Some(statistic) = line.strip_prefix("stat ") {
                let (name, value) = statistic
                    .split_once('\t')
                    .ok_or_else(|| unreadable("statistics"))?;
                let value = value.trim().parse().map_err(|_| unreadable("statistics"))?;
                let report = reports.last_mut().ok_or_else(|| unreadable("statistics"))?;
                report.statistics.push((name.to_owned(), value));
            } else if let Some(ir) = line.strip_prefix("ir ") {
                let (name, length) = ir.split_once('\t').ok_or_else(|| unreadable("assembly"))?;
                let length: usize = length.trim().parse().map_err(|_| unreadable("assembly"))?;
                let body = rest.get(..length).ok_or_else(|| unreadable("assembly"))?;
                let report = reports.last_mut().ok_or_else(|| unreadable("assembly"))?;
                report
                    .representations
                    .push((name.to_owned(), body.to_owned()));
                rest = rest.get(length..).unwrap_or("").trim_start_matches('\n');
            }
        }
        Ok((device, reports))
    }

    fn statistic(&self, name: &str) -> Option<f64> {
        self.statistics
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }

    /// The kernel's assembly, registers and ACO's estimates.
    fn disassembly(self, device: &str) -> Result<Disassembly, IsaError> {
        let assembly = self
            .representations
            .iter()
            .find(|(name, _)| name == "Assembly")
            .map(|(_, text)| text.clone())
            .ok_or_else(|| IsaError::Unreadable("RADV returned no assembly".to_owned()))?;
        let estimates = [
            ("Latency", "ACO's estimated latency, cycles"),
            (
                "Inverse Throughput",
                "ACO's estimated inverse throughput, cycles per wave",
            ),
            ("Instructions", "ACO's instruction count"),
            ("SGPRs", "scalar registers"),
            ("Subgroup size", "wave size"),
        ]
        .into_iter()
        .filter_map(|(statistic, name)| {
            self.statistic(statistic).map(|value| Estimate {
                name: name.to_owned(),
                value,
            })
        })
        .collect();
        Ok(Disassembly {
            compiler: format!("ACO in {device}"),
            text: assembly,
            simd: self.statistic("Subgroup size").unwrap_or(64.0) as u32,
            registers: self.statistic("VGPRs").map(|v| v as u32),
            estimates,
        })
    }
}
