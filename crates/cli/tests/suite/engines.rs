//! `specula shader --lang threejs` and `--lang babylon`: ES modules that Node.js parses, whose
//! lobe functions are the GLSL ES 3.00 export of the same lobe, with `n` a uniform exactly where
//! the GLSL export can take it. (That the engines render with them as specula does is
//! `.ci/engines-check`'s to show, in Chromium.)

use specula::LobeKind;

use crate::common::{have_tool, ok, specula};

#[test]
fn the_engine_modules_parse_and_carry_the_glsl_export() {
    if !have_tool("node", "--version", "nodejs") {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let lobes = LobeKind::ALL
        .iter()
        .map(ToString::to_string)
        .chain(["=exp2(n * (t - 1) * 1.4427)".to_owned()]);
    for (k, lobe) in lobes.enumerate() {
        let (geometry, normalisation) = [("phong", "none"), ("blinn", "lafortune")][k % 2];
        let common = [
            "shader",
            "--lobe",
            &lobe,
            "--n",
            "48",
            "--geometry",
            geometry,
            "--normalisation",
            normalisation,
        ];
        let glsl_of = |n_input: bool| {
            let mut args = common.to_vec();
            args.extend(["--lang", "glsl", "--glsl-version", "300es"]);
            if n_input {
                args.push("--n-input");
            }
            let output = specula(d, &args);
            output
                .status
                .success()
                .then(|| String::from_utf8_lossy(&output.stdout).into_owned())
        };
        let taking_n = glsl_of(true);
        let glsl = taking_n.clone().or_else(|| glsl_of(false)).unwrap();
        let body: Vec<&str> = glsl
            .lines()
            .filter(|line| !line.starts_with("#version") && !line.starts_with("precision "))
            .collect();
        for engine in ["threejs", "babylon"] {
            let file = format!("{engine}-{k}.mjs");
            let mut args = common.to_vec();
            args.extend(["--lang", engine, "-o", &file]);
            ok(d, &args);
            let module = std::fs::read_to_string(d.join(&file)).unwrap();
            let label = format!("{lobe} {engine}");
            assert!(
                module.contains(&body.join("\n")),
                "{label}: not the GLSL export"
            );
            assert_eq!(
                module.contains("export const N_RANGE = null;"),
                taking_n.is_none(),
                "{label}: N_RANGE against the GLSL export's --n-input"
            );
            let check = std::process::Command::new("node")
                .arg("--check")
                .arg(d.join(&file))
                .output()
                .unwrap();
            assert!(
                check.status.success(),
                "{label}: {}",
                String::from_utf8_lossy(&check.stderr)
            );
        }
    }
    let refused = specula(
        d,
        &[
            "shader",
            "--lobe",
            "pow",
            "--n",
            "8",
            "--lang",
            "threejs",
            "--n-input",
        ],
    );
    assert!(!refused.status.success());
    let message = String::from_utf8_lossy(&refused.stderr);
    assert!(
        message.contains("--n-input is for naga's languages") && message.lines().count() == 1,
        "{message}"
    );
}
