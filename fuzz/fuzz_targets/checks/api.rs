//! The API target's check, also run by `crates/serve/tests/fuzz_regressions.rs` on the seeds
//! and every crash input kept in `fuzz/regressions/api/`: any query string gets 200 or a JSON
//! 400, never a panic or a 500. The first byte picks the endpoint; renders are pinned to a
//! small size (a second `size` is itself a 400).

use std::sync::OnceLock;

use axum::body::{to_bytes, Body};
use axum::http::{Request, StatusCode};
use tower::ServiceExt as _;

fn runtime() -> &'static tokio::runtime::Runtime {
    static RUNTIME: OnceLock<tokio::runtime::Runtime> = OnceLock::new();
    RUNTIME.get_or_init(|| {
        tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .expect("runtime")
    })
}

/// Sends `data` to the API as described above and checks the answer.
pub fn check_api(data: &[u8]) {
    let Some((&which, rest)) = data.split_first() else {
        return;
    };
    let query = String::from_utf8_lossy(rest);
    let uri = match which % 3 {
        0 => format!("/api/evaluate?{query}"),
        1 => format!("/api/analyze?{query}"),
        _ => format!("/api/render?size=16&{query}"),
    };
    let Ok(request) = Request::get(uri.as_str()).body(Body::empty()) else {
        return; // not a URI at all: the HTTP layer refuses it before the API sees it
    };
    runtime().block_on(async {
        let response = specula_serve::router()
            .oneshot(request)
            .await
            .expect("infallible");
        let status = response.status();
        let body = to_bytes(response.into_body(), usize::MAX)
            .await
            .expect("body");
        assert!(
            status == StatusCode::OK || status == StatusCode::BAD_REQUEST,
            "{uri}: {status}"
        );
        if status == StatusCode::BAD_REQUEST {
            let error: serde_json::Value = serde_json::from_slice(&body).expect("a JSON error");
            assert!(error["error"].is_string(), "{uri}: {error}");
        }
    });
}
