//! The HTTP service: `thirdbody serve`. JSON in and out through the job layer, compute
//! through the [`Engine`], one error contract ([`error`]), the spec generated from the
//! routes ([`openapi`]).
//!
//! [`app`] builds the router for a state; [`run`] serves it on a listener until a shutdown
//! signal, then drains. Tests and the binary start the service the same way.

mod accept;
pub mod access;
mod body;
pub mod config;
mod dashboard;
pub mod error;
mod observe;
pub mod openapi;
mod request_id;
mod responses;
pub mod routes;
mod server;
mod stack;

use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use axum::extract::DefaultBodyLimit;
use axum::http::{header, HeaderName, HeaderValue, Method, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::{middleware, Router};
use metrics_exporter_prometheus::{PrometheusBuilder, PrometheusHandle};
use tokio::net::TcpListener;
use tokio_util::sync::CancellationToken;
use tower::layer::layer_fn;
use tower::ServiceBuilder;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::compression::{CompressionLayer, CompressionLevel};
use tower_http::cors::{AllowOrigin, CorsLayer};
use tower_http::timeout::TimeoutLayer;
use tower_http::trace::{DefaultOnResponse, TraceLayer};
use tower_http::LatencyUnit;
use utoipa_swagger_ui::SwaggerUi;

pub use config::{Config, ConfigError, CorsOrigins, LogFormat, ServeArgs};
pub use error::ApiError;
pub use server::ConnectionLimits;

use crate::engine::metrics::Metrics;
use crate::engine::{Engine, Storage};

use request_id::{RequestId, X_REQUEST_ID};
/// How often metrics histograms are drained and expired jobs forgotten.
const HOUSEKEEPING_INTERVAL: Duration = Duration::from_secs(5);
/// How often the API keys' file is read again (a revoked key stops working within this).
const KEYS_INTERVAL: Duration = Duration::from_secs(1);

/// What every handler shares: the settings, the engine and the metrics.
#[derive(Clone)]
pub struct AppState {
    inner: Arc<Inner>,
}

struct Inner {
    config: Config,
    engine: Arc<Engine>,
    prometheus: PrometheusHandle,
    /// Large request bodies read at once (see `body::offload`).
    readers: Arc<tokio::sync::Semaphore>,
    /// Event streams open at once (an eighth of `--max-connections`).
    streams: Arc<tokio::sync::Semaphore>,
    /// The request metrics' series, each looked up once.
    series: observe::RequestSeries,
}

/// Why the service cannot start: its storage cannot be opened (the database, or the fleet's
/// Redis), in words for the operator.
#[derive(Debug, thiserror::Error)]
pub enum CannotStart {
    #[error(transparent)]
    Database(#[from] crate::engine::archive::ArchiveError),
    #[error(transparent)]
    Fleet(#[from] crate::engine::fleet::link::LinkError),
}

impl AppState {
    /// A service with its own engine, its answers and jobs in its own memory (and its
    /// database) or its fleet's Redis, and its own metrics registry; or why it
    /// cannot start.
    pub fn new(config: Config) -> Result<Self, CannotStart> {
        let storage = match &config.fleet {
            Some(fleet) => Storage::in_fleet(&config.engine, fleet.clone())?,
            None => Storage::in_process(&config.engine)?,
        };
        Ok(AppState::with_storage(config, storage))
    }

    /// A service whose engine keeps answers and jobs in `storage`.
    pub fn with_storage(config: Config, storage: Storage) -> Self {
        let recorder = PrometheusBuilder::new()
            .set_buckets(&observe::BUCKETS)
            .expect("the buckets are not empty")
            .build_recorder();
        let prometheus = recorder.handle();
        let metrics = Metrics::new(Arc::new(recorder));
        observe::describe(&metrics);
        let engine = Engine::with_storage(config.engine.clone(), metrics, storage);
        let readers = Arc::new(tokio::sync::Semaphore::new(config.engine.pool_size));
        let streams = Arc::new(tokio::sync::Semaphore::new(config.max_event_streams));
        AppState {
            inner: Arc::new(Inner {
                config,
                engine,
                prometheus,
                readers,
                streams,
                series: observe::RequestSeries::default(),
            }),
        }
    }

    pub fn config(&self) -> &Config {
        &self.inner.config
    }

    pub fn engine(&self) -> &Arc<Engine> {
        &self.inner.engine
    }

    /// A place to read a large request body, if one is free.
    fn reader_permit(&self) -> Option<tokio::sync::OwnedSemaphorePermit> {
        self.inner.readers.clone().try_acquire_owned().ok()
    }

    /// A place for an event stream, if one is free; held as long as the stream.
    fn stream_permit(&self) -> Result<tokio::sync::OwnedSemaphorePermit, ApiError> {
        let streams = self.inner.streams.clone();
        streams
            .try_acquire_owned()
            .map_err(|_| ApiError::too_many_streams(self.inner.config.max_event_streams))
    }

    fn request_series(&self) -> &observe::RequestSeries {
        &self.inner.series
    }

    /// The metrics in the Prometheus text format.
    pub fn render_metrics(&self) -> String {
        self.inner.prometheus.render()
    }
}

/// The service's router, with every layer: request id, tracing, metrics, CORS, problem
/// responses for every error, panic guard, request timeout and body limit.
///
/// The layers are one stack, given to `Router::layer` once. `Router::layer` wraps each
/// route's handler in the layer and boxes the result; called once a layer, it nested 16
/// boxes, and every `from_fn` among them cloned (allocating anew) all the boxes below it on
/// every request: 60,000 of the 78,000 instructions a `/healthz` took (issue 46).
pub fn app(state: AppState) -> Router {
    let (api, spec) = openapi::router_and_spec();
    let config = state.config();
    // Outermost first: each request passes the request id, tracing and metrics first, and
    // each response leaves through the problem mapping (inside CORS, so that errors carry
    // CORS headers too).
    let layers = ServiceBuilder::new()
        .layer(layer_fn(|inner| RequestId { inner }))
        .layer(
            TraceLayer::new_for_http()
                .make_span_with(observe::request_span)
                .on_response(
                    DefaultOnResponse::new()
                        .level(tracing::Level::INFO)
                        .latency_unit(LatencyUnit::Micros),
                ),
        )
        .layer(layer_fn({
            let state = state.clone();
            move |inner| stack::Observed {
                state: state.clone(),
                inner,
            }
        }))
        .option_layer(cors(&config.cors_origins))
        .map_response(weaken_compressed_etag)
        // gzip for a client that accepts it (the default predicate leaves out small bodies,
        // images other than SVG, and event streams); the fastest level: a sweep's numbers
        // shrink about fivefold at a fraction of the CPU of the default level.
        .layer(CompressionLayer::new().quality(CompressionLevel::Fastest))
        .and_then(stack::problems)
        .map_response(IntoResponse::into_response)
        .layer(CatchPanicLayer::custom(error::panic_response))
        .layer(TimeoutLayer::with_status_code(
            StatusCode::REQUEST_TIMEOUT,
            config.request_timeout,
        ))
        .layer(DefaultBodyLimit::max(config.body_limit))
        .layer(layer_fn({
            let state = state.clone();
            move |inner| stack::Admitted {
                state: state.clone(),
                inner,
            }
        }));
    api.merge(SwaggerUi::new("/docs").url("/openapi.json", spec))
        .merge(dashboard::router())
        .route_layer(layer_fn(|inner| observe::TagRoute { inner }))
        .fallback(not_found)
        .layer(layers)
        .with_state(state)
}

/// A compressed body is another representation of the answer: its `ETag` becomes weak
/// (RFC 9110 §8.8.1), as nginx does, so that it is never taken for the uncompressed bytes;
/// `If-None-Match` compares weakly, so a client's validator still matches.
fn weaken_compressed_etag<B>(mut response: Response<B>) -> Response<B> {
    let headers = response.headers_mut();
    if headers.contains_key(header::CONTENT_ENCODING) {
        if let Some(etag) = headers.get(header::ETAG) {
            if !etag.as_bytes().starts_with(b"W/") {
                let mut weak = b"W/".to_vec();
                weak.extend_from_slice(etag.as_bytes());
                if let Ok(weak) = HeaderValue::from_bytes(&weak) {
                    headers.insert(header::ETAG, weak);
                }
            }
        }
    }
    response
}

async fn not_found() -> ApiError {
    ApiError::not_found("no such route: see /docs or /openapi.json")
}

/// CORS for a dashboard on another origin: it may POST JSON and read the headers that
/// carry meaning (the job's `Location`, `ETag`, `X-Cache`, `Retry-After`, the request id).
fn cors(origins: &CorsOrigins) -> Option<CorsLayer> {
    let allow = match origins {
        CorsOrigins::None => return None,
        CorsOrigins::Any => AllowOrigin::any(),
        CorsOrigins::List(list) => AllowOrigin::list(list.iter().cloned()),
    };
    Some(
        CorsLayer::new()
            .allow_origin(allow)
            .allow_methods([Method::GET, Method::POST, Method::DELETE])
            .allow_headers([
                header::CONTENT_TYPE,
                header::ACCEPT,
                header::IF_NONE_MATCH,
                header::AUTHORIZATION,
                HeaderName::from_static(access::API_KEY_HEADER),
                HeaderName::from_static(routes::shared::OWNER_HEADER),
                X_REQUEST_ID,
            ])
            .expose_headers(
                [
                    header::LOCATION,
                    header::ETAG,
                    header::RETRY_AFTER,
                    header::WWW_AUTHENTICATE,
                    routes::X_CACHE,
                    X_REQUEST_ID,
                ]
                .into_iter()
                .chain(routes::PROVENANCE)
                .collect::<Vec<_>>(),
            )
            .max_age(Duration::from_secs(3600)),
    )
}

/// The end of a drain kept for the clients of the jobs it interrupts to poll their fate:
/// time for a big job to stop and keep what it finished (0.5 s for 300,000 points), then
/// several polls at the pace a job's `Retry-After` asks (1 s). Without it, 4 of 5 pollers
/// of an interrupted job found the port closed.
const FATE_NOTICE: Duration = Duration::from_secs(5);

/// Serves `state` on `listener` until `shutdown` resolves, then drains: new work is refused
/// (503, `/readyz` fails) while the jobs already accepted, queued or running, go on and their
/// clients can still poll and follow them. After the drain delay, once those jobs are done
/// and their clients have read them, the listener closes; a job not finished
/// [`FATE_NOTICE`] before the shutdown timeout (half the timeout, if shorter) ends
/// `interrupted` and the listener closes at the timeout, so that its clients read that. The
/// requests in flight finish within what remains of the timeout.
pub async fn run(
    listener: TcpListener,
    state: AppState,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let config = state.config().clone();
    // In a fleet, this process also works the fleet's stream, leaving a solver thread to
    // synchronous requests.
    let workers = config.engine.pool_size.saturating_sub(1).max(1);
    state.engine().jobs.start_workers(workers, true);
    let stop_accepting = CancellationToken::new();
    let _chores = chores(&state);
    let deadline = Arc::new(std::sync::Mutex::new(None::<tokio::time::Instant>));
    let remaining = {
        let deadline = deadline.clone();
        move || {
            let at = *deadline.lock().unwrap_or_else(|p| p.into_inner());
            at.map_or(config.shutdown_timeout, |at| {
                at.saturating_duration_since(tokio::time::Instant::now())
            })
        }
    };
    let mut server = tokio::spawn(server::serve(
        listener,
        app(state.clone()),
        config.connections,
        stop_accepting.clone(),
        remaining,
    ));
    tokio::select! {
        result = &mut server => return result?,
        () = shutdown => {}
    }
    let engine = state.engine();
    let end = tokio::time::Instant::now() + config.shutdown_timeout;
    *deadline.lock().unwrap_or_else(|p| p.into_inner()) = Some(end);
    // The caller says what the drain waits for, in its own words (`thirdbody serve`).
    tracing::debug!("shutting down: draining");
    engine.jobs.begin_drain();
    tokio::time::sleep(config.drain_delay).await;
    // Jobs still running when the notice begins are interrupted, and the port stays open to
    // its end: every client polling such a job (there may be several: a script and a
    // dashboard) learns its fate from this process, not from a refused connection.
    let notice = FATE_NOTICE.min(config.shutdown_timeout / 2);
    if engine.jobs.finish_jobs(end - notice).await {
        // Their clients read them (within what is left of the timeout) before the port closes.
        if tokio::time::timeout_at(end, engine.jobs.jobs_collected())
            .await
            .is_err()
        {
            tracing::warn!("some finished jobs were not collected before the shutdown timeout");
        }
    } else {
        tracing::warn!("the drain ran out of time: the jobs left were interrupted");
        tokio::time::sleep_until(end).await;
    }
    stop_accepting.cancel();
    server.await?
}

/// Tasks of a process that stop when this is dropped.
pub struct Tasks(Vec<tokio::task::JoinHandle<()>>);

impl Drop for Tasks {
    fn drop(&mut self) {
        for task in &self.0 {
            task.abort();
        }
    }
}

/// The chores of every process, `serve` or `worker`: [`housekeeping`] and [`reread_keys`].
pub fn chores(state: &AppState) -> Tasks {
    Tasks(vec![
        tokio::spawn(housekeeping(state.clone())),
        tokio::spawn(reread_keys(state.clone())),
    ])
}

/// The routes for operators of a process without the API (`thirdbody worker
/// --metrics-bind`): `/metrics`, `/healthz` and `/readyz`, under the same access rules and
/// with the same problems as the service's.
pub fn operations_app(state: AppState) -> Router {
    use axum::routing::get;
    Router::new()
        .route("/metrics", get(routes::ops::metrics))
        .route("/healthz", get(routes::ops::healthz))
        .route("/readyz", get(routes::ops::readyz))
        .fallback(not_found)
        .layer(middleware::from_fn_with_state(state.clone(), access::admit))
        .layer(middleware::map_response(error::problem_for_errors))
        .with_state(state)
}

/// Serves [`operations_app`] on `listener`, with the service's limits on connections,
/// until the returned task is dropped.
pub fn serve_operations(listener: TcpListener, state: AppState) -> Tasks {
    if let Ok(address) = listener.local_addr() {
        tracing::info!(%address, "serving /metrics, /healthz and /readyz");
    }
    let limits = state.config().connections;
    let app = operations_app(state);
    Tasks(vec![tokio::spawn(async move {
        let served = server::serve(listener, app, limits, CancellationToken::new(), || {
            Duration::ZERO
        });
        if let Err(e) = served.await {
            tracing::error!(error = %e, "the operations' routes stopped");
        }
    })])
}

/// Periodic chores: drain the metrics histograms (they buffer samples until rendered) and
/// forget expired jobs.
async fn housekeeping(state: AppState) {
    let mut tick = tokio::time::interval(HOUSEKEEPING_INTERVAL);
    loop {
        tick.tick().await;
        state.inner.prometheus.run_upkeep();
        state.engine().jobs.purge_expired_jobs().await;
    }
}

/// Reads the API keys' file again every [`KEYS_INTERVAL`]: keys are added, rotated and
/// revoked without a restart. (A blocking read of a small file, off the async threads.)
async fn reread_keys(state: AppState) {
    if !state.config().access.keys.configured() {
        return;
    }
    let mut tick = tokio::time::interval(KEYS_INTERVAL);
    loop {
        tick.tick().await;
        let access = state.config().access.clone();
        let _ = tokio::task::spawn_blocking(move || access.keys.reload()).await;
    }
}
