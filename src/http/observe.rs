//! What operators see of each request: a tracing span with its request id, and Prometheus
//! counts and latencies by route.

use std::time::Instant;

use axum::extract::{MatchedPath, Request, State};
use axum::middleware::Next;
use axum::response::Response;
use tracing::Span;

use super::AppState;
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
        .get("x-request-id")
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
    let method = request.method().clone();
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
            &[
                ("method", method.as_str()),
                ("route", route),
                ("status", &status),
            ],
        )
        .increment(1);
    metrics
        .histogram(
            HTTP_DURATION,
            &[("method", method.as_str()), ("route", route)],
        )
        .record(start.elapsed());
    response
}
