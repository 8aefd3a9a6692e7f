//! The HTTP floor under thirdbody (issue 46): axum on a multi-threaded tokio runtime and
//! mimalloc, as thirdbody runs, with no middleware. `POST /v1/rolling` answers the bytes and
//! headers of thirdbody's cached answer to `{}` (captured in `rolling.json` and
//! `rolling.headers`, a fixed `x-request-id` among them), after reading the request's body;
//! `GET /healthz` answers `{"status":"ok"}` with the same headers as thirdbody's. The wire
//! bytes are thirdbody's but for the request id's value and the date. Everything thirdbody adds per request (its layers, its connection
//! guards, the job's validation and the cache look-up) is what this does not do.
//!
//!   thirdbody-bare serve --bind 127.0.0.1:PORT [ignored thirdbody flags...]
//!
//! so that `loadtest/instructions.sh` and `loadtest/ratio.sh` run it as they run thirdbody.

use axum::body::Bytes;
use axum::http::{HeaderMap, HeaderName, HeaderValue};
use axum::routing::{get, post};
use axum::serve::ListenerExt;
use axum::Router;

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

const ROLLING: &[u8] = include_bytes!("rolling.json");
const HEADERS: &str = include_str!("rolling.headers");
const HEALTH: &[u8] = br#"{"status":"ok"}"#;

/// The captured answer's headers (`name: value` lines), parsed once.
fn rolling_headers() -> HeaderMap {
    HEADERS
        .lines()
        .filter_map(|line| line.split_once(": "))
        .map(|(name, value)| {
            (
                HeaderName::from_bytes(name.as_bytes()).expect("a header name"),
                HeaderValue::from_str(value.trim_end()).expect("a header value"),
            )
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bind = args
        .iter()
        .position(|a| a == "--bind")
        .and_then(|i| args.get(i + 1))
        .cloned()
        .unwrap_or_else(|| "127.0.0.1:8080".to_string());
    let runtime = tokio::runtime::Runtime::new().expect("a runtime");
    runtime.block_on(async move {
        let headers = rolling_headers();
        let app = Router::new()
            .route(
                "/v1/rolling",
                post(move |_body: Bytes| {
                    let headers = headers.clone();
                    async move { (headers, Bytes::from_static(ROLLING)) }
                }),
            )
            .route(
                "/healthz",
                get(|| async {
                    (
                        [
                            (
                                axum::http::header::CONTENT_TYPE,
                                HeaderValue::from_static("application/json"),
                            ),
                            (
                                HeaderName::from_static("x-request-id"),
                                HeaderValue::from_static("82cc5402-2738-45cc-bed6-f8f97805f2eb"),
                            ),
                        ],
                        Bytes::from_static(HEALTH),
                    )
                }),
            );
        // TCP_NODELAY, as thirdbody sets it.
        let listener = tokio::net::TcpListener::bind(&bind)
            .await
            .expect("bind")
            .tap_io(|tcp| {
                let _ = tcp.set_nodelay(true);
            });
        tokio::spawn(async {
            let mut term =
                tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
                    .expect("a signal handler");
            term.recv().await;
            std::process::exit(0);
        });
        axum::serve(listener, app).await.expect("serve");
    });
}
