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
pub mod vtk_peer;
mod yours;

use std::path::PathBuf;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use specula::claims::ClaimOptions;
use specula::{Exponent, LobeKind};
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

type Section = (&'static str, fn(&mut Context) -> Result<String, String>);

/// The sections that take longest, started first (the others in the order they are shown):
/// the medical volumes and the designs' measured ranking on every run, the renders and the
/// materials when the store lacks them, the claims when the synthesis cache does.
const LONGEST_FIRST: [&str; 7] = [
    VOLUMES,
    RENDERS,
    MATERIALS,
    DESIGNED,
    RECIPROCITY,
    ERRORS,
    CLAIMS,
];
pub(crate) const RENDERS: &str = "Renders";
pub(crate) const MATERIALS: &str = "Real materials";
const VOLUMES: &str = "Medical volumes";
const CLAIMS: &str = "The thesis's claims";
const DESIGNED: &str = "Designed lobes";
pub(crate) const RECIPROCITY: &str = "Reciprocity and white furnace";
pub(crate) const ERRORS: &str = "Error against the angle and against n";

/// The sections that read the hardware sweeps.
const HARDWARE_SECTIONS: [&str; 2] = [VERDICT, HARDWARE];
const VERDICT: &str = "Which lobe when";
const HARDWARE: &str = "Hardware";
/// The page's last section, after every section's.
pub const NOTES: &str = "Notes on this machine";

/// The answer first (which lobe when), then the thesis's claims, then the details.
const SECTIONS: [Section; 14] = [
    (VERDICT, verdict::verdict),
    (DESIGNED, designed::designed),
    (CLAIMS, sections::claims),
    ("Models", sections::models),
    ("Lobe shapes", sections::shapes),
    (ERRORS, sections::errors),
    ("Energy and normalisation", energy::energy),
    (RECIPROCITY, energy::reciprocity),
    (RENDERS, renders::renders),
    (MATERIALS, materials::materials),
    (VOLUMES, volumes::volumes),
    ("Into other renderers", other_renderers::other_renderers),
    (sections::COST, sections::cost),
    (HARDWARE, hardware::hardware),
];

/// Writes the report at once from what the synthesis cache holds, then, where the FPGA's
/// answers wait on synthesis ([`Summary::pending_synthesis`]), runs it and writes the report
/// again: what `specula report` does. `written` is told of each page as it is written (an
/// interrupted second pass leaves the first page whole: pages are written atomically).
pub fn write_report_then_synthesize(
    options: &Options,
    written: &dyn Fn(&Summary),
) -> Result<Summary, String> {
    let first = write_report(&Options {
        synthesize: false,
        ..options.clone()
    })?;
    written(&first);
    if first.pending_synthesis == 0 {
        return Ok(first);
    }
    let second = write_report(&Options {
        synthesize: true,
        ..options.clone()
    })?;
    written(&second);
    Ok(second)
}

/// Writes the report once, progress bar included ([`Options::synthesize`] says whether
/// Yosys and nextpnr run).
///
/// The sections are independent, so they run concurrently, each writing its own files; the
/// cost section's throughput measurement (`bench`) runs alone afterwards, on a quiet machine.
/// Refuses, before any section runs, a user's lobe that is not a lobe at an exponent a
/// section uses and a materials folder without readable materials.
pub fn write_report(options: &Options) -> Result<Summary, String> {
    let started = Instant::now();
    std::fs::create_dir_all(&options.out).map_err(|e| {
        format!(
            "{}: cannot create the report folder: {e}",
            options.out.display()
        )
    })?;
    let lobes = specula_decide::candidates(&options.lobes);
    let yours = lobes[LobeKind::ALL.len()..].to_vec();
    // Every exponent a section uses lies on the plots' grid or among these.
    let sizes = sections::sizes(options.quick);
    let mut checked = sections::exponents(sizes.n_steps);
    checked.extend([8.0, 64.0, 100.0, 512.0].map(Exponent::new));
    checked.extend(
        sizes
            .hardware_exponents
            .iter()
            .map(|&n| Exponent::new(f64::from(n))),
    );
    specula_decide::check_lobes(&yours, &checked)?;
    if let Some(directory) = &options.materials {
        materials::check(directory, &yours)?;
    }
    let context = || Context {
        lobes: lobes.clone(),
        directory: options.out.clone(),
        sizes: sections::sizes(options.quick),
        bench: options.bench,
        files: Vec::new(),
        materials: options.materials.clone(),
        notes: Vec::new(),
        store: stored::default_store(),
        from_store: false,
        synthesize: options.synthesize,
        pending_synthesis: 0,
    };
    let bar = ProgressBar::new(SECTIONS.len() as u64).with_style(
        ProgressStyle::with_template("report {bar:30} {pos}/{len} sections {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    // Without a terminal (a CI log, nohup, a notebook) the bar draws nothing: a line per
    // section instead, as each finishes.
    let lines = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    let run_section = |&(heading, section): &Section| {
        let mut own = context();
        let begun = Instant::now();
        let body = section(&mut own);
        bar.inc(1);
        if lines {
            eprintln!(
                "report: {heading} ({:.1} s{}; {}/{} sections)",
                begun.elapsed().as_secs_f64(),
                if own.from_store {
                    ", stored by this build"
                } else {
                    ""
                },
                bar.position(),
                SECTIONS.len()
            );
        }
        body.map(|body| {
            let took = begun.elapsed();
            (
                heading,
                body,
                (took, own.from_store),
                own.files,
                (own.notes, own.pending_synthesis),
            )
        })
    };
    let alone = |(heading, _): &&Section| options.bench && *heading == sections::COST;
    // The hardware sweeps run beside the sections that do not need them (waiting for them
    // inside a section would hold one of the two worker threads idle); then the two that do.
    let needs_sweeps = |(heading, _): &&Section| HARDWARE_SECTIONS.contains(heading);
    // Started in this order, first come first served: the longest sections first, so that
    // the short ones fill in around them rather than leave one running alone at the end.
    let mut order: Vec<&Section> = SECTIONS
        .iter()
        .filter(|section| !alone(section) && !needs_sweeps(section))
        .collect();
    order.sort_by_key(|(heading, _)| {
        LONGEST_FIRST
            .iter()
            .position(|h| h == heading)
            .unwrap_or(LONGEST_FIRST.len())
    });
    let mut sweeps = Err("the hardware sweeps did not run".to_owned());
    let first: Vec<Mutex<Option<Result<_, String>>>> =
        order.iter().map(|_| Mutex::new(None)).collect();
    rayon::scope_fifo(|scope| {
        for (section, slot) in order.iter().zip(&first) {
            scope.spawn_fifo(move |_| {
                let done = run_section(section);
                *slot.lock().unwrap_or_else(PoisonError::into_inner) = Some(done);
            });
        }
        let sweeps = &mut sweeps;
        scope.spawn_fifo(move |_| {
            let begun = Instant::now();
            *sweeps = context().hardware_sweeps().map(|_| begun.elapsed());
        });
    });
    let first = first
        .into_iter()
        .map(|slot| {
            slot.into_inner()
                .unwrap_or_else(PoisonError::into_inner)
                .unwrap_or_else(|| Err("a section did not run".into()))
        })
        .collect::<Result<Vec<_>, String>>();
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
    let mut notes: Vec<String> = Vec::new();
    let mut pending_synthesis = 0;
    for (heading, body, (took, from_store), written, (noted, pending)) in done {
        pending_synthesis += pending;
        let stored = if from_store {
            " (stored by this build)"
        } else {
            ""
        };
        timings.push(format!("{heading} {:.1} s{stored}", took.as_secs_f64()));
        bodies.push((heading.to_owned(), body));
        files.extend(written);
        for note in noted {
            if !notes.contains(&note) {
                notes.push(note);
            }
        }
    }
    bodies.push((NOTES.to_owned(), machine_notes(&notes)));
    timings.push(format!(
        "hardware sweeps (shared by two sections) {:.1} s",
        sweeps_took.as_secs_f64()
    ));
    let timings = format!("sections concurrently: {}", timings.join(", "));
    let page = html::page(
        "specula report",
        &bodies,
        &footer(options, started, &timings),
    );
    let mut page_context = context();
    page_context.write("index.html", page.as_bytes())?;
    Ok(Summary {
        page: options.out.join("index.html"),
        images: files.len(),
        took: started.elapsed(),
        timings,
        pending_synthesis,
    })
}

/// The last section: what this machine lacked, a sentence each.
fn machine_notes(notes: &[String]) -> String {
    if notes.is_empty() {
        return html::paragraph("Nothing: every tool, scan and adapter the report uses was here.");
    }
    let items: String = notes
        .iter()
        .map(|note| format!("<li>{}</li>", html::escape(note)))
        .collect();
    html::paragraph(
        "What this machine lacked, and what the report did instead. None of it changes an answer \
            above; each says what to install to see the missing part.",
    ) + &format!("<ul class=\"notes\">{items}</ul>\n")
}

fn footer(options: &Options, started: Instant, timings: &str) -> String {
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
        "specula {} on {cpu}, {threads} threads, {} {}; {} mode; computed in {:.1} s ({timings}); \
            command: {}",
        env!("CARGO_PKG_VERSION"),
        std::env::consts::OS,
        std::env::consts::ARCH,
        if options.quick { "quick" } else { "full" },
        started.elapsed().as_secs_f64(),
        command.join(" ")
    ))
}
