//! Your own lobe through the whole workbench: `docs/lobes/k4.toml` (the thesis's `K_4`
//! written by hand) must give the built-in `cosquad`'s figures and pixels, a new lobe
//! (`docs/lobes/quartic.toml`, energy-matched to `t^n` by construction) must go through
//! every command with figures its closed forms predict, and bad formulas must be refused in
//! one line each, before any work.

use crate::common;

use crate::common::{ok, specula};
use serde_json::Value;

fn lobe_file(name: &str) -> String {
    format!("@{}/../../docs/lobes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn json(directory: &std::path::Path, args: &[&str]) -> Vec<Value> {
    let output = ok(directory, args);
    serde_json::from_slice::<Value>(&output.stdout)
        .expect("JSON")
        .as_array()
        .expect("an array")
        .clone()
}

/// Every number of `analyze` for K_4 by hand equals cosquad's to 1e-6 (relative), at
/// exponents on both sides of `n = 2^4` where cosquad's mask changes.
#[test]
fn k4_by_hand_reproduces_cosquad_analysis() {
    let directory = tempfile::tempdir().unwrap();
    let lobes = format!("{},cosquad", lobe_file("k4.toml"));
    let rows = json(
        directory.path(),
        &[
            "analyze",
            "--lobe",
            &lobes,
            "--n",
            "3,16,64,500",
            "--format",
            "json",
        ],
    );
    let (mine, theirs): (Vec<&Value>, Vec<&Value>) =
        rows.iter().partition(|row| row["lobe"] == "k4-by-hand");
    assert_eq!((mine.len(), theirs.len()), (4, 4));
    for (a, b) in mine.iter().zip(&theirs) {
        let (a, b) = (a.as_object().unwrap(), b.as_object().unwrap());
        let mut compared = 0;
        for (key, value) in a {
            if let (Some(x), Some(y)) = (value.as_f64(), b[key].as_f64()) {
                assert!(
                    (x - y).abs() <= 1e-6 * y.abs().max(1e-12),
                    "{key} at n = {}: {x} vs {y}",
                    a["n"]
                );
                compared += 1;
            }
        }
        assert!(compared >= 8, "too few figures compared: {a:?}");
    }
}

/// K_4 by hand renders the same pixels as cosquad: rasterized on the CPU and on the GPU, and
/// lit by an environment.
#[test]
fn k4_by_hand_renders_as_cosquad() {
    let directory = tempfile::tempdir().unwrap();
    let k4 = lobe_file("k4.toml");
    let mut runs: Vec<Vec<&str>> = vec![
        vec!["--width", "240", "--height", "135"],
        vec![
            "--width",
            "160",
            "--height",
            "90",
            "--env",
            "sky",
            "--samples",
            "2",
        ],
    ];
    if common::have_gpu() {
        runs.push(vec![
            "--width",
            "240",
            "--height",
            "135",
            "--backend",
            "gpu",
        ]);
    }
    for (k, run) in runs.iter().enumerate() {
        let mut images = Vec::new();
        for lobe in [k4.as_str(), "cosquad"] {
            let out = format!("{k}-{}.png", images.len());
            let mut args = vec!["render", "--lobe", lobe, "-o", &out];
            args.extend(run);
            ok(directory.path(), &args);
            images.push(std::fs::read(directory.path().join(&out)).unwrap());
        }
        assert!(images[0] == images[1], "{run:?}: the renders differ");
    }
}

/// A new lobe everywhere: the biweight kernel, sized so that its integral is `t^n`'s
/// `1 / (n + 1)` (`docs/lobes/quartic.toml`), so its energy ratio is 1 by construction;
/// its value at a cosine is the closed form; it samples (Newton on its own tail) and passes
/// the chi-square test; recommend ranks it; it renders, marches a volume, exports to every
/// language, and appears in every section of the report.
#[test]
fn a_new_lobe_goes_through_every_command() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let quartic = lobe_file("quartic.toml");
    let n = 64.0_f64;
    let (w, t) = (1.875 / (n + 1.0), 0.99_f64);
    let u = ((1.0 - t) / w).min(1.0);
    let eval = ok(
        dir,
        &["eval", "--lobe", &quartic, "--n", "64", "--cos", "0.99"],
    );
    let text = String::from_utf8_lossy(&eval.stdout);
    let reported: f64 = text
        .lines()
        .find_map(|line| line.strip_prefix("value"))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no value in {text}"));
    // eval prints four significant digits.
    assert!(
        (reported - (1.0 - u * u).powi(2)).abs() < 5e-5,
        "{reported}"
    );

    let analysis = json(
        dir,
        &[
            "analyze", "--lobe", &quartic, "--n", "8,64,512", "--format", "json",
        ],
    );
    for row in &analysis {
        let ratio = row["energy_ratio"].as_f64().unwrap();
        assert!(
            (ratio - 1.0).abs() < 1e-6,
            "energy ratio {ratio} at n = {}",
            row["n"]
        );
    }

    let test = ok(
        dir,
        &[
            "sample",
            "--test",
            "--lobe",
            &quartic,
            "--n",
            "64",
            "--samples",
            "200000",
        ],
    );
    let text = String::from_utf8_lossy(&test.stdout);
    assert!(text.contains("newton") && text.contains("pass"), "{text}");

    let ranked = json(
        dir,
        &[
            "recommend",
            "--target",
            "gpu-nvidia",
            "--max-error",
            "1%",
            "--lobe",
            &quartic,
            "--format",
            "json",
        ],
    );
    assert!(
        ranked.iter().any(|row| row["lobe"] == "quartic"),
        "{ranked:?}"
    );

    ok(
        dir,
        &[
            "render",
            "--lobe",
            &quartic,
            "--width",
            "96",
            "--height",
            "54",
            "-o",
            "quartic.png",
        ],
    );
    ok(
        dir,
        &[
            "volume",
            "--input",
            "phantom",
            "--size",
            "24",
            "--width",
            "64",
            "--height",
            "64",
            "--lobe",
            &quartic,
            "-o",
            "volume.png",
        ],
    );
    for lang in [
        "wgsl", "glsl", "hlsl", "msl", "spirv", "osl", "mtlx", "mitsuba",
    ] {
        ok(
            dir,
            &[
                "shader",
                "--lobe",
                &quartic,
                "--n",
                "64",
                "--lang",
                lang,
                "-o",
                &format!("quartic.{lang}"),
            ],
        );
    }
    // One measured material, so that the materials section fits the lobe too.
    let materials = dir.join("materials");
    std::fs::create_dir(&materials).unwrap();
    std::os::unix::fs::symlink(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/rgl/paper_white_rgb.bsdf"),
        materials.join("paper_white_rgb.bsdf"),
    )
    .unwrap();
    ok(
        dir,
        &[
            "report",
            "--quick",
            "--out",
            "report",
            "--lobe",
            &quartic,
            "--materials",
            "materials",
        ],
    );
    let page = std::fs::read_to_string(dir.join("report/index.html")).unwrap();
    // A section shows the lobe in its text or in one of its figures (plots' legends).
    let shows = |section: &str| {
        section.contains("quartic")
            || section.split("src=\"").skip(1).any(|rest| {
                let file = rest.split('"').next().unwrap_or_default();
                std::fs::read_to_string(dir.join("report").join(file))
                    .is_ok_and(|figure| figure.contains("quartic"))
            })
    };
    let missing: Vec<&str> = page
        .split("<h2>")
        .skip(1)
        .filter(|section| !shows(section))
        .map(|section| section.split('<').next().unwrap_or_default())
        .collect();
    // The hardware section lists datapaths, which a user lobe does not have.
    assert!(
        missing.iter().all(|s| s.contains("Hardware")),
        "sections without the lobe: {missing:?}"
    );
}

/// Bad formulas, files and values: exit code 2, one line naming the problem, before any
/// work (a 10 MB formula and a 10,000-deep one are refused at once).
/// `lobe check` states a lobe's shape with figures its closed form gives: `t^n / (1 + t)`
/// peaks at 1/2 where `t = 1`, lies `t / (1 + t)` below `t^n` relatively (1/2 at the
/// mirror direction, the epicentre's worst), and carries `(n + 1) int_0^1 t^n / (1 + t) dt`
/// of `t^n`'s energy (here by the midpoint rule); it warns that the lobe does not reach 1.
/// `t^n` itself gets no warning. The CSV is numbers under one header, nothing before it.
#[test]
fn lobe_check_states_the_peak_the_error_and_the_energy() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let output = ok(
        dir,
        &[
            "lobe",
            "check",
            "=t^n/(1+t)",
            "--n",
            "8",
            "--format",
            "json",
        ],
    );
    let rows: Vec<Value> = serde_json::from_slice(&output.stdout).expect("JSON");
    let [row] = rows.as_slice() else {
        panic!("one exponent, one row: {rows:?}");
    };
    let number = |field: &str| {
        row[field]
            .as_f64()
            .unwrap_or_else(|| panic!("{field}: {row}"))
    };
    assert_eq!(number("n"), 8.0);
    assert!((number("peak") - 0.5).abs() < 1e-9, "{row}");
    assert!(number("peak_degrees") < 1e-3, "{row}");
    assert!((number("at_t_1") - 0.5).abs() < 1e-12, "{row}");
    assert!(
        (number("epicentre_error_percent") - 50.0).abs() < 0.1,
        "{row}"
    );
    let steps = 100_000;
    let energy = 9.0
        * (0..steps)
            .map(|i| {
                let t = (f64::from(i) + 0.5) / f64::from(steps);
                t.powi(8) / (1.0 + t)
            })
            .sum::<f64>()
        / f64::from(steps);
    assert!(
        (number("energy_ratio") - energy).abs() < 1e-5,
        "{row} {energy}"
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("warning: the lobe is 0.500000 at t = 1 (n = 8.000), not 1: it dims"),
        "{stderr}"
    );
    let plain = ok(
        dir,
        &["lobe", "check", "=t^n", "--n", "1..100", "--format", "csv"],
    );
    assert!(
        plain.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&plain.stderr)
    );
    let csv = String::from_utf8_lossy(&plain.stdout);
    let mut lines = csv.lines();
    assert!(lines.next().unwrap().starts_with("n,peak,"), "{csv}");
    let rows: Vec<Vec<f64>> = lines
        .map(|line| {
            line.split(',')
                .map(|cell| cell.parse().expect(cell))
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 5, "{csv}");
    for row in rows {
        // Peak 1 at the mirror direction, no error, t^n's own energy.
        assert_eq!(&row[1..6], &[1.0, 1.0, 0.0, 1.0, 0.0], "{csv}");
        assert!((row[6] - 1.0).abs() < 1e-4, "{csv}");
    }
}

#[test]
fn bad_formulas_get_one_line_each() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    std::fs::write(
        dir.join("huge.toml"),
        format!(
            "name = \"huge\"\nformula = \"{}t\"\n",
            "t+".repeat(5_000_000)
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("deep.toml"),
        format!(
            "name = \"deep\"\nformula = \"{}t{}\"\n",
            "(".repeat(10_000),
            ")".repeat(10_000)
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("typo.toml"),
        "name = \"typo\"\nformul = \"t ^ n\"\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("range.toml"),
        "name = \"range\"\nformula = \"t ^ (n * \
        k)\"\n[parameters.k]\ndefault = 1\nmin = 1\nmax = 2\n",
    )
    .unwrap();
    std::fs::create_dir(dir.join("folder.toml")).unwrap();
    let cases: [(&[&str], &str); 12] = [
        (
            &["eval", "--lobe", "=tt ^ n", "--n", "8", "--cos", "0.5"],
            "unknown name 'tt'; did you mean 't'?",
        ),
        (
            &["eval", "--lobe", "=t ^ n +", "--n", "8", "--cos", "0.5"],
            "column 8: expected a number",
        ),
        (
            &["eval", "--lobe", "=2 * t ^ n", "--n", "8", "--cos", "0.5"],
            "above 1",
        ),
        (
            &[
                "eval",
                "--lobe",
                "=log(t) * 0 + t",
                "--n",
                "8",
                "--cos",
                "0.5",
            ],
            "not finite",
        ),
        (&["analyze", "--lobe", "=t - 0.5", "--n", "8"], "negative"),
        (
            &["eval", "--lobe", "@huge.toml", "--n", "8", "--cos", "0.5"],
            "bytes",
        ),
        (
            &["eval", "--lobe", "@deep.toml", "--n", "8", "--cos", "0.5"],
            "lobe 'deep'",
        ),
        (
            &["eval", "--lobe", "@typo.toml", "--n", "8", "--cos", "0.5"],
            "typo.toml:2:1",
        ),
        (
            &[
                "eval",
                "--lobe",
                "@range.toml:k=3",
                "--n",
                "8",
                "--cos",
                "0.5",
            ],
            "k = 3 is out of range",
        ),
        (
            &["eval", "--lobe", "@folder.toml", "--n", "8", "--cos", "0.5"],
            "not a regular file",
        ),
        (
            &[
                "render",
                "--lobe",
                "=t ^ (n - 40)",
                "--n",
                "8",
                "-o",
                "x.png",
            ],
            "at n = 8",
        ),
        (
            &["hw", "verilog", "--lobe", "@range.toml"],
            "`range` has no datapath: it computes pow of a real exponent",
        ),
    ];
    for (args, says) in cases {
        let started = std::time::Instant::now();
        let output = specula(dir, args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
        assert!(
            started.elapsed().as_secs_f64() < 5.0,
            "{args:?} took {:?}",
            started.elapsed()
        );
    }
    assert!(
        !dir.join("x.png").exists(),
        "a refused render wrote its output"
    );
}
