//! One error contract: every error response is an RFC 9457 problem
//! (`application/problem+json`), whether it comes from a job, the engine, a JSON body axum
//! could not read, or a layer (method not allowed, timeout, panic).

use axum::body::Body;
use axum::extract::rejection::BytesRejection;
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use serde::Serialize;
use serde_json::{Map, Value};
use std::time::Duration;
use utoipa::ToSchema;

use crate::check::Report;
use crate::engine::{Backlogged, EngineError};
use crate::job::{FieldError, JobError};
use crate::model::text::{count, quantity};

pub const PROBLEM_JSON: &str = "application/problem+json";

/// Prefix of the problem type URIs: names, not addresses (RFC 9457 §3.1.1 allows a URI
/// that is not meant to be dereferenced; the types are listed in the OpenAPI spec).
const TYPE_PREFIX: &str = "tag:thirdbody,2026:problems/";

/// An RFC 9457 problem: the body of every error response.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Problem {
    /// The kind of problem: `tag:thirdbody,2026:problems/` followed by one of
    /// `malformed-json` (400), `invalid-input` (422: a field's shape or value; see `errors`),
    /// `solve-failed` (422: valid values for which the model cannot produce a number, e.g. a
    /// root finder that did not converge; change the input), `out-of-domain` (422: an
    /// assumption of the model fails for these values, see `meta.validity`),
    /// `checks-failed` (422: checks run by `POST /v1/checks` failed; the report's fields are
    /// extension members),
    /// `unsupported-media-type` (415),
    /// `not-acceptable` (406: the `Accept` header names no form the resource offers),
    /// `payload-too-large` (413), `unauthorized` (401: no API key where one is needed, or a
    /// key not accepted: unknown, expired), `forbidden` (403: the caller's key lacks the
    /// scope, or the job is another's to change; a refused cross-origin preflight),
    /// `not-found` (404), `interrupted` (410: the service stopped
    /// before the job finished), `not-ready` (409: the job has no result yet), `cancelled`
    /// (409), `overloaded` (429), `quota-exceeded` (429: the caller's quota of points a
    /// minute, or of unfinished jobs, is used up; `Retry-After` when waiting helps),
    /// `too-many-streams` (429: every event stream the service follows at once is open; poll
    /// the job instead),
    /// `draining` (503), `unavailable` (503: the shared job store cannot be reached),
    /// `results-full` (503: no room to keep the job's result now; retry after `Retry-After`),
    /// `result-too-large` (422: the job's result would not fit even in an empty store),
    /// `deadline-exceeded` (504), `internal` (500); or `about:blank` for a
    /// status with no more to say than its title.
    #[serde(rename = "type")]
    pub problem_type: String,
    /// A short summary of the kind of problem.
    pub title: String,
    /// The HTTP status code.
    pub status: u16,
    /// What went wrong in this case.
    pub detail: String,
    /// Every invalid field, with its path, the value sent and the allowed values
    /// (`invalid-input` only).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<FieldError>,
    /// Extension members (RFC 9457 §3.2) at the top level: for `checks-failed`, the report's
    /// own fields (`passed`, `summary`, `checks`), read as in the 200 answer of checks that
    /// passed.
    #[serde(flatten)]
    pub extensions: Map<String, Value>,
}

/// The kinds of problem the service names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    MalformedJson,
    InvalidInput,
    SolveFailed,
    OutOfDomain,
    ChecksFailed,
    UnsupportedMediaType,
    NotAcceptable,
    PayloadTooLarge,
    Unauthorized,
    Forbidden,
    NotFound,
    Interrupted,
    NotReady,
    Cancelled,
    Overloaded,
    QuotaExceeded,
    TooManyStreams,
    Draining,
    Unavailable,
    ResultsFull,
    ResultTooLarge,
    DeadlineExceeded,
    Internal,
    /// `about:blank`: the status says it all.
    Blank(StatusCode),
}

impl Kind {
    fn status(self) -> StatusCode {
        match self {
            Kind::MalformedJson => StatusCode::BAD_REQUEST,
            // Not 417 for failed checks: curl resends a request answered 417 (as a refusal
            // of `Expect: 100-continue`), so a pipeline would run its checks twice.
            Kind::InvalidInput
            | Kind::SolveFailed
            | Kind::OutOfDomain
            | Kind::ChecksFailed
            | Kind::ResultTooLarge => StatusCode::UNPROCESSABLE_ENTITY,
            Kind::UnsupportedMediaType => StatusCode::UNSUPPORTED_MEDIA_TYPE,
            Kind::NotAcceptable => StatusCode::NOT_ACCEPTABLE,
            Kind::PayloadTooLarge => StatusCode::PAYLOAD_TOO_LARGE,
            Kind::Unauthorized => StatusCode::UNAUTHORIZED,
            Kind::Forbidden => StatusCode::FORBIDDEN,
            Kind::NotFound => StatusCode::NOT_FOUND,
            Kind::Interrupted => StatusCode::GONE,
            Kind::Cancelled | Kind::NotReady => StatusCode::CONFLICT,
            Kind::Overloaded | Kind::QuotaExceeded | Kind::TooManyStreams => {
                StatusCode::TOO_MANY_REQUESTS
            }
            Kind::Draining | Kind::Unavailable | Kind::ResultsFull => {
                StatusCode::SERVICE_UNAVAILABLE
            }
            Kind::DeadlineExceeded => StatusCode::GATEWAY_TIMEOUT,
            Kind::Internal => StatusCode::INTERNAL_SERVER_ERROR,
            Kind::Blank(status) => status,
        }
    }

    /// The last segment of the type URI, and the title.
    fn name(self) -> Option<(&'static str, &'static str)> {
        Some(match self {
            Kind::MalformedJson => ("malformed-json", "The body is not valid JSON"),
            Kind::InvalidInput => ("invalid-input", "The input is not valid"),
            Kind::SolveFailed => ("solve-failed", "The model cannot solve this input"),
            Kind::OutOfDomain => ("out-of-domain", "Outside the model's domain of validity"),
            Kind::ChecksFailed => ("checks-failed", "Checks failed"),
            Kind::UnsupportedMediaType => ("unsupported-media-type", "Send application/json"),
            Kind::NotAcceptable => ("not-acceptable", "No acceptable form of the answer"),
            Kind::PayloadTooLarge => ("payload-too-large", "The body is too large"),
            Kind::Unauthorized => (
                "unauthorized",
                "An API key is needed, or the one sent is not accepted",
            ),
            Kind::Forbidden => ("forbidden", "The caller may not do this"),
            Kind::NotFound => ("not-found", "Not found"),
            Kind::Interrupted => ("interrupted", "The service stopped before the job finished"),
            Kind::NotReady => ("not-ready", "The job has no result yet"),
            Kind::Cancelled => ("cancelled", "The job was cancelled"),
            Kind::Overloaded => ("overloaded", "Every solver thread is busy"),
            Kind::QuotaExceeded => ("quota-exceeded", "The caller's quota is used up"),
            Kind::TooManyStreams => ("too-many-streams", "Too many event streams are open"),
            Kind::Draining => ("draining", "The service is shutting down"),
            Kind::Unavailable => (
                "unavailable",
                "The shared job store cannot take the job now",
            ),
            Kind::ResultsFull => ("results-full", "No room to keep the job's result now"),
            Kind::ResultTooLarge => ("result-too-large", "The job's result is too large to keep"),
            Kind::DeadlineExceeded => ("deadline-exceeded", "The solve ran past its deadline"),
            Kind::Internal => ("internal", "Internal error"),
            Kind::Blank(_) => return None,
        })
    }

    /// Seconds a client should wait before trying again, where waiting helps.
    fn retry_after(self) -> Option<u32> {
        match self {
            // Solves take microseconds to seconds: a permit is soon free.
            Kind::Overloaded | Kind::NotReady => Some(1),
            // Another instance should have taken over by then; streams end as jobs do.
            Kind::Draining | Kind::TooManyStreams => Some(5),
            // Redis reconnects by itself within a second or two.
            Kind::Unavailable => Some(2),
            _ => None,
        }
    }
}

/// Marks a response as an error the service answered itself (a problem, or another form of
/// one that the client asked for), which [`problem_for_errors`] leaves as it is.
#[derive(Clone, Copy, Debug)]
struct Answered;

/// An error on its way to the client.
#[derive(Clone, Debug, PartialEq)]
pub struct ApiError {
    kind: Kind,
    detail: String,
    errors: Vec<FieldError>,
    extensions: Map<String, Value>,
    /// Seconds to wait before trying again, when this case knows better than its kind.
    retry_after: Option<u32>,
    /// What went wrong inside the service: logged when the answer is sent, never sent (it
    /// may name files, threads or internals a client has no use for).
    internal: Option<String>,
}

/// The detail of every internal error a client sees.
const INTERNAL_DETAIL: &str = "the service failed to answer this request; the failure was \
    logged with its x-request-id: quote it when reporting this";

impl ApiError {
    fn new(kind: Kind, detail: impl Into<String>) -> Self {
        ApiError {
            kind,
            detail: detail.into(),
            errors: Vec::new(),
            extensions: Map::new(),
            retry_after: None,
            internal: None,
        }
    }

    /// Checks run by `POST /v1/checks` failed: an error status, so that a pipeline calling
    /// `curl --fail-with-body` fails and still prints the report, whose fields are the
    /// problem's extension members.
    pub fn checks_failed(report: &Report) -> Self {
        let Ok(Value::Object(extensions)) = serde_json::to_value(report) else {
            unreachable!("a report is a JSON object");
        };
        ApiError {
            extensions,
            ..ApiError::new(Kind::ChecksFailed, report.failed_checks())
        }
    }

    pub fn not_found(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::NotFound, detail)
    }

    /// No API key where one is needed, or one that is not accepted.
    pub fn unauthorized(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::Unauthorized, detail)
    }

    /// A caller known, and not allowed to do this.
    pub fn forbidden(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::Forbidden, detail)
    }

    pub fn not_acceptable(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::NotAcceptable, detail)
    }

    pub fn unsupported_media_type(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::UnsupportedMediaType, detail)
    }

    pub fn payload_too_large(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::PayloadTooLarge, detail)
    }

    pub fn interrupted(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::Interrupted, detail)
    }

    pub fn not_ready(detail: impl Into<String>) -> Self {
        ApiError::new(Kind::NotReady, detail)
    }

    /// An internal failure: `detail` is logged, the client told only that it happened.
    pub fn internal(detail: impl Into<String>) -> Self {
        ApiError {
            internal: Some(detail.into()),
            ..ApiError::new(Kind::Internal, INTERNAL_DETAIL)
        }
    }

    /// The caller's quota is used up: retry after `retry_after`, if waiting helps.
    pub fn quota_exceeded(detail: impl Into<String>, retry_after: Option<Duration>) -> Self {
        ApiError {
            retry_after: retry_after
                .map(|wait| wait.as_secs().clamp(1, u64::from(u32::MAX)) as u32),
            ..ApiError::new(Kind::QuotaExceeded, detail)
        }
    }

    /// Every event stream this service follows at once (`limit`) is open.
    pub fn too_many_streams(limit: usize) -> Self {
        ApiError::new(
            Kind::TooManyStreams,
            format!(
                "{limit} event streams are open, the most this service follows at once \
                 (an eighth of --max-connections): poll GET /v1/jobs/{{id}} instead, or follow the job \
                 again later"
            ),
        )
    }

    pub fn draining() -> Self {
        EngineError::Draining.into()
    }

    /// A problem that says no more than `status` and `detail`.
    pub fn from_status(status: StatusCode, detail: impl Into<String>) -> Self {
        ApiError::new(Kind::Blank(status), detail)
    }

    pub fn status(&self) -> StatusCode {
        self.kind.status()
    }

    /// The problem document.
    pub fn problem(&self) -> Problem {
        let status = self.status();
        let (problem_type, title) = match self.kind.name() {
            Some((name, title)) => (format!("{TYPE_PREFIX}{name}"), title),
            None => (
                "about:blank".to_string(),
                status.canonical_reason().unwrap_or("Error"),
            ),
        };
        Problem {
            problem_type,
            title: title.to_string(),
            status: status.as_u16(),
            detail: self.detail.clone(),
            errors: self.errors.clone(),
            extensions: self.extensions.clone(),
        }
    }

    /// The answer with this error's status and headers, and `body` (of `content_type`)
    /// instead of the problem document: the form of the problem the client asked for, e.g.
    /// the JUnit report of failed checks for a CI system that reads JUnit.
    pub fn respond_as(self, content_type: &'static str, body: impl Into<Body>) -> Response {
        let status = self.status();
        if status.is_server_error() {
            tracing::error!(status = status.as_u16(), detail = %self.detail, "request failed");
        }
        let mut response =
            (status, [(header::CONTENT_TYPE, content_type)], body.into()).into_response();
        if let Some(seconds) = self.retry_after.or(self.kind.retry_after()) {
            response
                .headers_mut()
                .insert(header::RETRY_AFTER, HeaderValue::from(seconds));
        }
        if self.kind == Kind::Unauthorized {
            response.headers_mut().insert(
                header::WWW_AUTHENTICATE,
                HeaderValue::from_static("Bearer realm=\"thirdbody\""),
            );
        }
        response.extensions_mut().insert(Answered);
        response
    }
}

impl From<JobError> for ApiError {
    fn from(e: JobError) -> Self {
        let e = e.cut();
        let detail = e.to_string();
        match e {
            JobError::Syntax(_) => ApiError::new(Kind::MalformedJson, detail),
            JobError::Schema { field, .. } => ApiError {
                errors: vec![FieldError {
                    field,
                    value: Value::Null,
                    allowed: "the shape given by the input's schema in /openapi.json".to_string(),
                    message: detail.clone(),
                }],
                ..ApiError::new(Kind::InvalidInput, detail)
            },
            JobError::Invalid(errors) => ApiError {
                errors,
                ..ApiError::new(Kind::InvalidInput, detail)
            },
            // Deterministic, so retrying cannot help and the service is not at fault: the
            // client must change the input.
            JobError::Unsolvable(_) => ApiError::new(Kind::SolveFailed, detail),
            JobError::OutOfDomain(_) => ApiError::new(Kind::OutOfDomain, detail),
            JobError::Cancelled => ApiError::new(Kind::Cancelled, detail),
            JobError::DeadlineExceeded => ApiError::new(Kind::DeadlineExceeded, detail),
            JobError::Abandoned(_) => ApiError::new(Kind::Internal, detail),
            JobError::Internal(_) => ApiError::internal(detail),
        }
    }
}

impl ApiError {
    /// A job refused because the queue ahead of it, or the job alone, would take it past
    /// its deadline.
    fn backlogged(backlogged: Backlogged) -> ApiError {
        let Backlogged {
            ahead,
            needs,
            deadline,
        } = backlogged;
        if needs > deadline {
            return ApiError::new(
                Kind::Overloaded,
                format!(
                    "the job was not accepted: it alone needs about {} (estimated from the \
                     jobs of its kind solved here), more than its deadline of {} \
                     (--job-deadline), and other work is queued ahead of it: split it",
                    quantity(needs.as_secs_f64(), "s"),
                    quantity(deadline.as_secs_f64(), "s"),
                ),
            );
        }
        let ahead_s = ahead.as_secs_f64().ceil().max(1.0);
        ApiError::new(
            Kind::Overloaded,
            format!(
                "the job was not accepted: the jobs accepted before it hold the \
                 job threads for about {} and it needs about {} more (estimated \
                 from the jobs of its kind solved here), past its deadline of {} \
                 (--job-deadline). Retry in about {}, or split it",
                quantity(ahead.as_secs_f64(), "s"),
                quantity(needs.as_secs_f64(), "s"),
                quantity(deadline.as_secs_f64(), "s"),
                quantity(ahead_s, "s"),
            ),
        )
        .retrying_in(ahead_s)
    }

    /// A job refused because the results kept have no room for its result now.
    fn results_full(what: &str, retry_after: Duration) -> ApiError {
        // Rounded up, and at least a second: room is made no sooner.
        let seconds = retry_after.as_secs_f64().ceil().max(1.0);
        ApiError::new(
            Kind::ResultsFull,
            format!(
                "the job was not accepted, so that its result is not lost after \
                 the work: {what}. Room is made as finished jobs expire (the next \
                 in {seconds} s) or are deleted (DELETE /v1/jobs/{{id}}); a \
                 smaller job may fit now"
            ),
        )
        .retrying_in(seconds)
    }

    /// The same error, saying to retry in `seconds` (whole, and at least one).
    fn retrying_in(self, seconds: f64) -> ApiError {
        ApiError {
            retry_after: Some(seconds.min(f64::from(u32::MAX)) as u32),
            ..self
        }
    }
}

impl From<EngineError> for ApiError {
    fn from(e: EngineError) -> Self {
        match e {
            EngineError::Job(e) => e.into(),
            EngineError::Overloaded => ApiError::new(
                Kind::Overloaded,
                "every solver thread is busy and the job queue is full or not used: \
                 retry shortly, or submit big work to /v1/jobs",
            ),
            EngineError::Backlogged(backlogged) => ApiError::backlogged(backlogged),
            EngineError::Draining => ApiError::new(
                Kind::Draining,
                "the service is shutting down and takes no new work",
            ),
            EngineError::Unavailable(why) => ApiError::new(
                Kind::Unavailable,
                format!(
                    "{why}: the job was not accepted, so that none is lost; synchronous \
                     solves still work"
                ),
            ),
            EngineError::ResultsFull { what, retry_after } => {
                ApiError::results_full(&what, retry_after)
            }
            EngineError::ResultTooLarge { needed, limit } => ApiError::new(
                Kind::ResultTooLarge,
                format!(
                    "the job's result may take up to {:.1} MB, more than the {:.1} MB this \
                     service keeps for one result (--memory-budget; a --database file keeps larger ones): split the \
                     job, or ask for fewer points",
                    needed as f64 / 1e6,
                    limit as f64 / 1e6
                ),
            ),
        }
    }
}

impl ApiError {
    /// A body that could not be read: over the service's `limit` (bytes), or cut off.
    pub fn unreadable_body(rejection: &BytesRejection, limit: usize) -> Self {
        match rejection.status() {
            StatusCode::PAYLOAD_TOO_LARGE => ApiError::payload_too_large(too_large(None, limit)),
            status => ApiError::from_status(
                status,
                format!(
                    "the body could not be read whole ({}): send it again",
                    rejection.body_text().to_lowercase()
                ),
            ),
        }
    }
}

/// Why a body is refused as too large: its size if it declared one, and the limit.
pub fn too_large(declared: Option<u64>, limit: usize) -> String {
    let limit = count(limit as f64, "byte", "bytes");
    match declared {
        Some(length) => format!(
            "the body declares {}; this service takes at most {limit} (its --body-limit)",
            count(length as f64, "byte", "bytes")
        ),
        None => format!(
            "the body is longer than this service takes: at most {limit} (its --body-limit)"
        ),
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        if let Some(internal) = &self.internal {
            tracing::error!(error = %internal, "internal error");
        }
        let body = serde_json::to_vec(&self.problem()).unwrap_or_default();
        self.respond_as(PROBLEM_JSON, body)
    }
}

/// Turns an error response the service did not answer itself (axum's 405, a timeout, a
/// rejection with a plain-text body) into a problem, keeping its status, headers and text.
pub async fn problem_for_errors(response: Response) -> Response {
    let status = response.status();
    let answered = response.extensions().get::<Answered>().is_some();
    if !(status.is_client_error() || status.is_server_error()) || answered {
        return response;
    }
    let (mut parts, body) = response.into_parts();
    let text = axum::body::to_bytes(body, 4096)
        .await
        .ok()
        .and_then(|b| String::from_utf8(b.to_vec()).ok())
        .map(|t| t.trim().to_string())
        .filter(|t| !t.is_empty());
    let detail = text.unwrap_or_else(|| match status {
        // Axum sets the Allow header after this mapping: the detail points to it.
        StatusCode::METHOD_NOT_ALLOWED => {
            "this route does not take this method; the Allow header names those it takes"
                .to_string()
        }
        StatusCode::REQUEST_TIMEOUT => "the request took longer than this service gives one \
            (its --solve-deadline and 30 s more): send less work at once, or submit it to /v1/jobs"
            .to_string(),
        _ => status.canonical_reason().unwrap_or("").to_string(),
    });
    let problem = ApiError::from_status(status, detail).problem();
    parts.headers.remove(header::CONTENT_LENGTH);
    parts
        .headers
        .insert(header::CONTENT_TYPE, HeaderValue::from_static(PROBLEM_JSON));
    let body = serde_json::to_vec(&problem).unwrap_or_default();
    Response::from_parts(parts, Body::from(body))
}

/// The answer to a request whose handler panicked.
pub fn panic_response(_panic: Box<dyn std::any::Any + Send + 'static>) -> Response {
    ApiError::internal("the request handler panicked").into_response()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{ModelError, ParameterError};

    fn kind_of(e: JobError) -> (u16, String) {
        let problem = ApiError::from(e).problem();
        (problem.status, problem.problem_type)
    }

    #[test]
    fn job_errors_map_to_their_statuses() {
        let t = |name: &str| format!("{TYPE_PREFIX}{name}");
        let no_convergence = ModelError::NoConvergence {
            what: "load equation",
            iterations: 100,
        };
        let invalid = ModelError::InvalidParameter(ParameterError {
            parameter: crate::model::Parameter::Radius,
            value: -1.0,
            allowed: "> 0".to_string(),
        });
        for (error, status, name) in [
            (JobError::Syntax("x".into()), 400, "malformed-json"),
            (JobError::Invalid(vec![]), 422, "invalid-input"),
            (invalid.into(), 422, "invalid-input"),
            (no_convergence.into(), 422, "solve-failed"),
            (JobError::Cancelled, 409, "cancelled"),
            (JobError::DeadlineExceeded, 504, "deadline-exceeded"),
            (JobError::Internal("x".into()), 500, "internal"),
        ] {
            assert_eq!(kind_of(error), (status, t(name)));
        }
    }

    #[test]
    fn an_internal_failure_is_logged_not_sent() {
        let why = "cannot write /var/lib/thirdbody/spill/17.json: permission denied";
        for error in [
            ApiError::internal(why),
            JobError::Internal(why.to_string()).into(),
        ] {
            let problem = serde_json::to_value(error.problem()).unwrap();
            assert_eq!(problem["detail"], INTERNAL_DETAIL);
            assert!(!problem.to_string().contains("spill"), "{problem}");
            assert!(error.internal.is_some_and(|logged| logged.ends_with(why)));
        }
    }

    #[test]
    fn a_schema_error_names_its_field() {
        let problem = ApiError::from(JobError::Schema {
            field: "layer.thickness".into(),
            message: "invalid type".into(),
        })
        .problem();
        assert_eq!(problem.errors.len(), 1);
        assert_eq!(problem.errors[0].field, "layer.thickness");
    }

    #[test]
    fn refusals_say_when_to_retry() {
        let overloaded = ApiError::from(EngineError::Overloaded).into_response();
        assert_eq!(overloaded.status(), StatusCode::TOO_MANY_REQUESTS);
        assert_eq!(overloaded.headers()[header::RETRY_AFTER], "1");
        let draining = ApiError::draining().into_response();
        assert_eq!(draining.status(), StatusCode::SERVICE_UNAVAILABLE);
        assert!(draining.headers().contains_key(header::RETRY_AFTER));
    }

    #[tokio::test]
    async fn plain_error_responses_become_problems_and_others_pass() {
        let plain = (StatusCode::METHOD_NOT_ALLOWED, [(header::ALLOW, "GET")], "").into_response();
        let mapped = problem_for_errors(plain).await;
        assert_eq!(mapped.status(), StatusCode::METHOD_NOT_ALLOWED);
        assert_eq!(mapped.headers()[header::CONTENT_TYPE], PROBLEM_JSON);
        assert_eq!(mapped.headers()[header::ALLOW], "GET");
        let body = axum::body::to_bytes(mapped.into_body(), 4096)
            .await
            .unwrap();
        let problem: Value = serde_json::from_slice(&body).unwrap();
        assert_eq!(problem["type"], "about:blank");
        assert_eq!(problem["title"], "Method Not Allowed");
        assert_eq!(
            problem["detail"],
            "this route does not take this method; the Allow header names those it takes"
        );

        let ok = problem_for_errors(StatusCode::NOT_MODIFIED.into_response()).await;
        assert_eq!(ok.status(), StatusCode::NOT_MODIFIED);
        assert!(!ok.headers().contains_key(header::CONTENT_TYPE));
    }

    #[tokio::test]
    async fn failed_checks_are_a_problem_carrying_the_report_in_any_form() {
        use crate::check::{CheckReport, Outcome};
        let mut low = CheckReport::new("mu stays low", "rolling");
        low.outcomes
            .push(Outcome::failed("x", "at most 1", Some(2.0), "x = 2"));
        low.settle();
        let mut area = CheckReport::new("area", "rolling");
        area.settle();
        let report = Report::new(vec![low, area]);
        let failed = ApiError::checks_failed(&report);

        let problem = serde_json::to_value(failed.problem()).unwrap();
        let mut members = serde_json::to_value(&report).unwrap();
        for (name, value) in [
            ("type", format!("{TYPE_PREFIX}checks-failed").into()),
            ("title", "Checks failed".into()),
            ("status", 422.into()),
            ("detail", "1 of 2 checks failed: mu stays low".into()),
        ] {
            members[name] = value;
        }
        assert_eq!(problem, members, "the report's fields at the top level");

        let junit = failed.respond_as("application/xml", report.to_junit());
        let kept = problem_for_errors(junit).await;
        assert_eq!(kept.status(), StatusCode::UNPROCESSABLE_ENTITY);
        assert_eq!(kept.headers()[header::CONTENT_TYPE], "application/xml");
        let body = axum::body::to_bytes(kept.into_body(), 1 << 16)
            .await
            .unwrap();
        assert_eq!(body, report.to_junit().as_bytes());
    }
}
