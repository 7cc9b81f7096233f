//! What `/api/isa` answers: a lobe's machine code beside `pow`'s for a GPU, as a vendor's
//! compiler writes it (`specula isa --format json`). The compilers are run by `specula-isa`,
//! above this crate, so the server is handed them ([`IsaModel`]) by the command that starts
//! it; a server without them says so.

use axum::extract::State;
use axum::response::{IntoResponse, Response};
use axum::Json;
use specula::gpus::Gpu;

use crate::api::{compute_with, AppState, DEFAULT_GPU};
use crate::query::{pairs, ApiError, Params, QueryPairs};

/// `GET /api/isa?lobe&n&gpu`: the lobe's and `pow`'s machine code for `gpu`.
pub async fn isa(State(state): State<AppState>, query: QueryPairs) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &["lobe", "n", "gpu"])?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let asked = params.text("gpu").unwrap_or(DEFAULT_GPU);
    let gpu = Gpu::find(asked).ok_or_else(|| {
        ApiError::bad(
            "gpu",
            format!("unknown GPU `{}`", specula::excerpt(asked)),
            Gpu::ALL.map(|gpu| gpu.id).join(", "),
        )
    })?;
    let model = state.isa.clone().ok_or_else(|| {
        ApiError::unavailable(
            "this server compiles no lobes: specula serve offers /api/isa".to_owned(),
        )
    })?;
    let answer = compute_with(&state, kind, n, move |lobe| model(&lobe, gpu)).await?;
    match answer {
        Ok(answer) => Ok(Json(answer).into_response()),
        Err(refusal) => Err(ApiError::unavailable(refusal).into()),
    }
}
