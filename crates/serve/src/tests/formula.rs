//! The explorer with a formula of the user's: the lobe it spells, its refusals, and the limits
//! a request for one obeys.

use axum::http::StatusCode;

use super::connections::spawn_server;
use super::{json, served_png};

/// `text` percent-encoded for a query value (every byte but letters and digits).
fn encoded(text: &str) -> String {
    text.bytes()
        .map(|b| {
            if b.is_ascii_alphanumeric() {
                char::from(b).to_string()
            } else {
                format!("%{b:02X}")
            }
        })
        .collect()
}

/// The thesis's `K_4`, `cosquad`'s default, written as a formula.
const K4: &str = "let a = (n + 1) / 17; max(0, a * (t - 1) + 1) ^ 16";

/// A formula given as `lobe==FORMULA` is every view's lobe: its curve is the built-in
/// `cosquad` it spells (the library's values, computed here), its analysis is `cosquad`'s,
/// and its render is `cosquad`'s, byte for byte (the formula's batch path computes `K_4` as
/// `cosquad`'s kernel does).
#[tokio::test]
async fn a_formula_is_plotted_analysed_and_rendered_as_the_lobe_it_spells() {
    use specula::{Exponent, Lobe, LobeKind};
    let formula = format!("lobe={}", encoded(&format!("={K4}")));
    let n = 40.0;
    let builtin = Lobe::new(LobeKind::CosQuad { v: 4 }, Exponent::new(n));

    let (status, data) = json(&format!(
        "/api/evaluate?{formula}&n={n}&geometry=phong&normalisation=lobe"
    ))
    .await;
    assert_eq!(status, StatusCode::OK, "{data}");
    assert!(data["lobe"].as_str().expect("name").starts_with("formula"));
    let angles = data["angles_deg"].as_array().expect("angles");
    let values = data["values"].as_array().expect("values");
    assert_eq!(angles.len(), values.len());
    let mut nonzero = 0;
    for (angle, value) in angles.iter().zip(values) {
        let t = angle.as_f64().expect("number").to_radians().cos();
        let (served, expected) = (value.as_f64().expect("number"), builtin.eval(t));
        assert!(
            (served - expected).abs() <= 1e-12,
            "at {angle} degrees: {served} against cosquad's {expected}"
        );
        nonzero += usize::from(expected > 1e-3);
    }
    assert!(nonzero > 100, "the curve covers the lobe");
    // Every other view's data too: the served cosquad's, to rounding.
    let (_, reference) = json(&format!(
        "/api/evaluate?lobe=cosquad&n={n}&geometry=phong&normalisation=lobe"
    ))
    .await;
    for key in ["polar", "albedo", "slice", "error"] {
        let (a, b) = (
            data[key].as_array().expect("array"),
            reference[key].as_array().expect("array"),
        );
        assert_eq!(a.len(), b.len(), "{key}");
        for (x, y) in a.iter().zip(b) {
            let (x, y) = (x.as_f64().expect("number"), y.as_f64().expect("number"));
            assert!(
                (x - y).abs() <= 1e-9 * y.abs().max(1.0),
                "{key}: {x} against {y}"
            );
        }
    }

    let (status, report) = json(&format!("/api/analyze?{formula}&n={n}")).await;
    assert_eq!(status, StatusCode::OK, "{report}");
    let (_, expected) = json(&format!("/api/analyze?lobe=cosquad&n={n}")).await;
    let (a, b) = (
        report["epicentre_max_rel"].as_f64().expect("number"),
        expected["epicentre_max_rel"].as_f64().expect("number"),
    );
    assert!((a - b).abs() <= 1e-9 * b, "{a} against {b}");
    assert_eq!(report["costs"][0]["target"], "cpu");

    let render = |lobe: &str| format!("/api/render?object=sphere&{lobe}&n={n}&size=48");
    let served = served_png(&render(&formula), (48, 48)).await;
    assert!(
        served == served_png(&render("lobe=cosquad"), (48, 48)).await,
        "the formula's render is not cosquad's"
    );
    // The other renders take it too.
    served_png(
        &format!("/api/volume?{formula}&n={n}&size=32&volume=marschner-lobb"),
        (32, 32),
    )
    .await;
    served_png(
        &format!("/api/environment?{formula}&n={n}&size=32&spp=1"),
        (32, 18),
    )
    .await;
}

/// A render names its lobe with its parameters: `cosquad:v=2` is not drawn as `cosquad`.
#[tokio::test]
async fn a_render_keeps_the_lobes_parameters() {
    let uri = |lobe: &str| format!("/api/render?object=sphere&lobe={lobe}&n=40&size=32");
    assert!(
        served_png(&uri("cosquad%3Av%3D1"), (32, 32)).await
            != served_png(&uri("cosquad"), (32, 32)).await,
        "cosquad:v=1 drew cosquad's image"
    );
}

/// A formula that does not parse, or whose values leave `[0, 1]` at the request's `n`, gets
/// a 400 from every endpoint, naming `lobe`, with the library's one-line message: the
/// position and the problem, which the page shows beside its text box.
#[tokio::test]
async fn bad_formulas_get_400_with_the_problem_in_one_line() {
    let cases = [
        (
            "tt + 1",
            64,
            "column 1: unknown name 'tt'; did you mean 't'?",
        ),
        ("max(0, t", 64, "column"),
        ("sqrt(t, t)", 64, "sqrt"),
        ("2 * t", 64, "above 1"),
        ("t - 1", 64, "negative"),
        ("log2(t)", 64, "not finite"),
        // Within [0, 1] at n = 64, above 1 at n = 128: checked at the request's n.
        ("(n / 64) * t ^ n", 128, "at n = 128"),
        ("", 64, ""),
    ];
    for (formula, n, expected) in cases {
        let lobe = encoded(&format!("={formula}"));
        for endpoint in ["evaluate", "analyze", "render", "volume", "environment"] {
            let uri = format!("/api/{endpoint}?lobe={lobe}&n={n}");
            let (status, body) = json(&uri).await;
            assert_eq!(status, StatusCode::BAD_REQUEST, "{uri}: {body}");
            assert_eq!(body["parameter"], "lobe", "{uri}: {body}");
            let error = body["error"].as_str().expect("a message");
            assert!(error.contains(expected), "{formula}: {error}");
            assert!(
                !error.is_empty() && !error.contains('\n') && error.len() < 400,
                "{formula}: not one line: {error}"
            );
            assert!(body["valid"].as_str().expect("valid").contains("=FORMULA"));
        }
    }
    let (status, body) = json(&format!(
        "/api/evaluate?lobe={}&n=64",
        encoded("=(n / 64) * t ^ n")
    ))
    .await;
    assert_eq!(status, StatusCode::OK, "{body}");
}

/// Formulas nested 10,000 (and 2,000) deep, in parentheses, calls, minus signs and powers, are
/// refused at once with the limit they break named (the depth, or, for the longest, the
/// number of terms, counted before any nesting); none reaches a recursion that could
/// overflow the stack.
#[tokio::test]
async fn deep_formulas_are_refused_at_once() {
    let nested = format!(
        "nested more than {} levels deep",
        specula::formula::MAX_DEPTH
    );
    for deep in [10_000, 2_000] {
        for formula in [
            "(".repeat(deep) + "t" + &")".repeat(deep),
            "-".repeat(deep) + "t",
            "t^".repeat(deep) + "t",
            "sqrt(".repeat(deep / 10) + "t" + &")".repeat(deep / 10),
        ] {
            let started = std::time::Instant::now();
            let uri = format!("/api/evaluate?lobe={}", encoded(&format!("={formula}")));
            let (status, body) = json(&uri).await;
            assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
            let error = body["error"].as_str().expect("a message");
            assert!(
                error.contains(&nested) || (deep > 4096 && error.contains("more than 4096 terms")),
                "{deep}: {error}"
            );
            assert!(error.len() < 400, "{error}");
            assert!(
                started.elapsed() < std::time::Duration::from_secs(1),
                "{:?}",
                started.elapsed()
            );
        }
    }
}

/// A formula of 1 MB never reaches the API: the server refuses the address (HTTP allows no
/// more than 65,534 bytes of it, below the formula limit of 64 KiB once percent-encoded) with
/// a 4xx at once; one just over the address limit is answered 414.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn oversize_formulas_are_refused_at_once() {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let address = spawn_server().await;
    for (bytes, status) in [(1 << 20, None), (70_000, Some("414"))] {
        let query = format!("lobe=%3D{}", "t".repeat(bytes));
        let started = std::time::Instant::now();
        let mut stream = tokio::net::TcpStream::connect(address)
            .await
            .expect("connect");
        let head = format!("GET /api/evaluate?{query} HTTP/1.1\r\nHost: {address}\r\n\r\n");
        // The server may answer and close before the whole request is sent.
        let _ = stream.write_all(head.as_bytes()).await;
        let mut response = Vec::new();
        let _ = tokio::time::timeout(
            std::time::Duration::from_secs(5),
            stream.read_to_end(&mut response),
        )
        .await
        .expect("answered at once");
        let answer = String::from_utf8_lossy(&response);
        assert!(answer.starts_with("HTTP/1.1 4"), "{bytes} bytes: {answer}");
        if let Some(status) = status {
            assert!(
                answer.starts_with(&format!("HTTP/1.1 {status}")),
                "{answer}"
            );
        }
        assert!(started.elapsed() < std::time::Duration::from_secs(2));
    }
    // The longest formula HTTP carries is parsed and refused, or served, in well under a
    // second: its own limit is the parser's node count.
    // (`*` needs no percent-encoding in a query.)
    let formula = "t*".repeat(32_000) + "t";
    let started = std::time::Instant::now();
    let (status, body) = json(&format!("/api/evaluate?lobe=%3D{formula}")).await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert!(
        body["error"].as_str().expect("a message").len() < 400,
        "{body}"
    );
    assert!(
        started.elapsed() < std::time::Duration::from_secs(1),
        "{:?}",
        started.elapsed()
    );
}
