//! `specula report`: one page that answers, for each lobe, what it costs, how wrong it is
//! where, what it does to energy, and whether the thesis's claims hold; every number computed
//! during the run.
//!
//! The page (`index.html`) and its images (SVG plots, PNG renders) go to one folder. Each file
//! is written atomically, and the page last, so an interrupted run never leaves a page that
//! points at missing images.

mod energy;
mod hardware;
mod html;
mod materials;
mod plot;
mod real_scans;
mod renderers;
mod renders;
mod sections;
mod verdict;
mod volumes;
mod yours;

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use specula::claims::ClaimOptions;
use specula::{Exponent, LobeKind};
use specula_hw::analysis::WidthSweep;
use specula_hw::{HwLobe, BITS};
use specula_render::{write_atomically, write_png_srgb8, Display, Image, Scene};

use super::CommandResult;

/// Arguments of `specula report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The folder to write `index.html` and its images to.
    #[arg(long, default_value = "report")]
    out: PathBuf,
    /// Reduced sizes: fewer exponents and samples, smaller renders (under 20 s on 2 cores).
    #[arg(long)]
    quick: bool,
    /// Also measure each lobe's throughput and plot error against speed.
    #[arg(long)]
    bench: bool,
    /// Add your own lobes to every section (`@FILE.toml`, `=FORMULA`; comma separated).
    #[arg(long, value_parser = crate::args::LobeListParser)]
    lobe: Vec<crate::args::LobeList>,
    /// Also fit every lobe to the measured materials in this folder (RGL isotropic RGB
    /// `.bsdf` files, the first 16 by name) and compare them in polar plots and renders.
    #[arg(long, value_name = "DIR")]
    materials: Option<PathBuf>,
}

/// How much each section computes.
#[derive(Clone, Debug)]
pub struct Sizes {
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
}

/// How much the medical section does with the real scans.
#[derive(Clone, Copy, Debug)]
pub struct RealScanSizes {
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
pub struct Context {
    directory: PathBuf,
    sizes: Sizes,
    bench: bool,
    files: Vec<String>,
    shared: Arc<Shared>,
    /// Every lobe the sections show: the built-in ones, then the user's.
    lobes: Vec<LobeKind>,
    /// The folder of measured materials (`--materials`).
    materials: Option<PathBuf>,
}

/// Every datapath's sweeps over word lengths, per hardware exponent.
type HardwareSweeps = Vec<(u32, Vec<WidthSweep>)>;

/// Work more than one section needs, done once by whichever asks first (the others wait).
#[derive(Default)]
pub struct Shared {
    /// Every datapath's sweep over word lengths at each of the hardware exponents.
    hardware: OnceLock<Result<HardwareSweeps, String>>,
}

impl Context {
    /// The hardware sweeps (the hardware section's, which the verdict's FPGA rows reuse).
    fn hardware_sweeps(&self) -> Result<&[(u32, Vec<WidthSweep>)], String> {
        let samples = self.sizes.samples_per_zone.min(20_001);
        let exponents = self.sizes.hardware_exponents;
        self.shared
            .hardware
            .get_or_init(|| {
                exponents
                    .iter()
                    .map(|&n| {
                        let sweeps = crate::commands::hw::sweeps(
                            &HwLobe::ALL,
                            n,
                            (*BITS.start(), *BITS.end()),
                            samples,
                            false,
                        )?;
                        Ok((n, sweeps))
                    })
                    .collect()
            })
            .as_ref()
            .map(Vec::as_slice)
            .map_err(Clone::clone)
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

    /// Writes a chart and returns its figure.
    fn svg(&mut self, name: &str, chart: &plot::Chart, caption: &str) -> Result<String, String> {
        let svg = chart.to_svg(580, 360)?;
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

type Section = (&'static str, fn(&mut Context) -> Result<String, String>);

/// The sections that read the hardware sweeps.
const HARDWARE_SECTIONS: [&str; 2] = [VERDICT, HARDWARE];
const VERDICT: &str = "Which lobe when";
const HARDWARE: &str = "Hardware";

/// The answer first (which lobe when), then the thesis's claims, then the details.
const SECTIONS: [Section; 13] = [
    (VERDICT, verdict::verdict),
    ("The thesis's claims", sections::claims),
    ("Models", sections::models),
    ("Lobe shapes", sections::shapes),
    ("Error against the angle and against n", sections::errors),
    ("Energy and normalisation", energy::energy),
    ("Reciprocity and white furnace", energy::reciprocity),
    ("Renders", renders::renders),
    ("Real materials", materials::materials),
    ("Medical volumes", volumes::volumes),
    ("Into other renderers", renderers::renderers),
    (sections::COST, sections::cost),
    (HARDWARE, hardware::hardware),
];

/// Writes the report.
///
/// The sections are independent, so they run concurrently, each writing its own files; the
/// cost section's throughput measurement (`--bench`) runs alone afterwards, on a quiet machine.
pub fn run(args: &Args) -> CommandResult {
    let started = Instant::now();
    std::fs::create_dir_all(&args.out).map_err(|e| {
        format!(
            "{}: cannot create the report folder: {e}",
            args.out.display()
        )
    })?;
    let yours = crate::args::flatten(&args.lobe);
    let mut lobes = LobeKind::ALL.to_vec();
    for &kind in &yours {
        if !lobes.contains(&kind) {
            lobes.push(kind);
        }
    }
    // Every exponent a section uses lies on the plots' grid or among these.
    let sizes = sections::sizes(args.quick);
    let mut checked = sections::exponents(sizes.n_steps);
    checked.extend([8.0, 64.0, 100.0, 512.0].map(Exponent::new));
    checked.extend(
        sizes
            .hardware_exponents
            .iter()
            .map(|&n| Exponent::new(f64::from(n))),
    );
    crate::args::check_lobes(&yours, &checked)?;
    if let Some(directory) = &args.materials {
        materials::check(directory, &yours)?;
    }
    let shared = Arc::new(Shared::default());
    let context = || Context {
        lobes: lobes.clone(),
        directory: args.out.clone(),
        sizes: sections::sizes(args.quick),
        bench: args.bench,
        files: Vec::new(),
        shared: Arc::clone(&shared),
        materials: args.materials.clone(),
    };
    let bar = ProgressBar::new(SECTIONS.len() as u64).with_style(
        ProgressStyle::with_template("report {bar:30} {pos}/{len} sections {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let run_section = |&(heading, section): &Section| {
        let mut own = context();
        let begun = Instant::now();
        let body = section(&mut own);
        bar.inc(1);
        body.map(|body| (heading, body, begun.elapsed(), own.files))
    };
    let alone = |(heading, _): &&Section| args.bench && *heading == sections::COST;
    // The hardware sweeps run beside the sections that do not need them (waiting for them
    // inside a section would hold one of the two worker threads idle); then the two that do.
    let needs_sweeps = |(heading, _): &&Section| HARDWARE_SECTIONS.contains(heading);
    let (sweeps, first) = rayon::join(
        || {
            let begun = Instant::now();
            context().hardware_sweeps().map(|_| begun.elapsed())
        },
        || {
            SECTIONS
                .par_iter()
                .filter(|section| !alone(section) && !needs_sweeps(section))
                .map(run_section)
                .collect::<Result<Vec<_>, String>>()
        },
    );
    let sweeps_took = sweeps?;
    let mut done = first?;
    done.extend(
        SECTIONS
            .par_iter()
            .filter(|section| !alone(section) && needs_sweeps(section))
            .map(run_section)
            .collect::<Result<Vec<_>, String>>()?,
    );
    for section in SECTIONS.iter().filter(alone) {
        done.push(run_section(section)?);
    }
    bar.finish_and_clear();
    done.sort_by_key(|(heading, ..)| SECTIONS.iter().position(|(h, _)| h == heading));
    let mut files = Vec::new();
    let mut bodies = Vec::new();
    let mut timings = Vec::new();
    for (heading, body, took, written) in done {
        timings.push(format!("{heading} {:.1} s", took.as_secs_f64()));
        bodies.push((heading.to_owned(), body));
        files.extend(written);
    }
    timings.push(format!(
        "hardware sweeps (shared by two sections) {:.1} s",
        sweeps_took.as_secs_f64()
    ));
    let timings = format!("sections concurrently: {}", timings.join(", "));
    let page = html::page("specula report", &bodies, &footer(args, started, &timings));
    let mut page_context = context();
    page_context.write("index.html", page.as_bytes())?;
    eprintln!(
        "wrote {} and {} images ({:.1} s; {timings})",
        args.out.join("index.html").display(),
        files.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

fn footer(args: &Args, started: Instant, timings: &str) -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_owned())
        })
        .unwrap_or_else(|| "unknown CPU".to_owned());
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let command: Vec<String> = std::env::args().collect();
    html::escape(&format!(
        "specula {} on {cpu}, {threads} threads, {} {}; {} mode; computed in {:.1} s ({timings}); command: {}",
        env!("CARGO_PKG_VERSION"),
        std::env::consts::OS,
        std::env::consts::ARCH,
        if args.quick { "quick" } else { "full" },
        started.elapsed().as_secs_f64(),
        command.join(" ")
    ))
}
