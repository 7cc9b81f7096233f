//! The README and `docs/` as a user meets them: every shell command in them runs as written,
//! the two set-up commands lead the README and are what CI runs, and the reference is what
//! `--help` prints.
//!
//! `UPDATE_REFERENCE=1 cargo test -p specula-cli --test suite readme::` rewrites the reference from
//! `--help` after a command changes.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::have_tool;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(relative: &str) -> String {
    std::fs::read_to_string(root().join(relative)).unwrap_or_else(|e| panic!("{relative}: {e}"))
}

/// The documents whose commands a user runs: the README, then `docs/*.md` but the reference.
fn documents() -> Vec<String> {
    let mut docs: Vec<String> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".md") && name != "reference.md")
        .map(|name| format!("docs/{name}"))
        .collect();
    docs.sort();
    docs.insert(0, "README.md".to_owned());
    docs
}

/// The lines of every ```sh block, in order, with the block's index.
fn shell_lines(markdown: &str) -> Vec<(usize, String)> {
    let mut lines = Vec::new();
    let (mut block, mut inside) = (0, false);
    for line in markdown.lines() {
        let trimmed = line.trim();
        if !inside && trimmed == "```sh" {
            inside = true;
        } else if inside && trimmed == "```" {
            inside = false;
            block += 1;
        } else if inside && !trimmed.is_empty() && !trimmed.starts_with('#') {
            lines.push((block, trimmed.to_owned()));
        }
    }
    lines
}

/// The set-up commands, the first block of the README: what CI runs itself.
const SET_UP: [&str; 2] = [
    "cargo run --release -p specula-cli -- report",
    "cargo test --workspace --locked",
];

/// Commands shown but not run here, each with the reason; every one must still be in a
/// document, so the list cannot outlive what it excuses.
const NOT_RUN: [(&str, &str); 2] = [
    (
        "fuzz/run",
        "installs cargo-fuzz from crates.io and fuzzes for minutes; cargo test replays its corpus",
    ),
    (
        "clinical-ct.nii",
        "makes and renders a clinical-size CT (226 MB on disk, 3.4 GB of memory with VTK's); \
         suite/volume.rs runs --resample on a small grid",
    ),
];

#[test]
fn the_two_set_up_commands_lead_the_readme_and_ci_runs_the_test_command() {
    let readme = read("README.md");
    let first: Vec<String> = shell_lines(&readme)
        .into_iter()
        .filter(|(block, _)| *block == 0)
        .map(|(_, line)| line)
        .collect();
    assert_eq!(first.len(), 2, "the README's first block: {first:?}");
    for (line, command) in first.iter().zip(SET_UP) {
        assert!(
            line.starts_with(command),
            "README set-up line {line:?} is not {command:?}"
        );
    }
    let ci = read(".ci/run");
    assert!(
        ci.lines().any(|line| line.trim() == SET_UP[1]),
        ".ci/run does not run {:?}",
        SET_UP[1]
    );
}

/// The tools a command line needs besides specula: `(tool, version flag, Debian package)`.
fn tools(line: &str) -> Vec<(&'static str, &'static str, &'static str)> {
    let mut needed = Vec::new();
    if line.contains("iverilog") {
        needed.extend([("iverilog", "-V", "iverilog"), ("vvp", "-V", "iverilog")]);
    }
    if line.contains("hw synth") {
        needed.extend([
            ("yosys", "-V", "yosys"),
            ("nextpnr-ice40", "--version", "nextpnr-ice40"),
        ]);
    }
    needed
}

/// Starts `line` (a `specula serve`), waits for the address it prints, fetches the page there
/// and stops it.
fn serve(line: &str, directory: &Path, path: &str) {
    let mut server = Command::new("bash")
        .args(["-c", &format!("exec {line}")])
        .current_dir(directory)
        .env("PATH", path)
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (sender, receiver) = std::sync::mpsc::channel();
    let forward = |stream: Box<dyn Read + Send>| {
        let sender = sender.clone();
        std::thread::spawn(move || {
            for text in BufReader::new(stream).lines().map_while(Result::ok) {
                let _ = sender.send(text);
            }
        });
    };
    forward(Box::new(server.stdout.take().unwrap()));
    forward(Box::new(server.stderr.take().unwrap()));
    let deadline = Instant::now() + Duration::from_secs(30);
    let address = loop {
        let remaining = deadline.saturating_duration_since(Instant::now());
        let text = receiver
            .recv_timeout(remaining)
            .unwrap_or_else(|_| panic!("{line}: printed no address in 30 s"));
        if let Some(at) = text.find("http://") {
            break text[at + 7..].split('/').next().unwrap().to_owned();
        }
    };
    let mut stream = std::net::TcpStream::connect(&address).unwrap();
    write!(
        stream,
        "GET / HTTP/1.1\r\nHost: {address}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut answer = String::new();
    stream.read_to_string(&mut answer).unwrap();
    server.kill().unwrap();
    server.wait().unwrap();
    assert!(
        answer.starts_with("HTTP/1.1 200") && answer.contains("<html"),
        "{line}: {answer:.200}"
    );
}

#[test]
fn every_command_in_the_readme_and_docs_runs_as_written() {
    let binary = Path::new(env!("CARGO_BIN_EXE_specula"));
    let path = format!(
        "{}:{}",
        binary.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut excused = vec![false; NOT_RUN.len()];
    for document in documents() {
        let directory = tempfile::tempdir().unwrap();
        // The measured materials the documents name as `data/rgl/...`, run from the clone's
        // root as written: the repository's own.
        std::os::unix::fs::symlink(root().join("data"), directory.path().join("data")).unwrap();
        let lines = shell_lines(&read(&document));
        assert!(
            document != "README.md" || lines.len() > SET_UP.len(),
            "the README shows no commands beyond the set-up"
        );
        for (block, line) in lines {
            if document == "README.md" && block == 0 {
                continue;
            }
            if let Some(k) = NOT_RUN.iter().position(|(start, _)| line.contains(start)) {
                excused[k] = true;
                continue;
            }
            let program = line.split_whitespace().next().unwrap();
            assert!(
                ["specula", "iverilog"].contains(&program),
                "{document}: {line:?} runs neither specula nor a tool this test knows"
            );
            if !tools(&line)
                .into_iter()
                .all(|(tool, flag, package)| have_tool(tool, flag, package))
            {
                continue;
            }
            let compiles = line.contains("specula isa") || line.contains("--target gpu-");
            if compiles && !crate::common::have_gpu_compilers() {
                continue;
            }
            if line.starts_with("specula serve") {
                serve(&line, directory.path(), &path);
                continue;
            }
            let started = Instant::now();
            let output = Command::new("bash")
                .args(["-o", "pipefail", "-c", &line])
                .current_dir(directory.path())
                .env("PATH", &path)
                .env("SPECULA_CACHE_DIR", crate::common::test_cache())
                .stdin(Stdio::null())
                .output()
                .unwrap();
            eprintln!(
                "{document}: {line} ({:.1} s)",
                started.elapsed().as_secs_f64()
            );
            assert!(
                output.status.success(),
                "{document}: {line:?} exited with {}: {}",
                output.status,
                String::from_utf8_lossy(&output.stderr)
            );
        }
    }
    for ((start, reason), found) in NOT_RUN.iter().zip(excused) {
        assert!(
            found,
            "{start} is excused ({reason}) but no document shows it"
        );
    }
}

/// `specula <args> --help`.
fn help(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_specula"))
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .args(args)
        .arg("--help")
        .output()
        .unwrap();
    assert!(output.status.success(), "{args:?} --help");
    String::from_utf8(output.stdout).unwrap()
}

/// The commands a help page lists (`help` left out), with their one-line descriptions
/// (clap continues a long one on the next, deeper-indented line).
fn commands(page: &str) -> Vec<(String, String)> {
    let mut found: Vec<(String, String)> = Vec::new();
    let section = page
        .split("\nCommands:\n")
        .nth(1)
        .and_then(|rest| rest.split("\n\n").next())
        .unwrap_or_default();
    for line in section.lines() {
        let text = line.trim();
        if line.starts_with("  ") && !line.starts_with("   ") {
            let (name, about) = text.split_once(' ').unwrap_or((text, ""));
            found.push((name.to_owned(), about.trim().to_owned()));
        } else if let Some(last) = found.last_mut() {
            last.1.push(' ');
            last.1.push_str(text);
        }
    }
    found.retain(|(name, _)| name != "help");
    found
}

/// The README's reference table and `docs/reference.md`, as `--help` makes them.
fn reference() -> (String, String) {
    let mut table = String::from("| command | what it does |\n|---|---|\n");
    let mut pages = String::from(
        "# Reference\n\nEvery command's `--help`, as it prints it (generated; \
         `crates/cli/tests/suite/readme.rs` checks it).\n",
    );
    let mut add = |args: Vec<&str>, about: &str| {
        let name = format!("specula {}", args.join(" "));
        let anchor = name.replace(' ', "-");
        table += &format!(
            "| [`{name}`](docs/reference.md#{anchor}) | {} |\n",
            about.replace('|', "\\|")
        );
        pages += &format!("\n## {name}\n\n```text\n{}```\n", help(&args));
    };
    for (command, about) in commands(&help(&[])) {
        let page = help(&[&command]);
        add(vec![&command], &about);
        for (sub, about) in commands(&page) {
            add(vec![&command, &sub], &about);
        }
    }
    (table, pages)
}

const TABLE_START: &str =
    "<!-- reference: generated from --help by crates/cli/tests/suite/readme.rs -->\n";
const TABLE_END: &str = "<!-- end of reference -->";

#[test]
fn the_reference_is_what_help_prints() {
    let (table, pages) = reference();
    let readme = read("README.md");
    let (before, rest) = readme
        .split_once(TABLE_START)
        .expect("the README's reference markers");
    let (_, after) = rest.split_once(TABLE_END).expect("the reference's end");
    let expected_readme = format!("{before}{TABLE_START}{table}{TABLE_END}{after}");
    if std::env::var("UPDATE_REFERENCE").as_deref() == Ok("1") {
        std::fs::write(root().join("README.md"), &expected_readme).unwrap();
        std::fs::write(root().join("docs/reference.md"), &pages).unwrap();
        return;
    }
    assert!(
        readme == expected_readme,
        "the README's command table differs from --help; run UPDATE_REFERENCE=1 cargo test -p \
            specula-cli --test suite readme::"
    );
    assert!(
        read("docs/reference.md") == pages,
        "docs/reference.md differs from --help; run UPDATE_REFERENCE=1 cargo test -p specula-cli \
            --test suite readme::"
    );
}
