//! `POST /v1/rolling`: one particle rolling over the layer, solved now.

use axum::response::Response;

use super::SolveRequest;
use crate::http::error::ApiError;
use crate::http::openapi::{BadBody, Busy, NotModified, SolveErrors};
use crate::job::rolling::{RollingInput, RollingOutput};
use crate::job::JobKind;

/// Solve one rolling contact.
///
/// The body is a rolling input: every field is optional and defaults to the paper's
/// particle (R = 25 nm, P = 1 nN, V = 4 nm/s on a 100 nm, 3 GPa Kelvin layer), so `{}` is a
/// valid job. Quantities are SI numbers or strings with units (`"25 nm"`).
#[utoipa::path(
    post,
    path = "/v1/rolling",
    tag = "solve",
    request_body(content = RollingInput, content_type = "application/json"),
    responses(
        (status = 200, description = "The contact: penetration, area, shifts, friction; \
            the same at V = 0; the boundary; meta", body = RollingOutput),
        NotModified, BadBody, Busy, SolveErrors,
    )
)]
pub async fn solve(request: SolveRequest) -> Result<Response, ApiError> {
    request.solve(JobKind::Rolling).await
}
