//! The external programs: finding them, their versions, and running them.

use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use crate::{SynthError, Target};

/// A program the flows run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Yosys, the synthesizer.
    Yosys,
    /// nextpnr for iCE40, the placer and router.
    Nextpnr,
}

impl Tool {
    /// The executable's name.
    #[must_use]
    pub fn program(self) -> &'static str {
        match self {
            Tool::Yosys => "yosys",
            Tool::Nextpnr => "nextpnr-ice40",
        }
    }

    /// The Debian package that provides it.
    #[must_use]
    pub fn package(self) -> &'static str {
        match self {
            Tool::Yosys => "yosys",
            Tool::Nextpnr => "nextpnr-ice40",
        }
    }

    /// The first line of the tool's version output, or why there is none. Found once per
    /// process: every synthesis (cache hits included) names its tools, and a version cannot
    /// change while the process runs (a missing tool is looked for again).
    pub fn version(self) -> Result<String, SynthError> {
        static YOSYS: OnceLock<String> = OnceLock::new();
        static NEXTPNR: OnceLock<String> = OnceLock::new();
        let cell = match self {
            Tool::Yosys => &YOSYS,
            Tool::Nextpnr => &NEXTPNR,
        };
        if let Some(version) = cell.get() {
            return Ok(version.clone());
        }
        let version = self.ask_version()?;
        Ok(cell.get_or_init(|| version).clone())
    }

    fn ask_version(self) -> Result<String, SynthError> {
        let flag = match self {
            Tool::Yosys => "-V",
            Tool::Nextpnr => "--version",
        };
        let output = run(self, &[flag], "its version", None)?;
        let text = String::from_utf8_lossy(&output);
        let line = text
            .lines()
            .find(|line| !line.trim().is_empty())
            .unwrap_or("");
        Ok(line.trim().to_owned())
    }
}

/// The versions a result was produced with.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ToolVersions {
    /// `yosys -V`.
    pub yosys: String,
    /// `nextpnr-ice40 --version`, for the iCE40 flows.
    pub nextpnr: Option<String>,
}

impl ToolVersions {
    /// The versions of the tools `target`'s flow runs, or which one is missing.
    pub fn find(target: Target) -> Result<Self, SynthError> {
        let yosys = Tool::Yosys.version()?;
        let nextpnr = match target {
            Target::Ice40(_) => Some(Tool::Nextpnr.version()?),
            Target::Generic | Target::Xilinx => None,
        };
        Ok(Self { yosys, nextpnr })
    }

    /// Every version, for labels and cache keys.
    #[must_use]
    pub fn describe(&self) -> String {
        match &self.nextpnr {
            Some(nextpnr) => format!("{}; {nextpnr}", self.yosys),
            None => self.yosys.clone(),
        }
    }
}

/// Lines of a failing tool's output kept in the message.
const LOG_LINES: usize = 4;

/// Runs `tool` with `args` on `design` in `directory` (the current one if `None`); what it printed
/// (standard output, then standard
/// error: nextpnr prints its version on the latter), or why it failed.
pub(crate) fn run(
    tool: Tool,
    args: &[&str],
    design: &str,
    directory: Option<&Path>,
) -> Result<Vec<u8>, SynthError> {
    let mut command = Command::new(tool.program());
    command.args(args);
    if let Some(directory) = directory {
        command.current_dir(directory);
    }
    let output = command.output().map_err(|error| match error.kind() {
        std::io::ErrorKind::NotFound => SynthError::ToolMissing {
            tool: tool.program(),
            package: tool.package(),
        },
        _ => SynthError::Io(error),
    })?;
    if output.status.success() {
        let mut printed = output.stdout;
        printed.extend_from_slice(&output.stderr);
        return Ok(printed);
    }
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    let lines: Vec<&str> = text
        .lines()
        .filter(|line| !line.trim().is_empty())
        .collect();
    let tail = lines[lines.len().saturating_sub(LOG_LINES)..].join(" | ");
    Err(SynthError::ToolFailed {
        tool: tool.program(),
        design: design.to_owned(),
        log: format!("{} ({})", tail.trim(), output.status),
    })
}
