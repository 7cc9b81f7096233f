//! `specula bench`: throughput measured in one run, printed as figures and ratios (never a
//! pass/fail timing: these machines are noisy).

use std::time::Instant;

use specula_render::{render, Overrides, Scene, Shading};

use super::CommandResult;
use crate::output::Table;

/// What to measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// The CPU renderer: ms per frame of the default scene for each shading method.
    Render,
}

/// Arguments of `specula bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// What to measure.
    #[arg(value_enum)]
    target: Target,
    /// Frame width.
    #[arg(long, default_value_t = 1920, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 1080, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: u32,
    /// Timed frames per method (after one untimed warm-up frame).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    frames: u32,
}

/// Measures and prints.
pub fn run(args: &Args) -> CommandResult {
    match args.target {
        Target::Render => bench_render(args),
    }
}

fn bench_render(args: &Args) -> CommandResult {
    let cores = rayon::current_num_threads();
    println!(
        "default scene, {}x{}, 1 sample per pixel, {} frames per method, {cores} threads",
        args.width, args.height, args.frames
    );
    let mut table = Table::new(&["shading", "best ms/frame", "mean ms/frame", "vs flat"]);
    let mut flat_best = None;
    for shading in Shading::ALL {
        let mut scene = Scene::default_scene();
        scene.apply(&Overrides {
            shading: Some(shading),
            width: Some(args.width),
            height: Some(args.height),
            samples: Some(1),
            ..Overrides::default()
        });
        let frame = || -> Result<f64, String> {
            let started = Instant::now();
            render(&scene, &|_, _| {}).map_err(|e| e.to_string())?;
            Ok(started.elapsed().as_secs_f64() * 1e3)
        };
        frame()?;
        let times = (0..args.frames)
            .map(|_| frame())
            .collect::<Result<Vec<_>, _>>()?;
        let best = times.iter().copied().fold(f64::INFINITY, f64::min);
        let mean = times.iter().sum::<f64>() / times.len() as f64;
        let flat = *flat_best.get_or_insert(best);
        table.push(vec![
            shading.id().to_owned(),
            format!("{best:.1}"),
            format!("{mean:.1}"),
            format!("{:.2}x", best / flat),
        ]);
    }
    table.print(crate::args::Format::Table);
    Ok(())
}
