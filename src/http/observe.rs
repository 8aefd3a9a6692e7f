//! What operators see of each request: a tracing span with its request id, and Prometheus
//! counts and latencies by route.

use std::future::Future;
use std::pin::Pin;
use std::sync::{Arc, RwLock};
use std::task::{Context, Poll};
use std::time::Instant;

use axum::extract::{MatchedPath, Request};
use axum::http::{header, Method};
use axum::response::{IntoResponse, Response};
use metrics::{Counter, Histogram};
use tower::Service;
use tracing::Span;

use super::error::{too_large, ApiError};
use super::request_id::X_REQUEST_ID;
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
        .get(X_REQUEST_ID)
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
/// than by raw path. A route's own layer (`route_layer`): a method the route does not take
/// (405) is counted as `unmatched`, as before.
///
/// A tower layer rather than an `axum::middleware::from_fn`, which clones the route below
/// it and boxes two things on every request.
#[derive(Clone, Debug)]
pub struct TagRoute<S> {
    pub inner: S,
}

impl<S> Service<Request> for TagRoute<S>
where
    S: Service<Request, Response = Response>,
    S::Future: Unpin,
{
    type Response = Response;
    type Error = S::Error;
    type Future = Tagged<S::Future>;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), Self::Error>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, request: Request) -> Self::Future {
        let route = request.extensions().get::<MatchedPath>().cloned();
        Tagged {
            inner: self.inner.call(request),
            route,
        }
    }
}

/// A route's answer, to be tagged with the route.
pub struct Tagged<F> {
    inner: F,
    route: Option<MatchedPath>,
}

impl<F, E> Future for Tagged<F>
where
    F: Future<Output = Result<Response, E>> + Unpin,
{
    type Output = Result<Response, E>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let this = self.get_mut();
        let mut response = std::task::ready!(Pin::new(&mut this.inner).poll(cx))?;
        if let Some(route) = this.route.take() {
            response.extensions_mut().insert(route);
        }
        Poll::Ready(Ok(response))
    }
}

/// The request series ([`HTTP_REQUESTS`], [`HTTP_DURATION`]) of each method, route and
/// status, looked up on the recorder once: a look-up builds the key, copying its labels
/// (the status formatted), and hashes it, on every request otherwise. A few dozen routes,
/// methods and statuses: a list.
#[derive(Default)]
pub struct RequestSeries {
    seen: RwLock<Vec<Series>>,
}

struct Series {
    method: &'static str,
    route: Arc<str>,
    status: u16,
    requests: Counter,
    duration: Histogram,
}

impl RequestSeries {
    /// Counts a request answered with `status` and records its time to the answer.
    fn record(
        &self,
        metrics: &Metrics,
        method: &'static str,
        route: &str,
        status: u16,
        elapsed: std::time::Duration,
    ) {
        let matches = |s: &&Series| s.status == status && s.method == method && &*s.route == route;
        {
            let seen = self.seen.read().unwrap_or_else(|e| e.into_inner());
            if let Some(series) = seen.iter().find(matches) {
                series.requests.increment(1);
                series.duration.record(elapsed);
                return;
            }
        }
        let mut seen = self.seen.write().unwrap_or_else(|e| e.into_inner());
        if !seen.iter().any(|s| matches(&s)) {
            let code = status.to_string();
            seen.push(Series {
                method,
                route: route.into(),
                status,
                requests: metrics.counter(
                    HTTP_REQUESTS,
                    &[("method", method), ("route", route), ("status", &code)],
                ),
                duration: metrics.histogram(HTTP_DURATION, &[("method", method), ("route", route)]),
            });
        }
        let series = seen.iter().find(matches).expect("just added");
        series.requests.increment(1);
        series.duration.record(elapsed);
    }
}

/// A request being counted and timed: started as it comes in, recorded with its response.
pub struct Timing {
    start: Instant,
    method: &'static str,
}

impl Timing {
    pub fn start(request: &Request) -> Timing {
        Timing {
            start: Instant::now(),
            method: method_label(request.method()),
        }
    }

    /// Counts and times the request answered by `response`.
    pub fn record<B>(self, state: &AppState, response: &Response<B>) {
        let route = response
            .extensions()
            .get::<MatchedPath>()
            .map_or("unmatched", |r| r.as_str());
        state.request_series().record(
            state.engine().metrics(),
            self.method,
            route,
            response.status().as_u16(),
            self.start.elapsed(),
        );
    }
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

/// The refusal (413) of a body whose declared length is over the limit, at once rather
/// than after reading it up to the limit.
pub fn declared_overflow(state: &AppState, request: &Request) -> Option<Response> {
    let limit = state.config().body_limit;
    let declared = request
        .headers()
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<u64>().ok());
    match declared {
        Some(length) if length > limit as u64 => {
            Some(ApiError::payload_too_large(too_large(Some(length), limit)).into_response())
        }
        _ => None,
    }
}
