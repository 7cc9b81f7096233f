//! The report's real scans (each lobe's images recomputed by `specula diff`, VTK's comparison)
//! and measured materials (every material, its fits, polar plot and renders), as the quick
//! report's test reads them from the page.

use super::{cells, check_row, flip_in, table_rows};
use crate::common::{have_python_module, ok};

/// The real scans the medical section shows, and the Debian packages that install them.
const REAL_SCANS: [(&str, &str, &str); 2] = [
    (
        "CT",
        "/usr/share/doc/invesalius-examples/examples/Cranium.inv3",
        "invesalius-examples",
    ),
    (
        "MRI",
        "/usr/share/mricron/templates/ch2.nii.gz",
        "mricron-data",
    ),
];

/// The lobes `--quick` renders the real scans with.
const QUICK_REAL_SCAN_LOBES: [&str; 3] = ["pow", "schlick", "cosquad"];

/// The measured materials in `data/rgl`, by name.
const MATERIALS: [&str; 5] = [
    "cc_ibiza_sunset_rgb",
    "cc_iris_purple_gem_rgb",
    "colodur_napoli_4f_rgb",
    "paper_white_rgb",
    "vch_golden_yellow_rgb",
];

/// The medical section's real scans: each lobe's figures recomputed by `specula diff` from the
/// images the rows name, and VTK's images beside specula's with their agreement. Without a
/// scan the section says which package installs it (and under `CI=true` the test fails);
/// without VTK it names the wheel.
pub(super) fn real_scans(document: &roxmltree::Document, text: &str, out: &std::path::Path) {
    let ci = std::env::var("CI").as_deref() == Ok("true");
    let mut shown = Vec::new();
    for (name, path, package) in REAL_SCANS {
        if !std::path::Path::new(path).is_file() {
            assert!(
                !ci,
                "{path} is missing, and CI=true requires the real {name}: apt-get install {package}"
            );
            eprintln!("skipped: the real {name} ({path}; apt-get install {package})");
            assert!(
                text.contains(&format!("The real {name} is not here"))
                    && text.contains(&format!("apt-get install {package}")),
                "the section says the real {name} is missing and names {package}"
            );
            continue;
        }
        let prefix = format!("real-{}", name.to_lowercase());
        let header = format!("PSNR vs pow on the real {name} (dB)");
        let rows = table_rows(document, &[header.as_str()]);
        let lobes: Vec<&str> = rows.iter().map(|row| row[0].as_str()).collect();
        assert_eq!(lobes, QUICK_REAL_SCAN_LOBES, "the real {name}'s lobes");
        for row in &rows {
            assert_eq!(row.len(), 4, "{row:?}");
            check_row(out, &prefix, &row[0], &row[1], &row[2], &row[3]);
        }
        shown.push((name, prefix));
    }
    // The phantom's and each scan's times: pow's frame alone, then every lobe's from one
    // march (read from the text nodes alone: `text` also holds each element's first text, so
    // each sentence twice).
    let prose: String = document
        .descendants()
        .filter(|n| n.is_text())
        .filter_map(|n| n.text())
        .collect();
    let times = prose
        .split("pow alone ")
        .skip(1)
        .map(|rest| {
            let ms = |field: &str| -> f64 {
                field
                    .trim()
                    .trim_end_matches("ms")
                    .trim()
                    .parse()
                    .unwrap_or_else(|_| panic!("a time: {field:?}"))
            };
            let (alone, rest) = rest.split_once(';').expect("pow's time, then the march's");
            let together = rest
                .split_once("from one march ")
                .and_then(|(_, t)| t.split_once(','))
                .map(|(t, _)| t)
                .expect("the march's time");
            (ms(alone), ms(together))
        })
        .collect::<Vec<_>>();
    // The phantom's CPU and (where a GPU was timed) GPU sentences, then each scan's.
    let gpu_untimed = ["GPU: not run", "a rasterizer in software"];
    let phantom = if gpu_untimed.iter().any(|said| prose.contains(said)) {
        1
    } else {
        2
    };
    assert!(
        times.len() == phantom + shown.len()
            && times
                .iter()
                .all(|&(alone, together)| alone > 0.0 && together > 0.0),
        "{times:?}"
    );
    if shown.is_empty() {
        return;
    }
    if !have_python_module("vtk", "vtk") {
        assert!(
            text.contains("VTK was not run") && text.contains("the vtk wheel"),
            "the section says VTK is missing and names the wheel"
        );
        return;
    }
    // --quick compares the first scan alone with VTK (the full report every scan).
    let compared = &shown[..1];
    let rows = table_rows(document, &["mean FLIP, specula vs VTK"]);
    assert_eq!(rows.len(), compared.len(), "{rows:?}");
    for (row, (name, prefix)) in rows.iter().zip(compared) {
        assert_eq!(row.len(), 9, "{row:?}");
        assert_eq!(row[0], format!("real {name}"));
        assert_eq!(row[1], format!("{prefix}-specula.png"));
        assert_eq!(row[2], format!("{prefix}-vtk.png"));
        // FLIP between the two images as shown, recomputed from the files.
        let output = ok(out, &["diff", &row[1], &row[2], "--format", "json"]);
        let measured: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
        let flip = measured["mean_flip"].as_f64().expect("FLIP");
        assert_eq!(row[5], format!("{flip:.5}"), "{name}: FLIP");
        // Agreement (measured at --quick's 64 x 64: CT 0.018, 3.4 %, FLIP 0.084; MRI 0.021,
        // 4.1 %, FLIP 0.12); the bounds catch a misplaced or misshaded image, not noise.
        let number = |cell: &str| -> f64 {
            cell.trim_end_matches(['%', 'x', ' '])
                .parse()
                .unwrap_or_else(|_| panic!("{row:?}"))
        };
        assert!(number(&row[3]) < 0.05, "{name}: mean difference {row:?}");
        assert!(number(&row[4]) < 10.0, "{name}: pixels off {row:?}");
        assert!(flip < 0.2, "{name}: FLIP {row:?}");
        // Timings are shown, never bounded.
        for cell in &row[6..] {
            assert!(number(cell) > 0.0, "{row:?}");
        }
    }
    for (_, prefix) in compared {
        let flip_map = out.join(format!("{prefix}-flip.png"));
        assert!(flip_map.is_file(), "{}", flip_map.display());
    }
}

/// The microfacet table: a column per material (after the lobe's), a row per lobe, then GGX
/// and Beckmann, each cell a fit error and its parameter; one verdict at most per material
/// (none where no distribution is within the margin of GGX, which the verdict line says).
fn microfacet_table(table: roxmltree::Node) {
    let cells = cells(table);
    assert_eq!(cells.len(), specula::LobeKind::ALL.len() + 2, "{cells:?}");
    assert_eq!(cells[cells.len() - 2][0], "ggx");
    assert_eq!(cells[cells.len() - 1][0], "beckmann");
    for column in 1..=MATERIALS.len() {
        let verdicts = cells
            .iter()
            .filter(|row| row[column].ends_with("(verdict)"))
            .count();
        assert!(verdicts <= 1, "{cells:?}");
        for row in &cells {
            let error: f64 = row[column]
                .split(['/', ' '])
                .find_map(|word| word.parse().ok())
                .expect("a fit error");
            assert!(error > 0.0 && error < 1.0, "{row:?}");
        }
    }
}

/// The microfacet costs: a row per lobe, per modelled GPU its term's throughput against the
/// pow distribution's and against GGX's; pow's own is 1, and within a GPU the two columns'
/// ratio is one number for every lobe (GGX's throughput over pow's).
fn microfacet_costs(table: roxmltree::Node) {
    let cells = cells(table);
    assert_eq!(cells.len(), specula::LobeKind::ALL.len(), "{cells:?}");
    let number = |text: &str| -> f64 { text.parse().expect("a number") };
    let pow = cells.iter().find(|row| row[0] == "pow").expect("pow's row");
    for column in [1, 3] {
        assert_eq!(number(&pow[column]), 1.0, "{pow:?}");
        let ratio = |row: &Vec<String>| number(&row[column]) / number(&row[column + 1]);
        for row in &cells {
            assert!(number(&row[column]) > 0.0, "{row:?}");
            // Both printed to two places: the ratio agrees to their rounding.
            assert!(
                (ratio(row) - ratio(pow)).abs() < 0.03 * ratio(pow),
                "{row:?} {pow:?}"
            );
        }
    }
}

/// The real materials' section: every material in name order, each with its table (every
/// lobe and GGX, one verdict), its polar plot and its renders, each fit's captioned with a mean
/// FLIP against the measured render.
pub(super) fn materials(document: &roxmltree::Document, out: &std::path::Path) {
    let section = document
        .descendants()
        .filter(|n| n.has_tag_name("section"))
        .find(|s| {
            s.children().any(|n| {
                n.has_tag_name("h2") && n.text().is_some_and(|t| t.ends_with("Real materials"))
            })
        })
        .expect("a real materials section");
    let names: Vec<&str> = section
        .children()
        .filter(|n| n.has_tag_name("h3"))
        .filter_map(|n| n.text())
        .collect();
    assert_eq!(names, MATERIALS);
    let mut tables: Vec<roxmltree::Node> = section
        .children()
        .filter(|n| n.has_tag_name("table"))
        .collect();
    // A table per material, then the lobes as microfacet distributions across them, then
    // what their whole microfacet terms cost.
    assert_eq!(tables.len(), MATERIALS.len() + 2);
    microfacet_costs(tables.pop().expect("the microfacet costs"));
    microfacet_table(tables.pop().expect("the microfacet table"));
    for table in tables {
        let cells = cells(table);
        // Every lobe in its better geometry, then GGX; one verdict, a lobe that meets.
        assert_eq!(cells.len(), specula::LobeKind::ALL.len() + 1, "{cells:?}");
        assert_eq!(cells.last().unwrap()[0], "ggx");
        let verdicts = cells
            .iter()
            .filter(|row| row[6] == "yes: the verdict")
            .count();
        assert_eq!(verdicts, 1, "{cells:?}");
    }
    let figures: Vec<(String, String)> = section
        .descendants()
        .filter(|n| n.has_tag_name("figure"))
        .map(|figure| {
            let source = figure
                .descendants()
                .find(|n| n.has_tag_name("img"))
                .and_then(|n| n.attribute("src"))
                .expect("an image")
                .to_owned();
            let caption: String = figure
                .descendants()
                .filter(|n| n.has_tag_name("figcaption"))
                .filter_map(|n| n.text())
                .collect();
            (source, caption)
        })
        .collect();
    for (k, name) in MATERIALS.iter().enumerate() {
        let prefix = format!("material-{}-{name}-", k + 1);
        let own: Vec<&(String, String)> = figures
            .iter()
            .filter(|(source, _)| source.starts_with(&prefix))
            .collect();
        let polar = format!("{prefix}polar.svg");
        assert!(own.iter().any(|(source, _)| *source == polar), "{polar}");
        assert!(
            own.iter()
                .any(|(source, _)| *source == format!("{prefix}measured.png")),
            "{name}: the measured render"
        );
        // Pow's fit, the verdict's lobe (unless pow) and GGX, each scored against it.
        let small = format!("{prefix}small-");
        let renders: Vec<&&(String, String)> = own
            .iter()
            .filter(|(source, _)| source.ends_with(".png") && !source.ends_with("measured.png"))
            .filter(|(source, _)| !source.starts_with(&small))
            .collect();
        assert!((2..=3).contains(&renders.len()), "{name}: {renders:?}");
        for (source, caption) in renders {
            assert!(out.join(source).is_file(), "{source}");
            let flip = flip_in(source, caption);
            assert!(flip > 0.0 && flip < 1.0, "{source}: mean FLIP {flip}");
        }
        // Then every lobe's fit and GGX, small, beside the measured material, each scored.
        let thumbnails: Vec<&&(String, String)> = own
            .iter()
            .filter(|(source, _)| source.starts_with(&small) && !source.ends_with("measured.png"))
            .collect();
        assert_eq!(thumbnails.len(), 14, "{name}: {thumbnails:?}");
        for (source, caption) in thumbnails {
            assert!(out.join(source).is_file(), "{source}");
            let flip = flip_in(source, caption);
            assert!(flip > 0.0 && flip < 1.0, "{source}: FLIP {flip}");
        }
    }
}
