//! `POST /v1/sweeps`: a sweep over radius, load and speed, solved now; JSON or CSV.

use axum::response::Response;

use super::SolveRequest;
use crate::http::error::ApiError;
use crate::http::openapi::{BadBody, Busy, NotModified, SolveErrors};
use crate::job::sweep::{SweepInput, SweepOutput};
use crate::job::JobKind;

/// Solve a sweep.
///
/// One row per point of the Cartesian product of `vary`'s lists over `base`. With
/// `Accept: text/csv` the answer is CSV (SI units, one header line). Big sweeps belong in
/// `POST /v1/jobs`, which reports progress and can be cancelled.
#[utoipa::path(
    post,
    path = "/v1/sweeps",
    tag = "solve",
    request_body(content = SweepInput, content_type = "application/json"),
    responses(
        (status = 200, description = "One row per point", content(
            (SweepOutput = "application/json"), (String = "text/csv"))),
        NotModified, BadBody, Busy, SolveErrors,
    )
)]
pub async fn solve(request: SolveRequest) -> Result<Response, ApiError> {
    request.solve(JobKind::Sweep).await
}
