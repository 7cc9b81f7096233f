//! # specula-synth: the datapaths through real synthesis
//!
//! `specula-hw` describes each datapath and emits its Verilog; this crate hands that Verilog to
//! the tools hardware engineers use and reads back what they report:
//! - **Yosys** (Debian package `yosys`): `synth` for a technology-independent gate count,
//!   `synth_ice40` (SB_LUT4, SB_CARRY, SB_DFF*, SB_MAC16) and `synth_xilinx` (LUT1-6, CARRY4,
//!   DSP48E1, FD*), each followed by `stat -json`;
//! - **nextpnr-ice40** (Debian packages `nextpnr-ice40` and `fpga-icestorm`): placement and
//!   routing of the pipelined form on an iCE40 UP5K or HX8K, whose `--report` JSON gives the
//!   achieved Fmax.
//!
//! Every figure comes from the tools' JSON ([`report`]), never from their prose, and every
//! result names the tool versions that produced it. The runs are cached ([`cache`]) by a hash
//! of everything that determines them (the Verilog, the flow, the tool versions), so a result
//! is recomputed exactly when it could differ.
//!
//! This is a crate of its own because it is the only layer that runs external programs: the
//! datapath models stay pure, and the CLI and the report ask here.

pub mod cache;
pub mod claim;
pub mod harness;
pub mod report;
mod tools;

use std::path::Path;

use serde::{Deserialize, Serialize};
use specula_hw::{verilog, HwError, HwLobe};

pub use tools::{Tool, ToolVersions};

/// What synthesis maps the datapath to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    /// Yosys's internal gate library: a technology-independent count.
    Generic,
    /// A Lattice iCE40 part, placed and routed by nextpnr for its Fmax.
    Ice40(Ice40Device),
    /// A Xilinx 7-series part (synthesis only: no open place-and-route is packaged for it).
    Xilinx,
}

/// The iCE40 part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ice40Device {
    /// iCE40UP5K (package SG48): 5,280 logic cells and eight SB_MAC16 multipliers, which
    /// synthesis uses.
    Up5k,
    /// iCE40HX8K (package CT256): 7,680 logic cells and no multiplier blocks, so every
    /// operator is in LUTs and the area is one number.
    Hx8k,
}

impl Ice40Device {
    /// The device's id on the command line and nextpnr's flag.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Ice40Device::Up5k => "up5k",
            Ice40Device::Hx8k => "hx8k",
        }
    }

    /// nextpnr's package name.
    #[must_use]
    pub fn package(self) -> &'static str {
        match self {
            Ice40Device::Up5k => "sg48",
            Ice40Device::Hx8k => "ct256",
        }
    }

    /// Logic cells and multiplier blocks on the part.
    #[must_use]
    pub fn capacity(self) -> (u64, u64) {
        match self {
            Ice40Device::Up5k => (5280, 8),
            Ice40Device::Hx8k => (7680, 0),
        }
    }
}

impl Target {
    /// A short name: `generic`, `ice40-up5k`, `ice40-hx8k`, `xilinx`.
    #[must_use]
    pub fn name(self) -> String {
        match self {
            Target::Generic => "generic".to_owned(),
            Target::Ice40(device) => format!("ice40-{}", device.id()),
            Target::Xilinx => "xilinx".to_owned(),
        }
    }

    /// What the target's logic figure counts.
    #[must_use]
    pub fn logic_unit(self) -> &'static str {
        match self {
            Target::Generic => "gates",
            Target::Ice40(_) => "SB_LUT4",
            Target::Xilinx => "LUT1-6",
        }
    }

    /// The Yosys script, run in the scratch directory, that synthesizes `top` from
    /// [`SOURCE`] and writes `stat -json` to [`STAT`]; for iCE40 it then places that same
    /// mapped datapath in the timing harness ([`harness`]) and writes the netlist nextpnr
    /// reads, [`NETLIST`]. The datapath is synthesized once: the harness is synthesized
    /// around it as a black box (a shift register and an XOR, under a second), and the mapped
    /// datapath is copied in, so nextpnr times exactly the netlist the resources count.
    fn yosys_script(self, top: &str) -> String {
        let ice40 = |device: Ice40Device, options: &str, top: &str| {
            format!(
                "synth_ice40{options} -top {top}{}",
                if device == Ice40Device::Up5k {
                    " -dsp"
                } else {
                    ""
                }
            )
        };
        let synth = match self {
            Target::Generic => format!("synth -flatten -top {top}"),
            Target::Ice40(device) => ice40(device, "", top),
            Target::Xilinx => format!("synth_xilinx -top {top} -family xc7"),
        };
        let stat = format!("read_verilog {SOURCE}; {synth}; tee -q -o {STAT} stat -json");
        match self {
            Target::Ice40(device) => format!(
                "{stat}; design -stash datapath; \
                 read_verilog -lib {SOURCE}; read_verilog {HARNESS_SOURCE}; {}; \
                 delete ={top}; design -copy-from datapath {top}; \
                 hierarchy -top {}; flatten; write_json {NETLIST}",
                ice40(device, " -noflatten", harness::HARNESS),
                harness::HARNESS
            ),
            Target::Generic | Target::Xilinx => stat,
        }
    }
}

/// The scratch directory's files (plain names: Yosys's `tee -o` takes no quoting).
const SOURCE: &str = "source.v";
const HARNESS_SOURCE: &str = "harness.v";
const STAT: &str = "stat.json";
const NETLIST: &str = "net.json";
const PLACED: &str = "report.json";

/// One datapath through one flow: what the tools report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Synthesis {
    /// The datapath's id.
    pub lobe: String,
    /// The word length.
    pub bits: u32,
    /// The flow.
    pub target: Target,
    /// The tools and versions that produced these figures.
    pub tools: ToolVersions,
    /// The resources, from Yosys's `stat -json`.
    pub cells: report::Cells,
    /// Placed-and-routed Fmax in MHz (nextpnr's report, the datapath in its timing
    /// [`harness`]), for the iCE40 flows.
    pub fmax_mhz: Option<f64>,
    /// Why there is no Fmax, when there is none.
    pub fmax_note: Option<String>,
    /// Logic cells nextpnr placed (a LUT, its flip-flop and carry share one), the harness's
    /// shift register and output included.
    pub logic_cells_placed: Option<u64>,
    /// The pipeline's latency in clock cycles (one result per clock after it).
    pub latency: u32,
}

impl Synthesis {
    /// Area times clock period per result, `logic x ns`: one result per clock, so the
    /// period is the time each result costs.
    #[must_use]
    pub fn logic_ns_per_result(&self) -> Option<f64> {
        self.fmax_mhz
            .map(|mhz| self.cells.logic as f64 * 1000.0 / mhz)
    }
}

/// Why a synthesis produced no result.
#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    /// A tool is not installed.
    #[error(
        "{tool} is not installed; install the Debian package `{package}` (apt-get install \
        {package})"
    )]
    ToolMissing {
        /// The program.
        tool: &'static str,
        /// The package that provides it.
        package: &'static str,
    },
    /// A tool ran and failed.
    #[error("{tool} failed on {design}: {log}")]
    ToolFailed {
        /// The program.
        tool: &'static str,
        /// The design it was given.
        design: String,
        /// The last lines of its output.
        log: String,
    },
    /// A report was not what the tool documents.
    #[error("{tool}'s report for {design} is not readable: {problem}")]
    Report {
        /// The program.
        tool: &'static str,
        /// The design.
        design: String,
        /// What was wrong.
        problem: String,
    },
    /// The datapath request itself.
    #[error(transparent)]
    Hw(#[from] HwError),
    /// The working directory.
    #[error("synthesis scratch files: {0}")]
    Io(#[from] std::io::Error),
}

/// The frequency nextpnr is asked to reach: above what any datapath achieves on an iCE40, so
/// the placer always optimises timing; `--timing-allow-fail` lets it report what it reached.
const TARGET_MHZ: u32 = 150;

/// Synthesizes the pipelined `lobe` datapath at `bits` for `target`, reading results from and
/// storing them in `cache` when one is given.
pub fn synthesize(
    lobe: HwLobe,
    bits: u32,
    target: Target,
    cache: Option<&cache::Cache>,
) -> Result<Synthesis, SynthError> {
    let result = synthesize_or(lobe, bits, target, cache, OnMiss::Synthesize)?;
    Ok(result.expect("a miss is synthesized"))
}

/// What to do when the cache does not hold a result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnMiss {
    /// Run the tools.
    Synthesize,
    /// Return nothing: for callers that must stay fast (a quick report).
    Skip,
}

/// [`synthesize`], or on a cache miss with [`OnMiss::Skip`], `None`.
pub fn synthesize_or(
    lobe: HwLobe,
    bits: u32,
    target: Target,
    cache: Option<&cache::Cache>,
    on_miss: OnMiss,
) -> Result<Option<Synthesis>, SynthError> {
    let datapath = lobe.build(bits)?;
    let tools = ToolVersions::find(target)?;
    let source = verilog::module(&datapath, lobe, bits);
    let (script, timing_harness) = (
        target.yosys_script(&datapath.name),
        harness::harness(&datapath),
    );
    let key = cache::key(&[
        &source,
        &timing_harness,
        &script,
        &target.name(),
        &tools.describe(),
    ]);
    if let Some(hit) = cache.and_then(|cache| cache.load(&key)) {
        return Ok(Some(hit));
    }
    if on_miss == OnMiss::Skip {
        return Ok(None);
    }
    // Whoever held the key before us may have stored the result while we waited.
    let _held = cache.map(|cache| cache.hold(&key)).transpose()?;
    if let Some(hit) = cache.and_then(|cache| cache.load(&key)) {
        return Ok(Some(hit));
    }
    let scratch = specula_temporaries::dir("synth-")?;
    let design = format!("{} at {bits} bits for {}", lobe.id(), target.name());
    std::fs::write(scratch.path().join(SOURCE), &source)?;
    std::fs::write(scratch.path().join(HARNESS_SOURCE), timing_harness)?;
    tools::run(
        Tool::Yosys,
        &["-q", "-p", &script],
        &design,
        Some(scratch.path()),
    )?;
    let stat = scratch.path().join(STAT);
    let cells = report::cells(&read(&stat, Tool::Yosys, &design)?, target)
        .map_err(|problem| report_error(Tool::Yosys, &design, problem))?;
    let mut result = Synthesis {
        lobe: lobe.id().to_owned(),
        bits,
        target,
        tools,
        cells,
        fmax_mhz: None,
        fmax_note: None,
        logic_cells_placed: None,
        latency: datapath.resources().latency,
    };
    match target {
        Target::Ice40(device) => place_and_route(&mut result, device, scratch.path(), &design)?,
        Target::Generic => result.fmax_note = Some("no timing for generic gates".to_owned()),
        Target::Xilinx => {
            result.fmax_note = Some("no open place-and-route for Xilinx is packaged".to_owned());
        }
    }
    if let Some(cache) = cache {
        cache.store(&key, &result)?;
    }
    Ok(Some(result))
}

/// Runs nextpnr on the synthesized netlist in `scratch`, or notes why the design does not fit.
fn place_and_route(
    result: &mut Synthesis,
    device: Ice40Device,
    scratch: &Path,
    design: &str,
) -> Result<(), SynthError> {
    let (cells_available, dsps_available) = device.capacity();
    if result.cells.dsp > dsps_available || result.cells.logic > cells_available {
        result.fmax_note = Some(format!(
            "does not fit the {}: {} of {cells_available} LUTs, {} of {dsps_available} multiplier \
                blocks",
            device.id().to_uppercase(),
            result.cells.logic,
            result.cells.dsp
        ));
        return Ok(());
    }
    let frequency = TARGET_MHZ.to_string();
    let placed = tools::run(
        Tool::Nextpnr,
        &[
            &format!("--{}", device.id()),
            "--package",
            device.package(),
            "--json",
            NETLIST,
            "--report",
            PLACED,
            "--freq",
            &frequency,
            "--timing-allow-fail",
            "--seed",
            "1",
            "--quiet",
        ],
        design,
        Some(scratch),
    );
    // Yosys's count is below the part's, but packing (carry chains, flip-flops that cannot
    // share a cell) needs more cells than the part has: it does not fit either.
    if let Err(SynthError::ToolFailed { log, .. }) = &placed {
        if log.contains("Failed to expand region") {
            result.fmax_note = Some(format!(
                "does not fit the {} once packed: {} LUTs by Yosys's count, more logic cells than \
                    its {cells_available} after packing",
                device.id().to_uppercase(),
                result.cells.logic
            ));
            return Ok(());
        }
    }
    placed?;
    let placed = scratch.join(PLACED);
    let placed_report = report::placed(&read(&placed, Tool::Nextpnr, design)?)
        .map_err(|problem| report_error(Tool::Nextpnr, design, problem))?;
    result.fmax_mhz = Some(placed_report.fmax_mhz);
    result.logic_cells_placed = Some(placed_report.logic_cells);
    Ok(())
}

/// A tool's JSON report as text.
fn read(path: &Path, tool: Tool, design: &str) -> Result<String, SynthError> {
    std::fs::read_to_string(path)
        .map_err(|e| report_error(tool, design, format!("{}: {e}", path.display())))
}

fn report_error(tool: Tool, design: &str, problem: String) -> SynthError {
    SynthError::Report {
        tool: tool.program(),
        design: design.to_owned(),
        problem,
    }
}

/// The gate-level netlist of the pipelined `lobe` datapath after generic synthesis, as
/// Verilog: simulating it against the model checks synthesis kept the function.
pub fn generic_netlist(lobe: HwLobe, bits: u32) -> Result<String, SynthError> {
    let datapath = lobe.build(bits)?;
    ToolVersions::find(Target::Generic)?;
    let scratch = specula_temporaries::dir("synth-")?;
    std::fs::write(
        scratch.path().join(SOURCE),
        verilog::module(&datapath, lobe, bits),
    )?;
    let script = format!(
        "read_verilog {SOURCE}; synth -flatten -top {}; write_verilog -noattr netlist.v",
        datapath.name,
    );
    let design = format!("{} at {bits} bits", lobe.id());
    tools::run(
        Tool::Yosys,
        &["-q", "-p", &script],
        &design,
        Some(scratch.path()),
    )?;
    Ok(std::fs::read_to_string(scratch.path().join("netlist.v"))?)
}
