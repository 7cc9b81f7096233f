//! `specula`: the command-line face of the specula workbench.
//!
//! Each subcommand lives in `commands/`; argument parsing delegates to the core's registry
//! (`args.rs`), so ids, ranges and their error messages have one source. Every failure is a
//! one-line message on stderr and exit code 2.

mod args;
mod commands;
mod output;
mod progress;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// specula: a workbench for specular reflectance models (Phong/Blinn lobes and their cheap
/// approximations).
#[derive(Debug, Parser)]
#[command(name = "specula", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// List every lobe model: id, formula, parameters, operation counts.
    #[command(after_help = "Examples:\n  specula models\n  specula models --n 512 --format json")]
    Models(commands::models::Args),
    /// Which lobe to ship on a target at an accuracy: ranked by cost, with the Pareto front.
    #[command(
        after_help = "Examples:\n  specula recommend --target gpu-nvidia --n 64 --max-error 1%\n  \
                            specula recommend --target cpu --n 8..512 --max-error 0.5% --zone \
                            epicentre\n  \
                            specula recommend --target gpu-amd --n 64 --max-error 2% --zone whole \
                            --energy-conserving --format json\n  \
                            specula recommend --material paper_white_rgb.bsdf --target gpu-nvidia \
                            --margin 5%"
    )]
    Recommend(commands::recommend::Args),
    /// Design the cheapest lobe for a target, a range of n and an accuracy: families the
    /// formula language writes, fitted across the range, verified by the analysis, costed as
    /// recommend costs, written as a lobe file.
    #[command(
        after_help = "Examples:\n  specula design --target gpu-nvidia --n 8..512 --max-error 0.1% \
            -o designed.toml\n  \
                            specula design --target cpu --n 8..512 --max-error 0.1%\n  \
                            specula design --target gpu-amd --n 64 --max-error 1% \
                            --energy-tolerance 0.5% --no-transcendentals"
    )]
    Design(commands::design::Args),
    /// Fit every lobe (and GGX) to measured materials (RGL isotropic RGB `.bsdf` files): the
    /// parameters, the fit errors against pow's and GGX's, the energy, and the lobe to ship.
    #[command(
        after_help = "Examples:\n  specula fit --material paper_white_rgb.bsdf\n  \
                            specula fit --material a.bsdf b.bsdf --target cpu --margin 2% --format \
                            json >> fits.jsonl\n  \
                            specula recommend --material paper_white_rgb.bsdf --target gpu-nvidia"
    )]
    Fit(commands::fit::Args),
    /// Evaluate one lobe at one cosine or angle, next to the exact t^n.
    #[command(
        after_help = "Examples:\n  specula eval --lobe schlick --n 32 --cos 0.98\n  \
                            specula eval --lobe cheb2 --n 100 --angle 5 --geometry blinn\n  \
                            specula eval --lobe cosquad:v=5 --n 64 --cos 0.99"
    )]
    Eval(commands::eval::Args),
    /// Measure lobes against t^n: error per zone, energy, albedo, cost.
    #[command(after_help = "Examples:\n  specula analyze\n  \
                            specula analyze --lobe schlick,schlick-mod --n 16,256\n  \
                            specula analyze --format json --backend f32 > errors.json")]
    Analyze(commands::analyze::Args),
    /// Your own lobe: write a lobe file to start from, or check one (a file or a formula) over
    /// a range of n.
    #[command(after_help = "Examples:\n  specula lobe new mine.toml\n  \
                            specula lobe check @mine.toml\n  \
                            specula lobe check '=exp2(n * (t - 1) * 1.4427)' --n 1..1000")]
    Lobe(commands::lobe::Args),
    /// Test the thesis's claims (SPEC section 9) with measured figures and verdicts.
    #[command(after_help = "Examples:\n  specula claims\n  specula claims --format json")]
    Claims(commands::claims::Args),
    /// Write the report: models, shapes, errors, energy, claims, renders, cost (HTML + images).
    #[command(
        after_help = "Examples:\n  specula report\n  specula report --quick --out /tmp/report\n  \
            specula report --bench"
    )]
    Report(commands::report::Args),
    /// Render a scene (TOML, or the embedded default) to PNG, EXR or HDR, lit by its lights or by
    /// an environment map.
    #[command(after_help = "Examples:\n  specula render -o out.png\n  \
                            specula render scene.toml --lobe schlick-mod --n 256 -o out.exr\n  \
                            specula render --shading gouraud --width 640 --height 360\n  \
                            specula render --grid lobes=pow,schlick,schlick-mod,cheb2,logexp -o \
                            grid.png\n  \
                            specula render --env sky --spp 64 -o sky.png\n  \
                            specula render scene.toml --env studio.hdr --spp 256 -o lit.exr\n  \
                            specula render --dump-default-scene > my-scene.toml")]
    Render(commands::render::Args),
    /// Compare two images: PSNR, largest error, mean FLIP, and a FLIP heatmap.
    #[command(after_help = "Examples:\n  specula diff reference.png test.png\n  \
                            specula diff a.exr b.exr --heatmap flip.png --format json")]
    Diff(commands::diff::Args),
    /// Export one lobe: a shader function (WGSL, GLSL, HLSL, MSL, SPIR-V), a Blender (OSL),
    /// MaterialX or Mitsuba 3 file, or a three.js, Babylon.js or VTK module.
    #[command(
        after_help = "Examples:\n  specula shader --lobe schlick-mod --n 64 --lang glsl\n  \
                            specula shader --lobe cosquad --n 100 --geometry blinn --normalisation \
                            lobe --lang hlsl -o lobe.hlsl\n  \
                            specula shader --lobe cheb2 --n 32 --lang spirv -o lobe.spv\n  \
                            specula shader --lobe cosquad --n 64 --lang osl -o \
                            specula_cosquad.osl\n  \
                            specula shader --lobe cosquad --n 64 --lang mtlx -o \
                            specula_cosquad.mtlx\n  \
                            specula shader --lobe cosquad --n 64 --normalisation lobe --lang \
                            mitsuba -o specula_cosquad.py\n  \
                            specula shader --lobe cosquad --n 32 --lang vtk -o \
                            specula_cosquad_vtk.py"
    )]
    Shader(commands::shader::Args),
    /// Measure throughput (printed figures and ratios, not pass/fail).
    #[command(
        after_help = "Examples:\n  specula bench render\n  specula bench gpu\n  specula bench \
            render --width 640 --height 360 --frames 3"
    )]
    Bench(commands::bench::Args),
    /// Hardware datapaths: error against word length and resources, Verilog, block diagrams,
    /// synthesis.
    #[command(
        after_help = "Datapaths (--lobe): schlick, schlick-mod, cheb2, logexp, logexp-mitchell, \
            cosquad, pow, sg\n\
                      Word lengths (--bits): 8 to 24 bits; n: an integer in [1, 1000]\n\n\
                      Examples:\n  specula hw table --lobe cosquad,logexp --bits 8..24 --n 64\n  \
                            specula hw verilog --lobe cosquad --bits 16 -o cosquad.v --testbench \
                            cosquad_tb.v\n  \
                            specula hw diagram --lobe logexp -o logexp.svg\n  \
                            specula hw synth --target ice40 --device hx8k --bits 12 --lobe \
                            cosquad,pow,sg"
    )]
    Hw(commands::hw::Args),
    /// A lobe's machine code beside pow's, as NVIDIA's, AMD's or Intel's compiler writes it
    /// for a named GPU: instructions by class, registers, the compiler's estimates.
    #[command(
        after_help = "Examples:\n  specula isa --lobe sg --n 64 --gpu sm_89\n  \
                            specula isa --lobe schlick --n 64 --gpu gfx1100 --context shading\n  \
                            specula isa --lobe cosquad --n 100 --gpu tgllp --format json\n\n\
                      The compilers need no GPU: nvcc and nvdisasm from PyPI \
                      (nvidia-cuda-nvcc, nvidia-nvvm, nvidia-cuda-crt, nvidia-cuda-runtime, \
                      nvidia-cuda-nvdisasm), Mesa's RADV (mesa-vulkan-drivers, with \
                      libvulkan-dev and gcc for its helper), Intel's ocloc (intel-opencl-icd)."
    )]
    Isa(commands::isa::Args),
    /// Render a volume (the Shepp-Logan head, Marschner-Lobb, NIfTI, a DICOM series) by ray
    /// marching or as an isosurface, any lobe as its specular term, on the CPU or GPU.
    #[command(
        after_help = "Examples:\n  specula volume --input phantom --mode dvr --lobe cosquad -o \
            head.png\n  \
                            specula volume --input head.nii.gz --mode iso --iso 0.5 --backend gpu \
                            -o skull.png\n  \
                            specula volume --input ct-series/ --transfer ct-bone --view axial -o \
                            ct.png\n  \
                            specula volume --input marschner-lobb --size 64 --eye 400,-300,200 -o \
                            ml.png"
    )]
    Volume(commands::volume::Args),
    /// Draw directions from a lobe's importance sampler (wi and pdf per line), or run the
    /// chi-square suite over every lobe.
    #[command(
        after_help = "Examples:\n  specula sample --lobe cosquad --n 64 --theta-o 30 --count 5\n  \
                            specula sample --lobe schlick --n 8 --form blinn --format json --count \
                            3\n  \
                            specula sample --test\n  \
                            specula sample --test --lobe sg --n 512 --theta-o 70 --images chi2/"
    )]
    Sample(commands::sample::Args),
    /// Write a volume (built in, NIfTI or a DICOM series) as NIfTI-1 or as a DICOM series.
    #[command(
        after_help = "Examples:\n  specula volume-convert --input phantom -o head.nii.gz\n  \
                            specula volume-convert --input phantom -o head-dicom\n  \
                            specula volume-convert --input ct-series/ -o ct.nii.gz\n  \
                            specula volume-convert --input Cranium.inv3 --resample 512x512x432 -o \
                            clinical-ct.nii"
    )]
    VolumeConvert(commands::volume::ConvertArgs),
    /// Write the built-in sky (`--env sky`) as an EXR or HDR map, for other renderers.
    #[command(
        after_help = "Examples:\n  specula sky -o sky.exr\n  specula sky --width 2048 -o \
            sky.hdr\n\n\
                      The map is equirectangular with world z up: row y covers polar angles \
                      pi y / H to pi (y + 1) / H from the zenith; column x looks along azimuth \
                      3 pi / 2 - 2 pi (x + 0.5) / W, so the middle column looks along +y."
    )]
    Sky(commands::sky::Args),
    /// Serve the interactive BRDF explorer (page and JSON API) on 127.0.0.1.
    #[command(
        after_help = "Examples:\n  specula serve --open\n  specula serve --port 9000\n  specula \
            serve --port 0   # a free port, printed"
    )]
    Serve(commands::serve::Args),
}

/// Exit status after an interrupt (128 + SIGINT), as shells report it.
const INTERRUPTED: i32 = 130;
/// Exit status when the reader of standard output has gone (128 + SIGPIPE): what `ls | head`
/// reports for `ls`.
const BROKEN_PIPE: i32 = 141;

/// Standard output errors end the process as Unix tools end: quietly when the reader has gone
/// (`specula models | head -c1`), with one line and status 1 otherwise (`> /dev/full`).
/// `println!` reports both by panicking, so the hook turns those panics into exits.
fn install_output_error_hook() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if let Some(cause) = message.strip_prefix("failed printing to stdout: ") {
            end_on_output_error(cause.contains("Broken pipe"), &cause);
        }
        default(info);
    }));
}

/// Ends the process after an error writing standard output, as Unix tools end: quietly with
/// [`BROKEN_PIPE`] when the reader has gone, with one line and status 1 otherwise.
fn end_on_output_error(reader_gone: bool, cause: &dyn std::fmt::Display) -> ! {
    if reader_gone {
        std::process::exit(BROKEN_PIPE);
    }
    eprintln!("error: writing to standard output: {cause}");
    std::process::exit(1);
}

/// What a command that writes standard output itself (rather than by `println!`) does with
/// its write's error: the same as `println!`'s.
pub(crate) fn output_error(error: &std::io::Error) -> ! {
    end_on_output_error(error.kind() == std::io::ErrorKind::BrokenPipe, error)
}

/// Gives the Vulkan loader a private `XDG_RUNTIME_DIR` when the session has none (CI, SSH,
/// containers): Mesa's drivers probe for a Wayland display through it and otherwise print
/// "XDG_RUNTIME_DIR is invalid or not set" on every GPU path. Runs first, before any thread
/// exists, since it sets an environment variable.
fn provide_runtime_directory() {
    let valid = std::env::var_os("XDG_RUNTIME_DIR")
        .is_some_and(|dir| std::fs::metadata(dir).is_ok_and(|m| m.is_dir()));
    if valid {
        return;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt};
        let uid = std::fs::metadata("/proc/self").map_or(0, |m| m.uid());
        let dir = std::env::temp_dir().join(format!("specula-runtime-{uid}"));
        let created = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        let usable =
            created.is_ok() || std::fs::metadata(&dir).is_ok_and(|m| m.is_dir() && m.uid() == uid);
        if usable {
            std::env::set_var("XDG_RUNTIME_DIR", dir);
        }
    }
}

fn main() -> ExitCode {
    provide_runtime_directory();
    install_output_error_hook();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(error) if !error.use_stderr() => {
            // --help and --version: print as clap formats them, exit 0.
            let _ = error.print();
            return ExitCode::SUCCESS;
        }
        Err(error) => {
            eprintln!("{}", printable_line(&one_line(&error.render().to_string())));
            return ExitCode::from(2);
        }
    };
    if !matches!(cli.command, Command::Serve(_)) {
        // The server shuts down on its own signal handling; everything else removes its
        // temporary files and exits.
        let _ = ctrlc::set_handler(|| {
            specula_temporaries::remove_all();
            eprintln!("interrupted");
            std::process::exit(INTERRUPTED);
        });
    }
    let result = match cli.command {
        Command::Models(args) => commands::models::run(&args),
        Command::Recommend(args) => commands::recommend::run(&args),
        Command::Design(args) => commands::design::run(&args),
        Command::Fit(args) => commands::fit::run(&args),
        Command::Eval(args) => commands::eval::run(&args),
        Command::Analyze(args) => commands::analyze::run(&args),
        Command::Claims(args) => commands::claims::run(&args),
        Command::Lobe(args) => commands::lobe::run(&args),
        Command::Report(args) => commands::report::run(&args),
        Command::Render(args) => commands::render::run(&args),
        Command::Volume(args) => commands::volume::run(&args),
        Command::Sample(args) => commands::sample::run(&args),
        Command::VolumeConvert(args) => commands::volume::convert(&args),
        Command::Diff(args) => commands::diff::run(&args),
        Command::Shader(args) => commands::shader::run(&args),
        Command::Bench(args) => commands::bench::run(&args),
        Command::Hw(args) => commands::hw::run(&args),
        Command::Isa(args) => commands::isa::run(&args),
        Command::Sky(args) => commands::sky::run(&args),
        Command::Serve(args) => commands::serve::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {}", printable_line(&message));
            ExitCode::from(2)
        }
    }
}

/// `message` as one line a terminal shows as written: line breaks (a library's multi-line
/// error) become `; `, and other control characters (an escape sequence in a bad argument)
/// are shown escaped rather than interpreted.
fn printable_line(message: &str) -> String {
    message
        .lines()
        .map(str::trim)
        .filter(|line| !line.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
        .chars()
        .flat_map(|c| {
            let escaped: Vec<char> = if c.is_control() {
                c.escape_default().collect()
            } else {
                vec![c]
            };
            escaped
        })
        .collect()
}

/// Clap's message folded onto one line, without the usage and `--help` trailer.
fn one_line(rendered: &str) -> String {
    let message = rendered.split("\n\nUsage:").next().unwrap_or(rendered);
    let message = message
        .split("\n\nFor more information")
        .next()
        .unwrap_or(message);
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}
