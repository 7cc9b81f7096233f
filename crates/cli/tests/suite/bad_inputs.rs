//! The bad-input corpus (`tests/bad-inputs/`): every scene there must be refused with exit
//! code 2, a one-line message containing its `# expect:` text, and no output file. Plus bad
//! command-line values, inputs that are nasty but valid, and outputs that must survive a
//! failed or interrupted render.

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use crate::common::{ok, specula};

/// A copy of the corpus in a fresh directory, so that nothing is written into the sources.
fn corpus_copy() -> tempfile::TempDir {
    let directory = tempfile::tempdir().expect("temporary directory");
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad-inputs");
    for entry in std::fs::read_dir(source).expect("corpus") {
        let path = entry.expect("entry").path();
        std::fs::copy(
            &path,
            directory.path().join(path.file_name().expect("name")),
        )
        .expect("copy");
    }
    directory
}

/// A render to `out.png` large enough to take a while on any machine, for the tests that
/// stop one part-way.
const SLOW_RENDER: [&str; 9] = [
    "render",
    "--width",
    "8000",
    "--height",
    "8000",
    "--samples",
    "2",
    "-o",
    "out.png",
];

fn files(directory: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(directory)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn every_scene_in_the_corpus_is_refused_with_its_message() {
    let directory = corpus_copy();
    let before = files(directory.path());
    let scenes: Vec<&String> = before
        .iter()
        .filter(|name| name.ends_with(".toml"))
        .collect();
    assert!(scenes.len() >= 15, "the corpus lost files: {scenes:?}");
    for scene in scenes {
        let text = std::fs::read_to_string(directory.path().join(scene)).expect("scene");
        let expected = text
            .lines()
            .next()
            .and_then(|line| line.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{scene} has no `# expect:` first line"));
        let output = specula(directory.path(), &["render", scene, "-o", "out.png"]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{scene}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{scene}: expected `{expected}` in: {stderr}"
        );
        assert_eq!(
            stderr.trim_end().lines().count(),
            1,
            "{scene}: one line: {stderr}"
        );
    }
    assert_eq!(
        files(directory.path()),
        before,
        "no output and no temporary file appeared"
    );
}

#[test]
fn bad_command_line_values_name_the_valid_range() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let cases: [(&[&str], &str); 9] = [
        (
            &["render", "--n", "0"],
            "n must be a finite number in [1, 1000]",
        ),
        (
            &["render", "--n", "-1"],
            "n must be a finite number in [1, 1000]",
        ),
        (
            &["render", "--n", "NaN"],
            "n must be a finite number in [1, 1000]",
        ),
        (
            &["render", "--n", "1e9"],
            "n must be a finite number in [1, 1000]",
        ),
        (&["render", "--lobe", "phong"], "valid lobes: pow, schlick"),
        (&["render", "--width", "0"], "1..=16384"),
        (&["render", "--width", "100000"], "1..=16384"),
        (&["render", "--samples", "9"], "1..=8"),
        (
            &["eval", "--lobe", "cosquad", "--n", "64", "--cos", "NaN"],
            "[-1, 1]",
        ),
    ];
    for (args, message) in cases {
        let output = specula(directory.path(), args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    assert!(files(directory.path()).is_empty());
}

const CAMERA: &str = "[camera]\neye = [0.0, -5.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, \
    1.0]\nfov = 40.0\n[render]\nwidth = 96\nheight = 64\n[[lights]]\nkind = \"point\"\nposition = \
    [0.0, -1.0, 0.5]\nintensity = [1.0, 1.0, 1.0]\n";

/// Degenerate triangles are dropped with a warning; a huge triangle through the camera's
/// plane (clipped) and a light inside the geometry render without a NaN pixel.
#[test]
fn nasty_but_valid_meshes_render_without_nan() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    std::fs::write(
        path.join("degenerate.obj"),
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n",
    )
    .expect("write");
    std::fs::write(
        path.join("huge.obj"),
        "v -1e7 -1e7 0\nv 1e7 -1e7 0\nv 0 1e7 0\nv -1e7 1e3 -1e6\nv 1e7 1e3 -1e6\nv 0 1e3 1e7\nf 1 \
            2 3\nf 4 5 6\n",
    )
    .expect("write");
    let scene = format!(
        "{CAMERA}[[objects]]\nshape = \"mesh\"\npath = \"degenerate.obj\"\n[[objects]]\nshape = \
            \"mesh\"\npath = \"huge.obj\"\n[objects.material]\nlobe = \"logexp-rr\"\nn = 1000\n"
    );
    std::fs::write(path.join("nasty.toml"), scene).expect("write");
    for shading in ["flat", "gouraud", "phong"] {
        let output = ok(
            path,
            &[
                "render",
                "nasty.toml",
                "--shading",
                shading,
                "-o",
                "out.exr",
            ],
        );
        assert!(
            String::from_utf8_lossy(&output.stderr).contains("skipped 1 degenerate triangle(s)")
        );
        let image = specula_render::read_image(&path.join("out.exr")).expect("EXR");
        assert!(
            image.pixels().iter().all(|p| p.is_finite()),
            "{shading}: a pixel is not finite"
        );
    }
}

/// A render that fails, or is killed part-way, leaves the previous output as it was and no
/// temporary file.
#[test]
fn earlier_outputs_survive_failed_and_interrupted_renders() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    let previous = b"the previous output".to_vec();
    std::fs::write(path.join("out.png"), &previous).expect("write");
    // A failing render: a bad scene.
    std::fs::write(path.join("bad.toml"), "[camera\n").expect("write");
    assert_eq!(
        specula(path, &["render", "bad.toml", "-o", "out.png"])
            .status
            .code(),
        Some(2)
    );
    // A write that cannot happen: the destination's folder does not exist.
    let output = specula(
        path,
        &[
            "render",
            "--width",
            "32",
            "--height",
            "32",
            "-o",
            "missing/out.png",
        ],
    );
    assert_eq!(
        output.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    // A render killed part-way.
    let mut child = Command::new(env!("CARGO_BIN_EXE_specula"))
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .current_dir(path)
        .args(SLOW_RENDER)
        .spawn()
        .expect("start a render");
    std::thread::sleep(Duration::from_millis(400));
    let still_running = child.try_wait().expect("status").is_none();
    child.kill().expect("kill");
    let _ = child.wait();
    assert!(
        still_running,
        "the render finished before it could be interrupted"
    );
    assert_eq!(std::fs::read(path.join("out.png")).expect("read"), previous);
    assert_eq!(
        files(path),
        ["bad.toml", "out.png"],
        "no partial or temporary file"
    );
}

/// Outputs as Unix tools write them: a device or FIFO in place, `-` to standard output, a
/// symlink followed (the link stays a link), an existing file's permissions kept, one file
/// not named twice, and temporary files of dead runs cleaned up.
#[test]
fn outputs_follow_unix_conventions() {
    use std::os::unix::fs::{FileTypeExt, PermissionsExt};
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    let verilog = |output: &str| {
        specula(
            path,
            &[
                "hw", "verilog", "--lobe", "cosquad", "--bits", "8", "-o", output,
            ],
        )
    };
    // A device stays a device.
    assert!(verilog("/dev/null").status.success());
    let null = std::fs::metadata("/dev/null").expect("exists");
    assert!(
        null.file_type().is_char_device(),
        "/dev/null is still a device"
    );
    // Standard output.
    let stdout = verilog("-");
    assert!(String::from_utf8_lossy(&stdout.stdout).contains("module specula_cosquad_w8"));
    // A FIFO is written in place, read by whoever opened it.
    let fifo = path.join("pipe.v");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo")
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).expect("read the FIFO"))
    };
    assert!(verilog("pipe.v").status.success());
    assert!(reader
        .join()
        .expect("reader")
        .contains("module specula_cosquad_w8"));
    assert!(std::fs::symlink_metadata(&fifo)
        .expect("exists")
        .file_type()
        .is_fifo());
    // A symlink is followed; the link stays a link, the target is replaced.
    std::fs::write(path.join("target.v"), "old").expect("write");
    std::os::unix::fs::symlink("target.v", path.join("link.v")).expect("symlink");
    assert!(verilog("link.v").status.success());
    assert!(std::fs::symlink_metadata(path.join("link.v"))
        .expect("exists")
        .file_type()
        .is_symlink());
    assert!(std::fs::read_to_string(path.join("target.v"))
        .expect("read")
        .contains("module"));
    // An existing file's permissions are kept.
    std::fs::write(path.join("private.v"), "old").expect("write");
    std::fs::set_permissions(
        path.join("private.v"),
        std::fs::Permissions::from_mode(0o640),
    )
    .expect("chmod");
    assert!(verilog("private.v").status.success());
    let mode = std::fs::metadata(path.join("private.v"))
        .expect("exists")
        .permissions()
        .mode();
    assert_eq!(mode & 0o777, 0o640);
    // The module and its testbench in one file would lose one of them.
    let same = specula(
        path,
        &[
            "hw",
            "verilog",
            "--lobe",
            "cosquad",
            "--bits",
            "8",
            "-o",
            "same.v",
            "--testbench",
            "./same.v",
        ],
    );
    assert_eq!(same.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&same.stderr).contains("its own file"));
    assert!(!path.join("same.v").exists());
    // A dead run's temporary file is removed by the next write there; a live one's is not.
    let dead = path.join(".specula-999999999-abcdef.tmp");
    let live = path.join(format!(".specula-{}-abcdef.tmp", std::process::id()));
    std::fs::write(&dead, "left by a killed run").expect("write");
    std::fs::write(&live, "being written").expect("write");
    assert!(verilog("fresh.v").status.success());
    assert!(
        !dead.exists(),
        "a dead process's temporary file is cleaned up"
    );
    assert!(
        live.exists(),
        "a running process's temporary file is left alone"
    );
}

/// SIGINT or SIGTERM: exit 130 with one line, the earlier output untouched, no file left.
#[test]
fn interrupted_commands_leave_nothing_behind() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    std::fs::write(path.join("out.png"), "the previous output").expect("write");
    for signal in ["-INT", "-TERM"] {
        let child = Command::new(env!("CARGO_BIN_EXE_specula"))
            .env("SPECULA_CACHE_DIR", crate::common::test_cache())
            .current_dir(path)
            .args(SLOW_RENDER)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("start a render");
        std::thread::sleep(Duration::from_millis(400));
        assert!(Command::new("kill")
            .arg(signal)
            .arg(child.id().to_string())
            .status()
            .expect("kill")
            .success());
        let output = child.wait_with_output().expect("wait");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(130), "{signal}: {stderr}");
        assert_eq!(stderr.trim(), "interrupted", "{signal}");
        assert_eq!(
            files(path),
            ["out.png"],
            "{signal}: no partial or temporary file"
        );
        assert_eq!(
            std::fs::read_to_string(path.join("out.png")).expect("read"),
            "the previous output"
        );
    }
}

/// Standard output's reader gone: a quiet exit (141, as `ls | head` reports); a full disk:
/// one line and status 1. Never a panic.
#[test]
fn standard_output_errors_end_like_unix_tools() {
    // `models` prints with `println!`, `sample` writes its own buffered stream; the reader
    // goes before either writes: it is closed before the command starts (closed after, a
    // command whose output fits the pipe could write it all first, and did under load).
    let commands = [&["models"][..], &["sample", "--lobe", "pow", "--n", "8"]];
    for args in commands {
        let (reader, writer) = std::io::pipe().expect("a pipe");
        drop(reader);
        let child = Command::new(env!("CARGO_BIN_EXE_specula"))
            .env("SPECULA_CACHE_DIR", crate::common::test_cache())
            .args(args)
            .stdout(writer)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("start");
        let output = child.wait_with_output().expect("wait");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(141), "{args:?}: {stderr}");
        assert!(output.stderr.is_empty(), "{args:?}: {stderr}");
    }
    for args in commands {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full");
        let output = Command::new(env!("CARGO_BIN_EXE_specula"))
            .env("SPECULA_CACHE_DIR", crate::common::test_cache())
            .args(args)
            .stdout(full)
            .output()
            .expect("run");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{args:?}: {stderr}");
        assert!(
            stderr.contains("writing to standard output"),
            "{args:?}: {stderr}"
        );
    }
}

/// A huge unknown key or id is quoted in part (its length named), and costs no edit-distance
/// search over its megabytes.
#[test]
fn huge_identifiers_are_quoted_in_part() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    let key = "x".repeat(5_000_000);
    std::fs::write(
        path.join("huge-key.toml"),
        format!("[camera]\neye = [0, -5, 1]\ntarget = [0, 0, 0]\n{key} = 1\n"),
    )
    .expect("write");
    let started = std::time::Instant::now();
    let output = specula(path, &["render", "huge-key.toml", "-o", "out.png"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr.contains("(5000000 characters)"),
        "{}",
        &stderr[..stderr.len().min(300)]
    );
    assert!(
        stderr.len() < 400,
        "the message quotes at most a line: {} bytes",
        stderr.len()
    );
    assert!(started.elapsed() < Duration::from_secs(10), "no hang");
    let lobe = "y".repeat(100_000);
    let output = specula(path, &["eval", "--lobe", &lobe, "--n", "8", "--cos", "0.5"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr.contains("(100000 characters)") && stderr.len() < 400,
        "{stderr}"
    );
}

/// An 8 x 8 render written to `name` in `directory`, and its bytes: a real image whose header
/// the test below patches.
fn small_render(directory: &Path, name: &str) -> Vec<u8> {
    let args = ["render", "--width", "8", "--height", "8", "-o", name];
    assert!(specula(directory, &args).status.success());
    std::fs::read(directory.join(name)).expect("read")
}

/// CRC-32 (IEEE), for patching a PNG header in the test below.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0_u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0xedb8_8320 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

/// Every size an input controls is bounded before anything is allocated or read: non-regular
/// files, files over the input limit, images declaring more pixels than allowed, too many
/// objects, a grid over the pixel limit.
#[test]
fn sizes_an_input_declares_are_bounded_before_reading() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    let refused = |args: &[&str], expected: &str| {
        let started = std::time::Instant::now();
        let output = specula(path, args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{args:?}: expected `{expected}` in {stderr}"
        );
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(
            started.elapsed() < Duration::from_secs(10),
            "{args:?}: no hang"
        );
    };
    let camera = "[camera]\neye = [0, -5, 1]\ntarget = [0, 0, 0]\n";
    let mesh_scene = |name: &str, mesh: &str| {
        std::fs::write(
            path.join(name),
            format!("{camera}[[objects]]\nshape = \"mesh\"\npath = \"{mesh}\"\n"),
        )
        .expect("write");
    };
    // A mesh that is a symlink to an endless device, and a scene that is a FIFO.
    std::os::unix::fs::symlink("/dev/zero", path.join("zero.obj")).expect("symlink");
    mesh_scene("zero.toml", "zero.obj");
    refused(
        &["render", "zero.toml", "-o", "out.png"],
        "is a device, not a regular file",
    );
    assert!(Command::new("mkfifo")
        .arg(path.join("fifo.toml"))
        .status()
        .expect("mkfifo")
        .success());
    refused(
        &["render", "fifo.toml", "-o", "out.png"],
        "is a FIFO, not a regular file",
    );
    // A mesh over the input limit (raised or lowered by --max-input-mib).
    std::fs::write(path.join("big.obj"), "v 0 0 0\n".repeat(300_000)).expect("write");
    mesh_scene("big.toml", "big.obj");
    refused(
        &[
            "render",
            "big.toml",
            "-o",
            "out.png",
            "--max-input-mib",
            "1",
        ],
        "above the input limit of 1048576 bytes",
    );
    // A PNG whose header declares 20000 x 20000 pixels (a real 8 x 8 image, patched).
    let mut png = small_render(path, "small.png");
    png[16..20].copy_from_slice(&20_000_u32.to_be_bytes());
    png[20..24].copy_from_slice(&20_000_u32.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    std::fs::write(path.join("huge.png"), png).expect("write");
    refused(
        &["diff", "small.png", "huge.png"],
        "declares 20000x20000 pixels",
    );
    // An EXR whose header declares 100000 x 100000 (its data and display windows patched).
    let mut exr = small_render(path, "small.exr");
    for name in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let at = exr
            .windows(name.len())
            .position(|w| w == name)
            .expect("the attribute")
            + name.len()
            + 4;
        for (k, value) in [0_i32, 0, 99_999, 99_999].into_iter().enumerate() {
            exr[at + 4 * k..at + 4 * k + 4].copy_from_slice(&value.to_le_bytes());
        }
    }
    std::fs::write(path.join("huge.exr"), exr).expect("write");
    refused(
        &["diff", "small.exr", "huge.exr"],
        "declares 100000x100000 pixels",
    );
    // Too many objects.
    let many = format!(
        "{camera}{}",
        "[[objects]]\nshape = \"plane\"\n".repeat(10_001)
    );
    std::fs::write(path.join("many.toml"), many).expect("write");
    refused(&["render", "many.toml", "-o", "out.png"], "at most 10000");
    // A grid over the pixel limit.
    refused(
        &[
            "render",
            "--grid",
            "lobes=pow,schlick",
            "--width",
            "8192",
            "--height",
            "8192",
            "-o",
            "grid.png",
        ],
        "above the limit of 67108864",
    );
    let outputs: Vec<String> = files(path)
        .into_iter()
        .filter(|name| name.starts_with("out") || name.starts_with("grid"))
        .collect();
    assert!(outputs.is_empty(), "no output written: {outputs:?}");
}
