//! The routes, one module per resource. A synchronous endpoint of a job kind is a thin
//! handler over [`SolveRequest::solve`]: validate the body as that kind's input, run it
//! through the engine, answer with the cached or fresh result.

pub mod figures;
pub mod jobs;
pub mod ops;
pub mod rolling;
pub mod sweeps;
pub mod three_body;

use axum::extract::{FromRequest, Request};
use axum::http::{header, HeaderMap, HeaderName, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use serde_json::Value;

use super::error::{ApiError, JsonBody};
use super::AppState;
use crate::engine::cache::Solved;
use crate::engine::CacheStatus;
use crate::job::{Job, JobKind, Meta};

/// `hit` when the answer came from the cache (or from an identical request solved at the
/// same time), `miss` when this request solved it.
pub const X_CACHE: HeaderName = HeaderName::from_static("x-cache");

/// A request to a synchronous endpoint: the job's input as the JSON body, and the headers
/// that choose the answer's form (`Accept`, `If-None-Match`).
pub struct SolveRequest {
    state: AppState,
    headers: HeaderMap,
    input: Value,
}

impl FromRequest<AppState> for SolveRequest {
    type Rejection = ApiError;

    async fn from_request(request: Request, state: &AppState) -> Result<Self, ApiError> {
        // Only the headers that choose the answer's form are kept.
        let mut headers = HeaderMap::new();
        for name in [header::ACCEPT, header::IF_NONE_MATCH] {
            for value in request.headers().get_all(&name) {
                headers.append(name.clone(), value.clone());
            }
        }
        let JsonBody(input) = JsonBody::from_request(request, state).await?;
        Ok(SolveRequest {
            state: state.clone(),
            headers,
            input,
        })
    }
}

impl SolveRequest {
    /// Validates the input as a job of `kind`, solves it and answers it. An input seen
    /// before (the same JSON up to key order and spacing) whose answer is cached is answered
    /// at once: validation and the cache key cost more than the lookup.
    pub async fn solve(self, kind: JobKind) -> Result<Response, ApiError> {
        let engine = self.state.engine();
        let text = format!("{}\n{}", kind.as_str(), self.input);
        if let Some(solved) = engine.cached_input(&text).await? {
            return Ok(respond(&solved, CacheStatus::Hit, &self.headers));
        }
        let job = Job::from_input(kind, self.input, &self.state.config().limits)?;
        let meta = job.meta();
        engine.remember_input(text, meta.input_hash.clone()).await;
        solve_and_answer(&self.state, job, meta, &self.headers).await
    }
}

/// Solves a validated job and answers it, in JSON or (if asked and offered) CSV.
pub async fn answer(state: &AppState, job: Job, headers: &HeaderMap) -> Result<Response, ApiError> {
    let meta = job.meta();
    solve_and_answer(state, job, meta, headers).await
}

/// [`answer`] for a job whose [`Meta`] (and so cache key) the caller already computed.
async fn solve_and_answer(
    state: &AppState,
    job: Job,
    meta: Meta,
    headers: &HeaderMap,
) -> Result<Response, ApiError> {
    let (solved, cache) = state.engine().solve(job, meta).await?;
    Ok(respond(&solved, cache, headers))
}

/// The answer with its validators: the `ETag` is the cache key (per representation), so an
/// `If-None-Match` that names it gets `304` and no body.
fn respond(solved: &Solved, cache: CacheStatus, headers: &HeaderMap) -> Response {
    let csv = if wants_csv(headers) {
        solved.csv()
    } else {
        None
    };
    let etag = match csv {
        Some(_) => format!("\"{}.csv\"", solved.key),
        None => format!("\"{}\"", solved.key),
    };
    let mut response = if if_none_match(headers, &etag) {
        StatusCode::NOT_MODIFIED.into_response()
    } else if let Some(csv) = csv {
        (
            [(
                header::CONTENT_TYPE,
                "text/csv; charset=utf-8; header=present",
            )],
            csv,
        )
            .into_response()
    } else {
        (
            [(header::CONTENT_TYPE, "application/json")],
            solved.json.clone(),
        )
            .into_response()
    };
    let h = response.headers_mut();
    if let Ok(etag) = HeaderValue::from_str(&etag) {
        h.insert(header::ETAG, etag);
    }
    h.insert(X_CACHE, HeaderValue::from_static(cache.as_str()));
    h.insert(header::VARY, HeaderValue::from_static("accept"));
    response
}

/// Whether the client prefers CSV: `text/csv` is acceptable and `application/json` is not
/// preferred to it (a wildcard does not count against CSV).
fn wants_csv(headers: &HeaderMap) -> bool {
    let (mut csv, mut json) = (0.0_f32, 0.0_f32);
    let ranges = headers
        .get_all(header::ACCEPT)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','));
    for range in ranges {
        let mut params = range.split(';').map(str::trim);
        let media = params.next().unwrap_or("").to_ascii_lowercase();
        let q = params
            .find_map(|p| p.strip_prefix("q="))
            .and_then(|q| q.parse().ok())
            .unwrap_or(1.0);
        match media.as_str() {
            "text/csv" => csv = csv.max(q),
            "application/json" => json = json.max(q),
            _ => {}
        }
    }
    csv > 0.0 && csv >= json
}

/// Whether `If-None-Match` names `etag` (weak comparison, as for GET) or is `*`.
fn if_none_match(headers: &HeaderMap, etag: &str) -> bool {
    headers
        .get_all(header::IF_NONE_MATCH)
        .iter()
        .filter_map(|v| v.to_str().ok())
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
            assert_eq!(wants_csv(&headers(header::ACCEPT, accept)), csv, "{accept}");
        }
        assert!(!wants_csv(&HeaderMap::new()));
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
            let h = headers(header::IF_NONE_MATCH, value);
            assert_eq!(if_none_match(&h, etag), matches, "{value}");
        }
    }
}
