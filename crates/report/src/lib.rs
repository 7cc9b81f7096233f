//! specula's report: one page that answers, for each lobe, what it costs, how wrong it is
//! where, what it does to energy, and whether the thesis's claims hold; every number computed
//! by this build (the pure analyses and drawings kept from an earlier run of it, every timing
//! measured in this one). A product of its own, which the command line (`specula report`) and the
//! Python bindings both write ([`write_report`]); its answers ("Which lobe when", the real
//! materials' verdicts) come from `specula-decide`, so they are the ones `specula recommend`
//! and `specula fit` give.
//!
//! The page (`index.html`) and its images (SVG plots, PNG renders) go to one folder. Each file
//! is written atomically, and the page last, so an interrupted run never leaves a page that
//! points at missing images.

mod comparison;
mod designed;
mod designer_checks;
mod energy;
#[cfg(all(test, feature = "example-lobe"))]
mod example_lobe;
pub mod format;
mod hardware;
mod html;
mod materials;
mod medical;
mod microfacet_table;
mod other_renderers;
mod plot;
mod polar;
mod prose;
mod real_scans;
mod renders;
mod sections;
mod stored;
mod verdict;
mod volumes;
mod vtk_gpu;
pub mod vtk_peer;
mod write;
mod yours;

pub use write::{write_report, write_report_then_synthesize};

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use specula::claims::ClaimOptions;
use specula::LobeKind;
use specula_hw::analysis::WidthSweep;
use specula_render::{write_atomically, write_png_srgb8, Display, Image, Scene};

/// What to write.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    /// The folder to write `index.html` and its images to (made if missing).
    pub out: PathBuf,
    /// Reduced sizes: fewer exponents and samples, smaller renders.
    pub quick: bool,
    /// Also measure each lobe's throughput and plot error against speed (alone, after the
    /// other sections).
    pub bench: bool,
    /// Your lobes, added to every section after the built-in ones (which every section
    /// shows anyway: listing one here adds nothing; a built-in with other parameters,
    /// `cosquad:v=5`, is one of yours).
    pub lobes: Vec<LobeKind>,
    /// Also fit every lobe to the measured materials in this folder (RGL isotropic RGB
    /// `.bsdf` files, the first 16 by name).
    pub materials: Option<PathBuf>,
    /// Run Yosys and nextpnr for what the FPGA rows and the hardware claim need; else read
    /// the synthesis cache only, answer the FPGA rows by the formula estimate where it lacks
    /// a design, and count what is still to synthesize ([`Summary::pending_synthesis`]): a
    /// first report is written at once, then again once the synthesis is done.
    pub synthesize: bool,
}

impl Options {
    /// A full report in `out` on the built-in lobes, without the benchmark or materials.
    #[must_use]
    pub fn new(out: impl Into<PathBuf>) -> Self {
        Self {
            out: out.into(),
            quick: false,
            bench: false,
            lobes: Vec::new(),
            materials: None,
            synthesize: false,
        }
    }
}

/// What a written report holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The page.
    pub page: PathBuf,
    /// The images beside it.
    pub images: usize,
    /// How long it took.
    pub took: Duration,
    /// The time each section took, in words (they overlap: sections run concurrently).
    pub timings: String,
    /// Designs the FPGA answers need that were not synthesized ([`Options::synthesize`]
    /// off): the page says they are coming, and a report with it on answers from them.
    pub pending_synthesis: usize,
}

/// How much each section computes.
#[derive(Clone, Debug)]
pub(crate) struct Sizes {
    /// Log steps of `n` from 1 to 1000 in the plots against `n`.
    pub n_steps: usize,
    /// Samples per zone of the error figures.
    pub samples_per_zone: usize,
    /// Direction pairs of the reciprocity checks.
    pub reciprocity_pairs: usize,
    /// The claims' options.
    pub claims: ClaimOptions,
    /// Render width, height and samples per axis.
    pub render: (u32, u32, u32),
    /// The environment-lit renders' width, height and samples per pixel.
    pub environment: (u32, u32, u32),
    /// The real materials' render width (the height is 9/16 of it) and samples per pixel.
    pub materials: (u32, u32),
    /// The medical section's phantom side (voxels), image side (pixels) and frames timed per
    /// lobe and backend.
    pub volume: (usize, u32, usize),
    /// What the medical section does with the real scans.
    pub real_scans: RealScanSizes,
    /// The (integer) exponents the hardware section sweeps word lengths at.
    pub hardware_exponents: &'static [u32],
    /// Whether the hardware claim's designs are synthesized when the cache lacks them (the
    /// first time, minutes) or only read from it.
    pub synthesis: specula_synth::OnMiss,
    /// The epicentre bounds the designed lobes are searched for.
    pub design_bounds: &'static [f64],
}

/// How much the medical section does with the real scans.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RealScanSizes {
    /// Image side in pixels.
    pub side: u32,
    /// Frames timed against VTK.
    pub frames: usize,
    /// Whether every lobe renders them (else pow, schlick and cosquad).
    pub every_lobe: bool,
    /// Whether every scan is compared with VTK (else the first: one VTK job).
    pub every_scan_against_vtk: bool,
}

/// What a section works with: where files go, how much to compute, and what it wrote.
#[derive(Clone)]
pub(crate) struct Context {
    directory: PathBuf,
    sizes: Sizes,
    bench: bool,
    files: Vec<String>,
    /// Every lobe the sections show: the built-in ones, then the user's.
    lobes: Vec<LobeKind>,
    /// The folder of measured materials (`--materials`).
    materials: Option<PathBuf>,
    /// What this machine lacked (a tool, a GPU adapter, a scan), a sentence each: shown
    /// once, at the page's end, not in the answers.
    notes: Vec<String>,
    /// Where sections that depend on the code and options alone are stored ([`stored`]).
    store: Option<PathBuf>,
    /// Whether the section was copied from the store rather than computed.
    from_store: bool,
    /// Whether Yosys and nextpnr may run ([`Options::synthesize`]).
    synthesize: bool,
    /// Designs the FPGA answers need that the synthesis cache lacks (none synthesized now).
    pending_synthesis: usize,
}

/// Every datapath's sweeps over word lengths, per hardware exponent.
type HardwareSweeps = Vec<(u32, Arc<Vec<WidthSweep>>)>;

impl Context {
    /// The user's lobes (every lobe shown that is not built in).
    fn yours(&self) -> Vec<LobeKind> {
        self.lobes
            .iter()
            .copied()
            .filter(|kind| !LobeKind::ALL.contains(kind))
            .collect()
    }

    /// A context for part of a section run beside the rest: the same settings, its own
    /// list of files (appended to the section's when the part is done).
    fn sibling(&self) -> Self {
        Self {
            files: Vec::new(),
            notes: Vec::new(),
            pending_synthesis: 0,
            ..self.clone()
        }
    }

    /// Takes a sibling's files and notes once its part is done.
    fn absorb(&mut self, mut sibling: Self) {
        self.files.append(&mut sibling.files);
        self.notes.append(&mut sibling.notes);
        self.pending_synthesis += sibling.pending_synthesis;
    }

    /// A note about this machine (a missing tool, no GPU adapter): the page gathers them at
    /// its end, each once.
    fn machine_note(&mut self, note: impl Into<String>) {
        self.notes.push(note.into());
    }

    /// The hardware sweeps at the hardware exponents, which the hardware section shows and
    /// the verdict's FPGA rows choose from: `specula_decide`'s, computed once per exponent in
    /// a process, so both read the sweeps `specula recommend --target fpga` reads.
    fn hardware_sweeps(&self) -> Result<HardwareSweeps, String> {
        self.sizes
            .hardware_exponents
            .iter()
            .map(|&n| Ok((n, specula_decide::hardware_sweeps(n)?)))
            .collect()
    }
}

#[cfg(test)]
impl Context {
    /// A quick report's context writing into `directory`, on the built-in lobes, storing
    /// nothing.
    pub(crate) fn for_tests(directory: &std::path::Path) -> Self {
        Self {
            directory: directory.to_owned(),
            sizes: sections::sizes(true),
            bench: false,
            files: Vec::new(),
            lobes: LobeKind::ALL.to_vec(),
            materials: None,
            notes: Vec::new(),
            store: None,
            from_store: false,
            synthesize: false,
            pending_synthesis: 0,
        }
    }
}

impl Context {
    fn write(&mut self, name: &str, bytes: &[u8]) -> Result<(), String> {
        write_atomically(&self.directory.join(name), |w| {
            std::io::Write::write_all(w, bytes).map_err(|e| e.to_string())
        })
        .map_err(|e| e.to_string())?;
        self.files.push(name.to_owned());
        Ok(())
    }

    /// Writes a chart and returns its figure: a scatter chart (dots with their names) taller,
    /// as its names need room near their dots where the dots crowd.
    fn svg(&mut self, name: &str, chart: &plot::Chart, caption: &str) -> Result<String, String> {
        let scatter = chart.series.iter().any(|series| series.markers);
        self.svg_sized(name, chart, caption, (580, if scatter { 500 } else { 360 }))
    }

    /// Writes a chart drawn at `size` pixels (a small multiple's) and returns its figure.
    fn svg_sized(
        &mut self,
        name: &str,
        chart: &plot::Chart,
        caption: &str,
        (width, height): (u32, u32),
    ) -> Result<String, String> {
        let svg = chart.to_svg(width, height)?;
        self.write(name, svg.as_bytes())?;
        Ok(html::figure(name, caption))
    }

    /// Writes a render (through the scene's display settings) and returns its figure.
    fn png(
        &mut self,
        name: &str,
        image: &Image,
        scene: &Scene,
        caption: &str,
    ) -> Result<String, String> {
        let display: Display = scene.display;
        self.png_srgb8(
            name,
            image.width(),
            image.height(),
            &image.to_srgb8(display),
            caption,
        )
    }

    fn png_srgb8(
        &mut self,
        name: &str,
        width: u32,
        height: u32,
        bytes: &[u8],
        caption: &str,
    ) -> Result<String, String> {
        self.write_png_file(name, width, height, bytes)?;
        Ok(html::figure(name, caption))
    }

    /// Writes 8-bit sRGB pixels as a PNG beside the page (no figure).
    fn write_png_file(
        &mut self,
        name: &str,
        width: u32,
        height: u32,
        bytes: &[u8],
    ) -> Result<(), String> {
        write_png_srgb8(&self.directory.join(name), width, height, bytes)
            .map_err(|e| e.to_string())?;
        self.files.push(name.to_owned());
        Ok(())
    }
}

pub(crate) const RENDERS: &str = "Renders";
pub(crate) const MATERIALS: &str = "Real materials";
const VOLUMES: &str = "Medical volumes";
const CLAIMS: &str = "The thesis's claims";
const DESIGNED: &str = "Designed lobes";
pub(crate) const RECIPROCITY: &str = "Reciprocity and white furnace";
pub(crate) const ERRORS: &str = "Error against the angle and against n";

const VERDICT: &str = "Which lobe when";
const HARDWARE: &str = "Hardware";
/// The page's last section, after every section's.
pub const NOTES: &str = "Notes on this machine";
