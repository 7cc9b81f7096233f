//! `specula bench first-run`: what a newcomer meets, measured as they meet it. Each job runs
//! this binary in a fresh, empty cache folder (`SPECULA_CACHE_DIR`; nothing compiled,
//! synthesized, searched or stored before) and prints its wall time and, for the report, the
//! time of each section and of the page's first and second writing (the second only where
//! the FPGA's synthesis came after the first).

use std::process::{Command, Stdio};
use std::time::Instant;

use specula_render::measured::BUNDLED_MATERIALS;

use crate::commands::CommandResult;

/// The jobs: a name and the arguments (`{material}` stands for a bundled material's file).
const JOBS: [(&str, &[&str]); 4] = [
    ("report --quick", &["report", "--quick", "--out", "report"]),
    ("report", &["report", "--out", "report"]),
    ("fit (classic)", &["fit", "--material", "{material}"]),
    (
        "fit --model microfacet",
        &["fit", "--material", "{material}", "--model", "microfacet"],
    ),
];

/// Runs every job cold and prints what it took.
pub fn run() -> CommandResult {
    let binary = std::env::current_exe().map_err(|e| format!("cannot find this binary: {e}"))?;
    let &(name, bytes) = BUNDLED_MATERIALS
        .first()
        .ok_or("no bundled material to fit")?;
    println!(
        "each job on an empty cache folder, {} threads:",
        rayon::current_num_threads()
    );
    for (job, args) in JOBS {
        let folder = specula_temporaries::dir("first-run-")
            .map_err(|e| format!("cannot make a scratch folder: {e}"))?;
        let material = folder.path().join(format!("{name}.bsdf"));
        std::fs::write(&material, bytes).map_err(|e| format!("{}: {e}", material.display()))?;
        let args: Vec<String> = args
            .iter()
            .map(|arg| arg.replace("{material}", &material.display().to_string()))
            .collect();
        let started = Instant::now();
        let output = Command::new(&binary)
            .args(&args)
            .current_dir(folder.path())
            .env("SPECULA_CACHE_DIR", folder.path().join("cache"))
            .stdin(Stdio::null())
            .output()
            .map_err(|e| format!("cannot run {}: {e}", binary.display()))?;
        let wall = started.elapsed().as_secs_f64();
        if !output.status.success() {
            return Err(format!(
                "specula {job} failed: {}",
                String::from_utf8_lossy(&output.stderr).trim()
            ));
        }
        println!("{job}: {wall:.1} s cold");
        let stderr = String::from_utf8_lossy(&output.stderr);
        for line in stderr
            .lines()
            .filter(|line| line.starts_with("wrote ") || line.starts_with("still coming"))
        {
            println!("  {line}");
        }
    }
    Ok(())
}
