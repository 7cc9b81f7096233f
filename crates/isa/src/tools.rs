//! Finding the vendors' compilers, their versions, and running them.
//!
//! - NVIDIA's `nvcc` and `nvdisasm` come from PyPI (`nvidia-cuda-nvcc`, `nvidia-nvvm`,
//!   `nvidia-cuda-crt`, `nvidia-cuda-runtime`, `nvidia-cuda-nvdisasm`: NVIDIA's licence, so
//!   installed, never shipped): `$SPECULA_CUDA/bin` where it is set, else `nvcc` on the `PATH`,
//!   else the
//!   `nvidia/cu*/bin` of the active virtual environment (`$VIRTUAL_ENV`) or of the checkout's
//!   `target/venv`, where `.ci/run` installs them.
//! - AMD's ACO is Mesa's RADV (`mesa-vulkan-drivers`), reached through the Vulkan loader
//!   (`libvulkan-dev` for the helper's headers, `gcc` to build it) on a null device.
//! - Intel's IGC is `ocloc` (`intel-opencl-icd`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::IsaError;

/// The folders NVIDIA's tools may be in, most specific first: `$SPECULA_CUDA/bin` alone where
/// it is set (so that it can also say "none here").
fn cuda_folders() -> Vec<PathBuf> {
    let mut folders = Vec::new();
    if let Some(root) = std::env::var_os("SPECULA_CUDA").filter(|v| !v.is_empty()) {
        folders.push(Path::new(&root).join("bin"));
        return folders;
    }
    if let Some(path) = std::env::var_os("PATH") {
        folders.extend(std::env::split_paths(&path));
    }
    let venvs = std::env::var_os("VIRTUAL_ENV")
        .map(PathBuf::from)
        .into_iter()
        .chain([Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/venv")]);
    for venv in venvs {
        let Ok(libs) = std::fs::read_dir(venv.join("lib")) else {
            continue;
        };
        for python in libs.flatten() {
            let nvidia = python.path().join("site-packages/nvidia");
            let Ok(entries) = std::fs::read_dir(&nvidia) else {
                continue;
            };
            let mut cuda: Vec<PathBuf> = entries
                .flatten()
                .map(|entry| entry.path().join("bin"))
                .filter(|bin| bin.is_dir())
                .collect();
            // The newest CUDA first (cu13 before cu12).
            cuda.sort();
            cuda.reverse();
            folders.extend(cuda);
        }
    }
    folders
}

/// The first folder holding `program`.
fn find_in(folders: &[PathBuf], program: &str) -> Option<PathBuf> {
    folders
        .iter()
        .map(|folder| folder.join(program))
        .find(|path| path.is_file())
}

/// What to install for NVIDIA's tools.
pub const CUDA_INSTALL: &str = "pip install nvidia-cuda-nvcc nvidia-nvvm nvidia-cuda-crt \
    nvidia-cuda-runtime nvidia-cuda-nvdisasm (into target/venv, the active virtual \
    environment, or anywhere with SPECULA_CUDA naming the folder above bin/nvcc)";

/// `nvcc` and `nvdisasm`.
pub fn cuda() -> Result<[PathBuf; 2], IsaError> {
    let folders = cuda_folders();
    let missing = |program: &str| IsaError::Missing {
        tool: program.to_owned(),
        install: CUDA_INSTALL.to_owned(),
    };
    let nvcc = find_in(&folders, "nvcc").ok_or_else(|| missing("nvcc"))?;
    // nvdisasm beside the nvcc found, else anywhere.
    let nvdisasm = nvcc
        .parent()
        .map(|bin| bin.join("nvdisasm"))
        .filter(|path| path.is_file())
        .or_else(|| find_in(&folders, "nvdisasm"))
        .ok_or_else(|| missing("nvdisasm"))?;
    Ok([nvcc, nvdisasm])
}

/// `ocloc`.
pub fn ocloc() -> Result<PathBuf, IsaError> {
    let folders: Vec<PathBuf> = std::env::var_os("PATH")
        .map(|path| std::env::split_paths(&path).collect())
        .unwrap_or_default();
    find_in(&folders, "ocloc").ok_or_else(|| IsaError::Missing {
        tool: "ocloc".to_owned(),
        install: "apt-get install intel-opencl-icd".to_owned(),
    })
}

/// The Vulkan ICD manifest of a Mesa driver (`radeon`, `lvp`), for `VK_ICD_FILENAMES`.
pub fn vulkan_driver(name: &str, package: &str) -> Result<PathBuf, IsaError> {
    let folders = [
        "/usr/share/vulkan/icd.d",
        "/etc/vulkan/icd.d",
        "/usr/local/share/vulkan/icd.d",
    ];
    folders
        .iter()
        .filter_map(|folder| std::fs::read_dir(folder).ok())
        .flat_map(|entries| entries.flatten())
        .map(|entry| entry.path())
        .find(|path| {
            path.file_name()
                .and_then(|name| name.to_str())
                .is_some_and(|file| file.starts_with(&format!("{name}_icd")))
        })
        .ok_or_else(|| IsaError::Missing {
            tool: format!("Mesa's {name} Vulkan driver"),
            install: format!("apt-get install {package}"),
        })
}

/// Runs `command`; its output, or the failure naming `what` with the program's own message.
pub fn run(mut command: Command, what: &str) -> Result<Output, IsaError> {
    let output = command.output().map_err(|e| IsaError::Failed {
        what: what.to_owned(),
        message: e.to_string(),
    })?;
    if output.status.success() {
        Ok(output)
    } else {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let stdout = String::from_utf8_lossy(&output.stdout);
        let message = [stderr.trim(), stdout.trim()]
            .into_iter()
            .find(|text| !text.is_empty())
            .unwrap_or("no message")
            .lines()
            .take(6)
            .collect::<Vec<_>>()
            .join(" | ");
        Err(IsaError::Failed {
            what: what.to_owned(),
            message: format!("{} ({message})", output.status),
        })
    }
}
