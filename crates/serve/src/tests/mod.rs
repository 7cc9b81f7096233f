//! The API through the router itself: valid, invalid, oversized and concurrent requests.

use axum::body::{to_bytes, Body};
use axum::http::{Request, StatusCode};
use serde_json::Value;
use tower::ServiceExt as _;

use super::router;

mod connections;
mod formula;
mod live;
mod measured;

async fn get(uri: &str) -> (StatusCode, Vec<u8>) {
    get_from(&router(), uri).await
}

/// `GET uri` from `app`: the status and the body.
async fn get_from(app: &axum::Router, uri: &str) -> (StatusCode, Vec<u8>) {
    let response = app
        .clone()
        .oneshot(Request::get(uri).body(Body::empty()).expect("request"))
        .await
        .expect("infallible");
    let status = response.status();
    let body = to_bytes(response.into_body(), usize::MAX)
        .await
        .expect("body");
    (status, body.to_vec())
}

async fn json(uri: &str) -> (StatusCode, Value) {
    let (status, body) = get(uri).await;
    (status, serde_json::from_slice(&body).expect("JSON body"))
}

#[tokio::test]
async fn evaluate_returns_the_lobe_and_its_closed_form_reference() {
    let (status, data) =
        json("/api/evaluate?lobe=pow&n=40&geometry=phong&normalisation=lobe&theta_in=20").await;
    assert_eq!(status, StatusCode::OK);
    let angles = data["angles_deg"].as_array().expect("angles");
    let values = data["values"].as_array().expect("values");
    for (angle, value) in angles.iter().zip(values).step_by(37) {
        let g = angle.as_f64().expect("number").to_radians();
        assert!((value.as_f64().expect("number") - g.cos().powi(40)).abs() < 1e-12);
    }
    // The epicentre ends where cos^n = 1/2.
    let epicentre = data["epicentre_deg"].as_f64().expect("number").to_radians();
    assert!((epicentre.cos().powi(40) - 0.5).abs() < 1e-9);
    assert_eq!(data["slice"].as_array().expect("slice").len(), 64 * 64);
}

#[tokio::test]
async fn analyze_matches_the_library() {
    let (status, report) = json("/api/analyze?lobe=schlick&n=64").await;
    assert_eq!(status, StatusCode::OK);
    let expected = specula::analysis::analyze(
        specula::LobeKind::Schlick,
        specula::Exponent::new(64.0),
        &mut specula::analysis::Precision::F64,
    );
    assert_eq!(
        report["epicentre_max_rel"].as_f64(),
        Some(expected.errors.epicentre_max_rel)
    );
}

#[tokio::test]
async fn render_returns_a_png_that_depends_on_the_lobe() {
    let uri = |n: u32| format!("/api/render?object=sphere&lobe=pow&n={n}&size=64");
    let (status, narrow) = get(&uri(500)).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(&narrow[..8], b"\x89PNG\r\n\x1a\n");
    let (_, broad) = get(&uri(4)).await;
    assert_ne!(
        narrow, broad,
        "a different exponent gives a different image"
    );
    let (status, teapot) = get("/api/render?object=teapot&size=32").await;
    assert_eq!((status, &teapot[1..4]), (StatusCode::OK, &b"PNG"[..]));
}

/// The PNG's width and height, from its IHDR chunk.
fn png_size(png: &[u8]) -> (u32, u32) {
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let word = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().expect("4 bytes"));
    (word(16), word(20))
}

/// The PNG served at `uri`, required to be `size`.
async fn served_png(uri: &str, size: (u32, u32)) -> Vec<u8> {
    let (status, served) = get(uri).await;
    assert_eq!(
        status,
        StatusCode::OK,
        "{uri}: {}",
        String::from_utf8_lossy(&served)
    );
    assert_eq!(png_size(&served), size, "{uri}");
    served
}

/// The volume view is the library's ray marcher with the parameters named in the address:
/// its bytes are those of `render_dvr` called directly with them, and each parameter changes
/// the image.
#[tokio::test]
async fn volume_renders_the_named_volume_view_and_lobe() {
    use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
    use specula_volume::dvr::{render_dvr, DvrSettings, Shading, View};
    use specula_volume::{phantom, transfer::TransferFunction};

    let uri =
        "/api/volume?volume=phantom&view=inferior&lobe=cosquad&n=40&geometry=phong&normalisat\
        ion=lobe&size=48";
    let served = served_png(uri, (48, 48)).await;

    let volume = phantom::shepp_logan(64).expect("phantom");
    let shading = Shading::new(
        Lobe::new(
            LobeKind::parse("cosquad").expect("a lobe"),
            Exponent::new(40.0),
        ),
        Geometry::Phong,
        Normalisation::Lobe,
    );
    let settings = DvrSettings::new(48, 48, View::Inferior, Some(shading));
    let transfer = TransferFunction::preset("mr")
        .expect("a preset")
        .for_volume(&volume);
    let image = render_dvr(&volume, &transfer, &settings, &|| {}).expect("render");
    let direct =
        specula_render::encode_png_srgb8(48, 48, &image.to_srgb8(Default::default())).expect("png");
    assert!(
        served == direct,
        "the served image is not the library's render"
    );

    for other in [
        uri.replace("lobe=cosquad", "lobe=schlick"),
        uri.replace("n=40", "n=400"),
        uri.replace("view=inferior", "view=left"),
        uri.replace("volume=phantom", "volume=marschner-lobb"),
        uri.replace("normalisation=lobe", "normalisation=none"),
    ] {
        assert!(
            served_png(&other, png_size(&served)).await != served,
            "{other} drew the same image"
        );
    }
}

/// The environment view is the library's environment render of its scene with the lobe,
/// exponent, geometry and normalisation the address names, at seed 0: the served bytes are
/// those of `render_ibl` called directly, and each parameter changes the image.
#[tokio::test]
async fn environment_renders_the_named_lobe_under_the_sky() {
    use specula::{Exponent, Geometry, LobeKind, Normalisation};
    use specula_render::ibl::{render_ibl, Environment, IblSettings, Strategy, SKY_WIDTH};
    use specula_render::{Overrides, Scene};

    let uri = "/api/environment?lobe=cheb2&n=100&geometry=blinn&normalisation=lobe&size=64&spp=4";
    let served = served_png(uri, (64, 36)).await;

    let mut scene = Scene::ibl_scene();
    scene.apply(&Overrides {
        lobe: Some(LobeKind::Cheb2),
        n: Some(Exponent::new(100.0)),
        geometry: Some(Geometry::Blinn),
        normalisation: Some(Normalisation::Lobe),
        width: Some(64),
        height: Some(36),
        ..Overrides::default()
    });
    let settings = IblSettings {
        spp: 4,
        seed: 0,
        strategy: Strategy::Mis,
    };
    let image =
        render_ibl(&scene, &Environment::sky(SKY_WIDTH), &settings, &|_, _| {}).expect("render");
    let direct =
        specula_render::encode_png_srgb8(64, 36, &image.to_srgb8(scene.display)).expect("png");
    assert!(
        served == direct,
        "the served image is not the library's render"
    );

    for other in [
        uri.replace("lobe=cheb2", "lobe=pow"),
        uri.replace("n=100", "n=10"),
        uri.replace("geometry=blinn", "geometry=phong"),
        uri.replace("normalisation=lobe", "normalisation=none"),
        uri.replace("spp=4", "spp=8"),
    ] {
        assert!(
            served_png(&other, png_size(&served)).await != served,
            "{other} drew the same image"
        );
    }
}

#[tokio::test]
async fn bad_parameters_get_400_naming_the_parameter_and_the_valid_values() {
    let cases = [
        ("/api/evaluate?lobe=phong", "lobe", "schlick-mod"),
        ("/api/evaluate?n=0", "n", "[1, 1000]"),
        ("/api/evaluate?n=NaN", "n", "[1, 1000]"),
        ("/api/evaluate?n=1e9", "n", "[1, 1000]"),
        ("/api/evaluate?geometry=ward", "geometry", "phong, blinn"),
        ("/api/evaluate?theta_in=90", "theta_in", "[0, 89]"),
        ("/api/evaluate?colour=red", "colour", "lobe, n, geometry"),
        ("/api/evaluate?n=3&n=4", "n", "one value"),
        (
            "/api/analyze?normalisation=lobe",
            "normalisation",
            "lobe, n",
        ),
        ("/api/render?size=4096", "size", "[16, 1024]"),
        ("/api/render?size=-5", "size", "[16, 1024]"),
        ("/api/render?object=cube", "object", "sphere, teapot"),
        (
            "/api/render?shading=toon",
            "shading",
            "flat, gouraud, phong",
        ),
        ("/api/render?light_phi=720", "light_phi", "[-180, 180]"),
        (
            "/api/volume?volume=brain",
            "volume",
            "phantom, marschner-lobb",
        ),
        (
            "/api/volume?view=oblique",
            "view",
            "anterior, posterior, left, right, superior, inferior",
        ),
        ("/api/volume?size=2048", "size", "[16, 512]"),
        ("/api/volume?lobe=gauss", "lobe", "cosquad"),
        ("/api/volume?object=sphere", "object", "volume, view, lobe"),
        ("/api/environment?size=4096", "size", "[16, 768]"),
        ("/api/environment?spp=0", "spp", "[1, 256]"),
        ("/api/environment?spp=1e6", "spp", "[1, 256]"),
        ("/api/environment?lobe=ggx", "lobe", "cosquad"),
        (
            "/api/environment?env=studio.hdr",
            "env",
            "lobe, n, geometry",
        ),
    ];
    for (uri, parameter, valid) in cases {
        let (status, body) = json(uri).await;
        assert_eq!(status, StatusCode::BAD_REQUEST, "{uri}");
        assert_eq!(body["parameter"], parameter, "{uri}: {body}");
        assert!(
            body["valid"].as_str().expect("valid").contains(valid),
            "{uri}: {body}"
        );
    }
    // Broken percent-encoding is kept as text, which is then not a number.
    let (status, body) = json("/api/evaluate?n=%ZZ%").await;
    assert_eq!(
        (status, &body["parameter"]),
        (StatusCode::BAD_REQUEST, &Value::from("n")),
        "{body}"
    );
    let (status, body) = json("/no/such/thing").await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert!(body["valid"]
        .as_str()
        .expect("routes")
        .contains("/api/environment"));
}

#[tokio::test]
async fn bodies_are_refused_and_the_page_is_self_contained() {
    let big = vec![b'x'; 1 << 20];
    let response = router()
        .oneshot(
            Request::post("/api/evaluate")
                .body(Body::from(big))
                .expect("request"),
        )
        .await
        .expect("infallible");
    assert_eq!(response.status(), StatusCode::METHOD_NOT_ALLOWED);
    // Every script and style sheet the page names, read from the page itself.
    let (_, page) = get("/").await;
    let page = String::from_utf8(page).expect("text");
    let named: Vec<&str> = page
        .split(['"', '\''])
        .filter(|word| word.starts_with('/') && (word.ends_with(".js") || word.ends_with(".css")))
        .collect();
    assert!(named.len() >= 9, "{named:?}");
    for asset in std::iter::once("/").chain(named) {
        let (status, body) = get(asset).await;
        let text = String::from_utf8(body).expect("text");
        assert_eq!(status, StatusCode::OK);
        assert!(
            !text.contains("http://") && !text.contains("https://"),
            "{asset} fetches from the network"
        );
    }
}

/// 200 requests at once, renders among them: every one answered, with 200 or, once the
/// computation queue is full, 503 and `Retry-After`; the catalogue never waits; and as many
/// computations as the queue holds succeed.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn two_hundred_parallel_requests_are_answered_or_deferred() {
    let app = router();
    let requests = (0..200).map(|k| {
        let app = app.clone();
        let uri = match k % 4 {
            0 => format!("/api/render?object=sphere&size=48&n={}", 1 + k),
            1 => format!("/api/evaluate?lobe=cosquad&n={}", 1 + k),
            2 => "/api/models".to_owned(),
            _ => format!("/api/analyze?lobe=schlick-mod&n={}", 1 + k),
        };
        tokio::spawn(async move {
            let response = app
                .oneshot(Request::get(&uri).body(Body::empty()).expect("request"))
                .await
                .expect("infallible");
            let retry = response
                .headers()
                .get(axum::http::header::RETRY_AFTER)
                .cloned();
            (uri, response.status(), retry)
        })
    });
    let (mut succeeded, mut deferred) = (0, 0);
    for handle in requests.collect::<Vec<_>>() {
        let (uri, status, retry) = handle.await.expect("task");
        match status {
            StatusCode::OK => succeeded += 1,
            StatusCode::SERVICE_UNAVAILABLE if !uri.ends_with("models") => {
                assert_eq!(retry.as_ref().map(|v| v.to_str().ok()), Some(Some("1")));
                deferred += 1;
            }
            other => panic!("{uri}: {other}"),
        }
    }
    assert_eq!(succeeded + deferred, 200);
    assert!(
        succeeded >= 50 + crate::QUEUED_COMPUTATIONS.min(150),
        "{succeeded} succeeded"
    );
}

/// A `Host` that names another server (DNS rebinding) is refused with 421; the loopback
/// names with the server's port are answered.
#[tokio::test]
async fn other_host_names_are_refused() {
    let app = crate::router_with(
        crate::AppState::default().answering(crate::Hosts::new(None, Some(8123))),
    );
    let status = |host: &'static str| {
        let app = app.clone();
        async move {
            app.oneshot(
                Request::get("/api/models")
                    .header("host", host)
                    .body(Body::empty())
                    .expect("request"),
            )
            .await
            .expect("infallible")
            .status()
        }
    };
    assert_eq!(
        status("evil.example:8123").await,
        StatusCode::MISDIRECTED_REQUEST
    );
    assert_eq!(
        status("localhost:9999").await,
        StatusCode::MISDIRECTED_REQUEST
    );
    assert_eq!(status("localhost:8123").await, StatusCode::OK);
    assert_eq!(status("127.0.0.1:8123").await, StatusCode::OK);
}

/// The analysis carries each lobe's costs from the server's cost model, each a rate (higher
/// is better) and that rate over pow's: by default the CPU's evaluations per counted SIMD
/// instruction; a supplied model's figures verbatim.
#[tokio::test]
async fn analyze_carries_the_cost_model() {
    let (status, report) = json("/api/analyze?lobe=cosquad&n=64").await;
    assert_eq!(status, StatusCode::OK);
    let instructions = |kind| {
        f64::from(
            specula::Lobe::new(kind, specula::Exponent::new(64.0))
                .batch_instructions()
                .total(),
        )
    };
    let cosquad = instructions(specula::LobeKind::CosQuad { v: 4 });
    let pow = instructions(specula::LobeKind::Pow);
    let cost = &report["costs"][0];
    assert_eq!(cost["target"], "cpu");
    assert_eq!(cost["value"].as_f64(), Some(8.0 / cosquad));
    let versus_pow = cost["versus_pow"].as_f64().expect("a ratio");
    assert!((versus_pow - pow / cosquad).abs() < 1e-12, "{cost}");
    let model: crate::CostModel = std::sync::Arc::new(|lobe: &specula::Lobe| {
        Ok(vec![crate::TargetRate {
            target: "test".into(),
            value: lobe.exponent().get() * 2.0,
            unit: "twice n".into(),
        }])
    });
    let response = crate::router_with(crate::AppState::with_costs(model))
        .oneshot(
            Request::get("/api/analyze?lobe=pow&n=10")
                .body(Body::empty())
                .expect("request"),
        )
        .await
        .expect("infallible");
    let body = axum::body::to_bytes(response.into_body(), 1 << 20)
        .await
        .expect("body");
    let value: serde_json::Value = serde_json::from_slice(&body).expect("json");
    assert_eq!(value["costs"][0]["value"].as_f64(), Some(20.0));
}

/// The page draws each lobe with the library's colour and dash, the report's.
#[tokio::test]
async fn the_catalogue_carries_each_lobes_line_style() {
    let (status, models) = json("/api/models").await;
    assert_eq!(status, StatusCode::OK);
    let lobes = models["lobes"].as_array().expect("lobes");
    assert_eq!(lobes.len(), specula::LobeKind::ALL.len());
    for (lobe, kind) in lobes.iter().zip(specula::LobeKind::ALL) {
        let style = kind.line_style();
        assert_eq!(lobe["colour"], style.hex(), "{kind}");
        assert_eq!(lobe["dashed"], style.dashed, "{kind}");
        // Every parameter, for the page's controls.
        let params = lobe["params"].as_array().expect("params");
        assert_eq!(params.len(), kind.info().params.len(), "{kind}");
        for (given, info) in params.iter().zip(kind.info().params) {
            assert_eq!(given["name"], info.name);
            assert_eq!(
                (
                    given["min"].as_u64(),
                    given["max"].as_u64(),
                    given["default"].as_u64()
                ),
                (
                    Some(info.min.into()),
                    Some(info.max.into()),
                    Some(info.default.into())
                )
            );
        }
    }
}

/// `/api/design` checks its query, hands the search the request as asked (the bound as a
/// fraction), answers with the search's JSON, and says so when the server has no search.
#[tokio::test]
async fn a_design_request_reaches_the_search_as_asked() {
    let (status, body) = json("/api/design?target=gpu-nvidia").await;
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE, "{body}");
    let model: crate::DesignModel = std::sync::Arc::new(|query: &crate::DesignQuery| {
        if query.max_error < 1e-6 {
            return Err("no designed lobe within 1e-8 %".to_owned());
        }
        Ok(serde_json::json!({
            "target": query.target,
            "range": [query.range.0, query.range.1],
            "max_error": query.max_error,
        }))
    });
    let app = crate::router_with(crate::AppState::default().with_designer(model));
    let ask = |uri: &'static str| {
        let app = app.clone();
        async move {
            let (status, bytes) = get_from(&app, uri).await;
            (
                status,
                serde_json::from_slice::<Value>(&bytes).expect("json"),
            )
        }
    };
    let (status, body) = ask("/api/design?target=gpu-amd&low=16&high=256&max_error=0.5").await;
    assert_eq!(status, StatusCode::OK, "{body}");
    assert_eq!(body["target"], "gpu-amd");
    assert_eq!(body["range"], serde_json::json!([16.0, 256.0]));
    assert!((body["max_error"].as_f64().unwrap() - 0.005).abs() < 1e-15);
    for (uri, parameter) in [
        ("/api/design?target=cpu", "target"),
        ("/api/design?target=fpga", "target"),
        ("/api/design?low=512&high=8", "high"),
        ("/api/design?max_error=0", "max_error"),
        ("/api/design?max_error=nan", "max_error"),
        ("/api/design?n=64", "n"),
        ("/api/design?max_error=0.000001", "max_error"),
    ] {
        let (status, body) = ask(uri).await;
        assert_eq!(status, StatusCode::BAD_REQUEST, "{uri}: {body}");
        assert_eq!(body["parameter"], parameter, "{uri}: {body}");
    }
}

/// `/api/isa` checks its query (the lobe, n and the GPU by its vendor's name), hands the
/// compilers the prepared lobe and the GPU as asked, answers with their JSON, passes a
/// compiler's refusal on as one line, and says so when the server has no compilers.
#[tokio::test]
async fn a_machine_code_request_reaches_the_compilers_as_asked() {
    let (status, body) = json("/api/isa?lobe=sg&n=64&gpu=sm_89").await;
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE, "{body}");
    let model: crate::IsaModel = std::sync::Arc::new(|lobe: &specula::Lobe, gpu| {
        if gpu.id == "tgllp" {
            return Err("ocloc is not installed: apt-get install intel-opencl-icd".to_owned());
        }
        Ok(serde_json::json!({
            "lobe": lobe.kind().to_string(),
            "n": lobe.exponent().get(),
            "gpu": gpu.id,
        }))
    });
    let app = crate::router_with(crate::AppState::default().with_isa(model));
    let ask = |uri: &'static str| {
        let app = app.clone();
        async move {
            let (status, bytes) = get_from(&app, uri).await;
            (
                status,
                serde_json::from_slice::<Value>(&bytes).expect("json"),
            )
        }
    };
    let (status, body) = ask("/api/isa?lobe=cosquad:v=5&n=100&gpu=gfx1030").await;
    assert_eq!(status, StatusCode::OK, "{body}");
    assert_eq!(
        body,
        serde_json::json!({ "lobe": "cosquad:v=5", "n": 100.0, "gpu": "gfx1030" })
    );
    // The GPU the page starts with.
    let (_, body) = ask("/api/isa?lobe=pow&n=8").await;
    assert_eq!(body["gpu"], crate::DEFAULT_GPU);
    let (status, body) = ask("/api/isa?lobe=pow&n=8&gpu=navi31").await;
    assert_eq!(status, StatusCode::BAD_REQUEST, "{body}");
    assert_eq!(body["parameter"], "gpu");
    assert!(
        body["valid"].as_str().unwrap().contains("gfx1100"),
        "{body}"
    );
    let (status, body) = ask("/api/isa?lobe=pow&n=8&gpu=tgllp").await;
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE, "{body}");
    assert!(
        body["error"].as_str().unwrap().contains("intel-opencl-icd"),
        "{body}"
    );
    let (status, body) = ask("/api/isa?lobe=pow&n=0&gpu=sm_89").await;
    assert_eq!(
        (status, body["parameter"].as_str()),
        (StatusCode::BAD_REQUEST, Some("n"))
    );
}
