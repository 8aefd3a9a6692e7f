//! A connection's transport with a send timeout: a write that waits longer than the
//! timeout for the client to read fails, and hyper closes the connection (nginx's
//! `send_timeout`: the time between two successive writes, not the whole answer). Reads and
//! writes also tell the connection's [`Activity`] what the client does.

use std::future::Future;
use std::io;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;

use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::TcpStream;
use tokio::time::Sleep;

use super::activity::Activity;

/// A TCP stream watched for stalled writes.
pub struct Watched {
    stream: TcpStream,
    activity: Arc<Activity>,
    send_timeout: Duration,
    /// Armed while a write waits.
    stall: Option<Pin<Box<Sleep>>>,
}

impl Watched {
    pub fn new(stream: TcpStream, activity: Arc<Activity>, send_timeout: Duration) -> Self {
        Watched {
            stream,
            activity,
            send_timeout,
            stall: None,
        }
    }

    /// Passes a write's outcome on, failing it once it has waited for the send timeout.
    fn progress<T>(
        &mut self,
        cx: &mut Context<'_>,
        outcome: Poll<io::Result<T>>,
    ) -> Poll<io::Result<T>> {
        if outcome.is_ready() {
            if self.stall.take().is_some() {
                self.activity.write_moved();
            }
            return outcome;
        }
        let stall = self.stall.get_or_insert_with(|| {
            self.activity.write_waits();
            Box::pin(tokio::time::sleep(self.send_timeout))
        });
        match stall.as_mut().poll(cx) {
            Poll::Ready(()) => Poll::Ready(Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "the client read nothing for the send timeout",
            ))),
            Poll::Pending => Poll::Pending,
        }
    }
}

/// A connection dropped while a write waits (cut by the send timeout, or evicted as a
/// reader that stopped reading) is reset rather than closed: its unsent bytes leave the
/// kernel at once instead of staying queued for a client that does not read them (nginx's
/// `reset_timedout_connection`). 511 such readers otherwise held 1.2 GB of socket memory,
/// which is counted against the container's memory and slows every connection's writes.
impl Drop for Watched {
    fn drop(&mut self) {
        if self.stall.is_some() {
            let _ = self.stream.set_zero_linger();
        }
    }
}

impl AsyncRead for Watched {
    fn poll_read(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        let this = self.get_mut();
        let before = buf.filled().len();
        let outcome = Pin::new(&mut this.stream).poll_read(cx, buf);
        if buf.filled().len() > before {
            this.activity.heard();
        }
        outcome
    }
}

impl AsyncWrite for Watched {
    fn poll_write(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        let this = self.get_mut();
        let outcome = Pin::new(&mut this.stream).poll_write(cx, buf);
        this.progress(cx, outcome)
    }

    fn poll_write_vectored(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        let this = self.get_mut();
        let outcome = Pin::new(&mut this.stream).poll_write_vectored(cx, bufs);
        this.progress(cx, outcome)
    }

    fn is_write_vectored(&self) -> bool {
        self.stream.is_write_vectored()
    }

    fn poll_flush(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        let this = self.get_mut();
        let outcome = Pin::new(&mut this.stream).poll_flush(cx);
        this.progress(cx, outcome)
    }

    fn poll_shutdown(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_shutdown(cx)
    }
}
