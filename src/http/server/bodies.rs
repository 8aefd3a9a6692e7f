//! The bodies of a connection's requests and answers, as the accept loop wraps them: a
//! request body must keep arriving (a progress timeout between its pieces and a minimum
//! rate after a grace period, as Kestrel's `MinRequestBodyDataRate`), and an answer's body
//! carries the guard that ends its request when hyper has taken all of it.

use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;

use axum::body::Body;
use bytes::Bytes;
use hyper::body::{Body as HttpBody, Frame, Incoming, SizeHint};
use tokio::time::{Instant, Sleep};

use super::activity::{Activity, RequestGuard};

/// How a request body must arrive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BodyPace {
    /// Longest wait for the next piece of the body; also the grace period before the
    /// minimum rate applies.
    pub timeout: Duration,
    /// Bytes per second the body must average once the grace period is over.
    pub min_rate: u64,
}

/// A request body that arrived too slowly; the JSON body extractor answers it with 408.
#[derive(Debug, thiserror::Error)]
#[error(
    "the request body arrived too slowly: {received} bytes in {secs:.1} s; this service waits at \
     most {wait} s for each piece of a body and, after that long, takes at least {rate} \
     bytes/s on average",
    secs = .after.as_secs_f64(),
    wait = .pace.timeout.as_secs_f64(),
    rate = .pace.min_rate
)]
pub struct TooSlow {
    pub received: u64,
    pub after: Duration,
    pub pace: BodyPace,
}

/// A request body held to its pace.
pub struct Paced {
    inner: Incoming,
    activity: Arc<Activity>,
    pace: BodyPace,
    started: Instant,
    received: u64,
    /// When the body is too slow unless more of it arrives; armed at the first wait (most
    /// bodies arrive whole with their head, and need no timer).
    deadline: Option<Pin<Box<Sleep>>>,
}

impl Paced {
    pub fn new(inner: Incoming, activity: Arc<Activity>, pace: BodyPace) -> Self {
        let started = Instant::now();
        if !inner.is_end_stream() {
            activity.receiving(true);
        }
        Paced {
            inner,
            activity,
            pace,
            started,
            received: 0,
            deadline: None,
        }
    }

    /// The next deadline: the progress timeout from now, or sooner the moment the average
    /// rate falls below the minimum (never before the grace period ends).
    fn next_deadline(&self) -> Instant {
        let now = Instant::now();
        let rate = self.pace.min_rate.max(1) as f64;
        let earned = Duration::from_secs_f64((self.received as f64 / rate).min(1e9));
        let by_rate = self.started + self.pace.timeout.max(earned);
        (now + self.pace.timeout).min(by_rate.max(now))
    }

    fn too_slow(&self) -> TooSlow {
        TooSlow {
            received: self.received,
            after: self.started.elapsed(),
            pace: self.pace,
        }
    }
}

impl HttpBody for Paced {
    type Data = Bytes;
    type Error = axum::BoxError;

    fn poll_frame(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, Self::Error>>> {
        let this = self.get_mut();
        match Pin::new(&mut this.inner).poll_frame(cx) {
            Poll::Ready(Some(Ok(frame))) => {
                if let Some(data) = frame.data_ref() {
                    this.received += data.len() as u64;
                }
                let next = this.next_deadline();
                if let Some(deadline) = &mut this.deadline {
                    deadline.as_mut().reset(next);
                }
                Poll::Ready(Some(Ok(frame)))
            }
            Poll::Ready(end) => {
                this.activity.receiving(false);
                Poll::Ready(end.map(|e| e.map_err(Into::into)))
            }
            Poll::Pending => {
                let next = this.next_deadline();
                let deadline = this
                    .deadline
                    .get_or_insert_with(|| Box::pin(tokio::time::sleep_until(next)));
                match deadline.as_mut().poll(cx) {
                    Poll::Ready(()) => {
                        this.activity.receiving(false);
                        Poll::Ready(Some(Err(this.too_slow().into())))
                    }
                    Poll::Pending => Poll::Pending,
                }
            }
        }
    }

    fn is_end_stream(&self) -> bool {
        self.inner.is_end_stream()
    }

    fn size_hint(&self) -> SizeHint {
        self.inner.size_hint()
    }
}

impl Drop for Paced {
    fn drop(&mut self) {
        self.activity.receiving(false);
    }
}

/// Finds a [`TooSlow`] among the causes of a body's error.
pub fn slow_body_in<'a>(error: &'a (dyn std::error::Error + 'static)) -> Option<&'a TooSlow> {
    let mut cause = Some(error);
    while let Some(e) = cause {
        if let Some(slow) = e.downcast_ref::<TooSlow>() {
            return Some(slow);
        }
        cause = e.source();
    }
    None
}

/// An answer's body, holding its request open until hyper has taken all of it.
pub struct Answer {
    inner: Body,
    _request: RequestGuard,
}

impl Answer {
    pub fn new(inner: Body, request: RequestGuard) -> Self {
        Answer {
            inner,
            _request: request,
        }
    }
}

impl HttpBody for Answer {
    type Data = Bytes;
    type Error = axum::Error;

    fn poll_frame(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, Self::Error>>> {
        Pin::new(&mut self.get_mut().inner).poll_frame(cx)
    }

    fn is_end_stream(&self) -> bool {
        self.inner.is_end_stream()
    }

    fn size_hint(&self) -> SizeHint {
        self.inner.size_hint()
    }
}
