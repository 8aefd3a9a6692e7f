//! What operators see of each request: a tracing span with its request id, and Prometheus
//! counts and latencies by route.

use std::time::Instant;

use axum::extract::{MatchedPath, Request, State};
use axum::http::{header, HeaderValue, Method};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use tracing::Span;

use super::error::{too_large, ApiError};
use super::AppState;

/// The request id header, set by the client or by the service.
const REQUEST_ID: &str = "x-request-id";
use crate::engine::metrics::Metrics;

/// Requests answered, by method, route and status.
pub const HTTP_REQUESTS: &str = "http_requests_total";
/// Time to the response head, by method and route.
pub const HTTP_DURATION: &str = "http_request_duration_seconds";

/// Histogram buckets (s): from a cached answer (~10 µs) to a long sweep.
pub const BUCKETS: [f64; 14] = [
    1e-5, 2.5e-5, 5e-5, 1e-4, 2.5e-4, 5e-4, 1e-3, 5e-3, 0.01, 0.05, 0.1, 0.5, 1.0, 10.0,
];

/// Gives the request metrics their help texts.
pub fn describe(metrics: &Metrics) {
    metrics.describe_counter(
        HTTP_REQUESTS,
        "Requests answered, by method, route and status",
    );
    metrics.describe_seconds(
        HTTP_DURATION,
        "Time to the response head, by method and route",
    );
}

/// The span of a request, named by the request id that `SetRequestId` put (or the client
/// sent), so that every log line of the request carries it.
pub fn request_span(request: &Request) -> Span {
    let id = request
        .headers()
        .get(REQUEST_ID)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("");
    tracing::info_span!(
        "request",
        method = %request.method(),
        uri = %request.uri(),
        request_id = %id,
    )
}

/// Passes the route a request matched out with its response (routing happens inside the
/// router, after the layers that measure), so that metrics are by route template rather
/// than by raw path.
pub async fn tag_route(request: Request, next: Next) -> Response {
    let route = request.extensions().get::<MatchedPath>().cloned();
    let mut response = next.run(request).await;
    if let Some(route) = route {
        response.extensions_mut().insert(route);
    }
    response
}

/// Counts and times every request.
pub async fn record_request(
    State(state): State<AppState>,
    request: Request,
    next: Next,
) -> Response {
    let start = Instant::now();
    let method = method_label(request.method());
    let response = next.run(request).await;
    let route = response
        .extensions()
        .get::<MatchedPath>()
        .map_or("unmatched", |r| r.as_str());
    let status = response.status().as_u16().to_string();
    let metrics = state.engine().metrics();
    metrics
        .counter(
            HTTP_REQUESTS,
            &[("method", method), ("route", route), ("status", &status)],
        )
        .increment(1);
    metrics
        .histogram(HTTP_DURATION, &[("method", method), ("route", route)])
        .record(start.elapsed());
    response
}

/// The method as a metric label: one of the standard methods, or `other`, so that a client
/// cannot make up series.
fn method_label(method: &Method) -> &'static str {
    const STANDARD: [Method; 9] = [
        Method::GET,
        Method::POST,
        Method::PUT,
        Method::DELETE,
        Method::HEAD,
        Method::OPTIONS,
        Method::PATCH,
        Method::TRACE,
        Method::CONNECT,
    ];
    STANDARD
        .iter()
        .find(|m| *m == method)
        .map_or("other", Method::as_str)
}

/// A request id a client may choose: up to 128 letters, digits and `-_.:`; anything else
/// (which could forge fields in a text log line) is replaced by one of ours.
pub async fn sanitize_request_id(mut request: Request, next: Next) -> Response {
    let valid = |v: &HeaderValue| {
        let bytes = v.as_bytes();
        !bytes.is_empty()
            && bytes.len() <= 128
            && bytes
                .iter()
                .all(|b| b.is_ascii_alphanumeric() || b"-_.:".contains(b))
    };
    let headers = request.headers_mut();
    if headers.get(REQUEST_ID).is_some_and(|v| !valid(v)) {
        headers.remove(REQUEST_ID);
    }
    next.run(request).await
}

/// Refuses at once (413) a body whose declared length is over the limit, rather than
/// reading it up to the limit first.
pub async fn refuse_declared_overflow(
    State(state): State<AppState>,
    request: Request,
    next: Next,
) -> Response {
    let limit = state.config().body_limit;
    let declared = request
        .headers()
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<u64>().ok());
    match declared {
        Some(length) if length > limit as u64 => {
            ApiError::payload_too_large(too_large(Some(length), limit)).into_response()
        }
        _ => next.run(request).await,
    }
}
