//! `POST /v1/three-body`: a population of particles between the upper surface and the
//! layer, solved now.

use axum::response::Response;

use super::SolveRequest;
use crate::http::error::ApiError;
use crate::http::openapi::{BadBody, Busy, NotModified, SolveErrors};
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
            per-particle means; meta", body = ThreeBodyOutput),
        NotModified, BadBody, Busy, SolveErrors,
    )
)]
pub async fn solve(request: SolveRequest) -> Result<Response, ApiError> {
    request.solve(JobKind::ThreeBody).await
}
