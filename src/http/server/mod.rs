//! The accept loop: HTTP/1.1 connections with the limits a public service needs, which
//! `axum::serve` does not set, as nginx and hyper users set them:
//! - a cap on open connections; at the cap the most dispensable connection is closed to
//!   make room ([`activity`]): an idle keep-alive connection first, then an unfinished
//!   request head, then a client that stopped reading, then a crawling body;
//! - a timeout on reading a request's headers, and a shorter one on idle keep-alive
//!   connections;
//! - a send timeout between successive writes ([`io`]), and a pace a request body must
//!   keep ([`bodies`]);
//! - a bounded graceful close.

mod activity;
mod bodies;
mod io;

use std::sync::Arc;
use std::time::Duration;

use axum::body::Body;
use axum::extract::Request;
use axum::Router;
use hyper::body::Incoming;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::server::graceful::GracefulShutdown;
use tokio::net::TcpListener;
use tokio::sync::{OwnedSemaphorePermit, Semaphore};
use tokio_util::sync::CancellationToken;
use tower::ServiceExt;

use activity::{Activity, Clock, Connections};
pub use bodies::{slow_body_in, BodyPace};

/// How long to wait before accepting again after the listener failed (out of file
/// descriptors, say): the connections in flight close meanwhile.
const ACCEPT_BACKOFF: Duration = Duration::from_millis(50);
/// How often a newcomer waiting at the cap looks again for a connection to close.
const EVICT_RETRY: Duration = Duration::from_millis(20);

/// The limits on connections.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConnectionLimits {
    /// Connections open at once; more wait in the kernel's backlog.
    pub max_connections: usize,
    /// Longest a client may take to send a request's headers.
    pub header_timeout: Duration,
    /// Longest a keep-alive connection may stay idle between requests.
    pub keep_alive_timeout: Duration,
    /// Longest a write may wait for the client to read.
    pub send_timeout: Duration,
    /// How a request body must arrive.
    pub body: BodyPace,
}

/// A slot for a newcomer. At the cap, it takes the slot of the most dispensable connection,
/// closed for it, or (when every connection is serving a request) waits for the first to
/// end; `None` once `stop` is cancelled.
async fn take_slot(
    slots: &Arc<Semaphore>,
    connections: &Connections,
    stop: &CancellationToken,
) -> Option<OwnedSemaphorePermit> {
    loop {
        if let Ok(slot) = slots.clone().try_acquire_owned() {
            return Some(slot);
        }
        if let Some(slot) = connections.evict() {
            return Some(slot);
        }
        tokio::select! {
            () = stop.cancelled() => return None,
            slot = slots.clone().acquire_owned() => return slot.ok(),
            () = tokio::time::sleep(EVICT_RETRY) => {}
        }
    }
}

/// Serves `app` on `listener` until `stop` is cancelled, then lets the open connections
/// finish their requests for at most `close_within`.
pub async fn serve(
    listener: TcpListener,
    app: Router,
    limits: ConnectionLimits,
    stop: CancellationToken,
    close_within: impl Fn() -> Duration,
) -> std::io::Result<()> {
    let slots = Arc::new(Semaphore::new(limits.max_connections));
    let clock = Clock::new();
    let connections = Connections::new(clock);
    let graceful = GracefulShutdown::new();
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new())
        .header_read_timeout(limits.header_timeout)
        .keep_alive(true);
    let keep_alive_ms = u64::try_from(limits.keep_alive_timeout.as_millis()).unwrap_or(u64::MAX);
    let mut reap =
        tokio::time::interval((limits.keep_alive_timeout / 4).max(Duration::from_millis(50)));
    reap.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    loop {
        let stream = tokio::select! {
            () = stop.cancelled() => break,
            _ = reap.tick() => {
                connections.close_idle(keep_alive_ms);
                continue;
            }
            accepted = listener.accept() => match accepted {
                Ok((stream, _)) => stream,
                Err(e) => {
                    tracing::warn!(error = %e, "accept failed");
                    tokio::time::sleep(ACCEPT_BACKOFF).await;
                    continue;
                }
            },
        };
        let Some(slot) = take_slot(&slots, &connections, &stop).await else {
            break;
        };
        let _ = stream.set_nodelay(true);
        let activity = Arc::new(Activity::new(clock));
        let service = hyper::service::service_fn({
            let (app, activity) = (app.clone(), activity.clone());
            move |request: Request<Incoming>| {
                let guard = activity.request();
                let request = request
                    .map(|body| Body::new(bodies::Paced::new(body, activity.clone(), limits.body)));
                let answer = app.clone().oneshot(request);
                async move {
                    let response = answer.await?;
                    Ok::<_, std::convert::Infallible>(
                        response.map(|body| Body::new(bodies::Answer::new(body, guard))),
                    )
                }
            }
        });
        let transport = io::Watched::new(stream, activity.clone(), limits.send_timeout);
        let connection = http.serve_connection(TokioIo::new(transport), service);
        let connection = graceful.watch(connection);
        let registry = connections.clone();
        connections.add(activity, slot, move |id| {
            tokio::spawn(async move {
                // Leaves the registry (giving its slot back) however the task ends, a
                // panic included.
                let _leave = registry.on_drop_close(id);
                // A closed or timed-out connection is the client's business, not an error.
                let _ = connection.await;
            })
            .abort_handle()
        });
    }
    drop(listener);
    if tokio::time::timeout(close_within(), graceful.shutdown())
        .await
        .is_err()
    {
        tracing::warn!("connections still open at the end of the drain: closing them");
    }
    Ok(())
}
