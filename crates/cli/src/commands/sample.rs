//! `specula sample`: directions drawn from a lobe's importance sampler, with their density,
//! or (`--test`) the chi-square suite over lobes, exponents, geometries and views.

use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use specula::lobe::Warp;
use specula::sampling::chi2::{self, sidak, Outcome, Settings};
use specula::sampling::uniform;
use specula::sampling::SpecularSampler;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::metrics::magma_srgb8;

use super::CommandResult;
use crate::args::{parse_exponent, GeometryArg, LobeParser};

/// The most directions one run prints.
const MAX_COUNT: u64 = 10_000_000;
/// The most directions one chi-square case draws.
const MAX_TEST_SAMPLES: usize = 100_000_000;
/// The exponents and views the suite covers unless told otherwise.
const SUITE_EXPONENTS: [f64; 4] = [1.0, 8.0, 64.0, 512.0];
const SUITE_VIEWS: [f64; 3] = [0.0, 35.0, 70.0];

/// Output formats of the drawn directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SampleFormat {
    /// `x,y,z,pdf,value` with a header line.
    Csv,
    /// An array of objects.
    Json,
}

/// Arguments of `specula sample`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Lobe id, optionally with parameters (e.g. `cosquad:v=5`); with --test, by default
    /// every lobe.
    #[arg(long, value_parser = LobeParser)]
    lobe: Option<LobeKind>,
    /// Specular exponent n, in [1, 1000]; with --test, by default 1, 8, 64 and 512.
    #[arg(long, value_parser = parse_exponent, allow_hyphen_values = true)]
    n: Option<Exponent>,
    /// The viewing direction's angle from the normal, in degrees, in [0, 89]; with --test, by
    /// default 0, 35 and 70.
    #[arg(long = "theta-o", value_parser = parse_view, allow_hyphen_values = true)]
    theta_o: Option<f64>,
    /// Which form is sampled: about the mirror direction (phong) or the half vector about the
    /// normal (blinn); with --test, by default both.
    #[arg(long, value_enum)]
    form: Option<GeometryArg>,
    /// Directions drawn, at most 10^7.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u64).range(1..=MAX_COUNT))]
    count: u64,
    /// The random stream (the same seed draws the same directions).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// How the directions are printed.
    #[arg(long, value_enum, default_value_t = SampleFormat::Csv)]
    format: SampleFormat,
    /// Run the chi-square suite instead: one line per case with its p-value, exit status 1
    /// if any case fails.
    #[arg(long)]
    test: bool,
    /// Directions drawn per chi-square case, at most 10^8.
    #[arg(long, default_value_t = 1_000_000, requires = "test", value_parser = parse_test_samples)]
    samples: usize,
    /// Write each case's histogram, expected counts and residuals as a PNG into this folder.
    #[arg(long, requires = "test")]
    images: Option<PathBuf>,
}

fn parse_view(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(degrees) if (0.0..=89.0).contains(&degrees) => Ok(degrees),
        _ => Err(format!(
            "'{}' is not an angle in [0, 89] degrees",
            specula::excerpt(text)
        )),
    }
}

fn parse_test_samples(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(count) if (1000..=MAX_TEST_SAMPLES).contains(&count) => Ok(count),
        _ => Err(format!(
            "'{}' is not a sample count in [1000, {MAX_TEST_SAMPLES}]",
            specula::excerpt(text)
        )),
    }
}

fn view(degrees: f64) -> DVec3 {
    let theta = degrees.to_radians();
    DVec3::new(theta.sin(), 0.0, theta.cos())
}

#[derive(Serialize)]
struct Drawn {
    x: f64,
    y: f64,
    z: f64,
    pdf: f64,
    value: f64,
}

/// Draws and prints, or runs the suite.
pub fn run(args: &Args) -> CommandResult {
    if args.test {
        return suite(args);
    }
    let (Some(kind), Some(n)) = (args.lobe, args.n) else {
        return Err("give --lobe and --n (or --test for the chi-square suite)".into());
    };
    let geometry = args.form.map_or(Geometry::Phong, Geometry::from);
    let lobe = Lobe::checked(kind, n).map_err(|e| e.to_string())?;
    let sampler = SpecularSampler::new(lobe, geometry, Normalisation::Lobe);
    let wo = view(args.theta_o.unwrap_or(30.0));
    let drawn = (0..args.count).filter_map(|index| {
        let u = [0, 1].map(|d| uniform(args.seed, index, d));
        sampler.sample(wo, u).map(|s| Drawn {
            x: s.wi.x,
            y: s.wi.y,
            z: s.wi.z,
            pdf: s.pdf,
            value: s.value,
        })
    });
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let written = match args.format {
        SampleFormat::Csv => write_csv(&mut out, drawn),
        SampleFormat::Json => serde_json::to_writer(&mut out, &drawn.collect::<Vec<_>>())
            .map_err(std::io::Error::other)
            .and_then(|()| std::io::Write::write_all(&mut out, b"\n")),
    };
    // A reader that stops early (`| head`) ends the process as it ends any other command.
    written
        .and_then(|()| std::io::Write::flush(&mut out))
        .unwrap_or_else(|e| crate::output_error(&e));
    Ok(())
}

fn write_csv(
    out: &mut impl std::io::Write,
    drawn: impl Iterator<Item = Drawn>,
) -> std::io::Result<()> {
    writeln!(out, "x,y,z,pdf,value")?;
    for d in drawn {
        writeln!(out, "{},{},{},{},{}", d.x, d.y, d.z, d.pdf, d.value)?;
    }
    Ok(())
}

/// The chi-square suite over every case the arguments leave open.
fn suite(args: &Args) -> CommandResult {
    let kinds: Vec<LobeKind> = args
        .lobe
        .map_or_else(|| LobeKind::ALL.to_vec(), |k| vec![k]);
    let exponents: Vec<f64> = args
        .n
        .map_or_else(|| SUITE_EXPONENTS.to_vec(), |n| vec![n.get()]);
    let forms: Vec<Geometry> = args
        .form
        .map_or_else(|| Geometry::ALL.to_vec(), |f| vec![Geometry::from(f)]);
    let views: Vec<f64> = args
        .theta_o
        .map_or_else(|| SUITE_VIEWS.to_vec(), |v| vec![v]);
    let checked: Vec<Exponent> = exponents.iter().map(|&n| Exponent::new(n)).collect();
    crate::args::check_lobes(&kinds, &checked)?;
    let mut cases = Vec::new();
    for &kind in &kinds {
        for &n in &exponents {
            for &geometry in &forms {
                for &degrees in &views {
                    cases.push((kind, n, geometry, degrees));
                }
            }
        }
    }
    if let Some(folder) = &args.images {
        std::fs::create_dir_all(folder)
            .map_err(|e| format!("cannot create {}: {e}", folder.display()))?;
    }
    let alpha = sidak(0.01, cases.len());
    let settings = Settings {
        samples: args.samples,
        seed: args.seed,
        ..Settings::default()
    };
    println!(
        "{} cases, {} directions each; significance 0.01 over all, {alpha:.2e} per case (Sidak)",
        cases.len(),
        settings.samples
    );
    println!(
        "lobe           n     form   theta_o  warp      newton     p-value   dof   pdf integral  \
            verdict"
    );
    let bar = ProgressBar::new(cases.len() as u64).with_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut failed = 0;
    for (kind, n, geometry, degrees) in cases {
        let sampler = SpecularSampler::new(
            Lobe::new(kind, Exponent::new(n)),
            geometry,
            Normalisation::None,
        );
        let outcome = chi2::run(&sampler, view(degrees), &settings);
        let passed = outcome.passes(alpha);
        failed += usize::from(!passed);
        let newton = match sampler.warp() {
            Warp::Newton => format!(
                "{:.2}/{}",
                outcome.newton_iterations.0, outcome.newton_iterations.1
            ),
            _ => "-".to_owned(),
        };
        bar.suspend(|| {
            println!(
                "{:<14} {:<5} {:<6} {:<8} {:<9} {:<10} {:<9.3e} {:<5} {:<13.6} {}",
                kind.to_string(),
                n,
                geometry.id(),
                degrees,
                sampler.warp().id(),
                newton,
                outcome.p_value,
                outcome.dof,
                outcome.pdf_integral,
                if passed { "pass" } else { "FAIL" }
            );
        });
        if let Some(folder) = &args.images {
            let name = format!("{kind}-n{n}-{}-{degrees}deg.png", geometry.id());
            write_tables(&folder.join(name), &outcome)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    if failed > 0 {
        return Err(format!("{failed} case(s) rejected the null hypothesis"));
    }
    Ok(())
}

/// Pixels per histogram cell in the written images.
const ZOOM: usize = 4;
/// Gap between the three panels.
const GAP: usize = 8;

/// The histogram, the expected counts (both on one square-root magma scale) and the Pearson
/// residuals `(observed - expected) / sqrt(expected)` (blue below, red above, saturating at
/// 4), side by side: rows go down from the lobe's axis, columns across its azimuth.
fn write_tables(path: &Path, outcome: &Outcome) -> CommandResult {
    let (columns, rows) = (outcome.columns, outcome.rows);
    let top = outcome
        .histogram
        .iter()
        .chain(&outcome.expected)
        .fold(f64::MIN_POSITIVE, |a, &b| a.max(b))
        .sqrt();
    let scaled =
        |values: &[f64]| -> Vec<f32> { values.iter().map(|v| (v.sqrt() / top) as f32).collect() };
    let panels = [
        magma_srgb8(&scaled(&outcome.histogram)),
        magma_srgb8(&scaled(&outcome.expected)),
    ];
    let residual: Vec<u8> = outcome
        .histogram
        .iter()
        .zip(&outcome.expected)
        .flat_map(|(&o, &e)| {
            let r = if e > 0.0 {
                ((o - e) / e.sqrt() / 4.0).clamp(-1.0, 1.0)
            } else {
                0.0
            };
            let fade = |v: f64| (255.0 * (1.0 - v.abs())).round() as u8;
            if r >= 0.0 {
                [255, fade(r), fade(r)]
            } else {
                [fade(r), fade(r), 255]
            }
        })
        .collect();
    let (panel_width, height) = (columns * ZOOM, rows * ZOOM);
    let width = 3 * panel_width + 2 * GAP;
    let mut bytes = vec![255u8; width * height * 3];
    for (p, panel) in panels.iter().chain(std::iter::once(&residual)).enumerate() {
        for y in 0..height {
            for x in 0..panel_width {
                let source = 3 * ((y / ZOOM) * columns + x / ZOOM);
                let target = 3 * (y * width + p * (panel_width + GAP) + x);
                bytes[target..target + 3].copy_from_slice(&panel[source..source + 3]);
            }
        }
    }
    let png = specula_render::encode_png_srgb8(width as u32, height as u32, &bytes)?;
    specula_render::write_atomically(path, |writer| {
        writer.write_all(&png).map_err(|e| e.to_string())
    })
    .map_err(|e| e.to_string())
}
