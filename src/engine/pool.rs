//! Admission control for the compute threads: one permit per solver thread, sized to the
//! cores. A synchronous request that finds no permit free is refused at once (the caller
//! answers 429) rather than queued without bound; an asynchronous job waits for one in the
//! job store's bounded queue.

use std::sync::Arc;

use tokio::sync::{OwnedSemaphorePermit, Semaphore};

use crate::job::{Control, JobError};

/// The permits of the solver threads.
#[derive(Clone, Debug)]
pub struct Pool {
    permits: Arc<Semaphore>,
}

impl Pool {
    /// A pool of `size` permits (at least one).
    pub fn new(size: usize) -> Self {
        Pool {
            permits: Arc::new(Semaphore::new(size.max(1))),
        }
    }

    /// A permit if one is free now.
    pub fn try_acquire(&self) -> Option<OwnedSemaphorePermit> {
        self.permits.clone().try_acquire_owned().ok()
    }

    /// Waits for a permit (first come, first served).
    pub async fn acquire(&self) -> OwnedSemaphorePermit {
        self.permits
            .clone()
            .acquire_owned()
            .await
            .expect("the pool's semaphore is never closed")
    }

    /// Runs `work` on a blocking thread (below the async threads, [`super::heavy`]) that holds `permit` until it returns, inside the
    /// caller's tracing span. If the caller stops waiting (a client hung up, a request timed
    /// out), `control` is cancelled: the solver stops at its next check instead of burning a
    /// core for nobody.
    pub async fn run<T, F>(
        permit: OwnedSemaphorePermit,
        control: Arc<Control>,
        work: F,
    ) -> Result<T, JobError>
    where
        T: Send + 'static,
        F: FnOnce(&Control) -> Result<T, JobError> + Send + 'static,
    {
        let guard = CancelOnDrop(Some(control.clone()));
        let span = tracing::Span::current();
        let result = super::heavy::run(move || {
            let _permit = permit;
            span.in_scope(|| work(&control))
        })
        .await;
        guard.disarm();
        result.map_err(|e| JobError::Internal(format!("the solver thread failed: {e}")))?
    }
}

/// Cancels a job when the future waiting for it is dropped before it finished.
struct CancelOnDrop(Option<Arc<Control>>);

impl CancelOnDrop {
    fn disarm(mut self) {
        self.0 = None;
    }
}

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if let Some(control) = &self.0 {
            control.cancel();
        }
    }
}
