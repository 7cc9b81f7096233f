//! `specula recommend`: its answer is confirmed by `specula analyze`, its front is a front,
//! and bad requests are refused in one line.

use crate::common::{ok, specula};
use serde_json::Value;

/// A command line's JSON answer (`line` split at spaces).
fn json(line: &str) -> Vec<Value> {
    let directory = tempfile::tempdir().unwrap();
    let args: Vec<&str> = line.split_whitespace().collect();
    let output = ok(directory.path(), &args);
    serde_json::from_slice::<Value>(&output.stdout)
        .unwrap()
        .as_array()
        .unwrap()
        .clone()
}

#[test]
fn the_recommendation_is_what_analyze_measures() {
    let rows = json("recommend --target gpu-nvidia --n 64 --max-error 1% --format json");
    assert_eq!(rows.len(), specula::LobeKind::ALL.len());
    let analyzed = json("analyze --n 64 --format json");
    for row in &rows {
        let lobe = row["lobe"].as_str().unwrap();
        let figures = analyzed
            .iter()
            .find(|a| a["lobe"] == lobe)
            .unwrap_or_else(|| panic!("{lobe} not analyzed"));
        let error = figures["epicentre_max_rel"].as_f64().unwrap();
        // analyze samples 10^5 angles per zone, recommend 2 x 10^4: the same maximum to 1e-4.
        let reported = row["error"].as_f64().unwrap();
        assert!(
            (reported - error).abs() <= 1e-4 * error.max(1e-12) + 1e-12,
            "{lobe}: recommend {reported}, analyze {error}"
        );
        assert_eq!(row["meets"].as_bool().unwrap(), error <= 0.01, "{lobe}");
    }
    // The met lobes come first, cheapest first.
    let met: Vec<f64> = rows
        .iter()
        .take_while(|r| r["meets"].as_bool().unwrap())
        .map(|r| r["rate"].as_f64().unwrap())
        .collect();
    assert!(met.windows(2).all(|w| w[0] >= w[1]), "{met:?}");
    assert!(rows
        .iter()
        .any(|r| r["lobe"] == "pow" && r["meets"] == true));
}

#[test]
fn the_front_is_undominated_and_everything_else_is_dominated() {
    let rows =
        json("recommend --target gpu-amd --n 8..512 --max-error 2 --zone whole --format json");
    let point = |r: &Value| (r["error"].as_f64().unwrap(), r["rate"].as_f64().unwrap());
    for row in &rows {
        let (error, rate) = point(row);
        let dominated = rows.iter().any(|other| {
            let (e, r) = point(other);
            e <= error && r >= rate && (e < error || r > rate)
        });
        assert_eq!(row["pareto"].as_bool().unwrap(), !dominated, "{row}");
    }
}

#[test]
fn an_impossible_accuracy_leaves_the_exact_lobe_and_bad_requests_are_refused() {
    let directory = tempfile::tempdir().unwrap();
    let args: Vec<&str> = "recommend --target gpu-amd --max-error 1e-9 --zone whole"
        .split_whitespace()
        .collect();
    let output = ok(directory.path(), &args);
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(text.starts_with("pow: the cheapest lobe within"), "{text}");
    for bad in [
        "recommend --target tpu --max-error 1%",
        "recommend --target cpu --max-error 0",
        "recommend --target cpu --max-error nan",
        "recommend --target cpu --max-error 1 --n 0..5",
        "recommend --target cpu --max-error 1 --n 64..8",
    ] {
        let bad: Vec<&str> = bad.split_whitespace().collect();
        let output = specula(directory.path(), &bad);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{bad:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{bad:?}: {stderr}");
    }
}

/// On the FPGA only lobes with a fixed-point datapath can meet, each named with the word
/// length costed, and the datapath's error is what `specula hw table` measures there.
#[test]
fn fpga_answers_come_from_the_datapaths() {
    let rows = json("recommend --target fpga --n 64 --max-error 2% --format json");
    let best = &rows[0];
    assert_eq!(best["meets"], true, "{best}");
    let datapath = best["datapath"].as_str().expect("a datapath is named");
    let (name, bits) = datapath.split_once(" at ").unwrap();
    let bits = bits.trim_end_matches(" bits");
    let table = json(&format!(
        "hw table --lobe {name} --n 64 --samples 20001 --bits {bits}..{bits} --format json"
    ));
    let measured = table[0]["rows"][0]["errors"]["epicentre_max_rel"]
        .as_f64()
        .unwrap();
    assert!(
        (best["error"].as_f64().unwrap() - measured).abs() <= 1e-3 * measured,
        "{best} vs {measured}"
    );
    for row in &rows {
        if row["datapath"].is_null() {
            assert_eq!(row["meets"], false, "{row}");
        }
    }
}

/// For scripts, `--format csv` is data alone: the header first (units in its names), then
/// numbers, ids and booleans; the error in % as the table gives it, the same figure the JSON
/// gives as a fraction, and the throughput against pow's; the verdict on stderr.
#[test]
fn csv_is_numbers_under_a_header_with_the_verdict_on_stderr() {
    let directory = tempfile::tempdir().unwrap();
    let line = "recommend --target cpu --n 64 --max-error 1% --format csv";
    let output = ok(
        directory.path(),
        &line.split_whitespace().collect::<Vec<_>>(),
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    // The cheapest, or, where measured rates overlap, the most accurate of those tied for it.
    assert!(
        stderr.contains("the cheapest lobe within 1 %")
            || stderr.contains("tied for the cheapest within 1 %"),
        "{stderr}"
    );
    let csv = String::from_utf8(output.stdout).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "lobe,meets,error (%),\"rate (evals/s, 1 thread)\",\"median pass (evals/s, 1 thread)\",\
            \"fastest pass (evals/s, 1 thread)\",x pow's throughput (higher is better),energy \
            ratio,pareto"
    );
    let answer = json(&line.replace("csv", "json"));
    let mut rows = 0;
    for row in lines {
        rows += 1;
        let cells: Vec<&str> = row.split(',').collect();
        assert_eq!(cells.len(), 9, "{row}");
        let number = |cell: &str| cell.parse::<f64>().unwrap_or_else(|_| panic!("{row}"));
        assert!(["true", "false"].contains(&cells[1]) && ["true", "false"].contains(&cells[8]));
        let rate = number(cells[3]);
        assert!(rate > 0.0 && number(cells[7]) > 0.0, "{row}");
        // The rate is the fastest pass, at or above the median one.
        let (median, fastest) = (number(cells[4]), number(cells[5]));
        assert!(
            fastest == rate && median <= fastest && median > 0.0,
            "{row}"
        );
        let same = answer.iter().find(|a| a["lobe"] == cells[0]).unwrap();
        // The CSV's % is the JSON's fraction; runs differ in their measured rates only.
        let fraction = same["error"].as_f64().unwrap();
        assert!((number(cells[2]) - 100.0 * fraction).abs() <= 1e-9 * (1.0 + 100.0 * fraction));
        if cells[0] == "pow" {
            assert_eq!(number(cells[6]), 1.0, "{row}");
        }
    }
    assert_eq!(rows, answer.len());
}
