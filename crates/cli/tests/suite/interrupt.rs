//! Interrupted runs leave nothing behind: `specula report` stopped by `SIGINT` or `SIGTERM` at
//! random moments (12 runs, one in each twelfth of an uninterrupted run's length) leaves no
//! temporary file in its output folder or in the temporary folder it was given, and every file it
//! finished is whole (images decode, pages and plots parse, JSON reads).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use rand::{RngExt, SeedableRng};

/// Runs of the report, each stopped at a random moment of its own share of the run's length
/// (stratified, so that every part of the run is tried, however few the runs).
const RUNS: usize = 12;

/// Every file under `folder`, folders walked.
fn files_under(folder: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![folder.to_owned()];
    while let Some(folder) = pending.pop() {
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        for entry in entries.map(|e| e.expect("entry")) {
            let path = entry.path();
            if entry.file_type().expect("type").is_dir() {
                pending.push(path.clone());
            }
            found.push(path);
        }
    }
    found
}

/// Why `path` is not a whole file of its kind, if it is not.
fn broken(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).ok()?;
    let text = || String::from_utf8(bytes.clone()).map_err(|e| e.to_string());
    let xml = |text: String| {
        let options = roxmltree::ParsingOptions {
            allow_dtd: true,
            ..roxmltree::ParsingOptions::default()
        };
        roxmltree::Document::parse_with_options(&text, options)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    let checked = match path.extension().and_then(|e| e.to_str()) {
        Some("png" | "exr" | "hdr") => specula_render::read_image(path)
            .map(|_| ())
            .map_err(|e| e.to_string()),
        Some("svg" | "html") => text().and_then(xml),
        Some("json") => text().and_then(|t| {
            serde_json::from_str::<serde_json::Value>(&t)
                .map(|_| ())
                .map_err(|e| e.to_string())
        }),
        _ => Ok(()),
    };
    checked.err().map(|e| format!("{}: {e}", path.display()))
}

fn report(out: &Path, temporary: &Path) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_specula"));
    command
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .args(["report", "--quick", "--out"])
        .arg(out)
        .env("TMPDIR", temporary)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    command
}

#[test]
fn a_report_interrupted_at_any_moment_leaves_no_temporary_and_only_whole_files() {
    let scratch = tempfile::tempdir().expect("scratch");
    let temporary = scratch.path().join("tmp");
    std::fs::create_dir(&temporary).expect("folder");
    // The first run fills the synthesis cache if it is empty (minutes with Yosys, once per
    // machine, shared with the other tests); the second, as
    // long as the interrupted ones would be, gives their moments' range.
    let mut length = Duration::ZERO;
    for attempt in ["cold", "warm"] {
        let started = Instant::now();
        let whole = report(&scratch.path().join(attempt), &temporary)
            .output()
            .expect("runs");
        length = started.elapsed();
        assert!(
            whole.status.success(),
            "{}",
            String::from_utf8_lossy(&whole.stderr)
        );
    }
    let mut random = rand_pcg::Pcg64::seed_from_u64(47);
    let mut stopped_with_files = 0;
    for run in 0..RUNS {
        let out = scratch.path().join(format!("run-{run}"));
        let signal = if run % 2 == 0 { "INT" } else { "TERM" };
        let moment = length.mul_f64((run as f64 + random.random_range(0.0..1.0)) / RUNS as f64);
        let mut child = report(&out, &temporary).spawn().expect("starts");
        std::thread::sleep(moment);
        let _ = Command::new("kill")
            .args([format!("-{signal}"), child.id().to_string()])
            .status()
            .expect("kill runs");
        let deadline = Instant::now() + Duration::from_secs(60);
        let status = loop {
            if let Some(status) = child.try_wait().expect("waits") {
                break status;
            }
            assert!(
                Instant::now() < deadline,
                "run {run}: still running 60 s after SIG{signal}"
            );
            std::thread::sleep(Duration::from_millis(10));
        };
        let when = format!("run {run}, SIG{signal} after {moment:?} (exit {status})");
        let files = files_under(&out);
        let left: Vec<_> = files_under(&out)
            .into_iter()
            .chain(files_under(&temporary))
            .filter(|p| {
                let name = p.file_name().unwrap().to_string_lossy();
                name.starts_with(".specula-") || name.ends_with(".tmp")
            })
            .collect();
        assert!(left.is_empty(), "{when}: left behind {left:?}");
        let broken: Vec<String> = files.iter().filter_map(|p| broken(p)).collect();
        assert!(broken.is_empty(), "{when}: {broken:?}");
        if !files.is_empty() {
            stopped_with_files += 1;
        }
    }
    // The moments fell while the report was writing, not only before it began.
    assert!(
        stopped_with_files >= RUNS / 4,
        "only {stopped_with_files} of {RUNS} runs were stopped after writing a file"
    );
}
