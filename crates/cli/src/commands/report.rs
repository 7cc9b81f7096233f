//! `specula report`: the report (`specula_report`), written where `--out` says.

use std::path::PathBuf;

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

/// Writes the report and says where; where the FPGA's answers wait on synthesis, says so,
/// synthesizes and writes it again.
pub fn run(args: &Args) -> CommandResult {
    let options = specula_report::Options {
        out: args.out.clone(),
        quick: args.quick,
        bench: args.bench,
        lobes: crate::args::flatten(&args.lobe),
        materials: args.materials.clone(),
        synthesize: true,
    };
    specula_report::write_report_then_synthesize(&options, &|summary| {
        eprintln!(
            "wrote {} and {} images ({:.1} s; {})",
            summary.page.display(),
            summary.images,
            summary.took.as_secs_f64(),
            summary.timings
        );
        if summary.pending_synthesis > 0 {
            eprintln!(
                "still coming: the FPGA answers are the formula estimate until {} or more \
                 datapaths are synthesized; synthesizing them now, then writing the report \
                 again (Ctrl-C keeps the page as written)",
                summary.pending_synthesis
            );
        }
    })?;
    Ok(())
}
