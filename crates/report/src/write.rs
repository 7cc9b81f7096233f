//! Writing the page: the sections run concurrently, the longest first, the two that read
//! the hardware sweeps after them and the benchmark alone at the end; the page written at
//! once from what the synthesis cache holds, and again after the synthesis its FPGA answers
//! wait on.

use std::sync::{Mutex, PoisonError};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use specula::{Exponent, LobeKind};

use super::*;

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
/// The sections that read the hardware sweeps.
const HARDWARE_SECTIONS: [&str; 2] = [VERDICT, HARDWARE];
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
