//! The JSON API: parameters parsed with the library's registries, every refusal a 400 with a
//! JSON body naming the parameter and its valid range or choices.
//!
//! Every `lobe` is a built-in id (`cosquad:v=2`) or, as on the command line, `=FORMULA`: a
//! formula of `t` and `n` (`lobe==exp2(n * (t - 1) * 1.4427)`, percent-encoded). A formula is
//! refused with a 400 whose `error` is the library's one-line message (the position and the
//! problem) when it does not parse, when it is longer than
//! [`MAX_SOURCE_BYTES`](specula::formula::MAX_SOURCE_BYTES) (before any work), or when
//! [`Lobe::checked`] finds it outside `[0, 1]` at the request's `n`.
//!
//! - `GET /api/models`: the lobes, geometries, normalisations, shadings, objects and limits,
//!   and the formula language's functions and length limit (the page's text box);
//! - `GET /api/evaluate?lobe&n&geometry&normalisation&theta_in`: every plot's data;
//! - `GET /api/analyze?lobe&n`: the error, energy and albedo figures (`specula analyze`'s),
//!   and `costs`, the lobe's cost on every target the server's cost model knows;
//! - `GET
//! /api/render?object&lobe&n&geometry&normalisation&shading&model&light_theta&light_phi&size`:
//!   a PNG from the CPU renderer;
//! - `GET /api/volume?volume&view&lobe&n&geometry&normalisation&size`: a volume (a built-in
//!   one, or a real scan while its file is installed) ray marched on the CPU, as a PNG;
//! - `GET /api/environment?lobe&n&geometry&normalisation&size&spp`: the environment scene lit
//!   by the procedural sky (Monte Carlo, CPU), as a PNG;
//! - `GET /api/materials`, `GET /api/fits?material`, `GET
//! /api/material-render?material&fit&size&spp`:
//!   the measured materials of the `--data` folder, by name (`measured.rs`);
//! - `GET /api/design?target&low&high&max_error`: a lobe designed for a GPU family, by the
//!   search the server was handed (`design.rs`);
//! - `GET /api/isa?lobe&n&gpu`: the lobe's and `pow`'s machine code for a GPU, by the compilers
//!   the server was handed (`isa.rs`).

use std::sync::Arc;

use axum::extract::State;
use axum::http::header;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde_json::json;
use specula::analysis::{analyze, Precision};
use specula::formula::MAX_SOURCE_BYTES;
use specula::measured::fit::POLAR_ANGLES_DEGREES;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::{IlluminationModel, Shading};
use specula_volume::dvr::View;

use crate::query::{bad_lobe, pairs, ApiError, Params, QueryPairs};

use super::explorer::{curves, render_png, Object, RenderRequest};
use super::guard::{Hosts, Limiter};
use specula_volume::phantom::BuiltIn;

use super::environment::{
    environment_png, EnvironmentRequest, MAX_ENVIRONMENT_SIZE, MAX_ENVIRONMENT_SPP,
};
use super::measured::{
    material, render_labels, Assessment, Materials, MAX_MATERIALS, MAX_MATERIAL_RENDER_SIZE,
    MAX_MATERIAL_RENDER_SPP, MEASURED, NO_DATA,
};
use super::volume::{volume_png, Choice, VolumeRequest, MAX_VOLUME_SIZE};
use crate::costs::{costs_versus_pow, cpu_cost, CostModel};

/// The largest render side, in pixels.
pub const MAX_RENDER_SIZE: u32 = 1024;

/// The compilers (`/api/isa`): `specula isa --format json`'s answer for a lobe on the GPU
/// named by its vendor's id, or a one-line refusal (a compiler missing, naming how to install
/// it).
pub type IsaModel = std::sync::Arc<
    dyn Fn(&specula::Lobe, specula::gpus::Gpu) -> Result<serde_json::Value, String> + Send + Sync,
>;

/// The GPU the machine-code view compiles for unless the page names one.
pub const DEFAULT_GPU: &str = "sm_89";

/// What the handlers share.
#[derive(Clone)]
pub struct AppState {
    computations: Limiter,
    pub(crate) costs: CostModel,
    pub(crate) designer: Option<crate::design::DesignModel>,
    pub(crate) isa: Option<IsaModel>,
    hosts: Hosts,
    pub(crate) materials: Arc<Materials>,
}

impl AppState {
    /// The state with `costs` as the cost model.
    #[must_use]
    pub fn with_costs(costs: CostModel) -> Self {
        Self {
            computations: Limiter::default(),
            costs,
            designer: None,
            isa: None,
            hosts: Hosts::default(),
            materials: Arc::new(Materials::none()),
        }
    }

    /// The state offering `materials` (the `--data` folder's; by default none).
    #[must_use]
    pub fn with_materials(self, materials: Materials) -> Self {
        Self {
            materials: Arc::new(materials),
            ..self
        }
    }

    /// The state answering `/api/design` with `designer`.
    #[must_use]
    pub fn with_designer(self, designer: crate::design::DesignModel) -> Self {
        Self {
            designer: Some(designer),
            ..self
        }
    }

    /// The state answering `/api/isa` with `isa`, the GPU vendors' compilers.
    #[must_use]
    pub fn with_isa(self, isa: IsaModel) -> Self {
        Self {
            isa: Some(isa),
            ..self
        }
    }

    /// The state answering only to `hosts` (the default: loopback names, any port).
    #[must_use]
    pub fn answering(self, hosts: Hosts) -> Self {
        Self { hosts, ..self }
    }

    /// The host names it answers to.
    #[must_use]
    pub fn hosts(&self) -> Hosts {
        self.hosts.clone()
    }
}

impl Default for AppState {
    fn default() -> Self {
        Self::with_costs(Arc::new(|lobe: &Lobe| Ok(vec![cpu_cost(lobe)])))
    }
}

/// `kind` prepared for `n`, refusing a formula whose values leave `[0, 1]` there or are not
/// finite ([`Lobe::checked`]). Run inside [`compute`]: a long formula's check takes a tenth of
/// a second.
fn checked(kind: LobeKind, n: Exponent) -> Result<Lobe, ApiError> {
    Lobe::checked(kind, n).map_err(|error| match error {
        specula::Error::Formula { message, .. } => bad_lobe(message),
        error => bad_lobe(error.to_string()),
    })
}

/// Runs `work` on the blocking pool once a worker is free, or answers the full queue's 503; a
/// panic inside becomes a 500, never a dropped server.
pub(crate) async fn compute<T: Send + 'static>(
    state: &AppState,
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, Response> {
    let _turn = state.computations.turn().await?;
    if crate::supersede::superseded() {
        return Err(ApiError::superseded().into());
    }
    tokio::task::spawn_blocking(work)
        .await
        .map_err(|e| ApiError::internal(format!("the computation failed: {e}")).into())
}

/// [`compute`] for a request's lobe: `work` is given the lobe once [`checked`] accepts it, in
/// the same turn.
pub(crate) async fn compute_with<T: Send + 'static>(
    state: &AppState,
    kind: LobeKind,
    n: Exponent,
    work: impl FnOnce(Lobe) -> T + Send + 'static,
) -> Result<T, Response> {
    compute(state, move || checked(kind, n).map(work))
        .await?
        .map_err(Response::from)
}

/// Any other path.
pub async fn not_found() -> ApiError {
    ApiError::not_found(
        "no such page or endpoint".into(),
        "/, /api/models, /api/evaluate, /api/analyze, /api/render, /api/volume, /api/environment, \
            /api/materials, /api/fits, /api/material-render, /api/design, /api/isa, \
            /api/shader, /api/microfacet, /api/live-sphere, /api/teapot"
            .into(),
    )
}

pub async fn models() -> impl IntoResponse {
    let lobes: Vec<_> = LobeKind::ALL
        .iter()
        .map(|kind| {
            let info = kind.info();
            let style = kind.line_style();
            let params: Vec<_> = info
                .params
                .iter()
                .map(|p| {
                    json!({
                        "name": p.name,
                        "description": p.description,
                        "default": p.default,
                        "min": p.min,
                        "max": p.max,
                    })
                })
                .collect();
            json!({
                "id": kind.id(),
                "summary": info.summary,
                "formula": info.formula,
                "colour": style.hex(),
                "dashed": style.dashed,
                "params": params,
            })
        })
        .collect();
    Json(json!({
        "lobes": lobes,
        "geometries": Geometry::ALL.map(Geometry::id),
        "normalisations": Normalisation::ALL.map(Normalisation::id),
        "shadings": Shading::ALL.map(Shading::id),
        "models": IlluminationModel::ALL.map(IlluminationModel::id),
        "objects": Object::ALL.map(Object::id),
        "n": [1.0, 1000.0],
        "max_render_size": MAX_RENDER_SIZE,
        // The built-in volumes, then the real scans whose files are installed.
        "volumes": Choice::available().into_iter().map(Choice::id).collect::<Vec<_>>(),
        "views": View::STANDARD.map(View::id),
        "max_volume_size": MAX_VOLUME_SIZE,
        "max_environment_size": MAX_ENVIRONMENT_SIZE,
        "max_environment_spp": MAX_ENVIRONMENT_SPP,
        // The GPUs the machine-code view compiles for, by their vendors' names.
        "gpus": specula::gpus::Gpu::ALL.map(|gpu| json!({ "id": gpu.id, "name": gpu.name })),
        "gpu": DEFAULT_GPU,
        // The sphere the page draws itself (live.js) and /api/live-sphere draws here.
        "live": crate::scene_setup::LIVE_SCENE,
        // The text box's language and limit (a formula is sent as `lobe==FORMULA`).
        "formula": {
            "max_bytes": MAX_SOURCE_BYTES,
            "functions": specula::formula::FUNCTIONS.map(|(_, signature)| signature),
        },
    }))
}

pub async fn evaluate(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &["lobe", "n", "geometry", "normalisation", "theta_in"],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let (geometry, normalisation) = (
        params.geometry()?,
        params.normalisation(Normalisation::Lobe)?,
    );
    let theta_in = params.number("theta_in", 0.0..=89.0, 30.0)?.to_radians();
    let data = compute_with(&state, kind, n, move |_| {
        curves(kind, n, geometry, normalisation, theta_in)
    })
    .await?;
    Ok(Json(data).into_response())
}

pub async fn analyze_lobe(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &["lobe", "n"])?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let costs = state.costs.clone();
    let (report, costs) = compute_with(&state, kind, n, move |lobe| {
        (
            analyze(kind, n, &mut Precision::F64),
            costs_versus_pow(&costs, &lobe),
        )
    })
    .await?;
    let costs = costs.map_err(ApiError::internal)?;
    let mut body = serde_json::to_value(report).map_err(|e| ApiError::internal(e.to_string()))?;
    body["costs"] = json!(costs);
    Ok(Json(body).into_response())
}

pub async fn render(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &[
            "object",
            "lobe",
            "n",
            "geometry",
            "normalisation",
            "shading",
            "model",
            "light_theta",
            "light_phi",
            "size",
        ],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let (light_theta, light_phi) = params.light()?;
    let request = RenderRequest {
        object: params.choice("object", &Object::ALL, Object::id, Object::Sphere)?,
        kind,
        n,
        geometry: params.geometry()?,
        normalisation: params.normalisation(Normalisation::None)?,
        shading: params.choice("shading", &Shading::ALL, Shading::id, Shading::Phong)?,
        model: params.model()?,
        light_theta,
        light_phi,
        size: params.number("size", 16.0..=f64::from(MAX_RENDER_SIZE), 512.0)? as u32,
    };
    let encoded = compute_with(&state, kind, n, move |_| render_png(&request)).await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

pub async fn volume(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &[
            "volume",
            "view",
            "lobe",
            "n",
            "geometry",
            "normalisation",
            "size",
        ],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let request = VolumeRequest {
        volume: params.choice(
            "volume",
            &Choice::available(),
            Choice::id,
            Choice::BuiltIn(BuiltIn::SheppLogan),
        )?,
        view: params.choice("view", &View::STANDARD, View::id, View::Anterior)?,
        kind,
        n,
        geometry: params.geometry()?,
        normalisation: params.normalisation(Normalisation::ThesisPhong)?,
        size: params.number("size", 16.0..=f64::from(MAX_VOLUME_SIZE), 256.0)? as u32,
    };
    let encoded = compute_with(&state, kind, n, move |_| volume_png(&request)).await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

pub async fn environment(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &["lobe", "n", "geometry", "normalisation", "size", "spp"],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let request = EnvironmentRequest {
        kind,
        n,
        geometry: params.geometry()?,
        normalisation: params.normalisation(Normalisation::Lobe)?,
        size: params.number("size", 16.0..=f64::from(MAX_ENVIRONMENT_SIZE), 384.0)? as u32,
        spp: params.number("spp", 1.0..=f64::from(MAX_ENVIRONMENT_SPP), 16.0)? as u32,
    };
    let encoded = compute_with(&state, kind, n, move |_| environment_png(&request)).await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

/// The encoded image as a PNG response.
pub(crate) fn png(encoded: Vec<u8>) -> Response {
    (
        [
            (header::CONTENT_TYPE, "image/png"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        encoded,
    )
        .into_response()
}

/// The material's fits: the cached ones at once, or computed in a turn of the queue.
async fn assessment(state: &AppState, index: usize) -> Result<Arc<Assessment>, Response> {
    let result = match state.materials.fitted(index) {
        Some(done) => done,
        None => {
            let (materials, costs) = (Arc::clone(&state.materials), state.costs.clone());
            compute(state, move || materials.assess(index, &costs)).await?
        }
    };
    result.map_err(|error| ApiError::internal(error).into())
}

/// `GET /api/materials`: the materials offered (each with whether its fits are ready), the
/// polar plots' viewing elevations and the renders' limits and choices.
pub async fn materials(State(state): State<AppState>) -> Response {
    let materials = &state.materials;
    let offered: Vec<_> = materials
        .names()
        .enumerate()
        .map(|(index, name)| json!({ "name": name, "fitted": materials.is_fitted(index) }))
        .collect();
    Json(json!({
        "hint": if offered.is_empty() { Some(NO_DATA) } else { None },
        "materials": offered,
        "max_materials": MAX_MATERIALS,
        "polar_angles_deg": POLAR_ANGLES_DEGREES,
        "render_fits": render_labels(),
        "max_render_size": MAX_MATERIAL_RENDER_SIZE,
        "max_render_spp": MAX_MATERIAL_RENDER_SPP,
    }))
    .into_response()
}

/// `GET /api/fits?material=NAME`: the shared-`n` fits and the polar data (see
/// [`Assessment`]'s JSON: `fits`, `polar_elevations_deg`, `polar`).
pub async fn fits(State(state): State<AppState>, query: QueryPairs) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &["material"])?;
    let index = material(&params, &state.materials)?;
    let assessment = assessment(&state, index).await?;
    Ok((
        [(header::CONTENT_TYPE, "application/json")],
        assessment.body(),
    )
        .into_response())
}

/// `GET /api/material-render?material=NAME&fit=LABEL&size&spp`: the environment scene in the
/// material (`fit=measured`, the default) or one of its shared fits (`pow/phong`, `ggx`), as a
/// PNG; every render uses seed 0.
pub async fn render_material(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &["material", "fit", "size", "spp"])?;
    let index = material(&params, &state.materials)?;
    let labels = render_labels();
    let shown = params.text("fit").unwrap_or(MEASURED).to_owned();
    if !labels.contains(&shown) {
        return Err(ApiError::bad(
            "fit",
            format!("unknown fit `{}`", specula::excerpt(&shown)),
            labels.join(", "),
        )
        .into());
    }
    let size = params.number("size", 16.0..=f64::from(MAX_MATERIAL_RENDER_SIZE), 256.0)? as u32;
    let spp = params.number("spp", 1.0..=f64::from(MAX_MATERIAL_RENDER_SPP), 8.0)? as u32;
    let (materials, costs) = (Arc::clone(&state.materials), state.costs.clone());
    let encoded = compute(&state, move || {
        materials.render_png(index, &shown, &costs, size, spp)
    })
    .await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

/// `GET /api/design?target&low&high&max_error`: `specula design`'s answer, from the search the
/// server was handed (`design.rs`).
pub async fn design_lobe(State(state): State<AppState>, query_pairs: QueryPairs) -> Response {
    let asked = match pairs(query_pairs)
        .and_then(|q| Params::new(q, &["target", "low", "high", "max_error"]))
        .and_then(|params| crate::design::query(&params))
    {
        Ok(asked) => asked,
        Err(error) => return error.into_response(),
    };
    let Some(model) = state.designer.clone() else {
        return ApiError::unavailable(
            "this server designs no lobes: specula serve offers /api/design".to_owned(),
        )
        .into_response();
    };
    match compute(&state, move || model(&asked)).await {
        Ok(Ok(answer)) => Json(answer).into_response(),
        Ok(Err(refusal)) => {
            ApiError::bad("max_error", refusal, "a bound the search can meet".into())
                .into_response()
        }
        Err(response) => response,
    }
}
