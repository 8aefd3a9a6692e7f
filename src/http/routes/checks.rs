//! `POST /v1/checks`: the checks `thirdbody check` runs, for a pipeline without the binary.

use axum::extract::State;
use axum::http::{header, HeaderMap};
use axum::response::{IntoResponse, Response};
use serde_json::Value;

use crate::check::{ChecksInput, Report, Suite};
use crate::engine::EngineError;
use crate::http::accept::Accept;
use crate::http::body::JsonBody;
use crate::http::error::ApiError;
use crate::http::responses::{BadBody, Busy, ChecksFailed, NotAcceptable};
use crate::http::AppState;
use crate::job::JobError;

/// The forms of a report: JSON, or JUnit XML for CI systems.
const FORMS: [&str; 2] = ["application/json", "application/xml"];

/// Run checks.
///
/// The body is a checks document, as `thirdbody check` takes (golden answers inline, as
/// `golden.answer`): each check a job and expectations on its answer. Every job is solved
/// through the cache like a synchronous request. The answer is the report, as JSON or, with
/// `Accept: application/xml`, as JUnit XML: 200 when every check passed, 422 when one
/// failed (as JSON, the problem `checks-failed` with the report's fields as members), so
/// that `curl --fail-with-body` fails a pipeline and still prints the report.
#[utoipa::path(
    post,
    path = "/v1/checks",
    operation_id = "run_checks",
    tag = "solve",
    request_body(content = ChecksInput, content_type = "application/json"),
    responses(
        (status = 200, description = "The report: every check passed", content(
            (Report = "application/json"), (String = "application/xml"))),
        BadBody, ChecksFailed, NotAcceptable, Busy,
    )
)]
pub async fn run(
    State(state): State<AppState>,
    headers: HeaderMap,
    body: JsonBody,
) -> Result<Response, ApiError> {
    let accept = Accept::from_headers(&headers);
    let xml = accept.choose_media(&FORMS)? == FORMS[1];
    let limits = state.config().limits;
    let suite = body
        .read(&state, move |checks| {
            Ok(Suite::from_value(checks, &limits)?)
        })
        .await?;
    if let Some(spec) = suite
        .checks
        .iter()
        .find(|c| c.golden.as_ref().is_some_and(|g| g.answer.is_none()))
    {
        return Err(JobError::Schema {
            field: "golden".to_string(),
            message: format!(
                "check \"{}\": a golden file is for `thirdbody check`; send the answer inline \
                 as golden.answer",
                spec.name
            ),
        }
        .into());
    }
    let mut reports = Vec::new();
    for spec in &suite.checks {
        let meta = spec.job.meta();
        let answer = match state.engine().solve(spec.job.clone(), meta).await {
            Ok((solved, _)) => serde_json::from_slice::<Value>(solved.json())
                .map_err(|e| JobError::Internal(e.to_string())),
            Err(EngineError::Job(e)) => Err(e),
            Err(refusal) => return Err(refusal.into()),
        };
        reports.push(spec.judge(answer));
    }
    let report = Report::new(reports);
    let failed = (!report.passed).then(|| ApiError::checks_failed(&report));
    Ok(match (failed, xml) {
        (None, false) => axum::Json(report).into_response(),
        (None, true) => ([(header::CONTENT_TYPE, FORMS[1])], report.to_junit()).into_response(),
        (Some(failed), false) => failed.into_response(),
        (Some(failed), true) => failed.respond_as(FORMS[1], report.to_junit()),
    })
}
