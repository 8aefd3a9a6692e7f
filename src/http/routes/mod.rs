//! The routes, one module per resource, registered in [`router`] (which the OpenAPI
//! description is built from). A synchronous endpoint of a job kind is a thin handler over
//! [`SolveRequest::solve`]: validate the body as that kind's input, run it through the
//! engine, answer with the cached or fresh result in the form the client accepts.

pub mod checks;
pub mod figures;
pub mod fits;
pub mod history;
pub mod jobs;
pub mod ops;
pub mod rolling;
pub mod shared;
pub mod sweeps;
pub mod three_body;

use axum::body::Body;
use axum::extract::{FromRequest, Request};
use axum::http::{header, HeaderMap, HeaderName, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use serde_json::Value;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::accept::Accept;
use super::access::{self, Caller};
use super::body::{offload, JsonBody};
use super::error::ApiError;
use super::AppState;
use crate::engine::cache::{picture, Solved};
use crate::engine::store::JobResult;
use crate::engine::{heavy, CacheStatus};
use crate::job::meta::{GIT_COMMIT, SOFTWARE_VERSION};
use crate::job::{input_hash_of, Job, Keyed};
use crate::model::MODEL_VERSION;
use crate::render::Format;

/// `hit` when the answer came from the cache (or from an identical request solved at the
/// same time), `miss` when this request solved it.
pub const X_CACHE: HeaderName = HeaderName::from_static("x-cache");

/// The provenance of every answer, for forms that carry no `meta` (CSV): the model's
/// version, the software's version and commit, and the SHA-256 of the input (the cache key).
pub const PROVENANCE: [HeaderName; 4] = [
    HeaderName::from_static("x-model-version"),
    HeaderName::from_static("x-software-version"),
    HeaderName::from_static("x-software-commit"),
    HeaderName::from_static("x-input-hash"),
];

/// The values of [`PROVENANCE`] for the answer whose cache key is `key`.
fn provenance(key: &str) -> [&str; 4] {
    [
        MODEL_VERSION,
        SOFTWARE_VERSION,
        GIT_COMMIT,
        input_hash_of(key),
    ]
}

/// The API's routes with their OpenAPI operations. A synchronous endpoint of a new job kind
/// is its route file and one more `.routes(routes!(...))` line here.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new()
        .routes(routes!(rolling::solve))
        .routes(routes!(three_body::solve))
        .routes(routes!(sweeps::solve))
        .routes(routes!(fits::solve))
        .routes(routes!(checks::run))
        .routes(routes!(jobs::submit, history::list))
        .routes(routes!(jobs::status, jobs::delete))
        .routes(routes!(jobs::cancel))
        .routes(routes!(jobs::events))
        .routes(routes!(jobs::result))
        .routes(routes!(history::by_input))
        .routes(routes!(figures::figure))
        .routes(routes!(ops::healthz))
        .routes(routes!(ops::readyz))
        .routes(routes!(ops::metrics))
}

/// Declares `solve`, the synchronous endpoint of a job kind: `POST $path` (OpenAPI operation
/// `$operation`) with the kind's input as the body, answered with its output as JSON or
/// CSV. The doc comment is the operation's description; `$answer` describes the 200 answer.
macro_rules! solve_endpoint {
    ($(#[doc = $doc:literal])* $path:literal, $operation:literal, $kind:ident, $input:ident, $output:ident, $answer:literal) => {
        $(#[doc = $doc])*
        #[utoipa::path(
            post,
            path = $path,
            operation_id = $operation,
            tag = "solve",
            request_body(content = $input, content_type = "application/json"),
            params($crate::http::routes::FormatQuery),
            responses(
                (status = 200, description = $answer, content(
                    ($output = "application/json"), (String = "text/csv"),
                    (String = "image/svg+xml"))),
                $crate::http::responses::NotModified,
                $crate::http::responses::BadBody,
                $crate::http::responses::NotAcceptable,
                $crate::http::responses::Busy,
                $crate::http::responses::SolveErrors,
            )
        )]
        pub async fn solve(
            request: $crate::http::routes::SolveRequest,
        ) -> Result<axum::response::Response, $crate::http::error::ApiError> {
            request.solve(<$kind as $crate::job::Kind>::NAME).await
        }
    };
}
use solve_endpoint;

/// `?format=`: the form of the answer, for links (overrides `Accept`).
#[derive(utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct FormatQuery {
    /// The answer's form: its JSON, its CSV table, or its picture (SVG).
    #[allow(dead_code)]
    #[param(inline)]
    format: Option<FormatName>,
}

/// The forms of an answer, by name.
#[derive(utoipa::ToSchema)]
#[allow(dead_code)]
#[schema(rename_all = "lowercase")]
pub enum FormatName {
    Json,
    Csv,
    Svg,
}

/// How an answer is to be sent: the form the client accepts, and the validator it holds.
/// As an extractor: from the request's headers and query.
pub struct Answering {
    format: Format,
    if_none_match: Vec<String>,
}

impl<S: Send + Sync> axum::extract::FromRequestParts<S> for Answering {
    type Rejection = ApiError;

    async fn from_request_parts(
        parts: &mut axum::http::request::Parts,
        _: &S,
    ) -> Result<Self, ApiError> {
        Answering::read(&parts.headers, parts.uri.query())
    }
}

impl Answering {
    /// Reads the form asked: `?format=` (for links, where no header can be set), else
    /// `Accept` (406 if no form of an answer is acceptable); and `If-None-Match`.
    pub fn read(headers: &HeaderMap, query: Option<&str>) -> Result<Answering, ApiError> {
        let asked = query
            .into_iter()
            .flat_map(|q| q.split('&'))
            .find_map(|pair| pair.strip_prefix("format="));
        let format = match asked {
            Some(name) => Format::from_name(name).ok_or_else(|| {
                ApiError::not_acceptable(format!(
                    "format={name}: the forms of an answer are json, csv and svg"
                ))
            })?,
            None => Accept::from_headers(headers).choose(&Format::ALL)?,
        };
        let if_none_match = headers
            .get_all(header::IF_NONE_MATCH)
            .iter()
            .filter_map(|v| v.to_str().ok())
            .map(str::to_string)
            .collect();
        Ok(Answering {
            format,
            if_none_match,
        })
    }

    /// The answer with its validators and provenance: the `ETag` is the cache key (per
    /// form), so an `If-None-Match` that names it gets `304` and no body. `cache` says
    /// whether it was solved for this request, when it may have been. A partial answer (of a
    /// stopped job) has no `ETag`: another stop would give another answer.
    pub fn respond(
        &self,
        solved: &Solved,
        cache: Option<CacheStatus>,
    ) -> Result<Response, ApiError> {
        self.answer(&solved.key, solved.complete, cache, || {
            solved
                .body(self.format)
                .map(Body::from)
                .map_err(|e| ApiError::internal(e.to_string()))
        })
    }

    /// A job's result as [`Answering::respond`] gives an answer, wherever it is kept: one in
    /// the database or the fleet's Redis is read in the form asked for only (a picture is
    /// drawn from its JSON).
    pub async fn respond_result(&self, result: &JobResult) -> Result<Response, ApiError> {
        let unreadable = |e: std::io::Error| {
            ApiError::internal(format!("the job's result cannot be read back: {e}"))
        };
        let (key, kind, complete) = match result {
            JobResult::Ready(solved) => return self.respond(solved, None),
            JobResult::Stored(stored) => (&stored.key, stored.kind, stored.complete),
        };
        let body = match (self.format, result) {
            (Format::Svg, _) => {
                let json = self
                    .stored_body(result, Format::Json)
                    .await
                    .map_err(unreadable)?;
                let svg = heavy::run(move || picture(kind, &json))
                    .await
                    .map_err(|e| ApiError::internal(e.to_string()))?
                    .map_err(|e| ApiError::internal(e.to_string()))?;
                Body::from(svg)
            }
            (format, _) => Body::from(self.stored_body(result, format).await.map_err(unreadable)?),
        };
        let mut body = Some(body);
        self.answer(key, complete, None, || {
            body.take()
                .ok_or_else(|| ApiError::internal("the body was taken twice"))
        })
    }

    /// The JSON or CSV of a result kept in the fleet's Redis.
    async fn stored_body(
        &self,
        result: &JobResult,
        format: Format,
    ) -> std::io::Result<bytes::Bytes> {
        let JobResult::Stored(stored) = result else {
            return Err(std::io::Error::other("the result is not in Redis"));
        };
        stored
            .place
            .body(if format == Format::Csv { "csv" } else { "json" })
            .await
    }

    /// The response carrying `body` (called unless the client holds it already) for the
    /// answer whose cache key is `key`.
    fn answer(
        &self,
        key: &str,
        complete: bool,
        cache: Option<CacheStatus>,
        body: impl FnOnce() -> Result<Body, ApiError>,
    ) -> Result<Response, ApiError> {
        let etag = complete.then(|| match self.format {
            Format::Json => format!("\"{key}\""),
            other => format!("\"{key}.{}\"", other.name()),
        });
        let held = etag
            .as_ref()
            .is_some_and(|etag| if_none_match(&self.if_none_match, etag));
        let mut response = if held {
            StatusCode::NOT_MODIFIED.into_response()
        } else {
            let content_type = [(header::CONTENT_TYPE, self.format.content_type())];
            (content_type, body()?).into_response()
        };
        let h = response.headers_mut();
        if let Some(etag) = etag.and_then(|etag| HeaderValue::from_str(&etag).ok()) {
            h.insert(header::ETAG, etag);
        }
        if let Some(cache) = cache {
            h.insert(X_CACHE, HeaderValue::from_static(cache.as_str()));
        }
        h.insert(header::VARY, HeaderValue::from_static("accept"));
        for (name, value) in PROVENANCE.into_iter().zip(provenance(key)) {
            if let Ok(value) = HeaderValue::from_str(value) {
                h.insert(name, value);
            }
        }
        Ok(response)
    }

    /// Solves a validated job and answers it.
    pub async fn solve(&self, state: &AppState, keyed: Keyed) -> Result<Response, ApiError> {
        let (solved, cache) = state.engine().solve(keyed).await?;
        self.respond(&solved, Some(cache))
    }
}

/// A request to a synchronous endpoint: the job's input as the JSON body, and how the
/// answer is to be sent.
pub struct SolveRequest {
    state: AppState,
    caller: Caller,
    answering: Answering,
    body: JsonBody,
}

impl FromRequest<AppState> for SolveRequest {
    type Rejection = ApiError;

    async fn from_request(request: Request, state: &AppState) -> Result<Self, ApiError> {
        let answering = Answering::read(request.headers(), request.uri().query())?;
        let caller = Caller::of(request.extensions());
        let body = JsonBody::from_request(request, state).await?;
        Ok(SolveRequest {
            state: state.clone(),
            caller,
            answering,
            body,
        })
    }
}

impl SolveRequest {
    /// Answers the input as a job of the kind named `kind` ([`crate::engine::Engine::answer`]:
    /// an input seen before, the same JSON up to key order and spacing, is answered from the
    /// cache without being validated again, and costs the caller's quota nothing).
    pub async fn solve(self, kind: &'static str) -> Result<Response, ApiError> {
        let state = &self.state;
        // A tenant's inputs are remembered, and their answers kept, apart ([`Keyed::scoped`]).
        let tenant = self.caller.tenant().map(str::to_string);
        let scope = tenant.clone().unwrap_or_default();
        let (input, text) = self
            .body
            .read(state, move |input: Value| {
                let text = format!("{scope}\n{kind}\n{input}");
                Ok((input, text))
            })
            .await?;
        let limits = state.config().limits;
        let valid = offload(state, text.len(), move || {
            let job = Job::from_input(kind, input, &limits)?;
            match job.asynchronous_only() {
                Some(refusal) => Err(refusal.into()),
                None => Ok(job.keyed().scoped(tenant.as_deref())),
            }
        });
        let caller = &self.caller;
        let charged = std::sync::Mutex::new(None);
        let validate = async {
            let keyed = valid.await?;
            *charged.lock().unwrap_or_else(|p| p.into_inner()) =
                access::charge(state, caller, &keyed).await?;
            Ok::<_, ApiError>(keyed)
        };
        let started = std::time::Instant::now();
        let answered = state.engine().answer(text, validate).await;
        let charged = charged.into_inner().unwrap_or_else(|p| p.into_inner());
        // What was charged is given back if the solve was refused before any work (no
        // thread, no room: 429, 503), and a guess is trued up by what the solve took
        // (nothing, for another request's solve).
        let refused_before_work = |e: &ApiError| {
            [
                StatusCode::TOO_MANY_REQUESTS,
                StatusCode::SERVICE_UNAVAILABLE,
            ]
            .contains(&e.status())
        };
        let (solved, cache) = match (answered, charged) {
            (Err(refused), Some(charge)) if refused_before_work(&refused) => {
                state.engine().points.refund(&charge).await;
                return Err(refused);
            }
            (answered, charge) => {
                let (solved, cache) = answered?;
                if let Some(charge) = charge {
                    let took = match cache {
                        CacheStatus::Miss => started.elapsed(),
                        CacheStatus::Hit => std::time::Duration::ZERO,
                    };
                    state.engine().points.true_up(&charge, took).await;
                }
                (solved, cache)
            }
        };
        self.answering.respond(&solved, Some(cache))
    }
}

/// Whether `If-None-Match` names `etag` (weak comparison, as for GET) or is `*`.
fn if_none_match(values: &[String], etag: &str) -> bool {
    values
        .iter()
        .flat_map(|v| v.split(','))
        .map(str::trim)
        .any(|tag| tag == "*" || tag.trim_start_matches("W/") == etag)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(name: HeaderName, value: &'static str) -> HeaderMap {
        HeaderMap::from_iter([(name, HeaderValue::from_static(value))])
    }

    #[test]
    fn csv_is_chosen_only_when_preferred() {
        for (accept, csv) in [
            ("text/csv", true),
            ("text/csv, application/json;q=0.5", true),
            ("application/json, text/csv;q=0.5", false),
            ("application/json", false),
            ("*/*", false),
            ("text/csv;q=0", false),
        ] {
            let format = Answering::read(&headers(header::ACCEPT, accept), None).map(|a| a.format);
            assert_eq!(format.is_ok_and(|f| f == Format::Csv), csv, "{accept}");
        }
        let none = Answering::read(&HeaderMap::new(), None).unwrap();
        assert_eq!(none.format, Format::Json);
    }

    #[test]
    fn an_unacceptable_form_is_406() {
        let refused = Answering::read(&headers(header::ACCEPT, "image/png"), None);
        assert_eq!(
            refused.err().map(|e| e.status()),
            Some(StatusCode::NOT_ACCEPTABLE)
        );
    }

    #[test]
    fn if_none_match_compares_weakly_and_takes_lists() {
        let etag = "\"abc\"";
        for (value, matches) in [
            ("\"abc\"", true),
            ("W/\"abc\"", true),
            ("\"x\", \"abc\"", true),
            ("*", true),
            ("\"abd\"", false),
        ] {
            assert_eq!(
                if_none_match(&[value.to_string()], etag),
                matches,
                "{value}"
            );
        }
    }
}
