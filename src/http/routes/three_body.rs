//! `POST /v1/three-body`: a population of particles between the upper surface and the
//! layer, solved now.

use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::Response;

use crate::http::error::{ApiError, JsonBody};
use crate::http::openapi::{BadBody, Busy, NotModified, SolveErrors};
use crate::http::AppState;
use crate::job::three_body::{ThreeBodyInput, ThreeBodyOutput};
use crate::job::JobKind;

/// Solve one three-body system.
///
/// The body is a three-body input: every field is optional and defaults to the paper's
/// system (1 mm², 1e12 particles/m² of 50 ± 5 nm, steel on the default Kelvin layer,
/// V = 4 nm/s) except the operating point, exactly one of `separation`, `total_load` or
/// `particle_load`. Quantities are SI numbers or strings with units (`"1 mN"`).
#[utoipa::path(
    post,
    path = "/v1/three-body",
    tag = "solve",
    request_body(content = ThreeBodyInput, content_type = "application/json"),
    responses(
        (status = 200, description = "The system at its operating point: separation, \
            particles in contact, areas, loads, friction with and without rolling, \
            per-particle means; meta", body = ThreeBodyOutput,
            headers(("etag" = String, description = "The cache key, quoted"),
                    ("x-cache" = String, description = "hit or miss"))),
        NotModified, BadBody, Busy, SolveErrors,
    )
)]
pub async fn solve(
    State(state): State<AppState>,
    headers: HeaderMap,
    JsonBody(input): JsonBody,
) -> Result<Response, ApiError> {
    super::solve(&state, JobKind::ThreeBody, input, &headers).await
}
