//! # specula-serve: the BRDF explorer
//!
//! A page and a JSON API over the library, the CPU renderer and its ray marcher; `specula
//! serve` runs it.
//!
//! The page, its script and its styles are compiled in (`assets/`); nothing is fetched from
//! the network. The server binds to 127.0.0.1 unless `--bind` says otherwise, answers only to
//! its own host names ([`Hosts`]), keeps at most [`max_waiting`] connections waiting for their
//! request (closing the oldest beyond that, so idle floods never block a request) with header
//! and idle timeouts (`listen.rs`), runs [`CONCURRENT_COMPUTATIONS`] computations at once on
//! the blocking pool behind a queue of [`QUEUED_COMPUTATIONS`] (a full queue answers 503), and
//! caps request bodies (the API takes none). Measured materials come only from the folder
//! given at start-up, named by their stems (`measured.rs`).

mod api;
mod costs;
mod design;
mod environment;
mod explorer;
mod guard;
mod isa;
mod listen;
mod live;
mod measured;
mod query;
mod scene_setup;
mod supersede;
#[cfg(test)]
mod tests;
mod volume;

use std::net::SocketAddr;

pub use api::{AppState, MAX_RENDER_SIZE};
pub use api::{IsaModel, DEFAULT_GPU};
pub use costs::{cpu_cost, CostModel, TargetCost, TargetRate};
pub use design::{DesignModel, DesignQuery, DESIGN_TARGETS};
pub use environment::{MAX_ENVIRONMENT_SIZE, MAX_ENVIRONMENT_SPP};
pub use guard::{Hosts, CONCURRENT_COMPUTATIONS, QUEUED_COMPUTATIONS};
pub use listen::{max_waiting, CONNECTION_TIMEOUT, HEADER_TIMEOUT, IDLE_TIMEOUT};
pub use live::{sphere_radiance, MAX_LIVE_SIZE};
pub use measured::{
    Materials, MAX_MATERIALS, MAX_MATERIAL_RENDER_SIZE, MAX_MATERIAL_RENDER_SPP, POLAR_POINTS,
};
pub use scene_setup::{LiveScene, LIVE_SCENE};
pub use volume::{Scan, MAX_VOLUME_SIZE};

use axum::extract::DefaultBodyLimit;
use axum::http::header;
use axum::response::IntoResponse;
use axum::routing::get;
use axum::Router;

/// The largest request body accepted.
const MAX_BODY_BYTES: usize = 16 * 1024;

/// The page's scripts, in the order it loads them: the 2D plots, the differences, the measured
/// materials, the WebGL2 views (spheres, 3D lobe, slice, teapot), the pointer, the machine code
/// and the page itself.
const SCRIPTS: [(&str, &str); 10] = [
    ("/plots.js", include_str!("assets/plots.js")),
    ("/difference.js", include_str!("assets/difference.js")),
    ("/measured.js", include_str!("assets/measured.js")),
    ("/live.js", include_str!("assets/live.js")),
    ("/lobe3d.js", include_str!("assets/lobe3d.js")),
    ("/slice.js", include_str!("assets/slice.js")),
    ("/teapot.js", include_str!("assets/teapot.js")),
    ("/linked.js", include_str!("assets/linked.js")),
    ("/isa.js", include_str!("assets/isa.js")),
    ("/app.js", include_str!("assets/app.js")),
];

/// The explorer's routes with the default cost model (the CPU's counted instructions).
pub fn router() -> Router {
    router_with(api::AppState::default())
}

/// The explorer's routes: the page, its assets and the API.
pub fn router_with(state: api::AppState) -> Router {
    let hosts = state.hosts();
    let asset = |content_type: &'static str, body: &'static str| {
        get(move || async move { ([(header::CONTENT_TYPE, content_type)], body).into_response() })
    };
    let page = Router::new()
        .route(
            "/",
            asset(
                "text/html; charset=utf-8",
                include_str!("assets/index.html"),
            ),
        )
        .route(
            "/style.css",
            asset("text/css; charset=utf-8", include_str!("assets/style.css")),
        );
    SCRIPTS
        .iter()
        .fold(page, |page, &(path, script)| {
            page.route(path, asset("text/javascript; charset=utf-8", script))
        })
        .route("/api/models", get(api::models))
        .route("/api/evaluate", get(api::evaluate))
        .route("/api/analyze", get(api::analyze_lobe))
        .route("/api/render", get(api::render))
        .route("/api/volume", get(api::volume))
        .route("/api/environment", get(api::environment))
        .route("/api/materials", get(api::materials))
        .route("/api/fits", get(api::fits))
        .route("/api/material-render", get(api::render_material))
        .route("/api/design", get(api::design_lobe))
        .route("/api/isa", get(isa::isa))
        .route("/api/shader", get(live::shader))
        .route("/api/microfacet", get(live::microfacet))
        .route("/api/live-sphere", get(live::live_sphere))
        .route("/api/teapot", get(live::teapot))
        .fallback(api::not_found)
        .layer(DefaultBodyLimit::max(MAX_BODY_BYTES))
        .layer(axum::middleware::from_fn_with_state(
            supersede::Views::default(),
            supersede::track,
        ))
        .layer(axum::middleware::from_fn_with_state(
            hosts,
            guard::check_host,
        ))
        .with_state(state)
}

/// Serves on `address` until Ctrl-C, printing the URL; `open` also opens it in a browser;
/// `costs` prices each lobe on each target; `designer` answers `/api/design`, `isa`
/// `/api/isa`; `materials` are the measured materials offered (`--data`).
/// Anything but a loopback address is warned about: the explorer has no authentication.
pub fn serve(
    address: SocketAddr,
    open: bool,
    costs: CostModel,
    designer: design::DesignModel,
    isa: IsaModel,
    materials: Materials,
) -> Result<(), String> {
    if !address.ip().is_loopback() {
        eprintln!(
            "warning: listening on {}, reachable from other machines; the explorer has no \
                authentication",
            address.ip()
        );
    }
    let runtime =
        tokio::runtime::Runtime::new().map_err(|e| format!("cannot start the server: {e}"))?;
    runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind(address).await.map_err(|e| {
            format!("cannot listen on {address}: {e}; choose another --port (0 picks a free one)")
        })?;
        let local = listener.local_addr().map_err(|e| e.to_string())?;
        let url = format!("http://{local}/");
        println!("specula explorer on {url} (Ctrl-C stops it)");
        if open {
            open_browser(&url);
        }
        let state = api::AppState::with_costs(costs)
            .with_designer(designer)
            .with_isa(isa)
            .with_materials(materials)
            .answering(Hosts::new(Some(local.ip()), Some(local.port())));
        listen::serve(listener, router_with(state), async {
            let _ = tokio::signal::ctrl_c().await;
        })
        .await
    })
}

/// Asks the desktop to open `url`; failing that, says so (the URL is already printed).
fn open_browser(url: &str) {
    let program = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(error) = std::process::Command::new(program).arg(url).spawn() {
        eprintln!("could not open a browser ({program}: {error}); open {url} by hand");
    }
}
