//! The `specula` binary: documented JSON schemas, values from closed forms, and bad input
//! answered with a one-line message and exit code 2, never a panic.

use assert_cmd::Command;
use serde_json::Value;

fn specula(args: &[&str]) -> std::process::Output {
    Command::cargo_bin("specula")
        .expect("binary built")
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .args(args)
        .output()
        .expect("runs")
}

fn json(args: &[&str]) -> Value {
    let output = specula(args);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("valid JSON")
}

#[test]
fn models_lists_every_registered_lobe() {
    let output = specula(&["models"]);
    assert!(output.status.success());
    let text = String::from_utf8_lossy(&output.stdout);
    for id in [
        "pow",
        "schlick",
        "schlick-mod",
        "cheb2-thesis",
        "cheb2",
        "logexp",
        "cosquad",
    ] {
        assert!(
            text.lines().any(|line| line.starts_with(&format!("{id} "))),
            "{id} missing"
        );
    }
    let rows = json(&["models", "--format", "json"]);
    assert_eq!(
        rows.as_array().map(Vec::len),
        Some(specula::LobeKind::ALL.len())
    );
}

#[test]
fn analyze_json_has_the_documented_schema_and_closed_form_values() {
    let rows = json(&[
        "analyze",
        "--lobe",
        "pow,cosquad,schlick",
        "--n",
        "16",
        "--format",
        "json",
    ]);
    let rows = rows.as_array().expect("an array");
    assert_eq!(rows.len(), 3);
    for row in rows {
        for key in [
            "lobe",
            "n",
            "epicentre_max_rel",
            "epicentre_max_abs",
            "bloom_max_abs",
            "tail_max_abs",
            "rms",
            "energy_ratio",
            "max_albedo",
            "ops",
        ] {
            assert!(row.get(key).is_some(), "missing {key} in {row}");
        }
        assert!(row["ops"].is_object());
    }
    // pow is the reference; K_4 at n = 2^4 is exactly t^16 (a = 1); the lobe-normalised pow's
    // largest albedo is at normal incidence, (n+1)/(n+2).
    let pow = &rows[0];
    assert_eq!(pow["epicentre_max_rel"].as_f64(), Some(0.0));
    assert!((pow["max_albedo"].as_f64().unwrap() - 17.0 / 18.0).abs() < 1e-9);
    assert!(rows[1]["bloom_max_abs"].as_f64().unwrap() < 1e-12);
    assert!(rows[2]["epicentre_max_rel"].as_f64().unwrap() > 0.01);
}

#[test]
fn analyze_defaults_cover_every_lobe_and_exponent() {
    let rows = json(&["analyze", "--format", "json"]);
    assert_eq!(
        rows.as_array().map(Vec::len),
        Some(specula::LobeKind::ALL.len() * 11)
    );
    let csv = specula(&[
        "analyze", "--lobe", "logexp", "--n", "2,3", "--format", "csv",
    ]);
    assert_eq!(String::from_utf8_lossy(&csv.stdout).lines().count(), 3);
}

#[test]
fn claims_json_has_the_documented_schema() {
    let claims = json(&["claims", "--format", "json"]);
    let claims = claims.as_array().expect("an array");
    // SPEC's seven, then the hardware claim, which needs Yosys and nextpnr: without them (not
    // allowed when CI=true) it is there with a null verdict saying why.
    assert_eq!(claims.len(), 8);
    let tools_required = std::env::var("CI").as_deref() == Ok("true");
    for (k, claim) in claims.iter().enumerate() {
        for key in ["claim", "measured", "verdict", "reading", "figures"] {
            assert!(claim.get(key).is_some(), "missing {key} in {claim}");
        }
        match claim["verdict"].as_str() {
            Some(verdict) => {
                assert!(["holds", "does not hold", "holds with qualification"].contains(&verdict))
            }
            None => assert!(k == 7 && !tools_required, "{claim}"),
        }
    }
    assert!(claims[7]["claim"]
        .as_str()
        .expect("text")
        .starts_with("8: "));
}

#[test]
fn eval_matches_closed_forms() {
    let schlick = json(&[
        "eval", "--lobe", "schlick", "--n", "1", "--cos", "0.3", "--json",
    ]);
    assert!((schlick["value"].as_f64().unwrap() - 0.3).abs() < 1e-15);
    let pow = json(&[
        "eval", "--lobe", "pow", "--n", "4", "--angle", "60", "--json",
    ]);
    assert!((pow["value"].as_f64().unwrap() - 0.0625).abs() < 1e-12);
    assert_eq!(pow["zone"], "bloom");
    let below = json(&[
        "eval", "--lobe", "logexp", "--n", "10", "--cos", "-0.5", "--json",
    ]);
    assert_eq!(below["value"].as_f64(), Some(0.0));
    // A negative number in exponent notation is a value, not a flag.
    let tiny = json(&[
        "eval", "--lobe", "logexp", "--n", "10", "--cos", "-1e-5", "--json",
    ]);
    assert_eq!(tiny["t"].as_f64(), Some(-1e-5));
    // Where t^n underflows to 0 a relative error is undefined: absolute only, never `inf`.
    let underflow = json(&[
        "eval", "--lobe", "schlick", "--n", "1000", "--cos", "1e-300", "--json",
    ]);
    assert_eq!(underflow["reference"].as_f64(), Some(0.0));
    assert!(underflow["rel_error"].is_null() && underflow["abs_error"].as_f64() > Some(0.0));
    let text = specula(&[
        "eval", "--lobe", "schlick", "--n", "1000", "--cos", "1e-300",
    ]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("absolute") && !text.contains("inf"), "{text}");
}

#[test]
fn bad_input_is_a_one_line_error_with_exit_code_two() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["eval", "--lobe", "phong", "--n", "10", "--cos", "0.5"],
            "schlick-mod",
        ),
        (
            &["eval", "--lobe", "pow", "--n", "0", "--cos", "0.5"],
            "[1, 1000]",
        ),
        (
            &["eval", "--lobe", "pow", "--n", "-1", "--cos", "0.5"],
            "[1, 1000]",
        ),
        (
            &["hw", "table", "--bits", "-3"],
            "`-3` is not a word length",
        ),
        (
            &["eval", "--lobe", "cosqaud", "--n", "8", "--cos", "0.5"],
            "did you mean 'cosquad'?",
        ),
        (
            &["hw", "table", "--lobe", "logexp-mitchel"],
            "did you mean 'logexp-mitchell'?",
        ),
        (&["models", "--n", "-1e-3"], "[1, 1000]"),
        (
            &["eval", "--lobe", "pow", "--n", "NaN", "--cos", "0.5"],
            "[1, 1000]",
        ),
        (
            &["eval", "--lobe", "pow", "--n", "1e9", "--cos", "0.5"],
            "[1, 1000]",
        ),
        (
            &["eval", "--lobe", "pow", "--n", "10", "--cos", "1.5"],
            "[-1, 1]",
        ),
        (&["eval", "--lobe", "pow", "--n", "10"], "--cos"),
        (
            &[
                "eval",
                "--lobe",
                "cosquad:v=12",
                "--n",
                "10",
                "--cos",
                "0.5",
            ],
            "[0, 10]",
        ),
        (&["analyze", "--lobe", "pow,blinn"], "valid lobes"),
        (&["analyze", "--n", "2000"], "[1, 1000]"),
        (&["analyze", "--format", "xml"], "table"),
        (
            &["shader", "--lobe", "pow", "--n", "64", "--lang", "blender"],
            "osl, mtlx, mitsuba",
        ),
        (
            &[
                "shader",
                "--lobe",
                "cosquad:v=11",
                "--n",
                "64",
                "--lang",
                "osl",
            ],
            "[0, 10]",
        ),
        (
            &[
                "shader", "--lobe", "pow", "--n", "1001", "--lang", "mitsuba",
            ],
            "[1, 1000]",
        ),
        (
            &[
                "shader",
                "--lobe",
                "pow",
                "--n",
                "64",
                "--normalisation",
                "lobe",
                "--lang",
                "osl",
            ],
            "takes no --normalisation",
        ),
    ];
    for (args, expected) in cases {
        let output = specula(args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{args:?}: expected '{expected}' in: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
        assert!(output.stdout.is_empty(), "{args:?} wrote output");
    }
}

/// `analyze --format csv` is data alone: a header, then every figure of the JSON as a number
/// with all its digits (the epicentre's relative error in %, as the table gives it), the
/// energy's convergence as a boolean and one column per kind of operation. (Equal within
/// 1e-14: `serde_json` reads floats to within an ulp, not always to the nearest.)
#[test]
fn analyze_csv_carries_the_json_figures_as_numbers() {
    let args = ["analyze", "--lobe", "schlick,cosquad", "--n", "16,256"];
    let output = specula(&[&args[..], &["--format", "csv"]].concat());
    assert!(output.status.success());
    let csv = String::from_utf8(output.stdout).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|line| line.split(',').collect()).collect();
    let reports = json(&[&args[..], &["--format", "json"]].concat());
    let reports = reports.as_array().unwrap();
    assert_eq!(rows.len(), reports.len());
    for (row, report) in rows.iter().zip(reports) {
        assert_eq!(row.len(), header.len());
        let cell = |name: &str| row[header.iter().position(|h| *h == name).unwrap()];
        let number = |name: &str| cell(name).parse::<f64>().unwrap();
        assert_eq!(cell("lobe"), report["lobe"].as_str().unwrap());
        assert_eq!(number("n"), report["n"].as_f64().unwrap());
        let near = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs();
        let relative = report["epicentre_max_rel"].as_f64().unwrap();
        assert!(near(number("epicentre max rel (%)"), 100.0 * relative));
        for (column, field) in [
            ("epicentre max abs", "epicentre_max_abs"),
            ("rms", "rms"),
            ("energy ratio", "energy_ratio"),
            ("max albedo", "max_albedo"),
        ] {
            let expected = report[field].as_f64().unwrap();
            assert!(near(number(column), expected), "{column}: {expected}");
        }
        assert_eq!(
            cell("energy converged"),
            report["energy_converged"].to_string()
        );
        let ops = &report["ops"];
        for name in ["add", "mul", "square", "cmp"] {
            assert_eq!(
                number(&format!("ops {name}")),
                ops[name].as_f64().unwrap(),
                "{name}"
            );
        }
    }
}

/// Every table a script may read as `--format csv` is data alone: its header is the first
/// line, and each cell below is a number, `true`/`false`, an id (no spaces, no `%`) or empty;
/// only a model's formula is text.
#[test]
fn csv_tables_hold_data_alone() {
    // Two images for `diff`: the default scene with pow and with schlick.
    let directory = tempfile::tempdir().unwrap();
    let image = |lobe: &str| {
        let path = directory.path().join(format!("{lobe}.png"));
        let path = path.to_str().unwrap().to_owned();
        let args = [
            "render", "--width", "32", "--height", "18", "--lobe", lobe, "-o", &path,
        ];
        assert!(specula(&args).status.success(), "{args:?}");
        path
    };
    let (pow, schlick) = (image("pow"), image("schlick"));
    let commands: [&[&str]; 7] = [
        &["diff", &pow, &schlick],
        &[
            "hw",
            "table",
            "--lobe",
            "schlick,cosquad",
            "--bits",
            "10..11",
            "--n",
            "64",
        ],
        &["analyze", "--lobe", "cosquad,sg", "--n", "8,512"],
        &[
            "recommend",
            "--target",
            "gpu-amd",
            "--n",
            "64",
            "--max-error",
            "2%",
        ],
        &["models"],
        &["lobe", "check", "=t^n"],
        &[
            "sample",
            "--lobe",
            "cosquad",
            "--n",
            "64",
            "--theta-o",
            "30",
            "--count",
            "3",
        ],
    ];
    let identifier = |cell: &str| {
        !cell.is_empty()
            && cell
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_.:=@^".contains(c))
    };
    for command in commands {
        let output = specula(&[command, &["--format", "csv"]].concat());
        assert!(output.status.success(), "{command:?}");
        let csv = String::from_utf8(output.stdout).unwrap();
        let mut lines = csv.lines();
        let header = lines.next().unwrap_or_default();
        let columns = csv_cells(header);
        assert!(
            columns
                .iter()
                .all(|c| !c.is_empty() && c.parse::<f64>().is_err()),
            "{command:?}: the first line is not a header: {header}"
        );
        let mut rows = 0;
        for line in lines {
            rows += 1;
            let cells = csv_cells(line);
            assert_eq!(cells.len(), columns.len(), "{command:?}: {line}");
            for (column, cell) in columns.iter().zip(&cells) {
                let data = cell.is_empty()
                    || cell.parse::<f64>().is_ok()
                    || cell == "true"
                    || cell == "false"
                    || identifier(cell);
                assert!(
                    column == "formula" || (data && !cell.contains('%')),
                    "{command:?}: {column} = {cell:?} in {line}"
                );
            }
        }
        assert!(rows > 0, "{command:?}: no rows");
    }
}

/// A CSV line's cells (RFC 4180: a quoted cell may hold commas, `""` is a quote).
fn csv_cells(line: &str) -> Vec<String> {
    let (mut cells, mut cell, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => cells.push(std::mem::take(&mut cell)),
            _ => cell.push(c),
        }
    }
    cells.push(cell);
    cells
}
