//! `GET /v1/figures/{n}`: the data behind one of the paper's figures; JSON or CSV.

use axum::extract::{Path, State};
use axum::response::Response;

use super::{Answering, FormatQuery};
use crate::http::error::ApiError;
use crate::http::responses::{Busy, NotAcceptable, NotFound, NotModified, SolveErrors};
use crate::http::AppState;
use crate::job::figure::FigureOutput;
use crate::job::{FigureJob, Job};

/// The data of Figure n of the paper.
///
/// Figures 3 to 9 (docs/model.md §5): the contact region, and contact area and friction
/// against load and radius, with and without rolling. With `Accept: text/csv` the answer is
/// CSV, one line per point.
#[utoipa::path(
    get,
    path = "/v1/figures/{n}",
    operation_id = "get_figure",
    tag = "figures",
    params(("n" = u8, Path, description = "The figure's number in the paper, 3 to 9",
        minimum = 3, maximum = 9, example = 6), FormatQuery),
    responses(
        (status = 200, description = "The figure's axes and series, or its picture", content(
            (FigureOutput = "application/json"), (String = "text/csv"),
            (String = "image/svg+xml"))),
        NotModified, NotFound, NotAcceptable, Busy, SolveErrors,
    )
)]
pub async fn figure(
    State(state): State<AppState>,
    Path(n): Path<String>,
    answering: Answering,
) -> Result<Response, ApiError> {
    let job = n
        .parse()
        .ok()
        .and_then(|number| FigureJob::new(number).ok())
        .ok_or_else(|| {
            ApiError::not_found(format!("there is no figure {n}: figures are 3 to 9"))
        })?;
    answering.solve(&state, Job::new(job).keyed()).await
}
