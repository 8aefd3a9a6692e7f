//! The accept loop: HTTP/1.1 connections with the limits a public service needs, which
//! `axum::serve` does not set: a cap on open connections, a timeout on reading a request's
//! headers (which also closes idle keep-alive connections), and a bounded graceful close.
//! At the cap, the oldest connection that has not yet sent a whole request head is closed to
//! make room: slow senders (slowloris) cannot keep new clients waiting in the backlog.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use axum::body::Body;
use axum::extract::Request;
use axum::Router;
use hyper::body::Incoming;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::server::graceful::GracefulShutdown;
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;
use tokio::sync::Semaphore;
use tokio::task::AbortHandle;
use tokio_util::sync::CancellationToken;
use tower::ServiceExt;

/// How long to wait before accepting again after the listener failed (out of file
/// descriptors, say): the connections in flight close meanwhile.
const ACCEPT_BACKOFF: Duration = Duration::from_millis(50);

/// The limits on connections.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConnectionLimits {
    /// Connections open at once; more wait in the kernel's backlog.
    pub max_connections: usize,
    /// Longest a client may take to send a request's headers, and longest a keep-alive
    /// connection may stay idle.
    pub header_timeout: Duration,
}

/// An open connection, as the accept loop sees it.
struct Open {
    id: u64,
    /// Whether a whole request head has arrived on it.
    served: Arc<AtomicBool>,
    task: AbortHandle,
}

/// The open connections, oldest first.
#[derive(Clone, Default)]
struct Connections {
    open: Arc<Mutex<VecDeque<Open>>>,
    next: Arc<AtomicU64>,
}

impl Connections {
    fn open(&self) -> MutexGuard<'_, VecDeque<Open>> {
        self.open.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn closed(&self, id: u64) {
        self.open().retain(|c| c.id != id);
    }

    /// Closes the oldest connection that has not sent a whole request head; false if every
    /// open connection has.
    fn evict_slowest(&self) -> bool {
        let mut open = self.open();
        let Some(index) = open.iter().position(|c| !c.served.load(Ordering::Relaxed)) else {
            return false;
        };
        if let Some(connection) = open.remove(index) {
            connection.task.abort();
        }
        true
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
    let slots = Arc::new(Semaphore::new(limits.max_connections.max(1)));
    let connections = Connections::default();
    let graceful = GracefulShutdown::new();
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new())
        .header_read_timeout(limits.header_timeout)
        .keep_alive(true);
    loop {
        if slots.available_permits() == 0 {
            connections.evict_slowest();
        }
        let slot = tokio::select! {
            () = stop.cancelled() => break,
            slot = slots.clone().acquire_owned() => slot.expect("the semaphore is never closed"),
        };
        let stream = tokio::select! {
            () = stop.cancelled() => break,
            accepted = listener.accept() => match accepted {
                Ok((stream, _)) => stream,
                Err(e) => {
                    tracing::warn!(error = %e, "accept failed");
                    tokio::time::sleep(ACCEPT_BACKOFF).await;
                    continue;
                }
            },
        };
        let _ = stream.set_nodelay(true);
        let served = Arc::new(AtomicBool::new(false));
        let service = app.clone().map_request({
            let served = served.clone();
            move |request: Request<Incoming>| {
                served.store(true, Ordering::Relaxed);
                request.map(Body::new)
            }
        });
        let service = TowerToHyperService::new(service);
        let connection = http.serve_connection(TokioIo::new(stream), service);
        let connection = graceful.watch(connection);
        let id = connections.next.fetch_add(1, Ordering::Relaxed);
        let registry = connections.clone();
        // Registered before it can finish, so that its removal always follows its entry.
        let mut open = connections.open();
        let task = tokio::spawn(async move {
            // A closed or timed-out connection is the client's business, not an error here.
            let _ = connection.await;
            registry.closed(id);
            drop(slot);
        });
        open.push_back(Open {
            id,
            served,
            task: task.abort_handle(),
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
